//! Goldfarb–Wang hysteretic wall: a spring in parallel with elasto-slide (Maxwell-slip) elements
//! (§5.8, [REC]).

use super::{NormalInput, NormalLaw};

crate::law_params! { HystereticLaw, "hysteretic";
    k0 (self.k0) [] "N/m" NonNegative "spring in parallel with the elements",
    k1 (self.elements[0].k) [] "N/m" NonNegative "element 1 spring",
    k2 (self.elements[1].k) [] "N/m" NonNegative "element 2 spring",
    k3 (self.elements[2].k) [] "N/m" NonNegative "element 3 spring",
    k4 (self.elements[3].k) [] "N/m" NonNegative "element 4 spring",
    f1 (self.elements[0].f) [] "N" NonNegative "element 1 block friction",
    f2 (self.elements[1].f) [] "N" NonNegative "element 2 block friction",
    f3 (self.elements[2].f) [] "N" NonNegative "element 3 block friction",
    f4 (self.elements[3].f) [] "N" NonNegative "element 4 block friction",
    m1 (self.elements[0].m) [] "kg" NonNegative "element 1 block mass (0 = massless)",
    m2 (self.elements[1].m) [] "kg" NonNegative "element 2 block mass (0 = massless)",
    m3 (self.elements[2].m) [] "kg" NonNegative "element 3 block mass (0 = massless)",
    m4 (self.elements[3].m) [] "kg" NonNegative "element 4 block mass (0 = massless)",
}

/// Most elasto-slide elements one wall can carry (fixed, so the law stays `Copy` and allocation-free).
pub const MAX_ELEMENTS: usize = 4;
// The parameter declarations below name elements 1–4 one by one.
const _: () = assert!(MAX_ELEMENTS == 4);

/// Karnopp stick threshold for blocks with mass (m/s).
pub const BLOCK_STICK_SPEED: f64 = 1e-4;

/// One elasto-slide element: a spring `k` from the surface point to a block held by Coulomb friction
/// `f`, optionally with mass `m`. An element with `k = 0` is unused.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SlideElement {
    /// Element spring stiffness `k_i` (N/m).
    pub k: f64,
    /// Block Coulomb friction level `f_i` (N).
    pub f: f64,
    /// Block mass `m_i` (kg); 0 = massless block (default).
    pub m: f64,
    /// Block position `b_i` in the penetration coordinate (m).
    b: f64,
    /// Block velocity `ḃ_i` (m/s); used only with mass.
    b_dot: f64,
}

impl SlideElement {
    /// A massless element of stiffness `k` (N/m) and slip force `f` (N).
    pub fn new(k: f64, f: f64) -> Self {
        Self {
            k,
            f,
            ..Self::default()
        }
    }

    /// Updates the block for penetration `delta` (m) and returns the element deflection `z = δ − b` (m).
    #[inline]
    fn update(&mut self, delta: f64, dt: f64) -> f64 {
        if self.k <= 0.0 {
            return 0.0;
        }
        if self.m > 0.0 {
            // Block with mass: m·b̈ = k·z − f·sgn(ḃ), semi-implicit Euler, Karnopp stick detection.
            let spring = self.k * (delta - self.b);
            let friction = if self.b_dot.abs() < BLOCK_STICK_SPEED {
                if spring.abs() <= self.f {
                    spring // stuck: friction balances the spring
                } else {
                    self.f * spring.signum() // breaks away
                }
            } else {
                self.f * self.b_dot.signum()
            };
            let v_old = self.b_dot;
            let mut v_new = v_old + dt * (spring - friction) / self.m;
            // Friction cannot reverse the motion: a sign change or a crawl below the threshold is a stick.
            if (v_old != 0.0 && v_new * v_old < 0.0) || v_new.abs() < BLOCK_STICK_SPEED {
                v_new = 0.0;
            }
            self.b_dot = v_new;
            self.b += dt * v_new;
            delta - self.b
        } else {
            // Massless block: it slips just enough to keep |k·z| ≤ f.
            let z_max = self.f / self.k;
            let z = delta - self.b;
            if z.abs() > z_max {
                self.b = delta - z.signum() * z_max;
                z.signum() * z_max
            } else {
                z
            }
        }
    }
}

/// Hysteretic wall: `F_w,k = max(0, k0·δ_k + Σ k_i·z_i)`. When `δ_k = 0` every block relaxes to 0.
///
/// Loading stiffness is `k0 + Σk_i`; unloading follows another path. Each cycle deeper than the slip
/// deflections `f_i/k_i` dissipates `Σ f_i·(slip distance of block i)`; below them the wall is elastic.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HystereticLaw {
    /// Parallel linear spring `k0` (N/m).
    pub k0: f64,
    /// Elasto-slide elements (unused slots have `k = 0`).
    pub elements: [SlideElement; MAX_ELEMENTS],
    /// Stored energy after the last sample (J): springs plus block kinetic energy.
    stored: f64,
}

