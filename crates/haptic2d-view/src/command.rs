//! Commands from the page to the haptic loop, and how client messages are parsed and checked.
//!
//! The page sends JSON text messages `{"type": "...", ...}` (at most [`MAX_MESSAGE_BYTES`]). The
//! server parses and validates them on its own thread; only valid commands reach the loop, through a
//! wait-free ring that the loop drains between ticks with
//! [`ViewHub::poll_command`](crate::ViewHub::poll_command). A [`Command`] is `Copy` and holds only
//! `'static` names, so receiving and dropping one on the real-time thread never touches the heap.

use haptic2d::contact::ImpactFriction;
use haptic2d::laws::friction::FrictionModel;
use haptic2d::laws::normal::NORMAL_MODEL_NAMES;
use haptic2d::scene::BUILTIN;
use serde::{Deserialize, Serialize};

/// Largest accepted client message (bytes). Longer ones get an error frame.
pub const MAX_MESSAGE_BYTES: usize = 4096;

/// Largest accepted coordinate of a hand target (m or rad, absolute value).
pub const MAX_TARGET_COORDINATE: f64 = 1000.0;

/// Largest trial number an answer may name.
pub const MAX_TRIAL: u64 = 1_000_000;

/// Largest number a magnitude estimate may give (above any modulus a study file accepts times a
/// sensible ratio; the page refuses larger ones too).
pub const MAX_MAGNITUDE: f64 = 1e9;

/// The controllers the page can select: the named configurations of `haptic2d run --controller`
/// ([`haptic2d::haptic::ControllerKind::from_name`]), with the same names.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum ControllerKind {
    /// The four-channel controller of §11.1 with the released-stable default gains (local force
    /// feedback `C6 = −1` and a small damping injection; the default of `haptic2d run`).
    #[serde(rename = "four-channel")]
    FourChannel,
    /// The §11.1 table exactly: unstable with the hand released against a stiff contact (§11.4);
    /// a comparison configuration.
    #[serde(rename = "four-channel-spec")]
    FourChannelSpec,
    /// The §11.1 table with master damping injection alone (a comparison configuration).
    #[serde(rename = "four-channel-damped")]
    FourChannelDamped,
    /// The virtual-coupling (impedance) controller of §11.2.
    #[serde(rename = "coupling")]
    Coupling,
}

impl ControllerKind {
    /// Every controller, in the order the page lists them (the default first).
    pub const ALL: [ControllerKind; 4] = [
        ControllerKind::FourChannel,
        ControllerKind::FourChannelSpec,
        ControllerKind::FourChannelDamped,
        ControllerKind::Coupling,
    ];

    /// The name used on the command line and in messages.
    pub fn name(self) -> &'static str {
        match self {
            ControllerKind::FourChannel => "four-channel",
            ControllerKind::FourChannelSpec => "four-channel-spec",
            ControllerKind::FourChannelDamped => "four-channel-damped",
            ControllerKind::Coupling => "coupling",
        }
    }

    /// The controller called `name`; the error lists the valid names.
    pub fn from_name(name: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|c| c.name() == name)
            .ok_or_else(|| {
                format!(
                    "unknown controller `{name}`; valid: four-channel, four-channel-spec, \
                     four-channel-damped, coupling"
                )
            })
    }

    /// The system's controller of this name, with its named gains (what the loop switches to).
    pub fn system(self) -> haptic2d::haptic::ControllerKind {
        // Every name of `ALL` is one of the system's (test `every_controller_exists_in_the_system`).
        haptic2d::haptic::ControllerKind::from_name(self.name()).unwrap_or_default()
    }
}

