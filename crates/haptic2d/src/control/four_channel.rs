//! Lawrence's four-channel teleoperation controller with a virtual slave (§11.1), with the local
//! force-feedback blocks C5 (slave) and C6 (master) and optional acceleration feedforwards.
//!
//! With `C_m = B_m + K_m/s`, `C_s = B_s + K_s/s`, the transparency choices `C1 = Z_s + C_s`,
//! `C2 = 1 + C6`, `C3 = 1 + C5`, `C4 = −(Z_m + C_m)` turn
//! `f_cm = −C_m·v_m − C4·v_s + C6·f_h − C2·f_e` and `f_cs = −C_s·v_s + C1·v_m + C3·f_h − C5·f_e` into
//!
//! ```text
//! f_cm = K_m·(x_s − x_m) + B_m·(v_s − v_m) + C6·f_h − (1 + C6)·f_e − D_m·v_m  [+ M̂_x·a_s]
//! f_cs = K_s·(x_m − x_s) + B_s·(v_m − v_s) + (1 + C5)·f_h − C5·f_e − D_s·v_s  [+ M_s·â_m]
//! ```
//!
//! (`C1`, `C4` are the PD blocks `(K_s, B_s)`, `(K_m, B_m)` plus the optional mass feedforwards;
//! `C2`, `C3` may be overridden, [`FourChannelGains::c2`], [`FourChannelGains::c3`], at the price of
//! transparency.)
//!
//! which with `C5 = C6 = 0`, `D_m = 0` is the spec's discrete law ([`FourChannelGains::spec`]). The
//! default is [`FourChannelGains::local_force_feedback`] (`C6 = −1`, `C5 = 2`, a small damping
//! injection), stable with the hand released (§11.4; see its derivation). All gains are diagonal (per DOF
//! x, y, θ); θ position errors are wrapped to `(−π, π]`.

use serde::{Deserialize, Serialize};

use crate::device::linalg::{m3_mul_v, M3, V3};
use crate::device::lowpass::LowPass2;
use crate::geom::wrap_angle;

/// The signals a teleoperation controller sees at sample `k` (3-vectors over x, y, θ).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TeleopSignals {
    /// Device (master) pose `x_m,k` (m, m, rad).
    pub x_m: V3,
    /// Filtered device twist `v̂_m,k` (m/s, m/s, rad/s).
    pub v_m: V3,
    /// Estimated hand wrench `Ŵ_h,k` (N, N, N·m).
    pub f_h: V3,
    /// Slave pose `x_s,k` (m, m, rad).
    pub x_s: V3,
    /// Post-impulse slave twist `v_s,k⁺` (m/s, m/s, rad/s).
    pub v_s: V3,
    /// Wrench the slave applies to the environment `f_e,k` (N, N, N·m): minus the sum of contact
    /// wrenches on the slave, at this sample.
    pub f_e: V3,
    /// Device mass matrix estimate `M̂_x` (kg, kg·m, kg·m²); only read by the master feedforward.
    pub master_mass: M3,
}

/// Position error `x_a − x_b` with the θ component wrapped.
#[inline]
pub fn pose_error(x_a: &V3, x_b: &V3) -> V3 {
    [
        x_a[0] - x_b[0],
        x_a[1] - x_b[1],
        wrap_angle(x_a[2] - x_b[2]),
    ]
}

