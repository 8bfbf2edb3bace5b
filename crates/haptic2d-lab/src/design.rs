//! The design study of the released-stable controllers (issue 36, MODELS.md §11.4): for a candidate
//! controller, its **stability margin** from the analysis of [`crate::stability`] (held and released,
//! every built-in scene, 0.5, 1 and 2 kHz, with and without the one-sample output delay), its
//! **transparency** (quasi-static values of the linear loop: what a held hand feels in free motion
//! and at a wall), and the **claims** of Figs. 5–6 and 8–11 it reproduces (the device-in-the-loop
//! runs of [`crate::scenarios`], unchanged criteria). The study itself is
//! `tests/it/design_search.rs`.

use haptic2d::control::coupling::VirtualCoupling;
use haptic2d::device::linalg::V3;
use haptic2d::haptic::{ControllerKind, HapticConfig};
use haptic2d::scene::{Scene, BUILTIN};

use crate::scenarios::{peg_with_device, walls_with_device};
use crate::stability::loop_model::axis_controller;
use crate::stability::{AxisController, LoopModel, AXES, MIN_DECAY_RATE};

/// The rates of the study (Hz).
pub const RATES: [f64; 3] = [500.0, 1000.0, 2000.0];

/// The output delays of the study (extra samples): the lab's simulated device and a real device
/// whose write lands a tick late (what `run`'s gate assumes).
pub const DELAYS: [usize; 2] = [0, 1];

/// Handle start pose of the Figs. 8–11 runs (m, m, rad): left of the workspace centre.
pub const PEG_ORIGIN: V3 = [-0.03, 0.14, 0.0];

/// The scene configurations of the study: `(scene, mapping scale, device origin)`. Every built-in
/// scene at scale 1 from the workspace centre, and the peg also as Figs. 8–11 run it (scale 2, from
/// [`PEG_ORIGIN`]).
pub const SCENES: [(&str, f64, Option<V3>); 5] = [
    ("box-in-walls", 1.0, None),
    ("box-in-walls-tilt", 1.0, None),
    ("peg-in-hole", 1.0, Some(PEG_ORIGIN)),
    ("peg-in-hole", 2.0, Some(PEG_ORIGIN)),
    ("pile", 1.0, None),
];

/// One loop of the study: a scene configuration at a rate, its per-axis model (built once; the
/// controller is swapped per candidate) and its slave's generalized mass.
#[derive(Clone, Debug)]
pub struct StudyCase {
    /// `scene@scale`, e.g. `peg-in-hole@2`.
    pub label: String,
    /// Rate (Hz).
    pub rate: f64,
    /// The loop model (delay 0; the study sets it).
    pub model: LoopModel,
    /// The slave's `(M, M, I)` (kg, kg, kg·m²), for the §6.4 minimum-mass check.
    pub slave_mass: V3,
}

/// Every loop of the study ([`SCENES`] × [`RATES`]).
pub fn study_cases() -> Result<Vec<StudyCase>, String> {
    let mut out = Vec::new();
    for (scene, scale, origin) in SCENES {
        let text = BUILTIN
            .iter()
            .find(|b| b.0 == scene)
            .ok_or_else(|| format!("built-in scene {scene} missing"))?
            .2;
        for rate in RATES {
            let world = Scene::from_toml(text, scene, Some(rate))
                .map_err(|e| e.to_string())?
                .world;
            let cfg = HapticConfig {
                scale,
                device_origin: origin,
                ..HapticConfig::default()
            };
            let model = LoopModel::new(&cfg, &world, rate, 0)?;
            let slave = world
                .bodies
                .iter()
                .find(|b| b.is_dynamic())
                .ok_or("no dynamic body")?;
            out.push(StudyCase {
                label: format!("{scene}@{scale}"),
                rate,
                model,
                slave_mass: [slave.mass, slave.mass, slave.inertia],
            });
        }
    }
    Ok(out)
}

