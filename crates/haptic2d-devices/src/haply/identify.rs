//! System identification of a 2-DOF five-bar (a Haply 2DIY) from small torque pulses on each joint:
//! the joint-space inertia and viscous damping at the rest pose, the lumped model the stability gate
//! uses (joint inertia `I_j`, end-point mass `m_e`, joint damping `b`; `haptic2d_lab`'s
//! `FiveBarDynamics`, the emulator's [`Plant2`](super::Plant2)), and the signs that reveal a motor
//! or encoder wired the other way (`haptic2d device identify`).
//!
//! **Excitation** ([`PulsePlan`]). With the handle still at the rest pose, each joint `j` in turn
//! gets a sine doublet, the other joint zero torque:
//!
//! ```text
//! τ_j(t) = +A·sin(π t/T)      0 ≤ t < T
//!          −A·sin(π (t−T)/T)  T ≤ t < 2T,      then 0 for the tail
//! ```
//!
//! It starts at zero and ramps in smoothly, never exceeds `A` (≤ the device file's torque limit,
//! and the driver clamps anyway), and a free, undamped joint ends it where it started, at rest: the
//! handle moves `A·T²/(π·M)` at most and comes back. The end point's distance from the rest pose is
//! watched every tick: beyond [`PulsePlan::max_excursion`] the torques are zeroed and the pulse
//! fails ([`IdentifyError::Excursion`]).
//!
//! **Model.** In the reported (encoder) angles `q` and commanded torques `τ`, for small, slow motion
//! (the centripetal terms are quadratic in `q̇` and left out; the hand released):
//!
//! ```text
//! M'·q̈ + B'·q̇ = τ        M' = D_m·M·D_e,  B' = D_m·B·D_e
//! ```
//!
//! with `M` (kg·m²) and `B` (N·m·s/rad) the true symmetric joint-space inertia and damping, and
//! `D_m`, `D_e` diagonal ±1: the motor and encoder directions (+1 where the device file is right).
//! `M'` and `B'` are fitted as general 2×2 matrices, so a wrong direction cannot bend the fit.
//!
//! **Estimation** ([`estimate`]): the equation integrated twice from the pulse's first sample `t₀`
//! (no differentiation of the quantised angles: integration averages the one-count noise instead of
//! amplifying it):
//!
//! ```text
//! M'·(q(t) − q(t₀)) + B'·∫(q − q(t₀)) − p·(t − t₀) − c = ∫∫τ
//! ```
//!
//! `p = M'·q̇(t₀)` (a handle not quite still) and `c` (the start sample's quantisation) are unknowns
//! per pulse and row; `∫τ` is exact (the board holds each torque until the next write), `∫(q − q₀)`
//! and `∫∫τ` are trapezoids over the sample times. Linear least squares over every sample of every
//! pulse (Householder QR on unit-norm columns), `8 + 4·pulses` unknowns.
//!
//! **A third pulse** ([`heavy_direction`]): near a 2DIY's folded rest pose `M` is nearly singular
//! (eigenvalues ~8× apart), the joint pulses hardly move the heavy direction and its inertia is
//! poorly seen (one joint came out 12 % off). A third doublet along the first estimate's heavy
//! eigenvector, sized to move the end point a few mm, fixes that; the final fit uses all three.
//!
//! **Directions.** The response `A' = M'⁻¹ = D_e·M⁻¹·D_m`: `sign A'_jj = e_j·m_j` (the sign of joint
//! `j`'s acceleration under its own torque) and `sign A'_kj = e_k·m_j·sign (M⁻¹)_kj`, where
//! `sign (M⁻¹)_kj = −sign (JᵀJ)_kj` (the end mass's coupling; the rotor inertia is diagonal). These
//! are the three signs `device check --pulse` diagnoses; [`Identification::response_displacement`]
//! gives them as the displacements the fitted model predicts at the end of each pulse's first half.
//!
//! **Lumped model** ([`lumped`]): `M = I_j·1 + m_e·JᵀJ(q_rest)` fitted to the three entries of the
//! symmetric part of `M'` (both ≥ 0), `b` the mean of `B`'s diagonal.

use std::time::{Duration, Instant};

