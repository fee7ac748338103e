//! Fixed-size linear algebra for the generated code of models whose mass
//! matrix is solved numerically (`build/emit.rs`, `Node::Solution`).
//!
//! The generated right-hand sides of models with three or more degrees of
//! freedom evaluate the mass matrix A(q) and solve A q' = p − b: a Cholesky
//! factorisation of a small symmetric positive definite matrix, written out
//! over `[f64; N]` so that the compiler unrolls it and keeps it in
//! registers (nalgebra's would do the same work through its generic
//! storage, with checks the generated code does not need).

/// The Cholesky factor L (A = L Lᵀ) of a symmetric positive definite
/// matrix, with the reciprocals of its diagonal.
///
/// A matrix that is not positive definite (a model at a singular point of
/// its coordinates) gives NaN entries, which the integrators report as a
/// divergence at that time and state: never a silent wrong number.
#[derive(Clone, Copy, Debug)]
pub struct Cholesky<const N: usize> {
    lower: [[f64; N]; N],
    inverse_diagonal: [f64; N],
}

impl<const N: usize> Cholesky<N> {
    /// Factorises `a` (only its lower triangle is read).
    #[inline]
    pub fn new(a: [[f64; N]; N]) -> Self {
        let mut lower = [[0.0; N]; N];
        let mut inverse_diagonal = [0.0; N];
        for j in 0..N {
            let d = a[j][j] - dot(&lower[j][..j], &lower[j][..j]);
            let pivot = if d > 0.0 { d.sqrt() } else { f64::NAN };
            lower[j][j] = pivot;
            inverse_diagonal[j] = 1.0 / pivot;
            for i in j + 1..N {
                let s = a[i][j] - dot(&lower[i][..j], &lower[j][..j]);
                lower[i][j] = s * inverse_diagonal[j];
            }
        }
        Cholesky {
            lower,
            inverse_diagonal,
        }
    }

    /// x with A x = b: forward substitution with L, back substitution with Lᵀ.
    #[inline]
    pub fn solve(&self, b: [f64; N]) -> [f64; N] {
        let mut y = [0.0; N];
        for i in 0..N {
            y[i] = (b[i] - dot(&self.lower[i][..i], &y[..i])) * self.inverse_diagonal[i];
        }
        let mut x = [0.0; N];
        for i in (0..N).rev() {
            let later: f64 = (i + 1..N).map(|k| self.lower[k][i] * x[k]).sum();
            x[i] = (y[i] - later) * self.inverse_diagonal[i];
        }
        x
    }
}

#[inline(always)]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}
