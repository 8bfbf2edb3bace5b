//! Contact solvers that act on the loaded contacts after the contact forces of a sample: the
//! implicit chain damper (MODELS §6.7, §0.5 step 10b), a projected Gauss–Seidel solve over the
//! chain contacts with graph colouring. (The impact solvers of §7 are `contact/impact*.rs`.)

mod chain;

pub use chain::{ChainDamping, DEFAULT_CHAIN_SWEEPS, DEFAULT_CHAIN_TAU};
