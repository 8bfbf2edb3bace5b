//! What `haptic2d teleop --live` prints: the start line (both devices, the link, the coupling) and
//! the closing report (timing, each port's ledger, the network's balance, the largest forces, the
//! simulated slave's contact, each handle's displacement, the link's counters, why it stopped).

use haptic2d::control::tdpa::planar_balance;
use haptic2d_lab::network::Impairment;
use haptic2d_rt::{DeviceError, TimingSummary};

use crate::cmd_teleop::TeleopArgs;
use crate::exit::Status;
use crate::outln;
use crate::teleop_end::LiveEnd;
use crate::teleop_live::{Live, LiveStop};

/// The line printed once both devices are open, before the loop starts.
pub fn start_line(live: &Live, a: &TeleopArgs, link: Impairment) {
    for e in [&live.m, &live.s] {
        outln!("{} {}: {}", e.role.name(), e.name, e.summary);
    }
    let axes: Vec<&str> = ["x", "y", "θ"]
        .iter()
        .zip(live.axes)
        .filter_map(|(n, on)| on.then_some(*n))
        .collect();
    outln!(
        "teleop live: 1000 Hz, position–force, coupling {} N/m, {} N·s/m on {}; one-way delay {} ms, loss {:.1} % each way (seed {}), TDPA {}; {:.1} s",
        a.stiffness,
        a.damping,
        axes.join(", "),
        link.delay,
        link.loss * 100.0,
        link.seed,
        if a.no_tdpa { "off" } else { "on" },
        a.duration
    );
}

/// One end's closing lines: its port's ledger, its largest force, its handle's displacement.
fn end_lines(e: &LiveEnd) {
    let (i, o, d) = e.port.totals();
    outln!(
        "{} port ({}): energy in {i:.6} J, out {o:.6} J, dissipated by TDPA {d:.6} J",
        e.role.name(),
        e.name
    );
    let x = e.displacement;
    outln!(
        "{} handle: largest force {:.3} N; displacement at the end ({:+.2}, {:+.2}) mm from its origin, largest excursion {:.2} mm",
        e.role.name(),
        e.max_force,
        x[0] * 1e3,
        x[1] * 1e3,
        e.max_excursion * 1e3
    );
}

/// Prints the closing report; the exit status (clean, safety stop, device lost, interrupted).
pub fn report(live: &Live, summary: &TimingSummary, interrupted: bool) -> Status {
    if let Some(w) = summary.rt.as_ref().and_then(|r| r.warning()) {
        outln!("{w}");
    }
    outln!("{summary}");
    end_lines(&live.m);
    end_lines(&live.s);
    let (m, s) = (live.m.port.totals(), live.s.port.totals());
    let net = planar_balance((m.0, m.1), (s.0, s.1));
    outln!(
        "network: energy in {:.6} J, out {:.6} J, created {:.6} J (out − in over both ports; ≤ 0 is passive); dissipated by TDPA {:.6} J",
        net.energy_in,
        net.energy_out,
        net.created,
        m.2 + s.2
    );
    match &live.contact {
        Some(c) => {
            let n = c.n.max(1) as f64;
            outln!(
                "slave contact (simulated wall): largest wall force {:.3} N, deepest penetration {:.2} mm; last second in contact ({} ticks): wall force {:.3} N, master force {:.3} N",
                c.max_wall,
                c.max_pen * 1e3,
                c.n,
                c.wall_sum / n,
                c.master_sum / n
            );
        }
        None => outln!("slave contact: not measured (a real slave has no force sensor)"),
    }
    let [(ul, us), (dl, ds)] = live.link_counters();
    outln!("link: master → slave {ul} lost, {us} stale; slave → master {dl} lost, {ds} stale");
    stop_lines(live, interrupted)
}

/// Why the run ended, and its status.
fn stop_lines(live: &Live, interrupted: bool) -> Status {
    let when = |t: Option<f64>| t.map_or("-".to_string(), |t| format!("{t:.3} s"));
    for e in [&live.m, &live.s] {
        outln!(
            "{} torques: last non-zero written at t = {}; zero written at the stop at t = {}; none written after",
            e.role.name(),
            when(e.last_torque_t),
            when(e.zeroed_t)
        );
    }
    let zeroed = "torques of both devices set to zero";
    let name = |r| {
        if r == crate::teleop_end::Role::Master {
            &live.m.name
        } else {
            &live.s.name
        }
    };
    match &live.stop {
        None if interrupted => {
            outln!("stopped: interrupted by a signal (SIGINT or SIGTERM); {zeroed}");
            Status::Interrupted
        }
        None => {
            outln!("stopped: the duration ended; no safety stop; {zeroed}");
            Status::Clean
        }
        Some((t, LiveStop::Latch(role, trip))) => {
            outln!(
                "stopped: the {} ({}) latched at t = {t:.3} s: {trip}; {zeroed}",
                role.name(),
                name(*role)
            );
            Status::SafetyStop
        }
        Some((t, LiveStop::Missed { role, run, limit })) => {
            outln!(
                "stopped: safety stop at t = {t:.3} s: {run} consecutive ticks missed their deadline (limit {limit}, the {}'s device file, {}): the machine is too loaded for this rate (give the loop real-time priority, close other programs, or raise max_missed_deadlines); {zeroed}",
                role.name(),
                name(*role)
            );
            Status::SafetyStop
        }
        Some((t, LiveStop::Lost(role, e))) => {
            let check = match e {
                DeviceError::Lost(_) => "check its cable, power and port",
                _ => "check the device and its driver",
            };
            outln!(
                "stopped: the {} ({}) was lost at t = {t:.3} s: {e}; {check}; {zeroed}",
                role.name(),
                name(*role)
            );
            Status::DeviceLost
        }
    }
}
