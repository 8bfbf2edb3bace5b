//! `haptic2d serve-world SCENE --bind ADDR --key FILE`: the world side of the haptic loop split at a
//! network (issue 41, docs/TELEOP.md). It waits for one device side (`haptic2d remote-device`) to
//! open an authenticated session, then at every period: reads the newest handle state received,
//! drives the slave body through a virtual coupling to it, with the slave port's TDPA passivity
//! controller (energy in from the device side received with every message), steps the world and
//! sends the coupling's reaction back (as computed, before this port's controller) with its
//! port's energies. With `--link wave` the lab's wave slave ([`WaveSlave`], one per axis) takes
//! the place of the coupling to the received handle: the newest forward wave, within the wave
//! energy the device side sent (and with the budgeted drift compensation to the handle's received
//! position), drives a commanded point that pulls the slave through the coupling; the returning
//! wave goes back. It runs at normal priority (it
//! drives no motor) and ends when the device side says goodbye or falls silent.

use std::net::UdpSocket;
use std::sync::atomic::AtomicBool;
use std::time::Duration;

use haptic2d::control::tdpa::PlanarTdpa;
use haptic2d_devices::world_link::message::{
    link_flags, FLAG_BYE, FLAG_LATCHED, FLAG_TDPA, FLAG_WAVE,
};
use haptic2d_devices::world_link::{
    LinkEndpoint, PortMessage, KIND_TO_DEVICE, KIND_TO_WORLD, PORT_LEN,
};
use haptic2d_lab::network::wave::{WaveMsg, WaveSlave};
use haptic2d_rt::clock::now_ns;
use haptic2d_rt::{run_loop, LoopConfig, TickControl, TickInfo};

use crate::exit::{Failure, Status};
use crate::outln;
use crate::slave_plant::{BodySlave, DeviceSlave, SlavePlant, SlaveStop};
use crate::world_link_arg::{energies, report_link, wave_totals, EndWording};
use crate::world_link_arg::{LinkArgs, LinkStats, Outbox};

/// Why a session ends when the device side runs the other link kind; such an end also says
/// goodbye with this end's link kind (the device side may not have heard any other message).
const LINK_MISMATCH: &str =
    "link mismatch: one end runs wave variables, the other forces (both ends need the same --link)";

/// Examples of `serve-world --help`.
pub const EXAMPLES: &[crate::Example] = &[
    (
        "Serve box-in-walls on port 7420 to a device side holding the same key",
        "haptic2d serve-world box-in-walls --bind 0.0.0.0:7420 --key world.key",
    ),
    (
        "A free loopback port (printed); 25 ms delay, 5 % loss injected on what it sends",
        "haptic2d serve-world box-in-walls --bind 127.0.0.1:0 --key k --delay-ms 25 --loss 0.05",
    ),
    (
        "Without the passivity controller (to see the delayed link create energy)",
        "haptic2d serve-world peg-in-hole --key world.key --no-tdpa",
    ),
];

/// `serve-world`'s options.
#[derive(clap::Args, Debug)]
pub struct ServeWorldArgs {
    /// A scene file path, or a built-in scene name (not with --device).
    #[arg(required_unless_present = "device", conflicts_with = "device")]
    pub scene: Option<String>,
    /// Serve a slave DEVICE instead of a scene's body: `haply:PATH`, `udp:ADDR:PORT`,
    /// `inverse3[:URL]` — the slave of a bilateral teleoperation whose master is
    /// `haptic2d run --device DEV --world udp:HOST:PORT` (docs/TELEOP.md).
    #[arg(long, value_name = "DEVICE")]
    pub device: Option<String>,
    /// The slave device's own device file (with --device).
    #[arg(long, value_name = "FILE.toml", requires = "device")]
    pub device_file: Option<std::path::PathBuf>,
    /// Let a UDP slave device be beyond loopback (with --device).
    #[arg(long, requires = "device")]
    pub allow_remote_device: bool,
    /// Normal scheduling for the loop of a slave device (by default it runs at real-time priority,
    /// as `run` does; a scene's world always runs at normal priority: it drives no motor).
    #[arg(long, requires = "device")]
    pub no_rt: bool,
    /// Address to listen on (`127.0.0.1:0` picks a free port; it is printed).
    #[arg(long, default_value = "127.0.0.1:7420")]
    pub bind: String,
    /// Name of the slave body (default: the first dynamic body).
    #[arg(long, conflicts_with = "device")]
    pub slave: Option<String>,
    /// Loop rate (Hz), overriding the scene's; the device side must run at the same rate.
    #[arg(long, default_value_t = 1000.0)]
    pub rate: f64,
    /// Coupling stiffness (N/m, N/m, N·m/rad) between the received handle and the slave.
    #[arg(long, value_delimiter = ',', num_args = 3, default_values_t = [500.0, 500.0, 1.0])]
    pub coupling_k: Vec<f64>,
    /// Coupling damping (N·s/m, N·s/m, N·m·s/rad).
    #[arg(long, value_delimiter = ',', num_args = 3, default_values_t = [5.0, 5.0, 0.01])]
    pub coupling_b: Vec<f64>,
    /// Wait at most this long (s) for a device side to open a session.
    #[arg(long, default_value_t = 30.0)]
    pub accept_timeout: f64,
    /// Stop after this long (s); default: when the device side closes or falls silent for 2 s.
    #[arg(long)]
    pub duration: Option<f64>,
    #[command(flatten)]
    pub link: LinkArgs,
}

