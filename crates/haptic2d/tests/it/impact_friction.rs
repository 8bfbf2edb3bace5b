//! Frictional impacts (issue 16) at the solver level: the energy guarantee on 10⁴ random
//! simultaneous impacts, the Coulomb interval, and a single rod end against Routh's closed-form
//! planar solutions (sliding throughout, sticking, slip reversal) written in world coordinates
//! from the textbook inverse-mass matrix, independent of the solver's Jacobians.

use haptic2d::body::Body;
use haptic2d::contact::impact::{ImpactRow, ImpactSolver};
use haptic2d::contact::ImpactFriction;
use haptic2d::geom::{cross, Pose, Vec2};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// 10⁴ random simultaneous frictional impacts (1–8 contacts on 1–3 dynamic bodies and a fixed
/// ground, random normals, lever arms, restitution in [0, 1], μ in [0, 2], approach and slip
/// velocities): the kinetic energy never rises (beyond the documented relative 1e-12 of the
/// energy check plus 1e-15 J), every impulse is finite, `p_n ≥ 0` and `|p_t| ≤ μ·p_n`.
#[test]
fn random_frictional_impacts_never_gain_energy_and_stay_finite() {
    let mut rng = ChaCha8Rng::seed_from_u64(16);
    let mut solver = ImpactSolver::new();
    let mut rows = Vec::new();
    let (mut fallbacks_seen, mut multi) = (0u64, 0usize);
    let (mut iterative, mut unconverged) = (0usize, 0usize);
    for case in 0..10_000 {
        let nb = rng.random_range(1..=3);
        let mut bodies = vec![Body::fixed("ground", Pose::IDENTITY)];
        for k in 0..nb {
            let m = rng.random_range(0.1..5.0);
            let i = m * rng.random_range(1e-4..0.05);
            let mut b = Body::dynamic(format!("b{k}"), m, i, Pose::new(0.0, 0.0, 0.0));
            b.vel = Vec2::new(rng.random_range(-2.0..2.0), rng.random_range(-2.0..2.0));
            b.omega = rng.random_range(-10.0..10.0);
            bodies.push(b);
        }
        let n = rng.random_range(1..=8);
        rows.clear();
        for _ in 0..n {
            let a = rng.random_range(1..=nb);
            let mut b = rng.random_range(0..=nb);
            if b == a {
                b = 0;
            }
            let ang: f64 = rng.random_range(0.0..std::f64::consts::TAU);
            let arm = |rng: &mut ChaCha8Rng| {
                Vec2::new(rng.random_range(-0.2..0.2), rng.random_range(-0.2..0.2))
            };
            rows.push(ImpactRow {
                body_a: a,
                body_b: b,
                n: Vec2::new(ang.cos(), ang.sin()),
                r_a: arm(&mut rng),
                r_b: arm(&mut rng),
                restitution: rng.random_range(0.0..=1.0),
            });
        }
        let mu = rng.random_range(0.0..2.0);
        solver.set_friction(ImpactFriction::Coulomb, mu);
        let ke0: f64 = bodies.iter().map(Body::kinetic_energy).sum();
        let out = solver.solve(&rows, &mut bodies);
        let ke1: f64 = bodies.iter().map(Body::kinetic_energy).sum();
        assert!(
            ke1 <= ke0 * (1.0 + 1e-12) + 1e-15,
            "case {case}: KE {ke0} -> {ke1} (n = {n}, μ = {mu})"
        );
        assert!((out.kinetic_energy_after - ke1).abs() <= 1e-12 * ke0.max(1.0));
        let f = solver.frictional();
        for i in 0..n {
            let (pn, pt) = (f.normal_impulses()[i], f.tangential_impulses()[i]);
            assert!(pn.is_finite() && pt.is_finite(), "case {case}: non-finite");
            assert!(pn >= 0.0, "case {case}: p_n = {pn}");
            assert!(
                pt.abs() <= mu * pn * (1.0 + 1e-9) + 1e-12,
                "case {case}: |p_t| = {} > μ·p_n = {}",
                pt.abs(),
                mu * pn
            );
        }
        for b in &bodies {
            assert!(b.vel.x.is_finite() && b.vel.y.is_finite() && b.omega.is_finite());
        }
        if out.energy_fallback {
            fallbacks_seen += 1;
        }
        multi += (n > 1) as usize;
        if n > 4 {
            iterative += 1;
            unconverged += (!out.compression.converged) as usize;
        }
    }
    let (restitution_scaled, jump_scaled) = solver.frictional().fallbacks();
    eprintln!(
        "10^4 random sets: {multi} with several contacts; energy fallbacks {fallbacks_seen} \
         (restitution scaled {restitution_scaled}, whole jump scaled {jump_scaled}); \
         iterative (n > 4) {iterative}, of which at the sweep limit {unconverged}"
    );
    // The random set exercises the guarantee (Poisson with friction does create energy sometimes)
    // and the multi-contact solver.
    assert!(fallbacks_seen > 0, "no case needed the energy fallback");
    assert!(multi > 5000);
    assert_eq!(
        solver.energy_fallbacks(),
        fallbacks_seen,
        "every fallback is counted"
    );
}

