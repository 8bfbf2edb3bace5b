//! The architectures of [`super::teleop`]: position–force (a virtual coupling at the slave, its
//! reaction sent back) and Lawrence's four-channel law (Lawrence 1993, "Stability and transparency
//! in bilateral teleoperation", IEEE TRA 9(5); Hashtrudi-Zaad & Salcudean 2001), between two real
//! (simulated) devices across a delayed link.
//!
//! **Four channels.** Each side sends its position, velocity *and* force: the master the hand's
//! force `f_h` on its handle, the slave the force `f_e` it applies to the environment (minus the
//! wall's force on it). With Lawrence's blocks (velocity form, `C_m = B_m + K_m/s`,
//! `C_s = B_s + K_s/s`, primes for what arrived over the link):
//!
//! ```text
//! master:  f_cm = −C_m·v_m − C4·v_s' + C6·f_h − C2·f_e'
//! slave:   f_cs = −C_s·v_s + C1·v_m' + C3·f_h' − C5·f_e
//! ```
//!
//! and the transparency choice `C1 = Z_s + C_s`, `C4 = −(Z_m + C_m)`, `C2 = 1 + C6`,
//! `C3 = 1 + C5`, this is, per axis,
//!
//! ```text
//! f_cm = K_m·(x_s' − x_m) + B_m·(v_s' − v_m) + C6·f_h − (1 + C6)·f_e'
//! f_cs = K_s·(x_m' − x_s) + B_s·(v_m' − v_s) + (1 + C5)·f_h' − C5·f_e
//! ```
//!
//! **The gains chosen** for the lumped twin-pantograph plants of MODELS §10.6
//! ([`FourChannel::lawrence`]): `K_m = K_s = K`, `B_m = B_s = B` (the position–force coupling's,
//! default 500 N/m, 5 N·s/m), `C2 = C3 = 1`, `C5 = C6 = 0`. The device impedance `Z = m·s + b`
//! inside `C1` and `C4` is left out: its inertial part needs the far device's acceleration (a
//! second difference of 4 000-count encoders at 1 kHz, noise of tens of m/s²) and its viscous
//! part (`f_v·(JᵀJ)_xx`, 0.028 N·s/m along x at the centre) is below 1 % of `B`. So the
//! conditions hold up to the devices' own impedance: in steady contact the law gives
//! `f_h = −f_e` and `x_m = x_s` exactly (add the two equilibria), and in motion the hand feels
//! both devices' inertia, as with position–force. [`FourChannel::c5`]/[`FourChannel::c6`] allow
//! the local force feedback of Hashtrudi-Zaad and Salcudean (e.g. `C6 = −1`: three channels).
//!
//! **Force measurement.** The law needs `f_h` and `f_e`. In simulation both are known exactly: the
//! grip's wrench on the master handle and the wall's force on the slave (what an ideal force
//! sensor at the handle would read). A real device would need a force/torque sensor at its
//! handle; the twin pantograph and the Haply boards have none (their hand force is only an
//! observer's estimate, §10.8).
//!
//! **Passivity.** TDPA is applied as for position–force: one port at each device, booking the
//! force its actuators really applied against its velocity, the two ports exchanging their
//! energy-in over the link. The link together with both controllers is treated as *one*
//! two-port whose ports are the two actuators. This is justified because the actuators are the
//! only sources of energy in the loop: whatever signals the controllers combine (positions,
//! velocities, measured forces), the energy the network puts into the physical world is the
//! actuators' work, and the port controllers keep it below what the network absorbed. It is not
//! the per-channel representation of Artigas et al. (2007, 2010), which would place passivity
//! controllers on each of the four channels and preserve more transparency; that is not built.

use haptic2d::device::linalg::V3;

/// Which signals cross the link and how each side turns them into a command.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Architecture {
    /// The slave follows the master through the virtual coupling `Teleop::k`, `Teleop::b`; the
    /// coupling's reaction is the master's force (the default).
    PositionForce,
    /// Lawrence's four channels with these gains.
    FourChannel(FourChannel),
}

