//! Planar mode of the Inverse3: the device's 3-D cursor seen as a point of the world plane, the
//! virtual plane that holds the third axis, and the force clamp.
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
//! The plane point goes to the run loop as it is: the loop's system for the Inverse3 is the
//! Cartesian pass-through [`PointSystem`](haptic2d::haptic::PointSystem) (the point in, the plane
//! force out, `J = I`), so no linkage stands between the plane and the force rendered.

use super::device_file::Inverse3DeviceFile;

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

#[cfg(test)]
mod tests {
    use super::*;

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