/// The stability of a candidate over every case of [`study_cases`] and every delay of [`DELAYS`].
#[derive(Clone, Debug, PartialEq)]
pub struct Margin {
    /// Slowest decay with the hand held, `min(−growth)` (1/s); ≥ [`MIN_DECAY_RATE`] is "with margin".
    pub held: f64,
    /// Slowest decay with the hand released (1/s).
    pub released: f64,
    /// Slowest decay per axis x, y, θ, held or released (1/s).
    pub axis: [f64; 3],
    /// Where the slowest decay (held or released) is: `scene@scale rate Hz delay d axis a held|released`.
    pub worst: String,
    /// The cases where the slave is lighter than 1.5 × the §6.4 minimum mass of the controller's
    /// slave coupling (the haptic system refuses to start there), e.g. `peg-in-hole@1 500 Hz theta`.
    pub min_mass_refusals: Vec<String>,
}

impl Margin {
    /// The smaller of the held and released decay rates (1/s).
    pub fn decay(&self) -> f64 {
        self.held.min(self.released)
    }

    /// Stable with margin everywhere (held and released decay ≥ [`MIN_DECAY_RATE`], i.e. the
    /// `stability` verdict "stable" on every axis of every case) and accepted by every case's
    /// minimum-mass check.
    pub fn stable_with_margin(&self) -> bool {
        self.decay() >= MIN_DECAY_RATE && self.min_mass_refusals.is_empty()
    }
}

/// The stability margin of `kind` over `cases` (see [`Margin`]).
pub fn margin(kind: &ControllerKind, cases: &[StudyCase]) -> Result<Margin, String> {
    let ctrl: [AxisController; 3] = std::array::from_fn(|i| axis_controller(kind, i));
    let (mut held, mut released) = (f64::INFINITY, f64::INFINITY);
    let mut worst = String::new();
    let mut worst_decay = f64::INFINITY;
    let mut axis = [f64::INFINITY; 3];
    let mut refusals = Vec::new();
    for c in cases {
        let dt = 1.0 / c.rate;
        let check = match kind {
            ControllerKind::FourChannel(g) => g.check_slave_mass(&c.slave_mass, dt),
            ControllerKind::Coupling(g) => {
                VirtualCoupling::new(*g).and_then(|v| v.check_slave_mass(&c.slave_mass, dt))
            }
        };
        if let Err(e) = check {
            let axis = AXES
                .iter()
                .find(|a| e.contains(&format!("slave {a} mass")))
                .unwrap_or(&"?");
            refusals.push(format!("{} {} Hz {axis}", c.label, c.rate));
        }
        for delay in DELAYS {
            let mut m = c.model.clone();
            m.delay = delay;
            for (_, axes) in m.cases.iter_mut() {
                for (i, a) in axes.iter_mut().enumerate() {
                    a.ctrl = ctrl[i];
                }
            }
            m.axes = m.cases[0].1;
            for (i, r) in m.analyse()?.into_iter().enumerate() {
                axis[i] = axis[i].min(-r.held.growth.max(r.released.growth));
                for (cond, g, acc) in [
                    ("held", r.held.growth, &mut held),
                    ("released", r.released.growth, &mut released),
                ] {
                    let d = -g;
                    *acc = acc.min(d);
                    if d < worst_decay {
                        worst_decay = d;
                        worst = format!(
                            "{} {} Hz delay {delay} axis {} {cond} ({})",
                            c.label, c.rate, r.axis, r.contact
                        );
                    }
                }
            }
        }
    }
    Ok(Margin {
        held,
        released,
        axis,
        worst,
        min_mass_refusals: refusals,
    })
}

