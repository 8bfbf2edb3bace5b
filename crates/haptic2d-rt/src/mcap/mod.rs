//! MCAP logs of the haptic loop and the world (issue 14; channels and schemas: docs/LOGS.md).
//!
//! - [`clock`]: `log_time` in Unix-epoch ns (the offset from `CLOCK_MONOTONIC`);
//! - [`columns`]: the one table of tick columns with units (CSV header, JSON Schema, JSON rows);
//! - [`record`]: [`LoggedTick`], the fixed-size record the loop pushes into the telemetry ring;
//! - [`encode`]: the JSON encoders of the messages (shared with the Foxglove live server);
//! - [`schemas`]: topics and JSON Schemas of the other channels (Foxglove `SceneUpdate` included);
//! - [`writer`]: [`McapSink`], an MCAP file being written;
//! - [`logger`]: [`McapLogger`], the logger thread draining the ring into a sink;
//! - [`limits`]: the caps every log reader checks first (1 GiB a file, 1 MiB a CSV line);
//! - [`frame`]: the bounded MCAP record reader (every length checked before it is used);
//! - [`reader`]: reading logs back (info, tick rows, encoder angles for a replay);
//! - [`replay`]: [`McapReplay`], `--device replay:FILE.mcap`;
//! - [`tick_csv`]: CSV tick logs read back (`log info`, `log convert`);
//! - [`world_csv`]: the world channels as CSV tables (`log convert FILE.mcap OUT.csv`).

pub mod clock;
pub mod columns;
pub mod encode;
pub mod frame;
pub mod limits;
pub mod logger;
pub mod reader;
pub mod record;
pub mod replay;
pub mod schemas;
pub mod tick_csv;
pub mod world_csv;
pub mod writer;

pub use logger::{McapLogger, McapReport};
pub use record::{LoggedTick, WorldSample};
pub use replay::McapReplay;
pub use writer::{McapSetup, McapSink, McapStats};

/// An MCAP metadata record (name and string map), re-exported from the `mcap` crate.
pub use ::mcap::records::Metadata;
