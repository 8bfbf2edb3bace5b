//! The `[identified]` table of a 2DIY device file: what `haptic2d device identify` measured
//! ([`super::identify`]), read back by the stability gate in place of the emulator's estimates.
//!
//! ```toml
//! [identified]                          # written by `haptic2d device identify --write`
//! date = "2026-12-05T14:02:11Z"         # UTC
//! command = "haptic2d device identify --device haply:/dev/ttyACM0 --device-file my.toml --write"
//! inertia = [2.57e-4, 2.76e-4]          # kg·m²: each joint's inertia at the rest pose (M_jj)
//! inertia_coupling = -2.08e-4           # kg·m²: M_01
//! damping = [1.94e-4, 1.82e-4]          # N·m·s/rad: each joint's viscous damping (B_jj)
//! joint_inertia = 3.4e-5                # kg·m²: I_j of M = I_j·1 + m_e·JᵀJ (rotor + proximal link)
//! end_mass = 0.051                      # kg: m_e of the same model (handle + distal links)
//! ```

use haptic2d::scene::SceneError;
use serde::Deserialize;

/// Largest inertia accepted (kg·m²): a desktop linkage is below 1e-2.
pub const MAX_INERTIA: f64 = 1.0;
/// Largest damping accepted (N·m·s/rad).
pub const MAX_DAMPING: f64 = 10.0;
/// Largest end mass accepted (kg).
pub const MAX_END_MASS: f64 = 10.0;

/// Identified dynamics of a 2-DOF five-bar at its rest pose.
#[derive(Clone, Debug, PartialEq)]
pub struct Identified {
    /// When (UTC, ISO 8601).
    pub date: String,
    /// The command that measured it.
    pub command: String,
    /// Joint-space inertia diagonal `M_jj` (kg·m²).
    pub inertia: [f64; 2],
    /// Joint-space inertia coupling `M_01` (kg·m²).
    pub inertia_coupling: f64,
    /// Joint viscous damping `B_jj` (N·m·s/rad).
    pub damping: [f64; 2],
    /// Lumped joint inertia `I_j` (kg·m²).
    pub joint_inertia: f64,
    /// Lumped end-point mass `m_e` (kg).
    pub end_mass: f64,
}

impl Identified {
    /// The joint viscous damping of the lumped model (N·m·s/rad): the mean of the two joints'.
    pub fn joint_damping(&self) -> f64 {
        0.5 * (self.damping[0] + self.damping[1])
    }

    /// The table as TOML (with a header line and unit comments).
    pub fn to_toml(&self) -> String {
        let q = |s: &str| toml::Value::String(s.to_string()).to_string();
        format!(
            "[identified]                          # written by `haptic2d device identify`\n\
             date = {}\n\
             command = {}\n\
             inertia = [{:.4e}, {:.4e}]          # kg·m²: each joint's inertia at the rest pose (M_jj)\n\
             inertia_coupling = {:.4e}           # kg·m²: M_01\n\
             damping = [{:.4e}, {:.4e}]          # N·m·s/rad: each joint's viscous damping (B_jj)\n\
             joint_inertia = {:.4e}              # kg·m²: I_j of M = I_j·1 + m_e·JᵀJ\n\
             end_mass = {:.4e}                   # kg: m_e of the same model\n",
            q(&self.date),
            q(&self.command),
            self.inertia[0],
            self.inertia[1],
            self.inertia_coupling,
            self.damping[0],
            self.damping[1],
            self.joint_inertia,
            self.end_mass
        )
    }
}

/// `text` (a device file) with its `[identified]` table replaced by `table`, or `table` appended.
/// The rest of the file, comments included, is kept as it was.
pub fn replace_table(text: &str, table: &str) -> String {
    let lines: Vec<&str> = text.lines().collect();
    let is_header = |l: &str| {
        let t = l.trim_start();
        t.starts_with('[')
    };
    let start = lines
        .iter()
        .position(|l| l.trim_start().starts_with("[identified]"));
    let mut out = String::new();
    match start {
        Some(s) => {
            let end = lines[s + 1..]
                .iter()
                .position(|l| is_header(l))
                .map_or(lines.len(), |e| s + 1 + e);
            for l in &lines[..s] {
                out.push_str(l);
                out.push('\n');
            }
            out.push_str(table);
            if end < lines.len() {
                out.push('\n');
            }
            for l in &lines[end..] {
                out.push_str(l);
                out.push('\n');
            }
        }
        None => {
            out.push_str(text.trim_end());
            out.push_str("\n\n");
            out.push_str(table);
        }
    }
    out
}

