//! The Haply driver's exchange (read the reply, write the torques) allocates nothing once open
//! (issue 34 keeps it so: the identify, rest check and loss latch happen at open or on the error
//! path). The shared counting allocator counts per thread: the emulator's thread allocates freely.

use crate::exchange_alloc::exchange_allocations;
use crate::support::*;

use haptic2d::device::HandModel;
use haptic2d_rt::DeviceIo;

#[test]
fn the_haply_exchange_allocates_nothing_once_open() {
    let file = device_file("haply-2diy-gen3.toml");
    let start = file.rest_pose().unwrap();
    let emu = start_emulator(&file, HandModel::grip(start), 0.001);
    let mut dev = open_driver(&emu, &file, 0.001);
    let allocs = exchange_allocations(&mut dev, 500, |_| {});
    assert_eq!(allocs, 0, "allocations on the exchange");
}

/// With buttons on analog pins (longer replies, the button reader), the exchange and `buttons()`
/// still allocate nothing.
#[test]
fn the_haply_exchange_with_buttons_allocates_nothing_once_open() {
    let mut file = device_file("haply-2diy-gen3.toml");
    file.buttons = vec![
        haptic2d_devices::haply::ButtonSpec {
            pin: 61,
            pressed_above: 512.0,
        },
        haptic2d_devices::haply::ButtonSpec {
            pin: 56,
            pressed_above: 512.0,
        },
    ];
    let start = file.rest_pose().unwrap();
    let emu = start_emulator(&file, HandModel::grip(start), 0.001);
    let mut dev = open_driver(&emu, &file, 0.001);
    let mut pressed = 0;
    let allocs = exchange_allocations(&mut dev, 500, |d| pressed |= d.buttons());
    assert_eq!(allocs, 0, "allocations on the exchange");
    assert_eq!(pressed, 0, "the emulator's pins read 0: nothing pressed");
}