use haptic2d::device::pantograph2::Pantograph2;
use haptic2d_rt::{DeviceError, DeviceIo};

/// One sample of a pulse: the board's angles when it serviced a write, and the torque that write
/// asked for (held until the next write).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// Time of the write (s, from the pulse's start).
    pub t: f64,
    /// Joint angles at that write (rad, joint order).
    pub q: [f64; 2],
    /// Joint torques written (N·m), held from `t` to the next sample.
    pub tau: [f64; 2],
}

/// How the pulses are applied.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PulsePlan {
    /// Doublet amplitude `A` (N·m).
    pub amplitude: f64,
    /// Half-period `T` of the doublet (s).
    pub half_period: f64,
    /// Zero-torque tail after the doublet, part of the fit (s).
    pub tail: f64,
    /// Stillness check before the first pulse, and pause between pulses (s).
    pub settle: f64,
    /// Largest end-point distance from the rest pose allowed during the pulses (m).
    pub max_excursion: f64,
    /// Control period (s).
    pub period: f64,
    /// Where sample times come from.
    pub timebase: Timebase,
}

impl Default for PulsePlan {
    /// 1.5 mN·m over 2 × 100 ms: a few mm of end-point motion on a 2DIY at its rest pose (a few dozen
    /// encoder counts), 1 kHz, wall clock, at most 15 mm from the rest pose.
    fn default() -> Self {
        Self {
            amplitude: 0.0015,
            half_period: 0.1,
            tail: 0.1,
            settle: 0.15,
            max_excursion: 0.015,
            period: 0.001,
            timebase: Timebase::Wall,
        }
    }
}

/// Where a sample's time comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Timebase {
    /// The host's monotonic clock at each write, paced at the period (a real board: its motors
    /// hold each torque in wall time).
    Wall,
    /// `k·period` for the `k`-th write, unpaced: an emulator that steps its linkage one period per
    /// write (`EmulatorClock::PerWrite`).
    Writes,
}

/// Why the identification stopped (the torques are zero when it returns).
#[derive(Debug)]
pub enum IdentifyError {
    /// The handle moved before any torque: not held still (or not released still) at the rest pose.
    NotStill(String),
    /// The handle went further from the rest pose than allowed.
    Excursion(String),
    /// The device failed.
    Device(DeviceError),
    /// The data do not determine the model.
    Fit(String),
}

impl std::fmt::Display for IdentifyError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            IdentifyError::NotStill(m) | IdentifyError::Excursion(m) | IdentifyError::Fit(m) => {
                f.write_str(m)
            }
            IdentifyError::Device(e) => write!(f, "{e}"),
        }
    }
}

impl From<DeviceError> for IdentifyError {
    fn from(e: DeviceError) -> Self {
        IdentifyError::Device(e)
    }
}

/// The doublet's torque at time `t` (s) from the pulse start: amplitude `a` (N·m), half-period
/// `half` (s); zero outside `[0, 2·half)`.
pub fn doublet(t: f64, a: f64, half: f64) -> f64 {
    if !(0.0..2.0 * half).contains(&t) {
        return 0.0;
    }
    let s = (std::f64::consts::PI * (t % half) / half).sin();
    if t < half {
        a * s
    } else {
        -a * s
    }
}

/// Applies one doublet per torque direction `dirs` (N·m per unit of the doublet's shape: joint
/// `j` alone is `[A, 0]` or `[0, A]`) to joints 0 and 1 of `dev` (a 2-DOF device at its rest pose,
/// opened and checked), returning the samples of each pulse. With `check_still`, the handle must not
/// move at zero torque before the first pulse ([`IdentifyError::NotStill`]). `linkage` and `rest`
/// (joint angles at the rest pose, rad) bound the end point's excursion. Zero torques are written on
/// every exit.
pub fn record_pulses<D: DeviceIo + ?Sized>(
    dev: &mut D,
    linkage: &Pantograph2,
    rest: [f64; 2],
    counts_per_turn: [f64; 2],
    dirs: &[[f64; 2]],
    check_still: bool,
    plan: &PulsePlan,
) -> Result<Vec<Vec<Sample>>, IdentifyError> {
    let out = record_inner(dev, linkage, rest, counts_per_turn, dirs, check_still, plan);
    dev.zero_torques();
    out
}

