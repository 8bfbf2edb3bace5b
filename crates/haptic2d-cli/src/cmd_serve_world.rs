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
use haptic2d::geom::Vec2;
use haptic2d::world::World;
use haptic2d_devices::world_link::message::{FLAG_BYE, FLAG_TDPA, FLAG_WAVE};
use haptic2d_devices::world_link::{
    LinkEndpoint, PortMessage, KIND_TO_DEVICE, KIND_TO_WORLD, PORT_LEN,
};
use haptic2d_lab::network::wave::{WaveMsg, WaveSlave};
use haptic2d_rt::clock::now_ns;
use haptic2d_rt::{run_loop, LoopConfig, TickControl, TickInfo};

use crate::exit::{Failure, Status};
use crate::outln;
use crate::world_link_arg::{energies, report_link, wave_totals, EndWording};
use crate::world_link_arg::{LinkArgs, LinkStats, Outbox};

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
    /// A scene file path, or a built-in scene name.
    pub scene: String,
    /// Address to listen on (`127.0.0.1:0` picks a free port; it is printed).
    #[arg(long, default_value = "127.0.0.1:7420")]
    pub bind: String,
    /// Name of the slave body (default: the first dynamic body).
    #[arg(long)]
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
    world: World,
    slave: usize,
    origin: [f64; 3],
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
    fn slave_state(&self) -> ([f64; 3], [f64; 3]) {
        let b = &self.world.bodies[self.slave];
        (
            [
                b.pose.pos.x - self.origin[0],
                b.pose.pos.y - self.origin[1],
                b.pose.angle - self.origin[2],
            ],
            [b.vel.x, b.vel.y, b.omega],
        )
    }

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
                self.end = Some("link mismatch: one end runs wave variables, the other forces (both ends need the same --link)");
            }
        }
        fresh
    }

    fn tick(&mut self, info: &TickInfo) -> TickControl {
        let (k, dt) = (info.deadline_index, info.period_s);
        let fresh = self.receive(k);
        let silent = k.saturating_sub(self.last_k);
        let (x_s, v_s) = self.slave_state();
        let live = self.last.is_some() && silent <= self.timeout_periods && self.end.is_none();
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
        self.world
            .set_drive(self.slave, Vec2::new(f_s[0], f_s[1]), f_s[2]);
        self.world.step();
        let (x_after, _) = self.slave_state();
        let moved: [f64; 3] = std::array::from_fn(|i| (x_after[i] - x_s[i]) / dt);
        self.plant_ledger.observe(&f_s, &moved, dt);
        let wall = self.world.contact_wrench(self.slave).force;
        let (wall, coupling) = (wall.x.hypot(wall.y), f_s[0].hypot(f_s[1]));
        if live && wall > 0.01 {
            let c = &mut self.contact;
            *c = (
                c.0 + 1,
                c.1 + wall,
                c.2 + coupling,
                c.3 + (wall - coupling).abs(),
            );
        }
        // The port books what the body really received: the force held over the world step
        // times the body's displacement over it (the world knows it at once). Booked on the
        // velocity at the start of the step instead, the controller's damping near its cap
        // `2m/T` counted as dissipated what the body did not lose (docs/TELEOP.md).
        if self.tdpa {
            self.ports.book(&f_s, &moved, dt);
        } else {
            self.ports.observe(&f_s, &moved, dt);
        }
        self.seq = self.seq.wrapping_add(1);
        let now = now_ns();
        let msg = PortMessage {
            seq: self.seq,
            flags: if self.tdpa {
                FLAG_TDPA
            } else if self.wave.is_some() {
                FLAG_WAVE
            } else {
                0
            },
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
        let (x, _) = self.slave_state();
        if !x.iter().all(|v| v.is_finite()) {
            self.end = Some("the world diverged (non-finite slave pose)");
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
    let scene = crate::scene_arg::load(&a.scene, Some(a.rate)).map_err(Failure::from)?;
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
    world.prime();
    let dt = world.params.dt;
    let body = &world.bodies[slave];
    let origin = [body.pose.pos.x, body.pose.pos.y, body.pose.angle];
    let alpha_max = [
        2.0 * body.mass / dt,
        2.0 * body.mass / dt,
        2.0 * body.inertia / dt,
    ];
    let socket = UdpSocket::bind(&a.bind)
        .map_err(|e| Failure::error(format!("cannot listen on {}: {e}", a.bind)))?;
    let local = socket
        .local_addr()
        .map_err(|e| Failure::error(e.to_string()))?;
    outln!(
        "serve-world: {} ({}), slave `{}` ({} kg), {} Hz, link {}, impairment: {}",
        scene.name,
        scene.source,
        body.name,
        body.mass,
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
        world,
        slave,
        origin,
        alpha_max,
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
        rt: false,
        spin_us: 100.0,
        ..LoopConfig::default()
    };
    let summary =
        run_loop(&config, &stop as &AtomicBool, |info| side.tick(&info)).map_err(Failure::error)?;
    report(&mut side, &summary);
    Ok(match side.end {
        Some(e) if e.contains("diverged") => Status::Diverged,
        _ if stop.load(std::sync::atomic::Ordering::Relaxed) => Status::Interrupted,
        _ => Status::Clean,
    })
}

fn report(side: &mut WorldSide, summary: &haptic2d_rt::TimingSummary) {
    outln!("{summary}");
    outln!("world port (slave): {}", energies(side.ports.totals()));
    let plant = side.plant_ledger.totals();
    outln!(
        "world port (body, true displacement): energy in {:.6} J, out {:.6} J",
        plant.0,
        plant.1
    );
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
    outln!(
        "contact: {n} periods with the slave in contact; mean wall force {:.3} N, mean coupling force {:.3} N, mean |difference| {:.3} N",
        wall / m,
        coupling / m,
        diff / m
    );
    if side.peer_tdpa.is_some_and(|p| p == side.tdpa) {
    } else if let Some(p) = side.peer_tdpa {
        outln!(
            "warning: TDPA is {} here but {} on the device side",
            if side.tdpa { "on" } else { "off" },
            if p { "on" } else { "off" }
        );
    }
    outln!(
        "stopped: {}",
        side.end.unwrap_or("the duration ended or a signal arrived")
    );
}
