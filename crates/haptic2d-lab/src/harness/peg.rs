//! The 1-D peg-in-hole friction harness (§13.2, the reduced version of the paper's Fig. 7).
//!
//! A point mass (the peg) moves along the hole axis, pressed on `n` contacts (the hole walls) that each
//! carry a constant normal force `F_n`. Each contact runs its own copy of one friction model. A push
//! `F(t)` acts along the axis. Per sample `k` (§0.5 reduced to one DOF):
//!
//! ```text
//! for each contact i:  F_t,i = model_i.update(ds = x_k − x_{k−1}, s = x_k, S0 = v_k, F_n, T, F(t_k)/n)
//! v_{k+1} = v_k + T·(F(t_k) + Σ F_t,i)/m;     x_{k+1} = x_k + T·v_{k+1}      (semi-implicit Euler, §6.2)
//! ```
//!
//! The result holds the trace and the Fig. 7 metrics: creep_k, advance_k, the per-cycle energy balance
//! `ΔE − W_push` (F7-5) and `max|x|`.

use haptic2d::laws::friction::{FrictionInput, FrictionLaw, FrictionMode, FrictionModel};

/// The push `F(t)` (N) along the hole axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PegPush {
    /// The unidirectional sinusoid of Fig. 7: `F(t) = F_pk·(1 − cos 2πft)/2`.
    RaisedCosine {
        /// Peak force `F_pk` (N).
        f_pk: f64,
        /// Frequency `f` (Hz).
        freq: f64,
    },
    /// A ramp `F(t) = min(rate·t, f_max)` (held at `f_max` once reached).
    Ramp {
        /// Slope (N/s).
        rate: f64,
        /// Level at which the ramp stops and holds (N).
        f_max: f64,
    },
    /// A constant force (N).
    Constant(f64),
}

impl PegPush {
    /// The Fig. 7 push with peak `f_pk` (N) at 1 Hz.
    pub fn fig7(f_pk: f64) -> Self {
        PegPush::RaisedCosine { f_pk, freq: 1.0 }
    }
    /// The force (N) at time `t` (s).
    pub fn at(&self, t: f64) -> f64 {
        match *self {
            PegPush::RaisedCosine { f_pk, freq } => {
                0.5 * f_pk * (1.0 - (2.0 * std::f64::consts::PI * freq * t).cos())
            }
            PegPush::Ramp { rate, f_max } => (rate * t).min(f_max),
            PegPush::Constant(f) => f,
        }
    }
}

/// The harness set-up. [`PegHarness::fig7`] gives the normative §13.2 values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PegHarness {
    /// Peg mass `m` (kg).
    pub mass: f64,
    /// Number of contacts `n` (each its own model instance).
    pub n_contacts: usize,
    /// Constant normal force per contact `F_n` (N).
    pub f_n: f64,
    /// Sample period `T` (s).
    pub dt: f64,
    /// Simulated duration (s); the run has `round(duration/T)` steps and one more recorded sample.
    pub duration: f64,
    /// Push period `P` (s) used by the cycle metrics: cycle `k` starts at `t = k·P`.
    pub period: f64,
    /// The friction model (prototype; each contact gets a copy).
    pub model: FrictionModel,
}

impl PegHarness {
    /// §13.2: `m = 0.2 kg`, 2 contacts with `F_n = 2 N`, `T = 0.002 s`, 5.2 s, 1 Hz cycles.
    pub fn fig7(model: FrictionModel) -> Self {
        Self {
            mass: 0.2,
            n_contacts: 2,
            f_n: 2.0,
            dt: 0.002,
            duration: 5.2,
            period: 1.0,
            model,
        }
    }

