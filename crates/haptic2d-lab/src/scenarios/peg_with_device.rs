//! Figs. 8–11 of the paper with the device in the loop: the peg in a tight hole, one friction model per
//! case.
//!
//! "Initially, the user pushes the peg into the hole. When the user releases the handle, the hand force
//! is replaced by the sinusoidal unidirectional force." Here: the peg-in-hole scene (0.2 kg peg, 1 mm
//! interference per wall, the scene's pure SEH stiffness `Kc = 1000 N/m` per corner, `Bc = 0`) with its
//! friction replaced by each model (per-contact defaults), the simulated twin pantograph at 1 kHz and,
//! by default, the four-channel controller with local force feedback (below; the virtual coupling
//! of §11.2 is a comparison run). The peg starts inside the hole (the push-in is
//! optional, [`Fig8Params::push_in`]); the hand grips the handle until `t_release`, then lets go and
//! the push `F_pk·(1 − cos 2πft)/2` along +x acts on the handle (the phase is measured from t = 0, so
//! it starts from zero at a whole number of periods); y and θ of the handle are then free.
//!
//! **Which runs carry the claims (issue 36).** The default controller
//! (`FourChannelGains::local_force_feedback`: `C6 = −1`, slave-side local force feedback `C5 = 2`,
//! master damping injection 1 N·s/m) — [`Fig8Params::default`]. Comparison runs: the virtual
//! coupling ([`Fig8Params::coupling`](crate::scenarios::ControllerRuns::coupling)) and the §11.1 table ([`Fig8Params::paper_controller`](crate::scenarios::ControllerRuns::paper_controller)).
//!
//! **The mechanism.** After the release nothing holds the handle: with the §11.1 table (`C2 = 1`) the
//! released loop of handle, peg and the squeezed corner springs is unstable in continuous time — for
//! the y axis at scale 2 (handle inertia divided by 4, peg 0.2 kg, 4 × 1000 N/m) the §11.4
//! polynomial has roots `+30 ± 185j` (the 30 Hz rattle; the runs end in safety stops). With
//! `C6 = −1` the environment force does not reach the handle and every axis decays with the hand
//! held or released (`haptic2d stability peg-in-hole --scale 2`). With `C5 = 0` (the former default)
//! the push reaches the peg through the hand-force estimate (`C3 = 1`) while the handle follows
//! through the PD, so each slip is braked by the handle's inertia and the coupling's dampers
//! (advance 0.2–5 mm per cycle, F7-3 fails; no classical drift, F7-1 fails). The slave-side local
//! force feedback `C5 = 2` drives the peg with `3·f_h − 2·f_e`: the push reaches it amplified and
//! the contact force is fed back at the slave only, so the peg slips its 5 mm and more while the
//! released handle still sees no contact force. The virtual coupling meets every claim too: it sends
//! no force channel to the device and drives the peg with the spring `K_vc` alone.
//!
//! Metrics as §13.2, on the peg's x, for the cycles after the release: `creep_k = x(k + 0.2) −
//! x(k − 0.1)` (the push is ≤ 0.73 N: any motion is drift or elastic presliding) and `advance_k =
//! x(k + 0.9) − x(k − 0.1)`. Pass criteria ([`Fig8Metrics::pass`]): the run ends without a safety stop,
//! every `advance_k > 5e-3 m` (F7-3, slips happen), and classical: `min creep_k ≥ 5e-4 m` (F7-1,
//! drift); the others: `max |creep_k| ≤ 2e-4 m` (F7-2, stick). The periodicity part of F7-2 (cycle-to-
//! cycle differences < 1e-5 m) is not required: the device's joint friction, encoder quantisation and
//! coupling make the staircase vary by about 1e-3 m per cycle.

use haptic2d::device::HandModel;
use haptic2d::laws::friction::FrictionModel;
use haptic2d::scene::Scene;

use haptic2d::haptic::config::HapticConfig;
use haptic2d::haptic::experiment::DeviceInTheLoop;
use haptic2d::haptic::record::TickRecord;
use haptic2d::haptic::system::HapticSystem;