/// What a held hand feels on the x axis, quasi-statically (low frequency, the hand-force estimate
/// equal to the hand force), from the linear loop of [`AxisController`] with the §10.2 device's
/// handle inertia `m` and damping `b` (world units).
///
/// - free motion at constant velocity: master `0 = k_m·e + (1 + g_mh)·f_h − (d_m + b)·v`, slave
///   `0 = −k_s·e + g_sh·f_h − d_s·v`, so the drag `f_h/v = (d_m + b + k_m·d_s/k_s) / (1 + g_mh +
///   k_m·g_sh/k_s)`;
/// - free motion under constant acceleration from rest: `m·a = k_m·e + (1 + g_mh)·f_h`,
///   `M_s·a = −k_s·e + g_sh·f_h`, so the felt mass `f_h/a = (m + k_m·M_s/k_s) / (1 + g_mh +
///   k_m·g_sh/k_s)`;
/// - static push on a wall `f_e = K_e·x_s`: `0 = k_m·e + (1 + g_mh)·f_h + g_me·f_e`,
///   `0 = −k_s·e + g_sh·f_h + (g_se − 1)·f_e`; the felt stiffness is `f_h/x_m`.
///
/// The virtual coupling has its own form (`f_cs = −f_cm`, no force channels) and gives `b`, `m +
/// M_s` and the series stiffness `K_e·K_vc/(K_e + K_vc)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transparency {
    /// Free-motion drag (N·s/m).
    pub drag: f64,
    /// Free-motion felt mass (kg).
    pub mass: f64,
    /// Felt wall stiffness (N/m).
    pub wall: f64,
    /// The wall's stiffness `K_e` (N/m), the ideal of `wall`.
    pub wall_ideal: f64,
    /// The slave's mass `M_s` (kg), what an ideal transparent loop would make the hand feel beyond
    /// the device.
    pub slave_mass: f64,
}

/// Quasi-static transparency of `kind` on the x axis of `m` (device inertia and damping, slave
/// mass, wall stiffness), see [`Transparency`].
pub fn transparency(kind: &ControllerKind, m: &crate::stability::AxisModel) -> Transparency {
    let (dm, b, ms, ke) = (m.m, m.b, m.m_s, m.k_e);
    match kind {
        ControllerKind::Coupling(g) => Transparency {
            drag: b,
            mass: dm + ms,
            wall: ke * g.k[0] / (ke + g.k[0]),
            wall_ideal: ke,
            slave_mass: ms,
        },
        ControllerKind::FourChannel(_) => {
            let c = axis_controller(kind, 0);
            let den = 1.0 + c.g_mh + c.k_m * c.g_sh / c.k_s;
            let drag = (c.d_m + b + c.k_m * c.d_s / c.k_s) / den;
            let mass = (dm + c.k_m * ms / c.k_s) / den;
            // Static wall: unknowns (x_m, x_s) for f_h = 1.
            // master: −k_m·x_m + (k_m + g_me·K_e)·x_s = −(1 + g_mh)
            // slave:   k_s·x_m + (−k_s + (g_se − 1)·K_e)·x_s = −g_sh
            let (a11, a12, r1) = (-c.k_m, c.k_m + c.g_me * ke, -(1.0 + c.g_mh));
            let (a21, a22, r2) = (c.k_s, -c.k_s + (c.g_se - 1.0) * ke, -c.g_sh);
            let det = a11 * a22 - a12 * a21;
            let x_m = (r1 * a22 - a12 * r2) / det;
            Transparency {
                drag,
                mass,
                wall: 1.0 / x_m,
                wall_ideal: ke,
                slave_mass: ms,
            }
        }
    }
}

/// One claim's outcome.
#[derive(Clone, Debug, PartialEq)]
pub struct ClaimOutcome {
    /// `fig5/seh`, …, `fig8/salcudean-vlaar`.
    pub claim: String,
    /// Whether the claim's criterion passes (Figs. 8–11: and no safety stop).
    pub pass: bool,
    /// The measured numbers behind it.
    pub detail: String,
}

/// Runs the 4 walls of Figs. 5–6 and the 5 friction models of Figs. 8–11 with `kind` (every other
/// setting of [`walls_with_device::Fig5Params::default`] and [`peg_with_device::Fig8Params::default`]).
pub fn claims(kind: &ControllerKind) -> Result<Vec<ClaimOutcome>, String> {
    let haptic = HapticConfig {
        controller: *kind,
        ..HapticConfig::default()
    };
    let mut out = fig5_claims(&walls_with_device::Fig5Params {
        haptic: haptic.clone(),
        ..walls_with_device::Fig5Params::default()
    });
    out.extend(fig8_claims(&peg_with_device::Fig8Params {
        haptic,
        ..peg_with_device::Fig8Params::default()
    }));
    Ok(out)
}

