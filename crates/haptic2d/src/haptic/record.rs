//! [`TickRecord`]: what one haptic tick publishes for telemetry, logging and tests. `Copy`, fixed size,
//! so it travels through wait-free rings without allocation.

use crate::device::linalg::{V3, V4};

/// Flag: saturation scaled the wrench part of the torques (§10.5).
pub const FLAG_SATURATED: u32 = 1;
/// Flag: the device was below the singularity margin this tick (torques zero).
pub const FLAG_NEAR_SINGULAR: u32 = 2;
/// Flag: the safety latch is set (torques zero).
pub const FLAG_SAFETY: u32 = 4;
/// Flag: the passivity controller added damping this tick (`α > 0` on some DOF).
pub const FLAG_PASSIVITY_ACTIVE: u32 = 8;

/// One tick's state. Vectors are `(x, y, θ)` 3-vectors; device quantities are in handle coordinates,
/// slave and controller quantities in world coordinates (see [`DeviceMap`](super::DeviceMap)).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TickRecord {
    /// Time `k·T` (s).
    pub t: f64,
    /// Device (handle) pose `x_m,k` (m, m, rad).
    pub x_m: V3,
    /// Filtered device twist `v̂_m,k` (m/s, m/s, rad/s).
    pub v_m: V3,
    /// Hand-wrench estimate `Ŵ_h,k` (N, N, N·m), handle coordinates.
    pub w_h: V3,
    /// Slave pose `x_s,k` after impacts (m, m, rad).
    pub x_s: V3,
    /// Post-impulse slave twist `v_s,k⁺` (m/s, m/s, rad/s).
    pub v_s: V3,
    /// Device command `f_cm,k` after the passivity controller (N, N, N·m), world coordinates.
    pub f_cm: V3,
    /// Slave drive `f_cs,k` (N, N, N·m).
    pub f_cs: V3,
    /// Wrench the slave applies to the environment `f_e,k` (N, N, N·m).
    pub f_e: V3,
    /// Motor torques sent to the amplifiers (N·m).
    pub tau: V4,
    /// Number of contact records.
    pub contacts: u32,
    /// World kinetic energy after the step (J).
    pub kinetic: f64,
    /// Energy stored in contact springs after the step (J).
    pub stored: f64,
    /// Work done on the world by loads and drives so far (J).
    pub applied_work: f64,
    /// Passivity-observer energy `E_obs` summed over the DOFs (J); 0 when the PO is off.
    pub po_energy: f64,
    /// Passivity-controller damping `α` per DOF (N·s/m, N·s/m, N·m·s/rad).
    pub alpha: V3,
    /// Singularity margin at the device pose (dimensionless).
    pub margin: f64,
    /// Closure error `|P_2 − P_1| − r_c` (m).
    pub closure_error: f64,
    /// Bit set of `FLAG_*`.
    pub flags: u32,
}

/// Number of columns of [`TickRecord::values`].
pub const TICK_COLUMN_COUNT: usize = 43;

/// Column names of [`TickRecord::values`], in order (units in docs of [`TickRecord`]).
pub const TICK_COLUMNS: [&str; TICK_COLUMN_COUNT] = [
    "t",
    "device.x",
    "device.y",
    "device.theta",
    "device.vx",
    "device.vy",
    "device.omega",
    "hand.fx",
    "hand.fy",
    "hand.tau",
    "slave.x",
    "slave.y",
    "slave.theta",
    "slave.vx",
    "slave.vy",
    "slave.omega",
    "f_cm.x",
    "f_cm.y",
    "f_cm.tau",
    "f_cs.x",
    "f_cs.y",
    "f_cs.tau",
    "f_e.x",
    "f_e.y",
    "f_e.tau",
    "tau1",
    "tau2",
    "tau3",
    "tau4",
    "contacts",
    "energy.kinetic",
    "energy.stored",
    "work.applied",
    "po.energy",
    "po.alpha_x",
    "po.alpha_y",
    "po.alpha_theta",
    "margin",
    "closure_error",
    "flag.saturated",
    "flag.near_singular",
    "flag.safety",
    "flag.passivity",
];

impl TickRecord {
    /// The record as numbers in [`TICK_COLUMNS`] order (flags as 0/1).
    pub fn values(&self) -> [f64; TICK_COLUMN_COUNT] {
        let f = |bit: u32| if self.flags & bit != 0 { 1.0 } else { 0.0 };
        let v3 = |v: &V3| -> [f64; 3] { *v };
        let mut out = [0.0; TICK_COLUMN_COUNT];
        out[0] = self.t;
        let mut i = 1;
        for v in [
            &self.x_m, &self.v_m, &self.w_h, &self.x_s, &self.v_s, &self.f_cm, &self.f_cs,
            &self.f_e,
        ] {
            out[i..i + 3].copy_from_slice(&v3(v));
            i += 3;
        }
        out[i..i + 4].copy_from_slice(&self.tau);
        i += 4;
        for v in [
            self.contacts as f64,
            self.kinetic,
            self.stored,
            self.applied_work,
            self.po_energy,
            self.alpha[0],
            self.alpha[1],
            self.alpha[2],
            self.margin,
            self.closure_error,
            f(FLAG_SATURATED),
            f(FLAG_NEAR_SINGULAR),
            f(FLAG_SAFETY),
            f(FLAG_PASSIVITY_ACTIVE),
        ] {
            out[i] = v;
            i += 1;
        }
        debug_assert_eq!(i, TICK_COLUMN_COUNT);
        out
    }
}
