//! The real-time haptic loop of haptic2d.
//!
//! Where time comes from, and how data leaves the real-time thread:
//!
//! - [`clock`]: absolute deadlines on `CLOCK_MONOTONIC`, sleep then spin;
//! - [`rt`]: best-effort `SCHED_FIFO`, `mlockall`, core pinning;
//! - [`runner`]: [`run_loop`] (or [`spawn_loop`] on its own thread) calls the
//!   haptic tick at every deadline;
//! - [`histogram`], [`stats`]: allocation-free timing statistics and the
//!   [`TimingSummary`] printed at exit;
//! - [`telemetry`]: wait-free ring (every record) and triple buffer (latest
//!   record) from the RT thread to other threads;
//! - [`logger`]: the CSV logger thread draining the ring (its handle a [`drain_thread`]);
//! - [`io`]: the [`DeviceIo`] trait the loop drives, and [`ReplayDevice`];
//! - [`watchdog`]: the latching safety watchdog that zeroes torques;
//! - [`signal`]: Ctrl-C to a stop flag;
//! - [`sim_io`]: the simulated twin pantograph and hand behind [`DeviceIo`];
//! - [`tick_log`]: CSV rows of the haptic tick record;
//! - [`float_text`]: an `f64` as `Display` writes it, fast (CSV numbers);
//! - [`mcap`]: MCAP logs (logger thread, schemas, reader).
#![warn(missing_docs)]

pub mod clock;
pub mod drain_thread;
pub mod float_text;
pub mod histogram;
pub mod io;
pub mod logger;
pub mod mcap;
pub mod rt;
pub mod runner;
pub mod signal;
pub mod sim_io;
pub mod stats;
pub mod telemetry;
pub mod throttle;
pub mod tick_log;
pub mod watchdog;

pub use io::{DeviceError, DeviceIo, ReplayDevice, ReplayEnd};
pub use logger::{CsvLogger, CsvRecord, LogReport, LoggerConfig};
pub use rt::{setup_realtime, CorePin, RtReport, RtRequest};
pub use runner::{run_loop, spawn_loop, LoopConfig, TickControl, TickInfo, TickInterval};
pub use sim_io::{SharedTarget, SimIo};
pub use stats::{Percentiles, TimingStats, TimingSummary};
pub use telemetry::{telemetry_channel, RecordRx, SnapshotRx, TelemetryTx};
pub use watchdog::{Fault, FaultKind, SafetyInput, Watchdog, WatchdogConfig};