/// The joint pulses: `[A, 0]` then `[0, A]` with the plan's amplitude `A`.
pub fn joint_directions(plan: &PulsePlan) -> [[f64; 2]; 2] {
    [[plan.amplitude, 0.0], [0.0, plan.amplitude]]
}

/// The third pulse, along the heavy eigen-direction of a first estimate's symmetric inertia: a
/// five-bar near its folded rest pose moves ~8× less in that direction under the joint pulses, so
/// its inertia there is poorly seen. Its amplitude (N·m) is the one the first estimate predicts to
/// move the end point a sixth of [`PulsePlan::max_excursion`] by the end of the doublet's first half
/// (`|J·M⁻¹·u|·T²/π`, `j` the Jacobian at the rest pose, `Ė = J·q̇`), at least the plan's amplitude
/// and at most `cap` (N·m). `None` when the estimate is not positive definite.
pub fn heavy_direction(
    first: &Identification,
    plan: &PulsePlan,
    cap: f64,
    j: &[[f64; 2]; 2],
) -> Option<[f64; 2]> {
    let (m, _) = first.symmetric();
    let tr = m[0][0] + m[1][1];
    let det = m[0][0] * m[1][1] - m[0][1] * m[0][1];
    if !(det > 0.0 && tr > 0.0) {
        return None;
    }
    let disc = (0.25 * tr * tr - det).max(0.0).sqrt();
    let heavy = 0.5 * tr + disc;
    // Eigenvector of `heavy`: (M01, heavy − M00) or (heavy − M11, M01), the better conditioned.
    let v = if (heavy - m[0][0]).abs() > (heavy - m[1][1]).abs() {
        [m[0][1], heavy - m[0][0]]
    } else {
        [heavy - m[1][1], m[0][1]]
    };
    let n = (v[0] * v[0] + v[1] * v[1]).sqrt();
    if !(n.is_finite() && n > 0.0) {
        return None;
    }
    let u = [v[0] / n, v[1] / n];
    let minv = inv2(&m)?;
    let s = plan.half_period * plan.half_period / std::f64::consts::PI;
    let dq = [
        s * (minv[0][0] * u[0] + minv[0][1] * u[1]),
        s * (minv[1][0] * u[0] + minv[1][1] * u[1]),
    ];
    let de = [
        j[0][0] * dq[0] + j[0][1] * dq[1],
        j[1][0] * dq[0] + j[1][1] * dq[1],
    ];
    let per_newton_metre = (de[0] * de[0] + de[1] * de[1]).sqrt();
    if !(per_newton_metre.is_finite() && per_newton_metre > 0.0) {
        return None;
    }
    let a = (plan.max_excursion / 6.0 / per_newton_metre)
        .max(plan.amplitude)
        .min(cap);
    Some([a * u[0], a * u[1]])
}

