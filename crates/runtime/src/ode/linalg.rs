//! Fixed-size linear algebra for the generated code of models whose mass
//! matrix is solved numerically (`crates/derive/src/emit.rs`, `Node::Solution`).
//!
//! The generated right-hand sides of models with three or more degrees of
//! freedom evaluate the mass matrix A(q) and solve A q' = p − b: a Cholesky
//! factorisation of a small symmetric positive definite matrix, written out
//! over `[f64; N]` so that the compiler unrolls it and keeps it in
//! registers (nalgebra's would do the same work through its generic
//! storage, with checks the generated code does not need).

use super::series::Scalar;

/// A pivot of a semidefinite factorisation at most this share of its
/// diagonal entry is a dependent row's: the row's part outside the span of
/// the earlier ones is a sine of at most 1e-5 of it (rounding leaves about
/// 1e-16 where rows are exactly dependent).
pub const REDUNDANT: f64 = 1e-10;

/// The Cholesky factor L (A = L Lᵀ) of a symmetric positive definite
/// matrix, with the reciprocals of its diagonal; over f64, or over
/// [`crate::ode::Lanes`] (one matrix per lane) in the batch recurrences.
///
/// A matrix that is not positive definite (a model at a singular point of
/// its coordinates) gives NaN entries, which the integrators report as a
/// divergence at that time and state: never a silent wrong number.
#[derive(Clone, Copy, Debug)]
pub struct Cholesky<L, const N: usize> {
    lower: [[L; N]; N],
    inverse_diagonal: [L; N],
}

impl<L: Scalar, const N: usize> Cholesky<L, N> {
    /// Factorises `a` (only its lower triangle is read).
    #[inline]
    pub fn new(a: [[L; N]; N]) -> Self {
        Self::factor(a, |d, _| d.positive_sqrt().recip())
    }

    /// The factor of a positive semidefinite matrix whose rows may depend
    /// on earlier ones (redundant constraints' Schur complement G M⁻¹ Gᵀ):
    /// a row whose pivot is at most [`REDUNDANT`] of its diagonal entry adds
    /// nothing new and is skipped, its unknown set to 0. For a consistent
    /// right-hand side that is a solution; any gives the same Gᵀx.
    #[inline]
    pub fn semidefinite(a: [[L; N]; N]) -> Self {
        Self::factor(a, L::semidefinite_inverse_sqrt)
    }

    /// L column by column, each pivot d (with its diagonal entry) turned
    /// into 1/√d by `inverse_pivot`; L's diagonal itself is never read.
    #[inline(always)]
    fn factor(a: [[L; N]; N], inverse_pivot: impl Fn(L, L) -> L) -> Self {
        let mut lower = [[L::default(); N]; N];
        let mut inverse_diagonal = [L::default(); N];
        for j in 0..N {
            let d = a[j][j] - dot(&lower[j][..j], &lower[j][..j]);
            inverse_diagonal[j] = inverse_pivot(d, a[j][j]);
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

    /// The rows kept by [`Cholesky::semidefinite`] (all of a positive
    /// definite matrix's).
    pub fn rank(&self) -> usize
    where
        L: PartialEq,
    {
        self.inverse_diagonal
            .iter()
            .filter(|x| **x != L::default())
            .count()
    }

    /// x with A x = b: forward substitution with L, back substitution with
    /// Lᵀ. The right-hand side may be a batch where A is one f64 matrix.
    #[inline]
    pub fn solve<B: Scalar + std::ops::Mul<L, Output = B>>(&self, b: [B; N]) -> [B; N] {
        let mut y = [B::default(); N];
        for i in 0..N {
            let mut earlier = B::from(-0.0);
            for k in 0..i {
                earlier += y[k] * self.lower[i][k];
            }
            y[i] = (b[i] - earlier) * self.inverse_diagonal[i];
        }
        let mut x = [B::default(); N];
        for i in (0..N).rev() {
            let mut later = B::from(-0.0);
            for k in i + 1..N {
                later += x[k] * self.lower[k][i];
            }
            x[i] = (y[i] - later) * self.inverse_diagonal[i];
        }
        x
    }
}

impl<const N: usize> Cholesky<f64, N> {
    /// [`Cholesky::semidefinite`] with its own threshold: a row whose
    /// pivot is at most `dependent` of its diagonal entry is skipped (a NaN
    /// pivot stays NaN). At [`REDUNDANT`] it is `semidefinite` itself.
    #[inline]
    pub fn semidefinite_within(a: [[f64; N]; N], dependent: f64) -> Self {
        Self::semidefinite_with_sines(a, dependent).0
    }

    /// [`Cholesky::semidefinite_within`], and each row's pivot over its
    /// diagonal entry: the squared sine of its angle to the span of the
    /// earlier rows kept (0 for a vanished row).
    #[inline]
    pub fn semidefinite_with_sines(a: [[f64; N]; N], dependent: f64) -> (Self, [f64; N]) {
        let sines = std::cell::Cell::new([0.0; N]);
        let row = std::cell::Cell::new(0);
        let factor = Self::factor(a, |d, diagonal| {
            let mut squared = sines.get();
            squared[row.get()] = if diagonal > 0.0 { d / diagonal } else { 0.0 };
            sines.set(squared);
            row.set(row.get() + 1);
            if d > dependent * diagonal && d > 0.0 {
                d.sqrt().recip()
            } else if d.is_nan() || diagonal.is_nan() {
                f64::NAN
            } else {
                0.0
            }
        });
        (factor, sines.get())
    }
}

/// Σ a_k b_k from −0.0 up, as `Iterator::sum` adds.
#[inline(always)]
fn dot<L: Scalar>(a: &[L], b: &[L]) -> L {
    let mut sum = L::from(-0.0);
    for (x, y) in a.iter().zip(b) {
        sum += *x * *y;
    }
    sum
}

/// The bialternate product M⊙M, whose eigenvalues are the products
/// λᵢλⱼ (i < j) of M's: its rows and columns are the pairs (i, j), i > j,
/// and its entries the 2×2 minors of M.
pub fn bialternate(m: &nalgebra::DMatrix<f64>) -> nalgebra::DMatrix<f64> {
    let n = m.nrows();
    let pairs: Vec<(usize, usize)> = (0..n).flat_map(|i| (0..i).map(move |j| (i, j))).collect();
    nalgebra::DMatrix::from_fn(pairs.len(), pairs.len(), |r, c| {
        let ((i, j), (k, l)) = (pairs[r], pairs[c]);
        m[(i, k)] * m[(j, l)] - m[(i, l)] * m[(j, k)]
    })
}

/// The bialternate sum 2J⊙I, whose eigenvalues are the sums λᵢ + λⱼ
/// (i < j) of J's (Govaerts' formula, rows and columns the pairs i > j).
pub fn bialternate_sum(a: &nalgebra::DMatrix<f64>) -> nalgebra::DMatrix<f64> {
    let n = a.nrows();
    let pairs: Vec<(usize, usize)> = (0..n).flat_map(|i| (0..i).map(move |j| (i, j))).collect();
    nalgebra::DMatrix::from_fn(pairs.len(), pairs.len(), |r, c| {
        let ((p, q), (r2, s)) = (pairs[r], pairs[c]);
        if r2 == p && s == q {
            a[(p, p)] + a[(q, q)]
        } else if r2 == p {
            a[(q, s)]
        } else if s == q {
            a[(p, r2)]
        } else if r2 == q {
            -a[(p, s)]
        } else if s == p {
            -a[(q, r2)]
        } else {
            0.0
        }
    })
}
