//! The `[world]` and `[contact]` tables of a scene file: the world's numerical and contact
//! parameters, every problem collected (docs/SCENES.md).

use super::bounds::{
    check_pos, MAX_CHAIN_SWEEPS, MAX_CHAIN_TAU_S, MAX_CONTACT_SPEED_M_S, MAX_GUARD_J, MAX_LENGTH_M,
    MAX_PROXIMITY_EVERY, MAX_RATE_HZ, MIN_RATE_HZ,
};
use super::file::{ContactSection, WorldSection};
use super::SceneError;
use crate::contact::ContactParams;
use crate::contact::WorkBudget;
use crate::integrate::IntegrationMode;
use crate::world::WorldParams;

/// `[world]`: the rate (Hz) and the world's numerical parameters. Returns them and whether the
/// rate was valid (an invalid one is reported and replaced by 500 Hz so the other tables can still
/// be checked).
pub(super) fn world_params(
    w: &WorldSection,
    rate: Option<f64>,
    errs: &mut Vec<SceneError>,
    warnings: &mut Vec<String>,
) -> (WorldParams, bool) {
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
        check_pos("world.delta_prox", x, MAX_LENGTH_M, "m", errs);
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
    if let Some(n) = w.chain_budget {
        params.chain_budget = WorkBudget::from_setting(n);
    }
    let margin_needed = 2.0 * 1.0 * dt * params.proximity_every as f64 + params.delta_c;
    if params.delta_prox < margin_needed {
        warnings.push(format!(
            "world.delta_prox = {} m is below 2·v_rel,max·T_g + δ_c = {margin_needed:.4} m (v_rel,max = 1 m/s): fast bodies may be missed between proximity updates",
            params.delta_prox
        ));
    }
    (params, rate_ok)
}

/// `[contact]`: the contact and impact parameters.
pub(super) fn contact_params(
    c: &ContactSection,
    errs: &mut Vec<SceneError>,
    warnings: &mut Vec<String>,
) -> ContactParams {
    /// Largest accepted impact friction coefficient (dimensionless): far above any material pair.
    const MAX_IMPACT_MU: f64 = 100.0;
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
            errs,
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
                "e.g. impact_sweeps = 32",
            ));
        }
        cp.impact_sweeps = n.clamp(1, 200);
    }
    if let Some(n) = c.impact_budget {
        cp.impact_budget = WorkBudget::from_setting(n);
    }
    cp
}
