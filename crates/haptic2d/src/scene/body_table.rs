//! The `[[body]]` and `[[grid]]` tables of a scene file: bodies, their pieces, mass properties,
//! initial state and damping, every problem collected (docs/SCENES.md).

use super::bounds::{
    check_abs, check_count, check_pos, damping_ok, MAX_ANGLE_RAD, MAX_BODIES, MAX_DAMPING_N_S_M,
    MAX_DENSITY_KG_M2, MAX_INERTIA_KG_M2, MAX_LENGTH_M, MAX_MASS_KG, MAX_OMEGA_RAD_S,
    MAX_PIECES_PER_BODY, MAX_SPEED_M_S, MAX_VERTICES,
};
use super::file::{BodySection, GridSection, SceneFile};
use super::SceneError;
use crate::body::Body;
use crate::geom::{ConvexPolygon, MassProperties, Pose, Rot, Vec2};

/// `[[body]]` and `[[grid]]`: every body and its pieces (in the body's frame, centred on its centre
/// of mass), then a check that no two share a name. `dt` (s) bounds the bodies' damping.
pub(super) fn bodies_from(
    file: &SceneFile,
    dt: f64,
    errs: &mut Vec<SceneError>,
) -> (Vec<Body>, Vec<Vec<ConvexPolygon>>) {
    let mut bodies = Vec::new();
    let mut shapes = Vec::new();
    let body_entries_ok = check_count("body", file.bodies.len(), MAX_BODIES, "bodies", errs);
    let body_entries = if body_entries_ok {
        &file.bodies[..]
    } else {
        &[]
    };
    for (i, b) in body_entries.iter().enumerate() {
        if let Some((body, pieces)) = body_from(i, b, dt, errs) {
            bodies.push(body);
            shapes.push(pieces);
        }
    }
    for (gi, g) in file.grids.iter().enumerate() {
        grid_bodies(gi, g, &mut bodies, &mut shapes, errs);
    }
    let mut names = std::collections::BTreeSet::new();
    for b in &bodies {
        if !names.insert(b.name.clone()) {
            errs.push(SceneError::new(
                format!("body \"{}\"", b.name),
                "duplicate body name",
                "give every body a unique name",
            ));
        }
    }
    (bodies, shapes)
}

/// One `[[body]]` entry (index `i`): its body and pieces, or `None` when a problem (reported)
/// leaves nothing to build.
fn body_from(
    i: usize,
    b: &BodySection,
    dt: f64,
    errs: &mut Vec<SceneError>,
) -> Option<(Body, Vec<ConvexPolygon>)> {
    let field = match &b.name {
        Some(n) => format!("body[{i}] \"{n}\""),
        None => format!("body[{i}]"),
    };
    let name = b.name.clone().unwrap_or_else(|| format!("body{i}"));
    let pieces = body_pieces(b, &field, errs);
    let fixed = match b.kind.as_deref() {
        None | Some("dynamic") => false,
        Some("fixed") => true,
        Some(k) => {
            errs.push(SceneError::new(
                format!("{field}.kind"),
                format!("unknown kind \"{k}\""),
                "use \"dynamic\" or \"fixed\"",
            ));
            false
        }
    };
    let (pos, angle, vel, omega) = body_state(b, &field, fixed, errs);
    if pieces.is_empty() {
        return None;
    }
    let (mp, inertia) = body_mass(b, &field, fixed, &pieces, errs)?;
    let pieces: Vec<ConvexPolygon> = pieces.iter().map(|p| p.shifted(mp.com)).collect();
    let com_world = Vec2::new(pos[0], pos[1]) + Rot::new(angle).apply(mp.com);
    let pose = Pose {
        pos: com_world,
        angle,
    };
    let mut body = if fixed {
        Body::fixed(name, pose)
    } else {
        Body::dynamic(name, mp.mass, inertia, pose)
    };
    body.vel = Vec2::new(vel[0], vel[1]);
    body.omega = omega;
    body_damping(b, &field, fixed, dt, &mut body, errs);
    Some((body, pieces))
}

