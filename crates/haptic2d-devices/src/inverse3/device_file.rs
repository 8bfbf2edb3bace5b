//! Inverse3 device files (`devices/inverse3.toml`): the service's addresses, the plane mapping (which
//! two device axes carry the world's x and y; the third is held by a virtual plane), the force
//! limit and the timing. Problems are reported with the field, the unit and the fix, through the
//! scene files' [`SceneError`] and the shared [`read_bounded`](crate::file_read::read_bounded).
//!
//! ```toml
//! kind = "inverse3"
//! [service]
//! http_url = "http://localhost:10001"
//! ws_url = "ws://localhost:10001/"
//! timeout_periods = 20          # no new state for this many periods = device lost
//! [plane]
//! axes = ["x", "y"]             # device axes of world x and y ("-z" flips); the third is held
//! position = 0.0                # m, held axis
//! stiffness = 1000.0            # N/m
//! damping = 10.0                # N·s/m
//! [limits]
//! force_limit = 5.0             # N, ≤ INVERSE3_FORCE_MAX
//! ramp_time = 0.5               # s
//! [workspace]
//! center = [0.0, 0.0]           # m, plane coordinates
//! half_width = 0.15             # m
//! ```

use crate::device_toml;
use haptic2d::scene::{SceneError, SceneErrors};
use serde::Deserialize;

/// The template named in error messages.
pub const INVERSE3_TEMPLATE: &str = "devices/inverse3.toml";

/// The shipped file, embedded (the default of `--device inverse3`).
pub const DEFAULT_FILE: &str = include_str!("../../../../devices/inverse3.toml");

/// The largest force magnitude a device file may ask for (N). Haply quotes about 10 N peak for
/// the Inverse3; an estimate (*verify* against your device's data sheet), the file's
/// `limits.force_limit` must not exceed it.
pub const INVERSE3_FORCE_MAX: f64 = 10.0;

/// One device axis with a sign: `index` 0, 1, 2 = x, y, z; `sign` ±1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SignedAxis {
    /// Device axis: 0 = x, 1 = y, 2 = z.
    pub index: usize,
    /// +1 or −1.
    pub sign: f64,
}

/// A parsed, validated Inverse3 device file.
#[derive(Clone, Debug, PartialEq)]
pub struct Inverse3DeviceFile {
    /// Human-readable name.
    pub name: String,
    /// Where it was read from (for messages).
    pub source: String,
    /// The Inverse Service's HTTP base, e.g. `http://localhost:10001`.
    pub http_url: String,
    /// Its WebSocket, e.g. `ws://localhost:10001/`.
    pub ws_url: String,
    /// No new state for this many control periods = device lost (≥ 1). Default 20.
    pub timeout_periods: f64,
    /// Consecutive missed deadlines that trip the watchdog; `None` (0) = off. Default 10.
    pub max_missed_deadlines: Option<u32>,
    /// The loop's own delay between two ticks that trips the stall check (periods, ≥ 1). Default 5.
    pub max_stall_periods: f64,
    /// The device axes carrying the world's x and y.
    pub axes: [SignedAxis; 2],
    /// The held device axis (the one not in `axes`), 0..3.
    pub held_axis: usize,
    /// Where the held axis is held (m, device frame).
    pub plane_position: f64,
    /// The virtual plane's spring (N/m).
    pub plane_stiffness: f64,
    /// The virtual plane's damper (N·s/m).
    pub plane_damping: f64,
    /// Largest force magnitude sent (N), ≤ [`INVERSE3_FORCE_MAX`].
    pub force_limit: f64,
    /// The plane's spring ramps in from zero over this time (s).
    pub ramp_time: f64,
    /// Centre of the usable square (m, plane coordinates: world x, y axes).
    pub center: [f64; 2],
    /// Half side of the usable square (m).
    pub half_width: f64,
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
    service: RawService,
    plane: RawPlane,
    limits: RawLimits,
    workspace: RawWorkspace,
    #[serde(default)]
    safety: Option<crate::device_safety::RawSafety>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, default)]
struct RawService {
    http_url: String,
    ws_url: String,
    timeout_periods: f64,
    max_missed_deadlines: i64,
    max_stall_periods: f64,
}

