//! Validation and construction: a parsed [`SceneFile`] → a [`World`], collecting every problem.

use super::bounds::{
    check_abs, check_count, check_pos, damping_ok, MAX_ANGLE_RAD, MAX_BODIES, MAX_CHAIN_SWEEPS,
    MAX_CHAIN_TAU_S, MAX_CONTACT_SPEED_M_S, MAX_DAMPING_N_S_M, MAX_DENSITY_KG_M2, MAX_FORCE_N,
    MAX_FREQUENCY_HZ, MAX_GUARD_J, MAX_INERTIA_KG_M2, MAX_LENGTH_M, MAX_LOADS, MAX_MASS_KG,
    MAX_OMEGA_RAD_S, MAX_PIECES_PER_BODY, MAX_PROXIMITY_EVERY, MAX_RATE_HZ, MAX_SPEED_M_S,
    MAX_TORQUE_N_M, MAX_VERTICES, MIN_RATE_HZ,
};
use super::device::device_from_table;
use super::file::{BodySection, SceneFile};
use super::laws::{friction_from, normal_from};
use super::{SceneError, SceneErrors};
use crate::body::Body;
use crate::collide::{body_thickness, speed_limit};
use crate::contact::ContactParams;
use crate::device::DeviceParams;
use crate::geom::{ConvexPolygon, MassProperties, Pose, Rot, Vec2};
use crate::integrate::{min_mass, IntegrationMode};
use crate::laws::normal::NormalModel;
use crate::load::{Load, Profile};
use crate::world::{World, WorldParams};

/// A validated scene: its world, ready to run, plus any warnings.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Scene name (from the file, or the built-in name).
    pub name: String,
    /// One-line description.
    pub description: String,
    /// Where it came from (file path or `built-in:<name>`).
    pub source: String,
    /// The world at its initial state.
    pub world: World,
    /// Non-fatal remarks (e.g. light bodies accepted with `allow_light_bodies`).
    pub warnings: Vec<String>,
    /// The device parameters of the file's `[device]` table (the spec defaults with the table's
    /// fields overriding them), validated at the scene's rate; `None` when the file has no `[device]`
    /// table. Only `haptic2d run` uses them; the world alone ignores them.
    pub device: Option<DeviceParams>,
    /// `world.allow_initial_overlap`: the file accepts bodies that start overlapping.
    pub allow_initial_overlap: bool,
}

impl Scene {
    /// Bodies that start overlapping deeper than the contact tolerance `δ_c` (`world.delta_c`):
    /// beyond it a vertex is no resting contact but an interpenetration the contact model was never
    /// asked to resolve. Shallower overlaps are resting contacts (booked as stored energy at t = 0).
    /// At most [`overlap::MAX_REPORTED`](super::overlap::MAX_REPORTED) pairs; the flag says the
    /// list was cut there.
    pub fn initial_overlaps(&self) -> (Vec<super::Overlap>, bool) {
        super::overlaps(&self.world, self.world.params.delta_c)
    }

    /// Parses and validates TOML scene text. `source` names the file in messages; `rate` overrides
    /// `world.rate` (Hz) when given.
    pub fn from_toml(text: &str, source: &str, rate: Option<f64>) -> Result<Scene, SceneErrors> {
        let fail = |errors| SceneErrors {
            source: source.to_string(),
            errors,
        };
        let file: SceneFile = toml::from_str(text).map_err(|e| {
            fail(vec![SceneError::from_toml(
                text,
                &e,
                "check the TOML syntax and field names against docs/SCENES.md",
            )])
        })?;
        build(&file, source, rate).map_err(fail)
    }
}

