//! A receive interrupted by a signal is retried, not a lost device (CI found it: after
//! SIGSTOP/SIGCONT, Linux fails a socket read that has a timeout with EINTR even without a signal
//! handler — signal(7) — and the UDP driver took that for a receive failure).
//!
//! The test provokes the same EINTR deterministically: a SIGUSR1 handler installed without
//! `SA_RESTART`, sent to the thread that waits for the device's answer.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::thread;
use std::time::{Duration, Instant};

use haptic2d_devices::udp::UdpTransport;

// Its own binary (not a module of `it`): see tests/it/main.rs.
#[path = "it/udp_echo.rs"]
#[allow(dead_code)]
mod udp_echo;
use udp_echo::{spawn_echo_device, ECHO_POSITION};

static SIGNALS: AtomicUsize = AtomicUsize::new(0);

extern "C" fn on_usr1(_: libc::c_int) {
    SIGNALS.fetch_add(1, Ordering::Relaxed);
}

/// Installs `on_usr1` for SIGUSR1 with no `SA_RESTART`, so a blocked `recv` returns EINTR.
fn install_interrupting_handler() {
    unsafe {
        let mut sa: libc::sigaction = std::mem::zeroed();
        sa.sa_sigaction = on_usr1 as *const () as usize;
        sa.sa_flags = 0;
        libc::sigemptyset(&mut sa.sa_mask);
        assert_eq!(libc::sigaction(libc::SIGUSR1, &sa, std::ptr::null_mut()), 0);
    }
}

#[test]
fn a_receive_interrupted_by_a_signal_is_retried_until_the_answer() {
    install_interrupting_handler();
    // The device answers each command 60 ms late.
    let addr = spawn_echo_device(Duration::from_millis(60));

    let mut t = UdpTransport::connect(addr).unwrap();
    // Signal this thread three times while it waits (10, 20, 30 ms into the wait).
    let me = unsafe { libc::pthread_self() };
    let before = SIGNALS.load(Ordering::Relaxed);
    t.send(0, [0.0; 3]).unwrap();
    let signaller = thread::spawn(move || {
        for _ in 0..3 {
            thread::sleep(Duration::from_millis(10));
            unsafe { libc::pthread_kill(me, libc::SIGUSR1) };
        }
    });
    let t0 = Instant::now();
    let answered = t
        .wait_answer(Instant::now() + Duration::from_millis(500))
        .expect("an interrupted receive is retried, not an error");
    signaller.join().unwrap();
    assert!(answered, "the answer arrived within the deadline");
    assert!(
        t0.elapsed() >= Duration::from_millis(50),
        "waited for the late answer"
    );
    assert_eq!(
        SIGNALS.load(Ordering::Relaxed) - before,
        3,
        "signals delivered"
    );
    assert_eq!(t.latest().expect("a state").position, ECHO_POSITION);
    assert_eq!(t.counters().timeouts, 0);
}
