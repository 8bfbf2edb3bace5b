//! Planar mode of the Inverse3: the device's 3-D cursor seen as a point of the world plane, the
//! virtual plane that holds the third axis, the force clamp, and the virtual linkage through which
//! the planar point enters the 2-DOF system of the run loop.
//!
//! Mapping. With the device file's axes `a = (i_x, s_x)`, `b = (i_y, s_y)` (device axis, sign) the
//! plane point of a cursor position `p` (m, device frame) is `u = (s_x·p[i_x], s_y·p[i_y])`; a plane
//! force `f = (f_x, f_y)` (N) goes back as `F[i_x] = s_x·f_x`, `F[i_y] = s_y·f_y`. The held axis `h`
//! gets the virtual plane's force
//!
//! ```text
//! F[h] = r(t)·(−K·(p[h] − p_0) − B·v[h]),     r(t) = min(1, t / T_ramp)
//! ```
//!
//! (K, B, p_0 from `[plane]`, `T_ramp` = `limits.ramp_time`), and the whole vector is clamped to
//! `|F| ≤ limits.force_limit` keeping its direction; a non-finite force becomes zero.
//!
//! Virtual linkage. The run loop's 2-DOF system is written for a five-bar (joint angles in, joint
//! torques out). A Cartesian device enters it through a *virtual* five-bar, `d = 0`,
//! `l1 = l2 = L = 0.5 m`: the plane point is shifted to the linkage's centre `(0, L·√2)`, where
//! the links meet at right angles, and turned into joint angles by the exact inverse kinematics;
//! the loop's joint torques come back as the plane force `f = J⁻ᵀ·τ` at the same angles. Both maps
//! are exact inverses, so the loop renders the same force it would on a Cartesian device. Within
//! `MAX_HALF_WIDTH` = 0.2 m of the centre the reach `r = |e|` stays in [0.507, 0.929] m of the
//! linkage's (0, 1) m, and the singularity margin `sin 2α`, `cos α = r / 2L`, above 0.68 (0.688 at the corners).

use haptic2d::device::pantograph2::{Pantograph2, M2};
use haptic2d::geom::Vec2;

use super::device_file::Inverse3DeviceFile;

/// Link length of the virtual five-bar (m).
pub const VIRTUAL_L: f64 = 0.5;

/// The virtual five-bar (`d = 0`, `l1 = l2 = VIRTUAL_L`).
pub fn virtual_linkage() -> Pantograph2 {
    Pantograph2 {
        d: 0.0,
        l1: VIRTUAL_L,
        l2: VIRTUAL_L,
    }
}

/// The virtual five-bar's centre (m, its frame): `(0, L·√2)`, links at right angles.
pub fn virtual_center() -> [f64; 2] {
    [0.0, VIRTUAL_L * std::f64::consts::SQRT_2]
}

/// Joint torque limit (N·m) of the virtual five-bar for a force limit `force_limit` (N): `4·L·F`.
/// A joint torque is `τ_i = (∂E/∂q_i)·f` with `|∂E/∂q_i| ≤ L / margin ≤ 2·L` in the usable square,
/// so the loop's torque clamp never binds before the driver's force clamp (twice the bound).
pub fn virtual_torque_limit(force_limit: f64) -> f64 {
    4.0 * VIRTUAL_L * force_limit
}

/// The plane mapping of one device file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlaneMap {
    axes: [(usize, f64); 2],
    held: usize,
    position: f64,
    k: f64,
    b: f64,
    force_limit: f64,
    ramp_time: f64,
    center: [f64; 2],
}

impl PlaneMap {
    /// The mapping of `file`.
    pub fn new(file: &Inverse3DeviceFile) -> Self {
        Self {
            axes: [
                (file.axes[0].index, file.axes[0].sign),
                (file.axes[1].index, file.axes[1].sign),
            ],
            held: file.held_axis,
            position: file.plane_position,
            k: file.plane_stiffness,
            b: file.plane_damping,
            force_limit: file.force_limit,
            ramp_time: file.ramp_time,
            center: file.center,
        }
    }

    /// The plane point `u` (m) of the cursor position `p` (m, device frame).
    #[inline]
    pub fn planar(&self, p: &[f64; 3]) -> [f64; 2] {
        let [(i, si), (j, sj)] = self.axes;
        [si * p[i], sj * p[j]]
    }

    /// The held axis's coordinate (m) of `p`.
    #[inline]
    pub fn held(&self, p: &[f64; 3]) -> f64 {
        p[self.held]
    }

    /// The ramp factor `r(t)` at `t` s after the plane was engaged, in [0, 1].
    #[inline]
    pub fn ramp(&self, t: f64) -> f64 {
        if self.ramp_time <= 0.0 {
            1.0
        } else {
            (t / self.ramp_time).clamp(0.0, 1.0)
        }
    }

