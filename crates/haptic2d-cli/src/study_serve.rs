//! `haptic2d study serve FILE`: the real-time loop of the browser study (the same rig, watchdog,
//! safety latch and display) driven by one local client over TCP, e.g. a Python/PsychoPy script
//! through `haptic2d.StudyServer` (docs/STUDIES.md, "Driving trials from Python or PsychoPy on the
//! device"; the protocol is in `serve_conn.rs`).
//!
//! The main thread accepts one client at a time on a **loopback** address (any other bind is
//! refused: there is no key), reads its JSON lines, builds each stimulus and hands it to the loop
//! thread through a wait-free ring; the loop thread runs the haptic tick with the
//! [`ServePresenter`] in it (stimulus switches in free space, the interval, the measures) and
//! reports back through another ring. The tick allocates nothing and takes no lock.
//!
//! The client's `stop` zeroes the torques, stops the loop and exits 0. A SIGINT or SIGTERM, the
//! page's stop button, a lost device or a safety stop end the loop as in `haptic2d run` (torques
//! zeroed and latched; exit 130, 0, 4 or 3), and the pending presentation is answered with the
//! reason.

use crate::exit::{Failure, Status};
use crate::hand_arg::HandSpec;
use crate::loop_end::LoopEnd;
use crate::run_rig::{DeviceChoice, Rig};
use crate::run_view::{self, LiveView, LoadedScene};
use crate::serve_conn::{Action, Protocol, MAX_LINE};
use crate::serve_present::{FromLoop, ServePresenter, ToLoop};
use crate::study_browser::{self, BrowserOptions};
use crate::study_mcap::{self, TrialLogger, TrialTap};
use haptic2d_lab::study::Study;
use haptic2d_rt::signal::install_stop_signals;
use haptic2d_rt::{TickControl, TickInfo, Watchdog};
use haptic2d_view::ViewHandle;
use serde_json::Value;
use std::io::{ErrorKind, Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Duration;

/// The options of `haptic2d study serve`.
#[derive(Clone, Debug)]
pub struct ServeOptions {
    /// The device and the display, as the browser study's (`bind` is the page's address).
    pub rig: BrowserOptions,
    /// `--hand` (simulated device only).
    pub hand: Option<String>,
    /// `--listen`: the client's address (loopback only).
    pub listen: String,
    /// `--out`: one MCAP per presentation in `OUT/trials/`.
    pub out: Option<PathBuf>,
    /// `--headless`: no display.
    pub headless: bool,
}

/// Checks `--listen`: an ADDRESS:PORT on loopback (the server has no key, so nothing else).
fn check_listen(listen: &str) -> Result<SocketAddr, Failure> {
    let addr: SocketAddr = listen.parse().map_err(|e| {
        Failure::from(format!(
            "--listen `{listen}` is not an ADDRESS:PORT ({e})\n    fix: e.g. --listen 127.0.0.1:7341"
        ))
    })?;
    if !addr.ip().is_loopback() {
        return Err(format!(
            "--listen {addr}: the study server accepts clients on loopback only (it has no key: anyone who reaches it drives the device)\n    fix: --listen 127.0.0.1:PORT and run the client on this machine"
        )
        .into());
    }
    Ok(addr)
}

/// Checks `--out`: presentations are numbered from 1 in every run, so a `trials/` folder with files
/// in it (an earlier run's) is refused rather than mixed with this run's.
fn check_out(out: &Path) -> Result<(), Failure> {
    let trials = out.join("trials");
    if std::fs::read_dir(&trials).is_ok_and(|mut d| d.next().is_some()) {
        return Err(format!(
            "--out {}: {} already holds logs of an earlier run\n    fix: give a new --out folder",
            out.display(),
            trials.display()
        )
        .into());
    }
    Ok(())
}

/// The `--hand` of the simulated device (`follow` by default); refused for any other device.
fn hand(o: &ServeOptions) -> Result<HandSpec, Failure> {
    let sim = DeviceChoice::parse(&o.rig.device)? == DeviceChoice::Sim;
    match (&o.hand, sim) {
        (None, _) => Ok(HandSpec::Follow),
        (Some(h), true) => Ok(HandSpec::parse(h)?),
        (Some(_), false) => Err("--hand applies to the simulated device only: on a real device the participant's hand is the hand\n    fix: leave --hand out".into()),
    }
}

/// The display page (unless `--headless`), the study owning the stimulus: the page cannot switch
/// the scene or the laws.
fn start_view(
    o: &ServeOptions,
    rig: &Rig,
    loaded: LoadedScene,
    rate: f64,
) -> Result<(Option<ViewHandle>, Option<LiveView>), Failure> {
    if o.headless {
        return Ok((None, None));
    }
    let bind = o.rig.bind.parse::<SocketAddr>().map_err(|e| {
        Failure::from(format!(
            "--bind `{}`: {e}\n    fix: e.g. --bind 127.0.0.1:8080",
            o.rig.bind
        ))
    })?;
    let (server, mut view) = run_view::start(bind, rig, loaded, rate, o.rig.require_token)?;
    crate::outln!("{}", server.banner());
    view.enable_study();
    Ok((Some(server), Some(view)))
}

/// The per-presentation MCAP logs in `out/trials/` (`--out`), each naming the study and the device.
fn start_logs(
    out: &Path,
    study: &Study,
    text: &str,
    rig: &Rig,
    o: &ServeOptions,
    rate: f64,
) -> Result<(TrialTap, TrialLogger), Failure> {
    check_out(out)?;
    let scene = crate::run_log::scene_strings(
        &study.scene_source,
        &study.name,
        o.rig.device_file.as_deref(),
        &[
            ("rate_hz", rate.to_string()),
            ("command", "study serve".into()),
            ("device", o.rig.device.clone()),
            ("study_toml", text.to_string()),
        ],
    );
    Ok(study_mcap::start(out, rig.system.world(), scene, rate)?)
}

/// Runs the server until the client's `stop`, a signal, the page's stop or the loop's end.
pub fn run(file: &Path, o: &ServeOptions) -> Result<Status, Failure> {
    let listen = check_listen(&o.listen)?;
    let hand = hand(o)?;
    let (study, text) = Study::read(file).map_err(Failure::from)?;
    let (mut rig, loaded, rate) = study_browser::build_rig(&study, &o.rig, hand)?;
    let listener = TcpListener::bind(listen)
        .and_then(|l| l.set_nonblocking(true).map(|_| l))
        .map_err(|e| Failure::from(format!("cannot listen on {listen}: {e}")))?;
    let local = listener.local_addr().map_err(|e| e.to_string())?;
    let (server, view) = start_view(o, &rig, loaded, rate)?;
    let stop = install_stop_signals()?;
    let watchdog = Watchdog::new(rig.watchdog_config())?;
    let loop_config = study_browser::study_loop_config(rate, o.rig.no_rt)?;
    let (tap, logger, trials_dir) = match &o.out {
        Some(out) => {
            let (tap, logger) = start_logs(out, &study, &text, &rig, o, rate)?;
            (Some(tap), Some(logger), Some(out.join("trials")))
        }
        None => (None, None, None),
    };
    let (to_tx, to_rx) = rtrb::RingBuffer::<ToLoop>::new(4);
    let (from_tx, from_rx) = rtrb::RingBuffer::<FromLoop>::new(16);
    let world = rig.system.world();
    let neutral = (world.normal, world.friction);
    let device = rig.io.name().to_string();
    crate::outln!("study server: listening on {local}");
    eprintln!(
        "study `{}` on device {device}, {rate} Hz: one client at a time on {local} (JSON lines: present, end, status, stop); Ctrl-C stops",
        study.name
    );
    let ended = AtomicBool::new(false);
    let t_bits = AtomicU64::new(0);
    let mut state = ServeLoop {
        rig: &mut rig,
        view,
        watchdog,
        presenter: ServePresenter::new(neutral),
        commands: to_rx,
        reports: from_tx,
        tap,
        end: None,
        page_stop: false,
        t_bits: &t_bits,
    };
    let mut proto = Protocol::new(&study, to_tx, trials_dir, device);
    let mut link = Link {
        listener,
        client: None,
        reports: from_rx,
    };
    let serve = || link.serve(&mut proto, &ended, &stop, &t_bits);
    let beside =
        study_browser::beside_the_loop(&loop_config, &stop, &ended, |i| state.tick(&i), serve);
    // A loop that could not start serves nobody: the session ends as if interrupted.
    let (client_stop, timing) = beside.unwrap_or((false, None));
    // Zero torques before anything else.
    state.rig.io.zero_torques();
    let (end, page_stop) = (state.end.take(), state.page_stop);
    drop(state);
    if let Some(s) = server {
        s.shutdown();
    }
    let (status, why) = match end {
        Some(end) => study_browser::loop_end_status(end),
        None if client_stop => (Status::Clean, "stopped by the client".into()),
        None if page_stop => (Status::Clean, "stopped from the page".into()),
        None => (
            Status::Interrupted,
            "interrupted by a signal (SIGINT or SIGTERM)".into(),
        ),
    };
    // The client hears why the latch tripped, not just that it did.
    let why = match (status, rig.system.safety_trip()) {
        (Status::SafetyStop, Some(trip)) => format!("{why}: {trip}"),
        _ => why,
    };
    let reason = format!("{why}; torques were set to zero");
    link.farewell(&mut proto, &reason, status == Status::Clean && client_stop);
    study_browser::report_trials_and_timing(logger, timing.as_ref().and_then(|t| t.as_ref().ok()));
    crate::outln!("stopped: {reason}");
    Ok(status)
}

/// Everything one tick touches, owned by the loop thread while it runs.
struct ServeLoop<'r> {
    rig: &'r mut Rig,
    view: Option<LiveView>,
    watchdog: Watchdog,
    presenter: ServePresenter,
    commands: rtrb::Consumer<ToLoop>,
    reports: rtrb::Producer<FromLoop>,
    tap: Option<TrialTap>,
    end: Option<LoopEnd>,
    page_stop: bool,
    /// The loop time (s, f64 bits) for `status`.
    t_bits: &'r AtomicU64,
}

