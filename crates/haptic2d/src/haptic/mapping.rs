//! The device ↔ world mapping: where the handle's pose lands in the virtual world.
//!
//! ```text
//! world pose  = world_origin + (scale·(x − x0), scale·(y − y0), θ − θ0)      (x0, y0, θ0) = device_origin
//! world twist = (scale·ẋ, scale·ẏ, θ̇)
//! device wrench = (scale·F_x, scale·F_y, τ)   for a world wrench (F_x, F_y, τ)
//! ```
//!
//! The wrench map is the transpose of the twist map, so power is the same on both sides
//! (`F_d·v_d = F_w·v_w`) and the mapping neither creates nor removes energy. The default anchors the
//! device workspace centre `(0, 0.14 m, 0)` to the slave body's initial pose with scale 1.

use crate::device::linalg::V3;
use crate::device::DeviceParams;

/// An affine, power-preserving map between handle coordinates and world coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeviceMap {
    /// The handle pose that maps to `world_origin` (m, m, rad).
    pub device_origin: V3,
    /// The world pose of `device_origin` (m, m, rad); usually the slave's initial pose.
    pub world_origin: V3,
    /// Translation scale world/device (dimensionless, > 0); 1 = one metre of handle motion is one
    /// metre in the world. Rotation is never scaled.
    pub scale: f64,
}

impl DeviceMap {
    /// The default map of device `p`: its workspace centre at θ = 0 ↔ `world_origin`, scale 1.
    pub fn centred(p: &DeviceParams, world_origin: V3) -> Self {
        Self {
            device_origin: [p.workspace_center_x, p.workspace_center_y, 0.0],
            world_origin,
            scale: 1.0,
        }
    }

    /// Checks that every field is finite and the scale positive; the error names the field.
    pub fn validate(&self) -> Result<(), String> {
        if !self
            .device_origin
            .iter()
            .chain(self.world_origin.iter())
            .all(|v| v.is_finite())
        {
            return Err("mapping.device_origin/world_origin must be finite".into());
        }
        if !(self.scale.is_finite() && self.scale > 0.0) {
            return Err(format!(
                "mapping.scale must be a finite number > 0 (got {})",
                self.scale
            ));
        }
        Ok(())
    }

    /// World pose (m, m, rad) of handle pose `x` (m, m, rad).
    #[inline]
    pub fn pose_to_world(&self, x: &V3) -> V3 {
        [
            self.world_origin[0] + self.scale * (x[0] - self.device_origin[0]),
            self.world_origin[1] + self.scale * (x[1] - self.device_origin[1]),
            self.world_origin[2] + (x[2] - self.device_origin[2]),
        ]
    }

    /// Handle pose (m, m, rad) of world pose `w` (m, m, rad): the inverse of [`Self::pose_to_world`].
    #[inline]
    pub fn pose_to_device(&self, w: &V3) -> V3 {
        [
            self.device_origin[0] + (w[0] - self.world_origin[0]) / self.scale,
            self.device_origin[1] + (w[1] - self.world_origin[1]) / self.scale,
            self.device_origin[2] + (w[2] - self.world_origin[2]),
        ]
    }

    /// World twist (m/s, m/s, rad/s) of handle twist `v`.
    #[inline]
    pub fn twist_to_world(&self, v: &V3) -> V3 {
        [self.scale * v[0], self.scale * v[1], v[2]]
    }

    /// Handle wrench (N, N, N·m) equivalent to world wrench `f` (same power).
    #[inline]
    pub fn wrench_to_device(&self, f: &V3) -> V3 {
        [self.scale * f[0], self.scale * f[1], f[2]]
    }

    /// World wrench (N, N, N·m) equivalent to handle wrench `f` (same power).
    #[inline]
    pub fn wrench_to_world(&self, f: &V3) -> V3 {
        [f[0] / self.scale, f[1] / self.scale, f[2]]
    }
}