/// The raw `[identified]` table.
#[derive(Deserialize, Clone, Debug)]
#[serde(deny_unknown_fields)]
pub struct RawIdentified {
    date: String,
    command: String,
    inertia: [f64; 2],
    inertia_coupling: f64,
    damping: [f64; 2],
    joint_inertia: f64,
    end_mass: f64,
}

impl RawIdentified {
    /// Validates the table; errors name `identified.FIELD`, the unit and the fix.
    pub fn check(&self, errs: &mut Vec<SceneError>) -> Option<Identified> {
        let n0 = errs.len();
        let fix = "run `haptic2d device identify --write` again, or delete the [identified] table to use the built-in estimates";
        let mut bound = |name: &str, v: f64, positive: bool, max: f64, unit: &str| {
            let ok = v.is_finite() && (if positive { v > 0.0 } else { v >= 0.0 }) && v <= max;
            if !ok {
                errs.push(SceneError::new(
                    format!("identified.{name}"),
                    format!(
                        "{v} {unit} is not plausible (must be {} and at most {max} {unit})",
                        if positive { "> 0" } else { ">= 0" }
                    ),
                    fix,
                ));
            }
        };
        for j in 0..2 {
            bound(
                &format!("inertia[{j}]"),
                self.inertia[j],
                true,
                MAX_INERTIA,
                "kg·m²",
            );
            bound(
                &format!("damping[{j}]"),
                self.damping[j],
                false,
                MAX_DAMPING,
                "N·m·s/rad",
            );
        }
        bound(
            "joint_inertia",
            self.joint_inertia,
            false,
            MAX_INERTIA,
            "kg·m²",
        );
        bound("end_mass", self.end_mass, false, MAX_END_MASS, "kg");
        if !(self.joint_inertia > 0.0 || self.end_mass > 0.0) {
            errs.push(SceneError::new(
                "identified.joint_inertia",
                "joint_inertia and end_mass are both 0: the device would have no inertia",
                fix,
            ));
        }
        // A physical inertia matrix is positive definite.
        let det = self.inertia[0] * self.inertia[1] - self.inertia_coupling.powi(2);
        if !(self.inertia_coupling.is_finite() && det > 0.0) {
            errs.push(SceneError::new(
                "identified.inertia_coupling",
                format!(
                    "{} kg·m² with inertia {:?}: the inertia matrix is not positive definite",
                    self.inertia_coupling, self.inertia
                ),
                fix,
            ));
        }
        (errs.len() == n0).then(|| Identified {
            date: self.date.clone(),
            command: self.command.clone(),
            inertia: self.inertia,
            inertia_coupling: self.inertia_coupling,
            damping: self.damping,
            joint_inertia: self.joint_inertia,
            end_mass: self.end_mass,
        })
    }
}

/// The UTC time `secs` seconds after the Unix epoch as `YYYY-MM-DDTHH:MM:SSZ` (the proleptic
/// Gregorian calendar; H. Hinnant's days-to-civil algorithm).
pub fn utc_iso8601(secs: u64) -> String {
    let days = (secs / 86_400) as i64;
    let rem = secs % 86_400;
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!(
        "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}Z",
        rem / 3600,
        rem % 3600 / 60,
        rem % 60
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn utc_dates_match_known_epochs() {
        assert_eq!(utc_iso8601(0), "1970-01-01T00:00:00Z");
        // 2000-03-01 (after a leap day of a century divisible by 400).
        assert_eq!(utc_iso8601(951_868_800), "2000-03-01T00:00:00Z");
        assert_eq!(utc_iso8601(1_764_944_531), "2025-12-05T14:22:11Z");
    }

    #[test]
    fn replacing_the_table_keeps_the_rest_of_the_file() {
        let t = "a = 1\n[identified]\nx = 1\n\n[[motor]]\nport = 1\n";
        let out = replace_table(t, "[identified]\ny = 2\n");
        assert_eq!(out, "a = 1\n[identified]\ny = 2\n\n[[motor]]\nport = 1\n");
        let out = replace_table("a = 1\n", "[identified]\ny = 2\n");
        assert_eq!(out, "a = 1\n\n[identified]\ny = 2\n");
    }
}