fn record_inner<D: DeviceIo + ?Sized>(
    dev: &mut D,
    linkage: &Pantograph2,
    rest: [f64; 2],
    counts: [f64; 2],
    dirs: &[[f64; 2]],
    check_still: bool,
    plan: &PulsePlan,
) -> Result<Vec<Vec<Sample>>, IdentifyError> {
    let e_rest = linkage
        .fk(rest)
        .map_err(|e| IdentifyError::Fit(format!("the rest pose does not assemble: {e}")))?;
    let count = [
        std::f64::consts::TAU / counts[0],
        std::f64::consts::TAU / counts[1],
    ];
    let period = Duration::from_secs_f64(plan.period);
    let mut clock = Clock::new(plan.timebase, plan.period);
    // Stillness at the rest pose, zero torque: no joint may move more than 2 counts.
    let n_settle = (plan.settle / plan.period).ceil().max(1.0) as usize;
    let q0 = dev.read_encoders()?;
    for _ in 0..n_settle {
        clock.pace(period);
        dev.write_torques(&[0.0; 4])?;
        let q = dev.read_encoders()?;
        for j in 0..2 {
            if check_still && (q[j] - q0[j]).abs() > 2.0 * count[j] + 1e-12 {
                return Err(IdentifyError::NotStill(format!(
                    "joint {j} moved {:.3}° at zero torque before the pulses: the handle is not still at the rest pose\n    fix: hold the handle still at the rest pose while the board is set up, then let go of it without moving it, and start again",
                    (q[j] - q0[j]).to_degrees()
                )));
            }
        }
    }
    let n = ((2.0 * plan.half_period + plan.tail) / plan.period).ceil() as usize;
    let mut pulses: Vec<Vec<Sample>> = Vec::with_capacity(dirs.len());
    for (j, u) in dirs.iter().enumerate() {
        if j > 0 {
            for _ in 0..n_settle {
                clock.pace(period);
                dev.write_torques(&[0.0; 4])?;
                dev.read_encoders()?;
            }
        }
        let mut samples = Vec::with_capacity(n);
        clock.restart();
        for _ in 0..n {
            clock.pace(period);
            let t = clock.now();
            let s = doublet(t, 1.0, plan.half_period);
            let tau = [s * u[0], s * u[1]];
            dev.write_torques(&[tau[0], tau[1], 0.0, 0.0])?;
            let q = dev.read_encoders()?;
            let qq = [q[0], q[1]];
            let away = linkage.fk(qq).map(|e| (e - e_rest).length());
            match away {
                Ok(d) if d <= plan.max_excursion => {}
                got => {
                    dev.zero_torques();
                    return Err(IdentifyError::Excursion(format!(
                        "during pulse {} ({:+.4}, {:+.4}) N·m the handle went {} from the rest pose (limit {:.1} mm): torques set to zero\n    fix: let the handle move freely (nothing in its way), or lower --torque",
                        j + 1,
                        u[0],
                        u[1],
                        got.map(|d| format!("{:.1} mm", d * 1e3))
                            .unwrap_or_else(|e| format!("out of the linkage's reach ({e})")),
                        plan.max_excursion * 1e3
                    )));
                }
            }
            samples.push(Sample { t, q: qq, tau });
        }
        pulses.push(samples);
    }
    Ok(pulses)
}

/// Sample times and pacing.
struct Clock {
    base: Timebase,
    period: f64,
    start: Instant,
    next: Instant,
    k: u64,
}

impl Clock {
    fn new(base: Timebase, period: f64) -> Self {
        let now = Instant::now();
        Self {
            base,
            period,
            start: now,
            next: now,
            k: 0,
        }
    }

    fn restart(&mut self) {
        self.start = Instant::now();
        self.next = self.start;
        self.k = 0;
    }

    /// Waits for the next tick (wall clock only).
    fn pace(&mut self, period: Duration) {
        if self.base == Timebase::Wall {
            let now = Instant::now();
            if self.next > now {
                std::thread::sleep(self.next - now);
            }
            self.next = self.next.max(now) + period;
        }
    }

    /// The current sample's time (s from the restart); advances the write count.
    fn now(&mut self) -> f64 {
        let t = match self.base {
            Timebase::Wall => self.start.elapsed().as_secs_f64(),
            Timebase::Writes => self.k as f64 * self.period,
        };
        self.k += 1;
        t
    }
}

/// The fitted joint-space model, in the reported angles and commanded torques (see the module
/// documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Identification {
    /// `M'` (kg·m²), general 2×2: row `i` is joint `i`'s torque equation.
    pub inertia: [[f64; 2]; 2],
    /// `B'` (N·m·s/rad), general 2×2.
    pub damping: [[f64; 2]; 2],
    /// RMS residual of the fit (N·m·s², the units of `∫∫τ`) over its RMS right-hand side.
    pub relative_residual: f64,
    /// Samples used.
    pub samples: usize,
}

impl Identification {
    /// `A' = M'⁻¹` (rad/s² per N·m): column `j` is the acceleration of both joints under a unit
    /// torque on joint `j`. `None` when `M'` is singular.
    pub fn response(&self) -> Option<[[f64; 2]; 2]> {
        inv2(&self.inertia)
    }

    /// For each pulse `j`, the displacement of both joints (rad) the fitted model predicts at the end
    /// of the doublet's first half from rest, `A'[:, j]·a·T²/π` (the sign of the acceleration; the
    /// input of the direction diagnosis).
    pub fn response_displacement(&self, a: f64, half: f64) -> Option<[[f64; 2]; 2]> {
        let r = self.response()?;
        let s = a * half * half / std::f64::consts::PI;
        Some([[r[0][0] * s, r[1][0] * s], [r[0][1] * s, r[1][1] * s]])
    }

