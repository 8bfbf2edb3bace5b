//! Best-effort real-time setup of the calling thread.
//!
//! Three independent steps, each reported rather than fatal:
//!
//! 1. `SCHED_FIFO` at a fixed priority (`pthread_setschedparam`), so that
//!    ordinary threads cannot preempt the haptic loop;
//! 2. `mlockall(MCL_CURRENT | MCL_FUTURE)` and a pre-faulted stack, so that
//!    the loop never waits for a page fault;
//! 3. pinning the thread to one core (`core_affinity`), so that it keeps its
//!    caches and is not migrated.
//!
//! Without privileges (`CAP_SYS_NICE`, `CAP_IPC_LOCK` or the matching
//! `ulimit -r` / `ulimit -l`), steps 1 and 2 are refused by the kernel. That is
//! not an error: the loop still runs, only with more jitter. The
//! [`RtReport::warning`] line says so once, with the fix, for the caller to print.

use std::fmt;

/// Which core to pin the real-time thread to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum CorePin {
    /// Do not pin.
    None,
    /// The highest-numbered core the process may run on (usually the one
    /// that services the fewest interrupts). Default.
    #[default]
    Last,
    /// A given core id (as numbered by the OS, from 0).
    Core(usize),
}

/// What real-time treatment to ask for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RtRequest {
    /// `SCHED_FIFO` priority, 1 (lowest) to 99 (highest); `None` keeps the
    /// normal scheduler. Default 80: above most kernel threads' default 50,
    /// below the watchdog/migration threads at 99.
    pub fifo_priority: Option<i32>,
    /// Lock all current and future memory (`mlockall`). Default true.
    pub lock_memory: bool,
    /// Bytes of stack to touch after locking, so later stack growth cannot
    /// fault. Default 256 KiB (must stay below the thread's stack size).
    pub prefault_stack_bytes: usize,
    /// Core to pin the thread to. Default [`CorePin::Last`].
    pub pin: CorePin,
}

impl Default for RtRequest {
    fn default() -> Self {
        Self {
            fifo_priority: Some(LOOP_FIFO_PRIORITY),
            lock_memory: true,
            prefault_stack_bytes: 256 * 1024,
            pin: CorePin::Last,
        }
    }
}

/// `SCHED_FIFO` priority of the haptic loop (`haptic2d run`): 80.
pub const LOOP_FIFO_PRIORITY: i32 = 80;

/// `SCHED_FIFO` priority of a stand-in device (`haptic2d emulate …`, the UDP reference devices):
/// 70. A real device has a CPU of its own; its stand-in shares the host's cores, and at normal
/// priority an ordinary loaded desktop delays its answers by tens of milliseconds, which the host
/// rightly reads as a late device (issue 39 item 4: at load average 14 on a 2-core machine, 4 of 4
/// runs against the Haply emulator at normal priority lost the device, 0 of 4 with it at
/// `SCHED_FIFO` 70). Below the loop's [`LOOP_FIFO_PRIORITY`], so that the stand-in never delays
/// the loop it serves; not pinned, so that it runs on whichever core the loop leaves free.
pub const DEVICE_FIFO_PRIORITY: i32 = 70;

impl RtRequest {
    /// What a stand-in device asks for: `SCHED_FIFO` at `priority` (default
    /// [`DEVICE_FIFO_PRIORITY`]), memory locked, no pinning. Threads the caller starts afterwards
    /// inherit the scheduling policy (Linux's default `PTHREAD_INHERIT_SCHED`).
    pub fn device(priority: i32) -> Self {
        Self {
            fifo_priority: Some(priority),
            lock_memory: true,
            prefault_stack_bytes: 64 * 1024,
            pin: CorePin::None,
        }
    }
}

/// Outcome of one real-time setup step.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum StepStatus {
    /// Applied; the text says what (e.g. "SCHED_FIFO 80").
    Applied(String),
    /// The kernel refused for lack of privilege; the text says what to grant.
    NotPermitted(String),
    /// Failed for another reason (text: the OS error).
    Failed(String),
    /// Not requested.
    Skipped,
}

impl StepStatus {
    /// True when the step was applied.
    pub fn is_applied(&self) -> bool {
        matches!(self, StepStatus::Applied(_))
    }

    /// True when the step was requested but not applied.
    pub fn is_degraded(&self) -> bool {
        matches!(self, StepStatus::NotPermitted(_) | StepStatus::Failed(_))
    }
}

impl fmt::Display for StepStatus {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            StepStatus::Applied(s) => write!(f, "{s}"),
            StepStatus::NotPermitted(s) => write!(f, "not permitted ({s})"),
            StepStatus::Failed(s) => write!(f, "failed ({s})"),
            StepStatus::Skipped => write!(f, "off"),
        }
    }
}