    /// Checks the set-up and the model's parameters; the error names the offending one.
    pub fn validate(&self) -> Result<(), String> {
        if !(self.mass.is_finite() && self.mass > 0.0) {
            return Err(format!("mass must be positive (kg), got {}", self.mass));
        }
        if self.n_contacts == 0 {
            return Err("n_contacts must be at least 1".to_string());
        }
        if !(self.f_n.is_finite() && self.f_n >= 0.0) {
            return Err(format!(
                "f_n must be a non-negative normal force (N), got {}",
                self.f_n
            ));
        }
        if !(self.dt.is_finite() && self.dt > 0.0) {
            return Err(format!("dt must be positive (s), got {}", self.dt));
        }
        if !(self.duration.is_finite() && self.duration >= 0.0) {
            return Err(format!(
                "duration must be non-negative (s), got {}",
                self.duration
            ));
        }
        if !(self.period.is_finite() && self.period > 0.0) {
            return Err(format!("period must be positive (s), got {}", self.period));
        }
        self.model.validate()
    }

    /// Runs the harness under `push`.
    pub fn run(&self, push: &PegPush) -> Result<PegResult, String> {
        self.run_with(|t| push.at(t))
    }

    /// Runs the harness under an arbitrary push `F(t)` (N), starting at rest at `x = 0`.
    pub fn run_with<F: FnMut(f64) -> f64>(&self, mut push: F) -> Result<PegResult, String> {
        self.validate()?;
        let n_steps = (self.duration / self.dt).round() as usize;
        let mut models = vec![self.model; self.n_contacts];
        for m in models.iter_mut() {
            m.begin(0.0); // god-object entry point at the start position
        }
        let mut r = PegResult::with_capacity(n_steps + 1, self);
        let (mut x, mut v, mut x_prev) = (0.0_f64, 0.0_f64, 0.0_f64);
        let n = self.n_contacts as f64;
        for k in 0..=n_steps {
            let t = k as f64 * self.dt;
            let f_push = push(t);
            // Friction: every contact sees the same relative motion and its share of the push.
            let input = FrictionInput {
                ds: x - x_prev,
                s: x,
                s0: v,
                fn_: self.f_n,
                dt: self.dt,
                f_ext_t: f_push / n,
            };
            let mut f_fric = 0.0;
            let mut u_f = 0.0;
            for m in models.iter_mut() {
                f_fric += m.update(&input);
                u_f += m.stored_energy();
            }
            r.t.push(t);
            r.x.push(x);
            r.v.push(v);
            r.f_push.push(f_push);
            r.f_friction.push(f_fric);
            r.mode.push(models[0].mode());
            r.u_f.push(u_f);
            if k == n_steps {
                break;
            }
            // Semi-implicit Euler (§6.2).
            x_prev = x;
            v += self.dt * (f_push + f_fric) / self.mass;
            x += self.dt * v;
        }
        r.compute_metrics();
        Ok(r)
    }
}

/// The trace and metrics of one harness run. Column vectors are indexed by sample `k` (time `k·T`); the
/// forces are those computed at that sample and held over `[kT, (k+1)T)`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PegResult {
    /// Mass (kg) of the run, for the energy metrics.
    pub mass: f64,
    /// Sample period (s) of the run.
    pub dt: f64,
    /// Cycle period `P` (s) of the metrics.
    pub period: f64,
    /// Name of the friction model.
    pub model: &'static str,
    /// Time `t_k` (s).
    pub t: Vec<f64>,
    /// Peg position `x_k` (m).
    pub x: Vec<f64>,
    /// Peg velocity `v_k` (m/s).
    pub v: Vec<f64>,
    /// Push `F(t_k)` (N).
    pub f_push: Vec<f64>,
    /// Total friction force `Σ F_t,i` (N) at sample `k`.
    pub f_friction: Vec<f64>,
    /// Mode of contact 0 after the update at sample `k` (all contacts see identical inputs).
    pub mode: Vec<FrictionMode>,
    /// Stored friction-spring energy `U_f = Σ_i U_f,i` (J) after the update at sample `k`.
    pub u_f: Vec<f64>,
    /// creep_k = `x(k + 0.2P) − x(k − 0.1P)` (m) for cycles `k = 1..=4` (as far as the run reaches).
    pub creep: Vec<f64>,
    /// advance_k = `x(k + 0.9P) − x(k − 0.1P)` (m) for cycles `k = 1..=3` (as far as the run reaches).
    pub advance: Vec<f64>,
    /// `ΔE − W_push` (J) from `t = k − 0.1P` to `k + 0.9P` for cycles `k = 1..=4` (F7-5), with
    /// `E = ½m v² + U_f` and `W_push = Σ F(t_j)·(x_{j+1} − x_j)`.
    pub energy_balance: Vec<f64>,
    /// `max_k |x_k|` (m).
    pub max_abs_x: f64,
}