    /// The symmetric parts of `M'` and `B'` (meaningful once the directions are right).
    pub fn symmetric(&self) -> ([[f64; 2]; 2], [[f64; 2]; 2]) {
        let sym = |m: &[[f64; 2]; 2]| {
            let o = 0.5 * (m[0][1] + m[1][0]);
            [[m[0][0], o], [o, m[1][1]]]
        };
        (sym(&self.inertia), sym(&self.damping))
    }

    /// `|M'_01 − M'_10| / (|M'_01| + |M'_10|)`: 0 for a perfectly reciprocal fit; near 1 when a
    /// single direction (motor or encoder alone) is wrong, which makes `M'` antisymmetric off the
    /// diagonal.
    pub fn asymmetry(&self) -> f64 {
        let (a, b) = (self.inertia[0][1], self.inertia[1][0]);
        let d = a.abs() + b.abs();
        if d > 0.0 {
            (a - b).abs() / d
        } else {
            0.0
        }
    }
}

/// Fits the model of the module documentation to the pulses' samples (at least two pulses that
/// move the joints independently).
pub fn estimate(pulses: &[Vec<Sample>]) -> Result<Identification, String> {
    // Unknowns: M'00 M'01 M'10 M'11 B'00 B'01 B'10 B'11, then per pulse p: (p0, p1, c0, c1).
    let n = 8 + 4 * pulses.len();
    let mut rows: Vec<Vec<f64>> = Vec::new();
    let mut rhs: Vec<f64> = Vec::new();
    for (pi, s) in pulses.iter().enumerate() {
        if s.len() < 10 {
            return Err(format!("pulse {pi}: only {} samples", s.len()));
        }
        let t0 = s[0].t;
        let q0 = s[0].q;
        let mut int_q = [0.0; 2]; // ∫(q − q0)
        let mut int_tau = [0.0; 2]; // ∫τ
        let mut int2_tau = [0.0; 2]; // ∫∫τ
        for k in 0..s.len() {
            if k > 0 {
                let h = s[k].t - s[k - 1].t;
                if !(h.is_finite() && h > 0.0) {
                    return Err(format!("pulse {pi}: sample times not increasing at {k}"));
                }
                for i in 0..2 {
                    int_q[i] += 0.5 * h * ((s[k].q[i] - q0[i]) + (s[k - 1].q[i] - q0[i]));
                    let prev = int_tau[i];
                    int_tau[i] += h * s[k - 1].tau[i];
                    int2_tau[i] += 0.5 * h * (prev + int_tau[i]);
                }
            }
            let dq = [s[k].q[0] - q0[0], s[k].q[1] - q0[1]];
            let t = s[k].t - t0;
            for i in 0..2 {
                let mut r = vec![0.0; n];
                r[2 * i] = dq[0];
                r[2 * i + 1] = dq[1];
                r[4 + 2 * i] = int_q[0];
                r[4 + 2 * i + 1] = int_q[1];
                r[8 + 4 * pi + i] = -t;
                r[8 + 4 * pi + 2 + i] = -1.0;
                rows.push(r);
                rhs.push(int2_tau[i]);
            }
        }
    }
    let x = lstsq(&rows, &rhs, n)?;
    let mut res2 = 0.0;
    let mut rhs2 = 0.0;
    for (r, b) in rows.iter().zip(&rhs) {
        let fit: f64 = r.iter().zip(&x).map(|(a, v)| a * v).sum();
        res2 += (fit - b).powi(2);
        rhs2 += b * b;
    }
    Ok(Identification {
        inertia: [[x[0], x[1]], [x[2], x[3]]],
        damping: [[x[4], x[5]], [x[6], x[7]]],
        relative_residual: if rhs2 > 0.0 {
            (res2 / rhs2).sqrt()
        } else {
            f64::NAN
        },
        samples: pulses.iter().map(Vec::len).sum(),
    })
}