/// Four-channel gains and options. The default is [`FourChannelGains::local_force_feedback`]; the
/// §11.1 table is [`FourChannelGains::spec`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FourChannelGains {
    /// Master position gain `K_m` (N/m, N/m, N·m/rad). Default (500, 500, 0.5) (spec: θ 1.0).
    pub k_m: V3,
    /// Master damping `B_m` (N·s/m, N·s/m, N·m·s/rad). Default (5, 5, 0.002) (spec: θ 0.01).
    pub b_m: V3,
    /// Slave position gain `K_s` (N/m, N/m, N·m/rad). Default (2000, 2000, 1.0) (spec: θ 4).
    pub k_s: V3,
    /// Slave damping `B_s` (N·s/m, N·s/m, N·m·s/rad). Default (30, 30, 0.003) (spec: θ 0.03).
    pub b_s: V3,
    /// Slave local force feedback `C5` (dimensionless). Default (2, 2, 0) (spec: 0).
    pub c5: V3,
    /// Master local force feedback `C6` (dimensionless). Default −1 (spec: 0).
    pub c6: V3,
    /// Master damping injection `D_m` (N·s/m, N·s/m, N·m·s/rad): a local damper `−D_m·v̂_m` on the
    /// device command, on top of `B_m` (which acts on the velocity error). Default (1, 1, 0.004) (spec: 0).
    pub d_m: V3,
    /// Slave damping injection `D_s` (N·s/m, N·s/m, N·m·s/rad): a local damper `−D_s·v_s` on the slave
    /// drive, on top of `B_s` (which acts on the velocity error). Default 0.
    pub d_s: V3,
    /// Environment-force channel `C2` (dimensionless) when it is not the transparent `1 + C6`:
    /// `None` (default) uses `1 + C6`. Setting it breaks §11.1's transparency conditions.
    pub c2: Option<V3>,
    /// Hand-force channel `C3` (dimensionless) when it is not the transparent `1 + C5`: `None`
    /// (default) uses `1 + C5`. Setting it breaks §11.1's transparency conditions.
    pub c3: Option<V3>,
    /// Add the master-mass feedforward `M̂_x·a_s` to `f_cm`. Default off.
    pub master_feedforward: bool,
    /// Add the slave-mass feedforward `M_s·â_m` to `f_cs` (amplifies encoder noise). Default off.
    pub slave_feedforward: bool,
    /// Slave generalized mass `diag(M_s, M_s, I_s)` for the slave feedforward (kg, kg, kg·m²).
    /// Default (0.5, 0.5, 1e-4).
    pub slave_mass: V3,
    /// Cut-off of the 2nd-order low-pass on the backward-difference accelerations (Hz). Default 30.
    pub accel_cutoff_hz: f64,
}

impl Default for FourChannelGains {
    /// The default configuration of `run` and `reproduce`: [`FourChannelGains::local_force_feedback`].
    fn default() -> Self {
        Self::local_force_feedback()
    }
}

/// Master damping injection of the default configuration in world units (N·s/m, N·s/m, N·m·s/rad);
/// see [`FourChannelGains::local_force_feedback`].
pub const DEFAULT_DAMPING_INJECTION: V3 = [1.0, 1.0, 0.004];

/// Slave local force feedback `C5` of the default configuration (x, y, θ; dimensionless).
pub const DEFAULT_SLAVE_FORCE_FEEDBACK: V3 = [2.0, 2.0, 0.0];

/// θ gains of the default configuration `[K_s, B_s, K_m, B_m]` (N·m/rad, N·m·s/rad, N·m/rad,
/// N·m·s/rad).
pub const DEFAULT_THETA_GAINS: [f64; 4] = [1.0, 0.003, 0.5, 0.002];

/// Master damping injection of [`FourChannelGains::damped`] (N·s/m, N·s/m, N·m·s/rad).
pub const SPEC_DAMPING_INJECTION: V3 = [40.0, 40.0, 0.04];

impl FourChannelGains {
    /// The §11.1 table exactly (`C5 = C6 = 0`, direct force reflection, no damping injection): the
    /// paper's configuration, kept as the named comparison `four-channel-spec`. **Unstable with the
    /// hand released** against a stiff contact (§11.4): with the handle let go, the master (inertia
    /// `m`, almost no physical damping) and the slave on the contact spring `K_e` close a loop through
    /// `C2 = 1` whose released characteristic polynomial has right-half-plane roots in continuous
    /// time — `+2.5 ± 67j` for the spec device on the Fig. 4 box (2000 N/m), `+30 ± 185j` for the
    /// peg's y axis at world scale 2 — so no sampling rate fixes it (`haptic2d stability
    /// --controller four-channel-spec`).
    pub fn spec() -> Self {
        Self {
            k_m: [500.0, 500.0, 1.0],
            b_m: [5.0, 5.0, 0.01],
            k_s: [2000.0, 2000.0, 4.0],
            b_s: [30.0, 30.0, 0.03],
            c5: [0.0; 3],
            c6: [0.0; 3],
            d_m: [0.0; 3],
            d_s: [0.0; 3],
            c2: None,
            c3: None,
            master_feedforward: false,
            slave_feedforward: false,
            slave_mass: [0.5, 0.5, 1e-4],
            accel_cutoff_hz: 30.0,
        }
    }

