//! Figs. 5–6 of the paper with the device in the loop: the walls on the haptic interface.
//!
//! "The user holds a rectangular virtual object inside a frictionless rectangular world. The user lets
//! go of the handle and the hand is replaced by a constant force. No wall damping exists." Here: the
//! box-in-walls scene (0.5 kg box 0.02 m from the left wall) with the wall's normal law replaced by one
//! of the §5 walls (per-contact defaults, impacts off, so the wall law alone handles the contact), the
//! simulated twin pantograph and, by default, the four-channel controller (the paper's) at 500 Hz; the
//! simulated hand grips the handle at its start pose for `t_hold`, then is replaced by a constant push
//! `F` toward the wall (y and θ keep the grip, see [`Fig5Params::guide_y_theta`]).
//!
//! Cases: SEH (marginally passive) and ZOH (active) — Fig. 5: the block keeps bouncing; braking pulse
//! and hysteretic wall — Fig. 6: contact stability at the first impact with the pulse, soon with the
//! hysteretic wall. Metrics per case from the slave's trajectory after the release (§13.1 definitions:
//! separations, entry/exit speeds, contact ratios, settle time). Pass criteria (§5.10's W6/W7
//! thresholds, with W7's absolute 0.06 m/s made relative to the 0.40 m/s entry of §5.10), `v1` the
//! measured first entry speed:
//!
//! - keeps bouncing: at least 2 separations in the last 2 s and no settle time;
//! - settles at the first impact (W7): first contact ratio ≤ 0.4 (a box that never leaves the wall has
//!   no ratio, which counts as 0), every entry speed after the second impact < 0.15·v1, and no
//!   separation in the last 2 s;
//! - settles soon (W6): each of the first three contact ratios (those that exist) < 0.85 and at most
//!   6 separations.
//!
//! **Which runs carry the claims (issue 36).** Each claim is carried by a named configuration on the
//! spec's device (§10.2, joint `f_v = 1e-4`, no calibrated damping), chosen for a reason the report
//! states beside `haptic2d stability`'s verdict (see `crate::figures::fig5`): the hysteretic wall by the
//! default controller ([`Fig5Params::default`]: `FourChannelGains::local_force_feedback`, `C6 = −1`,
//! `C5 = 2`), the pulse wall by the former default (`C6 = −1`, `C5 = 0`, `D_m = 2`), and the SEH and
//! ZOH bouncing by the paper's §11.1 table ([`Fig5Params::paper_controller`](crate::scenarios::ControllerRuns::paper_controller)), which is unstable
//! released against these walls and refused on a real device. Comparison runs: the §11.1 table on a
//! device damped at twice Colgate's bound ([`Fig5Params::calibrated_damping`]) and the virtual
//! coupling ([`Fig5Params::coupling`](crate::scenarios::ControllerRuns::coupling)).
//!
//! **The mechanism.** After the release the hand is a constant force: the handle is *released* in the
//! sense of §11.4 (no hand impedance). With the §11.1 table (`C2 = 1`) the released loop of handle,
//! slave and wall spring is unstable in continuous time — the §11.4 polynomial for this device and
//! wall (m ≈ 0.445 kg, b ≈ 0.028 N·s/m, K = 2000 N/m) has roots `+2.4 ± 67j`, and the sampled-data
//! growth at 500 Hz is about +19 1/s (`haptic2d stability`). That is what made the §10.2-device runs
//! "active" (SEH contact ratios above 1) — not Colgate's `b > K·T/2`: the instability is there
//! before sampling, and the 5 N·s/m of calibrated damping works because it moves the polynomial's
//! roots left (stable above `b ≈ 2.65 N·s/m`), not because it exceeds `K·T/2`. With `C6 = −1`
//! (`C2 = 0`) the environment force no longer reaches the handle; the handle follows the box through
//! the PD `(K_m, B_m)` and the slave's `(K_s, B_s)`, and at each impact the handle's momentum is
//! dissipated in those dampers (the box stops, the handle does not). So the stable design is
//! dissipative at the wall: the box bounces at most once, so the "keeps bouncing" claims of SEH and
//! ZOH fail while the hysteretic wall passes. The bouncing claim needs the handle to stop with the
//! box, i.e. force reflection `C2 = 1`, which is exactly the released-unstable path; no design of
//! the study of issue 36 (`tests/it/design_search.rs`, 700+ candidates, MODELS.md §11.4) has both.

