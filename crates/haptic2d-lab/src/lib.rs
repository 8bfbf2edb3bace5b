//! `haptic2d-lab`: reproduction of the paper's experiments as data, plots, metrics and a report, and
//! parameter sweeps of the virtual walls.
//!
//! - [`figures`]: the [`Figure`] trait and the registry of figures; [`reproduce`] runs a selection of
//!   them, writes `DIR/<figure>/` (CSV series, SVG + PNG plots, `metrics.json`) and `DIR/REPORT.md`.
//!   One module a figure: [`figures::fig4`] (Fig. 4, a box pushed into undamped walls, §5.10,
//!   §13.1, in 1-D and through the 2-D world), [`figures::fig5`] (Figs. 5–6, the walls with the
//!   device in the loop, with [`figures::fig5_sweep`]), [`figures::fig7`] (Fig. 7, a peg pushed into
//!   a tight hole, §13.2) and [`figures::fig8`] (Figs. 8–11, the peg with the device in the loop).
//! - [`scenarios`]: the device-in-the-loop simulations the figures call, named for what they
//!   simulate: [`scenarios::walls_with_device`] (Figs. 5–6) and [`scenarios::peg_with_device`]
//!   (Figs. 8–11).
//! - [`harness`]: the 1-D reduced harnesses of Figs. 4 and 7 (§5.1, §13).
//! - [`network`]: the loop split at a network: an impairment layer and a device–world run across it
//!   with and without time-domain passivity (issue 41).
//! - [`sweep`]: stiffness × damping sweeps of the wall laws on the 1-D Fig. 4 harness (Z-width chart).
//!
//! Adding a figure: implement [`Figure`] in a new file of `figures/` and add it to
//! [`figures::registry`].

#![warn(missing_docs)]

pub mod csv;
pub mod design;
pub mod figures;
pub mod harness;
pub mod network;
pub mod plot;
pub mod scenarios;
pub mod schema;
pub mod stability;
pub mod study;
pub mod sweep;
pub mod world2d;

pub use figures::{
    registry, reproduce, reproduce_with, Figure, FigureContext, FigureReport, ReproduceSummary,
};
pub use schema::{CaseMetrics, Check, Dimension, FigureMetrics, Measured};