/// A body's pose and velocity: position (m), angle (rad), velocity (m/s), angular velocity
/// (rad/s). Each is checked against its bound; a fixed body may not be given a velocity.
fn body_state(
    b: &BodySection,
    field: &str,
    fixed: bool,
    errs: &mut Vec<SceneError>,
) -> ([f64; 2], f64, [f64; 2], f64) {
    let pos = b.position.unwrap_or([0.0, 0.0]);
    let angle = match (b.angle, b.angle_deg) {
        (Some(_), Some(_)) => {
            errs.push(SceneError::new(
                format!("{field}.angle"),
                "both angle and angle_deg given",
                "keep one of them",
            ));
            0.0
        }
        (Some(a), None) => a,
        (None, Some(d)) => d.to_radians(),
        (None, None) => 0.0,
    };
    let vel = b.velocity.unwrap_or([0.0, 0.0]);
    let omega = b.omega.unwrap_or(0.0);
    let mut state_ok = true;
    for (k, v, max, unit) in [
        ("position[0]", pos[0], MAX_LENGTH_M, "m"),
        ("position[1]", pos[1], MAX_LENGTH_M, "m"),
        (
            if b.angle_deg.is_some() {
                "angle_deg"
            } else {
                "angle"
            },
            angle,
            MAX_ANGLE_RAD,
            "rad",
        ),
        ("velocity[0]", vel[0], MAX_SPEED_M_S, "m/s"),
        ("velocity[1]", vel[1], MAX_SPEED_M_S, "m/s"),
        ("omega", omega, MAX_OMEGA_RAD_S, "rad/s"),
    ] {
        state_ok &= check_abs(&format!("{field}.{k}"), v, max, unit, errs);
    }
    // A fixed body never moves, but the contacts would read a velocity given to it as a
    // moving surface and feed energy into every body resting on it.
    if fixed && vel.iter().all(|v| v.is_finite()) && (vel[0] != 0.0 || vel[1] != 0.0) {
        errs.push(SceneError::new(
            format!("{field}.velocity"),
            format!("a fixed body never moves, so its velocity must be 0, got {vel:?} m/s"),
            "remove `velocity`, or make the body dynamic (kind = \"dynamic\") to give it one",
        ));
    }
    if fixed && omega.is_finite() && omega != 0.0 {
        errs.push(SceneError::new(
            format!("{field}.omega"),
            format!("a fixed body never moves, so its omega must be 0, got {omega} rad/s"),
            "remove `omega`, or make the body dynamic (kind = \"dynamic\") to give it one",
        ));
    }
    // A bad pose or velocity has been reported; the body is still built (with its checked
    // fields) so that loads naming it do not report a second, misleading problem.
    let _ = state_ok;
    (pos, angle, vel, omega)
}

/// A body's mass properties and inertia (kg·m², `inertia` overriding the shape's), or `None` when
/// a reported problem leaves none. A fixed body gets unit-density properties (its centroid).
fn body_mass(
    b: &BodySection,
    field: &str,
    fixed: bool,
    pieces: &[ConvexPolygon],
    errs: &mut Vec<SceneError>,
) -> Option<(MassProperties, f64)> {
    let mp = if fixed {
        MassProperties::from_density(pieces, 1.0)
    } else {
        match (b.mass, b.density) {
            (Some(m), None) => {
                if !check_pos(&format!("{field}.mass"), m, MAX_MASS_KG, "kg", errs) {
                    return None;
                }
                MassProperties::from_mass(pieces, m)
            }
            (None, Some(d)) => {
                if !check_pos(
                    &format!("{field}.density"),
                    d,
                    MAX_DENSITY_KG_M2,
                    "kg/m²",
                    errs,
                ) {
                    return None;
                }
                let mp = MassProperties::from_density(pieces, d);
                // density × area can still exceed the mass bound.
                if !check_pos(
                    &format!("{field}.density"),
                    mp.mass,
                    MAX_MASS_KG,
                    "kg (the mass it gives)",
                    errs,
                ) {
                    return None;
                }
                mp
            }
            (Some(_), Some(_)) => {
                errs.push(SceneError::new(
                    format!("{field}.mass"),
                    "both mass and density given",
                    "keep one of them",
                ));
                return None;
            }
            (None, None) => {
                errs.push(SceneError::new(
                    field.to_string(),
                    "a dynamic body needs a mass or a density",
                    "add mass = <kg> or density = <kg/m²>, or kind = \"fixed\"",
                ));
                return None;
            }
        }
    };
    let inertia = match b.inertia {
        Some(ii) if !fixed => {
            if !check_pos(
                &format!("{field}.inertia"),
                ii,
                MAX_INERTIA_KG_M2,
                "kg·m²",
                errs,
            ) {
                return None;
            }
            ii
        }
        _ => mp.inertia,
    };
    Some((mp, inertia))
}

