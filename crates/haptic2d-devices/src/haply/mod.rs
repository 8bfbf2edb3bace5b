//! Haply control boards (M0/M3; 2DIY kits) over USB serial: the protocol codec, the transport, the
//! driver behind `DeviceIo`, device files, and the board emulator with its simulated linkages.

pub mod buttons;
pub mod codec;
pub mod device_file;
pub mod driver;
pub mod emulator;
pub mod identified;
pub mod identify;
pub mod plant;
pub mod serial;
pub mod system;
pub mod transport;

pub use buttons::{ButtonReader, ButtonSpec};
pub use codec::{BoardSetup, CodecError, FirmwareIdentity, Reply, Rotation};
pub use device_file::{HaplyDeviceFile, HaplyKind, MotorSpec};
pub use driver::{check_rest, HaplyDevice, NO_WATCHDOG_WARNING};
pub use emulator::{
    serve, serve_with_analog, AnalogInputs, BoardKind, EmulatorClock, EmulatorConfig,
    EmulatorReport, Firmware,
};
pub use plant::{Plant, Plant2};
pub use system::{HaplySystem, HaplyTick};
pub use transport::{HaplyError, Transport};
