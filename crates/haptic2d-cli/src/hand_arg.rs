//! `--hand` for the simulated device: what the simulated operator does.
//!
//! ```text
//! follow                              spring–damper grip following a target (default: hold still at the start pose)
//! free                                no hand: the handle is let go
//! constant:FX,FY,TAU                  a constant wrench (N, N, N·m)
//! sine:FPK,FREQ[,DIRX,DIRY]           unidirectional sinusoid FPK·(1 − cos 2π·FREQ·t)/2 (N, Hz) along (DIRX, DIRY), default +x
//! script:HOLD,FX,FY,TAU,PUSH[,RFX,RFY,RTAU]
//!                                     hold the start pose for HOLD s, push with (FX, FY, TAU) for PUSH s, then
//!                                     apply (RFX, RFY, RTAU) (default 0: let go)
//! ```

use haptic2d::device::linalg::V3;
use haptic2d::device::HandModel;

/// A parsed `--hand` value; the model is made once the start pose is known.
#[derive(Clone, Debug, PartialEq)]
pub enum HandSpec {
    /// Spring–damper grip following a (shared) target, initially the start pose.
    Follow,
    /// No hand.
    Free,
    /// Constant wrench (N, N, N·m).
    Constant(V3),
    /// Unidirectional sinusoid: peak (N), frequency (Hz), unit direction in the plane.
    Sine {
        /// Peak force (N).
        peak: f64,
        /// Frequency (Hz).
        frequency: f64,
        /// Unit direction `(x, y)`.
        direction: [f64; 2],
    },
    /// Hold, push, release.
    Script {
        /// Hold time (s).
        hold: f64,
        /// Push wrench (N, N, N·m).
        push: V3,
        /// Push time (s).
        push_time: f64,
        /// Wrench after the push (N, N, N·m).
        release: V3,
    },
}

/// Largest force of a simulated hand, per component (N): far beyond any person's push on a desktop
/// haptic device (a strong arm push is a few hundred newtons); a larger one is a typo, refused.
pub const MAX_HAND_FORCE_N: f64 = 1000.0;

/// Largest torque of a simulated hand (N·m), as [`MAX_HAND_FORCE_N`].
pub const MAX_HAND_TORQUE_NM: f64 = 100.0;

/// Largest frequency of `sine` (Hz): ten times a hand's bandwidth, below any control rate.
pub const MAX_HAND_FREQUENCY_HZ: f64 = 100.0;

/// Checks a wrench `(FX, FY, TAU)` of `--hand KIND:BODY` against the documented bounds.
fn check_wrench(kind: &str, body: &str, w: &[f64]) -> Result<(), String> {
    for (i, &v) in w.iter().enumerate() {
        let (cap, unit, name) = if i % 3 == 2 {
            (MAX_HAND_TORQUE_NM, "N·m", "torque")
        } else {
            (MAX_HAND_FORCE_N, "N", "force")
        };
        if v.abs() > cap {
            return Err(format!(
                "--hand {kind}:{body}: a {name} of {v:?} {unit} is beyond the simulated hand's bound of {cap} {unit}\n    fix: e.g. --hand constant:-2,0,0 (2 N into the left wall)"
            ));
        }
    }
    Ok(())
}

const FORMS: &str = "follow | free | constant:FX,FY,TAU | sine:FPK,FREQ[,DIRX,DIRY] | script:HOLD,FX,FY,TAU,PUSH[,RFX,RFY,RTAU]";

fn numbers(kind: &str, body: &str, min: usize, max: usize) -> Result<Vec<f64>, String> {
    let parts: Vec<&str> = body.split(',').map(str::trim).collect();
    if parts.len() < min || parts.len() > max {
        return Err(format!(
            "--hand {kind}:{body}: expected {} comma-separated numbers, got {}\n    forms: {FORMS}",
            if min == max {
                min.to_string()
            } else {
                format!("{min} to {max}")
            },
            parts.len()
        ));
    }
    parts
        .iter()
        .map(|p| {
            p.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| format!("--hand {kind}:{body}: `{p}` is not a finite number"))
        })
        .collect()
}

