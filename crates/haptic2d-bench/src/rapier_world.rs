//! The rapier2d twin of a haptic2d world: every body, piece, pose, velocity, mass, inertia and load is
//! copied from the haptic2d [`World`], so both engines start from the same state.
//!
//! What is identical: geometry (each haptic2d convex piece becomes one rapier collider; axis-aligned
//! rectangles become rapier cuboids, its fast box path), mass and centroidal inertia (set explicitly,
//! colliders have zero density), initial poses and velocities, the constant loads (gravity as a body
//! force `m·g` and the 2 N push, applied as persistent rapier user forces at the centre of mass), the
//! time step (1 ms), the Coulomb coefficient (haptic2d's static μ_s) and the restitution coefficient.
//! Rapier's sleeping is disabled on every dynamic body (haptic2d never sleeps) and CCD is off (default);
//! every other rapier parameter keeps its default (4 solver iterations, soft contacts, warm-starting).
//!
//! What is not: haptic2d resolves contact with penalty springs per vertex–edge pair, impulses only at
//! collision, and reset-integrator friction, at 1 kHz with no iterations; rapier solves a velocity-level
//! constraint problem (PGS with soft constraints and stabilisation) with Coulomb friction. The two do
//! not produce the same trajectories; the comparison is the cost of one step of a comparable scene.

use haptic2d::geom::{ConvexPolygon, Vec2};
use haptic2d::load::Profile;
use haptic2d::world::World;
use rapier2d_f64::prelude::{
    ColliderBuilder, MassProperties, PhysicsWorld, RigidBodyBuilder, RigidBodyHandle, Vector,
};

/// A rapier2d world built from a haptic2d world.
pub struct RapierTwin {
    /// The rapier state.
    pub world: PhysicsWorld,
    /// Rapier body of every haptic2d body (same index).
    handles: Vec<RigidBodyHandle>,
}

impl RapierTwin {
    /// One rapier step of `dt` (set at construction).
    #[inline]
    pub fn step(&mut self) {
        self.world.step();
    }

    /// (position m, angle rad, velocity m/s) of every body, in haptic2d body order.
    pub fn poses(&self) -> Vec<(Vec2, f64, Vec2)> {
        self.handles
            .iter()
            .map(|&h| {
                let b = &self.world.bodies[h];
                (b.translation(), b.rotation().angle(), b.linvel())
            })
            .collect()
    }
}

/// `Some((centre, half extents))` if `p` is an axis-aligned rectangle (body frame).
fn as_rectangle(p: &ConvexPolygon) -> Option<(Vec2, Vec2)> {
    let v = p.vertices();
    if v.len() != 4 {
        return None;
    }
    let axis_aligned = (0..4).all(|i| {
        let d = v[(i + 1) % 4] - v[i];
        d.x.abs() < 1e-12 || d.y.abs() < 1e-12
    });
    if !axis_aligned {
        return None;
    }
    let lo = v.iter().fold(Vec2::splat(f64::INFINITY), |a, b| a.min(*b));
    let hi = v
        .iter()
        .fold(Vec2::splat(f64::NEG_INFINITY), |a, b| a.max(*b));
    Some((0.5 * (lo + hi), 0.5 * (hi - lo)))
}

/// Builds the rapier twin of `w` with time step `dt` (s), friction coefficient `mu` and restitution
/// `e` on every collider. Fails if a load is not constant (rapier user forces are held constant).
pub fn twin(w: &World, dt: f64, mu: f64, e: f64) -> Result<RapierTwin, String> {
    let mut world = PhysicsWorld::new();
    world.gravity = Vector::ZERO; // gravity is one of the copied loads
    world.integration_parameters.dt = dt;
    let mut handles: Vec<RigidBodyHandle> = Vec::with_capacity(w.bodies.len());
    for b in &w.bodies {
        let builder = if b.is_dynamic() {
            RigidBodyBuilder::dynamic()
                .linvel(b.vel)
                .angvel(b.omega)
                .can_sleep(false)
                .additional_mass_properties(MassProperties::new(Vec2::ZERO, b.mass, b.inertia))
        } else {
            RigidBodyBuilder::fixed()
        };
        let h = world.insert_body(builder.translation(b.pose.pos).rotation(b.pose.angle));
        handles.push(h);
    }
    for c in &w.colliders {
        let builder = match as_rectangle(&c.local) {
            Some((centre, half)) => ColliderBuilder::cuboid(half.x, half.y).translation(centre),
            None => ColliderBuilder::convex_polyline(c.local.vertices().to_vec())
                .ok_or_else(|| format!("body {}: rapier rejected a piece", c.body))?,
        };
        let builder = builder.density(0.0).friction(mu).restitution(e);
        world.insert_collider(builder, Some(handles[c.body]));
    }
    for l in &w.loads {
        if l.profile != Profile::Constant {
            return Err(format!(
                "load on body {}: only constant loads are copied to rapier",
                l.body
            ));
        }
        let (f, tau) = l.wrench(&w.bodies[l.body], 0.0);
        let rb = &mut world.bodies[handles[l.body]];
        rb.add_force(f, true);
        rb.add_torque(tau, true);
    }
    Ok(RapierTwin { world, handles })
}