    /// The default (`four-channel`), chosen by the design study of issue 36 (MODELS.md §11.4,
    /// `haptic2d-lab/tests/it/design_search.rs`): the §11.1 PD gains on x and y with **local force
    /// feedback at both ends** — `C6 = −1` at the master (so `C2 = 0`: the wall force is not reflected
    /// to a released handle) and `C5` = [`DEFAULT_SLAVE_FORCE_FEEDBACK`] at the slave (so `C3 = 1 + C5`:
    /// the hand's push reaches the slave amplified, against `−C5·f_e`) — plus a master damping
    /// injection `D_m` = [`DEFAULT_DAMPING_INJECTION`], and θ gains [`DEFAULT_THETA_GAINS`].
    ///
    /// Still transparent by §11.1's conditions: in steady contact `f_e = f_h`, `x_s = x_m` (X1, X3).
    /// What the study measured (spec device; stability analysis on every built-in scene, the peg
    /// also at scale 2, at 0.5, 1 and 2 kHz with and without one sample of output delay): slowest
    /// decay 11.3 1/s held and 4.1 1/s released (the verdict "stable" needs 2), 6 of the 9 claims of
    /// Figs. 5–6 and 8–11 (every Figs. 8–11 claim and the hysteretic wall; not the pulse wall, and
    /// not the SEH/ZOH bouncing, which no released-stable design reproduces), and quasi-statically a
    /// free-motion drag of 1.37 N·s/m and a felt mass of 0.76 kg for the 0.5 kg box (the former
    /// default `C5 = 0`, `D_m = 2`: 8.1 N·s/m and 2.28 kg), the wall felt at its 2000 N/m.
    ///
    /// θ: the §11.1 table's θ slave PD (4 N·m/rad, 0.03 N·m·s/rad) is refused on the peg at 500 Hz
    /// (§6.4: the peg's 3.3e-5 kg·m² is below 1.5 × its minimum mass) and grows there against the
    /// contacts' friction-stick spring; the study picked θ gains by stability alone (the claims are
    /// on x): slowest θ decay 25 1/s.
    pub fn local_force_feedback() -> Self {
        let spec = Self::spec();
        let [k_s, b_s, k_m, b_m] = DEFAULT_THETA_GAINS;
        Self {
            k_m: [spec.k_m[0], spec.k_m[1], k_m],
            b_m: [spec.b_m[0], spec.b_m[1], b_m],
            k_s: [spec.k_s[0], spec.k_s[1], k_s],
            b_s: [spec.b_s[0], spec.b_s[1], b_s],
            c5: DEFAULT_SLAVE_FORCE_FEEDBACK,
            c6: [-1.0; 3],
            d_m: DEFAULT_DAMPING_INJECTION,
            ..spec
        }
    }

    /// The former default (before issue 36's study; `controllers/former-default.toml`): the §11.1
    /// gains with local force feedback `C6 = −1` at the master only and `D_m = (2, 2, 0.002)`.
    /// Stable released on box-in-walls and on the peg at 1 kHz and up, but its θ slave PD is refused
    /// on the peg at 500 Hz; 2 of the 9 claims (the pulse and hysteretic walls): the push reaches
    /// the peg through `C3 = 1` while the handle's inertia and the dampers brake every slip.
    pub fn master_force_feedback() -> Self {
        Self {
            c6: [-1.0; 3],
            d_m: [2.0, 2.0, 0.002],
            ..Self::spec()
        }
    }

