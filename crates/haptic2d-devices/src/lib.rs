//! Real-device drivers of haptic2d behind `haptic2d-rt`'s [`DeviceIo`](haptic2d_rt::DeviceIo), and
//! emulators that speak the same protocols so that every test runs without hardware.
//!
//! - [`haply`]: Haply boards (the 2DIY pantograph, and the twin pantograph built from two 2DIY
//!   linkages on one board's 4 ports), docs/DEVICES.md §1–§3.
//! - [`udp`]: the open UDP device protocol for custom hardware and other programs
//!   (docs/DEVICE-PROTOCOL.md).
//! - [`world_link`]: the haptic loop split at the network (the device on one machine, the world on
//!   another), in the UDP protocol's authenticated framing (docs/TELEOP.md).
//! - `inverse3` (feature `inverse3`): Haply's Inverse3 through its Inverse Service and the `haply`
//!   client crate, in planar mode, and an emulator of the service (docs/DEVICES.md §4).
#![warn(missing_docs)]

pub mod device_safety;
pub mod device_toml;
pub mod file_read;
pub mod haply;
#[cfg(feature = "inverse3")]
pub mod inverse3;
pub mod registry;
pub mod udp;
pub mod world_link;