/// The result of [`setup_realtime`], one status per step.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RtReport {
    /// `SCHED_FIFO` priority.
    pub scheduler: StepStatus,
    /// `mlockall` and stack pre-faulting.
    pub memory_lock: StepStatus,
    /// Core pinning.
    pub pinning: StepStatus,
}

impl RtReport {
    /// A report where nothing was requested.
    pub fn skipped() -> Self {
        Self {
            scheduler: StepStatus::Skipped,
            memory_lock: StepStatus::Skipped,
            pinning: StepStatus::Skipped,
        }
    }

    /// True if any requested step was not applied.
    pub fn is_degraded(&self) -> bool {
        self.scheduler.is_degraded() || self.memory_lock.is_degraded() || self.pinning.is_degraded()
    }

    /// One line for the caller to print when some requested step was not
    /// applied (the loop still runs); `None` when everything asked for was
    /// applied.
    pub fn warning(&self) -> Option<String> {
        if !self.is_degraded() {
            return None;
        }
        let mut parts = Vec::new();
        for (name, s) in [
            ("SCHED_FIFO", &self.scheduler),
            ("mlockall", &self.memory_lock),
            ("core pinning", &self.pinning),
        ] {
            if s.is_degraded() {
                parts.push(format!("{name} {s}"));
            }
        }
        Some(format!(
            "note: real-time setup incomplete, running best-effort with more jitter: {}",
            parts.join("; ")
        ))
    }
}

impl RtReport {
    /// The line a stand-in device (`program`, e.g. `haptic2d emulate haply`) prints at start: its
    /// real-time status, and when `SCHED_FIFO` was refused, what the refusal means for the host and
    /// the three ways to get it (the capability, an rtprio limit, or `chrt`).
    pub fn device_note(&self, program: &str, priority: i32) -> String {
        match &self.scheduler {
            StepStatus::Applied(s) => format!("{program}: real-time priority {s}"),
            StepStatus::Skipped => format!(
                "{program}: normal priority (--no-rt): on a loaded machine its answers come late and the host may stop with a lost device"
            ),
            s => format!(
                "warning: {program} runs without real-time priority (SCHED_FIFO {priority} {s}): on a loaded machine its answers come late and the host may stop with a lost device (exit 4)\n    fix: run it as root, or `sudo setcap cap_sys_nice,cap_ipc_lock+ep BINARY`, or raise the rtprio limit (`ulimit -r {priority}`; `@audio - rtprio 95` in /etc/security/limits.conf), or start it with `sudo chrt -f {priority} …`"
            ),
        }
    }
}

impl fmt::Display for RtReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "real-time: scheduler {}, memory {}, pinning {}",
            self.scheduler, self.memory_lock, self.pinning
        )
    }
}

/// Applies `req` to the calling thread (and, for `mlockall`, the process),
/// step by step. Never fails; see [`RtReport::warning`].
pub fn setup_realtime(req: &RtRequest) -> RtReport {
    RtReport {
        scheduler: match req.fifo_priority {
            Some(p) => set_fifo_priority(p),
            None => StepStatus::Skipped,
        },
        memory_lock: if req.lock_memory {
            lock_memory(req.prefault_stack_bytes)
        } else {
            StepStatus::Skipped
        },
        pinning: pin_to_core(req.pin),
    }
}

/// Switches the calling thread to `SCHED_FIFO` at `priority` (1–99).
pub fn set_fifo_priority(priority: i32) -> StepStatus {
    // SAFETY: plain libc queries with no pointers.
    let (lo, hi) = unsafe {
        (
            libc::sched_get_priority_min(libc::SCHED_FIFO),
            libc::sched_get_priority_max(libc::SCHED_FIFO),
        )
    };
    if priority < lo || priority > hi {
        return StepStatus::Failed(format!("fifo_priority = {priority} is outside {lo}..={hi}"));
    }
    let param = libc::sched_param {
        sched_priority: priority,
    };
    // SAFETY: `param` is a valid sched_param; pthread_self() is always valid.
    let rc = unsafe { libc::pthread_setschedparam(libc::pthread_self(), libc::SCHED_FIFO, &param) };
    match rc {
        0 => StepStatus::Applied(format!("SCHED_FIFO {priority}")),
        libc::EPERM => StepStatus::NotPermitted(format!(
            "needs CAP_SYS_NICE or `ulimit -r {priority}` or higher"
        )),
        e => StepStatus::Failed(std::io::Error::from_raw_os_error(e).to_string()),
    }
}

