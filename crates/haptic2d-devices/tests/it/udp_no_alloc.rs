//! The UDP exchange allocates nothing once open (issue 15): the shared counting allocator counts per
//! thread, so the in-test device thread allocates freely.

use std::thread;
use std::time::Duration;

use haptic2d_devices::udp::{UdpDevice, UdpDeviceFile};

use crate::exchange_alloc::exchange_allocations;
use crate::udp_echo::{spawn_echo_device, spawn_echo_device_v2};

#[test]
fn the_exchange_allocates_nothing_once_open() {
    exchange_allocates_nothing(
        spawn_echo_device(Duration::ZERO),
        UdpDeviceFile::reference(),
    );
}

/// Version 2: the MAC of every command and the check of every state allocate nothing either.
#[test]
fn the_authenticated_exchange_allocates_nothing_once_open() {
    let key = haptic2d_devices::udp::UdpKey::from_bytes(&[0x42; 32]).unwrap();
    let mut file = UdpDeviceFile::reference();
    file.key = Some(key.clone());
    exchange_allocates_nothing(spawn_echo_device_v2(key), file);
}

fn exchange_allocates_nothing(addr: std::net::SocketAddr, mut file: UdpDeviceFile) {
    file.timeout_periods = 100.0;
    let mut dev = UdpDevice::open(addr, &file, Duration::from_millis(1), "udp:alloc").unwrap();
    let allocs = exchange_allocations(&mut dev, 500, |_| thread::sleep(Duration::from_micros(200)));
    assert!(dev.counters().fresh > 400, "{}", dev.counters());
    assert_eq!(allocs, 0, "allocations on the exchange");
}
