//! The one place this crate reaches the 1-D harnesses of Figs. 4 and 7 and the wall sweep's set-up.
//! When the harnesses move (to `haptic2d_lab`), only these paths change.

pub use haptic2d::harness::peg::{PegHarness, PegPush};
pub use haptic2d::harness::wall::{
    run_wall, EntryImpulse, WallConfig, WallIntegration, WallSample,
};
pub use haptic2d_lab::sweep::{classify, setup as sweep_setup, DampingKind, WallClass, MODELS};