use crate::schema::Check;
use haptic2d::device::dynamics::LumpedDynamics;
use haptic2d::device::HandModel;
use haptic2d::device::TwinPantograph;
use haptic2d::laws::normal::{BrakingPulseLaw, NormalModel};
use haptic2d::metrics::{BounceMetrics, BounceSample};
use haptic2d::scene::Scene;

use super::ControllerRuns as _;
use haptic2d::haptic::config::HapticConfig;
use haptic2d::haptic::experiment::DeviceInTheLoop;
use haptic2d::haptic::record::TickRecord;
use haptic2d::haptic::safety::SafetyConfig;
use haptic2d::haptic::system::HapticSystem;

/// Settings of the Fig. 5–6 experiment.
#[derive(Clone, Debug, PartialEq)]
pub struct Fig5Params {
    /// Control rate (Hz). Default 500 (the paper's).
    pub rate: f64,
    /// Hold time before the hand lets go (s). Default 0.5.
    pub t_hold: f64,
    /// Constant push that replaces the hand, along −x (N). Default 2.
    pub push: f64,
    /// Duration (s). Default 10.
    pub duration: f64,
    /// Haptic-system settings (device, observer, controller, passivity). Default: the defaults.
    pub haptic: HapticConfig,
    /// Encoder quantisation in the simulated plant. Default true.
    pub quantize: bool,
    /// After the release, keep the hand's grip on y and θ (the push stays a constant force along x).
    /// Default true. With a fully free handle (false) the x push also turns the handle through the
    /// device's inertial x–θ coupling; nothing restrains θ or y, the box hits the wall on a corner,
    /// tumbles, and the handle wanders to the edge of the workspace within about 2 s (safety stop).
    pub guide_y_theta: bool,
    /// Size the braking pulse for the box plus the device's mass (the "effective mass at the handle"
    /// of §5.7): `e_b` is raised so the pulse removes the device's momentum too. Default false (the box
    /// mass alone): the larger pulse makes the contact chatter (144 separations in 10 s instead of 2).
    pub pulse_device_mass: bool,
    /// The device's physical damping as a multiple of Colgate's bound (§5.4). `Some(m)`: the joint
    /// viscous friction `f_v` of `haptic.device` is replaced by the value that gives the handle an x
    /// damping `b_x = f_v·(J_aᵀJ_a)_xx = m·K·T/2` at its start pose, `K` = [`WALL_STIFFNESS`], `T` the
    /// control period (see [`colgate_joint_damping`]); `None`: `haptic.device.f_v` as given (§10.2's
    /// \[REC\] 1e-4 N·m·s/rad by default, i.e. m ≈ 0.014). Default `None` (the §10.2 device);
    /// [`Fig5Params::calibrated_damping`] uses 2.
    pub colgate_margin: Option<f64>,
    /// The haptic system's safety settings (start-up ramp, stall limit, torque trip margin).
    /// Default: [`SafetyConfig::default`] (the torques ramp in over 0.5 s from the first tick).
    pub safety: SafetyConfig,
    /// Where the constant push acts after the release: on the handle (default) or in the
    /// hand-force estimate (the handle is then released along x, y and θ still guided when
    /// [`Fig5Params::guide_y_theta`]).
    pub protocol: super::Protocol,
}

impl super::ControllerRuns for Fig5Params {
    fn haptic_mut(&mut self) -> &mut HapticConfig {
        &mut self.haptic
    }
}

impl Fig5Params {
    /// Same as [`Fig5Params::paper_controller`](crate::scenarios::ControllerRuns::paper_controller) (the §11.1 table on the undamped §10.2 device).
    pub fn spec_device() -> Self {
        Self::paper_controller()
    }

