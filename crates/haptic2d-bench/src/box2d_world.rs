//! The Box2D v3 twin of a haptic2d world (through `boxdd` 0.6), built like the rapier2d twin: every
//! body, piece, pose, velocity, mass, inertia and load is copied from the haptic2d [`World`].
//!
//! What is identical: geometry (each convex piece becomes one Box2D polygon, radius 0), mass and
//! centroidal inertia (set explicitly with `set_mass_data` after the shapes, which have zero density), initial poses
//! and velocities, the time step (1 ms), friction and restitution, sleeping off (world and bodies).
//! Loads: a per-mass load shared by every dynamic body (gravity) becomes Box2D's world gravity
//! (`m·g`, the same body force); any other constant load is re-applied before every step, because
//! Box2D clears applied forces at the end of each step. Every other Box2D setting keeps its default
//! (soft-step solver, relax and restitution passes, continuous collision against static bodies,
//! one worker thread). Box2D stores positions in `f32` (its default build).
//!
//! Two builds of the bundled C library cannot be linked into one binary, so the AVX2 build is the
//! cargo feature `box2d-avx2` of this bench (`boxdd/simd-avx2`), a separate run.

use boxdd::{
    shapes, BodyId, BodyType, Foundation, MassData, ShapeDef, SurfaceMaterial, World as BWorld,
    WorldBuilder,
};
use haptic2d::geom::Vec2;
use haptic2d::load::Profile;
use haptic2d::world::World;

/// Label of the linked Box2D build.
pub const BUILD: &str = if cfg!(feature = "box2d-avx2") {
    "avx2"
} else {
    "default"
};

/// A Box2D world built from a haptic2d world.
pub struct Box2dTwin {
    world: BWorld,
    /// Box2D body of every haptic2d body (same index).
    ids: Vec<BodyId>,
    /// Loads re-applied before every step: (body, force N, torque N m).
    forces: Vec<(BodyId, [f32; 2], f32)>,
    dt: f32,
    substeps: i32,
}

fn err(what: &str, e: impl std::fmt::Display) -> String {
    format!("box2d: {what}: {e}")
}

impl Box2dTwin {
    /// One Box2D step of `dt` with the configured number of substeps.
    #[inline]
    pub fn step(&mut self) {
        for &(id, f, tau) in &self.forces {
            if let Ok(mut b) = self.world.body(id) {
                let _ = b.apply_force_to_center(f, false);
                let _ = b.apply_torque(tau, false);
            }
        }
        let _ = self.world.step(self.dt, self.substeps);
    }

    /// (position m, angle rad, velocity m/s) of every body, in haptic2d body order.
    pub fn poses(&mut self) -> Vec<(Vec2, f64, Vec2)> {
        let mut out = Vec::with_capacity(self.ids.len());
        for &id in &self.ids {
            let b = match self.world.body(id) {
                Ok(b) => b,
                Err(_) => {
                    out.push((Vec2::splat(f64::NAN), f64::NAN, Vec2::splat(f64::NAN)));
                    continue;
                }
            };
            let p = b.position().unwrap_or_default();
            let a = b.rotation().map(|r| r.angle() as f64).unwrap_or(f64::NAN);
            let v = b.linear_velocity().unwrap_or_default();
            out.push((
                Vec2::new(p.x as f64, p.y as f64),
                a,
                Vec2::new(v.x as f64, v.y as f64),
            ));
        }
        out
    }
}

