//! Controller files: a teleoperation controller's architecture and gains in TOML (`haptic2d run`,
//! `stability` and `reproduce` take one with `--controller-file FILE.toml`; examples in
//! `controllers/`). Validated like a scene: every problem names the field and the fix, unknown keys
//! are refused, nothing panics.
//!
//! ```toml
//! architecture = "four-channel"    # or "coupling"
//! description = "free text"        # optional
//! # per axis [x, y, theta]; world units (N/m, N·s/m; N·m/rad, N·m·s/rad for theta)
//! k_m = [500, 500, 1.0]            # C4 = −(B_m + K_m/s): master PD
//! b_m = [5, 5, 0.01]
//! k_s = [2000, 2000, 4.0]          # C1 = B_s + K_s/s: slave PD
//! b_s = [30, 30, 0.03]
//! c5 = [0, 0, 0]                   # slave local force feedback (C3 = 1 + C5)
//! c6 = [0, 0, 0]                   # master local force feedback (C2 = 1 + C6)
//! d_m = [0, 0, 0]                  # master damping injection −D_m·v_m
//! d_s = [0, 0, 0]                  # slave damping injection −D_s·v_s
//! # c2 = [...], c3 = [...]         # optional: override the transparent C2 = 1 + C6, C3 = 1 + C5
//! ```
//!
//! A four-channel field left out takes the §11.1 table's value (`FourChannelGains::spec`, the
//! paper's gains); a coupling field the §11.2 defaults. The file says nothing about stability:
//! `haptic2d stability --controller-file FILE` does, and `run` refuses to drive a real device with a
//! controller that the analysis finds unstable with the hand released.

use super::coupling::CouplingGains;
use super::four_channel::FourChannelGains;
use crate::device::linalg::V3;
use crate::haptic::config::ControllerKind;
use crate::scene::{SceneError, SceneErrors};

/// Where the example controller files live (repository root), named in fixes.
pub const CONTROLLER_EXAMPLES: &str = "controllers/paper-4ch.toml";

/// The per-axis fields of a four-channel file: `(key, unit, may be negative)`.
const FOUR_CHANNEL_FIELDS: [(&str, &str, bool); 10] = [
    ("k_m", "N/m, N/m, N·m/rad", false),
    ("b_m", "N·s/m, N·s/m, N·m·s/rad", false),
    ("k_s", "N/m, N/m, N·m/rad", false),
    ("b_s", "N·s/m, N·s/m, N·m·s/rad", false),
    ("c5", "dimensionless", true),
    ("c6", "dimensionless", true),
    ("d_m", "N·s/m, N·s/m, N·m·s/rad", false),
    ("d_s", "N·s/m, N·s/m, N·m·s/rad", false),
    ("c2", "dimensionless", true),
    ("c3", "dimensionless", true),
];

/// The other four-channel keys (not per-axis gains).
const FOUR_CHANNEL_OPTIONS: [&str; 4] = [
    "master_feedforward",
    "slave_feedforward",
    "slave_mass",
    "accel_cutoff_hz",
];

/// The per-axis fields of a coupling file.
const COUPLING_FIELDS: [(&str, &str, bool); 2] = [
    ("k", "N/m, N/m, N·m/rad", false),
    ("b", "N·s/m, N·s/m, N·m·s/rad", false),
];

/// Keys every file may have.
const COMMON: [&str; 2] = ["architecture", "description"];

/// A parsed controller file.
#[derive(Clone, Debug, PartialEq)]
pub struct ControllerFile {
    /// The controller.
    pub kind: ControllerKind,
    /// The file's `description`, if any.
    pub description: Option<String>,
}

fn number(v: &toml::Value) -> Option<f64> {
    match v {
        toml::Value::Float(x) => Some(*x),
        toml::Value::Integer(i) => Some(*i as f64),
        _ => None,
    }
}

/// `[x, y, theta]` from `v`, checked finite (and ≥ 0 unless `signed`); the error names `key[i]`.
fn axis_values(key: &str, unit: &str, signed: bool, v: &toml::Value) -> Result<V3, SceneError> {
    let example = |k: &str| {
        format!("give three numbers [x, y, theta] in {unit}, e.g. {k} = [1.0, 1.0, 0.002]")
    };
    let arr = match v {
        toml::Value::Array(a) if a.len() == 3 => a,
        toml::Value::Array(a) => {
            return Err(SceneError::new(
                key,
                format!("expected 3 values [x, y, theta], got {}", a.len()),
                example(key),
            ))
        }
        other => {
            return Err(SceneError::new(
                key,
                format!("expected an array [x, y, theta], got {other}"),
                example(key),
            ))
        }
    };
    let mut out = [0.0; 3];
    for (i, x) in arr.iter().enumerate() {
        let field = format!("{key}[{i}]");
        let Some(n) = number(x) else {
            return Err(SceneError::new(
                field,
                format!("expected a number, got {x}"),
                example(key),
            ));
        };
        if !n.is_finite() {
            return Err(SceneError::new(
                field,
                format!("must be finite (got {n})"),
                example(key),
            ));
        }
        if !signed && n < 0.0 {
            return Err(SceneError::new(
                field,
                format!("must be >= 0 (got {n}): a negative gain or damper injects energy"),
                example(key),
            ));
        }
        out[i] = n;
    }
    Ok(out)
}