/// Four-channel gains, per axis (x, y, θ).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FourChannel {
    /// Master position gain `K_m` (N/m, N/m, N·m/rad).
    pub k_m: V3,
    /// Master damping on the velocity error `B_m` (N·s/m, N·s/m, N·m·s/rad).
    pub b_m: V3,
    /// Slave position gain `K_s` (N/m, N/m, N·m/rad).
    pub k_s: V3,
    /// Slave damping on the velocity error `B_s` (N·s/m, N·s/m, N·m·s/rad).
    pub b_s: V3,
    /// Slave local force feedback `C5` (dimensionless); `C3 = 1 + C5`.
    pub c5: V3,
    /// Master local force feedback `C6` (dimensionless); `C2 = 1 + C6`.
    pub c6: V3,
}

impl FourChannel {
    /// Lawrence's transparent choice with the local position controllers `(K, B)` on both sides:
    /// `C_m = C_s = B + K/s`, `C2 = C3 = 1`, `C5 = C6 = 0`.
    pub fn lawrence(k: V3, b: V3) -> Self {
        Self {
            k_m: k,
            b_m: b,
            k_s: k,
            b_s: b,
            c5: [0.0; 3],
            c6: [0.0; 3],
        }
    }

    /// The master's command (N, N, N·m): from its own pose `x_m` (m, m, rad, relative to its
    /// start), twist `v_m` and hand force `f_h`, and the slave's `x_s'`, `v_s'`, `f_e'` as they
    /// arrived.
    pub fn master(&self, x_m: &V3, v_m: &V3, f_h: &V3, x_s: &V3, v_s: &V3, f_e: &V3) -> V3 {
        std::array::from_fn(|i| {
            self.k_m[i] * (x_s[i] - x_m[i]) + self.b_m[i] * (v_s[i] - v_m[i]) + self.c6[i] * f_h[i]
                - (1.0 + self.c6[i]) * f_e[i]
        })
    }

    /// The slave's command (N, N, N·m): from its own `x_s`, `v_s`, `f_e` and the master's `x_m'`,
    /// `v_m'`, `f_h'` as they arrived.
    pub fn slave(&self, x_s: &V3, v_s: &V3, f_e: &V3, x_m: &V3, v_m: &V3, f_h: &V3) -> V3 {
        std::array::from_fn(|i| {
            self.k_s[i] * (x_m[i] - x_s[i])
                + self.b_s[i] * (v_m[i] - v_s[i])
                + (1.0 + self.c5[i]) * f_h[i]
                - self.c5[i] * f_e[i]
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Lawrence's transparency in statics: with both sides at rest and the messages current,
    /// the equilibria `f_h + f_cm = 0` (master) and `f_cs = f_e` (slave; `f_e` its force on the
    /// environment) are `f_h − K·e − f_e = 0` and `K·e + f_h = f_e` (`e = x_m − x_s`), whose only
    /// solution is `e = 0`, `f_h = f_e`. Checked by solving the 2×2 system the law gives for
    /// `(e, f_h)` at a given `f_e`.
    #[test]
    fn lawrence_gains_hold_equal_positions_and_forces_in_statics() {
        let g = FourChannel::lawrence([500.0; 3], [5.0; 3]);
        let f_e = [1.7, 0.0, 0.0];
        let z = [0.0; 3];
        // Unknowns e = x_m − x_s and f_h along x: master f_h + f_cm = 0, slave f_cs = f_e.
        // f_cm(e, f_h) and f_cs(e, f_h) are affine: sample them to get the coefficients.
        let fm = |e: f64, fh: f64| g.master(&[e, 0.0, 0.0], &z, &[fh, 0.0, 0.0], &z, &z, &f_e)[0];
        let fs = |e: f64, fh: f64| g.slave(&z, &z, &f_e, &[e, 0.0, 0.0], &z, &[fh, 0.0, 0.0])[0];
        let (a11, a12, r1) = (
            fm(1.0, 0.0) - fm(0.0, 0.0),
            1.0 + fm(0.0, 1.0) - fm(0.0, 0.0),
            -fm(0.0, 0.0),
        );
        let (a21, a22, r2) = (
            fs(1.0, 0.0) - fs(0.0, 0.0),
            fs(0.0, 1.0) - fs(0.0, 0.0),
            f_e[0] - fs(0.0, 0.0),
        );
        let det = a11 * a22 - a12 * a21;
        let e = (r1 * a22 - a12 * r2) / det;
        let fh = (a11 * r2 - a21 * r1) / det;
        assert!(e.abs() < 1e-12, "position error {e}");
        assert!((fh - f_e[0]).abs() < 1e-12, "hand force {fh} vs {}", f_e[0]);
    }
}
