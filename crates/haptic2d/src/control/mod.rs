//! Teleoperation controllers coupling the device to the virtual slave (§11) and passivity tools (§12).

pub mod coupling;
pub mod file;
pub mod four_channel;
pub mod held_work;
pub mod paced;
pub mod passivity;
pub mod tdpa;
