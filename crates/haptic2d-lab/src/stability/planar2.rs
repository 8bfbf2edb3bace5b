//! The 2-DOF form of the stability analysis (issue 12 item 3, task L item 4): a five-bar such as a
//! Haply 2DIY holding the slave at a grasp point, per axis x and y, with the hand held and released.
//! The same per-axis loop ([`AxisModel`]) as the twin's, with the five-bar's numbers:
//!
//! ```text
//! joint inertia I_j per motor, end-point mass m_e, joint viscous friction b (N·m·s/rad)
//! M_x = I_j·(J·Jᵀ)⁻¹ + m_e·1      (T = ½ I_j |q̇|² + ½ m_e |Ė|², q̇ = J⁻¹·Ė)
//! B_x = b·(J·Jᵀ)⁻¹                (τ = b·q̇ seen at the end point, f = J⁻ᵀ·τ)
//! m_i = 1 / (M_x⁻¹)_ii            (the apparent inertia along axis i, the other axis free)
//! ```
//!
//! at the workspace centre; no hand-wrench estimate on a 2DIY (`f̂_h = 0` as in `Planar2System`:
//! the controller's hand-force paths are cut); velocity filter of `Planar2Config` (50 Hz).

use haptic2d::device::pantograph2::Pantograph2;
use haptic2d::geom::Vec2;
use haptic2d::haptic::ControllerKind;
use haptic2d::world::World;

use super::axis::AxisModel;
use super::loop_model::{
    axis_controller, AxisReport, Environment, Verdict, AXES, GRIP_DAMPING, GRIP_STIFFNESS,
};

/// Gain of the model's (decoupled, unused) hand-wrench observer (1/s).
const DECOUPLED_OBSERVER_GAIN: f64 = 50.0;

/// Lumped dynamics of a five-bar (the emulator's `Plant2` uses the same three numbers).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FiveBarDynamics {
    /// Joint inertia per motor, rotor + proximal link (kg·m²).
    pub i_j: f64,
    /// End-point mass: handle + distal links (kg).
    pub m_e: f64,
    /// Viscous joint friction (N·m·s/rad).
    pub b: f64,
}

/// Analyses the x and y axes of `linkage` (dynamics `dyn_`) at handle point `at` (m, board frame)
/// driving the first dynamic body of `world` with `controller` at `rate` (Hz), `delay` extra output
/// samples, against each spring of the scene's stiffest contact (per axis the worse is kept).
pub fn analyse_planar2(
    linkage: &Pantograph2,
    dyn_: &FiveBarDynamics,
    at: Vec2,
    controller: &ControllerKind,
    world: &World,
    rate: f64,
    delay: usize,
) -> Result<[AxisReport; 2], String> {
    let (slave, dt) = slave_and_period(world, rate)?;
    let q = linkage
        .ik(at)
        .map_err(|e| format!("stability: handle point ({}, {}) m: {e}", at.x, at.y))?;
    let j = linkage.state(q).map_err(|e| format!("stability: {e}"))?.j;
    // (J·Jᵀ)⁻¹, 2×2.
    let a = [
        [
            j[0][0] * j[0][0] + j[0][1] * j[0][1],
            j[0][0] * j[1][0] + j[0][1] * j[1][1],
        ],
        [0.0, j[1][0] * j[1][0] + j[1][1] * j[1][1]],
    ];
    let det = a[0][0] * a[1][1] - a[0][1] * a[0][1];
    if !(det.is_finite() && det > 0.0) {
        return Err("stability: the five-bar is singular at the handle point".into());
    }
    let w = [
        [a[1][1] / det, -a[0][1] / det],
        [-a[0][1] / det, a[0][0] / det],
    ];
    let m_x = [
        [dyn_.i_j * w[0][0] + dyn_.m_e, dyn_.i_j * w[0][1]],
        [dyn_.i_j * w[0][1], dyn_.i_j * w[1][1] + dyn_.m_e],
    ];
    let dm = m_x[0][0] * m_x[1][1] - m_x[0][1] * m_x[0][1];
    // 1/(M_x⁻¹)_ii: (M_x⁻¹)_00 = M_11/det, (M_x⁻¹)_11 = M_00/det.
    let m_app = [dm / m_x[1][1], dm / m_x[0][0]];
    let b_app = [dyn_.b * w[0][0], dyn_.b * w[1][1]];
    analyse_axes(m_app, b_app, slave, controller, world, dt, delay)
}

