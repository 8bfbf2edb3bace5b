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
    axis_controller, AxisReport, Environment, LoopPoles, Verdict, AXES, GRIP_DAMPING,
    GRIP_STIFFNESS,
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
    if !(rate.is_finite() && rate > 0.0) {
        return Err(format!("stability: the rate must be > 0 Hz (got {rate})"));
    }
    let dt = 1.0 / rate;
    let slave = world
        .bodies
        .iter()
        .position(|b| b.is_dynamic())
        .ok_or("stability: the scene has no dynamic body for the device to drive")?;
    let body = &world.bodies[slave];
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
                b: dyn_.b * w[i][i],
                k_h: GRIP_STIFFNESS[i],
                b_h: GRIP_DAMPING[i],
                m_s: body.mass,
                k_e,
                b_e,
                ctrl,
                k_o: DECOUPLED_OBSERVER_GAIN,
                velocity_cutoff_hz: 50.0,
            };
            let r = AxisReport {
                axis: AXES[i],
                contact: name,
                model: m,
                held: LoopPoles::of(&m, dt, delay)?,
                released: LoopPoles::of(&m.released(), dt, delay)?,
            };
            let worse = worst.as_ref().is_none_or(|w| {
                r.released.growth.max(r.held.growth) > w.released.growth.max(w.held.growth)
            });
            if worse {
                worst = Some(r);
            }
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
    for a in analyse_planar2(linkage, dyn_, at, controller, world, rate, 1)? {
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
