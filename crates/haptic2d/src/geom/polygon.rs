//! Convex polygons stored counter-clockwise, with their features (§0.4, §9.3).
//!
//! Feature numbering: vertex `i` is `vertices[i]`; edge `i` runs from vertex `i` to vertex
//! `i + 1 (mod n)`, with unit tangent `tangents[i]`, outward unit normal
//! `normals[i] = (t_y, −t_x)` and length `lengths[i]`.

use super::{cross, Aabb, Vec2};
use std::fmt;

/// Why a list of points is not a valid convex polygon.
#[derive(Clone, Debug, PartialEq)]
pub enum PolygonError {
    /// Fewer than 3 vertices.
    TooFewVertices(usize),
    /// A coordinate is NaN or infinite.
    NonFinite(usize),
    /// Two consecutive vertices coincide (edge shorter than 1e-9 m).
    DegenerateEdge(usize),
    /// The vertices turn clockwise (the polygon is stored the wrong way round).
    Clockwise,
    /// The polygon is not convex at this vertex (or three vertices are collinear).
    NotConvex(usize),
}

impl fmt::Display for PolygonError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PolygonError::TooFewVertices(n) => write!(f, "a polygon needs at least 3 vertices, this one has {n}"),
            PolygonError::NonFinite(i) => write!(f, "vertex {i} has a NaN or infinite coordinate"),
            PolygonError::DegenerateEdge(i) => {
                write!(f, "vertices {i} and {} coincide (zero-length edge)", i + 1)
            }
            PolygonError::Clockwise => write!(
                f,
                "the vertices are listed clockwise; list them counter-clockwise (reverse the list)"
            ),
            PolygonError::NotConvex(i) => write!(
                f,
                "the polygon is not strictly convex at vertex {i}; split it into convex pieces (a body may have several)"
            ),
        }
    }
}

impl std::error::Error for PolygonError {}

/// A strictly convex polygon with counter-clockwise vertices in its own frame (m).
///
/// Its `n` vertices, normals and tangents share one allocation, in that order (a collider's
/// update reads the first two back to back, and the struct is 56 bytes instead of 104).
#[derive(Clone, Debug, PartialEq)]
pub struct ConvexPolygon {
    /// Vertices `[0, n)`, outward normals `[n, 2n)`, tangents `[2n, 3n)`.
    features: Vec<Vec2>,
    lengths: Vec<f64>,
    /// Largest distance of a vertex from the frame origin (m).
    radius: f64,
}

/// Largest length of `vertices` (m).
fn vertex_radius(vertices: &[Vec2]) -> f64 {
    vertices.iter().map(|v| v.length()).fold(0.0, f64::max)
}

impl ConvexPolygon {
    /// Builds a polygon from counter-clockwise vertices, checking that it is finite, CCW and strictly convex.
    pub fn new(vertices: Vec<Vec2>) -> Result<Self, PolygonError> {
        let n = vertices.len();
        if n < 3 {
            return Err(PolygonError::TooFewVertices(n));
        }
        for (i, v) in vertices.iter().enumerate() {
            if !v.x.is_finite() || !v.y.is_finite() {
                return Err(PolygonError::NonFinite(i));
            }
        }
        let mut tangents = Vec::with_capacity(n);
        let mut normals = Vec::with_capacity(n);
        let mut lengths = Vec::with_capacity(n);
        for i in 0..n {
            let e = vertices[(i + 1) % n] - vertices[i];
            let l = e.length();
            if l < 1e-9 {
                return Err(PolygonError::DegenerateEdge(i));
            }
            let t = e / l;
            tangents.push(t);
            normals.push(Vec2::new(t.y, -t.x));
            lengths.push(l);
        }
        // Signed area decides orientation; every turn must then be a strict left turn.
        let mut area2 = 0.0;
        for i in 0..n {
            area2 += cross(vertices[i], vertices[(i + 1) % n]);
        }
        if area2 < 0.0 {
            // Report clockwise only if the reversed polygon would be convex; otherwise it's non-convex.
            let all_right = (0..n).all(|i| cross(tangents[(i + n - 1) % n], tangents[i]) < -1e-12);
            return Err(if all_right {
                PolygonError::Clockwise
            } else {
                PolygonError::NotConvex(
                    (0..n)
                        .find(|&i| cross(tangents[(i + n - 1) % n], tangents[i]) >= -1e-12)
                        .unwrap_or(0),
                )
            });
        }
        for i in 0..n {
            if cross(tangents[(i + n - 1) % n], tangents[i]) <= 1e-12 {
                return Err(PolygonError::NotConvex(i));
            }
        }
        // A strictly convex simple polygon turns through exactly 2π; a star-shaped self-intersecting one more.
        let total: f64 = (0..n)
            .map(|i| {
                let a = tangents[(i + n - 1) % n];
                let b = tangents[i];
                cross(a, b).atan2(a.dot(b))
            })
            .sum();
        if (total - std::f64::consts::TAU).abs() > 1e-6 {
            return Err(PolygonError::NotConvex(0));
        }
        let radius = vertex_radius(&vertices);
        let mut features = vertices;
        features.reserve_exact(2 * n);
        features.extend_from_slice(&normals);
        features.extend_from_slice(&tangents);
        Ok(Self {
            features,
            lengths,
            radius,
        })
    }

