//! Stability of the delayed teleoperation loop (issue 41 item 4; MODELS §11.5): the
//! delay margin of the linear one-axis model of `network::teleop`, position–force or
//! four-channel, without TDPA.
//!
//! **Model** (x axis, continuous time, Laplace variable `s`). Each device is the lumped
//! twin-pantograph plant of §10.6 along x: apparent inertia `m = 1/(M_x⁻¹)_xx` at the workspace
//! centre (the other axes free, as in [`super::loop_model`]) and the viscous joint friction
//! reflected to the handle, `b = f_v·(J_aᵀJ_a)_xx`; the Coulomb friction, the saturation and the
//! sampling are left out. The hand is a spring–damper `H = K_h + B_h·s` to its (moving) target,
//! the wall `W = K_w + B_w·s` (in contact), the coupling `C = K + B·s`. The round trip `T` is split
//! `T₁` master→slave, `T₂` back; every closed path through the link crosses it both ways, so
//! only `e^{−sT}` appears. With `P_m = m s² + b s + H` and `P_s = m s² + b s + W`:
//!
//! ```text
//! position–force:  Δ(s) = P_m·(P_s + C)  +  C·P_s · e^{−sT}
//! four-channel:    Δ(s) = (P_m + C_m + C6·H)·(P_s + C_s + C5·W)  −  (C_m − C2·W)·(C_s − C3·H) · e^{−sT}
//! ```
//!
//! (position–force: the slave `P_s·X_s = C·(e^{−sT₁}X_m − X_s)`, the master
//! `P_m·X_m = −e^{−sT₂}·C·(e^{−sT₁}X_m − X_s)`; four-channel: the law of
//! `network::four_channel` with `f_h = −H·X_m`, `f_e = W·X_s`; Δ is the determinant of the 2×2
//! system in `(X_m, X_s)`.) Both are `Δ = A(s) + B(s)·e^{−sT}` with `deg B < deg A` (retarded).
//!
//! **Method: the crossing frequencies** (the Nyquist criterion of the loop `L = B/A` with the
//! delay: `L(jω)·e^{−jωT} = −1`). A root of Δ is on the imaginary axis at `s = jω` only if
//! `|A(jω)| = |B(jω)|`; at such an `ω_c` the delays that put it there are
//! `T = (−arg(−A/B) mod 2π + 2πk)/ω_c`. If the undelayed loop `A + B` is Hurwitz, the loop stays
//! stable up to the smallest such `T` (roots of a retarded quasi-polynomial move continuously with
//! `T` and can only reach the right half-plane through the imaginary axis): that `T` is the delay
//! margin, exact for the model. Chosen over a Padé approximation (which adds spurious roots and
//! needs a high order at 50 ms delays) and over Llewellyn's criterion (which certifies absolute
//! stability against *every* passive hand and wall, a sufficient condition, not the margin of this
//! hand and wall). `|A|² − |B|²` is scanned on a logarithmic grid of `ω` and each sign change
//! refined by bisection, together with the positive real roots in `ω²` of the polynomial
//! `|A(jω)|² − |B(jω)|²` (so that two crossings closer than the grid are not missed).

use haptic2d::device::dynamics::LumpedDynamics;
use haptic2d::device::linalg::inv3;
use haptic2d::device::{ObserverKind, TwinPantograph};

use super::eig::{poly_roots, rightmost, Complex};
use crate::network::{Architecture, Teleop};

/// The linear one-axis (x) model of a teleoperation run (SI units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DelayedLoop {
    /// Each device's apparent inertia along x (kg).
    pub m: f64,
    /// Each device's viscous damping along x (N·s/m).
    pub b: f64,
    /// Hand stiffness `K_h` (N/m) and damping `B_h` (N·s/m).
    pub hand: (f64, f64),
    /// Wall stiffness `K_w` (N/m) and damping `B_w` (N·s/m).
    pub wall: (f64, f64),
    /// The architecture and its gains (the x components are used).
    pub arch: Architecture,
    /// Position–force coupling `(K, B)` (N/m, N·s/m).
    pub coupling: (f64, f64),
}

/// The delay margin of a [`DelayedLoop`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DelayMargin {
    /// The largest round trip (s) up to which the loop is stable: 0 if it is unstable without
    /// delay, infinite if no delay destabilises it.
    pub round_trip: f64,
    /// The frequency (rad/s) of the roots that cross at `round_trip` (0 if none).
    pub omega: f64,
    /// The right-most root of the undelayed loop `A + B` (1/s, rad/s).
    pub undelayed: Complex,
}

