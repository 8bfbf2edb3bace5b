//! Stability of the haptic loop per axis, with the hand held and released (issue 11, spec §11.4).
//!
//! **The mechanism.** The four-channel law of §11.1 with `C5 = C6 = 0` reflects the environment force
//! to the device (`C2 = 1`) and expects the hand's impedance to absorb it. With the handle released
//! against a stiff contact, the master (inertia `m`, tiny physical damping `b`) and the slave on the
//! contact spring `K_e` form a loop that is unstable **in continuous time**, before any sampling: the
//! released characteristic polynomial of §11.4 ([`axis::AxisModel::released_polynomial`]) has roots
//! at `+2.4 ± 67j` for the §10.2 device on the Fig. 4 box and `+30 ± 185j` for the peg's y axis at
//! world scale 2. Sampling faster does not help; Colgate's `b > K·T/2` is a different (sampling)
//! mechanism and is not what limits these runs. Local force feedback `C6 = −1` (so `C2 = 0`, the
//! three-channel form of Hashtrudi-Zaad and Salcudean, still transparent by §11.1's conditions)
//! removes the force path to the device and makes the released loop a passive-looking mass–spring
//! network; master damping injection `D_m` moves the polynomial's roots left at the price of a
//! damper the operator feels in free motion. The named configurations are in
//! `haptic2d::control::four_channel::FourChannelGains`.
//!
//! **What is computed** ([`LoopModel`], [`axis`]): for each axis (x, y, θ), a 1-DOF linear model in
//! world units (device inertia and damping at the start pose, the slave's mass, the scene's stiffest
//! contact as a spring to ground), with the grip hand and with none; its continuous-time poles, and
//! the eigenvalues of the sampled-data loop as the tick runs it (ZOH plant, velocity filter, momentum
//! observer, semi-implicit slave, optional output delay), whose growth rate `ln ρ/T` is the verdict.
//! Linear algebra: [`dense`] (matrix exponential) and [`eig`] (Hessenberg + shifted QR; polynomial
//! roots through the companion matrix).
//!
//! [`check_released_stability`] is the gate `haptic2d run` applies before driving a real device.

pub mod axis;
pub mod delayed;
pub mod delayed_plot;
pub mod dense;
pub mod eig;
pub mod loop_model;
pub mod planar2;
pub mod plot;
pub mod report;

pub use axis::{AxisController, AxisModel};
pub use delayed::{delay_margin, DelayMargin, DelayedLoop};
pub use loop_model::{
    AxisReport, Environment, LoopModel, LoopPoles, Verdict, AXES, MIN_DECAY_RATE,
};
pub use report::{analyse_config, check_released_stability, StabilityReport};
