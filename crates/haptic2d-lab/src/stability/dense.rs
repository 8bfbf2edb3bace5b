//! A small dense real matrix (row-major `Vec<f64>`), with just what the loop analysis needs: products
//! and the matrix exponential (for the zero-order-hold discretisation of the device plant).

// Index loops on purpose: the algorithms read like their textbook statements.
#![allow(clippy::needless_range_loop)]

/// A dense `n × n` real matrix, row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct Mat {
    /// Dimension `n`.
    pub n: usize,
    /// Entries, `a[i·n + j]` = row `i`, column `j`.
    pub a: Vec<f64>,
}

impl Mat {
    /// The `n × n` zero matrix.
    pub fn zeros(n: usize) -> Self {
        Self {
            n,
            a: vec![0.0; n * n],
        }
    }

    /// The `n × n` identity.
    pub fn identity(n: usize) -> Self {
        let mut m = Self::zeros(n);
        for i in 0..n {
            m.a[i * n + i] = 1.0;
        }
        m
    }

    /// The matrix whose column `j` is `f(e_j)`: the matrix of the linear map `f` (ℝⁿ → ℝⁿ).
    pub fn from_linear_map(n: usize, f: impl Fn(&[f64]) -> Vec<f64>) -> Self {
        let mut m = Self::zeros(n);
        let mut e = vec![0.0; n];
        for j in 0..n {
            e.iter_mut().for_each(|v| *v = 0.0);
            e[j] = 1.0;
            let col = f(&e);
            for i in 0..n {
                m.a[i * n + j] = col[i];
            }
        }
        m
    }

    /// Entry `(i, j)`.
    #[inline]
    pub fn get(&self, i: usize, j: usize) -> f64 {
        self.a[i * self.n + j]
    }

    /// Sets entry `(i, j)`.
    #[inline]
    pub fn set(&mut self, i: usize, j: usize, v: f64) {
        self.a[i * self.n + j] = v;
    }

    /// The product `self · b`.
    pub fn mul(&self, b: &Mat) -> Mat {
        let n = self.n;
        let mut c = Mat::zeros(n);
        for i in 0..n {
            for k in 0..n {
                let aik = self.a[i * n + k];
                if aik != 0.0 {
                    for j in 0..n {
                        c.a[i * n + j] += aik * b.a[k * n + j];
                    }
                }
            }
        }
        c
    }

    /// `self · x`.
    pub fn mul_vec(&self, x: &[f64]) -> Vec<f64> {
        (0..self.n)
            .map(|i| (0..self.n).map(|j| self.a[i * self.n + j] * x[j]).sum())
            .collect()
    }

    /// The induced ∞-norm (largest absolute row sum).
    pub fn norm_inf(&self) -> f64 {
        (0..self.n)
            .map(|i| {
                (0..self.n)
                    .map(|j| self.a[i * self.n + j].abs())
                    .sum::<f64>()
            })
            .fold(0.0, f64::max)
    }

    /// `self · s`.
    pub fn scaled(&self, s: f64) -> Mat {
        Mat {
            n: self.n,
            a: self.a.iter().map(|v| v * s).collect(),
        }
    }

    /// The matrix exponential `e^A`, by scaling and squaring: `e^A = (e^{A/2^s})^{2^s}` with
    /// `‖A/2^s‖∞ ≤ 1/2`, and `e^{A/2^s}` from its Taylor series to 18 terms (truncation error below
    /// `0.5^19/19! ≈ 1e-23` relative, far under f64 rounding).
    pub fn expm(&self) -> Mat {
        let norm = self.norm_inf();
        let s = if norm > 0.5 {
            (norm / 0.5).log2().ceil() as i32
        } else {
            0
        };
        let a = self.scaled(0.5f64.powi(s));
        let mut sum = Mat::identity(self.n);
        let mut term = Mat::identity(self.n);
        for k in 1..=18 {
            term = term.mul(&a).scaled(1.0 / k as f64);
            for (x, t) in sum.a.iter_mut().zip(&term.a) {
                *x += t;
            }
        }
        for _ in 0..s {
            sum = sum.mul(&sum);
        }
        sum
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn expm_of_a_rotation_generator_is_the_rotation() {
        // A = [[0, −w], [w, 0]]·t → e^A = [[cos wt, −sin wt], [sin wt, cos wt]].
        let (w, t) = (67.0, 0.3);
        let mut a = Mat::zeros(2);
        a.set(0, 1, -w * t);
        a.set(1, 0, w * t);
        let e = a.expm();
        assert!((e.get(0, 0) - (w * t).cos()).abs() < 1e-12);
        assert!((e.get(1, 0) - (w * t).sin()).abs() < 1e-12);
        assert!((e.get(0, 1) + (w * t).sin()).abs() < 1e-12);
    }

    #[test]
    fn expm_of_a_diagonal_is_elementwise() {
        let mut a = Mat::zeros(2);
        a.set(0, 0, -3.0);
        a.set(1, 1, 1.5);
        let e = a.expm();
        assert!((e.get(0, 0) - (-3.0f64).exp()).abs() < 1e-13);
        assert!((e.get(1, 1) - 1.5f64.exp()).abs() < 1e-12);
        assert_eq!(e.get(0, 1), 0.0);
    }
}