/// Polynomials, lowest power first.
type Poly = Vec<f64>;

fn mul(a: &[f64], b: &[f64]) -> Poly {
    let mut c = vec![0.0; a.len() + b.len() - 1];
    for (i, x) in a.iter().enumerate() {
        for (j, y) in b.iter().enumerate() {
            c[i + j] += x * y;
        }
    }
    c
}

fn add(a: &[f64], b: &[f64]) -> Poly {
    (0..a.len().max(b.len()))
        .map(|i| a.get(i).unwrap_or(&0.0) + b.get(i).unwrap_or(&0.0))
        .collect()
}

fn scale(a: &[f64], k: f64) -> Poly {
    a.iter().map(|x| x * k).collect()
}

/// `p(jω)` as `(re, im)`.
fn at_jw(p: &[f64], w: f64) -> Complex {
    let (mut re, mut im) = (0.0, 0.0);
    let mut pw = (1.0, 0.0);
    for c in p {
        re += c * pw.0;
        im += c * pw.1;
        pw = (-pw.1 * w, pw.0 * w);
    }
    (re, im)
}

/// `|p(jω)|²` as a polynomial in ω (lowest power first): `Re² + Im²` with
/// `Re = Σ_even (−1)^{k/2}·p_k·ω^k`, `Im = Σ_odd (−1)^{(k−1)/2}·p_k·ω^k`.
fn abs2_jw(p: &[f64]) -> Poly {
    let sign = |k: usize| if (k / 2).is_multiple_of(2) { 1.0 } else { -1.0 };
    let re: Poly = (0..p.len())
        .map(|k| {
            if k.is_multiple_of(2) {
                sign(k) * p[k]
            } else {
                0.0
            }
        })
        .collect();
    let im: Poly = (0..p.len())
        .map(|k| {
            if k.is_multiple_of(2) {
                0.0
            } else {
                sign(k) * p[k]
            }
        })
        .collect();
    add(&mul(&re, &re), &mul(&im, &im))
}

/// The positive real roots `u = ω²` of `|A(jω)|² − |B(jω)|²` (an even polynomial in ω).
fn squared_gap_roots(a: &[f64], b: &[f64]) -> Result<Vec<f64>, String> {
    let r = add(&abs2_jw(a), &scale(&abs2_jw(b), -1.0));
    let mut hi_first: Poly = r.iter().step_by(2).copied().collect();
    while hi_first.last() == Some(&0.0) {
        hi_first.pop();
    }
    hi_first.reverse();
    if hi_first.len() < 2 {
        return Ok(Vec::new());
    }
    Ok(poly_roots(&hi_first)?
        .into_iter()
        .filter(|z| z.0 > 0.0 && z.1.abs() <= 1e-9 * z.0)
        .map(|z| z.0)
        .collect())
}

impl DelayedLoop {
    /// The model of `cfg`'s x axis: its devices at the workspace centre, the simulated grip
    /// (300 N/m, 5 N·s/m), its wall and its architecture.
    pub fn of_teleop(cfg: &Teleop) -> Result<Self, String> {
        let p = &cfg.device;
        let x0 = [p.workspace_center_x, p.workspace_center_y, 0.0];
        let dev = TwinPantograph::new(*p, cfg.dt, ObserverKind::default())?;
        let j = dev
            .jacobian(&x0)
            .map_err(|e| format!("delayed loop: start pose: {e}"))?;
        let mx = LumpedDynamics::new(p).mass_matrix(&j, x0[2]);
        let inv = inv3(&mx).ok_or("delayed loop: the device mass matrix is singular")?;
        let jtj: f64 = j.iter().map(|row| row[0] * row[0]).sum();
        Ok(Self {
            m: 1.0 / inv[0][0],
            b: p.f_v * jtj,
            hand: (300.0, 5.0),
            wall: (cfg.k_wall, cfg.b_wall),
            arch: cfg.architecture,
            coupling: (cfg.k[0], cfg.b[0]),
        })
    }

