//! UDP device files (`devices/udp-*.toml`): what the device sends (joint angles or a pose), what it
//! takes (joint torques or a wrench), the kinematics that relate them to the 2-DOF system, the
//! limits and the timing. Problems are reported with the field, the unit and the fix.
//!
//! ```toml
//! kind = "udp"
//! name = "UDP reference pantograph"
//! [protocol]
//! input = "joints"              # joints | pose: what the device's states carry
//! output = "torques"            # torques | wrench: what the host's commands carry
//! timeout_periods = 3           # no state for this many periods = device lost
//! reply_wait_periods = 0.3      # how long a read waits for the answer (periods)
//! torque_limit = 0.123          # N·m on each joint, enforced by the host
//! max_missed_deadlines = 10     # watchdog: consecutive missed deadlines (0 = off)
//! max_stall_periods = 5         # the loop's own delay between two ticks that trips (periods)
//! key_file = "udp.key"          # protocol version 2: the shared key (hex or raw, mode 600),
//!                               # relative to this file; without it version 1, loopback only
//! [linkage]                     # the 2-DOF pantograph (docs/DEVICES.md §2), device frame
//! d = 0.038                     # m
//! l1 = 0.07                     # m
//! l2 = 0.09                     # m
//! ```
//!
//! With `input = "pose"` the host turns the pose into joint angles by the linkage's inverse
//! kinematics (elbows out); with `output = "wrench"` it turns the joint torques into the end-point
//! force `f = J⁻ᵀ·τ` at the current angles. The system behind the device is always the 2-DOF
//! pantograph system, so both ends of a pose/wrench device meet in joint space.

use haptic2d::device::pantograph2::Pantograph2;
use haptic2d::scene::{SceneError, SceneErrors};
use serde::Deserialize;
use std::path::{Path, PathBuf};

use super::auth::UdpKey;
use crate::device_toml;

/// The template named in error messages.
pub const UDP_TEMPLATE: &str = "devices/udp-pantograph.toml";

/// The reference device's file, embedded (the default of `--device udp:ADDR:PORT`).
pub const REFERENCE_FILE: &str = include_str!("../../../../devices/udp-pantograph.toml");

