//! The dual-pantograph ("twin pantograph") planar haptic device (§10): kinematics, Jacobian,
//! redundancy resolution, lumped dynamics, hand-wrench observers, sensing, a simulated plant and
//! simulated hands. [`TwinPantograph`] is the per-tick façade for the real-time loop.

pub mod cartesian;
pub mod dynamics;
pub mod encoder;
pub mod fault;
pub mod filter;
pub mod five_bar;
pub mod hand;
pub mod jacobian;
pub mod linalg;
pub mod lowpass;
pub mod observer;
pub mod pantograph2;
pub mod pantograph2_device;
pub mod params;
pub mod point;
pub mod redundancy;
pub mod sim;
pub mod twin;
pub mod twin_pantograph;

pub use cartesian::CartesianDevice;
pub use fault::DeviceFault;
pub use hand::HandModel;
pub use observer::{HandWrenchObserver, ObserverKind};
pub use pantograph2_device::Pantograph2Device;
pub use params::DeviceParams;
pub use point::PointDevice;
pub use sim::SimDevice;
pub use twin::TwinKinematics;
pub use twin_pantograph::{DeviceEstimate, TorqueCommand, TwinPantograph};