    /// `four-channel-damped`: the §11.1 gains (`C5 = C6 = 0`, full force reflection) made stable
    /// released by master damping injection alone, `D_m` = [`SPEC_DAMPING_INJECTION`].
    ///
    /// Derivation. In the §11.4 polynomial the injection adds to the device's damping `b`; the Fig. 4
    /// box needs `b + D_m ≳ 2.65 N·s/m`, but the peg's y axis at scale 2 (world inertia 0.0625 kg on
    /// 4000–8900 N/m) needs far more: `D_m = 20` still grows at `+8 1/s` (2 kHz); `D_m = 40` decays at
    /// `≥ 9 1/s` on the box and `≥ 24 1/s` on the peg at 1 kHz and up with no output delay, but grows
    /// again with one sample of delay (`+24 1/s` on the peg at 1 kHz): the damper is a derivative
    /// action the delay turns active. A comparison configuration, not a default: it is refused for a
    /// real device by `run`'s released-stability gate (which assumes one sample of delay) at 1 kHz,
    /// and the operator feels 40 N·s/m of drag (4 N at 0.1 m/s).
    pub fn damped() -> Self {
        Self {
            d_m: SPEC_DAMPING_INJECTION,
            ..Self::spec()
        }
    }
}

fn check_finite_nonneg(name: &str, v: &V3) -> Result<(), String> {
    for (i, x) in v.iter().enumerate() {
        if !(x.is_finite() && *x >= 0.0) {
            return Err(format!(
                "controller.{name}[{i}] must be a finite number >= 0 (got {x})"
            ));
        }
    }
    Ok(())
}

impl FourChannelGains {
    /// The named configuration of the command line: `four-channel` (default), `four-channel-spec`,
    /// `four-channel-damped`; `None` for another name.
    pub fn named(name: &str) -> Option<Self> {
        match name {
            "four-channel" | "4ch" => Some(Self::local_force_feedback()),
            "four-channel-spec" => Some(Self::spec()),
            "four-channel-damped" => Some(Self::damped()),
            _ => None,
        }
    }

    /// The name of these gains if they are one of the named configurations.
    pub fn name(&self) -> Option<&'static str> {
        ["four-channel", "four-channel-spec", "four-channel-damped"]
            .into_iter()
            .find(|n| Self::named(n).as_ref() == Some(self))
    }

    /// Checks that every gain is finite and non-negative (C5, C6 only finite), naming the field.
    pub fn validate(&self) -> Result<(), String> {
        check_finite_nonneg("k_m", &self.k_m)?;
        check_finite_nonneg("b_m", &self.b_m)?;
        check_finite_nonneg("k_s", &self.k_s)?;
        check_finite_nonneg("b_s", &self.b_s)?;
        check_finite_nonneg("d_m", &self.d_m)?;
        check_finite_nonneg("d_s", &self.d_s)?;
        check_finite_nonneg("slave_mass", &self.slave_mass)?;
        for (name, c) in [
            ("c5", Some(&self.c5)),
            ("c6", Some(&self.c6)),
            ("c2", self.c2.as_ref()),
            ("c3", self.c3.as_ref()),
        ] {
            if c.is_some_and(|c| !c.iter().all(|v| v.is_finite())) {
                return Err(format!("controller.{name} must be finite"));
            }
        }
        if !(self.accel_cutoff_hz.is_finite() && self.accel_cutoff_hz > 0.0) {
            return Err(format!(
                "controller.accel_cutoff_hz must be > 0 (got {})",
                self.accel_cutoff_hz
            ));
        }
        Ok(())
    }

    /// §6.4 check of the slave coupling `(K_s, B_s)` on a slave of generalized mass `mass` (kg, kg,
    /// kg·m²) at period `dt` (s): refuses masses below `1.5·(K·T²/4 + B·T/2)`, naming the DOF.
    pub fn check_slave_mass(&self, mass: &V3, dt: f64) -> Result<(), String> {
        check_min_mass("k_s/b_s", &self.k_s, &self.b_s, mass, dt)
    }
}

