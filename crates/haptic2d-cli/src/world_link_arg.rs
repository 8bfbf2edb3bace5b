//! What `serve-world` and the device side (`run --world`, alias `remote-device`) share (issue 41,
//! docs/TELEOP.md): the key, what keeps the link passive (TDPA, wave variables, or nothing), the
//! link timeout, the impairment in front of the socket, and the link's statistics.

use std::path::PathBuf;

use haptic2d_devices::udp::UdpKey;
use haptic2d_devices::world_link::{LinkCounters, LinkEndpoint, PortMessage, PORT_LEN};
use haptic2d_lab::network::wave::{WaveBudget, WaveMsg, WaveParams};
use haptic2d_lab::network::{Impairment, Link};

/// The default wave impedances (N·s/m, N·s/m, N·m·s/rad): the lab's 20 N·s/m
/// ([`WaveParams::default`]) on the two translations; on the rotation, the same ratio to the
/// coupling's default damping (5 N·s/m, 0.01 N·m·s/rad) as on the translations.
pub const WAVE_B: [f64; 3] = [20.0, 20.0, 0.04];

/// Options of both ends of the world link.
#[derive(clap::Args, Debug, Clone)]
pub struct LinkArgs {
    /// The shared key file (hex, `chmod 600`), as for a UDP device (docs/DEVICE-PROTOCOL.md §3);
    /// both ends need the same one. Required on both ends.
    #[arg(long, value_name = "FILE")]
    pub key: Option<PathBuf>,
    /// Turn the time-domain passivity controller off on this end (its port only observes): to see
    /// what the link does without it. Never on a real device.
    #[arg(long)]
    pub no_tdpa: bool,
    /// What keeps the link passive: `tdpa` (time-domain passivity on both ports), `wave` (wave
    /// variables with an energy budget per wave and the budgeted drift compensation), or `none`
    /// (the ports only observe; the same as --no-tdpa). Both ends need the same.
    #[arg(long, value_name = "tdpa|wave|none", default_value = "tdpa")]
    pub link: String,
    /// With --link wave: the wave impedance per axis (N·s/m, N·s/m, N·m·s/rad); both ends need
    /// the same.
    #[arg(long, value_delimiter = ',', num_args = 3, default_values_t = WAVE_B, value_name = "BX,BY,BTHETA")]
    pub wave_b: Vec<f64>,
    /// With --link wave: the drift compensation's gain (1/s) on the world side; 0 turns it off.
    #[arg(long, default_value_t = 5.0, value_name = "PER_S")]
    pub drift_gain: f64,
    /// No authentic datagram from the other end for this long (ms) counts as a lost link: the
    /// device side latches zero torques and says why; the world side stops driving the slave.
    #[arg(long, default_value_t = 100.0, value_name = "MS")]
    pub link_timeout_ms: f64,
    /// Test impairment of what this end sends: a one-way delay (ms), rounded to whole periods.
    #[arg(long, default_value_t = 0.0, value_name = "MS")]
    pub delay_ms: f64,
    /// Test impairment: the fraction of this end's port messages dropped, in [0, 1].
    #[arg(long, default_value_t = 0.0)]
    pub loss: f64,
    /// Seed of the impairment's random numbers.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

impl LinkArgs {
    /// Reads the key; checks the numbers. Errors name the option and the fix.
    pub fn key(&self) -> Result<UdpKey, String> {
        if !(self.link_timeout_ms.is_finite() && self.link_timeout_ms >= 1.0) {
            return Err(format!(
                "--link-timeout-ms must be at least 1 ms (got {})",
                self.link_timeout_ms
            ));
        }
        if !(self.delay_ms.is_finite() && (0.0..=10_000.0).contains(&self.delay_ms)) {
            return Err(format!(
                "--delay-ms must be within 0..=10000 ms (got {})",
                self.delay_ms
            ));
        }
        if !(0.0..=1.0).contains(&self.loss) {
            return Err(format!(
                "--loss must be a fraction in [0, 1] (got {})",
                self.loss
            ));
        }
        match self.link.as_str() {
            "tdpa" | "none" => {}
            "wave" if self.no_tdpa => return Err("--link wave --no-tdpa: --no-tdpa means --link none\n    fix: one of --link wave, --link none".into()),
            "wave" => {}
            other => return Err(format!("--link {other}: expected tdpa, wave or none\n    fix: --link tdpa")),
        }
        if self.wave_b.len() != 3 || !self.wave_b.iter().all(|b| b.is_finite() && *b > 0.0) {
            return Err(format!(
                "--wave-b needs three finite impedances > 0 (x, y, θ), got {:?}\n    fix: e.g. --wave-b 20,20,0.04",
                self.wave_b
            ));
        }
        if !(self.drift_gain.is_finite() && self.drift_gain >= 0.0) {
            return Err(format!(
                "--drift-gain must be finite and ≥ 0 (1/s), got {}",
                self.drift_gain
            ));
        }
        match &self.key {
            Some(k) => UdpKey::from_file(k),
            None => Err("the world link needs --key FILE (the same key on both ends)\n    fix: head -c 32 /dev/urandom | od -An -tx1 | tr -d ' \\n' > world.key; chmod 600 world.key".into()),
        }
    }

