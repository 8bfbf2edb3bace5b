//! The `SceneInfo` message: what does not change while a scene runs (body shapes, device geometry,
//! workspace), sent once per connection and again on every scene change or reset.
//!
//! Built off the real-time path (it allocates): by the loop when it loads a scene, then handed to
//! [`ViewHub::publish_scene`](crate::ViewHub::publish_scene).

use haptic2d::device::{DeviceParams, TwinKinematics};
use haptic2d::world::World;
use serde::Serialize;

/// One body of the scene: its name, kind and convex pieces in the body frame.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BodyShape {
    /// Body name (as in the scene file).
    pub name: String,
    /// True for a fixed body (part of the environment).
    pub fixed: bool,
    /// Mass (kg); `null` for fixed bodies.
    pub mass: Option<f64>,
    /// Convex pieces, each a counter-clockwise list of vertices `[x, y]` in the body frame (m).
    pub pieces: Vec<Vec<[f64; 2]>>,
}

/// Geometry of the twin-pantograph device, for drawing its linkage.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct DeviceGeometry {
    /// Motor axes `B_1`, `B_2` (m, world frame; both pantographs share them, in parallel planes).
    pub motors: [[f64; 2]; 2],
    /// Motor-axis spacing `s` (m).
    pub s: f64,
    /// Proximal link length `l1` (m).
    pub l1: f64,
    /// Distal link length `l2` (m).
    pub l2: f64,
    /// Crank radius `r_c` (m).
    pub r_c: f64,
    /// The device workspace square in the world frame: `[x_min, y_min, x_max, y_max]` (m).
    pub workspace: [f64; 4],
}

/// The static description of a running scene (`{"type": "scene", …}`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SceneInfo {
    /// Sequence number, set by the hub when published; frames carry the number of their scene.
    pub seq: u64,
    /// Scene name.
    pub name: String,
    /// One-line description.
    pub description: String,
    /// Sample period of the world `T` (s).
    pub dt: f64,
    /// Bodies, indexed like [`Frame::bodies`](crate::Frame::bodies).
    pub bodies: Vec<BodyShape>,
    /// Index of the body driven by the controller (the slave), if any.
    pub slave: Option<u32>,
    /// Bounding rectangle of every piece at the initial poses, `[x_min, y_min, x_max, y_max]` (m):
    /// what the page fits to its canvas.
    pub bounds: [f64; 4],
    /// Translation from the device frame to the world frame (m): world = device + offset.
    pub device_to_world: [f64; 2],
    /// The device, when one is in the loop.
    pub device: Option<DeviceGeometry>,
}

impl SceneInfo {
    /// The description of `world` named `name`, with the slave body `slave` and, if a device is in
    /// the loop, its parameters and the device→world offset (m).
    pub fn from_world(
        world: &World,
        name: &str,
        description: &str,
        slave: Option<usize>,
        device: Option<(&DeviceParams, [f64; 2])>,
    ) -> Self {
        let mut bodies: Vec<BodyShape> = world
            .bodies
            .iter()
            .map(|b| BodyShape {
                name: b.name.clone(),
                fixed: !b.is_dynamic(),
                mass: b.is_dynamic().then_some(b.mass),
                pieces: Vec::new(),
            })
            .collect();
        let mut bounds = [f64::INFINITY, f64::INFINITY, -f64::INFINITY, -f64::INFINITY];
        for c in &world.colliders {
            let pose = world.bodies[c.body].pose;
            let piece: Vec<[f64; 2]> = c.local.vertices().iter().map(|v| [v.x, v.y]).collect();
            for v in c.local.vertices() {
                let p = pose.transform_point(*v);
                bounds = [
                    bounds[0].min(p.x),
                    bounds[1].min(p.y),
                    bounds[2].max(p.x),
                    bounds[3].max(p.y),
                ];
            }
            bodies[c.body].pieces.push(piece);
        }
        if !bounds.iter().all(|b| b.is_finite()) {
            bounds = [-0.1, -0.1, 0.1, 0.1];
        }
        let (device, device_to_world) = match device {
            Some((p, off)) => (Some(DeviceGeometry::new(p, off)), off),
            None => (None, [0.0; 2]),
        };
        Self {
            seq: 0,
            name: name.to_string(),
            description: description.to_string(),
            dt: world.params.dt,
            bodies,
            slave: slave.filter(|&i| i < world.bodies.len()).map(|i| i as u32),
            bounds,
            device_to_world,
            device,
        }
    }
}

impl DeviceGeometry {
    /// The geometry of the device `p`, placed in the world with offset `off` (m).
    pub fn new(p: &DeviceParams, off: [f64; 2]) -> Self {
        let kin = TwinKinematics::new(p);
        let b = |i| {
            let v = kin.pantographs[0].base(i);
            [v.x + off[0], v.y + off[1]]
        };
        let (cx, cy, hw) = (
            p.workspace_center_x + off[0],
            p.workspace_center_y + off[1],
            p.workspace_half_width,
        );
        Self {
            motors: [b(0), b(1)],
            s: p.s,
            l1: p.l1,
            l2: p.l2,
            r_c: p.r_c,
            workspace: [cx - hw, cy - hw, cx + hw, cy + hw],
        }
    }
}
