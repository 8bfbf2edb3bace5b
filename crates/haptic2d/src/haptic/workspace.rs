//! The workspace bound of the device file (DESIGN §7): a stiff passive wall just past the edge of the
//! workspace square, and a trip beyond it.
//!
//! Per axis `x`, `y` with edges `c ± h` (centre `c`, half-width `h`): outside the square the
//! penetration is `p = |x − edge|` and the outward unit `n = ±1`, and the handle gets
//!
//! ```text
//! F = −n·max(0, K·p + B·n·ẋ)
//! ```
//!
//! a spring–damper that only ever pushes back (clamping at zero keeps it from pulling the handle
//! outward when it moves inward fast). A continuous spring–damper acting only in penetration is
//! passive; sampled with a zero-order hold it stays passive when `B ≥ K·T/2` (Colgate, §5.4), so the
//! stiffness rendered is `K = min(K_file, 2·B/T)`. Beyond `p > trip distance` the safety latch trips.
//! θ is unbounded (the twin pantograph rotates without limit).

use crate::device::linalg::V3;
use crate::device::DeviceParams;

/// The bound, in handle coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorkspaceBound {
    /// Centre of the square `(x, y)` (m).
    pub centre: [f64; 2],
    /// Half-width of the square (m).
    pub half_width: f64,
    /// Rendered stiffness `min(K_file, 2·B/T)` (N/m).
    pub stiffness: f64,
    /// Damping `B` (N·s/m).
    pub damping: f64,
    /// Trip distance past the edge (m).
    pub trip_distance: f64,
}

/// A handle past the trip distance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorkspaceExcursion {
    /// 0 = x, 1 = y.
    pub axis: usize,
    /// Handle coordinate on that axis (m).
    pub position: f64,
    /// The edge it passed (m).
    pub edge: f64,
}

impl WorkspaceBound {
    /// The bound of device `p` at period `dt` (s).
    pub fn new(p: &DeviceParams, dt: f64) -> Self {
        Self {
            centre: [p.workspace_center_x, p.workspace_center_y],
            half_width: p.workspace_half_width,
            stiffness: p
                .workspace_wall_stiffness
                .min(2.0 * p.workspace_wall_damping / dt),
            damping: p.workspace_wall_damping,
            trip_distance: p.workspace_trip_distance,
        }
    }

    /// The wall wrench (N, N, 0) at handle pose `x` (m, m, rad) and twist `v` (m/s, m/s, rad/s), and
    /// the first axis past the trip distance, if any.
    #[inline]
    pub fn wrench(&self, x: &V3, v: &V3) -> (V3, Option<WorkspaceExcursion>) {
        let mut f = [0.0; 3];
        let mut out = None;
        for axis in 0..2 {
            let (lo, hi) = (
                self.centre[axis] - self.half_width,
                self.centre[axis] + self.half_width,
            );
            let (pen, edge, n) = if x[axis] > hi {
                (x[axis] - hi, hi, 1.0)
            } else if x[axis] < lo {
                (lo - x[axis], lo, -1.0)
            } else {
                continue;
            };
            f[axis] = -n * (self.stiffness * pen + self.damping * n * v[axis]).max(0.0);
            if pen > self.trip_distance && out.is_none() {
                out = Some(WorkspaceExcursion {
                    axis,
                    position: x[axis],
                    edge,
                });
            }
        }
        (f, out)
    }
}