    /// True when any of these options was given (for `run`, which accepts them with `--world` only).
    pub fn any_given(&self) -> bool {
        self.key.is_some()
            || self.no_tdpa
            || self.link != "tdpa"
            || self.wave_b != WAVE_B
            || self.drift_gain != 5.0
            || self.link_timeout_ms != 100.0
            || self.delay_ms != 0.0
            || self.loss != 0.0
            || self.seed != 1
    }

    /// True when this end runs its TDPA passivity controller (`--link tdpa` without --no-tdpa).
    pub fn tdpa(&self) -> bool {
        !self.no_tdpa && self.link == "tdpa"
    }

    /// The wave settings per axis when this end runs wave variables (`--link wave`).
    pub fn wave(&self) -> Option<[WaveParams; 3]> {
        (self.link == "wave").then(|| {
            std::array::from_fn(|i| WaveParams {
                b: self.wave_b.get(i).copied().unwrap_or(WAVE_B[i]),
                drift_gain: self.drift_gain,
            })
        })
    }

    /// The link's passivity method, in words: `tdpa`, `wave (b …)` or `none`.
    pub fn method(&self) -> String {
        match (self.tdpa(), self.wave()) {
            (true, _) => "tdpa".into(),
            (false, Some(w)) => format!(
                "wave (b {}, {}, {}; drift gain {} /s)",
                w[0].b, w[1].b, w[2].b, w[0].drift_gain
            ),
            _ => "none".into(),
        }
    }

    /// The impairment in periods of `rate_hz`, `None` when there is none.
    pub fn outbox(&self, rate_hz: f64) -> Outbox {
        let delay = (self.delay_ms * 1e-3 * rate_hz).round() as u32;
        let link = (delay > 0 || self.loss > 0.0)
            .then(|| Link::new(Impairment::delay_loss(delay, self.loss, self.seed)));
        Outbox { link }
    }

    /// The impairment, in words.
    pub fn describe(&self, rate_hz: f64) -> String {
        let delay = (self.delay_ms * 1e-3 * rate_hz).round();
        if delay == 0.0 && self.loss == 0.0 {
            return "none".into();
        }
        format!(
            "delay {} ms, loss {:.1} %, seed {}",
            delay * 1e3 / rate_hz,
            self.loss * 100.0,
            self.seed
        )
    }
}

/// What an end sends goes through the test impairment (the lab's seeded [`Link`], in periods of
/// the loop) before the socket. Allocation-free once its queue has grown to the delay.
pub struct Outbox {
    link: Option<Link<[u8; PORT_LEN]>>,
}

impl Outbox {
    /// Seals `msg` as a port message of `kind` in `ep`'s session into `buf`, then sends it at
    /// deadline `k` ([`send`](Self::send)).
    #[inline]
    pub fn seal_and_send(
        &mut self,
        ep: &mut LinkEndpoint,
        msg: &PortMessage,
        kind: u8,
        k: u64,
        buf: &mut [u8; PORT_LEN],
    ) {
        msg.seal(ep.key(), kind, ep.session(), buf);
        self.send(ep, k, buf);
    }

    /// Sends `datagram` at deadline `k` (through the impairment, if any).
    #[inline]
    pub fn send(&mut self, ep: &mut LinkEndpoint, k: u64, datagram: &[u8; PORT_LEN]) {
        match &mut self.link {
            None => ep.send(datagram),
            Some(l) => {
                l.send(k, *datagram);
                if let Some(d) = l.deliver(k) {
                    ep.send(&d);
                }
            }
        }
    }

    /// Port messages the impairment dropped.
    pub fn dropped(&self) -> u64 {
        self.link.as_ref().map_or(0, |l| l.lost)
    }
}

/// The link as one end sees it: round trips (from the echoed timestamps) and arrival intervals,
/// kept in preallocated buffers (the hot path does not allocate; beyond the capacity, samples are
/// counted but not kept).
pub struct LinkStats {
    round_trip_ns: Vec<u64>,
    interval_ns: Vec<u64>,
    last_arrival_ns: Option<u64>,
    /// Samples not kept for lack of room.
    pub overflow: u64,
}

impl LinkStats {
    /// Room for `n` samples of each.
    pub fn with_capacity(n: usize) -> Self {
        Self {
            round_trip_ns: Vec::with_capacity(n),
            interval_ns: Vec::with_capacity(n),
            last_arrival_ns: None,
            overflow: 0,
        }
    }