fn unknown_key(key: &str, valid: &[&str], architecture: &str) -> SceneError {
    let hint = match key {
        "c1" => " (C1 is the slave PD block B_s + K_s/s: set k_s and b_s)".to_string(),
        "c4" => " (C4 is the master PD block −(B_m + K_m/s): set k_m and b_m)".to_string(),
        _ => String::new(),
    };
    SceneError::new(
        key,
        format!("unknown key for a {architecture} controller{hint}"),
        format!(
            "use one of: {} (see {CONTROLLER_EXAMPLES})",
            valid.join(", ")
        ),
    )
}

/// Parses a controller file (`text`; `source` names it in messages). Every problem is reported with
/// the field and the fix.
pub fn controller_from_toml(text: &str, source: &str) -> Result<ControllerFile, SceneErrors> {
    let fail = |errors| SceneErrors::new(source, errors);
    let fix = format!("check the TOML syntax against {CONTROLLER_EXAMPLES}");
    let table: toml::Table = SceneErrors::parse(text, source, fix)?;
    let mut errs = Vec::new();
    let description = match table.get("description") {
        None => None,
        Some(toml::Value::String(s)) => Some(s.clone()),
        Some(other) => {
            errs.push(SceneError::new(
                "description",
                format!("expected a string, got {other}"),
                "write description = \"...\" or remove the line",
            ));
            None
        }
    };
    let architecture = match table.get("architecture") {
        Some(toml::Value::String(s)) if s == "four-channel" || s == "coupling" => s.clone(),
        Some(other) => {
            return Err(fail(vec![SceneError::new(
                "architecture",
                format!("unknown architecture {other}"),
                "write architecture = \"four-channel\" (Lawrence's, §11.1) or \"coupling\" (the virtual coupling, §11.2)",
            )]))
        }
        None => {
            return Err(fail(vec![SceneError::new(
                "architecture",
                "missing",
                "add architecture = \"four-channel\" or architecture = \"coupling\" at the top",
            )]))
        }
    };
    let kind = if architecture == "coupling" {
        let mut g = CouplingGains::default();
        let valid: Vec<&str> = COMMON
            .iter()
            .copied()
            .chain(COUPLING_FIELDS.iter().map(|f| f.0))
            .collect();
        for (key, v) in &table {
            if COMMON.contains(&key.as_str()) {
                continue;
            }
            let Some((_, unit, signed)) = COUPLING_FIELDS.iter().find(|f| f.0 == key.as_str())
            else {
                errs.push(unknown_key(key, &valid, "coupling"));
                continue;
            };
            match axis_values(key, unit, *signed, v) {
                Ok(x) if key == "k" => g.k = x,
                Ok(x) => g.b = x,
                Err(e) => errs.push(e),
            }
        }
        ControllerKind::Coupling(g)
    } else {
        let mut g = FourChannelGains::spec();
        let valid: Vec<&str> = COMMON
            .iter()
            .copied()
            .chain(FOUR_CHANNEL_FIELDS.iter().map(|f| f.0))
            .chain(FOUR_CHANNEL_OPTIONS)
            .collect();
        for (key, v) in &table {
            if COMMON.contains(&key.as_str()) {
                continue;
            }
            if let Some((_, unit, signed)) =
                FOUR_CHANNEL_FIELDS.iter().find(|f| f.0 == key.as_str())
            {
                match axis_values(key, unit, *signed, v) {
                    Ok(x) => match key.as_str() {
                        "k_m" => g.k_m = x,
                        "b_m" => g.b_m = x,
                        "k_s" => g.k_s = x,
                        "b_s" => g.b_s = x,
                        "c5" => g.c5 = x,
                        "c6" => g.c6 = x,
                        "d_m" => g.d_m = x,
                        "d_s" => g.d_s = x,
                        "c2" => g.c2 = Some(x),
                        _ => g.c3 = Some(x),
                    },
                    Err(e) => errs.push(e),
                }
                continue;
            }
            match (key.as_str(), v) {
                ("master_feedforward", toml::Value::Boolean(b)) => g.master_feedforward = *b,
                ("slave_feedforward", toml::Value::Boolean(b)) => g.slave_feedforward = *b,
                ("master_feedforward" | "slave_feedforward", other) => errs.push(SceneError::new(
                    key.as_str(),
                    format!("expected true or false, got {other}"),
                    format!("write {key} = false (the default) or true"),
                )),
                ("slave_mass", _) => match axis_values(key, "kg, kg, kg·m²", false, v) {
                    Ok(x) => g.slave_mass = x,
                    Err(e) => errs.push(e),
                },
                ("accel_cutoff_hz", v) => match number(v) {
                    Some(x) if x.is_finite() && x > 0.0 => g.accel_cutoff_hz = x,
                    _ => errs.push(SceneError::new(
                        key.as_str(),
                        format!("must be a number of Hz > 0, got {v}"),
                        "write accel_cutoff_hz = 30 (the default) or remove the line",
                    )),
                },
                _ => errs.push(unknown_key(key, &valid, "four-channel")),
            }
        }
        if errs.is_empty() {
            if let Err(e) = g.validate() {
                errs.push(SceneError::new(
                    "file",
                    e,
                    format!("compare with {CONTROLLER_EXAMPLES}"),
                ));
            }
        }
        ControllerKind::FourChannel(g)
    };
    if errs.is_empty() {
        Ok(ControllerFile { kind, description })
    } else {
        Err(fail(errs))
    }
}

