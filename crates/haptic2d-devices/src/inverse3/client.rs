//! The Inverse Service client thread: Haply's own client (`haply::HaplyDevice`, HTTP + WebSocket)
//! on a small tokio runtime of its own, exchanging state and force with the haptic loop through the
//! wait-free [`slots`](super::slots).
//!
//! Every control period the client (1) copies the newest state the `haply` listener has merged into
//! the state slot (a new `seq` when the service's message is new), (2) reads the loop's newest
//! command and (3) sends `set_cursor_force` (zero-order hold on the service side): the plane force
//! of the loop plus the virtual plane on the held axis (ramped in from zero from the first enabled
//! command), clamped to the force limit. Zero force is sent before the first valid state, when the
//! loop has latched, when the newest state is older than the timeout, and when the driver stops the
//! client (then the connection is closed). A failed send closes the client with its reason; the
//! loop sees it (and, in any case, a state older than its timeout) as a lost device. So does a
//! state without a cursor position (DEVICES §4: a missing field is a fault, never a zero): the
//! client sends zero force, closes naming the field, and the driver latches.
//!
//! Pacing. The `haply` listener task loops without yielding once its stream has ended (its
//! `listen` retries `next()`, which returns at once), and a worker stuck in one poll also stops
//! driving the runtime's timers. So this loop does not use tokio timers: it runs on the client
//! thread itself (`block_on`, not a worker) and paces itself with `std::thread::sleep` to absolute
//! deadlines; its other awaits (the state mutex, the WebSocket write) need no timer. When it stops
//! it drops the `HaplyDevice`, whose stop signal the listener checks first on every turn.

use std::sync::atomic::Ordering;
use std::sync::mpsc;
use std::sync::Arc;
use std::time::{Duration, Instant};

use haply::device_model::{Force, ForceInput};
use haply::HaplyDevice;
use haptic2d_rt::clock::now_ns;

use super::planar::PlaneMap;
use super::slots::{ClientStatus, ForceCommand, Inverse3Sample};

/// The longest the client waits for the WebSocket connection (and [`Inverse3Device::open`] for
/// the first state).
///
/// [`Inverse3Device::open`]: super::Inverse3Device::open
pub const OPEN_TIMEOUT: Duration = Duration::from_secs(2);

/// What the client thread needs.
pub struct ClientConfig {
    /// The service's HTTP base.
    pub http_url: String,
    /// Its WebSocket.
    pub ws_url: String,
    /// The control period.
    pub period: Duration,
    /// A state older than this is stale: zero force.
    pub timeout: Duration,
    /// The plane mapping.
    pub map: PlaneMap,
}

/// The client's ends of the slots.
pub struct ClientEnds {
    /// State slot, written by the client.
    pub state: triple_buffer::Input<Inverse3Sample>,
    /// Command slot, read by the client.
    pub command: triple_buffer::Output<ForceCommand>,
    /// Shared status.
    pub status: Arc<ClientStatus>,
}

/// Starts the client thread; returns once the WebSocket is connected (or with the error, after at
/// most [`OPEN_TIMEOUT`]).
pub fn spawn(
    cfg: ClientConfig,
    ends: ClientEnds,
    name: &str,
) -> Result<std::thread::JoinHandle<()>, String> {
    let (tx, rx) = mpsc::channel::<Result<(), String>>();
    let thread_name = format!("inverse3-client {name}");
    let handle = std::thread::Builder::new()
        .name(thread_name)
        .spawn(move || {
            // The device side of the host at real-time priority (below the loop's), inherited by
            // the runtime's workers that receive the states: at normal priority a loaded machine
            // delayed them past the timeout in 8 of 10 runs against the emulator (issue 39 item
            // 4). Refused without privilege: then it runs at normal priority, as before.
            let _ = haptic2d_rt::rt::set_fifo_priority(haptic2d_rt::rt::DEVICE_FIFO_PRIORITY);
            let rt = match tokio::runtime::Builder::new_multi_thread()
                .worker_threads(2)
                .enable_all()
                .build()
            {
                Ok(rt) => rt,
                Err(e) => {
                    let _ = tx.send(Err(format!("cannot start the client's runtime: {e}")));
                    return;
                }
            };
            rt.block_on(run(cfg, ends, tx));
            rt.shutdown_timeout(Duration::from_millis(200));
        })
        .map_err(|e| format!("cannot start the Inverse3 client thread: {e}"))?;
    match rx.recv_timeout(OPEN_TIMEOUT + Duration::from_millis(500)) {
        Ok(Ok(())) => Ok(handle),
        Ok(Err(e)) => {
            let _ = handle.join();
            Err(e)
        }
        Err(_) => Err(format!(
            "no WebSocket connection within {} ms",
            OPEN_TIMEOUT.as_millis()
        )),
    }
}