/// A body's linear damping (N·s/m): within its bound and, on a dynamic body, stable for the
/// explicit damping step at the sample time `dt` (s).
fn body_damping(
    b: &BodySection,
    field: &str,
    fixed: bool,
    dt: f64,
    body: &mut Body,
    errs: &mut Vec<SceneError>,
) {
    if let Some(d) = b.damping {
        if !(d.is_finite() && (0.0..=MAX_DAMPING_N_S_M).contains(&d)) {
            errs.push(SceneError::new(
                format!("{field}.damping"),
                format!(
                    "must be a non-negative damping in N·s/m up to {MAX_DAMPING_N_S_M:e}, got {d}"
                ),
                "e.g. damping = 2.4",
            ));
        } else if !fixed && !damping_ok(d, body.mass, dt) {
            errs.push(SceneError::new(
                format!("{field}.damping"),
                format!(
                    "b·T/m = {d} N·s/m × {dt} s / {} kg = {:.3} is not below 2: the explicit damping step would diverge",
                    body.mass,
                    d * dt / body.mass
                ),
                format!(
                    "lower damping below {:.4e} N·s/m, raise the mass, or raise world.rate",
                    2.0 * body.mass / dt
                ),
            ));
        }
        body.damping = d;
    }
}

/// One `[[grid]]` entry (index `gi`): appends its boxes to `bodies` and `shapes`, or reports why
/// it cannot (the scene's body cap is checked before a single box is allocated).
fn grid_bodies(
    gi: usize,
    g: &GridSection,
    bodies: &mut Vec<Body>,
    shapes: &mut Vec<Vec<ConvexPolygon>>,
    errs: &mut Vec<SceneError>,
) {
    let field = format!("grid[{gi}]");
    let prefix = g.name.clone().unwrap_or_else(|| "box".into());
    if g.columns == 0 || g.count == 0 {
        errs.push(SceneError::new(
            field.clone(),
            "count and columns must be at least 1",
            "e.g. count = 100, columns = 10",
        ));
        return;
    }
    // The cap applies to the scene's total, checked before a single box is allocated.
    if g.count > MAX_BODIES.saturating_sub(bodies.len()) {
        errs.push(SceneError::new(
            format!("{field}.count"),
            format!(
                "{} boxes would make the scene {} bodies, above the documented cap of {MAX_BODIES}",
                g.count,
                bodies.len().saturating_add(g.count)
            ),
            format!(
                "use at most {} boxes here (bounds: docs/SCENES.md)",
                MAX_BODIES.saturating_sub(bodies.len())
            ),
        ));
        return;
    }
    let mut grid_ok = true;
    for (k, v, max, unit) in [
        ("origin[0]", g.origin[0], MAX_LENGTH_M, "m"),
        ("origin[1]", g.origin[1], MAX_LENGTH_M, "m"),
        ("spacing[0]", g.spacing[0], MAX_LENGTH_M, "m"),
        ("spacing[1]", g.spacing[1], MAX_LENGTH_M, "m"),
    ] {
        grid_ok &= check_abs(&format!("{field}.{k}"), v, max, unit, errs);
    }
    for (k, v, max, unit) in [
        ("box[0]", g.rect[0], MAX_LENGTH_M, "m"),
        ("box[1]", g.rect[1], MAX_LENGTH_M, "m"),
        ("mass", g.mass, MAX_MASS_KG, "kg"),
    ] {
        grid_ok &= check_pos(&format!("{field}.{k}"), v, max, unit, errs);
    }
    if !grid_ok {
        return;
    }
    // The farthest box centre must stay within the coordinate bound too.
    let rows = g.count.div_ceil(g.columns.min(g.count));
    let far = [
        g.origin[0] + (g.columns.min(g.count) as f64 - 0.5) * g.spacing[0].abs(),
        g.origin[1] + (rows as f64 - 1.0) * g.spacing[1].abs(),
    ];
    if far.iter().any(|x| x.abs() > MAX_LENGTH_M) {
        errs.push(SceneError::new(
            field.clone(),
            format!(
                "the grid reaches ({:.4e} m, {:.4e} m), beyond the documented bound ±{MAX_LENGTH_M:e} m",
                far[0], far[1]
            ),
            "reduce count, columns or spacing, or move the origin",
        ));
        return;
    }
    let Ok(shape) = ConvexPolygon::rectangle(g.rect[0], g.rect[1]) else {
        return;
    };
    let inertia = MassProperties::from_mass(std::slice::from_ref(&shape), g.mass).inertia;
    for k in 0..g.count {
        let (row, col) = (k / g.columns, k % g.columns);
        let shift = if g.stagger.unwrap_or(false) && row % 2 == 1 {
            0.5 * g.spacing[0]
        } else {
            0.0
        };
        let p = Pose::new(
            g.origin[0] + col as f64 * g.spacing[0] + shift,
            g.origin[1] + row as f64 * g.spacing[1],
            0.0,
        );
        bodies.push(Body::dynamic(format!("{prefix}{k}"), g.mass, inertia, p));
        shapes.push(vec![shape.clone()]);
    }
}