    /// The §11.1 table on a device whose damping is calibrated to twice Colgate's bound (`f_v =
    /// 1.44e-2 N·m·s/rad` at 500 Hz): the former default, now a comparison run. It passes the four
    /// walls because 4 N·s/m at the handle moves the released loop's poles left (§11.4 needs
    /// `b ≳ 2.65 N·s/m`), not because of Colgate's bound.
    pub fn calibrated_damping() -> Self {
        Self {
            colgate_margin: Some(2.0),
            ..Self::paper_controller()
        }
    }

    /// These settings with the device damped at `margin` times Colgate's bound.
    pub fn with_margin(&self, margin: f64) -> Self {
        Self {
            colgate_margin: Some(margin),
            ..self.clone()
        }
    }

    /// The haptic settings actually used: `haptic` with `f_v` from [`Fig5Params::colgate_margin`].
    pub fn haptic_config(&self) -> Result<HapticConfig, String> {
        let mut h = self.haptic.clone();
        if let Some(m) = self.colgate_margin {
            h.device.f_v = colgate_joint_damping(&h, self.rate, m)?;
        }
        Ok(h)
    }
}

/// Stiffness of every Fig. 5–6 wall against the box's face (N/m): each law's per-contact default is
/// 1000 N/m on each of the face's two corner contacts.
pub const WALL_STIFFNESS: f64 = 2000.0;

/// The joint viscous friction `f_v` (N·m·s/rad) that gives the handle of `h.device`, at its start
/// pose, the x damping `b_x = margin·K·T/2` (N·s/m), `K` = [`WALL_STIFFNESS`], `T = 1/rate`.
///
/// Colgate's passivity condition for a wall of stiffness `K` rendered through a zero-order hold is
/// `b > K·T/2` (§5.4). Through channel C2 the four-channel loop renders the slave's wall force on the
/// handle one sample late, so the handle is such a ZOH wall, and `b` is the device's own damping. Joint
/// viscous friction `τ_f = f_v·q̇` with `q̇ = J_a·ẋ` maps to the handle as `J_aᵀ·f_v·J_a·ẋ`, so
/// `b_x = f_v·(J_aᵀJ_a)_xx`; at the workspace centre `(J_aᵀJ_a)_xx ≈ 277 m⁻²`. With the spec's
/// `f_v = 1e-4` that is 0.028 N·s/m against `K·T/2 = 2 N·s/m` at 500 Hz. Margin 2 needs
/// `f_v ≈ 1.44e-2 N·m·s/rad`: the back-EMF damping `n_g²·K_t²/R` of a voltage-driven motor with
/// `K_t = 25 mN·m/A`, `R = 4.3 Ω` and §10.2's `n_g = 10`.
pub fn colgate_joint_damping(h: &HapticConfig, rate: f64, margin: f64) -> Result<f64, String> {
    if !(margin.is_finite() && margin >= 0.0 && rate.is_finite() && rate > 0.0) {
        return Err(format!(
            "fig5: the Colgate margin ({margin}) must be ≥ 0 and the rate ({rate} Hz) > 0"
        ));
    }
    let dev = TwinPantograph::new(h.device, 1.0 / rate, h.observer)?;
    let x0 = h.device_origin.unwrap_or([
        h.device.workspace_center_x,
        h.device.workspace_center_y,
        0.0,
    ]);
    let j = dev.jacobian(&x0).map_err(|e| e.to_string())?;
    let jtj_xx: f64 = j.iter().map(|row| row[0] * row[0]).sum();
    Ok(margin * WALL_STIFFNESS / (2.0 * rate) / jtj_xx)
}

/// Mass of the box of box-in-walls (kg).
const BOX_MASS: f64 = 0.5;

impl Default for Fig5Params {
    fn default() -> Self {
        Self {
            rate: 500.0,
            t_hold: 0.5,
            push: 2.0,
            duration: 10.0,
            haptic: HapticConfig::default(),
            quantize: true,
            guide_y_theta: true,
            pulse_device_mass: false,
            colgate_margin: None,
            safety: SafetyConfig::default(),
            protocol: super::Protocol::HandleForce,
        }
    }
}

