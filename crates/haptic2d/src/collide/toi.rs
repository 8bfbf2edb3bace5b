//! The swept test (time of impact) for bodies that move farther in one sample than the contact
//! pipeline can follow (issue 10: a 2 mm rod thrown end-on at 5 m/s went 10 cm into a wall).
//!
//! # Why a sample can be too long
//!
//! The local stage gives a penetrating vertex the edge of the *nearest* line (§9.4, `local.rs`).
//! That is the crossed face only while the vertex is less than half the local thickness of the
//! other body deep: a vertex that jumps, in one sample, past the middle of a thin part (a wall, a
//! rod seen broadside) is nearer the far face and is pushed out through it. A sample of motion
//! `m` (m) can therefore add a depth of `m` to a pair; it is safe while `m` stays below
//! [`allowed_depth`] `= min(δ_c, w_min/4)` (`w_min` the thinner body's thickness, the minimum
//! width of the polygon): then the nearest line is still the crossed one and the record stores at
//! most `½·K_c·δ_c²`, as a slow contact does.
//!
//! # The test (after integration, `world/swept.rs`)
//!
//! Poses move linearly over the sample, `p(λ) = p_0 + λ·Δp`, `θ(λ) = θ_0 + λ·Δθ`, `λ ∈ [0, 1]`.
//! A body point `c + R(θ)·r` then moves at most `M_i = |Δp_i| + |Δθ_i|·ρ_i` per sample (`ρ_i` the
//! largest vertex radius about the centre of mass), so the distance of a pair shrinks at most at
//! `M = M_a + M_b` per unit `λ` (the relative bound [`pair_motion`] is used: a common translation
//! changes nothing), and so does the pair's separating-axis depth `D(λ)` (the
//! penetration depth of two convex polygons: moving every point by at most `δ` changes it by at
//! most `δ`). For a pair with `M > a` ([`allowed_depth`] `a`), `D` is sampled at `λ_j = j/n`,
//! `n = ⌈2M/a⌉` (steps of at most `a/2` of motion, so no passage through a part thicker than
//! `a/2` is skipped, and the end pose is not needed to overlap: a body that would pass right
//! through is caught in the middle). At the first `λ_j` with `D(λ_j) > D(0) + a/2` the bodies are
//! put back to `λ_t = λ_j`, where `D(λ_t) ≤ D(λ_{j−1}) + a/2 ≤ D(0) + a`: the pair is in contact,
//! at most `a` deeper than at the start, so the next sample creates the contact on the crossed
//! face, shallow, and the impact (or the contact law) takes it from there. A pair that slides in
//! contact keeps `D` near `D(0)` and is not touched.
//!
//! Putting a body back to `λ_t` (`world/swept.rs`) interpolates its velocity too, `v = v_0 + λ_t·Δv`: the
//! body lives only the fraction `λ_t` of the sample. For the semi-implicit step under a held
//! force `F`, `ΔE_kin − W = λ·F·T·(λ·T·a/2 − T·a) ≤ 0` for `λ ≤ 1`, so the put-back is passive,
//! like the full step (which is the case `λ = 1`). Box2D v3 does the same for fast bodies
//! (`b2SolveContinuous`: the body is moved back to its time of impact, velocity kept); here the
//! velocity is scaled with the time actually lived.
//!
//! # Limits
//!
//! The test runs on the proximity set, so a pair must be proximate before it can be swept: the
//! pairs of a body are decided again whenever it may have moved more than `(δ_prox − δ_c)/2`
//! since they were last decided (`world/proximity.rs`, `collide/broad/partial.rs`; the whole
//! global stage when many bodies did), which covers every pair as long as each body moves less than
//! `(δ_prox − δ_c)/2` per sample (20 mm with the defaults: 20 m/s at 1 kHz, 10 m/s at 500 Hz);
//! [`speed_limit`] gives that bound for a world. Poses are interpolated linearly, so a body that
//! turns by more than about a radian per sample is swept only approximately.

use crate::geom::{ConvexPolygon, Pose, Vec2};

/// Most depth samples of one swept test. A pair moving more than `TOI_MAX_SAMPLES·a/2` in one
/// sample (far beyond [`speed_limit`]) is sampled more coarsely.
pub const TOI_MAX_SAMPLES: u32 = 1024;

/// Depth a pair may gain in one sample without a swept test (m): `min(δ_c, w_min/4)`, with
/// `w_min` the smaller of the two bodies' thicknesses (minimum widths, m).
#[inline]
pub fn allowed_depth(delta_c: f64, thickness_a: f64, thickness_b: f64) -> f64 {
    delta_c.min(0.25 * thickness_a.min(thickness_b))
}

