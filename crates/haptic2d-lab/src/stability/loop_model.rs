//! The per-axis models of a configured haptic loop: device, controller, slave and the scene's stiffest
//! contact, from a [`HapticConfig`] and a [`World`], and the analysis of each axis with the hand held
//! and released.

use haptic2d::control::four_channel::FourChannelGains;
use haptic2d::device::dynamics::LumpedDynamics;
use haptic2d::device::linalg::{inv3, V3};
use haptic2d::device::TwinPantograph;
use haptic2d::haptic::{ControllerKind, HapticConfig};
use haptic2d::world::World;

use super::axis::{AxisController, AxisModel};
use super::dense::Mat;
use super::eig::{eigenvalues, rightmost, spectral_radius, Complex};

/// Axis names, in state order.
pub const AXES: [&str; 3] = ["x", "y", "theta"];

/// The hand held: the simulated grip of `HandModel::grip` (handle units: N/m, N/m, N·m/rad and
/// N·s/m, N·s/m, N·m·s/rad).
pub const GRIP_STIFFNESS: V3 = [300.0, 300.0, 0.5];
/// Damping of the simulated grip (N·s/m, N·s/m, N·m·s/rad).
pub const GRIP_DAMPING: V3 = [5.0, 5.0, 0.005];

/// Required decay rate of the slowest mode for a verdict "stable" (1/s): its amplitude must fall at
/// least by a factor e every 0.5 s, held and released. A loop that decays slower is "marginal".
pub const MIN_DECAY_RATE: f64 = 2.0;

/// The scene's stiffest contact on the slave, linearised per axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Environment {
    /// Per-contact stiffness and damping of the normal law `(K_n, B_n)` (N/m, N·s/m).
    pub normal: (f64, f64),
    /// Per-contact stick stiffness and damping of the friction model `(K_f, B_f)` (N/m, N·s/m); zero
    /// for models without a stick spring.
    pub friction: (f64, f64),
    /// Contacts assumed to act together (at least 2: a face flat on a wall; more when the slave
    /// starts squeezed, e.g. 4 for the peg in its channel).
    pub contacts: usize,
    /// Lever arm of the contacts about the slave's centre (m): its farthest vertex.
    pub lever: f64,
}

impl Environment {
    /// The contacts of `world` on body `slave`: the per-contact laws of the world's prototypes,
    /// `max(2, contacts at the start)` corners, and the slave's farthest vertex as lever.
    pub fn of_world(world: &World, slave: usize) -> Self {
        let mut w = world.clone();
        w.begin_step();
        let contacts = w.contacts().contact_count().max(2);
        let lever = world
            .colliders
            .iter()
            .filter(|c| c.body == slave)
            .flat_map(|c| c.local.vertices().iter().map(|v| v.length()))
            .fold(0.0, f64::max);
        Self {
            normal: world.normal.stiffness_damping(),
            friction: world.friction.stiffness_damping(),
            contacts,
            lever,
        }
    }

    /// `(K_e, B_e)` along axis `i` for the per-contact spring `(k, b)`: `n·k`, `n·b` for x and y
    /// (N/m, N·s/m); `n·k·r²`, `n·b·r²` for θ (N·m/rad, N·m·s/rad).
    pub fn axis(&self, i: usize, (k, b): (f64, f64)) -> (f64, f64) {
        let n = self.contacts as f64;
        let l2 = if i == 2 { self.lever * self.lever } else { 1.0 };
        (n * k * l2, n * b * l2)
    }

    /// The springs an axis may meet: the normal law (a face pressed along the axis) and, if the
    /// friction model has one, its stick spring (the axis along a sticking contact).
    pub fn springs(&self) -> Vec<(&'static str, (f64, f64))> {
        let mut v = vec![("normal", self.normal)];
        if self.friction.0 > 0.0 {
            v.push(("friction stick", self.friction));
        }
        v
    }
}