/// Settings of the Figs. 8–11 experiment.
#[derive(Clone, Debug, PartialEq)]
pub struct Fig8Params {
    /// Control rate (Hz). Default 1000 (the paper ran at 500 Hz): at 500 Hz the peg's 3.3e-5 kg·m²
    /// is below 1.5× the minimum mass of the §11.1 table's rotational gains (§6.4; the default's θ
    /// gains accept it), and the classical model's creep turns negative with the coupling.
    pub rate: f64,
    /// Start of the optional push-in (s). Default 0.7.
    pub t_hold: f64,
    /// Hand push along +x during the optional push-in (world N). Default 2.2.
    pub push: f64,
    /// Release time (s); a whole number of sine periods. Default 1.
    pub t_release: f64,
    /// Peak of the unidirectional sinusoid `F_pk` in the world (N). Default 2.1 (§13.2's main value).
    pub peak: f64,
    /// Frequency of the sinusoid (Hz). Default 1.
    pub frequency: f64,
    /// Number of cycles measured after the release. Default 4.
    pub cycles: usize,
    /// Handle x at the start (m), left of the workspace centre so the peg can advance. Default −0.03.
    pub start_x: f64,
    /// Translation scale world/device of the mapping (§ [`DeviceMap`](haptic2d::haptic::DeviceMap)). Default 2,
    /// so four slips fit in the device's reach. The mapping preserves power, so a world force `F`
    /// needs `scale·F` at the handle; the forces above are world forces and the hand applies them times
    /// `scale`.
    pub scale: f64,
    /// Haptic-system settings. Default: the defaults (four-channel, released-stable gains).
    pub haptic: HapticConfig,
    /// Push the peg with `push` (y and θ still gripped) between `t_hold` and `t_release`. Default
    /// false: the peg starts inside the hole. A constant push above the 2 N stiction makes the peg
    /// accelerate for the whole push (1.2 m/s and 0.16 m after 0.3 s at 2.2 N).
    pub push_in: bool,
    /// Keep the hand's y/θ grip after the release (the sinusoid then acts along x only, through a
    /// 1 N/m spring whose anchor is moved every tick). Default false: the paper's user releases the
    /// handle.
    pub guide_y_theta: bool,
    /// Where the sinusoid acts after the release: on the handle (default) or in the hand-force
    /// estimate (the handle is then released with nothing pushing it).
    pub protocol: super::Protocol,
}

impl Default for Fig8Params {
    fn default() -> Self {
        Self {
            rate: 1000.0,
            t_hold: 0.7,
            push: 2.2,
            t_release: 1.0,
            peak: 2.1,
            frequency: 1.0,
            cycles: 4,
            start_x: -0.03,
            scale: 2.0,
            haptic: HapticConfig::default(),
            push_in: false,
            guide_y_theta: false,
            protocol: super::Protocol::HandleForce,
        }
    }
}

impl Fig8Params {
    /// The defaults (the four-channel controller with its released-stable default gains).
    pub fn four_channel() -> Self {
        Self::default()
    }
}

impl super::ControllerRuns for Fig8Params {
    fn haptic_mut(&mut self) -> &mut HapticConfig {
        &mut self.haptic
    }
}

/// The friction models of Figs. 8–11 (plus Salcudean–Vlaar): `(case name, model name, drifts?)`.
pub const FIG8_CASES: [(&str, &str, bool); 5] = [
    ("classical", "classical", true),
    ("reset-integrator", "reset-integrator", false),
    ("dahl", "hayward-armstrong", false),
    ("nahvi", "nahvi", false),
    ("salcudean-vlaar", "salcudean-vlaar", false),
];

/// Metrics of one friction model.
#[derive(Clone, Debug, PartialEq)]
pub struct Fig8Metrics {
    /// `creep_k` for each measured cycle (m).
    pub creep: Vec<f64>,
    /// `advance_k` for each measured cycle but the last (m).
    pub advance: Vec<f64>,
    /// Whether the model is expected to drift (classical).
    pub expect_drift: bool,
    /// Largest `|y|` of the peg after the release (m): the rattle across the channel.
    pub max_abs_y: f64,
    /// Largest `|θ|` of the peg after the release (rad).
    pub max_abs_theta: f64,
    /// Largest handle travel along x from its start (m).
    pub device_travel: f64,
    /// No safety stop; classical: `min creep ≥ 5e-4 m` (drift, F7-1); others: `max creep ≤ 2e-4 m`
    /// (stick, F7-2, on `|creep|`: a peg rattling backwards does not stick); all: every `advance > 5e-3 m` (slips happen, F7-3).
    pub pass: bool,
}

/// One friction model's run.
#[derive(Clone, Debug, PartialEq)]
pub struct Fig8Case {
    /// Case name.
    pub name: &'static str,
    /// Every tick's record.
    pub records: Vec<TickRecord>,
    /// The push applied by the hand, in world terms, per tick (N).
    pub push: Vec<f64>,
    /// Metrics.
    pub metrics: Fig8Metrics,
    /// The safety stop that ended the run early, if any (then `metrics.pass` is false).
    pub stopped: Option<String>,
}

fn peg_toml(friction: &str) -> Result<String, String> {
    FrictionModel::from_name(friction, true)?;
    super::builtin_with_table(
        "peg-in-hole",
        "[friction]",
        "[[body]]",
        &format!("[friction]\nmodel = \"{friction}\"\n\n"),
    )
}

/// The peg-in-hole world with friction model `friction` at `rate` (Hz), and the haptic settings a
/// run of `p` uses (its start pose and mapping scale): what the stability analysis of a Figs. 8–11
/// case is run against.
pub fn case_world(
    p: &Fig8Params,
    friction: &str,
) -> Result<(haptic2d::world::World, HapticConfig), String> {
    let world = Scene::from_toml(&peg_toml(friction)?, "fig8", Some(p.rate))
        .map_err(|e| e.to_string())?
        .world;
    let mut cfg = p.haptic.clone();
    cfg.device_origin = Some([p.start_x, cfg.device.workspace_center_y, 0.0]);
    cfg.scale = p.scale;
    Ok((world, cfg))
}