/// The largest motion per sample of any body point (m/sample) up to which the global stage's
/// re-run rule keeps every pair that can touch in the proximity set: `(δ_prox − δ_c)/2`. Divide by
/// the sample period for a speed (m/s, rim speed `|v| + |ω|·ρ` included).
#[inline]
pub fn speed_limit(delta_prox: f64, delta_c: f64) -> f64 {
    0.5 * (delta_prox - delta_c).max(0.0)
}

/// Minimum width of a convex polygon (m): the smallest, over its edges, of the depth of its
/// deepest vertex behind that edge's line (the thickness a vertex can cross).
pub fn thickness(p: &ConvexPolygon) -> f64 {
    let (v, n) = (p.vertices(), p.normals());
    (0..p.len())
        .map(|e| {
            v.iter()
                .map(|&w| -n[e].dot(w - v[e]))
                .fold(0.0f64, f64::max)
        })
        .fold(f64::INFINITY, f64::min)
}

/// Largest distance of a vertex from the body-frame origin (the centre of mass) (m): the
/// polygon's [`ConvexPolygon::radius`].
pub fn radius(p: &ConvexPolygon) -> f64 {
    p.radius()
}

/// One body's side of a swept pair: its shape (body frame), its poses at the start and end of the
/// sample, and its vertex radius `ρ` (m).
#[derive(Clone, Copy)]
pub struct SweptShape<'a> {
    /// The polygon in the body frame.
    pub shape: &'a ConvexPolygon,
    /// Pose at the start of the sample.
    pub start: Pose,
    /// Pose at the end of the sample (after integration).
    pub end: Pose,
    /// Largest vertex distance from the centre of mass (m), see [`radius`].
    pub radius: f64,
    /// The shape's seam mask ([`Collider::seams`](super::Collider::seams)): seams are no
    /// separating axes of the depth (`seam.rs`).
    pub seams: u128,
}

impl SweptShape<'_> {
    /// Motion bound of any point of the shape over the sample, `|Δp| + |Δθ|·ρ` (m).
    #[inline]
    pub fn motion(&self) -> f64 {
        (self.end.pos - self.start.pos).length()
            + (self.end.angle - self.start.angle).abs() * self.radius
    }
    fn pose_at(&self, lam: f64) -> Pose {
        Pose {
            pos: self.start.pos + (self.end.pos - self.start.pos) * lam,
            angle: self.start.angle + (self.end.angle - self.start.angle) * lam,
        }
    }
}

/// Bound on the motion of any point of `a` relative to `b` over the sample (m): the depth of a
/// pair does not change under a common translation, so only the relative translation counts,
/// `|Δp_a − Δp_b| + |Δθ_a|·ρ_a + |Δθ_b|·ρ_b` (two boxes falling side by side move 0 relative to
/// each other and need no swept test).
#[inline]
pub fn pair_motion(a: &SweptShape, b: &SweptShape) -> f64 {
    ((a.end.pos - a.start.pos) - (b.end.pos - b.start.pos)).length()
        + (a.end.angle - a.start.angle).abs() * a.radius
        + (b.end.angle - b.start.angle).abs() * b.radius
}

/// Scratch buffers of the swept test (world-frame vertices and normals), so it never allocates
/// once they have grown to the largest polygon.
#[derive(Clone, Debug, Default)]
pub struct SweepScratch {
    va: Vec<Vec2>,
    vb: Vec<Vec2>,
    na: Vec<Vec2>,
    nb: Vec<Vec2>,
    seams: [u128; 2],
}

impl SweepScratch {
    /// Scratch for polygons of up to `n` vertices.
    pub fn with_capacity(n: usize) -> Self {
        Self {
            va: Vec::with_capacity(n),
            vb: Vec::with_capacity(n),
            na: Vec::with_capacity(n),
            nb: Vec::with_capacity(n),
            seams: [0; 2],
        }
    }

    fn place(&mut self, a: &SweptShape, b: &SweptShape, lam: f64) {
        fn fill(s: &SweptShape, lam: f64, v: &mut Vec<Vec2>, n: &mut Vec<Vec2>) {
            let pose = s.pose_at(lam);
            let rot = pose.rot();
            v.clear();
            n.clear();
            v.extend(s.shape.vertices().iter().map(|&p| pose.pos + rot.apply(p)));
            n.extend(s.shape.normals().iter().map(|&m| rot.apply(m)));
        }
        fill(a, lam, &mut self.va, &mut self.na);
        fill(b, lam, &mut self.vb, &mut self.nb);
        self.seams = [a.seams, b.seams];
    }

