//! Body-level bounce metrics of Fig. 4 (§13.1): separations, entry and exit speeds, contact ratios and
//! settle time, computed from a sampled trajectory. Shared by the 2-D tests and the lab.

/// One sample of a body approaching a wall with outward normal `+x` (surface at gap 0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BounceSample {
    /// Time (s).
    pub t: f64,
    /// The body's minimum gap to the wall over its vertices (m); negative when penetrating.
    pub gap: f64,
    /// Velocity along the wall normal (m/s), positive away from the wall.
    pub v_n: f64,
    /// Speed `|v|` (m/s).
    pub speed: f64,
    /// `|ω|` (rad/s).
    pub omega: f64,
}

/// The §13.1 metrics of a run.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BounceMetrics {
    /// Entry speeds `−v_n` at the first sample of each contact with gap < 0 (m/s).
    pub entry_speeds: Vec<f64>,
    /// Exit speeds `v_n` at each separation sample (m/s).
    pub exit_speeds: Vec<f64>,
    /// Times of the separations (s).
    pub separation_times: Vec<f64>,
    /// Exit speed / entry speed per completed contact.
    pub contact_ratios: Vec<f64>,
    /// Earliest time after which `|v| < 1e-3 m/s` and `|ω| < 0.05 rad/s` hold to the end (s); `None`
    /// if that does not hold at the last sample.
    pub settle_time: Option<f64>,
    /// Largest penetration `max(−gap)` (m).
    pub max_penetration: f64,
    /// Penetration at the last sample (m).
    pub final_penetration: f64,
}

impl BounceMetrics {
    /// Number of separations.
    pub fn separations(&self) -> usize {
        self.separation_times.len()
    }

    /// Computes the metrics of a sampled run.
    pub fn from_samples(samples: &[BounceSample]) -> Self {
        let mut m = BounceMetrics::default();
        let mut in_contact = false;
        let mut entry = 0.0;
        for s in samples {
            m.max_penetration = m.max_penetration.max(-s.gap);
            if !in_contact && s.gap < 0.0 {
                in_contact = true;
                entry = -s.v_n;
                m.entry_speeds.push(entry);
            } else if in_contact && s.gap >= 0.0 {
                in_contact = false;
                m.exit_speeds.push(s.v_n);
                m.separation_times.push(s.t);
                m.contact_ratios.push(s.v_n / entry);
            }
        }
        if let Some(last) = samples.last() {
            m.final_penetration = (-last.gap).max(0.0);
        }
        let settled = |s: &BounceSample| s.speed < 1e-3 && s.omega < 0.05;
        if samples.last().is_some_and(settled) {
            let first_unsettled_from_end = samples.iter().rposition(|s| !settled(s));
            m.settle_time = Some(match first_unsettled_from_end {
                Some(i) => samples[i + 1].t,
                None => samples[0].t,
            });
        }
        m
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_a_bounce() {
        let mk = |t, gap, v_n| BounceSample {
            t,
            gap,
            v_n,
            speed: f64::abs(v_n),
            omega: 0.0,
        };
        let s = [
            mk(0.0, 0.01, -0.4),
            mk(0.1, -0.001, -0.4),
            mk(0.2, 0.0, 0.2),
            mk(0.3, 0.01, 0.0),
        ];
        let m = BounceMetrics::from_samples(&s);
        assert_eq!(m.separations(), 1);
        assert!((m.contact_ratios[0] - 0.5).abs() < 1e-15);
        assert_eq!(m.settle_time, Some(0.3));
    }
}