    /// An axis-aligned rectangle of full width `w` and height `h` (m), centred on the origin.
    pub fn rectangle(w: f64, h: f64) -> Result<Self, PolygonError> {
        let (a, b) = (0.5 * w, 0.5 * h);
        Self::new(vec![
            Vec2::new(-a, -b),
            Vec2::new(a, -b),
            Vec2::new(a, b),
            Vec2::new(-a, b),
        ])
    }

    /// Number of vertices (= number of edges).
    #[inline]
    pub fn len(&self) -> usize {
        self.lengths.len()
    }
    /// Always false: a valid polygon has at least 3 vertices.
    #[inline]
    pub fn is_empty(&self) -> bool {
        false
    }
    /// Vertices, counter-clockwise (m).
    #[inline]
    pub fn vertices(&self) -> &[Vec2] {
        &self.features[..self.len()]
    }
    /// Unit edge tangents; edge `i` runs from vertex `i` to vertex `i+1`.
    #[inline]
    pub fn tangents(&self) -> &[Vec2] {
        &self.features[2 * self.len()..]
    }
    /// Outward unit edge normals `n_i = (t_y, −t_x)`.
    #[inline]
    pub fn normals(&self) -> &[Vec2] {
        let n = self.len();
        &self.features[n..2 * n]
    }
    /// Edge lengths (m).
    #[inline]
    pub fn lengths(&self) -> &[f64] {
        &self.lengths
    }
    /// Largest distance of a vertex from the polygon's frame origin (m): the vertex radius that
    /// bounds how far a rotation about the origin moves any point of the polygon.
    #[inline]
    pub fn radius(&self) -> f64 {
        self.radius
    }
    /// Index of the next vertex/edge, counter-clockwise.
    #[inline]
    pub fn next(&self, i: usize) -> usize {
        if i + 1 == self.len() {
            0
        } else {
            i + 1
        }
    }
    /// Index of the previous vertex/edge.
    #[inline]
    pub fn prev(&self, i: usize) -> usize {
        if i == 0 {
            self.len() - 1
        } else {
            i - 1
        }
    }
    /// The polygon translated by `-offset` (used to put a body's centre of mass at its frame origin).
    pub fn shifted(&self, offset: Vec2) -> Self {
        let mut p = self.clone();
        let n = p.len();
        for v in &mut p.features[..n] {
            *v -= offset;
        }
        p.radius = vertex_radius(p.vertices());
        p
    }
    /// Bounding box in the polygon's own frame.
    pub fn local_aabb(&self) -> Aabb {
        Aabb::from_points(self.vertices())
    }
    /// The parry shape of this polygon (for the global stage and as a test oracle).
    pub fn to_parry(&self) -> parry2d_f64::shape::ConvexPolygon {
        parry2d_f64::shape::ConvexPolygon::from_convex_polyline_unmodified(self.vertices().to_vec())
            .expect("a validated convex polygon is a valid parry polygon")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cached vertex radius is the largest vertex distance from the frame origin, also after
    /// a shift of the origin.
    #[test]
    fn radius_is_the_largest_vertex_distance() {
        let r = ConvexPolygon::rectangle(0.04, 0.02).unwrap();
        assert_eq!(r.radius(), Vec2::new(0.02, 0.01).length());
        let s = r.shifted(Vec2::new(0.02, 0.01));
        assert_eq!(s.radius(), Vec2::new(-0.04, -0.02).length());
    }

    #[test]
    fn rectangle_features() {
        let r = ConvexPolygon::rectangle(0.04, 0.02).unwrap();
        assert_eq!(r.len(), 4);
        // Edge 0 is the bottom edge, normal −y.
        assert!((r.normals()[0] - Vec2::new(0.0, -1.0)).length() < 1e-15);
        assert!((r.normals()[1] - Vec2::new(1.0, 0.0)).length() < 1e-15);
        assert!((r.lengths()[0] - 0.04).abs() < 1e-15);
    }

    #[test]
    fn rejects_bad_polygons() {
        let v = |p: &[(f64, f64)]| p.iter().map(|&(x, y)| Vec2::new(x, y)).collect::<Vec<_>>();
        assert_eq!(
            ConvexPolygon::new(v(&[(0., 0.), (1., 0.)])),
            Err(PolygonError::TooFewVertices(2))
        );
        assert_eq!(
            ConvexPolygon::new(v(&[(0., 0.), (0., 1.), (1., 0.)])),
            Err(PolygonError::Clockwise)
        );
        assert!(matches!(
            ConvexPolygon::new(v(&[(0., 0.), (2., 0.), (1., 0.5), (2., 2.), (0., 2.)])),
            Err(PolygonError::NotConvex(_))
        ));
        assert!(matches!(
            ConvexPolygon::new(v(&[(0., 0.), (1., 0.), (f64::NAN, 1.)])),
            Err(PolygonError::NonFinite(2))
        ));
        // A pentagram: every turn is left but it winds twice.
        let star: Vec<Vec2> = (0..5)
            .map(|k| {
                let a = (k as f64) * 4.0 * std::f64::consts::PI / 5.0;
                Vec2::new(a.cos(), a.sin())
            })
            .collect();
        assert!(ConvexPolygon::new(star).is_err());
    }
}