/// Everything the analysis needs besides the gains: per-axis device, slave and environment numbers
/// in world units, the sample period and the output delay.
#[derive(Clone, Debug, PartialEq)]
pub struct LoopModel {
    /// The three axes with the grip hand (see [`GRIP_STIFFNESS`]), against the normal law;
    /// `.released()` for no hand.
    pub axes: [AxisModel; 3],
    /// The same axes against each spring of [`Environment::springs`] (name, axes); the first is
    /// `axes`.
    pub cases: Vec<(&'static str, [AxisModel; 3])>,
    /// Sample period `T` (s).
    pub dt: f64,
    /// Extra samples between the controller and the amplifiers (0: the lab's simulated device).
    pub delay: usize,
    /// The environment the axes were built against.
    pub env: Environment,
}

/// The linear controller of axis `i` for `kind`.
pub fn axis_controller(kind: &ControllerKind, i: usize) -> AxisController {
    match kind {
        ControllerKind::FourChannel(g) => four_channel_axis(g, i),
        ControllerKind::Coupling(g) => AxisController {
            k_m: g.k[i],
            b_m: g.b[i],
            k_s: g.k[i],
            b_s: g.b[i],
            g_mh: 0.0,
            g_me: 0.0,
            g_sh: 0.0,
            g_se: 0.0,
            d_m: 0.0,
            d_s: 0.0,
        },
    }
}

fn four_channel_axis(g: &FourChannelGains, i: usize) -> AxisController {
    AxisController {
        k_m: g.k_m[i],
        b_m: g.b_m[i],
        k_s: g.k_s[i],
        b_s: g.b_s[i],
        g_mh: g.c6[i],
        g_me: -g.c2.map_or(1.0 + g.c6[i], |c| c[i]),
        g_sh: g.c3.map_or(1.0 + g.c5[i], |c| c[i]),
        g_se: -g.c5[i],
        d_m: g.d_m[i],
        d_s: g.d_s[i],
    }
}

impl LoopModel {
    /// The loop of `config` around `world` (slave = `config.slave` or the first dynamic body) at
    /// `rate` (Hz), with `delay` extra output samples.
    ///
    /// Device numbers at the start pose `x0` (the mapping's device origin): the apparent inertia along
    /// axis `i` with the other axes free, `1/(M_x⁻¹)_ii` (the x–θ and y–θ inertial coupling of the
    /// twin pantograph makes it smaller than `(M_x)_ii`; the released handle is free on every axis);
    /// the damping `b_i = f_v·(J_aᵀJ_a)_ii` of the joint viscous friction `τ = f_v·q̇`, `q̇ = J_a·ẋ`.
    /// The world/device map scales translations by `s`, so in world units inertia, damping and hand
    /// impedance are divided by `s²` (power is preserved: `f_d = s·f_w`, `v_w = s·v_d`).
    pub fn new(
        config: &HapticConfig,
        world: &World,
        rate: f64,
        delay: usize,
    ) -> Result<Self, String> {
        if !(rate.is_finite() && rate > 0.0) {
            return Err(format!("stability: the rate must be > 0 Hz (got {rate})"));
        }
        let dt = 1.0 / rate;
        let slave = match &config.slave {
            Some(name) => world
                .body_index(name)
                .ok_or_else(|| format!("stability: slave body `{name}` not found"))?,
            None => world
                .bodies
                .iter()
                .position(|b| b.is_dynamic())
                .ok_or("stability: the scene has no dynamic body for the device to drive")?,
        };
        let body = &world.bodies[slave];
        let p = &config.device;
        let dev = TwinPantograph::new(*p, dt, config.observer)?;
        let x0 = config
            .device_origin
            .unwrap_or([p.workspace_center_x, p.workspace_center_y, 0.0]);
        let j = dev
            .jacobian(&x0)
            .map_err(|e| format!("stability: device start pose {x0:?}: {e}"))?;
        let m_x = LumpedDynamics::new(p).mass_matrix(&j, x0[2]);
        let m_inv = inv3(&m_x).ok_or("stability: the device mass matrix is singular")?;
        let env = Environment::of_world(world, slave);
        let s = config.scale;
        let build = |spring: (f64, f64)| -> [AxisModel; 3] {
            std::array::from_fn(|i| {
                let jtj: f64 = j.iter().map(|row| row[i] * row[i]).sum();
                let w = if i < 2 { 1.0 / (s * s) } else { 1.0 };
                let (k_e, b_e) = env.axis(i, spring);
                AxisModel {
                    m: w / m_inv[i][i],
                    b: w * p.f_v * jtj,
                    k_h: w * GRIP_STIFFNESS[i],
                    b_h: w * GRIP_DAMPING[i],
                    m_s: if i < 2 { body.mass } else { body.inertia },
                    k_e,
                    b_e,
                    ctrl: axis_controller(&config.controller, i),
                    k_o: p.observer_gain[i],
                    velocity_cutoff_hz: p.velocity_cutoff_hz,
                }
            })
        };
        let cases: Vec<(&'static str, [AxisModel; 3])> = env
            .springs()
            .into_iter()
            .map(|(n, k)| (n, build(k)))
            .collect();
        Ok(Self {
            axes: cases[0].1,
            cases,
            dt,
            delay,
            env,
        })
    }

    /// Analyses every axis, held and released, against each spring of [`Self::cases`]; per axis the
    /// report keeps the spring with the larger released growth rate (the worse one).
    pub fn analyse(&self) -> Result<[AxisReport; 3], String> {
        let mut out: Vec<AxisReport> = Vec::with_capacity(3);
        for i in 0..3 {
            let mut worst: Option<AxisReport> = None;
            for (name, axes) in &self.cases {
                let r = AxisReport::analyse(AXES[i], name, axes[i], self.dt, self.delay)?;
                r.keep_if_worse(&mut worst);
            }
            out.extend(worst);
        }
        out.try_into()
            .map_err(|_| "stability: three axes expected".to_string())
    }
}

/// The poles of one axis in one hand condition.
#[derive(Clone, Debug, PartialEq)]
pub struct LoopPoles {
    /// Every continuous-time pole (1/s), right-most first.
    pub continuous: Vec<Complex>,
    /// Every eigenvalue of the sampled-data state matrix (dimensionless), largest modulus first.
    pub discrete: Vec<Complex>,
    /// Growth rate of the sampled-data loop, `ln ρ(A_d)/T` (1/s): > 0 grows, < 0 decays.
    pub growth: f64,
}

impl LoopPoles {
    /// Continuous and sampled-data poles of `a` at period `dt` with `delay`.
    pub fn of(a: &AxisModel, dt: f64, delay: usize) -> Result<Self, String> {
        let mut continuous = eigenvalues(&a.continuous())?;
        continuous.sort_by(|p, q| q.0.total_cmp(&p.0).then(q.1.total_cmp(&p.1)));
        let ad: Mat = a.discrete(dt, delay);
        let mut discrete = eigenvalues(&ad)?;
        discrete.sort_by(|p, q| q.0.hypot(q.1).total_cmp(&p.0.hypot(p.1)));
        // Structural zeros (the delay slot when unused) give |λ| = 0; ρ > 0 for any real loop.
        let rho = spectral_radius(&discrete);
        Ok(Self {
            continuous,
            discrete,
            growth: rho.ln() / dt,
        })
    }

