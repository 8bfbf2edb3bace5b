//! The simulated device behind [`DeviceIo`]: the lumped twin-pantograph plant
//! ([`SimDevice`], MODELS §10.6) pushed by a simulated [`HandModel`].
//!
//! Time in the plant advances only in [`write_torques`](DeviceIo::write_torques): each call integrates
//! one period `T` (RK4 sub-steps) under the torques just written, held, and the hand's wrench. So one
//! loop tick = read the encoders at `kT` → compute → write → the plant reaches `(k+1)T`.
//!
//! A spring–damper hand can follow a target that another thread moves (the browser pointer, later):
//! [`SharedTarget`] is three atomics, read once per tick without locks.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

use haptic2d::device::linalg::{V3, V4};
use haptic2d::device::{DeviceParams, HandModel, SimDevice};

use crate::io::{DeviceError, DeviceIo};

/// A hand target pose `(x, y, θ)` (m, m, rad, handle coordinates) shared between threads without locks.
#[derive(Debug, Default)]
pub struct SharedTarget {
    bits: [AtomicU64; 3],
}

impl SharedTarget {
    /// A target at `pose` (m, m, rad).
    pub fn new(pose: V3) -> Self {
        let t = Self::default();
        t.set(pose);
        t
    }

    /// Moves the target to `pose` (m, m, rad). Non-finite components are ignored.
    pub fn set(&self, pose: V3) {
        for (b, v) in self.bits.iter().zip(pose) {
            if v.is_finite() {
                b.store(v.to_bits(), Ordering::Relaxed);
            }
        }
    }

    /// The current target (m, m, rad).
    pub fn get(&self) -> V3 {
        std::array::from_fn(|i| f64::from_bits(self.bits[i].load(Ordering::Relaxed)))
    }
}

/// A simulated twin-pantograph device with a simulated hand.
#[derive(Debug)]
pub struct SimIo {
    plant: SimDevice,
    hand: HandModel,
    target: Option<Arc<SharedTarget>>,
    dt: f64,
    name: String,
}

impl SimIo {
    /// A plant for device `params` at rest at handle pose `x0` (m, m, rad), stepped by `dt` (s) per
    /// write with `substeps` RK4 sub-steps, pushed by `hand`. Errors name the bad setting.
    pub fn new(
        params: &DeviceParams,
        x0: V3,
        hand: HandModel,
        dt: f64,
        substeps: u32,
    ) -> Result<Self, String> {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(format!("simulated device: period must be > 0 s (got {dt})"));
        }
        if substeps == 0 {
            return Err("simulated device: substeps must be at least 1".into());
        }
        let mut plant = SimDevice::new(params, x0)?;
        plant.substeps = substeps;
        Ok(Self {
            plant,
            hand,
            target: None,
            dt,
            name: "sim".into(),
        })
    }

    /// Makes a spring–damper (or scripted) hand follow `target`, read at every tick. Returns false,
    /// changing nothing, if the hand has no target.
    pub fn follow(&mut self, target: Arc<SharedTarget>) -> bool {
        let ok = self.hand.set_target(target.get());
        if ok {
            self.target = Some(target);
        }
        ok
    }

    /// The simulated plant (true state).
    pub fn plant(&self) -> &SimDevice {
        &self.plant
    }

    /// The hand model.
    pub fn hand(&self) -> &HandModel {
        &self.hand
    }
}

impl DeviceIo for SimIo {
    fn read_encoders(&mut self) -> Result<[f64; 4], DeviceError> {
        self.plant
            .encoders()
            .map_err(|e| DeviceError::Lost(format!("simulated device: {e}")))
    }

    fn write_torques(&mut self, tau: &V4) -> Result<(), DeviceError> {
        if let Some(t) = &self.target {
            self.hand.set_target(t.get());
        }
        self.plant
            .step(tau, &self.hand, self.dt)
            .map(|_| ())
            .map_err(|e| DeviceError::Lost(format!("simulated device: {e}")))
    }

    fn zero_torques(&mut self) {
        // Nothing is held between writes: the next write decides the torques of the next period.
    }

    fn name(&self) -> &str {
        &self.name
    }

    fn paced_by_ticks(&self) -> bool {
        true
    }
}