/// A uniform rod (mass m, length 2l, I = m l²/3) whose lower end touches the ground `y = 0` at
/// angle θ above the horizontal, the end at `r = l·(−cos θ, −sin θ)` from the centre.
struct Rod {
    m: f64,
    i: f64,
    r: Vec2,
}

impl Rod {
    fn new(theta_deg: f64) -> Self {
        let (m, l) = (1.0, 0.5);
        let th = theta_deg.to_radians();
        Rod {
            m,
            i: m * l * l / 3.0,
            r: Vec2::new(-l * th.cos(), -l * th.sin()),
        }
    }

    /// Textbook inverse-mass matrix at the contact (Stronge, Impact Mechanics §2):
    /// `Δv_c = K·P`, `K = [[1/m + r_y²/I, −r_x r_y/I], [−r_x r_y/I, 1/m + r_x²/I]]` in (x, y).
    fn k(&self) -> (f64, f64, f64) {
        let (rx, ry) = (self.r.x, self.r.y);
        (
            1.0 / self.m + ry * ry / self.i,
            -rx * ry / self.i,
            1.0 / self.m + rx * rx / self.i,
        )
    }

    /// Runs the engine's frictional impact on this rod with COM velocity `v` and spin `w`.
    fn engine(&self, v: Vec2, w: f64, e: f64, mu: f64) -> (Vec2, f64) {
        self.impact(v, w, e, Some(mu))
    }

    /// The rod's impact with COM velocity `v`, spin `w` and restitution `e`, solved by the engine
    /// with Coulomb friction `mu`, or with the frictionless default when `mu` is `None`.
    fn impact(&self, v: Vec2, w: f64, e: f64, mu: Option<f64>) -> (Vec2, f64) {
        let mut bodies = vec![
            Body::fixed("ground", Pose::IDENTITY),
            Body::dynamic("rod", self.m, self.i, Pose::new(0.0, 0.0, 0.0)),
        ];
        bodies[1].vel = v;
        bodies[1].omega = w;
        let row = ImpactRow {
            body_a: 1,
            body_b: 0,
            n: Vec2::new(0.0, 1.0),
            r_a: self.r,
            r_b: self.r,
            restitution: e,
        };
        let mut s = ImpactSolver::new();
        if let Some(mu) = mu {
            s.set_friction(ImpactFriction::Coulomb, mu);
        }
        s.solve(&[row], &mut bodies);
        (bodies[1].vel, bodies[1].omega)
    }

    /// The contact-point velocity `v + ω·perp(r)`.
    fn point(&self, v: Vec2, w: f64) -> Vec2 {
        v + Vec2::new(-self.r.y, self.r.x) * w
    }

    /// COM velocity and spin after the impulse `P` at the end.
    fn after(&self, v: Vec2, w: f64, p: Vec2) -> (Vec2, f64) {
        (v + p / self.m, w + cross(self.r, p) / self.i)
    }
}