    /// The right-most continuous pole `(σ, ω)` (1/s, rad/s).
    pub fn rightmost(&self) -> Complex {
        rightmost(&self.continuous)
    }
}

/// Verdict on one axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// Held and released both decay at least at [`MIN_DECAY_RATE`].
    Stable,
    /// Both decay, but one slower than [`MIN_DECAY_RATE`].
    Marginal,
    /// The loop grows with the hand released.
    UnstableReleased,
    /// The loop grows with the hand held.
    UnstableHeld,
}

impl Verdict {
    /// Text for the report.
    pub fn label(&self) -> &'static str {
        match self {
            Verdict::Stable => "stable",
            Verdict::Marginal => "marginal (stable, little margin)",
            Verdict::UnstableReleased => "UNSTABLE with the hand released",
            Verdict::UnstableHeld => "UNSTABLE with the hand held",
        }
    }
}

/// One axis: held and released poles.
#[derive(Clone, Debug, PartialEq)]
pub struct AxisReport {
    /// `x`, `y` or `theta`.
    pub axis: &'static str,
    /// Which spring of the contact this is: `normal` or `friction stick`.
    pub contact: &'static str,
    /// The axis model analysed (with the grip hand).
    pub model: AxisModel,
    /// With the grip hand.
    pub held: LoopPoles,
    /// With no hand.
    pub released: LoopPoles,
}

impl AxisReport {
    /// The loop poles of `model` on axis `axis` against the spring `contact`, held and released, at
    /// period `dt` (s) with `delay` extra output samples.
    pub fn analyse(
        axis: &'static str,
        contact: &'static str,
        model: AxisModel,
        dt: f64,
        delay: usize,
    ) -> Result<Self, String> {
        Ok(AxisReport {
            axis,
            contact,
            model,
            held: LoopPoles::of(&model, dt, delay)?,
            released: LoopPoles::of(&model.released(), dt, delay)?,
        })
    }

    /// Puts `self` in `worst` when `worst` is empty or grows slower (held or released, 1/s) than
    /// `self`: the per-axis reports keep the worse spring.
    pub fn keep_if_worse(self, worst: &mut Option<AxisReport>) {
        let growth = |r: &AxisReport| r.released.growth.max(r.held.growth);
        if worst.as_ref().is_none_or(|w| growth(&self) > growth(w)) {
            *worst = Some(self);
        }
    }

    /// The verdict from the sampled-data growth rates.
    pub fn verdict(&self) -> Verdict {
        if self.released.growth >= 0.0 {
            Verdict::UnstableReleased
        } else if self.held.growth >= 0.0 {
            Verdict::UnstableHeld
        } else if self.released.growth > -MIN_DECAY_RATE || self.held.growth > -MIN_DECAY_RATE {
            Verdict::Marginal
        } else {
            Verdict::Stable
        }
    }
}
