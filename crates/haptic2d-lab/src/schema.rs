//! The `metrics.json` schema: one file per figure,
//! `{"figure": "fig4", "cases": [{"model", "dimension", <measured metrics>, "pass", "checks"}]}`.

use serde::{Deserialize, Serialize};

/// Which pipeline produced a case.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Dimension {
    /// The 1-D reduced harness (normative numbers).
    #[serde(rename = "1d")]
    OneD,
    /// The full 2-D world pipeline.
    #[serde(rename = "2d")]
    TwoD,
}

impl Dimension {
    /// `"1d"` or `"2d"`.
    pub fn as_str(&self) -> &'static str {
        match self {
            Dimension::OneD => "1d",
            Dimension::TwoD => "2d",
        }
    }
}

/// One spec test evaluated on a case.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Check {
    /// Spec test ID (e.g. `W1`, `F7-2`, `F4-2D`).
    pub id: String,
    /// Whether it holds.
    pub pass: bool,
    /// What was measured against what threshold.
    pub detail: String,
}

impl Check {
    /// A check named `id` that holds when `pass`, with a human-readable `detail`.
    pub fn new(id: &str, pass: bool, detail: impl Into<String>) -> Self {
        Self {
            id: id.to_string(),
            pass,
            detail: detail.into(),
        }
    }
}

/// Fig. 4 body-level metrics (§13.1).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Fig4Measured {
    /// Number of separations in the run.
    pub separations: usize,
    /// Exit speed / entry speed of every completed contact, in order.
    pub contact_ratios: Vec<f64>,
    /// Settle time (s); `null` if the body never settles.
    pub settle_time_s: Option<f64>,
    /// Entry speed of every contact (m/s).
    pub entry_speeds_m_s: Vec<f64>,
    /// Largest penetration (m).
    pub max_penetration_m: f64,
    /// Penetration at the end of the run (m).
    pub final_penetration_m: f64,
    /// Largest `|ω|` (rad/s); 0 in 1-D.
    pub max_abs_omega_rad_s: f64,
    /// Times of the separations (s): samples at which the gap goes from `< 0` to `≥ 0`.
    pub separation_times_s: Vec<f64>,
}

/// Fig. 7 metrics (§13.2).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Fig7Measured {
    /// Peak push `F_pk` (N).
    pub peak_force_n: f64,
    /// creep_k (m), k = 1..4.
    pub creep_m: Vec<f64>,
    /// advance_k (m), k = 1..3.
    pub advance_m: Vec<f64>,
    /// `ΔE − W_push` per cycle (J), k = 1..4.
    pub energy_balance_j: Vec<f64>,
    /// `max|x|` of the peg (m).
    pub max_abs_x_m: f64,
    /// `max|θ|` of the peg (rad); 0 in 1-D.
    pub max_abs_theta_rad: f64,
    /// `max|y|` of the peg (m); 0 in 1-D.
    pub max_abs_y_m: f64,
}

/// The measured metrics of a case, by figure (flattened into the case object).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Measured {
    /// Fig. 4 metrics.
    Fig4(Fig4Measured),
    /// Fig. 7 metrics.
    Fig7(Fig7Measured),
}

/// One case of a figure: a model run in one dimension.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CaseMetrics {
    /// The case name (a wall model or friction model, as listed in the figure).
    pub model: String,
    /// Which pipeline.
    pub dimension: Dimension,
    /// Measured metrics.
    #[serde(flatten)]
    pub measured: Measured,
    /// Whether every check holds.
    pub pass: bool,
    /// A comparison run (another controller or device than the one that carries the paper's claim):
    /// reported with its verdict, but not counted in the figure's pass count nor by `--strict`.
    #[serde(default)]
    pub comparison: bool,
    /// The spec tests evaluated on this case.
    pub checks: Vec<Check>,
    /// Device-in-the-loop claim cases: the configuration that carries this claim and why it is
    /// the one (absent for Figs. 4 and 7, which use no controller).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub carrier: Option<String>,
    /// Device-in-the-loop cases: `haptic2d stability`'s verdict for this case's configuration on
    /// this case's scene and rate, for the simulated device and for a real one (one sample of
    /// output delay).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stability: Option<String>,
}

impl CaseMetrics {
    /// A case whose `pass` is the conjunction of `checks` (false if there are none).
    pub fn new(model: &str, dimension: Dimension, measured: Measured, checks: Vec<Check>) -> Self {
        Self {
            model: model.to_string(),
            dimension,
            measured,
            pass: !checks.is_empty() && checks.iter().all(|c| c.pass),
            comparison: false,
            checks,
            carrier: None,
            stability: None,
        }
    }

    /// The verdict for a report table: `yes` / `**NO**` for a claim case, `yes (comparison)` /
    /// `no (comparison)` for a comparison run.
    pub fn verdict(&self) -> &'static str {
        match (self.pass, self.comparison) {
            (true, false) => "yes",
            (false, false) => "**NO**",
            (true, true) => "yes (comparison)",
            (false, true) => "no (comparison)",
        }
    }

    /// This case with the configuration that carries its claim and the reason.
    pub fn with_carrier(self, carrier: impl Into<String>) -> Self {
        Self {
            carrier: Some(carrier.into()),
            ..self
        }
    }

    /// This case with the stability analysis's verdict for its configuration.
    pub fn with_stability(self, stability: impl Into<String>) -> Self {
        Self {
            stability: Some(stability.into()),
            ..self
        }
    }

    /// This case marked as a comparison run (`comparison = true`) or not.
    pub fn with_comparison(self, comparison: bool) -> Self {
        Self { comparison, ..self }
    }
}

/// The contents of one `metrics.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FigureMetrics {
    /// Figure name (`fig4`, `fig7`, …).
    pub figure: String,
    /// Every case, in a stable order.
    pub cases: Vec<CaseMetrics>,
}

impl FigureMetrics {
    /// The cases that carry the figure's claims (every case but the comparison runs).
    pub fn claims(&self) -> impl Iterator<Item = &CaseMetrics> {
        self.cases.iter().filter(|c| !c.comparison)
    }

    /// Number of claim cases (comparison runs excluded).
    pub fn claim_count(&self) -> usize {
        self.claims().count()
    }

    /// Number of claim cases that pass (comparison runs excluded).
    pub fn passed(&self) -> usize {
        self.claims().filter(|c| c.pass).count()
    }

    /// Number of comparison runs.
    pub fn comparisons(&self) -> usize {
        self.cases.len() - self.claim_count()
    }

    /// `"P / N"`, with ` (+C comparison runs)` when there are any.
    pub fn pass_summary(&self) -> String {
        let c = self.comparisons();
        let extra = if c > 0 {
            format!(" (+{c} comparison runs)")
        } else {
            String::new()
        };
        format!("{} / {}{extra}", self.passed(), self.claim_count())
    }
}