/// What the page asks the loop to do. Delivered through [`ViewHub::poll_command`](crate::ViewHub::poll_command);
/// the loop applies it between ticks.
///
/// Semantics the loop must implement:
///
/// - [`SetHandTarget`](Command::SetHandTarget): the new target pose of the (simulated) hand, in the
///   **world** frame. With a simulated device the simulated hand pulls the handle towards
///   `target − device_to_world` (device frame); without a device (the demo) the controller's master
///   pose is the target itself. Clamp it to the device workspace if needed; ignore it with a real
///   device (the real hand is the input).
/// - [`SwitchScene`](Command::SwitchScene): load the built-in scene `name` (at the loop's rate),
///   rebuild the world, re-pick the slave, reset the controller, the passivity observer and the hand
///   target (to the slave's initial pose); keep the currently selected wall law, friction model and
///   controller. Then publish a new [`SceneInfo`](crate::SceneInfo) with
///   [`ViewHub::publish_scene`](crate::ViewHub::publish_scene). Loading allocates: do it between
///   ticks and accept one late tick, or prepare the scene on another thread.
/// - [`SetWallLaw`](Command::SetWallLaw): `world.normal = NormalModel::from_name(name, true)`:
///   every contact created from now on uses it (existing contacts keep their copy until released).
/// - [`SetFriction`](Command::SetFriction): `world.friction = FrictionModel::from_name(name, true)`,
///   same rule as the wall law.
/// - [`SetImpactFriction`](Command::SetImpactFriction): `world.set_impact_friction(mode)`
///   (`"none"` or `"coulomb"`, [`ImpactFriction::NAMES`]): impacts from the next sample on.
/// - [`SetController`](Command::SetController): switch the teleoperation controller, starting from a
///   reset state (no stored integrator or filter state carried over).
/// - [`Pause`](Command::Pause): stop stepping the world and command zero device force; frames keep
///   flowing with `paused = true`. Idempotent.
/// - [`Resume`](Command::Resume): step again from the frozen state. Idempotent.
/// - [`Reset`](Command::Reset): reload the current scene to its initial state (as `SwitchScene` to
///   the current scene, keeping the selected laws and controller) and publish its `SceneInfo` again;
///   the paused state is kept.
/// - [`Answer`](Command::Answer) (`haptic2d study run --observer browser` only): the participant's
///   answer to trial `trial`. The loop accepts it only for the trial it is presenting, while it
///   waits for the answer, and only a choice the study's task offers; any other answer (an old
///   trial, a double click, a choice the task has not) is refused with a message and changes
///   nothing. Without a running study it is refused.
/// - [`Magnitude`](Command::Magnitude): the participant's magnitude estimate for trial `trial`
///   (a magnitude-estimation study only; finite, > 0 and at most [`MAX_MAGNITUDE`]). Taken like an
///   answer: for the trial presented, in its answer phase.
/// - [`ContinueStudy`](Command::ContinueStudy): the participant ends the rest break before trial
///   `trial` (the study's `[breaks]`). Taken only during that break; any other is refused.
/// - [`StopStudy`](Command::StopStudy): end the study session after the current trial's answer is
///   saved (an unanswered trial is not written: the session resumes at it). Torques go to zero as
///   the loop stops. Without a running study it is refused.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Command {
    /// Move the hand target to `(x, y, theta)` (m, m, rad, world frame; θ unwrapped).
    SetHandTarget {
        /// x (m).
        x: f64,
        /// y (m).
        y: f64,
        /// θ (rad).
        theta: f64,
    },
    /// Switch to the built-in scene `name` (one of [`haptic2d::scene::BUILTIN`]).
    SwitchScene {
        /// Scene name.
        name: &'static str,
    },
    /// Select the normal (wall) law `name` (one of [`NORMAL_MODEL_NAMES`]).
    SetWallLaw {
        /// Law name.
        name: &'static str,
    },
    /// Select the friction model `name` (one of [`FrictionModel::NAMES`]).
    SetFriction {
        /// Model name.
        name: &'static str,
    },
    /// Select the impact friction mode `name` (one of [`ImpactFriction::NAMES`]).
    SetImpactFriction {
        /// Mode name.
        name: &'static str,
    },
    /// Select the controller.
    SetController {
        /// Which one.
        kind: ControllerKind,
    },
    /// Freeze the world.
    Pause,
    /// Unfreeze the world.
    Resume,
    /// Restart the current scene.
    Reset,
    /// A study participant's answer (`haptic2d study run --observer browser`).
    Answer {
        /// The trial answered (from 1, as the page shows it).
        trial: u32,
        /// The interval named (1 to 3: "first", "second", "third"), or, in a same–different task,
        /// 0 = "same" and 1 = "different".
        choice: u8,
    },
    /// A magnitude estimate (`haptic2d study run --observer browser`, magnitude estimation).
    Magnitude {
        /// The trial answered (from 1).
        trial: u32,
        /// The number given to the comparison (finite, > 0).
        value: f64,
    },
    /// End the rest break before `trial`.
    ContinueStudy {
        /// The trial the break comes before (from 1).
        trial: u32,
    },
    /// End the study session (it resumes at its next unanswered trial).
    StopStudy,
}

