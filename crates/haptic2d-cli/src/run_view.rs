//! The live display of `haptic2d run`: the loop's side of `haptic2d-view`.
//!
//! [`start`] binds the display server (a taken port is an error here, before the loop starts) and
//! returns the [`LiveView`] that the loop thread owns. Every tick the loop calls
//! [`LiveView::apply_commands`] before reading the device (the page's commands take effect between
//! ticks, with the semantics documented on [`haptic2d_view::Command`]), and
//! [`LiveView::after_tick`] at the end (a ~60 Hz frame when someone watches, and the tick's
//! timing). Both are wait-free and allocation-free in steady state; only a scene switch or reset
//! allocates (a new world), accepting one late tick.
//!
//! Security (docs/DISPLAY.md): the server accepts commands only from the page it served (or a
//! program, with the token where one is required); the token is required off loopback and, with
//! `--require-token`, on loopback too. Before the loop starts, every built-in scene is run for a
//! short timed trial at the loop's rate ([`haptic2d_view::scene_budget`]); a switch to one whose
//! measured step does not fit the period is refused by the server with the reason (greyed out on
//! the page), and again here.

use crate::run_rig::Rig;
use haptic2d::contact::ImpactFriction;
use haptic2d::haptic::ControllerKind as SystemController;
use haptic2d::laws::friction::FrictionModel;
use haptic2d::laws::normal::NormalModel;
use haptic2d::scene::{builtin, BUILTIN};
use haptic2d::world::World;
use haptic2d_rt::clock::now_ns;
use haptic2d_rt::TickInfo;
use haptic2d_view::scene_budget::assess;
use haptic2d_view::{
    Command, Frame, FrameInputs, LiveTiming, SceneCost, SceneInfo, ViewHandle, ViewHub,
    ViewOptions, ViewServer, DEFAULT_FRAME_RATE_HZ, DEFAULT_STEP_FRACTION,
};
use std::net::SocketAddr;

/// Why a study command is refused by `haptic2d run`.
const NO_STUDY: &str = "no study is running (haptic2d study run --observer browser)";

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
    /// The impact friction mode the page selected (kept likewise); `None` = the scene's own.
    impact_friction: Option<ImpactFriction>,
    paused: bool,
    /// `haptic2d study run --observer browser`: the study loop takes the page's answers and stop
    /// request here (`None` outside a study: they are refused).
    study: Option<StudyInbox>,
    /// Built-in scenes the loop cannot run at its rate, with the reason (the server refuses them
    /// first; this is the loop's own check).
    too_heavy: Vec<(&'static str, String)>,
}

/// Starts the display server on `bind` for the rig's current scene `scene` at `rate` (Hz); with
/// `require_token`, commands need the token on a loopback bind too. Returns the server handle (keep
/// it on the main thread; dropping it stops the server) and the loop's end. Call it before the
/// loop starts: it runs a timed trial of every built-in scene (at most 0.6 s each).
pub fn start(
    bind: SocketAddr,
    rig: &Rig,
    scene: LoadedScene,
    rate: f64,
    require_token: bool,
) -> Result<(ViewHandle, LiveView), String> {
    // Frames are preallocated for the largest scene the page can switch to, so that capturing never
    // allocates, not even after a switch. The same worlds are timed: can the loop run them?
    let mut bodies = rig.system.world().bodies.len();
    let mut costs: Vec<SceneCost> = Vec::new();
    for (name, _, _) in BUILTIN {
        if let Some(Ok(s)) = builtin(name, Some(rate)) {
            bodies = bodies.max(s.world.bodies.len());
            costs.push(assess(name, &s.world, rate, DEFAULT_STEP_FRACTION));
        }
    }
    let too_heavy = costs
        .iter()
        .filter_map(|c| Some((c.name, c.reason.clone()?)))
        .collect();
    let prototype = Frame::with_capacity(bodies, haptic2d_view::frame::MAX_FRAME_CONTACTS);
    let (hub, end) = ViewHub::new(&prototype, DEFAULT_FRAME_RATE_HZ)?;
    let options = ViewOptions {
        require_token,
        scene_costs: costs,
        ..ViewOptions::default()
    };
    let server = ViewServer::start(bind, end, options)?;
    let mut view = LiveView {
        hub,
        timing: LiveTiming::new(rate, 1.0)?,
        rate,
        scene,
        wall_law: None,
        friction: None,
        impact_friction: None,
        paused: false,
        study: None,
        too_heavy,
    };
    view.publish_scene(rig);
    Ok((server, view))
}

/// The page's study commands since the study loop last looked (the hook of `study_browser`).
#[derive(Clone, Copy, Debug, Default)]
pub struct StudyInbox {
    /// The last answer `(trial, choice)` not yet taken.
    pub answer: Option<(u32, u8)>,
    /// The last magnitude estimate `(trial, value)` not yet taken.
    pub magnitude: Option<(u32, f64)>,
    /// The last "continue after the break" `trial` not yet taken.
    pub cont: Option<u32>,
    /// The page asked to stop the session.
    pub stop: bool,
}

