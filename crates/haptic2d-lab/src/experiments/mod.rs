//! The paper's device-in-the-loop experiments, as library code: each runs a
//! [`HapticSystem`](haptic2d::haptic::HapticSystem) closed around the simulated twin pantograph and a
//! simulated hand ([`DeviceInTheLoop`](haptic2d::haptic::DeviceInTheLoop)) and measures the claim.
//! The [`Figure`](crate::Figure)s of [`crate::fig5`] and [`crate::fig8`] turn them into data, plots
//! and the report.
//!
//! - [`fig5`]: Figs. 5–6, the walls on the haptic interface.
//! - [`fig8`]: Figs. 8–11, the peg in a tight hole, one friction model per case.

pub mod fig5;
pub mod fig8;