fn finite_pos(x: f64) -> bool {
    x.is_finite() && x > 0.0
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

/// Validates `file` and builds its world.
pub(super) fn build(
    file: &SceneFile,
    source: &str,
    rate: Option<f64>,
) -> Result<Scene, Vec<SceneError>> {
    let mut errs = Vec::new();
    let mut warnings = Vec::new();
    let w = &file.world;

    // [world]
    let rate = rate.or(w.rate).unwrap_or(500.0);
    let rate_ok = rate.is_finite() && (MIN_RATE_HZ..=MAX_RATE_HZ).contains(&rate);
    if !rate_ok {
        errs.push(SceneError::new(
            "world.rate",
            format!("must be a rate in Hz within [{MIN_RATE_HZ}, {MAX_RATE_HZ:e}], got {rate}"),
            "e.g. rate = 1000 (bounds: docs/SCENES.md)",
        ));
    }
    // An invalid rate has been reported; carry on with the default to find the other problems.
    let rate = if rate_ok { rate } else { 500.0 };
    let dt = 1.0 / rate;
    let mut params = WorldParams {
        dt,
        ..WorldParams::default()
    };
    if let Some(n) = w.proximity_every {
        if n == 0 || n > MAX_PROXIMITY_EVERY {
            errs.push(SceneError::new(
                "world.proximity_every",
                format!("must be in [1, {MAX_PROXIMITY_EVERY}], got {n}"),
                "e.g. proximity_every = 10",
            ));
        }
        params.proximity_every = n.clamp(1, MAX_PROXIMITY_EVERY);
    }
    if let Some(x) = w.delta_prox {
        check_pos("world.delta_prox", x, MAX_LENGTH_M, "m", &mut errs);
        params.delta_prox = x;
    }
    if let Some(x) = w.delta_c {
        if !(x.is_finite() && (0.0..=MAX_LENGTH_M).contains(&x)) {
            errs.push(SceneError::new(
                "world.delta_c",
                format!("must be a non-negative distance in m, got {x}"),
                "e.g. delta_c = 0.002",
            ));
        }
        params.delta_c = x;
    }
    params.mode = match w.integration.as_deref() {
        None | Some("semi-implicit") => IntegrationMode::SemiImplicit,
        Some("exact-zoh") => IntegrationMode::ExactZoh,
        Some("explicit-euler") => IntegrationMode::ExplicitEuler,
        Some(other) => {
            errs.push(SceneError::new(
                "world.integration",
                format!("unknown integration mode \"{other}\""),
                "use \"semi-implicit\" (passive, default) or \"exact-zoh\" (lossless, for wall comparisons)",
            ));
            IntegrationMode::SemiImplicit
        }
    };
    if let Some(g) = w.guard {
        if !(g.is_finite() && (0.0..=MAX_GUARD_J).contains(&g)) {
            errs.push(SceneError::new(
                "world.guard",
                format!("must be a non-negative energy in J, got {g}"),
                "e.g. guard = 1e-9",
            ));
        }
        params.guard = Some(g);
    }
    if let Some(t) = w.chain_tau {
        if !(t.is_finite() && (0.0..=MAX_CHAIN_TAU_S).contains(&t)) {
            errs.push(SceneError::new(
                "world.chain_tau",
                format!("must be a damping time in [0, {MAX_CHAIN_TAU_S}] s, got {t}"),
                "e.g. chain_tau = 0.0002, or chain_tau = 0 to turn the chain damper off",
            ));
        }
        params.chain_tau = (t > 0.0 && t.is_finite()).then_some(t);
    }
    if let Some(n) = w.chain_sweeps {
        if n > MAX_CHAIN_SWEEPS {
            errs.push(SceneError::new(
                "world.chain_sweeps",
                format!("must be in [0, {MAX_CHAIN_SWEEPS}], got {n}"),
                "e.g. chain_sweeps = 16",
            ));
        }
        params.chain_sweeps = n.min(MAX_CHAIN_SWEEPS);
    }
    let margin_needed = 2.0 * 1.0 * dt * params.proximity_every as f64 + params.delta_c;
    if params.delta_prox < margin_needed {
        warnings.push(format!(
            "world.delta_prox = {} m is below 2·v_rel,max·T_g + δ_c = {margin_needed:.4} m (v_rel,max = 1 m/s): fast bodies may be missed between proximity updates",
            params.delta_prox
        ));
    }

    // [contact]
    /// Largest accepted impact friction coefficient (dimensionless): far above any material pair.
    const MAX_IMPACT_MU: f64 = 100.0;
    let c = &file.contact;
    let mut cp = ContactParams::default();
    if let Some(x) = c.impacts {
        cp.impacts = x;
    }
    if let Some(e) = c.restitution {
        if !(0.0..=1.0).contains(&e) {
            errs.push(SceneError::new(
                "contact.restitution",
                format!("must be in [0, 1], got {e}"),
                "e.g. restitution = 0.5",
            ));
        }
        cp.restitution = e;
    }
    if let Some(v) = c.v_c {
        if !(v.is_finite() && (0.0..=MAX_CONTACT_SPEED_M_S).contains(&v)) {
            errs.push(SceneError::new(
                "contact.v_c",
                format!("must be a non-negative speed in m/s, got {v}"),
                "e.g. v_c = 0.02",
            ));
        }
        cp.v_c = v;
    }
    if let Some(x) = c.eps_s {
        if !(x.is_finite() && (0.0..=MAX_LENGTH_M).contains(&x)) {
            errs.push(SceneError::new(
                "contact.eps_s",
                format!("must be a non-negative distance in m, got {x}"),
                "e.g. eps_s = 1e-4",
            ));
        }
        cp.eps_s = x;
    }
    if let Some(v) = c.recollision_speed {
        check_pos(
            "contact.recollision_speed",
            v,
            MAX_CONTACT_SPEED_M_S,
            "m/s",
            &mut errs,
        );
        cp.v_re = Some(v);
    }
    if let Some(name) = &c.impact_friction {
        match crate::contact::ImpactFriction::from_name(name) {
            Ok(f) => cp.impact_friction = f,
            Err(e) => errs.push(SceneError::new(
                "contact.impact_friction",
                e,
                "e.g. impact_friction = \"coulomb\" (or \"none\", the default)",
            )),
        }
    }
    if let Some(mu) = c.impact_mu {
        if !(mu.is_finite() && (0.0..=MAX_IMPACT_MU).contains(&mu)) {
            errs.push(SceneError::new(
                "contact.impact_mu",
                format!("must be a friction coefficient in [0, {MAX_IMPACT_MU}], got {mu}"),
                "e.g. impact_mu = 0.3, or leave it out to use the friction model's mu_k",
            ));
        }
        cp.impact_mu = Some(mu);
        if cp.impact_friction == crate::contact::ImpactFriction::None {
            warnings.push(
                "contact.impact_mu is set but contact.impact_friction is \"none\": impacts stay frictionless (set impact_friction = \"coulomb\")".to_string(),
            );
        }
    }
    if let Some(on) = c.impact_surface_offset {
        cp.impact_surface_offset = on;
    }
    if let Some(n) = c.impact_sweeps {
        if !(1..=200).contains(&n) {
            errs.push(SceneError::new(
                "contact.impact_sweeps",
                format!("must be in [1, 200], got {n}"),
                "e.g. impact_sweeps = 8",
            ));
        }
        cp.impact_sweeps = n.clamp(1, 200);
    }
    params.contact = cp;

    // [device]
    let device = file
        .device
        .as_ref()
        .and_then(|t| device_from_table(t, "device.", rate_ok.then_some(dt), &mut errs));

    // [normal], [friction]
    let normal = normal_from(&file.normal, &mut errs);
    let friction = friction_from(&file.friction, &mut errs);

    // [[body]] and [[grid]]
    let mut bodies = Vec::new();
    let mut shapes = Vec::new();
    let body_entries_ok = check_count("body", file.bodies.len(), MAX_BODIES, "bodies", &mut errs);
    let body_entries = if body_entries_ok {
        &file.bodies[..]
    } else {
        &[]
    };
    for (i, b) in body_entries.iter().enumerate() {
        let field = match &b.name {
            Some(n) => format!("body[{i}] \"{n}\""),
            None => format!("body[{i}]"),
        };
        let name = b.name.clone().unwrap_or_else(|| format!("body{i}"));
        let pieces = body_pieces(b, &field, &mut errs);
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
            state_ok &= check_abs(&format!("{field}.{k}"), v, max, unit, &mut errs);
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
        if pieces.is_empty() {
            continue;
        }
        let mp = if fixed {
            MassProperties::from_density(&pieces, 1.0)
        } else {
            match (b.mass, b.density) {
                (Some(m), None) => {
                    if !check_pos(&format!("{field}.mass"), m, MAX_MASS_KG, "kg", &mut errs) {
                        continue;
                    }
                    MassProperties::from_mass(&pieces, m)
                }
                (None, Some(d)) => {
                    if !check_pos(
                        &format!("{field}.density"),
                        d,
                        MAX_DENSITY_KG_M2,
                        "kg/m²",
                        &mut errs,
                    ) {
                        continue;
                    }
                    let mp = MassProperties::from_density(&pieces, d);
                    // density × area can still exceed the mass bound.
                    if !check_pos(
                        &format!("{field}.density"),
                        mp.mass,
                        MAX_MASS_KG,
                        "kg (the mass it gives)",
                        &mut errs,
                    ) {
                        continue;
                    }
                    mp
                }
                (Some(_), Some(_)) => {
                    errs.push(SceneError::new(
                        format!("{field}.mass"),
                        "both mass and density given",
                        "keep one of them",
                    ));
                    continue;
                }
                (None, None) => {
                    errs.push(SceneError::new(
                        field.clone(),
                        "a dynamic body needs a mass or a density",
                        "add mass = <kg> or density = <kg/m²>, or kind = \"fixed\"",
                    ));
                    continue;
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
                    &mut errs,
                ) {
                    continue;
                }
                ii
            }
            _ => mp.inertia,
        };
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
        bodies.push(body);
        shapes.push(pieces);
    }
    for (gi, g) in file.grids.iter().enumerate() {
        let field = format!("grid[{gi}]");
        let prefix = g.name.clone().unwrap_or_else(|| "box".into());
        if g.columns == 0 || g.count == 0 {
            errs.push(SceneError::new(
                field.clone(),
                "count and columns must be at least 1",
                "e.g. count = 100, columns = 10",
            ));
            continue;
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
            continue;
        }
        let mut grid_ok = true;
        for (k, v, max, unit) in [
            ("origin[0]", g.origin[0], MAX_LENGTH_M, "m"),
            ("origin[1]", g.origin[1], MAX_LENGTH_M, "m"),
            ("spacing[0]", g.spacing[0], MAX_LENGTH_M, "m"),
            ("spacing[1]", g.spacing[1], MAX_LENGTH_M, "m"),
        ] {
            grid_ok &= check_abs(&format!("{field}.{k}"), v, max, unit, &mut errs);
        }
        for (k, v, max, unit) in [
            ("box[0]", g.rect[0], MAX_LENGTH_M, "m"),
            ("box[1]", g.rect[1], MAX_LENGTH_M, "m"),
            ("mass", g.mass, MAX_MASS_KG, "kg"),
        ] {
            grid_ok &= check_pos(&format!("{field}.{k}"), v, max, unit, &mut errs);
        }
        if !grid_ok {
            continue;
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
            continue;
        }
        let Ok(shape) = ConvexPolygon::rectangle(g.rect[0], g.rect[1]) else {
            continue;
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

    // Minimum mass (§6.4): a flat face rests on two contacts in parallel, so check 2K and 2B.
    let (k, b) = super::laws::stiffest(&normal, &friction);
    let (k2, b2) = (2.0 * k, 2.0 * b);
    for (i, body) in bodies.iter().enumerate() {
        if !body.is_dynamic() {
            continue;
        }
        let m_min = min_mass(k2, b2, dt);
        let r2 = shapes[i]
            .iter()
            .flat_map(|p| p.vertices().iter().map(|v| v.length_squared()))
            .fold(0.0, f64::max);
        let i_min = min_mass(k2 * r2, b2 * r2, dt);
        for (what, have, need, unit) in [
            ("mass", body.mass, m_min, "kg"),
            ("inertia", body.inertia, i_min, "kg·m²"),
        ] {
            if have < 1.5 * need {
                let msg = format!(
                    "{what} {have:.4e} {unit} is below 1.5 × min_{what} = {:.4e} {unit} for the stiffest contact (K = {k2} N/m, B = {b2} N·s/m for a face on two contacts, T = {dt} s): the simulation would be unstable or nearly so (§6.4)",
                    1.5 * need
                );
                if w.allow_light_bodies.unwrap_or(false) {
                    warnings.push(format!("body \"{}\": {msg}", body.name));
                } else {
                    errs.push(SceneError::new(
                        format!("body \"{}\".{what}", body.name),
                        msg,
                        "increase the mass, lower the contact stiffness/damping, raise world.rate, or set world.allow_light_bodies = true to accept it with a warning",
                    ));
                }
            }
        }
    }

    // Where the no-tunnelling promise needs the contact springs (issue 35): with impacts off,
    // nothing but the normal law stops a body that reaches a part, so it is stopped before a
    // corner passes the middle of the thinnest part only below `(w/2)·√(K/m)`.
    if !params.contact.impacts {
        warnings.extend(spring_stop_warnings(
            &bodies,
            &shapes,
            &normal,
            speed_limit(params.delta_prox, params.delta_c) / dt,
        ));
    }
    if normal.name() == "pulse" {
        warnings.push(PULSE_NOT_PASSIVE_2D.to_string());
    }

    // [[load]]
    let mut loads = Vec::new();
    for (li, l) in file.loads.iter().enumerate() {
        let field = format!("load[{li}]");
        let profile = match l.profile.as_deref() {
            None | Some("constant") => Profile::Constant,
            Some("sine") => match l.frequency {
                Some(f) if finite_pos(f) && f <= MAX_FREQUENCY_HZ => {
                    Profile::UnidirectionalSine { frequency: f }
                }
                _ => {
                    errs.push(SceneError::new(
                        format!("{field}.frequency"),
                        format!("the sine profile needs a positive frequency in Hz, at most {MAX_FREQUENCY_HZ:e}"),
                        "e.g. frequency = 1.0",
                    ));
                    Profile::Constant
                }
            },
            Some(p) => {
                errs.push(SceneError::new(
                    format!("{field}.profile"),
                    format!("unknown profile \"{p}\""),
                    "use \"constant\" or \"sine\"",
                ));
                Profile::Constant
            }
        };
        let f = l.force.unwrap_or([0.0, 0.0]);
        let tau = l.torque.unwrap_or(0.0);
        let unit = if l.per_mass.unwrap_or(false) {
            "m/s²"
        } else {
            "N"
        };
        let mut load_ok = check_abs(
            &format!("{field}.force[0]"),
            f[0],
            MAX_FORCE_N,
            unit,
            &mut errs,
        );
        load_ok &= check_abs(
            &format!("{field}.force[1]"),
            f[1],
            MAX_FORCE_N,
            unit,
            &mut errs,
        );
        load_ok &= check_abs(
            &format!("{field}.torque"),
            tau,
            MAX_TORQUE_N_M,
            "N·m",
            &mut errs,
        );
        if !load_ok {
            continue;
        }
        let targets: Vec<usize> = if l.body == "*" {
            (0..bodies.len())
                .filter(|&i| bodies[i].is_dynamic())
                .collect()
        } else {
            match bodies.iter().position(|b| b.name == l.body) {
                Some(i) if bodies[i].is_dynamic() => vec![i],
                Some(_) => {
                    errs.push(SceneError::new(
                        format!("{field}.body"),
                        format!("body \"{}\" is fixed; loads on it have no effect", l.body),
                        "load a dynamic body",
                    ));
                    vec![]
                }
                None => {
                    errs.push(SceneError::new(
                        format!("{field}.body"),
                        format!("no body named \"{}\"", l.body),
                        format!(
                            "use one of: {}",
                            bodies
                                .iter()
                                .map(|b| b.name.as_str())
                                .take(8)
                                .collect::<Vec<_>>()
                                .join(", ")
                        ),
                    ));
                    vec![]
                }
            }
        };
        if loads.len() + targets.len() > MAX_LOADS {
            check_count(
                &field,
                loads.len() + targets.len(),
                MAX_LOADS,
                "loads (after body = \"*\" expands)",
                &mut errs,
            );
            break;
        }
        for body in targets {
            loads.push(Load {
                body,
                force: Vec2::new(f[0], f[1]),
                torque: tau,
                per_mass: l.per_mass.unwrap_or(false),
                profile,
            });
        }
    }
    if !bodies.iter().any(|b| b.is_dynamic()) && errs.is_empty() {
        warnings.push("the scene has no dynamic body: nothing will move".into());
    }
    if !errs.is_empty() {
        return Err(errs);
    }
    let name = file.name.clone().unwrap_or_else(|| source.to_string());
    Ok(Scene {
        name,
        description: file.description.clone().unwrap_or_default(),
        source: source.to_string(),
        world: World::new(bodies, shapes, loads, normal, friction, params),
        warnings,
        device,
        allow_initial_overlap: w.allow_initial_overlap.unwrap_or(false),
    })
}

/// The `check` warning of a scene with the braking-pulse law (docs/MODELS.md §5.7): measured on
/// `pulse-energy.toml` (impacts off, two polygons in a box, 2 s at 1 kHz).
pub const PULSE_NOT_PASSIVE_2D: &str = "normal.model = \"pulse\" is not passive in 2-D: its pulse is sized from the pair's \
     reduced mass (no rotational inertia) and pushes for n_p samples after entry whatever the body does (a spinning \
     polygon, a corner that leaves early, other contacts), so it can return more energy than the entry had; measured \
     +1.545 J on pulse-energy.toml (2 s, impacts off). Passive only in the 1-D Fig. 4 case (a face flat against a \
     wall); prefer \"paper\", \"minsky\" or \"hysteretic\" for general scenes (docs/MODELS.md §5.7)";

/// With impacts off, the speed (m/s) below which the normal law alone stops a body of mass `m`
/// before one corner passes the middle of a part of thickness `w` (m): a corner spring `K`
/// (N/m) absorbs `½·m·v²` within `w/2` iff `v ≤ (w/2)·√(K/m)` (damping and other corners only
/// help). Beyond it, the nearest line of the corner is the far face and the body can pass.
pub fn spring_stop_speed(mass: f64, k: f64, w: f64) -> f64 {
    0.5 * w * (k / mass).sqrt()
}

/// One warning per dynamic body whose [`spring_stop_speed`] against the thinnest part of any
/// other body is below `limit` (m/s, the proximity guarantee), i.e. where `check` cannot promise
/// "no tunnelling below `limit`" with impacts off.
fn spring_stop_warnings(
    bodies: &[Body],
    shapes: &[Vec<ConvexPolygon>],
    normal: &NormalModel,
    limit: f64,
) -> Vec<String> {
    let (k, _) = normal.stiffness_damping();
    let thick: Vec<f64> = shapes
        .iter()
        .map(|ps| ps.iter().map(body_thickness).fold(f64::INFINITY, f64::min))
        .collect();
    let mut out = Vec::new();
    for (i, b) in bodies.iter().enumerate() {
        if !b.is_dynamic() || k.is_nan() || k <= 0.0 {
            continue;
        }
        let Some((j, w)) = thick
            .iter()
            .enumerate()
            .filter(|&(j, _)| j != i)
            .min_by(|a, b| a.1.total_cmp(b.1))
            .map(|(j, &w)| (j, w))
        else {
            continue;
        };
        let v = spring_stop_speed(b.mass, k, w);
        if v.is_finite() && v < limit {
            out.push(format!(
                "contact.impacts = false: only the contact springs stop body \"{}\" ({:.3} kg), so the \
                 no-tunnelling promise holds below {v:.2} m/s, not {limit:.1} m/s: faster, one corner \
                 (K = {k} N/m) is not stopped within half the thinnest part it can hit (\"{}\", {:.1} mm) \
                 and can pass through it, (w/2)·√(K/m); fix: contact.impacts = true, a stiffer normal \
                 law or thicker parts",
                b.name,
                b.mass,
                bodies[j].name,
                w * 1e3
            ));
        }
    }
    out
}
