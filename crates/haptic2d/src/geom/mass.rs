//! Mass properties of convex polygons and of unions of them.

use super::{cross, ConvexPolygon, Vec2};

/// Mass, centre of mass and centroidal inertia of a planar body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MassProperties {
    /// Mass (kg).
    pub mass: f64,
    /// Centre of mass in the shape frame (m).
    pub com: Vec2,
    /// Moment of inertia about the centre of mass (kg·m²).
    pub inertia: f64,
}

impl MassProperties {
    /// Area (m²), centroid (m) and polar second moment of area about the centroid (m⁴) of one polygon.
    pub fn polygon_geometry(p: &ConvexPolygon) -> (f64, Vec2, f64) {
        let v = p.vertices();
        let n = v.len();
        let mut area2 = 0.0;
        let mut c = Vec2::ZERO;
        let mut j_origin = 0.0;
        for i in 0..n {
            let a = v[i];
            let b = v[(i + 1) % n];
            let k = cross(a, b);
            area2 += k;
            c += (a + b) * k;
            j_origin += k * (a.dot(a) + a.dot(b) + b.dot(b));
        }
        let area = 0.5 * area2;
        let centroid = c / (3.0 * area2);
        let j_origin = j_origin / 12.0;
        (area, centroid, j_origin - area * centroid.length_squared())
    }

    /// Mass properties of a union of non-overlapping convex pieces with uniform `density` (kg/m²).
    pub fn from_density(pieces: &[ConvexPolygon], density: f64) -> Self {
        let mut total_area = 0.0;
        let mut moment = Vec2::ZERO;
        let mut geo = Vec::with_capacity(pieces.len());
        for p in pieces {
            let g = Self::polygon_geometry(p);
            total_area += g.0;
            moment += g.1 * g.0;
            geo.push(g);
        }
        let com = moment / total_area;
        let mut j = 0.0;
        for (a, c, jc) in geo {
            j += jc + a * (c - com).length_squared();
        }
        Self {
            mass: density * total_area,
            com,
            inertia: density * j,
        }
    }

    /// Mass properties of a union of pieces with a given total `mass` (kg), uniformly distributed.
    pub fn from_mass(pieces: &[ConvexPolygon], mass: f64) -> Self {
        let unit = Self::from_density(pieces, 1.0);
        let density = mass / unit.mass;
        Self {
            mass,
            com: unit.com,
            inertia: unit.inertia * density,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rectangle_inertia_matches_formula() {
        let r = ConvexPolygon::rectangle(0.04, 0.02)
            .unwrap()
            .shifted(Vec2::new(-0.3, 0.1));
        let mp = MassProperties::from_mass(&[r], 0.5);
        assert!((mp.inertia - 0.5 * (0.04f64.powi(2) + 0.02f64.powi(2)) / 12.0).abs() < 1e-15);
        assert!((mp.com - Vec2::new(0.3, -0.1)).length() < 1e-14);
    }

    #[test]
    fn union_of_two_halves_equals_whole() {
        let whole = ConvexPolygon::rectangle(0.04, 0.02).unwrap();
        let left = ConvexPolygon::rectangle(0.02, 0.02)
            .unwrap()
            .shifted(Vec2::new(0.01, 0.0));
        let right = ConvexPolygon::rectangle(0.02, 0.02)
            .unwrap()
            .shifted(Vec2::new(-0.01, 0.0));
        let a = MassProperties::from_mass(&[whole], 1.0);
        let b = MassProperties::from_mass(&[left, right], 1.0);
        assert!((a.inertia - b.inertia).abs() < 1e-15);
        assert!(b.com.length() < 1e-15);
    }
}
