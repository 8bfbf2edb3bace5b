//! Device faults: kinematic failures and monitor trips. The real-time loop turns any of these into
//! "torques to zero and a clear message" (DESIGN §7).

use std::fmt;

/// A kinematic or consistency fault of the twin-pantograph device model (§10.3–§10.5).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DeviceFault {
    /// Inverse kinematics failed: the `acos` argument of pantograph `pantograph` (1 or 2), motor `motor`
    /// (1 = left, 2 = right) left `[−1, 1]` (value `arg`): the endpoint is out of reach.
    Unreachable {
        /// Pantograph index, 1 or 2.
        pantograph: u8,
        /// Motor index within the pantograph, 1 (left) or 2 (right).
        motor: u8,
        /// The offending `acos` argument (dimensionless).
        arg: f64,
    },
    /// Forward kinematics failed: the elbow distance `D` (m) of pantograph `pantograph` is not in
    /// `(0, 2·l2)`, so the distal links cannot meet (type-2 singularity or impossible encoder reading).
    FkNoAssembly {
        /// Pantograph index, 1 or 2.
        pantograph: u8,
        /// Elbow distance `D = |E_j2 − E_j1|` (m).
        elbow_distance: f64,
    },
    /// The closure monitor tripped: `| |P_2 − P_1| − r_c |` (m) exceeded the tolerance (default 1e-3 m).
    /// Usually an encoder calibration error or a slipped cable.
    ClosureViolation {
        /// `|P_2 − P_1| − r_c` (m).
        error: f64,
    },
    /// A Jacobian-based computation hit a singular matrix (`J_aᵀJ_a` or `M_x` not invertible).
    Singular,
    /// An input (encoder angle, pose, wrench) was NaN or infinite.
    NonFinite,
    /// A method that needs a measured pose was called before the first successful `pose_from_encoders`.
    NoPose,
}

impl fmt::Display for DeviceFault {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            DeviceFault::Unreachable {
                pantograph,
                motor,
                arg,
            } => write!(
                f,
                "pantograph {pantograph} motor {motor}: endpoint out of reach (acos argument {arg:.6} outside [-1, 1])"
            ),
            DeviceFault::FkNoAssembly {
                pantograph,
                elbow_distance,
            } => write!(
                f,
                "pantograph {pantograph}: distal links cannot meet (elbow distance {elbow_distance:.6} m)"
            ),
            DeviceFault::ClosureViolation { error } => write!(
                f,
                "closure monitor: |P2 - P1| differs from the crank radius by {error:.6} m (check encoder calibration)"
            ),
            DeviceFault::Singular => write!(f, "device Jacobian or mass matrix is singular"),
            DeviceFault::NonFinite => write!(f, "non-finite device input (NaN or infinity)"),
            DeviceFault::NoPose => write!(f, "no device pose measured yet"),
        }
    }
}

impl std::error::Error for DeviceFault {}