impl Command {
    /// The message `type` that carries this command.
    pub fn kind(&self) -> &'static str {
        match self {
            Command::SetHandTarget { .. } => "set_hand_target",
            Command::SwitchScene { .. } => "switch_scene",
            Command::SetWallLaw { .. } => "set_wall_law",
            Command::SetFriction { .. } => "set_friction",
            Command::SetImpactFriction { .. } => "set_impact_friction",
            Command::SetController { .. } => "set_controller",
            Command::Pause => "pause",
            Command::Resume => "resume",
            Command::Reset => "reset",
            Command::Answer { .. } => "answer",
            Command::Magnitude { .. } => "magnitude",
            Command::ContinueStudy { .. } => "continue_study",
            Command::StopStudy => "stop_study",
        }
    }
}

/// A message from the page, as parsed (names still owned strings).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
enum Incoming {
    Hello { token: String },
    SetHandTarget { x: f64, y: f64, theta: f64 },
    SwitchScene { name: String },
    SetWallLaw { name: String },
    SetFriction { name: String },
    SetImpactFriction { name: String },
    SetController { name: String },
    // Struct variants, so that `deny_unknown_fields` rejects extra fields.
    Pause {},
    Resume {},
    Reset {},
    Answer { trial: u64, choice: u64 },
    Magnitude { trial: u64, value: f64 },
    ContinueStudy { trial: u64 },
    StopStudy {},
}

/// A checked client message.
#[derive(Clone, Debug, PartialEq)]
pub enum ClientMessage {
    /// Authentication: the token printed at startup.
    Hello {
        /// The token as sent.
        token: String,
    },
    /// A command for the loop.
    Command(Command),
}