impl ServeLoop<'_> {
    /// One tick: the page's commands, the presenter (stimulus switch, interval end), the haptic tick
    /// of `haptic2d run` (device read, system, watchdog, device write), the interval's measures and
    /// the display. Allocation-free in steady state.
    fn tick(&mut self, info: &TickInfo) -> TickControl {
        let mut paused = false;
        if let Some(v) = self.view.as_mut() {
            v.apply_commands(self.rig);
            if v.take_study().stop {
                self.page_stop = true;
                return TickControl::Stop;
            }
            paused = v.paused();
        }
        let slave = self.rig.system.slave();
        let cmd = self.commands.pop().ok();
        let report = self.presenter.before_step(
            cmd,
            self.rig.system.world_mut(),
            slave,
            info.t_s,
            info.period_s,
            paused,
        );
        if let Some(r) = report {
            if let (Some(tap), FromLoop::Started { id, .. }) = (self.tap.as_mut(), r) {
                tap.start(id);
            }
            if let (Some(tap), FromLoop::Done { id, .. }) = (self.tap.as_mut(), r) {
                tap.end(id, 0, 0.0);
            }
            // The ring holds 16 reports and the main thread drains it every 2 ms.
            let _ = self.reports.push(r);
        }
        let stepped = study_browser::haptic_step(
            self.rig,
            &mut self.watchdog,
            self.tap.as_mut(),
            info,
            paused,
        );
        if let Err(end) = stepped {
            self.end = Some(end);
            return TickControl::Stop;
        }
        self.presenter
            .after_step(self.rig.system.world(), slave, info.period_s, paused);
        self.t_bits.store(info.t_s.to_bits(), Ordering::Relaxed);
        if let Some(v) = self.view.as_mut() {
            v.after_tick(info, self.rig);
        }
        TickControl::Continue
    }
}