/// The world side's state, owned by the loop.
struct WorldSide {
    /// The slave: the scene's body, or a device (`--device`).
    plant: SlavePlant,
    alpha_max: [f64; 3],
    k: [f64; 3],
    b: [f64; 3],
    tdpa: bool,
    /// The wave slave per axis with `--link wave`, and what it sent last.
    wave: Option<[WaveSlave; 3]>,
    wave_out: [WaveMsg; 3],
    ports: PlanarTdpa,
    /// The port's energy as the slave body really received it: the applied force times its
    /// displacement over the world step.
    plant_ledger: PlanarTdpa,
    ep: LinkEndpoint,
    outbox: Outbox,
    stats: LinkStats,
    timeout_periods: u64,
    last: Option<PortMessage>,
    last_k: u64,
    last_arrival_ns: u64,
    seq: u32,
    buf: [u8; PORT_LEN],
    /// Periods with a live link, and the largest coupling force (N).
    live_ticks: u64,
    max_force: f64,
    /// Periods with the slave in contact, and the sums of the wall force on it, the coupling
    /// force and their difference in magnitude (N).
    contact: (u64, f64, f64, f64),
    /// The device side's TDPA flag, as last received.
    peer_tdpa: Option<bool>,
    /// The device side's wave flag, as last received.
    peer_wave: Option<bool>,
    end: Option<&'static str>,
}

impl WorldSide {
    /// The device side's newest message this period, if one arrived: kept as the last, with the
    /// link's statistics and the peer's link kind; a goodbye or a link mismatch ends the session.
    fn receive(&mut self, k: u64) -> Option<PortMessage> {
        let fresh = self.ep.poll(KIND_TO_WORLD);
        if let Some(m) = fresh {
            let now = now_ns();
            self.stats.arrived(now, m.echo_time_ns, m.echo_age_ns);
            (self.last, self.last_k, self.last_arrival_ns) = (Some(m), k, now);
            self.peer_tdpa = Some(m.flags & FLAG_TDPA != 0);
            let peer_wave = m.flags & FLAG_WAVE != 0;
            self.peer_wave = Some(peer_wave);
            if m.flags & FLAG_BYE != 0 {
                self.end = Some("the device side closed the session");
            } else if peer_wave != self.wave.is_some() {
                self.end = Some(LINK_MISMATCH);
            }
        }
        fresh
    }