fn body_pieces(b: &BodySection, field: &str, errs: &mut Vec<SceneError>) -> Vec<ConvexPolygon> {
    let pts = |p: &Vec<[f64; 2]>| p.iter().map(|q| Vec2::new(q[0], q[1])).collect::<Vec<_>>();
    let mut raw: Vec<(String, Vec<Vec2>)> = Vec::new();
    let given = b.polygon.is_some() as u8 + b.rect.is_some() as u8 + b.pieces.is_some() as u8;
    if given != 1 {
        errs.push(SceneError::new(
            field,
            if given == 0 {
                "no shape given".to_string()
            } else {
                "more than one shape given".to_string()
            },
            "give exactly one of: polygon = [[x, y], ...], box = [width, height], pieces = [[[x, y], ...], ...]",
        ));
        return Vec::new();
    }
    // Counts first (each piece's vertices are checked before any polygon is built from them).
    if let Some(ps) = &b.pieces {
        if !check_count(
            &format!("{field}.pieces"),
            ps.len(),
            MAX_PIECES_PER_BODY,
            "pieces",
            errs,
        ) {
            return Vec::new();
        }
    }
    let listed: Vec<(String, &Vec<[f64; 2]>)> = match (&b.polygon, &b.pieces) {
        (Some(p), _) => vec![(format!("{field}.polygon"), p)],
        (_, Some(ps)) => ps
            .iter()
            .enumerate()
            .map(|(k, p)| (format!("{field}.pieces[{k}]"), p))
            .collect(),
        _ => Vec::new(),
    };
    let mut bad = false;
    for (f, p) in &listed {
        if !check_count(f, p.len(), MAX_VERTICES, "vertices", errs) {
            bad = true;
            continue;
        }
        for (j, q) in p.iter().enumerate() {
            for (c, x) in ["x", "y"].iter().zip(q) {
                bad |= !check_abs(&format!("{f}[{j}].{c}"), *x, MAX_LENGTH_M, "m", errs);
            }
        }
    }
    if bad {
        return Vec::new();
    }
    if let Some(p) = &b.polygon {
        raw.push((format!("{field}.polygon"), pts(p)));
    }
    if let Some([w, h]) = b.rect {
        if !(check_pos(&format!("{field}.box[0]"), w, MAX_LENGTH_M, "m", errs)
            & check_pos(&format!("{field}.box[1]"), h, MAX_LENGTH_M, "m", errs))
        {
            return Vec::new();
        }
        let (a, c) = (0.5 * w, 0.5 * h);
        raw.push((
            format!("{field}.box"),
            vec![
                Vec2::new(-a, -c),
                Vec2::new(a, -c),
                Vec2::new(a, c),
                Vec2::new(-a, c),
            ],
        ));
    }
    if let Some(ps) = &b.pieces {
        for (k, p) in ps.iter().enumerate() {
            raw.push((format!("{field}.pieces[{k}]"), pts(p)));
        }
    }
    let mut out = Vec::new();
    for (f, v) in raw {
        match ConvexPolygon::new(v) {
            Ok(p) => out.push(p),
            Err(e) => errs.push(SceneError::new(
                f,
                e.to_string(),
                "vertices must be listed counter-clockwise and form a convex polygon; split non-convex shapes into `pieces`",
            )),
        }
    }
    out
}
