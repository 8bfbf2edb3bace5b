//! The text of one transport's measurement, and the machine it ran on.

use crate::ping::{Answers, PingRun};
use crate::summary::{row, summarize, HEADER};

/// One transport's report: counts and losses, then the round trip, the echo side's turnaround
/// and the ping loop's send lateness, then the echo side's own report.
pub fn text(name: &str, n: u32, run: &PingRun, answers: &Answers, echo: &str) -> String {
    let mut rtt = answers.rtt.values();
    let got = rtt.len();
    let mut late = run.lateness.clone();
    format!(
        "== {name}: {n} messages sent at 1 kHz after {} warm-up; {got} answers, {} lost ({:.3} %), \
{} answers refused, {} sends refused, {} deadlines skipped\n{HEADER}\n{}\n{}\n{}\n{}",
        run.warmup_sent,
        n as usize - got,
        100.0 * (n as usize - got) as f64 / n as f64,
        answers.refused(),
        run.send_errors,
        run.skipped,
        row("round trip", summarize(&mut rtt)),
        row("echo turnaround (in rtt)", summarize(&mut answers.turnaround.values())),
        row("ping send lateness", summarize(&mut late)),
        echo.trim_end()
    )
}

/// The machine: CPU model, core count, kernel, and the load average now.
pub fn machine() -> String {
    let read = |p: &str| std::fs::read_to_string(p).unwrap_or_default();
    let cpu = read("/proc/cpuinfo");
    let model = cpu
        .lines()
        .find_map(|l| l.strip_prefix("model name"))
        .map(|l| l.trim_start_matches([' ', '\t', ':']).to_string())
        .unwrap_or_else(|| "unknown CPU".into());
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    format!(
        "machine: {model}, {cores} cores, kernel {}, load average {}",
        read("/proc/sys/kernel/osrelease").trim(),
        load()
    )
}

/// The 1, 5 and 15 min load averages (/proc/loadavg).
pub fn load() -> String {
    let l = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    l.split_whitespace().take(3).collect::<Vec<_>>().join(" ")
}
