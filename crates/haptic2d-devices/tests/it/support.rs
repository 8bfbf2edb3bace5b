//! Shared set-up of the driver-vs-emulator tests: an emulated board on a pseudo-terminal pair, the
//! driver on the slave side, and a haptic system on a built-in scene.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Duration;

use haptic2d::device::HandModel;
use haptic2d::haptic::ControllerKind;
use haptic2d::world::World;
use haptic2d_devices::haply::serial::{open_port, BoardPort, Pty};
use haptic2d_devices::haply::{
    emulator, serve, EmulatorClock, EmulatorConfig, EmulatorReport, HaplyDevice, HaplyDeviceFile,
    HaplyKind, HaplySystem,
};

/// A shipped device file, with a generous reply timeout (100 periods): these tests check physics
/// and protocol on a machine shared with compilers, not timing (the lost-device tests set theirs).
pub fn device_file(name: &str) -> HaplyDeviceFile {
    let path = format!("{}/../../devices/{name}", env!("CARGO_MANIFEST_DIR"));
    let mut f = HaplyDeviceFile::from_path(std::path::Path::new(&path)).unwrap();
    f.timeout_periods = 100.0;
    f
}

/// [`device_file`] with the rest (homing) pose moved to the workspace centre: the offsets become the
/// centre's inverse kinematics (a homing jig at the centre). The stock firmware reports the offsets
/// at setup (docs/DEVICES.md §1.3.3), so an emulator whose handle starts at the centre agrees with
/// this file; the closed-loop physics tests start there.
pub fn device_file_homed_at_center(name: &str) -> HaplyDeviceFile {
    let mut f = device_file(name);
    let c = f.workspace_center();
    let q = match &f.kind {
        HaplyKind::TwoDiy { linkage, .. } => {
            let q = linkage.ik(haptic2d::geom::Vec2::new(c[0], c[1])).unwrap();
            [q[0], q[1], 0.0, 0.0]
        }
        HaplyKind::Twin(p) => haptic2d::device::TwinKinematics::new(p).ik(&c).unwrap(),
    };
    for (m, qj) in f.motors.iter_mut().zip(q) {
        m.offset_deg = qj.to_degrees();
    }
    f
}

/// A running emulator.
pub struct Emu {
    pub path: String,
    pub stop: Arc<AtomicBool>,
    pub handle: Option<JoinHandle<EmulatorReport>>,
    pub keep: Option<std::fs::File>,
}

impl Emu {
    /// Stops the emulator and closes its end of the pseudo-terminal ("killed").
    pub fn kill(&mut self) -> EmulatorReport {
        self.stop.store(true, Ordering::Relaxed);
        let r = self.handle.take().unwrap().join().unwrap();
        self.keep = None;
        r
    }
}

impl Drop for Emu {
    fn drop(&mut self) {
        if self.handle.is_some() {
            self.kill();
        }
    }
}

/// Starts an emulated board of `file` with `hand`, one plant step of `dt` per write.
pub fn start_emulator(file: &HaplyDeviceFile, hand: HandModel, dt: f64) -> Emu {
    start_emulator_damped(file, hand, dt, 2.0)
}

/// [`start_emulator`] with hand damping `b_h` (N·s/m).
pub fn start_emulator_damped(file: &HaplyDeviceFile, hand: HandModel, dt: f64, b_h: f64) -> Emu {
    start_emulator_with(file, hand, dt, b_h, |_| {})
}

/// [`start_emulator_damped`] with `edit` applied to the emulated plant first (e.g. its inertia).
pub fn start_emulator_with(
    file: &HaplyDeviceFile,
    hand: HandModel,
    dt: f64,
    b_h: f64,
    edit: impl FnOnce(&mut haptic2d_devices::haply::Plant),
) -> Emu {
    let pty = Pty::new().unwrap();
    let stop = Arc::new(AtomicBool::new(false));
    let config = EmulatorConfig {
        hand,
        clock: EmulatorClock::PerWrite(dt),
        hand_damping: b_h,
        ..EmulatorConfig::default()
    };
    let mut plant = emulator::plant_for(file, None, &config).unwrap();
    edit(&mut plant);
    let (s2, f2) = (stop.clone(), file.clone());
    let master = pty.master;
    let handle = std::thread::spawn(move || serve(master, &f2, plant, &config, &s2));
    Emu {
        path: pty.path,
        stop,
        handle: Some(handle),
        keep: Some(pty.keep),
    }
}

/// Opens the driver on the emulator's port at period `dt` (s).
pub fn open_driver(emu: &Emu, file: &HaplyDeviceFile, dt: f64) -> HaplyDevice<BoardPort> {
    let port = open_port(&emu.path).unwrap();
    HaplyDevice::open(
        port,
        file,
        Duration::from_secs_f64(dt),
        &format!("haply:{}", emu.path),
    )
    .unwrap()
}

/// The box-in-walls scene at `rate` Hz with the box's centre moved to `box_x` (m).
pub fn box_world(rate: f64, box_x: f64) -> World {
    let scene = haptic2d::scene::builtin("box-in-walls", Some(rate))
        .unwrap()
        .unwrap();
    let mut w = scene.world;
    let i = w.body_index("box").unwrap();
    w.bodies[i].pose.pos.x = box_x;
    w
}

/// A hand that holds the handle at its start pose (in the emulator's plant frame) for `hold` s,
/// then pushes with the constant force `(fx, 0)` N.
pub fn hold_then_push(start: [f64; 3], hold: f64, fx: f64) -> HandModel {
    HandModel::Scripted {
        pose: start,
        stiffness: [300.0, 300.0, 0.5],
        damping: [5.0, 5.0, 0.005],
        t_hold: hold,
        push: [fx, 0.0, 0.0],
        t_push: 1e9,
        release: [0.0; 3],
    }
}

/// The virtual coupling with its default gains (500 N/m, 5 N·s/m).
pub fn coupling() -> ControllerKind {
    ControllerKind::from_name("coupling").unwrap()
}

/// Runs `ticks` ticks of `system` against `dev` as fast as the exchanges go (the emulator's plant
/// steps one period per write). Returns every record's handle x (world, m), the slave's x (m) and
/// the contact count.
pub fn run(
    system: &mut HaplySystem,
    dev: &mut HaplyDevice<BoardPort>,
    ticks: usize,
) -> Vec<(f64, f64, u32)> {
    use haptic2d_rt::DeviceIo;
    let mut out = Vec::with_capacity(ticks);
    for k in 0..ticks {
        let q = match dev.read_encoders() {
            Ok(q) => q,
            Err(e) => panic!("tick {k}: {e}"),
        };
        let t = system.tick(&q);
        assert!(!t.tripped, "safety trip: {:?}", system.trip());
        dev.write_torques(&t.torques).unwrap();
        out.push((
            system.handle_world(&t.record)[0],
            t.record.x_s[0],
            t.record.contacts,
        ));
    }
    out
}
