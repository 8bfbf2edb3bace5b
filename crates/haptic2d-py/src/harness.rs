//! The one place this crate reaches the 1-D harnesses of Figs. 4 and 7 and the wall sweep's set-up.
//! They live in `haptic2d_lab::harness`; only these paths name them.

pub use haptic2d_lab::harness::peg::{PegHarness, PegPush};
pub use haptic2d_lab::harness::wall::{
    run_wall, EntryImpulse, WallConfig, WallIntegration, WallSample,
};
pub use haptic2d_lab::sweep::{classify, setup as sweep_setup, DampingKind, WallClass, MODELS};