    /// `(A, B)` of `Δ(s) = A(s) + B(s)·e^{−sT}` (lowest power first; see the module docs).
    pub fn quasi_polynomial(&self) -> (Poly, Poly) {
        let h = vec![self.hand.0, self.hand.1];
        let w = vec![self.wall.0, self.wall.1];
        let pm = vec![self.hand.0, self.b + self.hand.1, self.m];
        let ps = vec![self.wall.0, self.b + self.wall.1, self.m];
        match &self.arch {
            Architecture::PositionForce => {
                let c = vec![self.coupling.0, self.coupling.1];
                (mul(&pm, &add(&ps, &c)), mul(&c, &ps))
            }
            Architecture::FourChannel(g) => {
                let cm = vec![g.k_m[0], g.b_m[0]];
                let cs = vec![g.k_s[0], g.b_s[0]];
                let (c5, c6) = (g.c5[0], g.c6[0]);
                let (c2, c3) = (1.0 + c6, 1.0 + c5);
                let a = mul(
                    &add(&add(&pm, &cm), &scale(&h, c6)),
                    &add(&add(&ps, &cs), &scale(&w, c5)),
                );
                let b = mul(&add(&cm, &scale(&w, -c2)), &add(&cs, &scale(&h, -c3)));
                (a, scale(&b, -1.0))
            }
        }
    }

    /// The delay margin (see the module docs for the method). Errors if the root finder fails.
    pub fn margin(&self) -> Result<DelayMargin, String> {
        let (a, b) = self.quasi_polynomial();
        delay_margin(&a, &b)
    }
}