impl HystereticLaw {
    /// A wall with spring `k0` (N/m) and the massless elements `(k_i N/m, f_i N)` (at most
    /// [`MAX_ELEMENTS`]; extra ones are an error).
    pub fn new(k0: f64, elements: &[(f64, f64)]) -> Result<Self, String> {
        if elements.len() > MAX_ELEMENTS {
            return Err(format!(
                "hysteretic: at most {MAX_ELEMENTS} elements, got {}",
                elements.len()
            ));
        }
        let mut law = Self {
            k0,
            elements: [SlideElement::default(); MAX_ELEMENTS],
            stored: 0.0,
        };
        for (slot, &(k, f)) in law.elements.iter_mut().zip(elements) {
            *slot = SlideElement::new(k, f);
        }
        Ok(law)
    }
    /// 1-D defaults: `k0 = 1000 N/m`, elements `(500 N/m, 0.5 N)` and `(500 N/m, 1.0 N)`.
    pub fn one_d() -> Self {
        let mut elements = [SlideElement::default(); MAX_ELEMENTS];
        elements[0] = SlideElement::new(500.0, 0.5);
        elements[1] = SlideElement::new(500.0, 1.0);
        Self {
            k0: 1000.0,
            elements,
            stored: 0.0,
        }
    }
    /// Per-contact defaults (halved): `k0 = 500 N/m`, elements `(250 N/m, 0.25 N)`, `(250 N/m, 0.5 N)`.
    pub fn per_contact() -> Self {
        let mut l = Self::one_d();
        l.k0 *= 0.5;
        for e in &mut l.elements {
            e.k *= 0.5;
            e.f *= 0.5;
            e.m *= 0.5;
        }
        l
    }
    /// The same wall with every block given mass `m` (kg) (0 = massless).
    pub fn with_block_mass(mut self, m: f64) -> Self {
        for e in &mut self.elements {
            e.m = m;
        }
        self
    }
    /// Loading stiffness `k0 + Σk_i` (N/m).
    pub fn loading_stiffness(&self) -> f64 {
        self.k0 + self.elements.iter().map(|e| e.k).sum::<f64>()
    }
    /// Block positions `b_i` (m).
    pub fn block_positions(&self) -> [f64; MAX_ELEMENTS] {
        let mut b = [0.0; MAX_ELEMENTS];
        for (out, e) in b.iter_mut().zip(&self.elements) {
            *out = e.b;
        }
        b
    }
}

impl NormalLaw for HystereticLaw {
    fn reset(&mut self) {
        for e in &mut self.elements {
            e.b = 0.0;
            e.b_dot = 0.0;
        }
        self.stored = 0.0;
    }
    #[inline(always)]
    fn force(&mut self, input: &NormalInput) -> f64 {
        let delta = input.depth();
        if delta <= 0.0 {
            // The wall relaxes.
            self.reset();
            return 0.0;
        }
        let mut f = self.k0 * delta;
        let mut stored = 0.5 * self.k0 * delta * delta;
        for e in &mut self.elements {
            let z = e.update(delta, input.dt);
            f += e.k * z;
            stored += 0.5 * e.k * z * z + 0.5 * e.m * e.b_dot * e.b_dot;
        }
        self.stored = stored;
        f.max(0.0)
    }
    fn stored_energy(&self) -> f64 {
        self.stored
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(delta: f64) -> NormalInput {
        NormalInput {
            d: [-delta; 3],
            hist: 3,
            c0: 0.0,
            dt: 0.002,
            m_eff: 0.5,
        }
    }

    #[test]
    fn blocks_with_mass_follow_the_massless_path_and_stick() {
        // Blocks of 10 g (k·T²/m = 0.2, well inside the semi-implicit stability bound 4).
        let mut massless = HystereticLaw::one_d();
        let mut heavy = HystereticLaw::one_d().with_block_mass(0.01);
        // Slow ramp to 4 mm over 2 s, then hold 0.4 s.
        let n = 1000;
        let (mut f0, mut f1) = (0.0, 0.0);
        for i in 1..=n + 200 {
            let delta = 0.004 * (i.min(n) as f64) / n as f64;
            f0 = massless.force(&at(delta));
            f1 = heavy.force(&at(delta));
        }
        assert!((f0 - 5.5).abs() < 1e-12);
        assert!((f1 - f0).abs() < 0.05, "massive {f1} vs massless {f0}");
        // Stuck at rest, each element within its friction bound.
        for e in &heavy.elements {
            assert_eq!(e.b_dot, 0.0);
            assert!(e.k * (0.004 - e.b).abs() <= e.f + 1e-9);
        }
        // Unloading by 0.5 mm is elastic for both.
        let g0 = massless.force(&at(0.0035));
        let g1 = heavy.force(&at(0.0035));
        // 3.5 + 500·0.0005 + 500·0.0015 = 4.5 N.
        assert!((g0 - 4.5).abs() < 1e-12);
        assert!((g1 - g0).abs() < 0.05, "massive {g1} vs massless {g0}");
    }
}