/// What is expected of a wall (the paper's claim).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fig5Expectation {
    /// Fig. 5: the block keeps bouncing (marginally passive or active wall).
    KeepsBouncing,
    /// Fig. 6: contact is stable from the first impact (wall with pulse).
    SettlesAtFirstImpact,
    /// Fig. 6: contact becomes stable within a few impacts (hysteretic wall).
    SettlesSoon,
}

/// The walls of Figs. 5–6: `(case name, normal-law name, expectation)`.
pub const FIG5_CASES: [(&str, &str, Fig5Expectation); 4] = [
    ("seh", "seh", Fig5Expectation::KeepsBouncing),
    ("zoh", "zoh", Fig5Expectation::KeepsBouncing),
    ("pulse", "pulse", Fig5Expectation::SettlesAtFirstImpact),
    ("hysteretic", "hysteretic", Fig5Expectation::SettlesSoon),
];

/// Metrics of one wall.
#[derive(Clone, Debug, PartialEq)]
pub struct Fig5Metrics {
    /// §13.1 bounce metrics of the box after the release.
    pub bounce: BounceMetrics,
    /// Separations in the last 2 s of the run.
    pub late_separations: usize,
    /// Entry speed of the first impact (m/s).
    pub first_entry_speed: f64,
    /// Largest entry speed after the first contact (m/s); 0 if none (for the report; the pulse
    /// criterion uses the entries after the second contact).
    pub max_later_entry_speed: f64,
    /// Largest `|v|` of the box over the last 2 s (m/s).
    pub late_max_speed: f64,
    /// Whether the run meets its expectation (criteria in the module docs).
    pub pass: bool,
}

/// One wall's run.
#[derive(Clone, Debug, PartialEq)]
pub struct Fig5Case {
    /// Case name.
    pub name: &'static str,
    /// The expectation checked by `metrics.pass`.
    pub expectation: Fig5Expectation,
    /// Every tick's record.
    pub records: Vec<TickRecord>,
    /// The box's minimum vertex x, i.e. its gap to the wall surface x = 0, per tick (m).
    pub gap: Vec<f64>,
    /// Metrics.
    pub metrics: Fig5Metrics,
    /// The safety stop that ended the run early, if any (then `metrics.pass` is false and the
    /// metrics cover the run up to the stop).
    pub stopped: Option<String>,
}

/// The box's gap to the left wall (its minimum vertex x) at pose `(x, y, θ)`, for a w × h box.
fn box_gap(x: &[f64; 3], half: [f64; 2]) -> f64 {
    let (s, c) = x[2].sin_cos();
    let mut g = f64::INFINITY;
    for (sx, sy) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
        let (px, py) = (sx * half[0], sy * half[1]);
        g = g.min(x[0] + c * px - s * py);
    }
    g
}

/// The box-in-walls scene with the wall law `normal` (per-contact defaults) and impacts off.
fn walls_toml(normal: &str, extra: &str) -> Result<String, String> {
    NormalModel::from_name(normal, true)?;
    let out = super::builtin_with_table(
        "box-in-walls",
        "[normal]",
        "[friction]",
        &format!("[normal]\nmodel = \"{normal}\"\n{extra}\n"),
    )?;
    if !out.contains("impacts = true") {
        return Err("box-in-walls: `impacts = true` not found".into());
    }
    Ok(out.replace("impacts = true", "impacts = false"))
}

/// The world of one wall (`normal` = a §5 law name, per-contact defaults, impacts off) at `rate`
/// (Hz): what the stability analysis of a Figs. 5–6 case is run against.
pub fn wall_world(normal: &str, rate: f64) -> Result<haptic2d::world::World, String> {
    Ok(
        Scene::from_toml(&walls_toml(normal, "")?, "fig5", Some(rate))
            .map_err(|e| e.to_string())?
            .world,
    )
}