    fn tick(&mut self, info: &TickInfo) -> TickControl {
        let (k, dt) = (info.deadline_index, info.period_s);
        let fresh = self.receive(k);
        let silent = k.saturating_sub(self.last_k);
        let sensed = self.plant.sense(info);
        let (x_s, v_s) = sensed.unwrap_or(([0.0; 3], [0.0; 3]));
        let live = self.last.is_some()
            && silent <= self.timeout_periods
            && self.end.is_none()
            && sensed.is_some();
        let (mut f_s, mut f_c) = ([0.0; 3], [0.0; 3]);
        let far = self.last.map_or([0.0; 3], |m| m.energy_in);
        if let (true, Some(ws)) = (live, &mut self.wave) {
            // Waves: the newest forward wave (once) drives the commanded point x_d, which pulls
            // the body through the coupling.
            for i in 0..3 {
                let msg = fresh.map(|m| WaveMsg {
                    wave: m.wave[i],
                    energy: m.wave_energy[i],
                    x: m.wave_x[i],
                });
                let st = ws[i].step(msg, x_s[i], v_s[i], self.k[i], self.b[i], dt);
                (f_s[i], self.wave_out[i]) = (st.force, st.msg);
            }
            f_c = f_s;
            self.live_ticks += 1;
            self.max_force = self.max_force.max(f_s[0].hypot(f_s[1]));
        } else if let (true, Some(m)) = (live, self.last) {
            f_c = std::array::from_fn(|i| {
                self.k[i] * (m.pose[i] - x_s[i]) + self.b[i] * (m.twist[i] - v_s[i])
            });
            f_s = if self.tdpa {
                self.ports.control(&f_c, &v_s, &far, dt, &self.alpha_max)
            } else {
                f_c
            };
            self.live_ticks += 1;
            self.max_force = self.max_force.max(f_s[0].hypot(f_s[1]));
        }
        let applied = self.plant.apply(info, &f_s, &x_s);
        if applied.exact {
            self.plant_ledger.observe(&applied.force, &applied.rate, dt);
        }
        let coupling = applied.force[0].hypot(applied.force[1]);
        if let (true, Some(wall)) = (live, applied.wall.filter(|w| *w > 0.01)) {
            let c = &mut self.contact;
            *c = (
                c.0 + 1,
                c.1 + wall,
                c.2 + coupling,
                c.3 + (wall - coupling).abs(),
            );
        }
        // The port books what the slave really received: a body's force held over the world step
        // times its displacement over it (the world knows it at once; booked on the velocity at
        // the start of the step instead, the controller's damping near its cap `2m/T` counted as
        // dissipated what the body did not lose, docs/TELEOP.md); a device's applied force (after
        // its ramp, saturation and gate) times its twist.
        if self.tdpa {
            self.ports.book(&applied.force, &applied.rate, dt);
        } else {
            self.ports.observe(&applied.force, &applied.rate, dt);
        }
        self.seq = self.seq.wrapping_add(1);
        let now = now_ns();
        let msg = PortMessage {
            seq: self.seq,
            flags: self.method_flags(),
            time_ns: now,
            echo_time_ns: self.last.map_or(0, |m| m.time_ns),
            echo_age_ns: u32::try_from(now.saturating_sub(self.last_arrival_ns))
                .unwrap_or(u32::MAX),
            echo_seq: self.last.map_or(0, |m| m.seq),
            pose: x_s,
            twist: v_s,
            // The coupling's reaction as computed: the handle feels the coupling's stretch even
            // while this port's controller holds the slave back (the master port's own
            // controller limits what comes out there).
            force: f_c.map(|f| -f),
            energy_in: self.ports.energy_in(),
            energy_out: self.ports.energy_out(),
            wave: self.wave_out.map(|o| o.wave),
            wave_energy: self.wave_out.map(|o| o.energy),
            wave_x: self.wave_out.map(|o| o.x),
        };
        let buf = &mut self.buf;
        (self.outbox).seal_and_send(&mut self.ep, &msg, KIND_TO_DEVICE, k, buf);
        if sensed.is_some_and(|(x, _)| !x.iter().all(|v| v.is_finite())) {
            self.end = Some("the world diverged (non-finite slave pose)");
        }
        if self.plant.stop().is_some() && self.end.is_none() {
            self.end = Some("the slave device stopped");
        }
        if self.end.is_none() && silent as f64 * dt > 2.0 {
            self.end = Some("the device side fell silent for 2 s");
        }
        if self.end.is_some() {
            TickControl::Stop
        } else {
            TickControl::Continue
        }
    }
}

impl WorldSide {
    /// `FLAG_TDPA` or `FLAG_WAVE` as this end runs.
    fn method_flags(&self) -> u32 {
        link_flags(self.tdpa, self.wave.is_some())
    }

    /// Tells the device side the session is over and latched (three times, past the impairment),
    /// with this end's link kind: a slave device that stopped stops its master at once rather
    /// than after its link timeout, and a device side running the other link kind hears why even
    /// when this end stops before any of its delayed messages left the impairment queue.
    fn bye(&mut self) {
        for _ in 0..3 {
            self.seq = self.seq.wrapping_add(1);
            let msg = PortMessage {
                seq: self.seq,
                flags: FLAG_BYE | FLAG_LATCHED | self.method_flags(),
                time_ns: now_ns(),
                energy_in: self.ports.energy_in(),
                energy_out: self.ports.energy_out(),
                ..PortMessage::default()
            };
            msg.seal(
                self.ep.key(),
                KIND_TO_DEVICE,
                self.ep.session(),
                &mut self.buf,
            );
            self.ep.send(&self.buf);
        }
    }
}

