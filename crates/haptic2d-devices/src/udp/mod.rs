//! The open UDP device protocol (docs/DEVICE-PROTOCOL.md): the codec, the host transport over
//! `std::net::UdpSocket`, the authentication of version 2 (`auth`), device files and the driver
//! behind `DeviceIo`.

pub mod auth;
pub mod codec;
pub mod device_file;
pub mod driver;
pub mod transport;

pub use auth::UdpKey;
pub use codec::{CodecError, Command, State};
pub use device_file::UdpDeviceFile;
pub use driver::UdpDevice;
pub use transport::{UdpCounters, UdpTransport};