/// Runs one wall (`normal` = a §5 law name).
pub fn run_case(
    p: &Fig5Params,
    name: &'static str,
    normal: &str,
    expectation: Fig5Expectation,
) -> Result<Fig5Case, String> {
    // The braking pulse is sized by the effective mass at the handle (§5.7). With the device in the
    // loop that is the box plus the device's x mass M_x,xx (0.445 kg at the workspace centre), but
    // the world only knows the box (m_eff = m/contacts); scale the restitution term instead:
    // (1 + e_b')·m_box = (1 + e_b)·(m_box + M_x,xx).
    let haptic = p.haptic_config()?;
    let extra = if normal == "pulse" && p.pulse_device_mass {
        let dev = TwinPantograph::new(haptic.device, 1.0 / p.rate, haptic.observer)?;
        let x0 = [
            haptic.device.workspace_center_x,
            haptic.device.workspace_center_y,
            0.0,
        ];
        let j = dev.jacobian(&x0).map_err(|e| e.to_string())?;
        let m_dev = LumpedDynamics::new(&haptic.device).mass_matrix(&j, 0.0)[0][0];
        let e_b = BrakingPulseLaw::per_contact().e_b;
        format!("e_b = {}", (1.0 + e_b) * (1.0 + m_dev / BOX_MASS) - 1.0)
    } else {
        String::new()
    };
    let world = Scene::from_toml(&walls_toml(normal, &extra)?, "fig5", Some(p.rate))
        .map_err(|e| e.to_string())?
        .world;
    let system = HapticSystem::with_safety(world, &haptic, p.safety)?;
    let mut l = DeviceInTheLoop::new(system, HandModel::Free, 10, p.quantize)?;
    let start = l.plant.pose();
    let (hold, stiffness, damping) = super::hold_at(start)?;
    // After the release: a constant push along −x. With the guide, a spring of 1 N/m stretched by
    // 2 m gives F·(1 ± 1 %) over the few centimetres of travel, with no damping along x, while y and θ
    // keep the grip's spring–damper.
    let inject = p.protocol == super::Protocol::EstimateInjection;
    let released = if inject {
        // The hand lets go along x; the push enters the hand-force estimate (set at the release).
        if p.guide_y_theta {
            HandModel::SpringDamper {
                target: start,
                stiffness: [0.0, stiffness[1], stiffness[2]],
                damping: [0.0, damping[1], damping[2]],
            }
        } else {
            HandModel::Free
        }
    } else if p.guide_y_theta {
        let len = 2.0;
        HandModel::SpringDamper {
            target: [start[0] - len, start[1], start[2]],
            stiffness: [p.push / len, stiffness[1], stiffness[2]],
            damping: [0.0, damping[1], damping[2]],
        }
    } else {
        HandModel::Constant {
            wrench: [-p.push, 0.0, 0.0],
        }
    };
    l.hand = hold;
    let dt = l.system.dt();
    let n = (p.duration / dt).round() as usize;
    let n_hold = (p.t_hold / dt).round() as usize;
    let (mut records, mut gap) = (Vec::with_capacity(n), Vec::with_capacity(n));
    let mut stopped = None;
    for k in 0..n {
        if k == n_hold {
            l.hand = released;
            if inject {
                let scale = l.system.map().scale;
                l.system
                    .set_hand_estimate_injection([-scale * p.push, 0.0, 0.0]);
            }
        }
        let out = l
            .step()
            .map_err(|e| format!("fig5 {name}: simulated device failed: {e}"))?;
        if let Some(d) = l.system.world().divergence() {
            return Err(format!("fig5 {name}: the world diverged: {d}"));
        }
        gap.push(box_gap(&out.record.x_s, [0.02, 0.01]));
        records.push(out.record);
        if out.tripped {
            stopped = Some(
                l.system
                    .safety_trip()
                    .map_or("safety stop".to_string(), |t| t.to_string()),
            );
            break;
        }
    }
    let samples: Vec<BounceSample> = records
        .iter()
        .zip(&gap)
        .filter(|(r, _)| r.t >= p.t_hold)
        .map(|(r, g)| BounceSample {
            t: r.t,
            gap: *g,
            v_n: r.v_s[0],
            speed: (r.v_s[0] * r.v_s[0] + r.v_s[1] * r.v_s[1]).sqrt(),
            omega: r.v_s[2].abs(),
        })
        .collect();
    let bounce = BounceMetrics::from_samples(&samples);
    let t_late = p.duration - 2.0;
    let late_separations = bounce
        .separation_times
        .iter()
        .filter(|t| **t >= t_late)
        .count();
    let late_max_speed = samples
        .iter()
        .filter(|s| s.t >= t_late)
        .map(|s| s.speed)
        .fold(0.0, f64::max);
    let first_entry_speed = bounce.entry_speeds.first().copied().unwrap_or(0.0);
    let max_later_entry_speed = bounce
        .entry_speeds
        .iter()
        .skip(1)
        .copied()
        .fold(0.0, f64::max);
    let ratios = &bounce.contact_ratios;
    let pass = stopped.is_none()
        && match expectation {
            // Bounces persist to the end of the run: still separating in the last 2 s, never settled.
            Fig5Expectation::KeepsBouncing => late_separations >= 2 && bounce.settle_time.is_none(),
            // W7: the first impact removes most of the energy, later impacts are slow, none at the end.
            Fig5Expectation::SettlesAtFirstImpact => {
                let after_second = bounce
                    .entry_speeds
                    .iter()
                    .skip(2)
                    .copied()
                    .fold(0.0, f64::max);
                // A box that never leaves the wall after its first impact has no completed contact and
                // so no ratio: that is the ideal outcome and counts as ratio 0.
                first_entry_speed > 0.0
                    && ratios.first().is_none_or(|r| *r <= 0.4)
                    && after_second < 0.15 * first_entry_speed
                    && late_separations == 0
            }
            // W6: the first three contacts lose energy, and the block stops leaving the wall soon.
            Fig5Expectation::SettlesSoon => {
                first_entry_speed > 0.0
                    && ratios.iter().take(3).all(|r| *r < 0.85)
                    && bounce.separations() <= 6
            }
        };
    Ok(Fig5Case {
        name,
        expectation,
        records,
        gap,
        stopped,
        metrics: Fig5Metrics {
            bounce,
            late_separations,
            first_entry_speed,
            max_later_entry_speed,
            late_max_speed,
            pass,
        },
    })
}