fn check_gains(name: &str, v: &[f64]) -> Result<[f64; 3], String> {
    if v.len() != 3 || !v.iter().all(|x| x.is_finite() && *x >= 0.0) {
        return Err(format!(
            "{name} needs three finite numbers ≥ 0 (x, y, θ), got {v:?}\n    fix: e.g. {name} 500,500,1"
        ));
    }
    Ok([v[0], v[1], v[2]])
}

/// Runs `serve-world`.
pub fn run(a: &ServeWorldArgs) -> Result<Status, Failure> {
    let key = a.link.key().map_err(Failure::from)?;
    let (k, b) = (
        check_gains("--coupling-k", &a.coupling_k).map_err(Failure::from)?,
        check_gains("--coupling-b", &a.coupling_b).map_err(Failure::from)?,
    );
    let dt = 1.0 / a.rate;
    let (plant, what) = match &a.device {
        Some(d) => slave_device(a, d, dt)?,
        None => slave_body(a)?,
    };
    let socket = UdpSocket::bind(&a.bind)
        .map_err(|e| Failure::error(format!("cannot listen on {}: {e}", a.bind)))?;
    let local = socket
        .local_addr()
        .map_err(|e| Failure::error(e.to_string()))?;
    outln!(
        "serve-world: {what}, {} Hz, link {}, impairment: {}",
        a.rate,
        a.link.method(),
        a.link.describe(a.rate)
    );
    outln!("serve-world: listening on {local}");
    let stop = haptic2d_rt::signal::install_stop_signals().map_err(Failure::error)?;
    let ep = LinkEndpoint::accept(
        socket,
        &key,
        Duration::from_secs_f64(a.accept_timeout.max(0.0)),
        &stop,
    )
    .map_err(Failure::error)?;
    outln!(
        "serve-world: session {:016x} with {}",
        ep.session(),
        ep.peer()
    );
    let mut side = WorldSide {
        alpha_max: plant.alpha_max(dt),
        plant,
        k,
        b,
        tdpa: a.link.tdpa(),
        wave: a.link.wave().map(|w| w.map(|p| WaveSlave::new(p, 0.0))),
        wave_out: [WaveMsg::default(); 3],
        ports: PlanarTdpa::default(),
        plant_ledger: PlanarTdpa::default(),
        outbox: a.link.outbox(a.rate),
        stats: LinkStats::with_capacity(((a.duration.unwrap_or(600.0) + 5.0) * a.rate) as usize),
        ep,
        timeout_periods: (a.link.link_timeout_ms * 1e-3 * a.rate).ceil() as u64,
        last: None,
        last_k: 0,
        last_arrival_ns: 0,
        seq: 0,
        buf: [0; PORT_LEN],
        live_ticks: 0,
        max_force: 0.0,
        contact: (0, 0.0, 0.0, 0.0),
        peer_tdpa: None,
        peer_wave: None,
        end: None,
    };
    let config = LoopConfig {
        rate_hz: a.rate,
        duration: a.duration.map(Duration::from_secs_f64),
        rt: a.device.is_some() && !a.no_rt,
        spin_us: 100.0,
        ..LoopConfig::default()
    };
    let summary =
        run_loop(&config, &stop as &AtomicBool, |info| side.tick(&info)).map_err(Failure::error)?;
    side.plant.zero();
    if side.plant.stop().is_some() || side.end == Some(LINK_MISMATCH) {
        side.bye();
    }
    report(&mut side, &summary);
    Ok(match (side.end, side.plant.stop()) {
        (_, Some(SlaveStop::Safety(_))) => Status::SafetyStop,
        (_, Some(SlaveStop::Lost(_))) => Status::DeviceLost,
        (Some(e), _) if e.contains("diverged") => Status::Diverged,
        _ if stop.load(std::sync::atomic::Ordering::Relaxed) => Status::Interrupted,
        _ => Status::Clean,
    })
}

