//! Haply device files (`devices/haply-*.toml`): the board set-up, the linkage geometry and the limits
//! of a 2DIY (2 DOF) or of a twin pantograph built from two 2DIY linkages (3 DOF). Every problem is
//! reported with the field, the unit and the fix, as scene files are.
//!
//! ```toml
//! kind = "2diy"                 # 2diy | twin
//! name = "Haply 2DIY gen 3"
//! [board]
//! id = 1                        # board id, 0–255
//! usb_ids = ["2341:804d"]       # vendor:product (hex) for --device haply:auto
//! torque_limit = 0.123          # N·m, ≤ the firmware's 0.123
//! timeout_periods = 20          # a reply later than this many periods = device lost
//! max_missed_deadlines = 10     # watchdog: consecutive missed deadlines (0 = off)
//! max_stall_periods = 5         # the loop's own delay between two ticks that trips (periods)
//! watchdog_ms = 20              # haptic2d firmware only: motors zeroed without a write for this long
//! [linkage]                     # 2diy only (the twin's geometry is its [device] table)
//! d = 0.038                     # m
//! l1 = 0.07                     # m
//! l2 = 0.09                     # m
//! [workspace]                   # 2diy only
//! center = [0.019, 0.10]        # m, board frame
//! half_width = 0.03             # m
//! [[motor]]                     # in joint order: 2diy motor 1, 2; twin q11, q12, q21, q22
//! port = 2
//! direction = "ccw"
//! offset_deg = 168.0
//! counts_per_turn = 4880.0
//! [safety]                      # optional (crate::device_safety): plausibility bounds, stall floor
//! max_velocity = 1000.0         # rad/s
//! [identified]                  # 2diy only, optional: written by `haptic2d device identify`
//! [[buttons]]                   # optional, at most 8 (super::buttons): button 0, 1, … in order
//! pin = "A2"                    # analog pin A0–A11 (or 54–65)
//! pressed_above = 512.0         # the analog reading (board's ADC units) above which it is pressed
//! ```

use haptic2d::device::pantograph2::Pantograph2;
use haptic2d::device::{DeviceParams, TwinKinematics};
use haptic2d::geom::Vec2;
use haptic2d::haptic::ControllerKind;
use haptic2d::scene::{device_params_from_toml, SceneError, SceneErrors};
use serde::Deserialize;

use super::buttons::{ButtonSpec, RawButton};
use super::codec::{BoardSetup, Rotation, FIRMWARE_TORQUE_LIMIT, PORTS};
use super::identified::{Identified, RawIdentified};
use crate::device_safety::{DeviceSafety, RawSafety};
use crate::device_toml;

/// Which device a file describes.
#[derive(Clone, Debug, PartialEq)]
pub enum HaplyKind {
    /// One 2DIY five-bar (2 motors): the linkage and its workspace square.
    TwoDiy {
        /// Geometry (m).
        linkage: Pantograph2,
        /// Workspace centre (m, board frame).
        center: [f64; 2],
        /// Workspace half-width (m).
        half_width: f64,
    },
    /// Two 2DIY linkages holding one handle (4 motors): the twin pantograph of MODELS §10.
    Twin(DeviceParams),
}

/// One motor + encoder on a port.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MotorSpec {
    /// Port 1–4.
    pub port: u8,
    /// Motor direction byte.
    pub direction: Rotation,
    /// Encoder direction byte.
    pub encoder_direction: Rotation,
    /// Encoder start angle (degrees).
    pub offset_deg: f64,
    /// Encoder counts per turn.
    pub counts_per_turn: f64,
}

