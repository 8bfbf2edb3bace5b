//! The live display of `haptic2d run`: the loop's side of `haptic2d-view`.
//!
//! [`start`] binds the display server (a taken port is an error here, before the loop starts) and
//! returns the [`LiveView`] that the loop thread owns. Every tick the loop calls
//! [`LiveView::apply_commands`] before reading the device (the page's commands take effect between
//! ticks, with the semantics documented on [`haptic2d_view::Command`]), and
//! [`LiveView::after_tick`] at the end (a ~60 Hz frame when someone watches, and the tick's
//! timing). Both are wait-free and allocation-free in steady state; only a scene switch or reset
//! allocates (a new world), accepting one late tick.

use crate::run_rig::Rig;
use haptic2d::haptic::ControllerKind as SystemController;
use haptic2d::laws::friction::FrictionModel;
use haptic2d::laws::normal::NormalModel;
use haptic2d::scene::{builtin, BUILTIN};
use haptic2d::world::World;
use haptic2d_rt::clock::now_ns;
use haptic2d_rt::TickInfo;
use haptic2d_view::{
    Command, Frame, FrameInputs, LiveTiming, SceneInfo, ViewHandle, ViewHub, ViewOptions,
    ViewServer, DEFAULT_FRAME_RATE_HZ,
};
use std::net::SocketAddr;

/// The scene the loop runs, as loaded (the world at its initial state, kept for resets).
pub struct LoadedScene {
    /// Scene name.
    pub name: String,
    /// One-line description.
    pub description: String,
    /// The world at its initial state.
    pub world: World,
}

/// The loop thread's end of the display.
pub struct LiveView {
    hub: ViewHub,
    timing: LiveTiming,
    rate: f64,
    scene: LoadedScene,
    /// Wall law and friction model the page selected (kept across resets and scene switches);
    /// `None` = the scene's own.
    wall_law: Option<NormalModel>,
    friction: Option<FrictionModel>,
    paused: bool,
}

/// Starts the display server on `bind` for the rig's current scene `scene` at `rate` (Hz). Returns
/// the server handle (keep it on the main thread; dropping it stops the server) and the loop's end.
pub fn start(
    bind: SocketAddr,
    rig: &Rig,
    scene: LoadedScene,
    rate: f64,
) -> Result<(ViewHandle, LiveView), String> {
    // Frames are preallocated for the largest scene the page can switch to, so that capturing never
    // allocates, not even after a switch.
    let mut bodies = rig.system.world().bodies.len();
    for (name, _, _) in BUILTIN {
        if let Some(Ok(s)) = builtin(name, Some(rate)) {
            bodies = bodies.max(s.world.bodies.len());
        }
    }
    let prototype = Frame::with_capacity(bodies, haptic2d_view::frame::MAX_FRAME_CONTACTS);
    let (hub, end) = ViewHub::new(&prototype, DEFAULT_FRAME_RATE_HZ)?;
    let server = ViewServer::start(bind, end, ViewOptions::default())?;
    let mut view = LiveView {
        hub,
        timing: LiveTiming::new(rate, 1.0)?,
        rate,
        scene,
        wall_law: None,
        friction: None,
        paused: false,
    };
    view.publish_scene(rig);
    Ok((server, view))
}

impl LiveView {
    /// True while the page has paused the world.
    #[inline]
    pub fn paused(&self) -> bool {
        self.paused
    }

    /// Applies every command the page sent since the last tick. Wait-free and allocation-free
    /// except for a scene switch or reset.
    #[inline]
    pub fn apply_commands(&mut self, rig: &mut Rig) {
        while let Some(cmd) = self.hub.poll_command() {
            if let Err(e) = self.apply(cmd, rig) {
                eprintln!("display: {} failed: {e}", cmd.kind());
            }
        }
    }

    /// Publishes a frame when one is due and someone watches, then records the tick's timing (call
    /// it last in the tick). Allocation-free.
    #[inline]
    pub fn after_tick(&mut self, info: &TickInfo, rig: &Rig) {
        if self.hub.frame_due(info.t_s) {
            let sys = &rig.system;
            let rec = sys.last_record();
            let inputs = FrameInputs {
                paused: self.paused,
                slave: Some(sys.slave()),
                hand_target: rig.hand_target_world(),
                drive: rec.f_cs,
                device: Some((&sys.device().kin, rec.x_m)),
                device_to_world: rig.device_to_world(),
                passivity_energy: sys.passivity().map(|p| p.e_obs()),
                timing: self.timing.snapshot(),
                controller: rig.config.controller.name(),
            };
            self.hub.publish_frame(info.t_s, sys.world(), &inputs);
        }
        self.timing.record_tick(info, now_ns());
    }

    fn apply(&mut self, cmd: Command, rig: &mut Rig) -> Result<(), String> {
        match cmd {
            Command::SetHandTarget { x, y, theta } => {
                // Ignored without a `follow` hand (a replay, or a scripted/free hand).
                let _ = rig.set_hand_target([x, y, theta]);
            }
            Command::SwitchScene { name } => {
                let s = builtin(name, Some(self.rate))
                    .ok_or_else(|| format!("no built-in scene `{name}`"))?
                    .map_err(|e| e.to_string())?;
                let scene = LoadedScene {
                    name: s.name,
                    description: s.description,
                    world: s.world,
                };
                self.load(scene.world.clone(), rig)?;
                self.scene = scene;
                self.publish_scene(rig);
            }
            Command::Reset => {
                self.load(self.scene.world.clone(), rig)?;
                self.publish_scene(rig);
            }
            Command::SetWallLaw { name } => {
                let m = NormalModel::from_name(name, true)?;
                rig.system.world_mut().normal = m;
                self.wall_law = Some(m);
            }
            Command::SetFriction { name } => {
                let m = FrictionModel::from_name(name, true)?;
                rig.system.world_mut().friction = m;
                self.friction = Some(m);
            }
            Command::SetController { kind } => {
                let k = SystemController::from_name(kind.name())?;
                rig.system.set_controller(k)?;
                rig.config.controller = k;
            }
            Command::Pause => self.paused = true,
            Command::Resume => self.paused = false,
        }
        Ok(())
    }

    /// Rebuilds the rig around `world` with the page's selected laws (and controller, in the rig's
    /// settings). The paused state is kept.
    fn load(&self, mut world: World, rig: &mut Rig) -> Result<(), String> {
        if let Some(m) = self.wall_law {
            world.normal = m;
        }
        if let Some(m) = self.friction {
            world.friction = m;
        }
        rig.rebuild(world)
    }

    fn publish_scene(&mut self, rig: &Rig) {
        let sys = &rig.system;
        let info = SceneInfo::from_world(
            sys.world(),
            &self.scene.name,
            &self.scene.description,
            Some(sys.slave()),
            Some((&rig.config.device, rig.device_to_world())),
        );
        if let Err(e) = self.hub.publish_scene(info) {
            eprintln!("display: {e}");
        }
    }
}