/// Analyses the x and y axes of a Cartesian point device (the handle point in, a force out, no
/// linkage: the Haply Inverse3 in planar mode) whose handle has apparent mass `mass` (kg) and
/// viscous damping `damping` (N·s/m) along each axis, as [`analyse_planar2`] does a five-bar's
/// (whose apparent mass and damping it computes from the linkage first).
pub fn analyse_point(
    mass: f64,
    damping: f64,
    controller: &ControllerKind,
    world: &World,
    rate: f64,
    delay: usize,
) -> Result<[AxisReport; 2], String> {
    let (slave, dt) = slave_and_period(world, rate)?;
    if !(mass.is_finite() && mass > 0.0 && damping.is_finite() && damping >= 0.0) {
        return Err(format!(
            "stability: the point device's mass {mass} kg must be > 0 and its damping {damping} N·s/m ≥ 0"
        ));
    }
    analyse_axes([mass; 2], [damping; 2], slave, controller, world, dt, delay)
}

/// The body a 2-DOF device drives (the first dynamic one) and the period (s) of `rate` (Hz), or
/// why the analysis cannot run.
fn slave_and_period(world: &World, rate: f64) -> Result<(usize, f64), String> {
    if !(rate.is_finite() && rate > 0.0) {
        return Err(format!("stability: the rate must be > 0 Hz (got {rate})"));
    }
    let slave = world
        .bodies
        .iter()
        .position(|b| b.is_dynamic())
        .ok_or("stability: the scene has no dynamic body for the device to drive")?;
    Ok((slave, 1.0 / rate))
}

/// The per-axis loops of a 2-DOF device of apparent masses `m_app` (kg) and damping `b_app`
/// (N·s/m) per axis holding body `slave` of `world`, at period `dt` (s) with `delay` extra output
/// samples, against each spring of the scene's stiffest contact (per axis the worse is kept).
fn analyse_axes(
    m_app: [f64; 2],
    b_app: [f64; 2],
    slave: usize,
    controller: &ControllerKind,
    world: &World,
    dt: f64,
    delay: usize,
) -> Result<[AxisReport; 2], String> {
    let body = &world.bodies[slave];
    let env = Environment::of_world(world, slave);
    let mut out: Vec<AxisReport> = Vec::with_capacity(2);
    for i in 0..2 {
        let mut worst: Option<AxisReport> = None;
        for (name, spring) in env.springs() {
            let (k_e, b_e) = env.axis(i, spring);
            // No hand-wrench estimate on a 2DIY: the controller's f̂_h paths are cut (g_mh = g_sh =
            // 0, exactly what f_h = 0 does in Planar2System). The model's observer then drives
            // nothing; a positive gain lets its decoupled mode decay instead of sitting at |λ| = 1.
            let mut ctrl = axis_controller(controller, i);
            ctrl.g_mh = 0.0;
            ctrl.g_sh = 0.0;
            let m = AxisModel {
                m: m_app[i],
                b: b_app[i],
                k_h: GRIP_STIFFNESS[i],
                b_h: GRIP_DAMPING[i],
                m_s: body.mass,
                k_e,
                b_e,
                ctrl,
                k_o: DECOUPLED_OBSERVER_GAIN,
                velocity_cutoff_hz: 50.0,
            };
            AxisReport::analyse(AXES[i], name, m, dt, delay)?.keep_if_worse(&mut worst);
        }
        out.extend(worst);
    }
    out.try_into()
        .map_err(|_| "stability: two axes expected".to_string())
}

/// The gate `haptic2d run` applies before driving a real 2-DOF device: `Err` naming the axis and the
/// fix when an axis grows with the hand released (one extra output sample, as for the twin).
pub fn check_released_stability_planar2(
    linkage: &Pantograph2,
    dyn_: &FiveBarDynamics,
    at: Vec2,
    controller: &ControllerKind,
    world: &World,
) -> Result<(), String> {
    let rate = 1.0 / world.params.dt;
    refuse_unstable_released(
        analyse_planar2(linkage, dyn_, at, controller, world, rate, 1)?,
        controller,
        rate,
    )
}

/// The same gate for a point device of handle mass `mass` (kg) and damping `damping` (N·s/m)
/// ([`analyse_point`]).
pub fn check_released_stability_point(
    mass: f64,
    damping: f64,
    controller: &ControllerKind,
    world: &World,
) -> Result<(), String> {
    let rate = 1.0 / world.params.dt;
    refuse_unstable_released(
        analyse_point(mass, damping, controller, world, rate, 1)?,
        controller,
        rate,
    )
}