    /// A new message arrived at `now_ns` (this end's clock) echoing this end's `echo_time_ns`
    /// after `echo_age_ns` at the other end.
    #[inline]
    pub fn arrived(&mut self, now_ns: u64, echo_time_ns: u64, echo_age_ns: u32) {
        if echo_time_ns != 0 {
            let rt = now_ns
                .saturating_sub(echo_time_ns)
                .saturating_sub(echo_age_ns as u64);
            push(&mut self.round_trip_ns, rt, &mut self.overflow);
        }
        if let Some(p) = self.last_arrival_ns {
            push(
                &mut self.interval_ns,
                now_ns.saturating_sub(p),
                &mut self.overflow,
            );
        }
        self.last_arrival_ns = Some(now_ns);
    }

    /// "round trip p50 … ms, p99 …, max …; arrival interval p50 …, p99 …, max … ms".
    pub fn describe(&mut self) -> String {
        let mut s = String::new();
        for (name, v) in [
            ("round trip", &mut self.round_trip_ns),
            ("arrival interval", &mut self.interval_ns),
        ] {
            if v.is_empty() {
                s.push_str(&format!("{name}: no samples; "));
                continue;
            }
            v.sort_unstable();
            let q = |p: f64| v[((v.len() - 1) as f64 * p).round() as usize] as f64 * 1e-6;
            s.push_str(&format!(
                "{name} p50 {:.3} ms, p99 {:.3} ms, p99.9 {:.3} ms, max {:.3} ms ({} samples); ",
                q(0.5),
                q(0.99),
                q(0.999),
                q(1.0),
                v.len()
            ));
        }
        s.trim_end_matches("; ").to_string()
    }
}

#[inline]
fn push(v: &mut Vec<u64>, x: u64, overflow: &mut u64) {
    if v.len() < v.capacity() {
        v.push(x);
    } else {
        *overflow += 1;
    }
}

/// "in 0.0123 J, out 0.0100 J, dissipated 0.0010 J".
pub fn energies(totals: (f64, f64, f64)) -> String {
    format!(
        "energy in {:.6} J, out {:.6} J, dissipated by TDPA {:.6} J",
        totals.0, totals.1, totals.2
    )
}

/// The wave energies of one end of the link over a run (J), for its closing report.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WaveTotals {
    /// Put on the link by this end's waves, summed over the axes.
    pub sent: f64,
    /// Put on the link by the other end's waves, as its last message received said.
    pub got: f64,
    /// Used by this end's energy budgets.
    pub used: f64,
    /// Cut by this end's energy budgets.
    pub cut: f64,
}

/// The [`WaveTotals`] of an end whose axes' budgets are `budgets`, whose last outgoing waves are
/// `wave_out` and whose last message received is `last`.
pub fn wave_totals(
    budgets: impl Iterator<Item = WaveBudget>,
    wave_out: &[WaveMsg; 3],
    last: Option<&PortMessage>,
) -> WaveTotals {
    let (used, cut) = budgets.fold((0.0, 0.0), |(u, c), b| (u + b.used(), c + b.cut()));
    WaveTotals {
        sent: wave_out.iter().map(|o| o.energy).sum(),
        got: last.map_or(0.0, |m| m.wave_energy.iter().sum::<f64>()),
        used,
        cut,
    }
}

/// How one end of the link words its closing report: the other end, and its waves.
#[derive(Clone, Copy, Debug)]
pub struct EndWording {
    /// The other end, as in "the world side is an older build": `world` or `device`.
    pub peer: &'static str,
    /// The other end's waves, as in "returning waves: the world sent 0.1 J".
    pub peer_waves: &'static str,
    /// Added after the energy the budgets used (the world side's includes the drift compensation).
    pub used_note: &'static str,
}

/// The link lines of one end's closing report: the waves' energies (`waves`, with wave variables),
/// a warning if authentic messages of the older message version 1 were refused, then the link's
/// counters `c` (`dropped`: by the test impairment in front of the socket) followed by `tail`.
pub fn report_link(
    end: &EndWording,
    waves: Option<WaveTotals>,
    c: &LinkCounters,
    dropped: u64,
    tail: std::fmt::Arguments,
) {
    if let Some(w) = waves {
        crate::outln!(
            "waves: sent {:.6} J; {} sent {:.6} J (as last received), used {:.6} J{}, {:.6} J cut by the budget",
            w.sent, end.peer_waves, w.got, w.used, end.used_note, w.cut
        );
    }
    if c.old_version > 0 {
        crate::outln!(
            "link: {} authentic port messages of the older world-link message version 1 refused: the {} side is an older build (update both ends)",
            c.old_version, end.peer
        );
    }
    crate::outln!(
        "link: {} received, {} stale, {} bad MAC, {} wrong session, {} malformed, {} send errors, {} dropped by the test impairment; {tail}",
        c.received, c.stale, c.bad_mac, c.wrong_session, c.malformed, c.send_errors, dropped
    );
}