/// Routh, sliding throughout (Stronge §4.3, case "slip continues"): with `P_x = −s μ P_y` the
/// normal contact velocity grows at `K_yy − s μ K_xy` per unit `P_y`, so compression ends at
/// `p_c = −v_y0/(K_yy − s μ K_xy)`, Poisson gives `P_y = (1 + e) p_c`, and slip keeps its sign
/// when `v_x0 + P_y (K_xy − s μ K_xx)` does.
#[test]
fn routh_sliding_throughout_rod_end() {
    for theta in [20.0, 45.0, 70.0] {
        let rod = Rod::new(theta);
        let (kxx, kxy, kyy) = rod.k();
        let (e, mu) = (0.5, 0.3);
        let v = Vec2::new(3.0, -1.0);
        let vc = rod.point(v, 0.0);
        let s = vc.x.signum();
        let pc = -vc.y / (kyy - s * mu * kxy);
        let py = (1.0 + e) * pc;
        assert!(
            (vc.x + py * (kxy - s * mu * kxx)) * s > 0.0,
            "θ = {theta}: case is not sliding throughout"
        );
        let (v_ref, w_ref) = rod.after(v, 0.0, Vec2::new(-s * mu * py, py));
        let (v_got, w_got) = rod.engine(v, 0.0, e, mu);
        assert!(
            (v_got - v_ref).length() < 1e-12 && (w_got - w_ref).abs() < 1e-11,
            "θ = {theta}: engine ({v_got:?}, {w_got}) vs Routh ({v_ref:?}, {w_ref})"
        );
    }
}

/// Routh, sticking (Stronge §4.3, "slip stops and sticks"): for a rod end at rest tangentially
/// (`v_x0 = 0`) with `|K_xy| ≤ μ K_xx`, the end sticks throughout: `P_x = −(K_xy/K_xx) P_y`, the
/// normal velocity grows at `det K / K_xx`, and the end leaves with `v_c = (0, −e·v_y0)`.
#[test]
fn routh_sticking_rod_end() {
    for theta in [20.0, 45.0, 70.0] {
        let rod = Rod::new(theta);
        let (kxx, kxy, kyy) = rod.k();
        let (e, mu) = (0.6, 0.9);
        assert!(kxy.abs() <= mu * kxx);
        // COM velocity chosen so the end's tangential velocity is zero with spin w.
        let w = 2.0;
        let v = Vec2::new(rod.r.y * w, -1.5);
        let vc = rod.point(v, w);
        assert!(vc.x.abs() < 1e-15);
        let pc = -vc.y * kxx / (kxx * kyy - kxy * kxy);
        let py = (1.0 + e) * pc;
        let (v_ref, w_ref) = rod.after(v, w, Vec2::new(-kxy / kxx * py, py));
        let (v_got, w_got) = rod.engine(v, w, e, mu);
        let vc_got = rod.point(v_got, w_got);
        assert!(
            vc_got.x.abs() < 1e-12,
            "θ = {theta}: end slips at {}",
            vc_got.x
        );
        assert!(
            (vc_got.y + e * vc.y).abs() < 1e-12,
            "θ = {theta}: v_n+ = {}",
            vc_got.y
        );
        assert!((v_got - v_ref).length() < 1e-12 && (w_got - w_ref).abs() < 1e-11);
    }
}

/// Routh, slip reversal (Stronge §4.3, "slip reverses"): the end slides with `s₀` against the
/// coupling (`s₀ = −sign K_xy`) and `|K_xy| > μ K_xx`, so slip stops at
/// `P₁ = −v_x0/(K_xy − s₀ μ K_xx)` and restarts the other way (`s₁ = −s₀`). The normal impulse
/// is piecewise: compression ends in the second piece here, `p_c = P₁ + (−v_y(P₁))/(K_yy − s₁ μ K_xy)`.
#[test]
fn routh_slip_reversal_rod_end() {
    for theta in [30.0, 45.0] {
        let rod = Rod::new(theta);
        let (kxx, kxy, kyy) = rod.k();
        let (e, mu) = (0.5, 0.2);
        assert!(kxy.abs() > mu * kxx, "θ = {theta}: stick would hold");
        let s0 = -kxy.signum();
        let v = Vec2::new(s0 * 0.1, -2.0);
        let vc = rod.point(v, 0.0);
        let p1 = -vc.x / (kxy - s0 * mu * kxx);
        let vy1 = vc.y + p1 * (kyy - s0 * mu * kxy);
        assert!(
            p1 > 0.0 && vy1 < 0.0,
            "θ = {theta}: slip must stop during compression"
        );
        let s1 = -s0;
        let pc = p1 - vy1 / (kyy - s1 * mu * kxy);
        let py = (1.0 + e) * pc;
        let px = -s0 * mu * p1 - s1 * mu * (py - p1);
        let (v_ref, w_ref) = rod.after(v, 0.0, Vec2::new(px, py));
        let (v_got, w_got) = rod.engine(v, 0.0, e, mu);
        assert!(
            (v_got - v_ref).length() < 1e-12 && (w_got - w_ref).abs() < 1e-11,
            "θ = {theta}: engine ({v_got:?}, {w_got}) vs Routh ({v_ref:?}, {w_ref})"
        );
        // The end leaves slipping the reversed way.
        assert!(rod.point(v_got, w_got).x * s1 > 0.0);
    }
}

