//! The haptic system: the twin-pantograph device, a teleoperation controller, the optional passivity
//! controller on the device port, and the virtual world, run one sample at a time by
//! [`HapticSystem::tick`] in the order of §0.5 (steps 1–11).
//!
//! The tick is pure computation (no allocation, no locks, no I/O). Where the encoder angles come from
//! and where the torques go is the caller's business: the real-time loop of `haptic2d-rt` (a real or
//! simulated device), or [`DeviceInTheLoop`], which closes the loop with a simulated plant and hand in
//! simulated time for tests and for the device-in-the-loop experiments of `haptic2d-lab`.

pub mod config;
mod controller;
pub mod coupling;
pub mod device_end;
pub mod device_system;
pub mod experiment;
pub mod limit_cycle;
pub mod mapping;
pub mod planar2;
pub mod plausibility;
pub mod point;
pub mod record;
pub mod safety;
pub mod safety_stage;
pub mod system;
pub mod tick;
pub mod workspace;

pub use config::{ControllerKind, HapticConfig};
pub use coupling::{DeviceCoupling, SlaveState};
pub use device_end::{DeviceEnd, EndDevice, EndOutput};
pub use device_system::DeviceSystem;
pub use experiment::DeviceInTheLoop;
pub use limit_cycle::LimitCycleMonitor;
pub use mapping::DeviceMap;
pub use planar2::{GraspConfig, GraspCoupling, GraspSettings, Planar2System};
pub use plausibility::JointPlausibility;
pub use point::{PointConfig, PointSystem};
pub use record::{TickRecord, TICK_COLUMNS};
pub use safety::{Safety, SafetyConfig, SafetyReason, SafetyTrip};
pub use safety_stage::SafetyStage;
pub use system::{HapticSystem, TwinCoupling};
pub use tick::{Haptic, TickOutput};
pub use workspace::{WorkspaceBound, WorkspaceSquare};
