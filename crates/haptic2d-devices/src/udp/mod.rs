//! The open UDP device protocol (docs/DEVICE-PROTOCOL.md): the codec, the host transport over
//! `std::net::UdpSocket`, device files and the driver behind `DeviceIo`.

pub mod codec;

pub use codec::{CodecError, Command, State};
