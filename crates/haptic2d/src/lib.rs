//! # haptic2d
//!
//! Passive planar rigid-body simulation for haptic rendering, after Constantinescu et al., *Haptic
//! Rendering of Planar Rigid-Body Motion using a Redundant Parallel Mechanism* (UBC).
//!
//! This core crate is pure computation: no threads, no I/O, `f64` throughout, deterministic. Section
//! numbers (§) refer to the project's model documentation, `docs/MODELS.md`; `DESIGN §N` to
//! `docs/ARCHITECTURE.md`.

#![warn(missing_docs)]

pub mod body;
mod buffers;
pub mod collide;
pub mod contact;
pub mod control;
pub mod device;
pub mod geom;
pub mod haptic;
pub mod integrate;
pub mod laws;
pub mod load;
pub mod metrics;
pub mod scene;
pub mod stage_time;
pub mod world;