/// `Err` naming the first axis of `axes` that grows with the hand released, and the fix.
fn refuse_unstable_released(
    axes: [AxisReport; 2],
    controller: &ControllerKind,
    rate: f64,
) -> Result<(), String> {
    for a in axes {
        if a.verdict() == Verdict::UnstableReleased {
            return Err(format!(
                "the {} controller is unstable on axis {} of the 2-DOF device with the hand released (sampled growth {:+.1} 1/s at {rate} Hz): a released handle would oscillate with growing amplitude. Fix: use `--controller four-channel` or `coupling`, check with `haptic2d stability --device-file FILE`, or pass --allow-unstable to override",
                controller.name(),
                a.axis,
                a.released.growth,
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn box_in_walls() -> World {
        haptic2d::scene::builtin("box-in-walls", Some(1000.0))
            .unwrap()
            .unwrap()
            .world
    }

    /// The module's `M_x = I_j·(J·Jᵀ)⁻¹ + m_e·1`, `B_x = b·(J·Jᵀ)⁻¹` with `I_j = b = 0` is the point
    /// mass `m_e` with no damping on each axis, wherever the linkage stands: the point device's
    /// analysis is that five-bar's.
    #[test]
    fn a_point_device_is_a_five_bar_without_joint_inertia_or_friction() {
        let world = box_in_walls();
        let c = ControllerKind::default();
        let point = analyse_point(0.05, 0.0, &c, &world, 1000.0, 1).unwrap();
        let linkage = Pantograph2::new(0.038, 0.07, 0.09).unwrap();
        let bare = FiveBarDynamics {
            i_j: 0.0,
            m_e: 0.05,
            b: 0.0,
        };
        let bar = analyse_planar2(
            &linkage,
            &bare,
            Vec2::new(0.019, 0.10),
            &c,
            &world,
            1000.0,
            1,
        )
        .unwrap();
        for (p, f) in point.iter().zip(&bar) {
            assert_eq!((p.model.m, p.model.b), (0.05, 0.0));
            assert!((f.model.m - 0.05).abs() < 1e-15 && f.model.b == 0.0);
            assert!((p.released.growth - f.released.growth).abs() < 1e-9);
        }
    }

    /// What `GATE_DYNAMICS` of the Inverse3 relies on: whatever the gate refuses for the heavier,
    /// damped emulator handle (0.2 kg, 1 N·s/m) it refuses for the lighter, undamped one
    /// (0.03 kg): over the named controllers and virtual couplings of rising damping, a released
    /// axis that grows with the heavy handle grows with the light one.
    #[test]
    fn the_gate_refuses_for_a_light_undamped_point_handle_whatever_it_refuses_for_a_heavy_one() {
        use haptic2d::control::coupling::CouplingGains;
        let world = box_in_walls();
        let mut kinds: Vec<ControllerKind> = ["coupling", "four-channel", "four-channel-spec"]
            .iter()
            .map(|n| ControllerKind::from_name(n).unwrap())
            .collect();
        for b in [1.0, 5.0, 10.0, 20.0, 40.0, 80.0] {
            kinds.push(ControllerKind::Coupling(CouplingGains {
                k: [500.0, 500.0, 1.0],
                b: [b, b, 0.01],
            }));
        }
        let (mut refused_light, mut refused_heavy) = (0, 0);
        for c in &kinds {
            let light = analyse_point(0.03, 0.0, c, &world, 1000.0, 1).unwrap();
            let heavy = analyse_point(0.2, 1.0, c, &world, 1000.0, 1).unwrap();
            for (l, h) in light.iter().zip(&heavy) {
                let unstable = |r: &AxisReport| r.verdict() == Verdict::UnstableReleased;
                refused_light += unstable(l) as u32;
                refused_heavy += unstable(h) as u32;
                assert!(
                    unstable(l) || !unstable(h),
                    "{c:?} axis {}: light {} 1/s, heavy {} 1/s",
                    l.axis,
                    l.released.growth,
                    h.released.growth
                );
            }
        }
        // Not vacuous: the spec's gains at least are refused for the light handle.
        assert!(refused_light > 0, "{refused_light} {refused_heavy}");
        assert!(analyse_point(0.0, 0.0, &ControllerKind::default(), &world, 1000.0, 1).is_err());
    }
}
