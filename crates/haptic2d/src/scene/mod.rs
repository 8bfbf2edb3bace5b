//! Scene files (TOML) → [`World`](crate::world::World), with validation that reports every problem with
//! the field it concerns and the fix.
//!
//! The format is documented in `docs/SCENES.md`; built-in scenes live in `scenes/` and are embedded in
//! the binary.

mod body_table;
pub mod bounds;
mod build;
mod builtin;
mod device;
mod error;
mod file;
mod laws;
mod load_table;
pub mod overlap;
pub mod static_sink;
mod world_table;

pub use bounds::{divergence, Divergence, MAX_BODIES, MAX_FILE_BYTES, MAX_RATE_HZ, MAX_SAMPLES};
pub use build::{spring_stop_speed, Scene, PULSE_NOT_PASSIVE_2D};
pub use builtin::{builtin, builtin_names, pile_toml, BUILTIN};
pub use device::{device_params_from_toml, DEVICE_TEMPLATE};
pub use error::{SceneError, SceneErrors};
pub use file::SceneFile;
pub use overlap::{overlaps, Overlap};