/// The scene's slave body, with the start line's description.
fn slave_body(a: &ServeWorldArgs) -> Result<(SlavePlant, String), Failure> {
    let source = a.scene.as_deref().unwrap_or_default();
    let scene = crate::scene_arg::load(source, Some(a.rate)).map_err(Failure::from)?;
    let mut world = scene.world;
    let slave = match &a.slave {
        Some(n) => world.body_index(n).ok_or_else(|| {
            Failure::from(format!(
                "--slave {n}: no body of that name in {}",
                scene.source
            ))
        })?,
        None => world
            .bodies
            .iter()
            .position(|b| b.is_dynamic())
            .ok_or_else(|| {
                Failure::from(format!("{}: no dynamic body to be the slave", scene.source))
            })?,
    };
    if !world.bodies[slave].is_dynamic() {
        return Err(Failure::from(format!(
            "slave body `{}` is fixed; the device needs a dynamic body",
            world.bodies[slave].name
        )));
    }
    // The hand drives the slave: the scene's loads on it are for the world alone (as in `run`).
    world.loads.retain(|l| l.body != slave);
    // Room for the contacts before the loop, so that a collapse does not allocate in its ticks.
    world.reserve_contacts(world.contact_room());
    world.prime();
    let body = &world.bodies[slave];
    let what = format!(
        "{} ({}), slave `{}` ({} kg)",
        scene.name, scene.source, body.name, body.mass
    );
    let origin = [body.pose.pos.x, body.pose.pos.y, body.pose.angle];
    let plant = SlavePlant::Body(BodySlave {
        world,
        slave,
        origin,
    });
    Ok((plant, what))
}

/// A slave device of the registry, its device file read and checked, opened at period `dt` (s).
fn slave_device(
    a: &ServeWorldArgs,
    device: &str,
    dt: f64,
) -> Result<(SlavePlant, String), Failure> {
    if device == "sim" {
        return Err(Failure::from(
            "--device sim: serve-world drives a real slave device; a simulated slave runs in `haptic2d teleop --live` (one process)\n    fix: --device haply:PATH, udp:ADDR:PORT or inverse3[:URL]",
        ));
    }
    let r = crate::real_end::open(device, a.device_file.as_deref(), a.allow_remote_device, dt)?;
    let what = format!("slave device {} ({})", r.name, r.summary);
    let (io, end) = (r.io, r.end);
    Ok((SlavePlant::Device(DeviceSlave::new(io, end)), what))
}

fn report(side: &mut WorldSide, summary: &haptic2d_rt::TimingSummary) {
    outln!("{summary}");
    outln!("world port (slave): {}", energies(side.ports.totals()));
    let plant = side.plant_ledger.totals();
    if let SlavePlant::Body(_) = side.plant {
        outln!(
            "world port (body, true displacement): energy in {:.6} J, out {:.6} J",
            plant.0,
            plant.1
        );
    } else {
        outln!("world port (body, true displacement): not known (a slave device; the books above are its encoders')");
    }
    let totals = |ws: &[WaveSlave; 3]| {
        wave_totals(
            ws.iter().map(|s| s.budget()),
            &side.wave_out,
            side.last.as_ref(),
        )
    };
    let end = EndWording {
        peer: "device",
        peer_waves: "forward waves: the device side",
        used_note: " (drift compensation included)",
    };
    report_link(
        &end,
        side.wave.as_ref().map(totals),
        &side.ep.counters,
        side.outbox.dropped(),
        format_args!(
            "{} periods live; largest coupling force {:.3} N",
            side.live_ticks, side.max_force
        ),
    );
    outln!("link: {}", side.stats.describe());
    let (n, wall, coupling, diff) = side.contact;
    let m = n.max(1) as f64;
    if let SlavePlant::Device(_) = side.plant {
        outln!("contact: not measured (a slave device has no force sensor)");
    } else {
        outln!(
        "contact: {n} periods with the slave in contact; mean wall force {:.3} N, mean coupling force {:.3} N, mean |difference| {:.3} N",
        wall / m,
        coupling / m,
        diff / m
        );
    }
    if side.peer_tdpa.is_some_and(|p| p == side.tdpa) {
    } else if let Some(p) = side.peer_tdpa {
        outln!(
            "warning: TDPA is {} here but {} on the device side",
            if side.tdpa { "on" } else { "off" },
            if p { "on" } else { "off" }
        );
    }
    match side.plant.stop() {
        Some(SlaveStop::Safety(trip)) => outln!(
            "stopped: safety stop: {} at t = {:.3} s; the slave's torques set to zero and latched; the device side told",
            trip.reason, trip.t
        ),
        Some(SlaveStop::Lost(e)) => outln!(
            "stopped: {e}; the slave's torques set to zero and latched; the device side told"
        ),
        None => outln!(
            "stopped: {}",
            side.end.unwrap_or("the duration ended or a signal arrived")
        ),
    }
}
