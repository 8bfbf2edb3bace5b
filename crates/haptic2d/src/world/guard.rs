//! The optional passivity guard's share of the step (§6.5, §0.5 step 11): the kinetic energy before
//! the impacts and the force it integrates, per body, around [`PassivityGuard`].

use crate::body::Body;
use crate::contact::Wrench2;
use crate::integrate::PassivityGuard;

/// The passivity guard (if the scene asks for it) and what it needs of each sample.
#[derive(Clone, Debug)]
pub(super) struct GuardStage {
    /// The guard; `None` = off.
    pub(super) guard: Option<PassivityGuard>,
    /// Kinetic energy per body before the contact step (J), to book impulses as input.
    ke_before: Vec<f64>,
    /// Force and torque the guard integrates, per body (pre-integration velocity).
    force: Vec<Wrench2>,
}

impl GuardStage {
    /// The guard with tolerance `epsilon` (J; `None` = off) for `bodies`.
    pub(super) fn new(epsilon: Option<f64>, bodies: &[Body]) -> Self {
        Self {
            guard: epsilon.map(|eps| PassivityGuard::new(eps, bodies)),
            ke_before: vec![0.0; bodies.len()],
            force: vec![Wrench2::default(); bodies.len()],
        }
    }

    /// Before the contact step: each body's kinetic energy (only with the guard on).
    pub(super) fn before_contacts(&mut self, bodies: &[Body]) {
        if self.guard.is_some() {
            for (k, b) in self.ke_before.iter_mut().zip(bodies) {
                *k = b.kinetic_energy();
            }
        }
    }

    /// After the impacts: an impulse changes a body's energy without a held force; count that
    /// change as the body's input, so the guard checks the integrator alone (impacts only lower
    /// the total, §7).
    pub(super) fn after_impacts(&mut self, bodies: &[Body]) {
        if let Some(g) = self.guard.as_mut() {
            for (i, b) in bodies.iter().enumerate() {
                g.add_input(i, b.kinetic_energy() - self.ke_before[i]);
            }
        }
    }

    /// Remembers the force body `i` is integrated under (its damping at the pre-integration
    /// velocity included).
    #[inline]
    pub(super) fn remember(&mut self, i: usize, b: &Body) {
        self.force[i] = Wrench2 {
            force: b.force - b.vel * b.damping,
            torque: b.torque,
        };
    }

    /// After the integration: books the work of body `i`'s integrated force over its motion
    /// `(dx, dth)` (m, rad) and checks it against its budget.
    #[inline]
    pub(super) fn check(&mut self, i: usize, body: &mut Body, dx: crate::geom::Vec2, dth: f64) {
        if let Some(g) = self.guard.as_mut() {
            let f = self.force[i];
            g.add_input(i, f.force.dot(dx) + f.torque * dth);
            g.check(i, body);
        }
    }
}
