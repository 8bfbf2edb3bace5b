//! Rigid bodies: mass properties, pose and twist, and the force accumulators of one tick.

use crate::geom::{perp, Pose, Vec2};

/// Whether a body moves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BodyKind {
    /// Part of the environment: infinite mass, never moves (`M⁻¹ = 0`).
    Fixed,
    /// A virtual body integrated by the passive integrator (§6).
    Dynamic,
}

/// A planar rigid body. Its frame origin is its centre of mass (§0.3).
#[derive(Clone, Debug, PartialEq)]
pub struct Body {
    /// Name used in logs and CSV columns (`NAME.x`, …).
    pub name: String,
    /// Fixed or dynamic.
    pub kind: BodyKind,
    /// Pose of the centre of mass (m, rad; the angle is unwrapped).
    pub pose: Pose,
    /// Linear velocity of the centre of mass (m/s).
    pub vel: Vec2,
    /// Angular velocity (rad/s).
    pub omega: f64,
    /// Mass (kg); infinite for fixed bodies.
    pub mass: f64,
    /// Centroidal moment of inertia (kg·m²); infinite for fixed bodies.
    pub inertia: f64,
    /// `1/m` (1/kg); 0 for fixed bodies.
    pub inv_mass: f64,
    /// `1/I` (1/(kg·m²)); 0 for fixed bodies.
    pub inv_inertia: f64,
    /// Physical (plant) viscous damping on the translation (N·s/m), e.g. the Colgate runs (§5.4).
    pub damping: f64,
    /// Force accumulated this tick (N), held over the sample.
    pub force: Vec2,
    /// Torque accumulated this tick (N·m), held over the sample.
    pub torque: f64,
}

impl Body {
    /// A dynamic body with mass `mass` (kg) and centroidal inertia `inertia` (kg·m²) at `pose`.
    pub fn dynamic(name: impl Into<String>, mass: f64, inertia: f64, pose: Pose) -> Self {
        Self {
            name: name.into(),
            kind: BodyKind::Dynamic,
            pose,
            vel: Vec2::ZERO,
            omega: 0.0,
            mass,
            inertia,
            inv_mass: 1.0 / mass,
            inv_inertia: 1.0 / inertia,
            damping: 0.0,
            force: Vec2::ZERO,
            torque: 0.0,
        }
    }
    /// A fixed body at `pose`.
    pub fn fixed(name: impl Into<String>, pose: Pose) -> Self {
        Self {
            name: name.into(),
            kind: BodyKind::Fixed,
            pose,
            vel: Vec2::ZERO,
            omega: 0.0,
            mass: f64::INFINITY,
            inertia: f64::INFINITY,
            inv_mass: 0.0,
            inv_inertia: 0.0,
            damping: 0.0,
            force: Vec2::ZERO,
            torque: 0.0,
        }
    }
    /// True if the body moves.
    #[inline]
    pub fn is_dynamic(&self) -> bool {
        self.kind == BodyKind::Dynamic
    }
    /// Velocity (m/s) of the material point at world position `p`: `v + ω·perp(p − c)`.
    #[inline]
    pub fn point_velocity(&self, p: Vec2) -> Vec2 {
        self.vel + perp(p - self.pose.pos) * self.omega
    }
    /// Adds a force `f` (N) applied at world point `p` to this tick's accumulators.
    #[inline]
    pub fn apply_force_at(&mut self, f: Vec2, p: Vec2) {
        self.force += f;
        self.torque += crate::geom::cross(p - self.pose.pos, f);
    }
    /// Kinetic energy `½m|v|² + ½Iω²` (J); 0 for fixed bodies.
    #[inline]
    pub fn kinetic_energy(&self) -> f64 {
        if self.is_dynamic() {
            0.5 * self.mass * self.vel.length_squared()
                + 0.5 * self.inertia * self.omega * self.omega
        } else {
            0.0
        }
    }

    /// The body's state as the world CSV's six columns per body write it: position `x`, `y`
    /// (m), angle `θ` (rad), velocity `v_x`, `v_y` (m/s), angular velocity `ω` (rad/s).
    #[inline]
    pub fn state(&self) -> [f64; 6] {
        [
            self.pose.pos.x,
            self.pose.pos.y,
            self.pose.angle,
            self.vel.x,
            self.vel.y,
            self.omega,
        ]
    }
}
