//! `haptic2d-view-demo`: a small stand-in for `haptic2d run` (which serves the same display with
//! the real haptic loop) that exercises the display without a device and without the CLI; the
//! display crate's own protocol and load tests run against it.
//!
//! A real [`World`] (built-in `box-in-walls`, frictionless) runs in a fixed-rate thread loop
//! (`haptic2d_rt::run_loop`, 1 kHz by default). The slave box is driven towards the hand target set
//! from the page by a controller:
//!
//! - `coupling` (default): the virtual coupling of §11.2 with `K = 500 N/m`, `B = 5 N·s/m`,
//!   `K_θ = 1 N·m/rad`, `B_θ = 0.01 N·m·s/rad`, the target as the master pose (`x_m` = target,
//!   `v_m = 0`): `f_cs = K·(x_target − x_s) − B·v_s`;
//! - `four-channel`: the slave side of §11.1 with its default gains, the target as an ideal
//!   position-source master (`x_m` = target, `v_m = 0`, `Ŵ_h = 0`).
//!
//! The scene's loads on the slave are removed (the page's hand is its only input); loads on other
//! bodies (e.g. gravity in a pile) stay. There is no device, but for drawing the linkage a default
//! twin pantograph is shown with its handle at the hand target (the device workspace centre is mapped
//! to the slave's initial position).
//!
//! Usage: `haptic2d-view-demo [--bind ADDR:PORT] [--rate HZ] [--duration S] [--token TOKEN]`.
//! Prints `display: http://…` on stdout once listening, and the loop's timing summary at exit.

use haptic2d::control::coupling::VirtualCoupling;
use haptic2d::control::four_channel::{FourChannel, TeleopSignals};
use haptic2d::device::{DeviceParams, TwinKinematics};
use haptic2d::haptic::ControllerKind as SystemController;
use haptic2d::laws::friction::FrictionModel;
use haptic2d::laws::normal::NormalModel;
use haptic2d::world::World;
use haptic2d_rt::clock::now_ns;
use haptic2d_rt::{LoopConfig, TickControl};
use haptic2d_view::{
    assess_builtin_scenes, Command, ControllerKind, Frame, FrameInputs, LiveTiming, SceneInfo,
    ViewHub, ViewOptions, ViewServer, DEFAULT_FRAME_RATE_HZ, DEFAULT_STEP_FRACTION,
};
use std::io::Write;
use std::net::SocketAddr;
use std::time::Duration;

struct Args {
    bind: SocketAddr,
    rate: f64,
    duration: Option<f64>,
    token: Option<String>,
    require_token: bool,
}

fn parse_args() -> Result<Args, String> {
    let mut a = Args {
        bind: SocketAddr::from(([127, 0, 0, 1], 8080)),
        rate: 1000.0,
        duration: None,
        token: None,
        require_token: false,
    };
    let mut it = std::env::args().skip(1);
    while let Some(k) = it.next() {
        let mut val = |name: &str| it.next().ok_or_else(|| format!("{name} needs a value"));
        match k.as_str() {
            "--bind" => {
                let v = val("--bind")?;
                a.bind = v
                    .parse()
                    .map_err(|e| format!("--bind {v}: expected ADDR:PORT ({e})"))?;
            }
            "--rate" => {
                let v = val("--rate")?;
                a.rate = v
                    .parse::<f64>()
                    .ok()
                    .filter(|r| r.is_finite() && *r > 0.0)
                    .ok_or(format!("--rate {v}: expected a positive rate in Hz"))?;
            }
            "--duration" => {
                let v = val("--duration")?;
                a.duration = Some(
                    v.parse::<f64>()
                        .ok()
                        .filter(|d| d.is_finite() && *d > 0.0)
                        .ok_or(format!("--duration {v}: expected seconds > 0"))?,
                );
            }
            "--token" => a.token = Some(val("--token")?),
            "--require-token" => a.require_token = true,
            "-h" | "--help" => {
                println!(
                    "usage: haptic2d-view-demo [--bind ADDR:PORT] [--rate HZ] [--duration S] [--token TOKEN] [--require-token]"
                );
                std::process::exit(0);
            }
            other => return Err(format!("unknown option `{other}` (see --help)")),
        }
    }
    Ok(a)
}

/// The demo's controller. Kept inline (not boxed): one instance, switched rarely.
#[allow(clippy::large_enum_variant)]
enum Controller {
    Coupling(VirtualCoupling),
    FourChannel(FourChannel),
}

