//! Stabilisation of an equilibrium by fast vertical vibration of the base.
//!
//! Near an equilibrium the averaged (limiting) potential has the Hessian
//! B = C + (a² mean(h²)/g²) C A⁻¹ C, with A the mass matrix and C = ∂²V/∂q²
//! there (docs/studies.md derives it, including the g² factor). In the
//! coordinates where A = I and C = diag(λᵢ), the λᵢ being the roots of
//! det(C − λA) = 0, B = diag(λᵢ + a² mean(h²) λᵢ²/g²): a direction with
//! λᵢ > 0 stays stable for every a, one with λᵢ < 0 becomes stable iff
//! a² > g²/(mean(h²)|λᵢ|). The binding root is the negative one smallest in
//! modulus, λ*.

use nalgebra::{DMatrix, SMatrix};

/// The roots λ of det(C − λA) = 0 for symmetric C and positive definite A,
/// ascending; None if A is not positive definite.
pub fn generalized_eigenvalues<const N: usize>(
    a: &[[f64; N]; N],
    c: &[[f64; N]; N],
) -> Option<[f64; N]> {
    let a = DMatrix::from_fn(N, N, |i, j| a[i][j]);
    let c = DMatrix::from_fn(N, N, |i, j| c[i][j]);
    generalized_eigenvalues_of(&a, &c)?.try_into().ok()
}

/// [`generalized_eigenvalues`] of matrices of any size.
pub fn generalized_eigenvalues_of(a: &DMatrix<f64>, c: &DMatrix<f64>) -> Option<Vec<f64>> {
    let n = a.nrows();
    // A = L Lᵀ; the roots are the eigenvalues of L⁻¹ C L⁻ᵀ (symmetric).
    let l = a.clone().cholesky()?.l();
    let l_inv = l.try_inverse()?;
    let m = &l_inv * c * l_inv.transpose();
    let m = DMatrix::from_fn(n, n, |i, j| 0.5 * (m[(i, j)] + m[(j, i)]));
    let mut values: Vec<f64> = m.symmetric_eigenvalues().iter().copied().collect();
    values.sort_by(f64::total_cmp);
    Some(values)
}

/// What vibration does to an equilibrium with roots λ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Stabilization {
    /// Every λ > 0: stable without vibration, and for every amplitude.
    AlreadyStable,
    /// Stable in the limiting system iff the velocity amplitude a > a*.
    Threshold { lambda_star: f64, a_star: f64 },
    /// A root is zero (to the relative tolerance): the criterion does not decide.
    Degenerate,
}

/// The verdict of criterion a² > g²/(mean(h²)|λ*|) for the roots `lambdas`.
pub fn stabilization(lambdas: &[f64], g: f64, mean_h2: f64) -> Stabilization {
    let scale = lambdas.iter().fold(0.0f64, |m, l| m.max(l.abs()));
    if lambdas.iter().any(|l| l.abs() <= 1e-12 * scale) || scale == 0.0 {
        return Stabilization::Degenerate;
    }
    let negative = lambdas
        .iter()
        .filter(|l| **l < 0.0)
        .fold(None, |best: Option<f64>, &l| {
            Some(best.map_or(l, |b| if l.abs() < b.abs() { l } else { b }))
        });
    match negative {
        None => Stabilization::AlreadyStable,
        Some(lambda_star) => Stabilization::Threshold {
            lambda_star,
            a_star: g / (mean_h2 * lambda_star.abs()).sqrt(),
        },
    }
}

/// Whether a symmetric matrix is positive definite (Cholesky succeeds).
pub fn positive_definite<const N: usize>(m: &[[f64; N]; N]) -> bool {
    SMatrix::<f64, N, N>::from_fn(|i, j| m[i][j])
        .cholesky()
        .is_some()
}

/// Eigenvalues (re, im) of the linearisation J of a vector field at an
/// equilibrium, sorted by decreasing real part.
pub fn linearization_eigenvalues<const N: usize>(jacobian: &[[f64; N]; N]) -> Vec<(f64, f64)> {
    let j = nalgebra::DMatrix::from_fn(N, N, |r, c| jacobian[r][c]);
    let mut values: Vec<(f64, f64)> = j
        .complex_eigenvalues()
        .iter()
        .map(|z| (z.re, z.im))
        .collect();
    values.sort_by(|a, b| b.0.total_cmp(&a.0));
    values
}