    /// Separating-axis depth of the placed pair (m, 0 if apart), with the seam rules of
    /// [`sat_depth`](super::sat_depth).
    fn depth(&self) -> f64 {
        let [sa, sb] = self.seams;
        let seam = |s: u128, e: usize| e < 128 && (s >> e) & 1 == 1;
        let through = |n: &[Vec2], s: u128, u: Vec2| {
            s != 0
                && n.iter()
                    .enumerate()
                    .any(|(e, m)| seam(s, e) && m.dot(u) > 1e-12)
        };
        let (mut depth, mut fallback) = (f64::INFINITY, f64::INFINITY);
        for (v, n, w, s, sign) in [
            (&self.va, &self.na, &self.vb, sa, -1.0),
            (&self.vb, &self.nb, &self.va, sb, 1.0),
        ] {
            for e in 0..v.len() {
                let min_d = w
                    .iter()
                    .map(|&q| n[e].dot(q - v[e]))
                    .fold(f64::INFINITY, f64::min);
                if min_d >= 0.0 {
                    return 0.0;
                }
                if seam(s, e) {
                    continue;
                }
                fallback = fallback.min(-min_d);
                let u = n[e] * sign;
                if (sa | sb) == 0 || !(through(&self.nb, sb, u) || through(&self.na, sa, -u)) {
                    depth = depth.min(-min_d);
                }
            }
        }
        if depth.is_finite() {
            depth
        } else if fallback.is_finite() {
            fallback
        } else {
            0.0
        }
    }
}

/// The swept test of one pair over one sample: `Some(λ_t)` if the pair's separating-axis depth
/// would grow by more than `allowed/2` (m, [`allowed_depth`]) during the sample and the bodies
/// must be put back to the fraction `λ_t ∈ (0, 1]` of it (module docs); `None` if the sample can
/// stand as integrated.
pub fn swept_put_back(
    a: &SweptShape,
    b: &SweptShape,
    allowed: f64,
    scratch: &mut SweepScratch,
) -> Option<f64> {
    let m = pair_motion(a, b);
    if !(m > allowed && allowed > 0.0 && m.is_finite()) {
        // It cannot gain more than its motion.
        return None;
    }
    let n = ((2.0 * m / allowed).ceil() as u32).clamp(1, TOI_MAX_SAMPLES);
    scratch.place(a, b, 0.0);
    let bound = scratch.depth() + 0.5 * allowed;
    for j in 1..=n {
        let lam = j as f64 / n as f64;
        scratch.place(a, b, lam);
        if scratch.depth() > bound {
            return (j < n).then_some(lam);
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::{pair_motion, SweptShape};
    use crate::geom::{ConvexPolygon, Pose};

    /// The bound the world's slow-pair skip rests on (`world/swept.rs`): over 200 000 seeded
    /// random pairs of motions of every scale (1e-9 m to 1 m, 1e-12 to 1 rad), half of them
    /// head-on (`Δp_b = −Δp_a`, where the triangle inequality is an equality and only rounding
    /// decides), the pair's relative motion is at most the sum of the two bodies' motions times
    /// `1 + 1e-9`; head-on it reaches that sum to within 1e-12 relative.
    #[test]
    fn pair_motion_is_within_the_sum_of_the_motions_up_to_rounding() {
        let mut state = 0x9fb2_1c65_1e98_df25u64;
        let mut uniform = move || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            ((state >> 11) as f64) / ((1u64 << 53) as f64)
        };
        let square = ConvexPolygon::rectangle(0.1, 0.1).unwrap();
        let mut closest = 0.0f64;
        for k in 0..200_000 {
            let scale = 10f64.powf(-9.0 * uniform());
            let turn = 10f64.powf(-12.0 * uniform());
            let (dx, dy) = (scale * (uniform() - 0.5), scale * (uniform() - 0.5));
            let head_on = k % 2 == 0;
            let (ex, ey) = if head_on {
                (-dx, -dy)
            } else {
                (scale * (uniform() - 0.5), scale * (uniform() - 0.5))
            };
            let start_a = Pose::new(uniform() - 0.5, uniform() - 0.5, uniform() - 0.5);
            let start_b = Pose::new(uniform() - 0.5, uniform() - 0.5, uniform() - 0.5);
            let side = |start: Pose, (x, y, w): (f64, f64, f64)| SweptShape {
                shape: &square,
                start,
                end: Pose::new(start.pos.x + x, start.pos.y + y, start.angle + w),
                radius: 0.05 + 0.1 * (start.pos.x + 0.5),
                seams: 0,
            };
            let a = side(start_a, (dx, dy, turn));
            let b = side(start_b, (ex, ey, -turn));
            let (m, sum) = (pair_motion(&a, &b), a.motion() + b.motion());
            assert!(m <= sum * (1.0 + 1e-9), "{m} > {sum} at {k}");
            if head_on {
                closest = closest.max(m / sum);
            }
        }
        assert!(
            closest > 1.0 - 1e-12,
            "head-on pairs came to {closest} of the sum"
        );
    }
}