/// `impact_friction = none` (the default) leaves the tangential velocity of a frictionless impact
/// untouched, exactly as before issue 16; `coulomb` with μ = 0 is the same algorithm.
#[test]
fn none_and_zero_mu_are_the_frictionless_solver() {
    let rod = Rod::new(45.0);
    let v = Vec2::new(3.0, -1.0);
    let run = |mode: Option<f64>| rod.impact(v, 0.0, 0.5, mode);
    let a = run(None);
    let b = run(Some(0.0));
    assert_eq!(a.0.x.to_bits(), b.0.x.to_bits());
    assert_eq!(a.0.y.to_bits(), b.0.y.to_bits());
    assert_eq!(a.1.to_bits(), b.1.to_bits());
    assert_eq!(
        a.0.x, v.x,
        "frictionless impact changed the tangential velocity"
    );
}

/// `[contact] impact_friction` and `impact_mu` are parsed like every other field: a bad value names
/// the field and the fix, never panics; the defaults keep the frictionless impacts of §7.
#[test]
fn scene_impact_friction_fields_are_checked() {
    use haptic2d::scene::Scene;
    let base = crate::shared::WALL_TOML;
    let err = |contact: &str| {
        let text = format!("[contact]\n{contact}\n{base}");
        crate::shared::scene_errors(&text)
    };
    let e = err("impact_friction = \"cone\"");
    assert!(e.errors.iter().any(|x| x.field == "contact.impact_friction"
        && x.message.contains("none, coulomb")
        && x.fix.contains("coulomb")));
    for bad in ["-0.1", "1e9", "nan"] {
        let e = err(&format!("impact_friction = \"coulomb\"\nimpact_mu = {bad}"));
        assert!(
            e.errors
                .iter()
                .any(|x| x.field == "contact.impact_mu" && x.fix.contains("mu_k")),
            "impact_mu = {bad}: {e}"
        );
    }
    let ok = Scene::from_toml(
        &format!("[contact]\nimpact_mu = 0.3\n{base}"),
        "t.toml",
        None,
    )
    .expect("valid");
    assert!(ok.warnings.iter().any(|w| w.contains("impact_friction")));
    let default = Scene::from_toml(base, "t.toml", None).expect("valid");
    assert_eq!(
        default.world.params.contact.impact_friction,
        ImpactFriction::None
    );
    assert_eq!(default.world.params.contact.impact_mu, None);
}

/// `pile:100` landing with frictional impacts: the ledger excess stays at round-off (the 6e-4 J
/// the stack tests allow) and the fallbacks the energy check took are the ledger's count.
#[test]
fn pile_with_frictional_impacts_stays_passive() {
    let mut w = haptic2d::scene::builtin("pile:100", None)
        .expect("built-in")
        .expect("valid")
        .world;
    w.params.contact.impact_friction = ImpactFriction::Coulomb;
    let mut max_excess = f64::NEG_INFINITY;
    let mut impacts = 0u64;
    for _ in 0..1000 {
        w.step();
        max_excess = max_excess.max(w.ledger().excess());
        impacts += w
            .contacts()
            .events()
            .iter()
            .filter(|e| e.kind == haptic2d::contact::EventKind::Resolved)
            .count() as u64;
    }
    eprintln!(
        "pile:100 coulomb: {impacts} resolved records, max excess {max_excess:e} J, fallbacks {}",
        w.ledger().impact_energy_fallbacks
    );
    assert!(impacts > 100, "the pile did not land");
    assert!(max_excess <= 6e-4, "excess {max_excess} J");
    assert_eq!(
        w.ledger().impact_energy_fallbacks,
        w.contacts().impact_energy_fallbacks()
    );
}