/// The delay margin of `Δ(s) = A(s) + B(s)·e^{−sT}` (`a`, `b` lowest power first, `deg b < deg a`):
/// the smallest round trip `T` at which a root reaches the imaginary axis, if `A + B` is Hurwitz.
pub fn delay_margin(a: &[f64], b: &[f64]) -> Result<DelayMargin, String> {
    let mut hi_first = add(a, b);
    while hi_first.last() == Some(&0.0) {
        hi_first.pop();
    }
    hi_first.reverse();
    let undelayed = rightmost(&poly_roots(&hi_first)?);
    if undelayed.0 >= 0.0 {
        return Ok(DelayMargin {
            round_trip: 0.0,
            omega: undelayed.1.abs(),
            undelayed,
        });
    }
    let gap = |w: f64| {
        let (pa, pb) = (at_jw(a, w), at_jw(b, w));
        (pa.0 * pa.0 + pa.1 * pa.1).sqrt() - (pb.0 * pb.0 + pb.1 * pb.1).sqrt()
    };
    // Candidate crossing frequencies: sign changes of |A| − |B| on a logarithmic grid (ω from
    // 0.01 to 1e6 rad/s, 200 points a decade), refined by bisection, and, so that a crossing
    // pair closer than the grid is not missed, the positive real roots of the polynomial
    // |A(jω)|² − |B(jω)|² in ω² that satisfy |A| = |B| to 1e-6.
    let grid = |i: usize| 10f64.powf(-2.0 + i as f64 / 200.0);
    let mut candidates = Vec::new();
    for i in 0..1600 {
        let (mut lo, mut hi) = (grid(i), grid(i + 1));
        if gap(lo).signum() == gap(hi).signum() {
            continue;
        }
        for _ in 0..80 {
            let mid = 0.5 * (lo + hi);
            if gap(mid).signum() == gap(lo).signum() {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        candidates.push(0.5 * (lo + hi));
    }
    for u in squared_gap_roots(a, b)? {
        let w = u.sqrt();
        let scale = at_jw(a, w).0.hypot(at_jw(a, w).1);
        if gap(w).abs() <= 1e-6 * scale {
            candidates.push(w);
        }
    }
    let mut best = (f64::INFINITY, 0.0);
    for wc in candidates {
        let (pa, pb) = (at_jw(a, wc), at_jw(b, wc));
        // −A/B = e^{−jωT}: T = −arg(−A/B)/ω modulo 2π/ω, the smallest T ≥ 0.
        let arg = (-pa.1).atan2(-pa.0) - pb.1.atan2(pb.0);
        let t = (-arg).rem_euclid(std::f64::consts::TAU) / wc;
        if t < best.0 {
            best = (t, wc);
        }
    }
    Ok(DelayMargin {
        round_trip: best.0,
        omega: best.1,
        undelayed,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::network::{FourChannel, Impairment};
    use crate::stability::dense::Mat;
    use crate::stability::eig::eigenvalues;

    /// Hayes (1950): `s + a + b·e^{−sT}` with `b > |a|` crosses at `ω = √(b² − a²)` when
    /// `T = arccos(−a/b)/ω`; for `a = 1`, `b = 2`: `ω = √3`, `T = (2π/3)/√3 = 1.2092 s`.
    #[test]
    fn the_margin_of_a_first_order_delayed_loop_is_hayes_closed_form() {
        let d = delay_margin(&[1.0, 1.0], &[2.0]).unwrap();
        let w = 3f64.sqrt();
        assert!((d.omega - w).abs() < 1e-9, "{d:?}");
        assert!((d.round_trip - (-0.5f64).acos() / w).abs() < 1e-9, "{d:?}");
    }

    /// A crossing band far narrower than the grid: `A = s² + 0.02·s + 10⁴` (|A(jω)| has its
    /// minimum 2 at ω = 100 rad/s) against `B = c = 2.0001` leaves `|A| < |B|` only for
    /// `|ω² − 10⁴| < 0.02`, about 1e-4 rad/s wide against the grid's 1.2 rad/s there. Expected,
    /// in closed form: the crossings `u = ω²` solve `(10⁴ − u)² + 4·10⁻⁴·u = c²` (the quadratic
    /// formula), and at each `T = (−arg(−A(jω)/c) mod 2π)/ω`; the margin is the smaller (close to
    /// `(π/2)/100 s`, where `−A/c ≈ −j`).
    #[test]
    fn a_crossing_band_narrower_than_the_grid_is_found() {
        let c = 2.0001f64;
        let d = delay_margin(&[1e4, 0.02, 1.0], &[c]).unwrap();
        let (p, q) = (-2e4 + 4e-4, 1e8 - c * c);
        let disc = (p * p / 4.0 - q).sqrt();
        let t = [-p / 2.0 - disc, -p / 2.0 + disc]
            .map(|u: f64| {
                let w = u.sqrt();
                let arg = (0.02 * w / -c).atan2((1e4 - u) / -c);
                (-arg).rem_euclid(std::f64::consts::TAU) / w
            })
            .into_iter()
            .fold(f64::INFINITY, f64::min);
        assert!((d.omega - 100.0).abs() < 1e-3, "{d:?}");
        assert!((d.round_trip - t).abs() < 1e-6 * t, "{d:?} vs {t}");
    }

    /// `|b| < a`: `|jω + a| > |b|` for every ω, no crossing: stable for every delay.
    #[test]
    fn a_loop_whose_delayed_gain_is_below_its_undelayed_one_is_stable_for_every_delay() {
        let d = delay_margin(&[2.0, 1.0], &[1.0]).unwrap();
        assert!(d.round_trip.is_infinite(), "{d:?}");
        // And a loop unstable without delay has no margin: s − 1 + 0.5.
        let d = delay_margin(&[-1.0, 1.0], &[0.5]).unwrap();
        assert_eq!(d.round_trip, 0.0, "{d:?}");
    }

    /// The state matrix of the undelayed loop written from the equations of motion, the force
    /// laws evaluated by `network::four_channel` (four-channel) or the coupling (position–force):
    /// state `(x_m, v_m, x_s, v_s)`.
    fn equations_of_motion(l: &DelayedLoop) -> Mat {
        let l = *l;
        Mat::from_linear_map(4, move |z| {
            let (xm, vm, xs, vs) = (z[0], z[1], z[2], z[3]);
            let f_h = -l.hand.0 * xm - l.hand.1 * vm;
            let f_e = l.wall.0 * xs + l.wall.1 * vs;
            let v3 = |a: f64| [a, 0.0, 0.0];
            let (f_m, f_s) = match &l.arch {
                Architecture::PositionForce => {
                    let f_c = l.coupling.0 * (xm - xs) + l.coupling.1 * (vm - vs);
                    (-f_c, f_c)
                }
                Architecture::FourChannel(g) => (
                    g.master(&v3(xm), &v3(vm), &v3(f_h), &v3(xs), &v3(vs), &v3(f_e))[0],
                    g.slave(&v3(xs), &v3(vs), &v3(f_e), &v3(xm), &v3(vm), &v3(f_h))[0],
                ),
            };
            vec![
                vm,
                (f_m + f_h - l.b * vm) / l.m,
                vs,
                (f_s - f_e - l.b * vs) / l.m,
            ]
        })
    }

    fn sorted(mut v: Vec<Complex>) -> Vec<Complex> {
        v.sort_by(|a, b| (a.0, a.1).partial_cmp(&(b.0, b.1)).unwrap());
        v
    }

    /// The determinant derivation (module docs) against the equations of motion: without delay
    /// the roots of `A + B` are the eigenvalues of the loop's state matrix, for position–force,
    /// Lawrence's four channels and a local-force-feedback variant (`C6 = −1`, `C5 = 1`).
    #[test]
    fn the_undelayed_quasi_polynomial_has_the_roots_of_the_equations_of_motion() {
        let base = DelayedLoop::of_teleop(&Teleop::new(Impairment::NONE, false)).unwrap();
        let mut lff = FourChannel::lawrence([400.0; 3], [4.0; 3]);
        lff.c6 = [-1.0; 3];
        lff.c5 = [1.0; 3];
        for arch in [
            Architecture::PositionForce,
            Architecture::FourChannel(FourChannel::lawrence([500.0; 3], [5.0; 3])),
            Architecture::FourChannel(lff),
        ] {
            let l = DelayedLoop { arch, ..base };
            let (a, b) = l.quasi_polynomial();
            let mut p = add(&a, &b);
            p.reverse();
            let roots = sorted(poly_roots(&p).unwrap());
            let ev = sorted(eigenvalues(&equations_of_motion(&l)).unwrap());
            assert_eq!(roots.len(), 4, "{arch:?}: {roots:?}");
            for (r, e) in roots.iter().zip(&ev) {
                let tol = 1e-6 * (1.0 + e.0.hypot(e.1));
                assert!(
                    (r.0 - e.0).abs() < tol && (r.1 - e.1).abs() < tol,
                    "{arch:?}: {roots:?} vs {ev:?}"
                );
            }
        }
    }

    /// The analysis against the nonlinear simulation (`network::onset`, position–force, no TDPA,
    /// no loss). Expected: the analysis's margin `T*` for the default run; checked: the onset the
    /// bisection finds in the simulated run, round trips `2·d` ms. The tolerance, from the
    /// model differences: the simulation's round trip moves in steps of 2 ms, and its sampling
    /// adds lag the continuous model does not have — the hold of each actuator's force (half a
    /// period each) and the backward-difference velocity (half a period) — so its onset lies
    /// *below* `T*` by up to 2 ms + 2 ms; Coulomb friction, saturation and contact loss only
    /// dissipate or bound, and cannot bring the onset below that. So: `0 ≤ T* − 2·d_unstable ≤ 4 ms`.
    #[test]
    fn the_position_force_margin_lies_within_4_ms_above_the_simulated_onset() {
        let cfg = Teleop::new(Impairment::NONE, false);
        let t = DelayedLoop::of_teleop(&cfg)
            .unwrap()
            .margin()
            .unwrap()
            .round_trip;
        assert!(t.is_finite() && t > 0.0, "{t}");
        let onset = crate::network::onset::simulated_onset(&cfg, 25)
            .unwrap()
            .unwrap();
        let sim = 2.0 * onset.first_unstable as f64 * cfg.dt;
        assert!(
            (0.0..=4e-3).contains(&(t - sim)),
            "analysis {t} s, simulation {onset:?}"
        );
    }

    /// Lawrence's four channels with the default gains, hand and wall: `|A(jω)| > |B(jω)|` at
    /// every frequency, so no round trip destabilises the loop in contact (the analysis), and the
    /// simulated run without TDPA does not oscillate at 10, 50 or 200 ms (the check).
    #[test]
    fn four_channels_in_contact_are_stable_at_every_round_trip_in_the_analysis_and_the_simulation()
    {
        let base = Teleop::new(Impairment::NONE, false);
        let cfg = Teleop {
            architecture: Architecture::FourChannel(FourChannel::lawrence(base.k, base.b)),
            ..base
        };
        let d = DelayedLoop::of_teleop(&cfg).unwrap().margin().unwrap();
        assert!(d.round_trip.is_infinite(), "{d:?}");
        for delay in [5, 25, 100] {
            assert!(
                !crate::network::onset::oscillates(&cfg, delay).unwrap(),
                "{delay}"
            );
        }
        // The same check sees position–force oscillate at 50 ms.
        assert!(crate::network::onset::oscillates(&base, 25).unwrap());
    }
}
