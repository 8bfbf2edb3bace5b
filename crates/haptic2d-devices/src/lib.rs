//! Real-device drivers of haptic2d behind `haptic2d-rt`'s [`DeviceIo`](haptic2d_rt::DeviceIo), and
//! emulators that speak the same protocols so that every test runs without hardware.
//!
//! - [`haply`]: Haply boards (the 2DIY pantograph, and the twin pantograph built from two 2DIY
//!   linkages on one board's 4 ports), DEVICES §1–§3.
//! - [`udp`]: the open UDP device protocol for custom hardware and other programs
//!   (docs/DEVICE-PROTOCOL.md).
#![warn(missing_docs)]

pub mod file_read;
pub mod haply;
pub mod udp;
