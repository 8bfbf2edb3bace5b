//! The borrowed step context: what the contact stage (§0.5 steps 4–6) reads and writes of the
//! world in one sample, lent once by the world instead of a dozen arguments (as Box2D's
//! `b2StepContext`, `src/solver.h`, is built once per step and handed to every stage).

use crate::body::Body;
use crate::collide::{Collider, VeCandidate};
use crate::contact::{PastPoses, Wrench2};
use crate::geom::Rot;
use crate::laws::friction::FrictionModel;
use crate::laws::normal::NormalModel;
use crate::stage_time::StageTimes;

/// One sample's view of the world for the contact stage, borrowed from the world's disjoint parts.
pub struct StepContext<'a> {
    /// The sample index `k`.
    pub tick: u64,
    /// The sample period `T` (s).
    pub dt: f64,
    /// The local stage's sorted VE candidates of this sample (§9.5).
    pub candidates: &'a [VeCandidate],
    /// Per candidate: whether it came from a full vertex scan (a penetrating pair).
    pub from_scan: &'a [bool],
    /// The colliders, their world-frame features at the sample's poses.
    pub colliders: &'a [Collider],
    /// The bodies: impacts change their velocities, forces add to their accumulators.
    pub bodies: &'a mut [Body],
    /// Each body's rotation at the sample's pose.
    pub rots: &'a [Rot],
    /// The body poses at `k − 1` and `k − 2`.
    pub past: PastPoses<'a>,
    /// Prototype of the normal law (§5).
    pub normal: &'a NormalModel,
    /// Prototype of the friction model (§1–§4).
    pub friction: &'a FrictionModel,
    /// Out: the contact wrench on each body (N, N·m).
    pub wrenches: &'a mut [Wrench2],
    /// Out: the wall time of each stage (zero without the `stage-timing` feature).
    pub times: &'a mut StageTimes,
}