/// The 4 walls of Figs. 5–6 with the settings `p5` (a run that fails counts as not passing).
pub fn fig5_claims(p5: &walls_with_device::Fig5Params) -> Vec<ClaimOutcome> {
    walls_with_device::FIG5_CASES
        .iter()
        .map(
            |(name, normal, e)| match walls_with_device::run_case(p5, name, normal, *e) {
                Ok(c) => ClaimOutcome {
                    claim: format!("fig5/{name}"),
                    pass: c.metrics.pass,
                    detail: walls_with_device::check(&c).detail,
                },
                Err(e) => ClaimOutcome {
                    claim: format!("fig5/{name}"),
                    pass: false,
                    detail: e,
                },
            },
        )
        .collect()
}

/// The 5 friction models of Figs. 8–11 with the settings `p8` (rate, mapping scale, protocol,
/// device and controller); a run that fails or stops counts as not passing.
pub fn fig8_claims(p8: &peg_with_device::Fig8Params) -> Vec<ClaimOutcome> {
    peg_with_device::FIG8_CASES
        .iter()
        .map(
            |(name, model, drift)| match peg_with_device::run_case(p8, name, model, *drift) {
                Ok(c) => {
                    let min_adv = c
                        .metrics
                        .advance
                        .iter()
                        .copied()
                        .fold(f64::INFINITY, f64::min);
                    let creep = if *drift {
                        c.metrics
                            .creep
                            .iter()
                            .copied()
                            .fold(f64::INFINITY, f64::min)
                    } else {
                        c.metrics.creep.iter().map(|x| x.abs()).fold(0.0, f64::max)
                    };
                    ClaimOutcome {
                        claim: format!("fig8/{name}"),
                        pass: c.metrics.pass && c.stopped.is_none(),
                        detail: format!(
                            "min advance {:.2} mm, {} creep {:.3} mm{}",
                            min_adv * 1e3,
                            if *drift { "min" } else { "max |.|" },
                            creep * 1e3,
                            c.stopped
                                .map_or(String::new(), |s| format!(", stopped: {s}"))
                        ),
                    }
                }
                Err(e) => ClaimOutcome {
                    claim: format!("fig8/{name}"),
                    pass: false,
                    detail: e,
                },
            },
        )
        .collect()
}

/// `haptic2d stability`'s verdict for `config` around `world` at `rate` (Hz), for the simulated
/// device (no output delay) and for a real one (one sample of delay, what `run`'s gate assumes):
/// per delay the worst axis, its verdict and its slowest decay (or growth) rate.
pub fn verdict_line(config: &HapticConfig, world: &haptic2d::world::World, rate: f64) -> String {
    let mut parts = Vec::new();
    for (delay, who) in [(0, "simulated device"), (1, "real device (+1 sample)")] {
        let text = match crate::stability::analyse_config(config, world, rate, delay, "case") {
            Ok(r) => {
                let worst = r
                    .axes
                    .iter()
                    .max_by(|a, b| {
                        a.held
                            .growth
                            .max(a.released.growth)
                            .total_cmp(&b.held.growth.max(b.released.growth))
                    })
                    .map(|a| {
                        let g = a.held.growth.max(a.released.growth);
                        format!(
                            "{} (axis {}, {} {:.1} 1/s)",
                            a.verdict().label(),
                            a.axis,
                            if g >= 0.0 { "growth" } else { "decay" },
                            g.abs()
                        )
                    })
                    .unwrap_or_default();
                worst
            }
            Err(e) => format!("not analysed: {e}"),
        };
        parts.push(format!("{who}: {text}"));
    }
    parts.join("; ")
}
