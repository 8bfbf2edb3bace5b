//! The workspace bound of the device file (DESIGN §7), written once for every device: a stiff
//! passive wall just past the edge of the workspace square, and a trip beyond it. The twin pantograph
//! ([`HapticSystem`](super::HapticSystem)) and every 2-DOF device ([`Planar2System`](super::planar2::Planar2System):
//! a 2DIY, a UDP device, the Inverse3's planar mode) apply the same [`WorkspaceBound::apply`] to the
//! handle point in the device frame.
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
use crate::device::pantograph2::Pantograph2;
use crate::device::DeviceParams;

use super::safety::SafetyReason;

/// The workspace square of a device file and its wall, before the period is known (SI units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorkspaceSquare {
    /// Centre `(x, y)` (m, device frame).
    pub centre: [f64; 2],
    /// Half-width (m), > 0.
    pub half_width: f64,
    /// Wall stiffness `K` (N/m), ≥ 0 (0 = no wall, the trip still applies).
    pub wall_stiffness: f64,
    /// Wall damping `B` (N·s/m), ≥ 0.
    pub wall_damping: f64,
    /// Trip distance past the edge (m), > 0.
    pub trip_distance: f64,
}

impl WorkspaceSquare {
    /// The square and wall of the twin-pantograph parameters `p` (`workspace_*` fields).
    pub fn of_device(p: &DeviceParams) -> Self {
        Self {
            centre: [p.workspace_center_x, p.workspace_center_y],
            half_width: p.workspace_half_width,
            wall_stiffness: p.workspace_wall_stiffness,
            wall_damping: p.workspace_wall_damping,
            trip_distance: p.workspace_trip_distance,
        }
    }

    /// The square of `centre` ± `half_width` (m) with the default wall of the device file
    /// (`K` = 2000 N/m, `B` = 5 N·s/m, trip 10 mm past the edge: the [`DeviceParams`] defaults).
    pub fn around(centre: [f64; 2], half_width: f64) -> Self {
        let d = DeviceParams::default();
        Self {
            centre,
            half_width,
            wall_stiffness: d.workspace_wall_stiffness,
            wall_damping: d.workspace_wall_damping,
            trip_distance: d.workspace_trip_distance,
        }
    }

    /// The square of a five-bar whose device file names none (a UDP pantograph): centred on the
    /// symmetry axis `x = d/2` at the middle of each motor's reach, `r = (l1 + l2 + |l1 − l2|)/2`,
    /// `y = √(r² − (d/2)²)`, with half-width `(l1 + l2)/5` (the 2DIY's published ±30 mm square for its
    /// 160 mm reach, rounded): for the 2DIY gen 3 geometry (0.019, 0.088) ± 0.032 m.
    pub fn five_bar(l: &Pantograph2) -> Self {
        let r = 0.5 * (l.l1 + l.l2 + (l.l1 - l.l2).abs());
        let x = 0.5 * l.d;
        Self::around([x, (r * r - x * x).max(0.0).sqrt()], (l.l1 + l.l2) / 5.0)
    }