/// The main thread's network side: the listener, the one client, the loop's reports.
struct Link {
    listener: TcpListener,
    client: Option<Client>,
    reports: rtrb::Consumer<FromLoop>,
}

/// The connected client and its unfinished line.
struct Client {
    stream: TcpStream,
    buf: Vec<u8>,
}

impl Client {
    /// Sends one reply line; false if the client is gone.
    fn send(&mut self, v: &Value) -> bool {
        let mut line = v.to_string();
        line.push('\n');
        self.stream.write_all(line.as_bytes()).is_ok()
    }
}

impl Link {
    /// Serves clients until the client's `stop` (true), the loop's end or a signal (false).
    fn serve(
        &mut self,
        proto: &mut Protocol,
        ended: &AtomicBool,
        stop: &AtomicBool,
        t_bits: &AtomicU64,
    ) -> bool {
        loop {
            if ended.load(Ordering::SeqCst) || stop.load(Ordering::SeqCst) {
                return false;
            }
            let t_s = f64::from_bits(t_bits.load(Ordering::Relaxed));
            // Read before accepting: a client that closed and reconnected at once is seen gone
            // first, so that its new connection is taken, not refused as a second client. The
            // requests it sent before closing are served (a `stop` too); then whatever presentation
            // it left running is ended.
            let (lines, gone) = self.read_lines();
            for line in lines {
                let (replies, action) = proto.request(&line, t_s);
                self.send_all(&replies);
                if action == Action::Stop {
                    return true;
                }
            }
            if gone {
                proto.drop_client();
            }
            self.accept();
            while let Ok(ev) = self.reports.pop() {
                if let Some(reply) = proto.on_report(ev) {
                    self.send_all(&[reply]);
                }
            }
            std::thread::sleep(Duration::from_millis(2));
        }
    }

