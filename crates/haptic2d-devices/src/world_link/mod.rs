//! The world link (issue 41, docs/TELEOP.md): the haptic loop split at a network, the device on
//! one machine and the world on another. Both sides exchange their port variables every period
//! over UDP in authenticated datagrams framed as the device protocol's version 2
//! (docs/DEVICE-PROTOCOL.md §3: the same `HELLO`/`WELCOME` handshake, the same key file and
//! HMAC-SHA256 MAC): [`message`] is the pure codec, [`endpoint`] the socket.

pub mod endpoint;
pub mod message;

pub use endpoint::{LinkCounters, LinkEndpoint};
pub use message::{PortMessage, Refused, KIND_TO_DEVICE, KIND_TO_WORLD, PORT_LEN};