/// Refuses any DOF whose mass is below `1.5·min_mass(K, B, T)` (§6.4).
pub(crate) fn check_min_mass(name: &str, k: &V3, b: &V3, mass: &V3, dt: f64) -> Result<(), String> {
    const DOF: [&str; 3] = ["x", "y", "theta"];
    for i in 0..3 {
        let min_mass = k[i] * dt * dt / 4.0 + b[i] * dt / 2.0;
        if mass[i].is_nan() || mass[i] <= 1.5 * min_mass {
            return Err(format!(
                "controller.{name}: slave {} mass {} is below 1.5 x min_mass = {} for K = {}, B = {}, T = {} s (lower the gains or raise the mass)",
                DOF[i],
                mass[i],
                1.5 * min_mass,
                k[i],
                b[i],
                dt
            ));
        }
    }
    Ok(())
}

/// The four-channel controller: gains plus the state of the acceleration estimators.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FourChannel {
    /// Gains and options.
    pub gains: FourChannelGains,
    dt: f64,
    lp_a_s: LowPass2,
    lp_a_m: LowPass2,
    v_s_prev: V3,
    v_m_prev: V3,
    started: bool,
}

impl FourChannel {
    /// A controller with `gains` (validated) at sample period `dt` (s).
    pub fn new(gains: FourChannelGains, dt: f64) -> Result<Self, String> {
        gains.validate()?;
        if !(dt.is_finite() && dt > 0.0) {
            return Err(format!("controller sample period must be > 0 (got {dt})"));
        }
        Ok(Self {
            gains,
            dt,
            lp_a_s: LowPass2::new(gains.accel_cutoff_hz, dt),
            lp_a_m: LowPass2::new(gains.accel_cutoff_hz, dt),
            v_s_prev: [0.0; 3],
            v_m_prev: [0.0; 3],
            started: false,
        })
    }

    /// Clears the acceleration estimators.
    pub fn reset(&mut self) {
        self.lp_a_s.reset();
        self.lp_a_m.reset();
        self.started = false;
    }

    /// One sample (§0.5 step 7): returns `(f_cm, f_cs)`, the device command and the slave drive
    /// (N, N, N·m).
    pub fn step(&mut self, s: &TeleopSignals) -> (V3, V3) {
        let g = &self.gains;
        // Backward-difference accelerations, low-passed (used only by the optional feedforwards).
        let (raw_a_s, raw_a_m): (V3, V3) = if self.started {
            (
                std::array::from_fn(|i| (s.v_s[i] - self.v_s_prev[i]) / self.dt),
                std::array::from_fn(|i| (s.v_m[i] - self.v_m_prev[i]) / self.dt),
            )
        } else {
            ([0.0; 3], [0.0; 3])
        };
        self.started = true;
        self.v_s_prev = s.v_s;
        self.v_m_prev = s.v_m;
        let a_s = self.lp_a_s.update(&raw_a_s);
        let a_m = self.lp_a_m.update(&raw_a_m);
        let ff_m = if g.master_feedforward {
            m3_mul_v(&s.master_mass, &a_s)
        } else {
            [0.0; 3]
        };

        let e = pose_error(&s.x_s, &s.x_m); // x_s − x_m, θ wrapped
        let mut f_cm = [0.0; 3];
        let mut f_cs = [0.0; 3];
        for i in 0..3 {
            let dv = s.v_s[i] - s.v_m[i];
            // C2 and C3 default to the transparent 1 + C6 and 1 + C5 (computed as before, so a
            // configuration without overrides runs bit for bit as it did).
            let c2 = match &g.c2 {
                Some(c) => c[i],
                None => 1.0 + g.c6[i],
            };
            let c3 = match &g.c3 {
                Some(c) => c[i],
                None => 1.0 + g.c5[i],
            };
            f_cm[i] = g.k_m[i] * e[i] + g.b_m[i] * dv + g.c6[i] * s.f_h[i]
                - c2 * s.f_e[i]
                - g.d_m[i] * s.v_m[i]
                + ff_m[i];
            let ff_s = if g.slave_feedforward {
                g.slave_mass[i] * a_m[i]
            } else {
                0.0
            };
            f_cs[i] = -g.k_s[i] * e[i] - g.b_s[i] * dv + c3 * s.f_h[i] - g.c5[i] * s.f_e[i] + ff_s;
            if g.d_s[i] != 0.0 {
                f_cs[i] -= g.d_s[i] * s.v_s[i];
            }
        }
        (f_cm, f_cs)
    }
}
