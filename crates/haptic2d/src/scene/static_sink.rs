//! The `check` warning of a body its own loads press through a part (issue 35): a penalty contact
//! holds a resting body only by being compressed, and a corner compressed through the whole part it
//! rests on leaves it: its record (tracking the face it entered) is released and the body falls
//! through. Under its
//! constant loads (gravity) a body resting on two corners compresses each by the depth at which the
//! law holds `F/2` (`F` the loads' peak force, N): `δ = F/(2·K)` for a spring of stiffness `K`
//! ([`NormalModel::static_depth`]); when `δ` reaches the
//! thickness of the thinnest part of another body, it sinks through (the random passivity suite's seed 6: a
//! 45 kg polygon on `minsky` k = 3360 N/m compresses 66 mm per corner against a 100 mm floor, and
//! leaves the box). A load stacked on top adds to `F`, so the warning is a lower bound on the
//! danger, not a guarantee of safety.

use crate::body::Body;
use crate::collide::body_thickness;
use crate::geom::ConvexPolygon;
use crate::laws::normal::NormalModel;
use crate::load::Load;

/// The thickness (m) of each body: its thinnest piece's.
pub(super) fn thicknesses(shapes: &[Vec<ConvexPolygon>]) -> Vec<f64> {
    shapes
        .iter()
        .map(|ps| ps.iter().map(body_thickness).fold(f64::INFINITY, f64::min))
        .collect()
}

/// The thinnest body other than `i` and its thickness (m), of [`thicknesses`] `thick`.
pub(super) fn thinnest_other(thick: &[f64], i: usize) -> Option<(usize, f64)> {
    thick
        .iter()
        .enumerate()
        .filter(|&(j, _)| j != i)
        .min_by(|a, b| a.1.total_cmp(b.1))
        .map(|(j, &w)| (j, w))
}

/// One warning per dynamic body whose loads compress its two resting corners through the thinnest
/// part of another body (a box flat on a 40 mm slab on the paper law with `kc` = 2000 N/m: 16 kg
/// and more, `δ` ≥ 39 mm, fall through; 14 kg rests).
pub fn static_sink_warnings(
    bodies: &[Body],
    shapes: &[Vec<ConvexPolygon>],
    loads: &[Load],
    normal: &NormalModel,
) -> Vec<String> {
    let thick = thicknesses(shapes);
    let mut out = Vec::new();
    for (i, b) in bodies.iter().enumerate() {
        if !b.is_dynamic() {
            continue;
        }
        let f: f64 = loads
            .iter()
            .filter(|l| l.body == i)
            .map(|l| {
                (if l.per_mass {
                    l.force * b.mass
                } else {
                    l.force
                })
                .length()
            })
            .sum();
        let Some((j, w)) = thinnest_other(&thick, i) else {
            continue;
        };
        if f <= 0.0 {
            continue;
        }
        let d = normal.static_depth(0.5 * f);
        if d >= w {
            out.push(format!(
                "body \"{}\" ({:.3} kg) rests on springs too soft for it: its loads ({f:.1} N) compress each of two \
                 resting corners by {:.1} mm (the depth at which the \"{}\" law holds F/2), at least the thickness of the thinnest part it can rest on \
                 (\"{}\", {:.1} mm), so its corners pass through that part and the body sinks through it; \
                 fix: a stiffer normal law, thicker parts or a lighter body",
                b.name,
                b.mass,
                d * 1e3,
                normal.name(),
                bodies[j].name,
                w * 1e3
            ));
        }
    }
    out
}
