//! Salcudean–Vlaar modified Karnopp friction (1997), per VE contact (§4.2).
//!
//! In stick a PD controller holds the vertex at a stick point `s_a`:
//! `F_t = −K_p·(s − s_a) − K_d·S0`, as long as `|F_t| ≤ μs·F_n`. Beyond that the contact breaks away;
//! it re-sticks (with a new stick point at the current `s`) as soon as `|S0| < v_th`. In slip the force
//! is Coulomb plus viscous: `F_t = −μk·F_n·sgn(S0) − b_v·S0`.

use super::shell::{engage, friction_law, LoadedFriction};
use super::{FrictionInput, FrictionMode};

crate::declare_law! {
    /// Salcudean–Vlaar friction (§4.2). Parameters are public; the state (`s_a`, mode) is private.
    pub struct SalcudeanVlaar as "friction model 'salcudean-vlaar'" {
        /// Stick-point spring `K_p` (N/m).
        k_p: f64 [] "N/m" Positive "stick PD stiffness",
        /// Stick damping `K_d` (N·s/m).
        k_d: f64 [] "N·s/m" NonNegative "stick PD damping",
        /// Viscous friction in slip, `b_v` (N·s/m).
        b_v: f64 [] "N·s/m" NonNegative "viscous friction",
        /// Re-stick velocity threshold `v_th` (m/s).
        v_th: f64 [] "m/s" Positive "stick velocity threshold",
        /// Static friction coefficient `μs` (dimensionless).
        mu_s: f64 [] "" Positive "static friction coefficient (≥ mu_k)",
        /// Kinetic friction coefficient `μk` (dimensionless).
        mu_k: f64 [] "" Positive "kinetic friction coefficient",
    }
    state {
        /// Stick-point edge coordinate `s_a` (m, in the edge body's frame).
        s_a: f64 = 0.0,
        /// Whether `s_a` holds a valid stick point; if not, the next loaded update sticks at the current `s`.
        engaged: bool = false,
        /// Stick or slip.
        mode: FrictionMode = FrictionMode::Stick,
        /// Stick-spring offset `s − s_a` after the last update (m); 0 in slip.
        offset: f64 = 0.0,
    }
    /// A model with gains `K_p` (N/m), `K_d` (N·s/m), `b_v` (N·s/m), band `v_th` (m/s), `μs`, `μk`.
    pub fn new;
}

impl SalcudeanVlaar {
    /// 1-D defaults (§4.2 table): `K_p = 3000 N/m`, `K_d = 15 N·s/m`, `b_v = 2 N·s/m`, `v_th = 0.01 m/s`,
    /// `μs = 0.5`, `μk = 0.45`.
    pub fn one_d() -> Self {
        Self::new(3000.0, 15.0, 2.0, 0.01, 0.5, 0.45)
    }
    /// Per-contact defaults of the 2-D peg (§4.2 table): `K_p = 1500`, `K_d = 7.5`, `b_v = 1`, `v_th = 0.01`.
    pub fn per_contact() -> Self {
        Self::new(1500.0, 7.5, 1.0, 0.01, 0.5, 0.45)
    }
}

friction_law!(SalcudeanVlaar);

impl LoadedFriction for SalcudeanVlaar {
    fn forget(&mut self) {
        self.engaged = false;
        self.offset = 0.0;
    }

    /// Sticks at the god-object's entry point.
    fn start(&mut self, s_entry: f64) {
        engage(&mut self.s_a, &mut self.engaged, &mut self.mode, s_entry);
    }

    #[inline(always)]
    fn loaded(&mut self, i: &FrictionInput) -> f64 {
        // Loaded again after a release (or never begun): anchor where the vertex is now.
        engage(&mut self.s_a, &mut self.engaged, &mut self.mode, i.s);
        if self.mode == FrictionMode::Stick {
            let offset = i.s - self.s_a;
            let f = -self.k_p * offset - self.k_d * i.s0;
            if f.abs() <= self.mu_s * i.fn_ {
                self.offset = offset;
                return f;
            }
            self.mode = FrictionMode::Slip; // break away; fall through
        }
        if i.s0.abs() < self.v_th {
            // re-stick at the current position
            self.mode = FrictionMode::Stick;
            self.s_a = i.s;
            self.offset = 0.0;
            return -self.k_d * i.s0;
        }
        self.offset = 0.0;
        -self.mu_k * i.fn_ * i.s0.signum() - self.b_v * i.s0 // Coulomb + viscous
    }

    /// `½·K_p·(s − s_a)²` in stick, 0 in slip (J): the U_f of §13.2 F7-5.
    fn spring_energy(&self) -> f64 {
        0.5 * self.k_p * self.offset * self.offset
    }

    /// The stick point `s_a` (§8.3), once engaged.
    fn stick_point(&self, _s: f64) -> Option<f64> {
        self.engaged.then_some(self.s_a)
    }
}