/// The lumped five-bar model `M = I_j·1 + m_e·JᵀJ` fitted to a symmetric joint-space inertia `m`
/// (kg·m²) at the pose whose Jacobian is `j` (`Ė = J·q̇`), both parameters ≥ 0; returns
/// `(I_j kg·m², m_e kg)`.
pub fn lumped(m: &[[f64; 2]; 2], j: &[[f64; 2]; 2]) -> (f64, f64) {
    let a00 = j[0][0] * j[0][0] + j[1][0] * j[1][0];
    let a01 = j[0][0] * j[0][1] + j[1][0] * j[1][1];
    let a11 = j[0][1] * j[0][1] + j[1][1] * j[1][1];
    // Rows (1, a00)·(i, m) = M00; (0, a01)·(i, m) = M01; (1, a11)·(i, m) = M11.
    let (s11, s12, s22) = (2.0, a00 + a11, a00 * a00 + a01 * a01 + a11 * a11);
    let (r1, r2) = (
        m[0][0] + m[1][1],
        a00 * m[0][0] + a01 * m[0][1] + a11 * m[1][1],
    );
    let det = s11 * s22 - s12 * s12;
    let (mut i, mut me) = if det.abs() > 1e-30 {
        ((s22 * r1 - s12 * r2) / det, (s11 * r2 - s12 * r1) / det)
    } else {
        (0.5 * r1, 0.0)
    };
    if me < 0.0 {
        me = 0.0;
        i = 0.5 * r1;
    }
    if i < 0.0 {
        i = 0.0;
        me = if s22 > 0.0 { r2 / s22 } else { 0.0 };
    }
    (i.max(0.0), me.max(0.0))
}

fn inv2(m: &[[f64; 2]; 2]) -> Option<[[f64; 2]; 2]> {
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    if !(det.is_finite() && det != 0.0) {
        return None;
    }
    Some([
        [m[1][1] / det, -m[0][1] / det],
        [-m[1][0] / det, m[0][0] / det],
    ])
}