/// Runs every wall of [`FIG5_CASES`].
pub fn run(p: &Fig5Params) -> Result<Vec<Fig5Case>, String> {
    FIG5_CASES
        .iter()
        .map(|(name, normal, e)| run_case(p, name, normal, *e))
        .collect()
}

/// The claim's check for case `c`: its pass criterion (module docs) as a [`Check`] with the
/// numbers behind it, a safety stop named first.
pub fn check(c: &Fig5Case) -> Check {
    let m = &c.metrics;
    let b = &m.bounce;
    let v1 = m.first_entry_speed;
    let (id, detail) = match c.expectation {
        Fig5Expectation::KeepsBouncing => (
            "F5-bounce",
            format!(
                "{} separations in the last 2 s (≥ 2), settle time {} (none)",
                m.late_separations,
                b.settle_time.map_or("none".into(), |t| format!("{t:.2} s"))
            ),
        ),
        Fig5Expectation::SettlesAtFirstImpact => (
            "F6-pulse",
            format!(
                "first ratio {} (≤ 0.4); max entry after the 2nd impact {:.3} m/s (< 0.15·v1 = {:.3}); {} separations in the last 2 s (0)",
                b.contact_ratios.first().map_or("none".into(), |r| format!("{r:.3}")),
                b.entry_speeds.iter().skip(2).copied().fold(0.0, f64::max),
                0.15 * v1,
                m.late_separations
            ),
        ),
        Fig5Expectation::SettlesSoon => (
            "F6-hysteretic",
            format!(
                "first ratios [{}] (< 0.85); {} separations (≤ 6)",
                b.contact_ratios
                    .iter()
                    .take(3)
                    .map(|x| format!("{x:.3}"))
                    .collect::<Vec<_>>()
                    .join(", "),
                b.separations()
            ),
        ),
    };
    let detail = match &c.stopped {
        Some(why) => format!("safety stop: {why}; {detail}"),
        None => detail,
    };
    Check::new(id, m.pass, detail)
}