impl Controller {
    fn new(kind: ControllerKind, dt: f64) -> Result<Self, String> {
        Ok(match kind.system() {
            SystemController::Coupling(g) => Controller::Coupling(VirtualCoupling::new(g)?),
            SystemController::FourChannel(g) => Controller::FourChannel(FourChannel::new(g, dt)?),
        })
    }
    fn kind(&self) -> ControllerKind {
        match self {
            Controller::Coupling(_) => ControllerKind::Coupling,
            Controller::FourChannel(c) => c
                .gains
                .name()
                .and_then(|n| ControllerKind::from_name(n).ok())
                .unwrap_or(ControllerKind::FourChannel),
        }
    }
    /// The slave drive `f_cs` (N, N, N·m).
    fn drive(&mut self, s: &TeleopSignals) -> [f64; 3] {
        match self {
            Controller::Coupling(c) => c.step(s).1,
            Controller::FourChannel(c) => c.step(s).1,
        }
    }
}

/// Everything the loop thread owns.
struct Demo {
    rate: f64,
    scene_name: &'static str,
    world: World,
    slave: Option<usize>,
    wall_law: &'static str,
    friction: &'static str,
    controller: Controller,
    hand_target: [f64; 3],
    drive: [f64; 3],
    paused: bool,
    device: DeviceParams,
    kin: TwinKinematics,
    offset: [f64; 2],
}

impl Demo {
    fn load(
        name: &'static str,
        rate: f64,
        wall_law: &'static str,
        friction: &'static str,
        controller: ControllerKind,
    ) -> Result<(Self, SceneInfo), String> {
        let scene = haptic2d::scene::builtin(name, Some(rate))
            .ok_or(format!("no built-in scene `{name}`"))?
            .map_err(|e| e.to_string())?;
        let mut world = scene.world;
        let slave = world
            .body_index("box")
            .or_else(|| world.bodies.iter().position(|b| b.is_dynamic()));
        if let Some(s) = slave {
            world.loads.retain(|l| l.body != s);
        }
        if !wall_law.is_empty() {
            world.normal = NormalModel::from_name(wall_law, true)?;
        }
        if !friction.is_empty() {
            world.friction = FrictionModel::from_name(friction, true)?;
        }
        let hand_target = slave.map_or([0.0; 3], |s| {
            let p = world.bodies[s].pose;
            [p.pos.x, p.pos.y, p.angle]
        });
        let device = DeviceParams::default();
        let offset = [
            hand_target[0] - device.workspace_center_x,
            hand_target[1] - device.workspace_center_y,
        ];
        let info = SceneInfo::from_world(
            &world,
            &scene.name,
            &scene.description,
            slave,
            Some((&device, offset)),
        );
        let dt = world.params.dt;
        Ok((
            Self {
                rate,
                scene_name: name,
                wall_law: world.normal.name(),
                friction: world.friction.name(),
                world,
                slave,
                controller: Controller::new(controller, dt)?,
                hand_target,
                drive: [0.0; 3],
                paused: false,
                kin: TwinKinematics::new(&device),
                device,
                offset,
            },
            info,
        ))
    }