    /// The device force (N, device frame) for the plane force `f` (N) at cursor position `p` (m) and
    /// velocity `v` (m/s), the plane's spring scaled by `ramp` ∈ [0, 1]: see the module's formula.
    /// Clamped to the force limit; zero if anything is non-finite.
    #[inline]
    pub fn device_force(&self, f: [f64; 2], p: &[f64; 3], v: &[f64; 3], ramp: f64) -> [f64; 3] {
        let mut out = [0.0; 3];
        let [(i, si), (j, sj)] = self.axes;
        out[i] = si * f[0];
        out[j] = sj * f[1];
        let h = self.held;
        out[h] = ramp * (-self.k * (p[h] - self.position) - self.b * v[h]);
        clamp_norm(out, self.force_limit)
    }

    /// The virtual linkage's end point (m) for the plane point `u` (m).
    #[inline]
    pub fn to_virtual(&self, u: [f64; 2]) -> Vec2 {
        let c = virtual_center();
        Vec2::new(u[0] - self.center[0] + c[0], u[1] - self.center[1] + c[1])
    }

    /// The device axis and sign carrying the plane's axis `k` (0 = world x, 1 = world y).
    pub fn axis(&self, k: usize) -> (usize, f64) {
        self.axes[k]
    }

    /// The force limit (N).
    pub fn force_limit(&self) -> f64 {
        self.force_limit
    }
}

/// `f` scaled down to magnitude `limit` if longer, keeping its direction; zero if not finite.
#[inline]
pub fn clamp_norm<const N: usize>(f: [f64; N], limit: f64) -> [f64; N] {
    let n2: f64 = f.iter().map(|x| x * x).sum();
    if !n2.is_finite() {
        return [0.0; N];
    }
    let n = n2.sqrt();
    if n <= limit {
        return f;
    }
    let s = limit / n;
    f.map(|x| x * s)
}

/// The end-point force `f = J⁻ᵀ·τ` (N) for joint torques `tau` (N·m): solves `Jᵀ·f = τ` by Cramer's
/// rule. `None` at a singularity.
#[inline]
pub fn wrench_of(j: &M2, tau: [f64; 2]) -> Option<[f64; 2]> {
    // Jᵀ = [[j00, j10], [j01, j11]].
    let (a, b, c, d) = (j[0][0], j[1][0], j[0][1], j[1][1]);
    let det = a * d - b * c;
    if det.abs() < 1e-12 || !det.is_finite() {
        return None;
    }
    Some([
        (d * tau[0] - b * tau[1]) / det,
        (a * tau[1] - c * tau[0]) / det,
    ])
}

#[cfg(test)]
mod tests {
    use super::*;
    use haptic2d::device::pantograph2::jt_mul;

    #[test]
    fn the_virtual_linkage_round_trips_points_and_forces_over_the_square() {
        let file = Inverse3DeviceFile::shipped();
        let map = PlaneMap::new(&file);
        let l = virtual_linkage();
        let h = super::super::device_file::MAX_HALF_WIDTH;
        for (dx, dy) in [(0.0, 0.0), (h, h), (-h, h), (h, -h), (-h, -h), (0.1, -0.05)] {
            let u = [file.center[0] + dx, file.center[1] + dy];
            let e = map.to_virtual(u);
            let q = l.ik(e).unwrap();
            let s = l.state(q).unwrap();
            assert!((s.e - e).length() < 1e-12, "{u:?}");
            assert!(s.margin > 0.68, "margin {} at {u:?}", s.margin);
            let f = [1.3, -2.1];
            let tau = jt_mul(&s.j, f);
            // |τ_i| ≤ |∂E/∂q_i|·|f| ≤ 2·L·|f|: half the virtual torque limit.
            let fnorm = f[0].hypot(f[1]);
            assert!(
                tau.iter().all(|t| t.abs() <= 2.0 * VIRTUAL_L * fnorm),
                "{tau:?}"
            );
            assert!(2.0 * VIRTUAL_L * fnorm <= 0.5 * virtual_torque_limit(fnorm));
            let back = wrench_of(&s.j, tau).unwrap();
            assert!((back[0] - f[0]).abs() < 1e-9 && (back[1] - f[1]).abs() < 1e-9);
        }
    }

    #[test]
    fn the_held_axis_gets_the_plane_spring_and_the_force_is_clamped() {
        let file = Inverse3DeviceFile::shipped(); // K = 1000 N/m, B = 10 N·s/m, limit 5 N
        let map = PlaneMap::new(&file);
        let p = [0.01, 0.02, 0.003];
        let v = [0.0, 0.0, -0.05];
        let f = map.device_force([0.5, -0.25], &p, &v, 1.0);
        // −1000·0.003 − 10·(−0.05) = −2.5 N on z.
        assert_eq!(f, [0.5, -0.25, -2.5]);
        let half = map.device_force([0.0, 0.0], &p, &v, map.ramp(0.25));
        assert_eq!(half, [0.0, 0.0, -1.25]);
        assert_eq!(map.device_force([0.0; 2], &p, &v, map.ramp(0.0)), [0.0; 3]);
        let big = map.device_force([30.0, 40.0], &[0.0; 3], &[0.0; 3], 1.0);
        assert!((big[0] - 3.0).abs() < 1e-12 && (big[1] - 4.0).abs() < 1e-12);
        assert_eq!(map.device_force([f64::NAN, 0.0], &p, &v, 1.0), [0.0; 3]);
    }
}