    /// Takes a waiting connection: the client if none is connected, else refused with a reason.
    fn accept(&mut self) {
        let Ok((mut stream, _)) = self.listener.accept() else {
            return;
        };
        if self.client.is_some() {
            let _ = stream.write_all(
                b"{\"ok\":false,\"cmd\":\"\",\"error\":\"another client is connected: one at a time\"}\n",
            );
            return;
        }
        if stream.set_nonblocking(true).is_ok() {
            let _ = stream.set_nodelay(true);
            self.client = Some(Client {
                stream,
                buf: Vec::new(),
            });
        }
    }

    /// The complete lines the client sent since the last call, and whether the client went away (a
    /// closed, failed or flooding client is dropped).
    fn read_lines(&mut self) -> (Vec<String>, bool) {
        let Some(c) = self.client.as_mut() else {
            return (Vec::new(), false);
        };
        let mut chunk = [0u8; 4096];
        let mut gone = false;
        loop {
            match c.stream.read(&mut chunk) {
                Ok(0) => {
                    gone = true;
                    break;
                }
                Ok(n) => c.buf.extend_from_slice(&chunk[..n]),
                Err(e) if e.kind() == ErrorKind::WouldBlock => break,
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(_) => {
                    gone = true;
                    break;
                }
            }
        }
        let mut lines = Vec::new();
        while let Some(i) = c.buf.iter().position(|&b| b == b'\n') {
            let line: Vec<u8> = c.buf.drain(..=i).collect();
            let s = String::from_utf8_lossy(&line).trim().to_string();
            if !s.is_empty() {
                lines.push(s);
            }
        }
        if c.buf.len() > MAX_LINE {
            let _ = c.send(&serde_json::json!({"ok": false, "cmd": "", "error": format!("a request line is longer than {MAX_LINE} bytes")}));
            gone = true;
        }
        if gone {
            self.client = None;
        }
        (lines, gone)
    }

    fn send_all(&mut self, replies: &[Value]) {
        if let Some(c) = self.client.as_mut() {
            if !replies.iter().all(|r| c.send(r)) {
                self.client = None;
            }
        }
    }

    /// The last words to the client when the server ends: the pending presentation's error, and
    /// (unless the client stopped it and has its reply) why the server ended.
    fn farewell(&mut self, proto: &mut Protocol, reason: &str, client_stopped: bool) {
        // Reports that arrived since the last poll (a presentation that ended just before).
        while let Ok(ev) = self.reports.pop() {
            if let Some(reply) = proto.on_report(ev) {
                self.send_all(&[reply]);
            }
        }
        let mut last = Vec::new();
        if let Some(r) = proto.abandon(reason) {
            last.push(r);
        }
        if !client_stopped {
            last.push(serde_json::json!({"ok": false, "cmd": "server", "error": reason}));
        }
        self.send_all(&last);
        if let Some(c) = self.client.take() {
            let _ = c.stream.shutdown(std::net::Shutdown::Both);
        }
    }
}