    /// Applies one command from the page (the semantics documented on [`Command`]).
    fn apply(&mut self, cmd: Command, hub: &mut ViewHub) {
        let reload = |d: &Self, name: &'static str, c: ControllerKind| {
            Self::load(name, d.rate, d.wall_law, d.friction, c)
        };
        let result = match cmd {
            Command::SetHandTarget { x, y, theta } => {
                self.hand_target = [x, y, theta];
                Ok(None)
            }
            Command::SwitchScene { name } => reload(self, name, self.controller.kind()).map(Some),
            Command::Reset => reload(self, self.scene_name, self.controller.kind()).map(Some),
            Command::SetWallLaw { name } => NormalModel::from_name(name, true).map(|m| {
                self.world.normal = m;
                self.wall_law = m.name();
                None
            }),
            Command::SetFriction { name } => FrictionModel::from_name(name, true).map(|m| {
                self.world.friction = m;
                self.friction = m.name();
                None
            }),
            Command::SetImpactFriction { name } => {
                haptic2d::contact::ImpactFriction::from_name(name).map(|m| {
                    self.world.set_impact_friction(m);
                    None
                })
            }
            Command::SetController { kind } => {
                Controller::new(kind, self.world.params.dt).map(|c| {
                    self.controller = c;
                    None
                })
            }
            Command::Pause => {
                self.paused = true;
                Ok(None)
            }
            Command::Resume => {
                self.paused = false;
                Ok(None)
            }
            Command::Answer { .. }
            | Command::Magnitude { .. }
            | Command::ContinueStudy { .. }
            | Command::StopStudy => {
                Err("no study is running (haptic2d study run --observer browser)".to_string())
            }
        };
        match result {
            Ok(Some((mut fresh, info))) => {
                fresh.paused = self.paused;
                *self = fresh;
                if let Err(e) = hub.publish_scene(info) {
                    eprintln!("haptic2d-view-demo: {e}");
                }
            }
            Ok(None) => {}
            Err(e) => eprintln!("haptic2d-view-demo: {} failed: {e}", cmd.kind()),
        }
    }

    /// One tick of the world: contacts, controller drive on the slave, integration.
    fn step(&mut self) {
        self.world.begin_step();
        if let Some(s) = self.slave {
            let b = &self.world.bodies[s];
            let w = self.world.contact_wrench(s);
            let sig = TeleopSignals {
                x_m: self.hand_target,
                v_m: [0.0; 3],
                f_h: [0.0; 3],
                x_s: [b.pose.pos.x, b.pose.pos.y, b.pose.angle],
                v_s: [b.vel.x, b.vel.y, b.omega],
                f_e: [-w.force.x, -w.force.y, -w.torque],
                master_mass: [[0.0; 3]; 3],
            };
            self.drive = self.controller.drive(&sig);
            let f = haptic2d::geom::Vec2::new(self.drive[0], self.drive[1]);
            self.world.set_drive(s, f, self.drive[2]);
        }
        self.world.finish_step();
    }

    fn inputs(&self, timing: &LiveTiming) -> FrameInputs<'_> {
        let t = self.hand_target;
        FrameInputs {
            paused: self.paused,
            slave: self.slave,
            hand_target: t,
            drive: self.drive,
            device: Some((
                &self.kin,
                [t[0] - self.offset[0], t[1] - self.offset[1], t[2]],
            )),
            device_to_world: self.offset,
            passivity_energy: None,
            timing: timing.snapshot(),
            controller: self.controller.kind().name(),
        }
    }
}

fn run() -> Result<(), String> {
    let args = parse_args()?;
    let (mut demo, info) = Demo::load(
        "box-in-walls",
        args.rate,
        "",
        "none",
        ControllerKind::Coupling,
    )?;
    let _ = demo.device.validate();
    let (mut hub, end) = ViewHub::new(&Frame::for_world(&demo.world), DEFAULT_FRAME_RATE_HZ)?;
    hub.publish_scene(info)?;
    let server = ViewServer::start(
        args.bind,
        end,
        ViewOptions {
            require_token: args.require_token || args.token.is_some(),
            token: args.token.clone(),
            // Off the loop's thread, before it starts: which scenes fit the period.
            scene_costs: assess_builtin_scenes(args.rate, DEFAULT_STEP_FRACTION),
            ..ViewOptions::default()
        },
    )?;
    println!("{}", server.banner());
    let _ = std::io::stdout().flush();

    let stop = haptic2d_rt::signal::install_ctrlc_stop()
        .unwrap_or_else(|_| std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false)));
    let config = LoopConfig {
        rate_hz: args.rate,
        duration: args.duration.map(Duration::from_secs_f64),
        ..LoopConfig::default()
    };
    let mut timing = LiveTiming::new(args.rate, 1.0)?;
    let summary = haptic2d_rt::run_loop(&config, &stop, |info| {
        while let Some(cmd) = hub.poll_command() {
            demo.apply(cmd, &mut hub);
        }
        if !demo.paused {
            demo.step();
        }
        if hub.frame_due(info.t_s) {
            let inputs = demo.inputs(&timing);
            hub.publish_frame(info.t_s, &demo.world, &inputs);
        }
        timing.record_tick(&info, now_ns());
        TickControl::Continue
    })?;
    println!("{summary}");
    server.shutdown();
    Ok(())
}

fn main() {
    if let Err(e) = run() {
        eprintln!("haptic2d-view-demo: {e}");
        std::process::exit(2);
    }
}
