//! [`DeviceInTheLoop`]: a [`HapticSystem`] closed around a simulated twin-pantograph plant and a
//! simulated hand, stepped in simulated time (deterministic; no clock, no threads). Used by the
//! device-in-the-loop experiments and tests.
//!
//! It stays in the core crate although the experiments live in `haptic2d-lab`: it is no experiment
//! (no scenario, metric or report), only the loop closed around the core's own simulated plant, and
//! the core's integration tests of the tick (`haptic_loop.rs`, `passivity_port.rs`,
//! `workspace_bound.rs`) need it; the lab cannot be their dependency.

use crate::device::linalg::V3;
use crate::device::{DeviceFault, HandModel, SimDevice};

use super::record::TickRecord;
use super::system::HapticSystem;
use super::tick::TickOutput;

/// A haptic system, a simulated device plant and a hand, one tick at a time.
#[derive(Clone, Debug)]
pub struct DeviceInTheLoop {
    /// The haptic system under test.
    pub system: HapticSystem,
    /// The simulated plant (true device state).
    pub plant: SimDevice,
    /// The simulated hand acting on the plant; may be replaced between ticks.
    pub hand: HandModel,
}

impl DeviceInTheLoop {
    /// Closes the loop: the plant starts at rest at the system's device origin with `substeps` RK4
    /// sub-steps per tick and encoder quantisation `quantize`.
    pub fn new(
        system: HapticSystem,
        hand: HandModel,
        substeps: u32,
        quantize: bool,
    ) -> Result<Self, String> {
        let params = system.device().params;
        let mut plant = SimDevice::new(&params, system.device_start())?;
        plant.substeps = substeps.max(1);
        plant.quantize = quantize;
        Ok(Self {
            system,
            plant,
            hand,
        })
    }

    /// One tick: read the plant's encoders, run the haptic tick, then advance the plant by `T` under
    /// the torques (held) and the hand. Errors if the plant itself fails (leaves its reachable set).
    pub fn step(&mut self) -> Result<TickOutput, DeviceFault> {
        let q = self.plant.encoders()?;
        let out = self.system.tick(&q);
        self.plant
            .step(&out.torques, &self.hand, self.system.dt())?;
        Ok(out)
    }

    /// Runs `n` ticks, returning every record (stops early, with the records so far and the fault,
    /// if the plant fails).
    pub fn run(&mut self, n: usize) -> (Vec<TickRecord>, Option<DeviceFault>) {
        let mut out = Vec::with_capacity(n);
        for _ in 0..n {
            match self.step() {
                Ok(o) => out.push(o.record),
                Err(e) => return (out, Some(e)),
            }
        }
        (out, None)
    }

    /// The true handle pose of the plant (m, m, rad).
    pub fn plant_pose(&self) -> V3 {
        self.plant.pose()
    }

    /// The true handle pose mapped into the world (m, m, rad).
    pub fn plant_pose_in_world(&self) -> V3 {
        self.system.map().pose_to_world(&self.plant.pose())
    }
}
