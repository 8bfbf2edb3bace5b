//! The haptic loop split at a network (issue 41): an in-process impairment layer ([`link`]) and a
//! device–world experiment across it with and without time-domain passivity ([`delayed_wall`]).
//! Everything is deterministic (seeded) and runs in simulated time, for tests and studies; the
//! process split over UDP is not built yet (docs/TELEOP.md says what is).

pub mod delayed_wall;
pub mod link;

pub use delayed_wall::{run_delayed_wall, DelayedWall, DelayedWallResult};
pub use link::{Impairment, Link};