fn fmt_v3(v: &V3) -> String {
    format!("[{:?}, {:?}, {:?}]", v[0], v[1], v[2])
}

/// The controller `kind` as a controller file (every field written out), with `description`.
/// [`controller_from_toml`] reads it back to the same gains.
pub fn controller_to_toml(kind: &ControllerKind, description: &str) -> String {
    let mut s = String::new();
    match kind {
        ControllerKind::FourChannel(g) => {
            s.push_str("architecture = \"four-channel\"\n");
            s.push_str(&format!("description = {:?}\n", description));
            s.push_str("# per axis [x, y, theta]; world units (N/m, N·s/m; N·m/rad, N·m·s/rad)\n");
            for (k, v) in [
                ("k_m", &g.k_m),
                ("b_m", &g.b_m),
                ("k_s", &g.k_s),
                ("b_s", &g.b_s),
                ("c5", &g.c5),
                ("c6", &g.c6),
                ("d_m", &g.d_m),
                ("d_s", &g.d_s),
            ] {
                s.push_str(&format!("{k} = {}\n", fmt_v3(v)));
            }
            if let Some(c) = &g.c2 {
                s.push_str(&format!("c2 = {}\n", fmt_v3(c)));
            }
            if let Some(c) = &g.c3 {
                s.push_str(&format!("c3 = {}\n", fmt_v3(c)));
            }
            s.push_str(&format!(
                "master_feedforward = {}\nslave_feedforward = {}\nslave_mass = {}\naccel_cutoff_hz = {:?}\n",
                g.master_feedforward,
                g.slave_feedforward,
                fmt_v3(&g.slave_mass),
                g.accel_cutoff_hz
            ));
        }
        ControllerKind::Coupling(g) => {
            s.push_str("architecture = \"coupling\"\n");
            s.push_str(&format!("description = {:?}\n", description));
            s.push_str(&format!("k = {}\nb = {}\n", fmt_v3(&g.k), fmt_v3(&g.b)));
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn controller_file_round_trips_every_named_configuration() {
        for kind in [
            ControllerKind::FourChannel(FourChannelGains::spec()),
            ControllerKind::FourChannel(FourChannelGains::default()),
            ControllerKind::FourChannel(FourChannelGains {
                c2: Some([0.5, 0.25, 0.0]),
                c3: Some([2.0, 2.0, 1.0]),
                d_s: [3.0, 3.0, 0.0],
                ..FourChannelGains::default()
            }),
            ControllerKind::Coupling(CouplingGains::default()),
        ] {
            let text = controller_to_toml(&kind, "round \"trip\"");
            let f = controller_from_toml(&text, "test").expect(&text);
            assert_eq!(f.kind, kind, "{text}");
            assert_eq!(f.description.as_deref(), Some("round \"trip\""));
        }
    }

    #[test]
    fn controller_file_fields_left_out_take_the_paper_table() {
        let f = controller_from_toml("architecture = \"four-channel\"\nc6 = [-1, -1, -1]\n", "t")
            .expect("valid");
        assert_eq!(
            f.kind,
            ControllerKind::FourChannel(FourChannelGains {
                c6: [-1.0; 3],
                ..FourChannelGains::spec()
            })
        );
    }

    #[test]
    fn controller_file_reports_every_problem_with_field_and_fix() {
        let e = controller_from_toml(
            "architecture = \"four-channel\"\nk_m = [1, \"a\", 3]\nc1 = [1, 1, 1]\nd_s = 5\n",
            "file.toml",
        )
        .unwrap_err();
        let text = e.to_string();
        assert_eq!(e.errors.len(), 3, "{text}");
        assert!(text.contains("k_m[1]: expected a number"), "{text}");
        assert!(
            text.contains("c1: unknown key") && text.contains("set k_s and b_s"),
            "{text}"
        );
        assert!(text.contains("d_s: expected an array"), "{text}");
        assert!(e.errors.iter().all(|x| !x.fix.is_empty()));
        let e = controller_from_toml("architecture = [", "f").unwrap_err();
        assert!(e.to_string().contains("line 1"), "{e}");
        let e = controller_from_toml("architecture = \"coupling\"\nb = [1, 1, inf]\n", "f")
            .unwrap_err();
        assert!(e.to_string().contains("b[2]: must be finite"), "{e}");
    }
}