fn static_name(kind: &str, name: &str, valid: &[&'static str]) -> Result<&'static str, String> {
    valid
        .iter()
        .copied()
        .find(|v| *v == name)
        .ok_or_else(|| format!("unknown {kind} `{name}`; valid: {}", valid.join(", ")))
}

/// The names of the built-in scenes the page may switch to.
pub fn scene_names() -> Vec<&'static str> {
    BUILTIN.iter().map(|b| b.0).collect()
}

/// A trial number a study message names: 1 to [`MAX_TRIAL`].
fn check_trial(kind: &str, trial: u64) -> Result<u32, String> {
    if (1..=MAX_TRIAL).contains(&trial) {
        Ok(trial as u32)
    } else {
        Err(format!(
            "{kind}.trial = {trial} is out of range (1 to {MAX_TRIAL})"
        ))
    }
}

/// Parses and checks one text message. Errors are one-line messages for the client and the log.
pub fn parse_client_message(text: &str) -> Result<ClientMessage, String> {
    if text.len() > MAX_MESSAGE_BYTES {
        return Err(format!(
            "message of {} bytes is larger than the limit of {MAX_MESSAGE_BYTES} bytes",
            text.len()
        ));
    }
    let msg: Incoming = serde_json::from_str(text).map_err(|e| {
        let mut s = e.to_string();
        s.truncate(200);
        format!("malformed message: {s}")
    })?;
    let cmd = match msg {
        Incoming::Hello { token } => return Ok(ClientMessage::Hello { token }),
        Incoming::SetHandTarget { x, y, theta } => {
            for (k, v) in [("x", x), ("y", y), ("theta", theta)] {
                if !(v.is_finite() && v.abs() <= MAX_TARGET_COORDINATE) {
                    return Err(format!(
                        "set_hand_target.{k} = {v:.3e} is out of range (|{k}| ≤ {MAX_TARGET_COORDINATE})"
                    ));
                }
            }
            Command::SetHandTarget { x, y, theta }
        }
        Incoming::SwitchScene { name } => Command::SwitchScene {
            name: static_name("scene", &name, &scene_names())?,
        },
        Incoming::SetWallLaw { name } => Command::SetWallLaw {
            name: static_name("wall law", &name, &NORMAL_MODEL_NAMES)?,
        },
        Incoming::SetFriction { name } => Command::SetFriction {
            name: static_name("friction model", &name, FrictionModel::NAMES)?,
        },
        Incoming::SetImpactFriction { name } => Command::SetImpactFriction {
            name: static_name("impact friction mode", &name, ImpactFriction::NAMES)?,
        },
        Incoming::SetController { name } => Command::SetController {
            kind: ControllerKind::from_name(&name)?,
        },
        Incoming::Pause {} => Command::Pause,
        Incoming::Resume {} => Command::Resume,
        Incoming::Reset {} => Command::Reset,
        Incoming::Answer { trial, choice } => {
            let trial = check_trial("answer", trial)?;
            if choice > 3 {
                return Err(format!(
                    "answer.choice = {choice} is out of range (1 to 3 = the interval named; same–different: 0 = same, 1 = different)"
                ));
            }
            Command::Answer {
                trial,
                choice: choice as u8,
            }
        }
        Incoming::Magnitude { trial, value } => {
            let trial = check_trial("magnitude", trial)?;
            if !(value.is_finite() && value > 0.0 && value <= MAX_MAGNITUDE) {
                return Err(format!(
                    "magnitude.value = {value} is not a number above 0 (at most {MAX_MAGNITUDE:e})"
                ));
            }
            Command::Magnitude { trial, value }
        }
        Incoming::ContinueStudy { trial } => Command::ContinueStudy {
            trial: check_trial("continue_study", trial)?,
        },
        Incoming::StopStudy {} => Command::StopStudy,
    };
    Ok(ClientMessage::Command(cmd))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_every_command() {
        let ok = |s: &str| match parse_client_message(s) {
            Ok(ClientMessage::Command(c)) => c,
            other => panic!("{s}: {other:?}"),
        };
        let answer = |trial, choice| Command::Answer { trial, choice };
        let magnitude = |trial, value| Command::Magnitude { trial, value };
        let table = [
            (
                r#"{"type":"set_hand_target","x":0.01,"y":-0.02,"theta":0.5}"#,
                Command::SetHandTarget {
                    x: 0.01,
                    y: -0.02,
                    theta: 0.5,
                },
            ),
            (
                r#"{"type":"switch_scene","name":"peg-in-hole"}"#,
                Command::SwitchScene {
                    name: "peg-in-hole",
                },
            ),
            (
                r#"{"type":"set_wall_law","name":"seh-pc"}"#,
                Command::SetWallLaw { name: "seh-pc" },
            ),
            (
                r#"{"type":"set_friction","name":"dahl"}"#,
                Command::SetFriction { name: "dahl" },
            ),
            (
                r#"{"type":"set_impact_friction","name":"coulomb"}"#,
                Command::SetImpactFriction { name: "coulomb" },
            ),
            (
                r#"{"type":"set_controller","name":"coupling"}"#,
                Command::SetController {
                    kind: ControllerKind::Coupling,
                },
            ),
            (r#"{"type":"pause"}"#, Command::Pause),
            (r#"{"type":"resume"}"#, Command::Resume),
            (r#"{"type":"reset"}"#, Command::Reset),
            (r#"{"type":"answer","trial":7,"choice":2}"#, answer(7, 2)),
            (r#"{"type":"answer","trial":1,"choice":0}"#, answer(1, 0)),
            (r#"{"type":"stop_study"}"#, Command::StopStudy),
            (
                r#"{"type":"magnitude","trial":4,"value":125.5}"#,
                magnitude(4, 125.5),
            ),
            (
                r#"{"type":"magnitude","trial":4,"value":3}"#,
                magnitude(4, 3.0),
            ),
            (
                r#"{"type":"continue_study","trial":9}"#,
                Command::ContinueStudy { trial: 9 },
            ),
        ];
        for (msg, cmd) in table {
            assert_eq!(ok(msg), cmd, "{msg}");
        }
        for kind in ControllerKind::ALL {
            let msg = format!(r#"{{"type":"set_controller","name":"{}"}}"#, kind.name());
            assert_eq!(ok(&msg), Command::SetController { kind });
        }
        assert_eq!(
            parse_client_message(r#"{"type":"hello","token":"abc"}"#),
            Ok(ClientMessage::Hello {
                token: "abc".into()
            })
        );
    }

    /// The page offers exactly the controllers the loop can run: every name of
    /// [`ControllerKind::ALL`] is a named configuration of the system (with the same name back),
    /// and every name the system accepts (`haptic2d run --controller`) is on the page.
    #[test]
    fn every_controller_exists_in_the_system() {
        use haptic2d::haptic::ControllerKind as System;
        for kind in ControllerKind::ALL {
            let sys = System::from_name(kind.name()).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(sys.name(), kind.name());
            assert_eq!(kind.system(), sys);
        }
        for name in System::NAMES.split(", ") {
            assert!(
                ControllerKind::from_name(name).is_ok(),
                "the system's controller `{name}` is not on the page"
            );
        }
        assert_eq!(ControllerKind::ALL[0].system(), System::default());
    }

    #[test]
    fn rejects_bad_messages_with_a_reason() {
        for (msg, needle) in [
            ("not json", "malformed"),
            (r#"{"type":"launch_rockets"}"#, "malformed"),
            (r#"{"type":"pause","extra":1}"#, "malformed"),
            (r#"{"type":"set_hand_target","x":1e9,"y":0,"theta":0}"#, "x"),
            (r#"{"type":"set_hand_target","x":0,"y":0}"#, "malformed"),
            (r#"{"type":"switch_scene","name":"nope"}"#, "box-in-walls"),
            (r#"{"type":"set_wall_law","name":"nope"}"#, "paper"),
            (
                r#"{"type":"set_friction","name":"nope"}"#,
                "reset-integrator",
            ),
            (r#"{"type":"set_controller","name":"nope"}"#, "four-channel"),
            ("[]", "malformed"),
            (r#"{"type":"answer","trial":0,"choice":1}"#, "trial"),
            (r#"{"type":"answer","trial":2000000,"choice":1}"#, "trial"),
            (r#"{"type":"answer","trial":-1,"choice":1}"#, "malformed"),
            (r#"{"type":"answer","trial":1.5,"choice":1}"#, "malformed"),
            (r#"{"type":"answer","trial":3,"choice":4}"#, "choice"),
            (r#"{"type":"answer","trial":3}"#, "malformed"),
            (
                r#"{"type":"answer","trial":3,"choice":1,"rt":0.2}"#,
                "malformed",
            ),
            (r#"{"type":"answer","trial":"3","choice":1}"#, "malformed"),
            (r#"{"type":"stop_study","now":true}"#, "malformed"),
            (r#"{"type":"magnitude","trial":4,"value":0}"#, "above 0"),
            (r#"{"type":"magnitude","trial":4,"value":-2.5}"#, "above 0"),
            (r#"{"type":"magnitude","trial":4,"value":1e300}"#, "above 0"),
            (
                r#"{"type":"magnitude","trial":4,"value":1e400}"#,
                "malformed",
            ),
            (
                r#"{"type":"magnitude","trial":4,"value":"NaN"}"#,
                "malformed",
            ),
            (
                r#"{"type":"magnitude","trial":4,"value":null}"#,
                "malformed",
            ),
            (r#"{"type":"magnitude","trial":0,"value":5}"#, "trial"),
            (r#"{"type":"magnitude","trial":4}"#, "malformed"),
            (
                r#"{"type":"magnitude","trial":4,"value":5,"choice":1}"#,
                "malformed",
            ),
            (r#"{"type":"continue_study"}"#, "malformed"),
            (r#"{"type":"continue_study","trial":0}"#, "trial"),
            (r#"{"type":"continue_study","trial":2000000}"#, "trial"),
            (r#"{"type":"continue_study","trial":3,"x":1}"#, "malformed"),
        ] {
            let e = parse_client_message(msg).expect_err(msg);
            assert!(e.contains(needle), "{msg}: {e}");
        }
        let big = format!(r#"{{"type":"hello","token":"{}"}}"#, "a".repeat(5000));
        assert!(parse_client_message(&big).unwrap_err().contains("limit"));
    }
}
