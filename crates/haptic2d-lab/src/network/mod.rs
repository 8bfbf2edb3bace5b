//! The haptic loop split at a network (issue 41): an in-process impairment layer ([`link`]) and a
//! device–world experiment across it with and without time-domain passivity ([`delayed_wall`]), and
//! bilateral teleoperation of two simulated devices across it ([`teleop`], position–force or
//! four-channel: [`four_channel`]).
//! Everything is deterministic (seeded) and runs in simulated time, for tests and studies; the
//! process split over UDP is `haptic2d serve-world` / `remote-device` (docs/TELEOP.md).

pub mod delayed_wall;
pub mod figures;
pub mod four_channel;
pub mod held;
pub mod link;
pub mod onset;
pub mod teleop;
pub mod wave;

pub use delayed_wall::{run_delayed_wall, DelayedWall, DelayedWallResult, LinkMode};
pub use four_channel::{Architecture, FourChannel};
pub use link::{Impairment, Link};
pub use teleop::{run_teleop, Teleop, TeleopResult};
pub use wave::{WaveMaster, WaveMsg, WaveParams, WaveSlave};
