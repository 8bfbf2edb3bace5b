//! The `[[load]]` table of a scene file: external loads on bodies, `body = "*"` expanded, every
//! problem collected (docs/SCENES.md).

use super::bounds::{
    check_abs, check_count, MAX_FORCE_N, MAX_FREQUENCY_HZ, MAX_LOADS, MAX_TORQUE_N_M,
};
use super::file::LoadSection;
use super::SceneError;
use crate::body::Body;
use crate::geom::Vec2;
use crate::load::{Load, Profile};

/// `[[load]]`: the loads, with `body = "*"` expanded to every dynamic body, up to the load cap.
pub(super) fn loads_from(
    entries: &[LoadSection],
    bodies: &[Body],
    errs: &mut Vec<SceneError>,
) -> Vec<Load> {
    let mut loads = Vec::new();
    for (li, l) in entries.iter().enumerate() {
        let field = format!("load[{li}]");
        let profile = match l.profile.as_deref() {
            None | Some("constant") => Profile::Constant,
            Some("sine") => match l.frequency {
                Some(f) if finite_pos(f) && f <= MAX_FREQUENCY_HZ => {
                    Profile::UnidirectionalSine { frequency: f }
                }
                _ => {
                    errs.push(SceneError::new(
                        format!("{field}.frequency"),
                        format!("the sine profile needs a positive frequency in Hz, at most {MAX_FREQUENCY_HZ:e}"),
                        "e.g. frequency = 1.0",
                    ));
                    Profile::Constant
                }
            },
            Some(p) => {
                errs.push(SceneError::new(
                    format!("{field}.profile"),
                    format!("unknown profile \"{p}\""),
                    "use \"constant\" or \"sine\"",
                ));
                Profile::Constant
            }
        };
        let f = l.force.unwrap_or([0.0, 0.0]);
        let tau = l.torque.unwrap_or(0.0);
        let unit = if l.per_mass.unwrap_or(false) {
            "m/s²"
        } else {
            "N"
        };
        let mut load_ok = check_abs(&format!("{field}.force[0]"), f[0], MAX_FORCE_N, unit, errs);
        load_ok &= check_abs(&format!("{field}.force[1]"), f[1], MAX_FORCE_N, unit, errs);
        load_ok &= check_abs(&format!("{field}.torque"), tau, MAX_TORQUE_N_M, "N·m", errs);
        if !load_ok {
            continue;
        }
        let targets: Vec<usize> = if l.body == "*" {
            (0..bodies.len())
                .filter(|&i| bodies[i].is_dynamic())
                .collect()
        } else {
            match bodies.iter().position(|b| b.name == l.body) {
                Some(i) if bodies[i].is_dynamic() => vec![i],
                Some(_) => {
                    errs.push(SceneError::new(
                        format!("{field}.body"),
                        format!("body \"{}\" is fixed; loads on it have no effect", l.body),
                        "load a dynamic body",
                    ));
                    vec![]
                }
                None => {
                    errs.push(SceneError::new(
                        format!("{field}.body"),
                        format!("no body named \"{}\"", l.body),
                        format!(
                            "use one of: {}",
                            bodies
                                .iter()
                                .map(|b| b.name.as_str())
                                .take(8)
                                .collect::<Vec<_>>()
                                .join(", ")
                        ),
                    ));
                    vec![]
                }
            }
        };
        if loads.len() + targets.len() > MAX_LOADS {
            check_count(
                &field,
                loads.len() + targets.len(),
                MAX_LOADS,
                "loads (after body = \"*\" expands)",
                errs,
            );
            break;
        }
        for body in targets {
            loads.push(Load {
                body,
                force: Vec2::new(f[0], f[1]),
                torque: tau,
                per_mass: l.per_mass.unwrap_or(false),
                profile,
            });
        }
    }
    loads
}

fn finite_pos(x: f64) -> bool {
    x.is_finite() && x > 0.0
}