impl LiveView {
    /// Accept the page's study commands (answers, stop) from now on; the study loop takes them with
    /// [`take_study`](Self::take_study).
    pub fn enable_study(&mut self) {
        self.study = Some(StudyInbox::default());
    }

    /// The study commands received since the last call (cleared). Wait-free.
    #[inline]
    pub fn take_study(&mut self) -> StudyInbox {
        self.study.map_or_else(StudyInbox::default, |s| {
            self.study = Some(StudyInbox::default());
            s
        })
    }

    /// The study trial shown in the next frames. Wait-free.
    #[inline]
    pub fn set_study_view(&mut self, v: Option<haptic2d_view::StudyView>) {
        self.hub.set_study(v);
    }

    /// Pages connected now.
    #[inline]
    pub fn viewers(&self) -> usize {
        self.hub.viewers()
    }

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
                device: sys.twin_kinematics().map(|k| (k, rec.x_m)),
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
        // A study owns the scene, the laws and the controller: the page cannot change the stimulus.
        if self.study.is_some()
            && matches!(
                cmd,
                Command::SwitchScene { .. }
                    | Command::Reset
                    | Command::SetWallLaw { .. }
                    | Command::SetFriction { .. }
                    | Command::SetImpactFriction { .. }
                    | Command::SetController { .. }
            )
        {
            return Err(
                "refused during a study: the study sets the scene, laws and controller".into(),
            );
        }
        match cmd {
            Command::SetHandTarget { x, y, theta } => {
                // Ignored without a `follow` hand (a replay, or a scripted/free hand).
                let _ = rig.set_hand_target([x, y, theta]);
            }
            Command::SwitchScene { name } => {
                if let Some((_, why)) = self.too_heavy.iter().find(|(n, _)| *n == name) {
                    return Err(why.clone());
                }
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
            Command::SetImpactFriction { name } => {
                let m = ImpactFriction::from_name(name)?;
                rig.system.world_mut().set_impact_friction(m);
                self.impact_friction = Some(m);
            }
            Command::SetController { kind } => {
                let k = SystemController::from_name(kind.name())?;
                rig.set_controller(k)?;
            }
            Command::Pause => self.paused = true,
            Command::Resume => self.paused = false,
            Command::Answer { trial, choice } => {
                let inbox = self.study.as_mut().ok_or(NO_STUDY)?;
                // Two answers in one tick: the first stands, the second is refused by the
                // study loop as an answer outside the answer phase.
                if inbox.answer.is_some() {
                    return Err("one answer per tick: refused".into());
                }
                inbox.answer = Some((trial, choice));
            }
            Command::Magnitude { trial, value } => {
                let inbox = self.study.as_mut().ok_or(NO_STUDY)?;
                if inbox.magnitude.is_some() {
                    return Err("one answer per tick: refused".into());
                }
                inbox.magnitude = Some((trial, value));
            }
            Command::ContinueStudy { trial } => {
                self.study.as_mut().ok_or(NO_STUDY)?.cont = Some(trial);
            }
            Command::StopStudy => self.study.as_mut().ok_or(NO_STUDY)?.stop = true,
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
        if let Some(m) = self.impact_friction {
            world.set_impact_friction(m);
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
            rig.twin_params().map(|p| (p, rig.device_to_world())),
        );
        if let Err(e) = self.hub.publish_scene(info) {
            eprintln!("display: {e}");
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use haptic2d_test_support::alloc::allocations;
    use std::time::Duration;

    haptic2d_test_support::install_counting_allocator!();

    fn until(what: &str, cond: impl Fn() -> bool) {
        haptic2d_test_support::wait_for(what, Duration::from_secs(10), cond);
    }

    /// A simulated rig and the display started for it on a free loopback port, with the built-in
    /// `box-in-walls` scene loaded at 1 kHz.
    fn start_on_box_in_walls() -> (Rig, ViewHandle, LiveView) {
        let scene = builtin("box-in-walls", Some(1000.0)).unwrap().unwrap();
        let loaded = LoadedScene {
            name: scene.name.clone(),
            description: scene.description.clone(),
            world: scene.world.clone(),
        };
        let rig = crate::run_rig::test_rig::sim_rig();
        let (server, view) =
            start("127.0.0.1:0".parse().unwrap(), &rig, loaded, 1000.0, false).unwrap();
        (rig, server, view)
    }

    /// The loop's side of the display — polling commands, the haptic tick, capturing and publishing
    /// frames for a connected viewer, recording timing — allocates nothing in steady state, with the
    /// box held against the wall by the hand target (contacts and the device linkage in every
    /// frame). Ticks are driven by hand here (simulated time), on this thread.
    #[test]
    fn loop_side_of_the_display_does_not_allocate_in_steady_state() {
        let (mut rig, server, mut view) = start_on_box_in_walls();
        let addr = server.local_addr();
        let stream = std::net::TcpStream::connect(addr).unwrap();
        let (mut ws, _) = tungstenite::client(format!("ws://{addr}/ws"), stream).unwrap();
        until("the viewer", || server.stats().viewers == 1);
        ws.send(tungstenite::Message::text(
            r#"{"type":"set_hand_target","x":-0.01,"y":0.0,"theta":0.0}"#,
        ))
        .unwrap();
        until("the command", || server.stats().commands_forwarded == 1);

        let period_ns = 1_000_000;
        let mut k = 0u64;
        let mut pass = |n: u64, view: &mut LiveView, rig: &mut Rig| {
            let before = allocations();
            for _ in 0..n {
                view.apply_commands(rig);
                let q = rig.io.read_encoders().unwrap();
                let out = rig.system.tick(&q, None, false);
                rig.io.write_torques(&out.torques).unwrap();
                let info = TickInfo {
                    index: k,
                    deadline_index: k,
                    t_s: k as f64 * 1e-3,
                    period_s: 1e-3,
                    period_ns,
                    lateness_ns: 0,
                    skipped: 0,
                    deadline_ns: k * period_ns,
                };
                view.after_tick(&info, rig);
                k += 1;
            }
            allocations() - before
        };
        pass(3000, &mut view, &mut rig);
        let allocs = pass(2000, &mut view, &mut rig);
        let w = rig.system.world();
        assert!(
            w.contacts().contact_count() > 0,
            "the box is against the wall"
        );
        assert!(w.bodies[rig.system.slave()].pose.pos.x < 0.025);
        assert_eq!(allocs, 0, "allocations in steady state");
        drop(ws);
        server.shutdown();
    }

    /// A WebSocket to the display with the `Origin` header a browser would send for a page there.
    fn connect_from(addr: SocketAddr, origin: &str) -> tungstenite::WebSocket<std::net::TcpStream> {
        use tungstenite::client::IntoClientRequest;
        let mut req = format!("ws://{addr}/ws").into_client_request().unwrap();
        req.headers_mut().insert("origin", origin.parse().unwrap());
        let stream = std::net::TcpStream::connect(addr).unwrap();
        tungstenite::client(req, stream).unwrap().0
    }

    /// Issue 11: a page from another origin open in the user's browser switched the controller,
    /// the wall law (to the active `zoh`) and the scene (to `pile`) of `haptic2d run`. Now its
    /// commands never reach the loop: after the loop drains its commands, the controller, wall law,
    /// scene and paused state are what they were; the page's own origin still commands it.
    #[test]
    fn cross_origin_page_cannot_change_the_running_loop() {
        let (mut rig, server, mut view) = start_on_box_in_walls();
        let addr = server.local_addr();
        let before = (
            rig.config.controller.name(),
            rig.system.world().normal.name(),
            view.scene.name.clone(),
        );
        let mut evil = connect_from(addr, "http://evil.example");
        let attack = [
            r#"{"type":"set_controller","name":"coupling"}"#,
            r#"{"type":"set_wall_law","name":"zoh"}"#,
            r#"{"type":"switch_scene","name":"pile"}"#,
            r#"{"type":"pause"}"#,
        ];
        for cmd in attack {
            evil.send(tungstenite::Message::text(cmd)).unwrap();
        }
        until("the refusals", || {
            server.stats().bad_messages >= attack.len() as u64
        });
        view.apply_commands(&mut rig);
        assert_eq!(server.stats().commands_forwarded, 0);
        assert_eq!(
            (
                rig.config.controller.name(),
                rig.system.world().normal.name(),
                view.scene.name.clone(),
            ),
            before
        );
        assert!(!view.paused());

        let mut page = connect_from(addr, &format!("http://{addr}"));
        page.send(tungstenite::Message::text(
            r#"{"type":"set_wall_law","name":"zoh"}"#,
        ))
        .unwrap();
        until("the command", || server.stats().commands_forwarded == 1);
        view.apply_commands(&mut rig);
        assert_eq!(rig.system.world().normal.name(), "zoh");
        // The impact friction switch (issue 16) reaches the world and survives a reset.
        page.send(tungstenite::Message::text(
            r#"{"type":"set_impact_friction","name":"coulomb"}"#,
        ))
        .unwrap();
        page.send(tungstenite::Message::text(r#"{"type":"reset"}"#))
            .unwrap();
        until("the commands", || server.stats().commands_forwarded == 3);
        view.apply_commands(&mut rig);
        assert_eq!(rig.system.world().impact_friction().name(), "coulomb");
        drop((evil, page));
        server.shutdown();
    }
}
