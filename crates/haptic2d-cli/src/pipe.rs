//! Broken pipes and `SIGPIPE` (issue 39 item 7, issue 38 item 3): a command whose reader goes
//! away (`haptic2d run … | head -1`) ends quietly with the shell status 141, as `cat` does, and
//! never by a panic (exit 101) — and never before its logs are finished and its torques zeroed.
//!
//! - Printing commands (no device, no log being written) keep `SIGPIPE`'s default action
//!   ([`quiet_on_closed_pipe`]): the first write to a closed pipe ends them.
//! - `run` keeps `SIGPIPE` ignored (Rust's default: a device socket must see `EPIPE` as an error it
//!   handles, not a signal that kills the loop with torques applied) and prints through [`outln!`]:
//!   a closed standard output is noted and sent to `/dev/null` from then on, the run ends as it
//!   would (torques zeroed, logs finished), then the process ends of `SIGPIPE`
//!   ([`end_if_broken`]).
//! - `simulate --out FILE` catches `SIGPIPE` like `SIGTERM` ([`stop_on_sigpipe`]): the step loop
//!   stops, the file is finished (an MCAP gets its summary and footer), then the process ends of
//!   `SIGPIPE` ([`restore_after_output`]).

use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};

/// Set when a write to standard output found the pipe closed.
static BROKEN: AtomicBool = AtomicBool::new(false);
/// Set by the `SIGPIPE` handler of [`stop_on_sigpipe`].
static SIGPIPE_SEEN: AtomicBool = AtomicBool::new(false);

/// `println!` for `run`: a closed standard output ends nothing (see the module docs).
#[macro_export]
macro_rules! outln {
    ($($arg:tt)*) => {
        $crate::pipe::write_line(format_args!($($arg)*))
    };
}

/// Writes one line to standard output; on a broken pipe, remembers it and points standard output
/// (and standard error, when it is the same pipe) at `/dev/null`, so that no later `println!`
/// anywhere in the process panics. Other write errors are ignored like a full terminal's.
pub fn write_line(args: std::fmt::Arguments) {
    if BROKEN.load(Ordering::Relaxed) {
        return;
    }
    let mut out = std::io::stdout().lock();
    let r = out
        .write_fmt(args)
        .and_then(|()| out.write_all(b"\n"))
        .and_then(|()| out.flush());
    if let Err(e) = r {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            BROKEN.store(true, Ordering::Relaxed);
            silence_closed_output();
        }
    }
}

/// Points fd 1 (and fd 2, when it is the same pipe) at `/dev/null`.
fn silence_closed_output() {
    #[cfg(unix)]
    // SAFETY: plain system calls on descriptors this process owns; `st` is written by fstat.
    unsafe {
        let null = libc::open(c"/dev/null".as_ptr(), libc::O_WRONLY);
        if null < 0 {
            return;
        }
        let mut a: libc::stat = std::mem::zeroed();
        let mut b: libc::stat = std::mem::zeroed();
        let same = libc::fstat(1, &mut a) == 0
            && libc::fstat(2, &mut b) == 0
            && a.st_dev == b.st_dev
            && a.st_ino == b.st_ino;
        libc::dup2(null, 1);
        if same {
            libc::dup2(null, 2);
        }
        libc::close(null);
    }
}

/// True when standard output was found closed.
pub fn broken() -> bool {
    BROKEN.load(Ordering::Relaxed)
}

/// Ends the process of `SIGPIPE` (shell status 141), as a command killed by a closed pipe does.
pub fn die_of_sigpipe() -> ! {
    #[cfg(unix)]
    // SAFETY: restoring the default disposition and raising a signal are async-signal-safe calls.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
        libc::raise(libc::SIGPIPE);
    }
    std::process::exit(141)
}

/// Called when a command that printed through [`outln!`] has finished everything: if its output
/// was closed, it ends of `SIGPIPE` now.
pub fn end_if_broken() {
    if broken() {
        die_of_sigpipe();
    }
}

/// `SIGPIPE`'s default action: a printing command ends quietly when its reader closes the pipe
/// (`haptic2d simulate … | head -1`), instead of panicking in `println!`.
pub fn quiet_on_closed_pipe() {
    #[cfg(unix)]
    // SAFETY: SIG_DFL is a valid disposition for SIGPIPE.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

#[cfg(unix)]
extern "C" fn on_sigpipe(_: libc::c_int) {
    SIGPIPE_SEEN.store(true, Ordering::SeqCst);
}

/// For a command writing a file (`simulate --out`): `SIGPIPE` (sent by `kill`, or a progress line
/// to a closed standard error) is noted instead of killing the process mid-file; the command stops
/// like on `SIGTERM` ([`sigpipe_seen`]) and finishes the file first.
pub fn stop_on_sigpipe() {
    #[cfg(unix)]
    // SAFETY: the handler only stores to an atomic (async-signal-safe); the sigaction struct is
    // zero-initialised then filled.
    unsafe {
        let mut sa: libc::sigaction = std::mem::zeroed();
        sa.sa_sigaction = on_sigpipe as extern "C" fn(libc::c_int) as libc::sighandler_t;
        libc::sigemptyset(&mut sa.sa_mask);
        sa.sa_flags = libc::SA_RESTART;
        libc::sigaction(libc::SIGPIPE, &sa, std::ptr::null_mut());
    }
}

/// True once `SIGPIPE` arrived under [`stop_on_sigpipe`].
pub fn sigpipe_seen() -> bool {
    SIGPIPE_SEEN.load(Ordering::SeqCst)
}

/// Called once the file of [`stop_on_sigpipe`] is finished: if `SIGPIPE` arrived, the process ends
/// of it now; otherwise `SIGPIPE` gets its default action back for the summary lines.
pub fn restore_after_output() {
    if sigpipe_seen() {
        die_of_sigpipe();
    }
    quiet_on_closed_pipe();
}