impl HandSpec {
    /// Parses a `--hand` value; the error names the problem and lists the forms.
    pub fn parse(s: &str) -> Result<Self, String> {
        let (kind, body) = s.split_once(':').unwrap_or((s, ""));
        match kind {
            "follow" if body.is_empty() => Ok(HandSpec::Follow),
            "free" if body.is_empty() => Ok(HandSpec::Free),
            "constant" => {
                let v = numbers(kind, body, 3, 3)?;
                check_wrench(kind, body, &v)?;
                Ok(HandSpec::Constant([v[0], v[1], v[2]]))
            }
            "sine" => {
                let v = numbers(kind, body, 2, 4)?;
                if v[0] < 0.0 {
                    return Err(format!(
                        "--hand sine: the peak FPK must be >= 0 N (got {})",
                        v[0]
                    ));
                }
                check_wrench(kind, body, &v[..1])?;
                if v[1] <= 0.0 || v[1] > MAX_HAND_FREQUENCY_HZ {
                    return Err(format!(
                        "--hand sine: the frequency must be > 0 Hz and at most {MAX_HAND_FREQUENCY_HZ} Hz (got {})",
                        v[1]
                    ));
                }
                let d = match v.len() {
                    2 => [1.0, 0.0],
                    4 => [v[2], v[3]],
                    _ => {
                        return Err(
                            "--hand sine: give both DIRX and DIRY, or neither (default +x)".into(),
                        )
                    }
                };
                let n = d[0].hypot(d[1]);
                if n == 0.0 {
                    return Err("--hand sine: the direction (DIRX, DIRY) must not be zero".into());
                }
                Ok(HandSpec::Sine {
                    peak: v[0],
                    frequency: v[1],
                    direction: [d[0] / n, d[1] / n],
                })
            }
            "script" => {
                let v = numbers(kind, body, 5, 8)?;
                if v.len() != 5 && v.len() != 8 {
                    return Err(
                        "--hand script: give HOLD,FX,FY,TAU,PUSH and optionally all three of RFX,RFY,RTAU"
                            .into(),
                    );
                }
                if v[0] < 0.0 || v[4] < 0.0 {
                    return Err(
                        "--hand script: HOLD and PUSH are durations and must be >= 0 s".into(),
                    );
                }
                check_wrench(kind, body, &v[1..4])?;
                if v.len() == 8 {
                    check_wrench(kind, body, &v[5..8])?;
                }
                Ok(HandSpec::Script {
                    hold: v[0],
                    push: [v[1], v[2], v[3]],
                    push_time: v[4],
                    release: if v.len() == 8 {
                        [v[5], v[6], v[7]]
                    } else {
                        [0.0; 3]
                    },
                })
            }
            _ => Err(format!(
                "--hand `{s}` is not understood\n    forms: {FORMS}"
            )),
        }
    }

    /// The hand model for a handle starting at `start` (m, m, rad).
    pub fn model(&self, start: V3) -> HandModel {
        match *self {
            HandSpec::Follow => HandModel::grip(start),
            HandSpec::Free => HandModel::Free,
            HandSpec::Constant(w) => HandModel::Constant { wrench: w },
            HandSpec::Sine {
                peak,
                frequency,
                direction,
            } => HandModel::Sinusoid {
                direction: [direction[0], direction[1], 0.0],
                peak,
                frequency,
            },
            HandSpec::Script {
                hold,
                push,
                push_time,
                release,
            } => {
                let HandModel::SpringDamper {
                    stiffness, damping, ..
                } = HandModel::grip(start)
                else {
                    unreachable!("grip is a spring-damper hand")
                };
                HandModel::Scripted {
                    pose: start,
                    stiffness,
                    damping,
                    t_hold: hold,
                    push,
                    t_push: push_time,
                    release,
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_every_form_and_rejects_bad_ones() {
        assert_eq!(HandSpec::parse("follow").unwrap(), HandSpec::Follow);
        assert_eq!(
            HandSpec::parse("constant:-2,0,0").unwrap(),
            HandSpec::Constant([-2.0, 0.0, 0.0])
        );
        assert!(matches!(
            HandSpec::parse("sine:2.1,1").unwrap(),
            HandSpec::Sine {
                direction: [1.0, 0.0],
                ..
            }
        ));
        assert!(matches!(
            HandSpec::parse("script:1,-2,0,0,0.5").unwrap(),
            HandSpec::Script { hold: 1.0, .. }
        ));
        for bad in [
            "constant:1,2",
            "sine:1,0",
            "sine:x,1",
            "push",
            "script:1,2,3",
            "sine:1,1,0,0",
            "constant:1e300,0,0",
            "constant:0,-1001,0",
            "constant:0,0,101",
            "sine:1e4,1",
            "sine:1,1e300",
            "script:1,1e9,0,0,1",
            "script:1,1,0,0,1,0,0,1e5",
        ] {
            assert!(HandSpec::parse(bad).is_err(), "{bad}");
        }
        // At the bounds: accepted.
        assert!(HandSpec::parse("constant:1000,-1000,100").is_ok());
        // A huge direction is normalised, not overflowed to zero.
        assert!(matches!(
            HandSpec::parse("sine:1,1,1e300,0").unwrap(),
            HandSpec::Sine {
                direction: [1.0, 0.0],
                ..
            }
        ));
    }
}