/// A parsed, validated UDP device file.
#[derive(Clone, Debug, PartialEq)]
pub struct UdpDeviceFile {
    /// Human-readable name.
    pub name: String,
    /// Where it was read from (for messages).
    pub source: String,
    /// The device sends a pose `(x, y, θ)` (true) or joint angles.
    pub pose_input: bool,
    /// The host sends a wrench (true) or joint torques.
    pub wrench_output: bool,
    /// No state for this many periods = device lost. Default 3.
    pub timeout_periods: f64,
    /// A read waits this many periods for the answer to the previous command. Default 0.3.
    pub reply_wait_periods: f64,
    /// Torque limit on each joint (N·m), enforced by the host. Default 0.123.
    pub torque_limit: f64,
    /// Consecutive missed deadlines that trip the watchdog; `None` (0) = off. Default 10.
    pub max_missed_deadlines: Option<u32>,
    /// The loop's own delay between two ticks that trips the stall check (periods, ≥ 1). Default 5.
    pub max_stall_periods: f64,
    /// The linkage (m).
    pub linkage: Pantograph2,
    /// Protocol version 2: the shared key read from `protocol.key_file`. `None`: version 1
    /// (unauthenticated), allowed on loopback only.
    pub key: Option<UdpKey>,
    /// Where the key was read from (for messages).
    pub key_file: Option<PathBuf>,
    /// The `[safety]` table: plausibility bounds on the joint readings and the stall floor
    /// (defaults when absent; `crate::device_safety`).
    pub safety: crate::device_safety::DeviceSafety,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFile {
    kind: String,
    #[serde(default)]
    name: Option<String>,
    #[serde(default)]
    protocol: Option<RawProtocol>,
    linkage: RawLinkage,
    #[serde(default)]
    safety: Option<crate::device_safety::RawSafety>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawProtocol {
    #[serde(default = "joints")]
    input: String,
    #[serde(default = "torques")]
    output: String,
    #[serde(default = "three")]
    timeout_periods: f64,
    #[serde(default = "wait")]
    reply_wait_periods: f64,
    #[serde(default = "limit")]
    torque_limit: f64,
    #[serde(default = "ten")]
    max_missed_deadlines: i64,
    #[serde(default = "five")]
    max_stall_periods: f64,
    #[serde(default)]
    key_file: Option<String>,
}

impl Default for RawProtocol {
    fn default() -> Self {
        Self {
            input: joints(),
            output: torques(),
            timeout_periods: three(),
            reply_wait_periods: wait(),
            torque_limit: limit(),
            max_missed_deadlines: ten(),
            max_stall_periods: five(),
            key_file: None,
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawLinkage {
    d: f64,
    l1: f64,
    l2: f64,
}

fn joints() -> String {
    "joints".into()
}
fn torques() -> String {
    "torques".into()
}
fn three() -> f64 {
    3.0
}
fn wait() -> f64 {
    0.3
}
fn limit() -> f64 {
    0.123
}
fn ten() -> i64 {
    10
}
fn five() -> f64 {
    5.0
}

/// A field of two values, `(field, value)`: false for `no`, true for `yes`; any other value is an
/// error ("`x` is not {what}", with `fix`) and false.
fn either(
    (field, value): (&str, &str),
    (no, yes): (&str, &str),
    what: &str,
    fix: &str,
    errs: &mut Vec<SceneError>,
) -> bool {
    match value {
        v if v == no => false,
        v if v == yes => true,
        o => {
            errs.push(SceneError::new(field, format!("`{o}` is not {what}"), fix));
            false
        }
    }
}

impl UdpDeviceFile {
    /// The reference device's file (devices/udp-pantograph.toml, embedded).
    pub fn reference() -> Self {
        Self::from_toml(REFERENCE_FILE, "built-in device file udp-pantograph")
            .expect("the shipped reference file is valid (tested)")
    }

    /// Reads and parses the file at `path` (a relative `key_file` is relative to its directory).
    pub fn from_path(path: &Path) -> Result<Self, String> {
        let dir = path.parent().unwrap_or(Path::new("."));
        device_toml::load(path, "a UDP device file", UDP_TEMPLATE, |text, source| {
            Self::from_toml_in(text, source, dir)
        })
    }

    /// Parses a device file's text; `source` names it in messages; a relative `key_file` is
    /// relative to the working directory.
    pub fn from_toml(text: &str, source: &str) -> Result<Self, SceneErrors> {
        Self::from_toml_in(text, source, Path::new(""))
    }

    /// Parses a device file's text; a relative `key_file` is relative to `dir`.
    pub fn from_toml_in(text: &str, source: &str, dir: &Path) -> Result<Self, SceneErrors> {
        let raw: RawFile = device_toml::parse(text, source, UDP_TEMPLATE)?;
        let mut errs = Vec::new();
        if raw.kind != "udp" {
            errs.push(SceneError::new(
                "kind",
                format!("`{}` is not a UDP device file", raw.kind),
                "write kind = \"udp\" (Haply boards use --device haply:PATH with a Haply device file)",
            ));
        }
        let p = raw.protocol.unwrap_or_default();
        let pose_input = either(
            ("protocol.input", &p.input),
            ("joints", "pose"),
            "a kind of state",
            "write input = \"joints\" (joint angles) or \"pose\" (x, y, θ)",
            &mut errs,
        );
        let wrench_output = either(
            ("protocol.output", &p.output),
            ("torques", "wrench"),
            "a kind of command",
            "write output = \"torques\" (joint torques) or \"wrench\" (fx, fy, τ)",
            &mut errs,
        );
        device_toml::check_timeout("protocol.timeout_periods", p.timeout_periods, 3, &mut errs);
        if !(p.reply_wait_periods.is_finite()
            && p.reply_wait_periods > 0.0
            && p.reply_wait_periods < 1.0)
        {
            errs.push(SceneError::new(
                "protocol.reply_wait_periods",
                format!("{} periods is outside (0, 1)", p.reply_wait_periods),
                "give a fraction of the control period, e.g. 0.3 (a read must leave time for the tick)",
            ));
        }
        if !(p.torque_limit.is_finite() && p.torque_limit > 0.0) {
            errs.push(SceneError::new(
                "protocol.torque_limit",
                format!("{} N·m is not a torque limit", p.torque_limit),
                "give the device's joint torque limit in N·m, > 0",
            ));
        }
        let (missed, stall) = (p.max_missed_deadlines, p.max_stall_periods);
        device_toml::check_watchdog("protocol", missed, stall, &mut errs);
        let (key, key_file) = match &p.key_file {
            None => (None, None),
            Some(k) => {
                let path = dir.join(k);
                match UdpKey::from_file(&path) {
                    Ok(key) => (Some(key), Some(path)),
                    Err(e) => {
                        errs.push(SceneError::new(
                            "protocol.key_file",
                            e,
                            "give a file of at least 16 key bytes (hex or raw), mode 600, that the device has too (docs/DEVICE-PROTOCOL.md §6)",
                        ));
                        (None, None)
                    }
                }
            }
        };
        let l = &raw.linkage;
        let linkage = match Pantograph2::new(l.d, l.l1, l.l2) {
            Ok(k) => Some(k),
            Err(e) => {
                errs.push(SceneError::new(
                    "linkage",
                    e,
                    "give the pantograph's d, l1, l2 in metres (docs/DEVICES.md §2)",
                ));
                None
            }
        };
        let safety = crate::device_safety::RawSafety::check(raw.safety.as_ref(), &mut errs);
        let file = linkage.map(|linkage| Self {
            name: raw.name.unwrap_or_else(|| "UDP device".into()),
            source: source.to_string(),
            pose_input,
            wrench_output,
            timeout_periods: p.timeout_periods,
            reply_wait_periods: p.reply_wait_periods,
            torque_limit: p.torque_limit,
            max_missed_deadlines: device_toml::missed_deadline_limit(missed),
            max_stall_periods: stall,
            linkage,
            key,
            key_file,
            safety,
        });
        device_toml::checked(source, errs, file)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_reference_file_parses() {
        let f = UdpDeviceFile::reference();
        assert!(!f.pose_input && !f.wrench_output);
        assert_eq!(f.linkage.d, 0.038);
        assert_eq!(f.timeout_periods, 3.0);
    }

    #[test]
    fn bad_fields_are_named_with_their_fix() {
        let text = "kind = \"udp\"\n[protocol]\ninput = \"angles\"\nreply_wait_periods = 2\n[linkage]\nd = 0.0\nl1 = 0.07\nl2 = 0.09\n";
        let e = UdpDeviceFile::from_toml(text, "device file x.toml")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("protocol.input") && e.contains("\"pose\""),
            "{e}"
        );
        assert!(e.contains("protocol.reply_wait_periods"), "{e}");
        let text = "kind = \"udp\"\n[protocol]\noutput = \"forces\"\n[linkage]\nd = 0.0\nl1 = 0.07\nl2 = 0.09\n";
        let e = UdpDeviceFile::from_toml(text, "f").unwrap_err().to_string();
        assert!(
            e.contains("protocol.output") && e.contains("`forces` is not a kind of command"),
            "{e}"
        );
        assert!(
            e.contains("\"wrench\"") && !e.contains("protocol.input"),
            "{e}"
        );
        let e = UdpDeviceFile::from_toml(
            "kind = \"udp\"\n[linkage]\nd = 0\nl1 = 0.07\nl2 = 0.09\nfoo = 1\n",
            "f",
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("foo"), "{e}");
    }
}