/// Builds the Box2D twin of `w`: time step `dt` (s), `substeps` solver substeps, friction `mu` and
/// restitution `e` on every shape. Fails if a load is not constant or Box2D rejects a definition.
pub fn twin(w: &World, dt: f64, substeps: i32, mu: f64, e: f64) -> Result<Box2dTwin, String> {
    let foundation = Foundation::initialize_default().map_err(|x| err("foundation", x))?;
    // Gravity: a constant, torque-free per-mass load that reaches every dynamic body once.
    let n_dyn = w.bodies.iter().filter(|b| b.is_dynamic()).count();
    let mut per_mass_count = vec![0usize; w.bodies.len()];
    let mut accel: Option<Vec2> = None;
    let mut uniform = true;
    for l in &w.loads {
        if l.profile != Profile::Constant {
            return Err(format!(
                "load on body {}: only constant loads are copied to Box2D",
                l.body
            ));
        }
        if l.per_mass && l.torque == 0.0 && w.bodies[l.body].is_dynamic() {
            per_mass_count[l.body] += 1;
            match accel {
                None => accel = Some(l.force),
                Some(a) if a != l.force => uniform = false,
                _ => {}
            }
        }
    }
    let gravity_ok = uniform
        && accel.is_some()
        && w.bodies
            .iter()
            .zip(&per_mass_count)
            .filter(|(b, _)| b.is_dynamic())
            .all(|(_, &c)| c == 1)
        && n_dyn > 0;
    let g = if gravity_ok {
        accel.unwrap_or(Vec2::ZERO)
    } else {
        Vec2::ZERO
    };
    let def = WorldBuilder::from(foundation.world_def())
        .gravity([g.x as f32, g.y as f32])
        .enable_sleep(false)
        .build()
        .map_err(|x| err("world definition", x))?;
    let mut world = foundation
        .create_world(def)
        .map_err(|x| err("create world", x))?;
    let mut ids = Vec::with_capacity(w.bodies.len());
    for (i, b) in w.bodies.iter().enumerate() {
        let kind = if b.is_dynamic() {
            BodyType::Dynamic
        } else {
            BodyType::Static
        };
        let def = world
            .body_builder()
            .body_type(kind)
            .position([b.pose.pos.x as f32, b.pose.pos.y as f32])
            .angle(b.pose.angle as f32)
            .linear_velocity([b.vel.x as f32, b.vel.y as f32])
            .angular_velocity(b.omega as f32)
            .enable_sleep(false)
            .build()
            .map_err(|x| err(&format!("body {i}"), x))?;
        ids.push(
            world
                .create_body(def)
                .map_err(|x| err(&format!("body {i}"), x))?,
        );
    }
    let material = SurfaceMaterial::new()
        .with_friction(mu as f32)
        .and_then(|m| m.with_restitution(e as f32))
        .map_err(|x| err("material", x))?;
    let shape_def = ShapeDef::builder()
        .material(material)
        .density(0.0)
        // `false` would leave the body's mass flagged dirty (Box2D asserts on it in the first step:
        // `b2Body_SetMassData` does not clear the flag); with density 0 the shapes add nothing, and
        // `set_mass_data` below sets the mass and inertia after the last shape.
        .update_body_mass(true)
        .build()
        .map_err(|x| err("shape definition", x))?;
    for c in &w.colliders {
        let pts: Vec<[f32; 2]> = c
            .local
            .vertices()
            .iter()
            .map(|v| [v.x as f32, v.y as f32])
            .collect();
        let poly = shapes::polygon_from_points(pts, 0.0)
            .map_err(|x| err(&format!("piece of body {}", c.body), x))?;
        let mut body = world.body(ids[c.body]).map_err(|x| err("body", x))?;
        body.create_polygon(&shape_def, &poly)
            .map_err(|x| err(&format!("piece of body {}", c.body), x))?;
    }
    for (i, b) in w.bodies.iter().enumerate() {
        if b.is_dynamic() {
            let md = MassData::new(b.mass as f32, boxdd::Vec2::new(0.0, 0.0), b.inertia as f32)
                .map_err(|x| err(&format!("mass of body {i}"), x))?;
            world
                .body(ids[i])
                .and_then(|mut x| x.set_mass_data(md))
                .map_err(|x| err(&format!("mass of body {i}"), x))?;
        }
    }
    let mut forces = Vec::new();
    for l in &w.loads {
        if gravity_ok && l.per_mass && l.torque == 0.0 && w.bodies[l.body].is_dynamic() {
            continue; // in world gravity
        }
        let (f, tau) = l.wrench(&w.bodies[l.body], 0.0);
        forces.push((ids[l.body], [f.x as f32, f.y as f32], tau as f32));
    }
    Ok(Box2dTwin {
        world,
        ids,
        forces,
        dt: dt as f32,
        substeps,
    })
}
