//! Haply's Inverse3 (3-DOF spatial) through Haply's Inverse Service and its official Rust client,
//! the `haply` crate (docs/DEVICES.md §4), in planar mode: two device axes carry the world plane, the third
//! is held by a stiff, damped virtual plane rendered on the device.
//!
//! - [`device_file`] — `devices/inverse3.toml`;
//! - [`planar`] — the plane mapping, the virtual plane, the force clamp;
//! - [`slots`] — the wait-free exchange with the client thread;
//! - [`client`] — the `haply::HaplyDevice` client on its own thread and tokio runtime;
//! - [`driver`] — [`Inverse3Device`], a Cartesian point device (the plane point in m, the plane
//!   force in N) behind the loop's [`DeviceIo`](haptic2d_rt::DeviceIo), driven by a
//!   [`PointSystem`](haptic2d::haptic::PointSystem);
//! - [`emulator`] — a stand-in for the Inverse Service on loopback (`haptic2d emulate inverse3`).

pub mod client;
pub mod device_file;
pub mod driver;
pub mod emulator;
pub mod planar;
pub mod slots;

pub use device_file::Inverse3DeviceFile;
pub use driver::Inverse3Device;
pub use emulator::{Emulator3Config, Hand3, Inverse3Emulator};