/// A parsed, validated Haply device file.
#[derive(Clone, Debug, PartialEq)]
pub struct HaplyDeviceFile {
    /// Human-readable name.
    pub name: String,
    /// Where it was read from (for messages).
    pub source: String,
    /// Board id.
    pub id: u8,
    /// USB ids `(vendor, product)` that identify this board for `haply:auto`.
    pub usb_ids: Vec<(u16, u16)>,
    /// Torque limit the driver enforces on every motor (N·m), ≤ 0.123.
    pub torque_limit: f64,
    /// A reply later than this many periods means the device is lost. Default 20: at 1 kHz, 3
    /// periods tripped within 0.2–2 s against the emulator on a 2-core machine at load average 11
    /// with nothing wrong (issue 34); the stock board holds the last torque meanwhile either way,
    /// haptic2d's firmware zeroes it after its own `watchdog_ms`.
    pub timeout_periods: f64,
    /// The watchdog trips after this many consecutive missed deadlines; `None` (0 in the file)
    /// turns the check off. Default 10.
    pub max_missed_deadlines: Option<u32>,
    /// The loop's own delay between two ticks (sleep overshoot and computation, not the wait for
    /// the board, which `timeout_periods` bounds) that trips the stall check (periods, ≥ 1).
    /// Default 5, the shared safety layer's.
    pub max_stall_periods: f64,
    /// The watchdog time set on a board running haptic2d's firmware (ms, 1–1000; the stock
    /// firmware has none). Default 20.
    pub watchdog_ms: u16,
    /// Motors in joint order.
    pub motors: Vec<MotorSpec>,
    /// 2DIY or twin.
    pub kind: HaplyKind,
    /// The `[safety]` table: plausibility bounds and the stall floor (defaults when absent).
    pub safety: DeviceSafety,
    /// The `[identified]` table of a 2DIY: the dynamics `haptic2d device identify` measured.
    pub identified: Option<Identified>,
    /// The `[[buttons]]` on analog pins, button `i` = the `i`-th table (none when absent).
    pub buttons: Vec<ButtonSpec>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFile {
    kind: String,
    #[serde(default)]
    name: Option<String>,
    board: RawBoard,
    #[serde(default)]
    linkage: Option<RawLinkage>,
    #[serde(default)]
    workspace: Option<RawWorkspace>,
    #[serde(default)]
    device: Option<toml::Table>,
    #[serde(default)]
    motor: Vec<RawMotor>,
    #[serde(default)]
    rest: Option<RawRest>,
    #[serde(default)]
    safety: Option<RawSafety>,
    #[serde(default)]
    identified: Option<RawIdentified>,
    #[serde(default)]
    buttons: Vec<RawButton>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawRest {
    pose: Vec<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawBoard {
    #[serde(default = "one")]
    id: i64,
    #[serde(default)]
    usb_ids: Vec<String>,
    #[serde(default = "firmware_limit")]
    torque_limit: f64,
    #[serde(default = "twenty_periods")]
    timeout_periods: f64,
    #[serde(default = "ten")]
    max_missed_deadlines: i64,
    #[serde(default = "five")]
    max_stall_periods: f64,
    #[serde(default = "twenty")]
    watchdog_ms: i64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawLinkage {
    d: f64,
    l1: f64,
    l2: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawWorkspace {
    center: [f64; 2],
    half_width: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMotor {
    port: i64,
    direction: String,
    #[serde(default)]
    encoder_direction: Option<String>,
    offset_deg: f64,
    counts_per_turn: f64,
}

fn one() -> i64 {
    1
}
fn twenty_periods() -> f64 {
    20.0
}
fn five() -> f64 {
    5.0
}
fn twenty() -> i64 {
    20
}
fn ten() -> i64 {
    10
}
fn firmware_limit() -> f64 {
    FIRMWARE_TORQUE_LIMIT as f64
}

/// The template named in fixes.
pub const HAPLY_TEMPLATE: &str = "devices/haply-2diy-gen3.toml";

fn rotation(s: &str, field: &str, errs: &mut Vec<SceneError>) -> Rotation {
    match s.to_ascii_lowercase().as_str() {
        "cw" | "clockwise" => Rotation::Clockwise,
        "ccw" | "counter-clockwise" | "counterclockwise" => Rotation::CounterClockwise,
        _ => {
            errs.push(SceneError::new(
                field,
                format!("`{s}` is not a direction"),
                "write \"cw\" or \"ccw\"",
            ));
            Rotation::Clockwise
        }
    }
}

fn usb_id(s: &str) -> Option<(u16, u16)> {
    let (v, p) = s.split_once(':')?;
    Some((
        u16::from_str_radix(v.trim(), 16).ok()?,
        u16::from_str_radix(p.trim(), 16).ok()?,
    ))
}

/// The `board.usb_ids` as `(vendor, product)`, an error for each that is not `VENDOR:PRODUCT` in hex.
fn usb_ids(raw: &[String], errs: &mut Vec<SceneError>) -> Vec<(u16, u16)> {
    let mut ids = Vec::new();
    for (i, s) in raw.iter().enumerate() {
        match usb_id(s) {
            Some(id) => ids.push(id),
            None => errs.push(SceneError::new(
                format!("board.usb_ids[{i}]"),
                format!("`{s}` is not VENDOR:PRODUCT in hex"),
                "write e.g. \"2341:804d\" (see `haptic2d devices` for the ids of your board)",
            )),
        }
    }
    ids
}

impl HaplyDeviceFile {
    /// Reads and parses the file at `path`.
    pub fn from_path(path: &std::path::Path) -> Result<Self, String> {
        device_toml::load(path, "a Haply device file", HAPLY_TEMPLATE, Self::from_toml)
    }

    /// Parses a device file's text; `source` names it in messages.
    pub fn from_toml(text: &str, source: &str) -> Result<Self, SceneErrors> {
        let raw: RawFile = device_toml::parse(text, source, HAPLY_TEMPLATE)?;
        let mut errs = Vec::new();
        let b = &raw.board;
        if !(0..=255).contains(&b.id) {
            errs.push(SceneError::new(
                "board.id",
                format!("{} is not a board id", b.id),
                "use a number 0–255 (1 unless you changed the board's id)",
            ));
        }
        let usb_ids = usb_ids(&b.usb_ids, &mut errs);
        if !(b.torque_limit.is_finite()
            && b.torque_limit > 0.0
            && b.torque_limit <= FIRMWARE_TORQUE_LIMIT as f64)
        {
            errs.push(SceneError::new(
                "board.torque_limit",
                format!("{} N·m is outside (0, 0.123] N·m", b.torque_limit),
                "give a torque limit in N·m above 0 and at most the firmware's clamp 0.123",
            ));
        }
        if !(b.timeout_periods.is_finite() && b.timeout_periods >= 1.0) {
            errs.push(SceneError::new(
                "board.timeout_periods",
                format!("{} periods is too short", b.timeout_periods),
                "give a number of control periods ≥ 1 (default 20)",
            ));
        }
        if !(0..=100_000).contains(&b.max_missed_deadlines) {
            errs.push(SceneError::new(
                "board.max_missed_deadlines",
                format!("{} is not a count of periods", b.max_missed_deadlines),
                "give a number of consecutive missed deadlines ≥ 1 (default 10), or 0 to turn the check off",
            ));
        }
        if !(b.max_stall_periods.is_finite() && b.max_stall_periods >= 1.0) {
            errs.push(SceneError::new(
                "board.max_stall_periods",
                format!("{} periods is not a stall limit", b.max_stall_periods),
                "give a number of control periods ≥ 1 (default 5)",
            ));
        }
        if !(1..=1000).contains(&b.watchdog_ms) {
            errs.push(SceneError::new(
                "board.watchdog_ms",
                format!("{} ms is outside 1–1000 ms", b.watchdog_ms),
                "give the time after which haptic2d's board firmware zeroes the motors without a write (default 20 ms)",
            ));
        }
        let n_expected = match raw.kind.as_str() {
            "2diy" => 2,
            "twin" => 4,
            k => {
                errs.push(SceneError::new(
                    "kind",
                    format!("`{k}` is not a Haply device kind"),
                    "write kind = \"2diy\" (one five-bar) or kind = \"twin\" (two five-bars on 4 ports)",
                ));
                0
            }
        };
        let mut motors = Vec::new();
        for (i, m) in raw.motor.iter().enumerate() {
            let f = format!("motor[{i}]");
            if !(1..=PORTS as i64).contains(&m.port) {
                errs.push(SceneError::new(
                    format!("{f}.port"),
                    format!("{} is not a port", m.port),
                    "use a port number 1–4",
                ));
            }
            let direction = rotation(&m.direction, &format!("{f}.direction"), &mut errs);
            let encoder_direction = match &m.encoder_direction {
                Some(s) => rotation(s, &format!("{f}.encoder_direction"), &mut errs),
                None => direction,
            };
            if !m.offset_deg.is_finite() {
                errs.push(SceneError::new(
                    format!("{f}.offset_deg"),
                    "must be a finite number of degrees",
                    "give the encoder's start angle in degrees (run `haptic2d device check` to calibrate)",
                ));
            }
            if !(m.counts_per_turn.is_finite() && m.counts_per_turn > 0.0) {
                errs.push(SceneError::new(
                    format!("{f}.counts_per_turn"),
                    format!("{} counts per turn must be > 0", m.counts_per_turn),
                    "give the encoder's counts per turn of the link (e.g. 4880 on gen 3, 10752 on gen 2)",
                ));
            }
            motors.push(MotorSpec {
                port: m.port.clamp(1, 4) as u8,
                direction,
                encoder_direction,
                offset_deg: m.offset_deg,
                counts_per_turn: m.counts_per_turn,
            });
        }
        if n_expected > 0 && motors.len() != n_expected {
            errs.push(SceneError::new(
                "motor",
                format!("{} [[motor]] tables for kind `{}`", motors.len(), raw.kind),
                format!("give exactly {n_expected} [[motor]] tables, in joint order"),
            ));
        }
        // Ports unique and 1..n without gaps: the firmware assigns direction bytes by position, so
        // a mask that does not start at port 1 would get shifted directions (docs/HARDWARE.md).
        let mut ports: Vec<u8> = motors.iter().map(|m| m.port).collect();
        ports.sort_unstable();
        if ports.windows(2).any(|w| w[0] == w[1]) {
            errs.push(SceneError::new(
                "motor.port",
                "two motors on the same port",
                "give each motor its own port",
            ));
        } else if !ports.is_empty() && ports != (1..=ports.len() as u8).collect::<Vec<_>>() {
            errs.push(SceneError::new(
                "motor.port",
                format!("ports {ports:?} do not start at port 1 without gaps"),
                "wire the motors to ports 1..n: with other masks the board's firmware assigns the direction bytes to the wrong ports",
            ));
        }
        let kind = match raw.kind.as_str() {
            "2diy" => match (&raw.linkage, &raw.workspace) {
                (Some(l), Some(w)) => {
                    let linkage = Pantograph2::new(l.d, l.l1, l.l2).map_err(|e| {
                        SceneError::new("linkage", e, "give d ≥ 0, l1 > 0, l2 > d/2 in metres")
                    });
                    match linkage {
                        Ok(linkage) => {
                            check_workspace(&linkage, w, &mut errs);
                            Some(HaplyKind::TwoDiy {
                                linkage,
                                center: w.center,
                                half_width: w.half_width,
                            })
                        }
                        Err(e) => {
                            errs.push(e);
                            None
                        }
                    }
                }
                _ => {
                    errs.push(SceneError::new(
                        if raw.linkage.is_none() { "linkage" } else { "workspace" },
                        "missing",
                        format!("a 2diy file needs [linkage] (d, l1, l2 in m) and [workspace] (center, half_width in m), as in {HAPLY_TEMPLATE}"),
                    ));
                    None
                }
            },
            "twin" => match &raw.device {
                Some(t) => {
                    let mut text = String::from("[device]\n");
                    text.push_str(&toml::to_string(t).unwrap_or_default());
                    match device_params_from_toml(&text, source, None) {
                        Ok(mut p) => {
                            p.tau_max = p.tau_max.min(b.torque_limit);
                            Some(HaplyKind::Twin(p))
                        }
                        Err(e) => {
                            errs.extend(e.errors.into_iter().map(|mut e| {
                                if !e.field.starts_with("device") {
                                    e.field = format!("device.{}", e.field);
                                }
                                e
                            }));
                            None
                        }
                    }
                }
                None => {
                    errs.push(SceneError::new(
                        "device",
                        "missing",
                        "a twin file needs a [device] table with the twin-pantograph parameters (devices/haply-twin.toml)",
                    ));
                    None
                }
            },
            _ => None,
        };
        if let (Some(k), true) = (&kind, errs.is_empty()) {
            check_rest_pose(k, &motors, raw.rest.as_ref(), &mut errs);
        }
        let safety = RawSafety::check(raw.safety.as_ref(), &mut errs);
        let buttons = super::buttons::check(&raw.buttons, &mut errs);
        let identified = match (&raw.identified, raw.kind.as_str()) {
            (None, _) => None,
            (Some(i), "2diy") => i.check(&mut errs),
            (Some(_), _) => {
                errs.push(SceneError::new(
                    "identified",
                    format!("kind `{}` has no identified model", raw.kind),
                    "delete the [identified] table: `haptic2d device identify` measures a 2diy",
                ));
                None
            }
        };
        let file = kind.map(|kind| Self {
            name: raw.name.unwrap_or_else(|| raw.kind.clone()),
            source: source.to_string(),
            id: b.id as u8,
            usb_ids,
            torque_limit: b.torque_limit,
            timeout_periods: b.timeout_periods,
            max_missed_deadlines: device_toml::missed_deadline_limit(b.max_missed_deadlines),
            max_stall_periods: b.max_stall_periods,
            watchdog_ms: b.watchdog_ms.clamp(1, 1000) as u16,
            motors,
            kind,
            safety,
            identified,
            buttons,
        });
        device_toml::checked(source, errs, file)
    }

    /// The board set-up this file asks for: motors and encoders on the motor ports, the buttons'
    /// analog pins as sensors (in file order), no PWM outputs.
    pub fn board_setup(&self) -> BoardSetup {
        let mut s = BoardSetup::empty(self.id);
        for m in &self.motors {
            let p = (m.port - 1) as usize;
            s.motor_mask |= 1 << p;
            s.enc_mask |= 1 << p;
            s.motor_dir[p] = m.direction;
            s.enc_dir[p] = m.encoder_direction;
            s.enc_offset_deg[p] = m.offset_deg as f32;
            s.enc_resolution[p] = m.counts_per_turn as f32;
        }
        super::buttons::add_to_setup(&self.buttons, &mut s);
        s
    }

    /// For each joint (motor in file order), its index among the used ports in ascending order:
    /// where its angle sits in a reply and its torque in a write.
    pub fn wire_index(&self) -> [usize; PORTS] {
        let mut idx = [0; PORTS];
        for (j, m) in self.motors.iter().enumerate() {
            idx[j] = self.motors.iter().filter(|o| o.port < m.port).count();
        }
        idx
    }

    /// Number of joints (2 or 4).
    pub fn joints(&self) -> usize {
        self.motors.len()
    }

    /// The controller `kind` matched to this device's θ axis. A 2DIY has none (unchanged). On the
    /// twin, the master-side θ gains (coupling `k[2]`, `b[2]`; four-channel `k_m[2]`, `b_m[2]`,
    /// `d_m[2]`) are capped at the translational ones times `r_c²`, i.e. at most the stiffness and
    /// damping at the crank pin that x and y have at the handle (N/m, N·s/m):
    ///
    /// ```text
    /// k_θ ≤ k_x·r_c²,   b_θ ≤ b_x·r_c²    (a θ error δθ moves the crank pin r_c·δθ; the torque
    ///                                    k_θ·δθ is the crank-pin force k_θ/r_c² · (r_c·δθ) · r_c)
    /// ```
    ///
    /// Why (issue 12, the twin's closed-loop test was 30 % off): the default θ gains (1 N·m/rad,
    /// 0.01 N·m·s/rad) were chosen for the paper's device. Through the Haply twin's 2 cm crank they
    /// are 2500 N/m at the crank pin, five times the 500 N/m at the handle; with the board's one
    /// period of latency and a θ inertia of ~1e-5 kg·m², θ limit-cycles (rms 18 mrad), the four
    /// motors sit at the 0.123 N·m clamp two ticks in three, and the direction-preserving
    /// saturation scales the x force the hand feels down by a quarter. Capped (0.2 N·m/rad,
    /// 0.002 N·m·s/rad) θ settles (rms 2 mrad), nothing saturates and the rendered force is
    /// exactly the hand's 0.8 N.
    pub fn controller_for(&self, kind: ControllerKind) -> ControllerKind {
        let HaplyKind::Twin(p) = &self.kind else {
            return kind;
        };
        let r2 = p.r_c * p.r_c;
        let cap = |v: &mut [f64; 3]| v[2] = v[2].min(v[0].min(v[1]) * r2);
        match kind {
            ControllerKind::Coupling(mut g) => {
                cap(&mut g.k);
                cap(&mut g.b);
                ControllerKind::Coupling(g)
            }
            ControllerKind::FourChannel(mut g) => {
                cap(&mut g.k_m);
                cap(&mut g.b_m);
                cap(&mut g.d_m);
                ControllerKind::FourChannel(g)
            }
        }
    }

    /// The joint angles of the rest (calibration) pose (rad, joint order): the offsets. Right after
    /// a setup the board reports exactly these, within one count, wherever the handle is
    /// (docs/DEVICES.md §1.3.3).
    pub fn rest_joint_angles(&self) -> [f64; PORTS] {
        let mut q = [0.0; PORTS];
        for (qj, m) in q.iter_mut().zip(&self.motors) {
            *qj = m.offset_deg.to_radians();
        }
        q
    }

    /// The rest (calibration) pose: the forward kinematics of the offsets (2DIY: end point `(x, y,
    /// 0)`, m, board frame; twin: handle pose `(x, y, θ)`, m, m, rad, MODELS §10 frame). The user
    /// holds the handle here when a host starts (docs/DEVICES.md §7). Errors when the offsets do
    /// not assemble (the twin: a closure error of `closure_tol` or more).
    pub fn rest_pose(&self) -> Result<[f64; 3], String> {
        let q = self.rest_joint_angles();
        match &self.kind {
            HaplyKind::TwoDiy { linkage, .. } => linkage
                .fk([q[0], q[1]])
                .map(|e| [e.x, e.y, 0.0])
                .map_err(|e| format!("the offsets do not assemble into the linkage: {e}")),
            HaplyKind::Twin(p) => TwinKinematics::new(p)
                .fk(&q, 0.0)
                .map(|f| f.pose)
                .map_err(|e| format!("the offsets are not a pose of the twin: {e}")),
        }
    }

    /// A start pose inside the workspace: the centre (m, board frame; θ = 0 for the twin).
    pub fn workspace_center(&self) -> [f64; 3] {
        match &self.kind {
            HaplyKind::TwoDiy { center, .. } => [center[0], center[1], 0.0],
            HaplyKind::Twin(p) => [p.workspace_center_x, p.workspace_center_y, 0.0],
        }
    }
}

/// The rest (homing) pose against the offsets (docs/DEVICES.md §1.3.3, §3): the twin's offsets must
/// close (closure error below `closure_tol`); a `[rest] pose` given must be the offsets' pose
/// (within 1 mm and 0.01 rad). Errors give the offsets that would match.
fn check_rest_pose(
    kind: &HaplyKind,
    motors: &[MotorSpec],
    rest: Option<&RawRest>,
    errs: &mut Vec<SceneError>,
) {
    let mut q = [0.0; PORTS];
    for (qj, m) in q.iter_mut().zip(motors) {
        *qj = m.offset_deg.to_radians();
    }
    let deg = |q: &[f64]| {
        q.iter()
            .map(|v| format!("{:.6}", v.to_degrees()))
            .collect::<Vec<_>>()
            .join(", ")
    };
    match kind {
        HaplyKind::TwoDiy { linkage, .. } => {
            let Some(r) = rest else { return };
            if r.pose.len() != 2 || !r.pose.iter().all(|v| v.is_finite()) {
                errs.push(SceneError::new(
                    "rest.pose",
                    "must be [x, y] in metres for a 2diy",
                    "give the end point of the rest pose, board frame",
                ));
                return;
            }
            let want = Vec2::new(r.pose[0], r.pose[1]);
            match linkage.fk([q[0], q[1]]) {
                Ok(e) if (e - want).length() <= 1e-3 => {}
                got => {
                    let fix = match linkage.ik(want) {
                        Ok(qi) => format!(
                            "offsets ({}) in joint order put the rest pose there",
                            deg(&qi)
                        ),
                        Err(_) => "the pose is out of reach: give a reachable one".into(),
                    };
                    errs.push(SceneError::new(
                        "rest.pose",
                        format!(
                            "the offsets put the end point at {}, not at ({:.4}, {:.4}) m",
                            got.map(|e| format!("({:.4}, {:.4}) m", e.x, e.y))
                                .unwrap_or_else(|e| e.to_string()),
                            want.x,
                            want.y
                        ),
                        fix,
                    ));
                }
            }
        }
        HaplyKind::Twin(p) => {
            let kin = TwinKinematics::new(p);
            let want = match rest {
                Some(r) if r.pose.len() == 3 && r.pose.iter().all(|v| v.is_finite()) => {
                    Some([r.pose[0], r.pose[1], r.pose[2]])
                }
                Some(_) => {
                    errs.push(SceneError::new(
                        "rest.pose",
                        "must be [x, y, theta] (m, m, rad) for a twin",
                        "give the handle's homing pose, MODELS §10 frame",
                    ));
                    return;
                }
                None => None,
            };
            let fix = |w: Option<[f64; 3]>| {
                match w.map(|w| kin.ik(&w)) {
                Some(Ok(qi)) => format!(
                    "set the four offsets to the homing pose's inverse kinematics ({}, q11 q12 q21 q22)",
                    deg(&qi)
                ),
                _ => "set the four offsets to the inverse kinematics of one handle pose and give it as [rest] pose = [x, y, theta] (docs/DEVICES.md §3)".into(),
            }
            };
            match kin.fk(&q, want.map_or(0.0, |w| w[2])) {
                Err(e) => errs.push(SceneError::new(
                    "motor.offset_deg",
                    format!("the offsets are not a pose of the twin: {e}"),
                    fix(want),
                )),
                Ok(f) => {
                    if let Some(w) = want {
                        let d = ((f.pose[0] - w[0]).powi(2) + (f.pose[1] - w[1]).powi(2)).sqrt();
                        if d > 1e-3 || (f.pose[2] - w[2]).abs() > 1e-2 {
                            errs.push(SceneError::new(
                                "rest.pose",
                                format!(
                                    "the offsets put the handle at ({:.4} m, {:.4} m, {:.4} rad), not at the rest pose",
                                    f.pose[0], f.pose[1], f.pose[2]
                                ),
                                fix(want),
                            ));
                        }
                    }
                }
            }
        }
    }
}

fn check_workspace(l: &Pantograph2, w: &RawWorkspace, errs: &mut Vec<SceneError>) {
    if !(w.half_width.is_finite() && w.half_width > 0.0 && w.center.iter().all(|c| c.is_finite())) {
        errs.push(SceneError::new(
            "workspace",
            "center must be finite and half_width > 0",
            "give center = [x, y] and half_width in metres",
        ));
        return;
    }
    for ix in 0..5 {
        for iy in 0..5 {
            let p = Vec2::new(
                w.center[0] + w.half_width * (ix as f64 / 2.0 - 1.0),
                w.center[1] + w.half_width * (iy as f64 / 2.0 - 1.0),
            );
            let ok = l
                .ik(p)
                .and_then(|q| l.state(q))
                .map(|s| s.margin >= 0.1)
                .unwrap_or(false);
            if !ok {
                errs.push(SceneError::new(
                    "workspace.half_width",
                    format!(
                        "point ({:.4} m, {:.4} m) is out of reach or near a singularity (margin < 0.1)",
                        p.x, p.y
                    ),
                    "shrink half_width or move center towards the middle of the reach",
                ));
                return;
            }
        }
    }
}