async fn run(cfg: ClientConfig, mut ends: ClientEnds, ready: mpsc::Sender<Result<(), String>>) {
    let connect = HaplyDevice::new(&cfg.http_url, &cfg.ws_url);
    let mut dev = match tokio::time::timeout(OPEN_TIMEOUT, connect).await {
        Ok(Ok(d)) => d,
        Ok(Err(e)) => {
            let _ = ready.send(Err(format!("cannot connect to {}: {e}", cfg.ws_url)));
            return;
        }
        Err(_) => {
            let _ = ready.send(Err(format!(
                "no WebSocket connection to {} within {} ms",
                cfg.ws_url,
                OPEN_TIMEOUT.as_millis()
            )));
            return;
        }
    };
    let _ = ready.send(Ok(()));
    let status = ends.status.clone();
    let period = cfg.period.max(Duration::from_micros(250));
    let mut next = Instant::now();
    let mut seq = 0u64;
    let mut last: Option<Instant> = None;
    let mut sample = Inverse3Sample::default();
    let mut device_id: Option<String> = None;
    let mut engaged: Option<Instant> = None;
    let mut latched = false;
    loop {
        // The next absolute deadline (late ones are skipped, not caught up).
        next += period;
        let now = Instant::now();
        if next > now {
            std::thread::sleep(next - now);
        } else {
            next = now;
        }
        let stopping = status.stop.load(Ordering::Acquire);
        // (1) The newest state. One without a cursor position is a fault, never (0, 0, 0)
        // (issue 34: read as the origin, it made the handle jump 20 mm in one sample).
        let mut missing: Option<String> = None;
        {
            let g = dev.state.lock().await;
            if let Some(d) = g.data.inverse3.first() {
                if last != Some(g.timestamp) && d.state.cursor_position.is_none() {
                    missing = Some(d.device_id.clone());
                } else if last != Some(g.timestamp) {
                    let p = d.state.cursor_position.unwrap_or_default();
                    let p = [p.x as f64, p.y as f64, p.z as f64];
                    let rx_ns = now_ns().saturating_sub(g.timestamp.elapsed().as_nanos() as u64);
                    let v = match d.state.cursor_velocity {
                        Some(v) => [v.x as f64, v.y as f64, v.z as f64],
                        None if seq > 0 && rx_ns > sample.rx_ns => {
                            let dt = (rx_ns - sample.rx_ns) as f64 * 1e-9;
                            std::array::from_fn(|i| (p[i] - sample.position[i]) / dt)
                        }
                        None => [0.0; 3],
                    };
                    let orientation = g
                        .data
                        .verse_grip
                        .iter()
                        .find_map(|v| v.state.orientation)
                        .or_else(|| {
                            g.data
                                .wireless_verse_grip
                                .iter()
                                .find_map(|v| v.state.orientation)
                        })
                        .map(|q| [q.w as f64, q.x as f64, q.y as f64, q.z as f64]);
                    seq += 1;
                    sample = Inverse3Sample {
                        seq,
                        rx_ns,
                        position: p,
                        velocity: v,
                        orientation,
                        ready: d.status.ready,
                    };
                    ends.state.write(sample);
                    last = Some(g.timestamp);
                    if device_id.is_none() {
                        device_id = Some(d.device_id.clone());
                    }
                }
            }
        }
        if let Some(id) = missing {
            // Zero force first, then the reason: the driver reads it as a lost device.
            let zero = ForceInput {
                device_id: id.clone(),
                forces: Force {
                    x: 0.0,
                    y: 0.0,
                    z: 0.0,
                },
            };
            let _ = dev.update_force(vec![zero], Some(true), Some(true)).await;
            status.close(format!(
                "the Inverse Service sent a state of Inverse3 `{id}` without its cursor position (field `state.cursor_position`); a state without a position is a fault, not (0, 0, 0)"
            ));
            break;
        }
        // (2) The loop's command, (3) the force.
        let cmd = *ends.command.read();
        latched |= cmd.latched;
        let fresh =
            seq > 0 && now_ns().saturating_sub(sample.rx_ns) <= cfg.timeout.as_nanos() as u64;
        let on = fresh && cmd.enable && !latched && !stopping;
        let force = if on {
            let t0 = *engaged.get_or_insert_with(Instant::now);
            let r = cfg.map.ramp(t0.elapsed().as_secs_f64());
            cfg.map
                .device_force(cmd.planar, &sample.position, &sample.velocity, r)
        } else {
            [0.0; 3]
        };
        let sent = match &device_id {
            Some(id) => {
                dev.update_force(
                    vec![ForceInput {
                        device_id: id.clone(),
                        forces: Force {
                            x: force[0] as f32,
                            y: force[1] as f32,
                            z: force[2] as f32,
                        },
                    }],
                    Some(true),
                    Some(true),
                )
                .await
            }
            // No device yet: ask the service for its full state.
            None => dev.send_force_full_render().await,
        };
        if let Err(e) = sent {
            status.close(format!(
                "the connection to the Inverse Service at {} failed: {e}",
                cfg.ws_url
            ));
            break;
        }
        if stopping {
            break;
        }
    }
    // Dropping the device signals and aborts the listener (no close handshake: the connection may
    // be gone, and a handshake would wait on it).
    drop(dev);
}
