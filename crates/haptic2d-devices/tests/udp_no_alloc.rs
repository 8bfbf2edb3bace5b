//! The UDP exchange allocates nothing once open (issue 15): a counting allocator that counts only
//! on the thread being measured (the in-test device thread allocates freely).

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::thread;
use std::time::Duration;

use haptic2d_devices::udp::{UdpDevice, UdpDeviceFile};
use haptic2d_rt::DeviceIo;

#[path = "support/udp_echo.rs"]
mod udp_echo;
use udp_echo::spawn_echo_device;

struct Counting;

static ALLOCS: AtomicUsize = AtomicUsize::new(0);
thread_local! {
    static MEASURING: Cell<bool> = const { Cell::new(false) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        if MEASURING.try_with(|m| m.get()).unwrap_or(false) {
            ALLOCS.fetch_add(1, Ordering::Relaxed);
        }
        unsafe { System.alloc(l) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        unsafe { System.dealloc(p, l) }
    }
}

#[global_allocator]
static A: Counting = Counting;

#[test]
fn the_exchange_allocates_nothing_once_open() {
    let addr = spawn_echo_device(Duration::ZERO);
    let mut file = UdpDeviceFile::reference();
    file.timeout_periods = 100.0;
    let mut dev = UdpDevice::open(addr, &file, Duration::from_millis(1), "udp:alloc").unwrap();
    for _ in 0..20 {
        dev.read_encoders().unwrap();
        dev.write_torques(&[0.01, -0.01, 0.0, 0.0]).unwrap();
    }
    MEASURING.with(|m| m.set(true));
    for _ in 0..500 {
        dev.read_encoders().unwrap();
        dev.write_torques(&[0.01, -0.01, 0.0, 0.0]).unwrap();
        thread::sleep(Duration::from_micros(200));
    }
    MEASURING.with(|m| m.set(false));
    assert!(dev.counters().fresh > 400, "{}", dev.counters());
    assert_eq!(
        ALLOCS.load(Ordering::Relaxed),
        0,
        "allocations on the exchange"
    );
}
