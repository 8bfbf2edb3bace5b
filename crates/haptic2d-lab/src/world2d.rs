//! Helpers to set up the 2-D worlds of the figures from the built-in scenes.

use haptic2d::geom::ConvexPolygon;
use haptic2d::laws::friction::FrictionModel;
use haptic2d::laws::normal::NormalModel;
use haptic2d::scene::builtin;
use haptic2d::world::{World, WorldParams};

/// Loads built-in scene `name` at its own rate.
pub fn load_builtin(name: &str) -> Result<World, String> {
    match builtin(name, None) {
        Some(Ok(scene)) => Ok(scene.world),
        Some(Err(e)) => Err(format!("built-in scene `{name}` is invalid: {e}")),
        None => Err(format!("no built-in scene `{name}`")),
    }
}

/// Rebuilds `world` (at its initial state) with new parameters and laws. Needed because the contact
/// set copies `params.contact` and the guard at construction.
pub fn rebuild(
    world: World,
    normal: NormalModel,
    friction: FrictionModel,
    params: WorldParams,
) -> World {
    let mut shapes: Vec<Vec<ConvexPolygon>> = vec![Vec::new(); world.bodies.len()];
    for c in &world.colliders {
        shapes[c.body].push(c.local.clone());
    }
    World::new(world.bodies, shapes, world.loads, normal, friction, params)
}

/// Index of the body called `name`, or an error naming the scene body that is missing.
pub fn body(world: &World, name: &str) -> Result<usize, String> {
    world
        .body_index(name)
        .ok_or_else(|| format!("the scene has no body called `{name}`"))
}

/// The smallest world x (m) over the vertices of body `b`'s colliders: the gap to a wall whose surface
/// is the plane `x = 0` with normal `+x`.
pub fn min_vertex_x(world: &World, b: usize) -> f64 {
    world
        .colliders
        .iter()
        .filter(|c| c.body == b)
        .flat_map(|c| {
            c.local
                .vertices()
                .iter()
                .map(|v| world.bodies[b].pose.transform_point(*v).x)
        })
        .fold(f64::INFINITY, f64::min)
}
