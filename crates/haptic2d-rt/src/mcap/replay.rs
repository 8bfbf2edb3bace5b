//! [`McapReplay`]: `--device replay:FILE.mcap` — the encoder angles of an MCAP log's
//! `/haptic2d/tick` messages played back like the CSV [`ReplayDevice`] (which it wraps).

use crate::io::{DeviceError, DeviceIo, ReplayDevice, ReplayEnd};
use crate::mcap::reader::read_encoders;
use std::path::Path;

/// A replay of the `encoders.q1..q4` (rad) of an MCAP tick log; torques are discarded.
#[derive(Debug, Clone)]
pub struct McapReplay {
    inner: ReplayDevice,
    name: String,
}

impl McapReplay {
    /// Loads every tick's encoder angles of the log at `path` (read once, here; reading a sample
    /// on the RT thread is an array index). Errors name the file and what is missing.
    pub fn from_path(path: &Path, end: ReplayEnd) -> Result<Self, String> {
        let samples = read_encoders(path)?;
        Ok(Self {
            inner: ReplayDevice::from_samples(samples, end)?,
            name: format!("replay:{}", path.display()),
        })
    }

    /// The samples, radians.
    pub fn samples(&self) -> &[[f64; 4]] {
        self.inner.samples()
    }
}

impl DeviceIo for McapReplay {
    fn read_encoders(&mut self) -> Result<[f64; 4], DeviceError> {
        self.inner.read_encoders()
    }

    fn write_torques(&mut self, tau: &[f64; 4]) -> Result<(), DeviceError> {
        self.inner.write_torques(tau)
    }

    fn zero_torques(&mut self) {
        self.inner.zero_torques()
    }

    fn name(&self) -> &str {
        &self.name
    }

    /// Like the CSV replay: one recorded row per read, whatever the wall clock says, so the loop
    /// neither measures the interval nor trips on a stall. (Without this the MCAP replay was taken
    /// for a real-time device: a scheduling stall of a loaded machine tripped the watchdog, and
    /// the measured intervals changed the replayed device twist.)
    fn paced_by_ticks(&self) -> bool {
        self.inner.paced_by_ticks()
    }
}