/// Runs one friction model (`friction` = a model name of [`FrictionModel::NAMES`]).
pub fn run_case(
    p: &Fig8Params,
    name: &'static str,
    friction: &str,
    expect_drift: bool,
) -> Result<Fig8Case, String> {
    let (world, cfg) = case_world(p, friction)?;
    let system = HapticSystem::new(world, &cfg)?;
    let s = p.scale;
    let mut l = DeviceInTheLoop::new(system, HandModel::Free, 10, true)?;
    let start = l.plant.pose();
    let (hold, stiffness, damping) = super::hold_at(start)?;
    // The push in: a 1 N/m spring stretched by s·F metres (constant to ±1 % over the travel), y and θ
    // still gripped.
    let pushing = HandModel::SpringDamper {
        target: [start[0] + s * p.push, start[1], start[2]],
        stiffness: [1.0, stiffness[1], stiffness[2]],
        damping: [0.0, damping[1], damping[2]],
    };
    let sine = HandModel::Sinusoid {
        direction: [1.0, 0.0, 0.0],
        peak: s * p.peak,
        frequency: p.frequency,
    };
    let dt = l.system.dt();
    let t_end = p.t_release + p.cycles as f64 / p.frequency + 0.3;
    let n = (t_end / dt).round() as usize;
    let (n_hold, n_release) = (
        (p.t_hold / dt).round() as usize,
        (p.t_release / dt).round() as usize,
    );
    l.hand = hold;
    let mut records = Vec::with_capacity(n);
    let mut push = Vec::with_capacity(n);
    let mut stopped = None;
    for k in 0..n {
        let t = k as f64 * dt;
        if k == n_hold && p.push_in {
            l.hand = pushing;
        }
        let mut f_world = if p.push_in && k >= n_hold {
            p.push
        } else {
            0.0
        };
        if k >= n_release {
            let x = l.plant.pose();
            let f = sine.wrench(&x, &[0.0; 3], t)[0];
            f_world = f / s;
            let inject = p.protocol == super::Protocol::EstimateInjection;
            if inject {
                l.system.set_hand_estimate_injection([f, 0.0, 0.0]);
            }
            let f = if inject { 0.0 } else { f };
            l.hand = if p.guide_y_theta {
                // The x push as a 1 N/m spring stretched by f metres from the current pose: f to within
                // 1 N/m × the travel in one tick; y and θ keep the grip.
                HandModel::SpringDamper {
                    target: [x[0] + f, start[1], start[2]],
                    stiffness: [1.0, stiffness[1], stiffness[2]],
                    damping: [0.0, damping[1], damping[2]],
                }
            } else if inject {
                HandModel::Free
            } else {
                sine
            };
        }
        let out = l
            .step()
            .map_err(|e| format!("fig8 {name}: simulated device failed: {e}"))?;
        if let Some(d) = l.system.world().divergence() {
            return Err(format!("fig8 {name}: the world diverged: {d}"));
        }
        records.push(out.record);
        push.push(f_world);
        if out.tripped {
            stopped = l.system.safety_trip().map(|t| t.to_string());
            break;
        }
    }
    // Windows past the end of a stopped run read its last sample (and `pass` is false).
    let x_at = |t: f64| records[((t / dt).round() as usize).min(records.len() - 1)].x_s[0];
    let period = 1.0 / p.frequency;
    let (mut creep, mut advance) = (Vec::new(), Vec::new());
    for c in 1..=p.cycles {
        let tk = p.t_release + c as f64 * period;
        creep.push(x_at(tk + 0.2 * period) - x_at(tk - 0.1 * period));
        if c < p.cycles {
            advance.push(x_at(tk + 0.9 * period) - x_at(tk - 0.1 * period));
        }
    }
    let after = || records.iter().filter(|r| r.t >= p.t_release);
    let max_abs_y = after().map(|r| r.x_s[1].abs()).fold(0.0, f64::max);
    let max_abs_theta = after().map(|r| r.x_s[2].abs()).fold(0.0, f64::max);
    let device_travel = records
        .iter()
        .map(|r| (r.x_m[0] - start[0]).abs())
        .fold(0.0, f64::max);
    let slips = advance.iter().all(|a| *a > 5e-3);
    let pass = stopped.is_none()
        && slips
        && if expect_drift {
            creep.iter().copied().fold(f64::INFINITY, f64::min) >= 5e-4
        } else {
            creep.iter().map(|c| c.abs()).fold(0.0, f64::max) <= 2e-4
        };
    Ok(Fig8Case {
        name,
        records,
        push,
        metrics: Fig8Metrics {
            creep,
            advance,
            expect_drift,
            max_abs_y,
            max_abs_theta,
            device_travel,
            pass,
        },
        stopped,
    })
}

/// Runs every friction model of [`FIG8_CASES`].
pub fn run(p: &Fig8Params) -> Result<Vec<Fig8Case>, String> {
    FIG8_CASES
        .iter()
        .map(|(name, model, drift)| run_case(p, name, model, *drift))
        .collect()
}