impl Default for RawService {
    fn default() -> Self {
        Self {
            http_url: "http://localhost:10001".into(),
            ws_url: "ws://localhost:10001/".into(),
            timeout_periods: 20.0,
            max_missed_deadlines: 10,
            max_stall_periods: 5.0,
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPlane {
    axes: Vec<String>,
    position: f64,
    stiffness: f64,
    damping: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawLimits {
    force_limit: f64,
    #[serde(default = "half")]
    ramp_time: f64,
}

fn half() -> f64 {
    0.5
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawWorkspace {
    center: [f64; 2],
    half_width: f64,
}

/// `"x"`, `"-y"`, … as a [`SignedAxis`].
fn parse_axis(s: &str) -> Option<SignedAxis> {
    let (sign, name) = match s.strip_prefix('-') {
        Some(n) => (-1.0, n),
        None => (1.0, s.strip_prefix('+').unwrap_or(s)),
    };
    let index = match name {
        "x" => 0,
        "y" => 1,
        "z" => 2,
        _ => return None,
    };
    Some(SignedAxis { index, sign })
}

impl Inverse3DeviceFile {
    /// The shipped file (devices/inverse3.toml, embedded).
    pub fn shipped() -> Self {
        Self::from_toml(DEFAULT_FILE, "built-in device file inverse3")
            .expect("the shipped Inverse3 file is valid (tested)")
    }

    /// Reads and parses the file at `path`.
    pub fn from_path(path: &std::path::Path) -> Result<Self, String> {
        let kind = "an Inverse3 device file";
        device_toml::load(path, kind, INVERSE3_TEMPLATE, Self::from_toml)
    }

    /// Parses a device file's text; `source` names it in messages.
    pub fn from_toml(text: &str, source: &str) -> Result<Self, SceneErrors> {
        let raw: RawFile = device_toml::parse(text, source, INVERSE3_TEMPLATE)?;
        let mut errs = Vec::new();
        let bad = |errs: &mut Vec<SceneError>, field: &str, msg: String, fix: &str| {
            errs.push(SceneError::new(field, msg, fix));
        };
        if raw.kind != "inverse3" {
            bad(
                &mut errs,
                "kind",
                format!("`{}` is not an Inverse3 device file", raw.kind),
                "write kind = \"inverse3\" (Haply boards: --device haply:PATH; UDP devices: --device udp:ADDR:PORT)",
            );
        }
        let s = &raw.service;
        if !s.http_url.starts_with("http://") {
            bad(
                &mut errs,
                "service.http_url",
                format!("`{}` is not an http:// address", s.http_url),
                "give the Inverse Service's HTTP base, e.g. \"http://localhost:10001\"",
            );
        }
        if !s.ws_url.starts_with("ws://") {
            bad(
                &mut errs,
                "service.ws_url",
                format!("`{}` is not a ws:// address", s.ws_url),
                "give the Inverse Service's WebSocket, e.g. \"ws://localhost:10001/\"",
            );
        }
        device_toml::check_timeout("service.timeout_periods", s.timeout_periods, 20, &mut errs);
        let (missed, stall) = (s.max_missed_deadlines, s.max_stall_periods);
        device_toml::check_watchdog("service", missed, stall, &mut errs);
        let p = &raw.plane;
        let axes: Vec<Option<SignedAxis>> = p.axes.iter().map(|a| parse_axis(a)).collect();
        let mut mapped = None;
        match axes.as_slice() {
            [Some(a), Some(b)] if a.index != b.index => mapped = Some([*a, *b]),
            _ => bad(
                &mut errs,
                "plane.axes",
                format!("{:?} is not two different device axes", p.axes),
                "give the device axes of world x and y, e.g. [\"x\", \"y\"] or [\"x\", \"-z\"] (x, y, z; a leading - flips)",
            ),
        }
        for (field, v, unit) in [
            ("plane.stiffness", p.stiffness, "N/m"),
            ("plane.damping", p.damping, "N·s/m"),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                bad(
                    &mut errs,
                    field,
                    format!("{v} {unit} is not ≥ 0"),
                    "give a finite value ≥ 0 (the virtual plane holding the third axis)",
                );
            }
        }
        if !p.position.is_finite() {
            bad(
                &mut errs,
                "plane.position",
                format!("{} m is not a position", p.position),
                "give where the held axis is held, in metres (device frame)",
            );
        }
        let l = &raw.limits;
        if !(l.force_limit.is_finite()
            && l.force_limit > 0.0
            && l.force_limit <= INVERSE3_FORCE_MAX)
        {
            bad(
                &mut errs,
                "limits.force_limit",
                format!("{} N is outside (0, {INVERSE3_FORCE_MAX}] N", l.force_limit),
                "give the largest force magnitude to send, in newtons, at most the device's",
            );
        }
        if !(l.ramp_time.is_finite() && l.ramp_time >= 0.0) {
            bad(
                &mut errs,
                "limits.ramp_time",
                format!("{} s is not a ramp time", l.ramp_time),
                "give a time ≥ 0 s (default 0.5)",
            );
        }
        let w = &raw.workspace;
        if !w.center.iter().all(|c| c.is_finite()) {
            bad(
                &mut errs,
                "workspace.center",
                format!("{:?} m is not a point", w.center),
                "give [x, y] in metres, plane coordinates",
            );
        }
        if !(w.half_width.is_finite() && w.half_width > 0.0 && w.half_width <= MAX_HALF_WIDTH) {
            bad(
                &mut errs,
                "workspace.half_width",
                format!("{} m is outside (0, {MAX_HALF_WIDTH}] m", w.half_width),
                "give half the side of the usable square in metres",
            );
        }
        let safety = crate::device_safety::RawSafety::check(raw.safety.as_ref(), &mut errs);
        let file = mapped.map(|axes| Self {
            name: raw.name.unwrap_or_else(|| "Haply Inverse3".into()),
            source: source.to_string(),
            http_url: s.http_url.clone(),
            ws_url: s.ws_url.clone(),
            timeout_periods: s.timeout_periods,
            max_missed_deadlines: device_toml::missed_deadline_limit(missed),
            max_stall_periods: stall,
            held_axis: 3 - axes[0].index - axes[1].index,
            axes,
            plane_position: p.position,
            plane_stiffness: p.stiffness,
            plane_damping: p.damping,
            force_limit: l.force_limit,
            ramp_time: l.ramp_time,
            center: w.center,
            half_width: w.half_width,
            safety,
        });
        device_toml::checked(source, errs, file)
    }

    /// The same file with the service at `http_url` / `ws_url` (from `--device inverse3:URL`).
    pub fn with_service(mut self, http_url: String, ws_url: String) -> Self {
        self.http_url = http_url;
        self.ws_url = ws_url;
        self
    }
}

/// The largest `workspace.half_width` (m): a plausibility bound on the file (a 0.4 m square is
/// larger than a desk-top device's reach; a slip such as `2` for `0.2` is refused). The square is
/// the workspace bound of the loop's point system, in plane coordinates.
pub const MAX_HALF_WIDTH: f64 = 0.2;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_shipped_file_parses() {
        let f = Inverse3DeviceFile::shipped();
        assert_eq!(
            f.axes[0],
            SignedAxis {
                index: 0,
                sign: 1.0
            }
        );
        assert_eq!(
            f.axes[1],
            SignedAxis {
                index: 1,
                sign: 1.0
            }
        );
        assert_eq!(f.held_axis, 2);
        assert_eq!(f.force_limit, 5.0);
        assert_eq!(f.ws_url, "ws://localhost:10001/");
    }

    #[test]
    fn bad_fields_are_named_with_their_fix() {
        let text = DEFAULT_FILE
            .replace("axes = [\"x\", \"y\"]", "axes = [\"x\", \"-x\"]")
            .replace("force_limit = 5.0", "force_limit = 40.0")
            .replace("ws://localhost:10001/", "localhost:10001");
        let e = Inverse3DeviceFile::from_toml(&text, "device file x.toml")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("plane.axes") && e.contains("[\"x\", \"-z\"]"),
            "{e}"
        );
        assert!(
            e.contains("limits.force_limit") && e.contains("40 N"),
            "{e}"
        );
        assert!(e.contains("service.ws_url"), "{e}");
        let e = Inverse3DeviceFile::from_toml(&format!("{DEFAULT_FILE}\nfoo = 1\n"), "f")
            .unwrap_err()
            .to_string();
        assert!(e.contains("foo"), "{e}");
    }

    #[test]
    fn a_flipped_axis_and_the_held_axis_follow_the_mapping() {
        let text = DEFAULT_FILE.replace("axes = [\"x\", \"y\"]", "axes = [\"-z\", \"x\"]");
        let f = Inverse3DeviceFile::from_toml(&text, "f").unwrap();
        assert_eq!(
            f.axes[0],
            SignedAxis {
                index: 2,
                sign: -1.0
            }
        );
        assert_eq!(f.held_axis, 1);
    }
}