    /// Checks every field; the error names it.
    pub fn validate(&self) -> Result<(), String> {
        if !self.centre.iter().all(|c| c.is_finite()) {
            return Err(format!(
                "workspace centre {:?} m must be finite",
                self.centre
            ));
        }
        for (name, v, strict) in [
            ("half_width", self.half_width, true),
            ("wall_stiffness", self.wall_stiffness, false),
            ("wall_damping", self.wall_damping, false),
            ("trip_distance", self.trip_distance, true),
        ] {
            if !(v.is_finite() && (v > 0.0 || (!strict && v == 0.0))) {
                return Err(format!(
                    "workspace {name} must be a finite number {} 0 (got {v})",
                    if strict { ">" } else { ">=" }
                ));
            }
        }
        Ok(())
    }
}

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
    /// Whether the bound acts. A 2-DOF device starts where its user holds it: a Haply 2DIY at its
    /// rest (calibration) pose, which can lie outside the square (a gen 3 2DIY's is 34 mm below
    /// it), and the user then brings the handle in. Its bound ([`Self::of_square`]) starts unarmed
    /// and arms when the handle is first inside; until then it neither pushes nor trips (the
    /// start-up ramp and the other trips hold as always). The twin's ([`Self::new`]) is armed from
    /// the start.
    pub armed: bool,
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
    /// The bound of the twin-pantograph device `p` at period `dt` (s), armed from the first tick: the
    /// twin starts at its homing pose, the centre of its square (simulated or on Haply boards), so a
    /// twin handle outside its square is a fault and trips at once.
    pub fn new(p: &DeviceParams, dt: f64) -> Self {
        let mut b = Self::of_square(&WorkspaceSquare::of_device(p), dt);
        b.armed = true;
        b
    }

    /// The bound of square `s` at period `dt` (s), not yet armed: it arms when the handle is first
    /// inside the square ([`Self::armed`]; a 2-DOF device, e.g. a 2DIY starting at its rest pose).
    pub fn of_square(s: &WorkspaceSquare, dt: f64) -> Self {
        Self {
            centre: s.centre,
            half_width: s.half_width,
            stiffness: s.wall_stiffness.min(2.0 * s.wall_damping / dt),
            damping: s.wall_damping,
            trip_distance: s.trip_distance,
            armed: false,
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

    /// The bound applied to a device command: adds the wall wrench at handle pose `x` (m, device
    /// frame) and twist `v` to the command `f` (N, device frame), and returns the trip reason when
    /// the handle is past the trip distance. The one place both systems' ticks call. Never allocates.
    ///
    /// The bound arms the first time the handle is inside the square ([`Self::armed`]).
    #[inline]
    pub fn apply(&mut self, x: &V3, v: &V3, f: &mut V3) -> Option<SafetyReason> {
        if !self.armed {
            let inside = (0..2).all(|a| (x[a] - self.centre[a]).abs() <= self.half_width);
            if !inside {
                return None;
            }
            self.armed = true;
        }
        let (wall, excursion) = self.wrench(x, v);
        f[0] += wall[0];
        f[1] += wall[1];
        excursion.map(|e| SafetyReason::Workspace {
            axis: e.axis,
            position: e.position,
            edge: e.edge,
            trip: self.trip_distance,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A Haply board starts at its rest pose, which can lie outside the square (a gen 3 2DIY's is
    /// 34 mm below it): the bound must neither push nor trip there, and must do both once the user
    /// has brought the handle inside (found when the rest-pose start-up met the 2-DOF bound).
    #[test]
    fn a_handle_starting_outside_the_square_arms_the_bound_when_it_first_enters() {
        let square = WorkspaceSquare::around([0.019, 0.100], 0.03);
        let mut b = WorkspaceBound::of_square(&square, 1e-3);
        let v = [0.0; 3];
        let rest = [0.019, 0.0357, 0.0]; // 34.3 mm below the edge: past the 10 mm trip distance
        let mut f = [0.0; 3];
        assert_eq!(b.apply(&rest, &v, &mut f), None);
        assert_eq!(
            f, [0.0; 3],
            "no wall force before the handle has been inside"
        );
        assert!(!b.armed);
        // Brought in: armed, no force inside.
        assert_eq!(b.apply(&[0.019, 0.100, 0.0], &v, &mut f), None);
        assert!(b.armed);
        assert_eq!(f, [0.0; 3]);
        // Now 5 mm past the lower edge: the wall pushes back (+y); 34 mm past: the trip.
        assert_eq!(b.apply(&[0.019, 0.065, 0.0], &v, &mut f), None);
        assert!(f[1] > 0.0, "{f:?}");
        assert!(matches!(
            b.apply(&rest, &v, &mut [0.0; 3]),
            Some(SafetyReason::Workspace { axis: 1, .. })
        ));
    }
}