impl PegResult {
    fn with_capacity(n: usize, h: &PegHarness) -> Self {
        Self {
            mass: h.mass,
            dt: h.dt,
            period: h.period,
            model: h.model.name(),
            t: Vec::with_capacity(n),
            x: Vec::with_capacity(n),
            v: Vec::with_capacity(n),
            f_push: Vec::with_capacity(n),
            f_friction: Vec::with_capacity(n),
            mode: Vec::with_capacity(n),
            u_f: Vec::with_capacity(n),
            ..Self::default()
        }
    }

    /// The sample index nearest to time `t` (s), if the run reaches it.
    pub fn index(&self, t: f64) -> Option<usize> {
        if t.is_nan() || t < 0.0 {
            return None;
        }
        let j = (t / self.dt).round() as usize;
        (j < self.x.len()).then_some(j)
    }

    /// Position (m) at the sample nearest to `t` (s).
    pub fn x_at(&self, t: f64) -> Option<f64> {
        self.index(t).map(|j| self.x[j])
    }

    /// Mean position (m) over the samples with `t0 ≤ t_j < t1` (s); `None` if the window is empty or
    /// beyond the run.
    pub fn mean_x(&self, t0: f64, t1: f64) -> Option<f64> {
        let j0 = self.index(t0)?;
        let j1 = ((t1 / self.dt).round() as usize).min(self.x.len());
        (j1 > j0).then(|| self.x[j0..j1].iter().sum::<f64>() / (j1 - j0) as f64)
    }

    /// Mechanical energy `½m v_j² + U_f,j` (J) at sample `j`.
    pub fn energy(&self, j: usize) -> f64 {
        0.5 * self.mass * self.v[j] * self.v[j] + self.u_f[j]
    }

    /// `ΔE − W_push` (J) between the samples nearest to `t0` and `t1` (s).
    pub fn energy_balance_between(&self, t0: f64, t1: f64) -> Option<f64> {
        let (j0, j1) = (self.index(t0)?, self.index(t1)?);
        let w_push: f64 = (j0..j1)
            .map(|j| self.f_push[j] * (self.x[j + 1] - self.x[j]))
            .sum();
        Some(self.energy(j1) - self.energy(j0) - w_push)
    }

    /// creep_k (m) of cycle `k`: `x(kP + 0.2P) − x(kP − 0.1P)`.
    pub fn creep_of(&self, k: usize) -> Option<f64> {
        let c = k as f64 * self.period;
        Some(self.x_at(c + 0.2 * self.period)? - self.x_at(c - 0.1 * self.period)?)
    }

    /// advance_k (m) of cycle `k`: `x(kP + 0.9P) − x(kP − 0.1P)`.
    pub fn advance_of(&self, k: usize) -> Option<f64> {
        let c = k as f64 * self.period;
        Some(self.x_at(c + 0.9 * self.period)? - self.x_at(c - 0.1 * self.period)?)
    }

    fn compute_metrics(&mut self) {
        self.creep = (1..=4).map_while(|k| self.creep_of(k)).collect();
        self.advance = (1..=3).map_while(|k| self.advance_of(k)).collect();
        let p = self.period;
        self.energy_balance = (1..=4)
            .map_while(|k| {
                let c = k as f64 * p;
                self.energy_balance_between(c - 0.1 * p, c + 0.9 * p)
            })
            .collect();
        self.max_abs_x = self.x.iter().fold(0.0, |a, x| a.max(x.abs()));
    }
}