/// Locks all current and future pages of the process in RAM and pre-faults
/// `prefault_stack_bytes` of the calling thread's stack.
pub fn lock_memory(prefault_stack_bytes: usize) -> StepStatus {
    // SAFETY: mlockall takes flags only.
    let rc = unsafe { libc::mlockall(libc::MCL_CURRENT | libc::MCL_FUTURE) };
    if rc != 0 {
        let err = std::io::Error::last_os_error();
        return match err.raw_os_error() {
            Some(libc::EPERM) | Some(libc::ENOMEM) => StepStatus::NotPermitted(
                "needs CAP_IPC_LOCK or a large enough `ulimit -l`, e.g. unlimited".to_string(),
            ),
            _ => StepStatus::Failed(err.to_string()),
        };
    }
    prefault_stack(prefault_stack_bytes);
    StepStatus::Applied(format!(
        "mlockall, {} KiB stack pre-faulted",
        prefault_stack_bytes / 1024
    ))
}

/// Touches `bytes` of stack below the current frame, 4 KiB at a time, so that
/// the pages are mapped (and, after `mlockall`, locked) before the loop runs.
#[inline(never)]
fn prefault_stack(bytes: usize) {
    const CHUNK: usize = 4096;
    fn touch(remaining: usize) {
        let mut page = [0u8; CHUNK];
        // Keep the page from being optimised away.
        std::hint::black_box(&mut page);
        if remaining > CHUNK {
            touch(remaining - CHUNK);
        }
        // Use the page after the call, so this is not a tail call that could reuse one frame.
        std::hint::black_box(&page);
    }
    if bytes > 0 {
        touch(bytes);
    }
}

/// Pins the calling thread to the core chosen by `pin`.
pub fn pin_to_core(pin: CorePin) -> StepStatus {
    if pin == CorePin::None {
        return StepStatus::Skipped;
    }
    let Some(cores) = core_affinity::get_core_ids() else {
        return StepStatus::Failed("cannot list the cores this process may use".to_string());
    };
    let core = match pin {
        CorePin::None => return StepStatus::Skipped,
        CorePin::Last => match cores.iter().max_by_key(|c| c.id) {
            Some(c) => *c,
            None => return StepStatus::Failed("no usable core".to_string()),
        },
        CorePin::Core(id) => match cores.iter().find(|c| c.id == id) {
            Some(c) => *c,
            None => {
                let ids: Vec<String> = cores.iter().map(|c| c.id.to_string()).collect();
                return StepStatus::Failed(format!(
                    "core {id} is not available; usable cores: {}",
                    ids.join(", ")
                ));
            }
        },
    };
    if core_affinity::set_for_current(core) {
        StepStatus::Applied(format!("core {}", core.id))
    } else {
        StepStatus::Failed(format!("sched_setaffinity to core {} refused", core.id))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn out_of_range_priority_is_reported_not_panicking() {
        assert!(set_fifo_priority(1000).is_degraded());
    }

    #[test]
    fn device_note_says_how_to_get_real_time_priority_when_refused() {
        let refused = RtReport {
            scheduler: StepStatus::NotPermitted("needs CAP_SYS_NICE".into()),
            ..RtReport::skipped()
        };
        let n = refused.device_note("haptic2d emulate haply", 70);
        assert!(n.starts_with("warning:"), "{n}");
        assert!(
            n.contains("lost device") && n.contains("chrt -f 70") && n.contains("ulimit -r 70")
        );
        let applied = RtReport {
            scheduler: StepStatus::Applied("SCHED_FIFO 70".into()),
            ..RtReport::skipped()
        };
        let n = applied.device_note("sim", 70);
        assert!(!n.contains("warning") && n.contains("SCHED_FIFO 70"), "{n}");
        assert!(RtReport::skipped()
            .device_note("sim", 70)
            .contains("normal priority"));
    }

    #[test]
    fn device_request_is_below_the_loop_and_unpinned() {
        const { assert!(DEVICE_FIFO_PRIORITY < LOOP_FIFO_PRIORITY) };
        let r = RtRequest::device(DEVICE_FIFO_PRIORITY);
        assert_eq!(r.fifo_priority, Some(70));
        assert_eq!(r.pin, CorePin::None);
        assert_eq!(RtRequest::default().fifo_priority, Some(80));
    }

    #[test]
    fn warning_is_one_line_only_when_degraded() {
        assert_eq!(RtReport::skipped().warning(), None);
        let r = RtReport {
            scheduler: StepStatus::NotPermitted("needs CAP_SYS_NICE".into()),
            memory_lock: StepStatus::Applied("mlockall".into()),
            pinning: StepStatus::Applied("core 1".into()),
        };
        let w = r.warning().unwrap();
        assert!(!w.contains('\n'));
        assert!(w.contains("SCHED_FIFO") && w.contains("CAP_SYS_NICE"));
        assert!(!w.contains("mlockall"));
    }
}