/// Least squares `min |A·x − b|` by Householder QR on unit-norm columns. Errors when a column is
/// zero or the problem is rank deficient.
fn lstsq(rows: &[Vec<f64>], b: &[f64], n: usize) -> Result<Vec<f64>, String> {
    let m = rows.len();
    if m < n {
        return Err(format!("{m} equations for {n} unknowns"));
    }
    // Column-major copy, columns scaled to unit norm.
    let mut a: Vec<Vec<f64>> = (0..n)
        .map(|c| rows.iter().map(|r| r[c]).collect())
        .collect();
    let mut scale = vec![0.0; n];
    for (c, col) in a.iter_mut().enumerate() {
        let n = col.iter().map(|v| v * v).sum::<f64>().sqrt();
        if !(n.is_finite() && n > 0.0) {
            return Err(format!("unknown {c} is not excited by the data"));
        }
        scale[c] = n;
        col.iter_mut().for_each(|v| *v /= n);
    }
    let mut y = b.to_vec();
    let mut rdiag = vec![0.0; n];
    for k in 0..n {
        let norm = a[k][k..].iter().map(|v| v * v).sum::<f64>().sqrt();
        if norm < 1e-10 {
            return Err("the pulses do not determine every parameter (rank deficient)".into());
        }
        let alpha = if a[k][k] > 0.0 { -norm } else { norm };
        // v = x − alpha·e_k, stored in a[k][k..].
        a[k][k] -= alpha;
        let vnorm2: f64 = a[k][k..].iter().map(|v| v * v).sum();
        rdiag[k] = alpha;
        let (left, right) = a.split_at_mut(k + 1);
        let v = &left[k][k..];
        for col in right.iter_mut() {
            let d: f64 = v.iter().zip(&col[k..]).map(|(p, q)| p * q).sum();
            let f = 2.0 * d / vnorm2;
            col[k..].iter_mut().zip(v).for_each(|(c, p)| *c -= f * p);
        }
        let d: f64 = v.iter().zip(&y[k..]).map(|(p, q)| p * q).sum();
        let f = 2.0 * d / vnorm2;
        y[k..].iter_mut().zip(v).for_each(|(c, p)| *c -= f * p);
    }
    let mut x = vec![0.0; n];
    for k in (0..n).rev() {
        let mut s = y[k];
        for c in k + 1..n {
            s -= a[c][k] * x[c];
        }
        x[k] = s / rdiag[k];
    }
    for (v, s) in x.iter_mut().zip(&scale) {
        *v /= s;
    }
    Ok(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn least_squares_recovers_an_exact_linear_model() {
        // y = 2·x0 − 3·x1 + 0.5 over a grid.
        let mut rows = Vec::new();
        let mut b = Vec::new();
        for i in 0..10 {
            for j in 0..10 {
                let (u, v) = (i as f64 * 0.1, (j as f64).sin());
                rows.push(vec![u, v, 1.0]);
                b.push(2.0 * u - 3.0 * v + 0.5);
            }
        }
        let x = lstsq(&rows, &b, 3).unwrap();
        assert!((x[0] - 2.0).abs() < 1e-12 && (x[1] + 3.0).abs() < 1e-12);
        assert!((x[2] - 0.5).abs() < 1e-12);
    }

    #[test]
    fn the_doublet_starts_at_zero_stays_within_its_amplitude_and_ends_at_zero() {
        assert_eq!(doublet(0.0, 0.004, 0.08), 0.0);
        assert_eq!(doublet(0.16, 0.004, 0.08), 0.0);
        for k in 0..200 {
            let t = k as f64 * 1e-3;
            assert!(doublet(t, 0.004, 0.08).abs() <= 0.004);
        }
        assert!((doublet(0.04, 0.004, 0.08) - 0.004).abs() < 1e-12);
        assert!((doublet(0.12, 0.004, 0.08) + 0.004).abs() < 1e-12);
    }

    /// A noise-free decoupled plant integrated exactly: the fit returns its numbers.
    #[test]
    fn the_fit_recovers_a_synthetic_coupled_plant() {
        let m = [[1.7e-4, 6.0e-5], [6.0e-5, 1.5e-4]];
        let bm = [[3e-4, 0.0], [0.0, 2e-4]];
        let minv = inv2(&m).unwrap();
        let mut pulses: Vec<Vec<Sample>> = vec![Vec::new(), Vec::new()];
        for (j, s) in pulses.iter_mut().enumerate() {
            let (mut q, mut qd) = ([0.3, 1.2], [0.0; 2]);
            let h = 1e-5;
            for k in 0..26_000 {
                let t = k as f64 * h;
                let mut tau = [0.0; 2];
                tau[j] = doublet(t - t % 1e-3, 0.004, 0.08);
                if k % 100 == 0 {
                    s.push(Sample { t, q, tau });
                }
                let f = [
                    tau[0] - bm[0][0] * qd[0] - bm[0][1] * qd[1],
                    tau[1] - bm[1][0] * qd[0] - bm[1][1] * qd[1],
                ];
                let a = [
                    minv[0][0] * f[0] + minv[0][1] * f[1],
                    minv[1][0] * f[0] + minv[1][1] * f[1],
                ];
                for i in 0..2 {
                    qd[i] += h * a[i];
                    q[i] += h * qd[i];
                }
            }
        }
        let id = estimate(&pulses).unwrap();
        for i in 0..2 {
            for k in 0..2 {
                assert!(
                    (id.inertia[i][k] - m[i][k]).abs() < 0.01 * m[0][0],
                    "{:?}",
                    id
                );
                assert!(
                    (id.damping[i][k] - bm[i][k]).abs() < 0.05 * bm[0][0],
                    "{id:?}"
                );
            }
        }
        assert!(id.asymmetry() < 0.02);
    }

    #[test]
    fn the_lumped_fit_inverts_its_own_form() {
        let j = [[0.05, -0.02], [0.03, 0.06]];
        let (i, me) = (2e-5, 0.03);
        let a00 = j[0][0] * j[0][0] + j[1][0] * j[1][0];
        let a01 = j[0][0] * j[0][1] + j[1][0] * j[1][1];
        let a11 = j[0][1] * j[0][1] + j[1][1] * j[1][1];
        let m = [[i + me * a00, me * a01], [me * a01, i + me * a11]];
        let (gi, gm) = lumped(&m, &j);
        assert!((gi - i).abs() < 1e-12 && (gm - me).abs() < 1e-12);
    }
}
