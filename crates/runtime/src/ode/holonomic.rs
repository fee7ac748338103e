//! Holonomic constraints g(q, t) = 0 on a state y = [q; q̇] of n coordinates
//! (possibly redundant) and k constraints: the accelerations and multipliers
//! of Lagrange's equations with constraints, and consistent states by
//! projection onto the constraint manifold.
//!
//! With M the mass matrix, F the free generalised force, G = ∂g/∂q and
//! h = ∂(G q̇ + g_t)/∂q · q̇ + ∂(G q̇ + g_t)/∂t, the equations
//! M q̈ = F + Gᵀλ and G q̈ + h = 0 give, by the Schur complement,
//! λ = (G M⁻¹ Gᵀ)⁻¹ (−h − G M⁻¹ F) and q̈ = M⁻¹ (F + Gᵀλ); Gᵀλ is the
//! reaction force in the coordinates. That ODE keeps g = 0 and
//! G q̇ + g_t = 0 only up to the integration error, which grows, so a run
//! projects its state back onto the manifold (at the ends of its segments)
//! in the metric of M, the projection that changes the energy least:
//! positions by Newton's method, q ← q − M⁻¹Gᵀ (G M⁻¹ Gᵀ)⁻¹ g, velocities
//! exactly, q̇ ← q̇ − M⁻¹Gᵀ (G M⁻¹ Gᵀ)⁻¹ (G q̇ + g_t). A partial start (any
//! positions and velocities near the manifold) is made consistent the same way.

use nalgebra::{DMatrix, DVector};

/// What a holonomically constrained system gives at (t, q).
pub trait Holonomic {
    /// The number n of coordinates (the state is [q; q̇], 2n numbers).
    fn coordinates(&self) -> usize;
    /// g(q, t), k values.
    fn residual(&self, t: f64, q: &[f64]) -> DVector<f64>;
    /// G = ∂g/∂q (k × n) and g_t = ∂g/∂t (k values).
    fn jacobian(&self, t: f64, q: &[f64]) -> (DMatrix<f64>, DVector<f64>);
    /// The mass matrix M(q) (n × n, positive definite).
    fn mass(&self, t: f64, q: &[f64]) -> DMatrix<f64>;
}

/// Why no consistent state or no accelerations could be had.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ConstraintError {
    /// Newton's method did not bring the positions onto the manifold: no
    /// consistent state is near the one given.
    #[error("no consistent state near the given one: the constraints' residual is still {residual:e} after {iterations} Newton steps")]
    NoConvergence { residual: f64, iterations: usize },
    /// G M⁻¹ Gᵀ is not invertible: the constraints are redundant or
    /// degenerate here, or M is not positive definite.
    #[error("the constraints are redundant or degenerate at q = {q:?} (G M⁻¹ Gᵀ is singular), or the mass matrix is not positive definite there")]
    Singular { q: Vec<f64> },
    /// A state of another length than 2n.
    #[error("a state of {given} numbers for a system of {coordinates} coordinates (2 per coordinate expected)")]
    StateLength { given: usize, coordinates: usize },
}

/// The steps a projection took, and the residuals it left.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Projection {
    pub newton_steps: usize,
    /// max |g| and max |G q̇ + g_t| after it.
    pub position_residual: f64,
    pub velocity_residual: f64,
}

/// The correction −M⁻¹Gᵀ (G M⁻¹ Gᵀ)⁻¹ r of a residual r at q.
fn correction(
    m: &DMatrix<f64>,
    g: &DMatrix<f64>,
    r: &DVector<f64>,
    q: &[f64],
) -> Result<DVector<f64>, ConstraintError> {
    let singular = || ConstraintError::Singular { q: q.to_vec() };
    let m = m.clone().cholesky().ok_or_else(singular)?;
    let m_inv_gt = m.solve(&g.transpose());
    let schur = (g * &m_inv_gt).cholesky().ok_or_else(singular)?;
    Ok(-(m_inv_gt * schur.solve(r)))
}

/// The accelerations q̈ and multipliers λ at a state, from the mass matrix
/// `m`, the free force `f`, G (`g`) and h (see the module's comment).
pub fn accelerations(
    m: &DMatrix<f64>,
    f: &DVector<f64>,
    g: &DMatrix<f64>,
    h: &DVector<f64>,
    q: &[f64],
) -> Result<(DVector<f64>, DVector<f64>), ConstraintError> {
    let singular = || ConstraintError::Singular { q: q.to_vec() };
    let m = m.clone().cholesky().ok_or_else(singular)?;
    let m_inv_f = m.solve(f);
    let m_inv_gt = m.solve(&g.transpose());
    let schur = (g * &m_inv_gt).cholesky().ok_or_else(singular)?;
    let lambda = schur.solve(&(-h - g * &m_inv_f));
    Ok((m_inv_f + m_inv_gt * &lambda, lambda))
}

/// Projects the state `y` = [q; q̇] at time t onto the manifold g = 0,
/// G q̇ + g_t = 0 in the metric of M: positions by Newton's method until
/// |g| ≤ `tolerance` (at most 20 steps), then velocities exactly.
pub fn project(
    system: &dyn Holonomic,
    t: f64,
    y: &mut [f64],
    tolerance: f64,
) -> Result<Projection, ConstraintError> {
    let n = system.coordinates();
    if y.len() != 2 * n {
        return Err(ConstraintError::StateLength {
            given: y.len(),
            coordinates: n,
        });
    }
    const MAX_STEPS: usize = 20;
    let (q, v) = y.split_at_mut(n);
    let mut newton_steps = 0;
    let position_residual = loop {
        let residual = system.residual(t, q);
        let size = residual.amax();
        if size <= tolerance {
            break size;
        }
        if newton_steps == MAX_STEPS || !size.is_finite() {
            return Err(ConstraintError::NoConvergence {
                residual: size,
                iterations: newton_steps,
            });
        }
        let (g, _) = system.jacobian(t, q);
        let step = correction(&system.mass(t, q), &g, &residual, q)?;
        for (x, d) in q.iter_mut().zip(step.iter()) {
            *x += d;
        }
        newton_steps += 1;
    };
    let (g, g_t) = system.jacobian(t, q);
    let velocity = DVector::from_column_slice(v);
    let step = correction(&system.mass(t, q), &g, &(&g * &velocity + &g_t), q)?;
    for (x, d) in v.iter_mut().zip(step.iter()) {
        *x += d;
    }
    let velocity = DVector::from_column_slice(v);
    Ok(Projection {
        newton_steps,
        position_residual,
        velocity_residual: (&g * velocity + g_t).amax(),
    })
}

/// An orthonormal basis (as columns) of the tangent space of the
/// constrained phase space at a state: the kernel of the Jacobian `c`
/// (2k × 2n) of the state's constraints [g; G q̇ + g_t]. None where `c`
/// does not have full rank 2k (degenerate constraints).
pub fn tangent_basis(c: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    let (rows, n) = c.shape();
    if rows >= n {
        return None;
    }
    // The full SVD's right singular vectors: the last n − rows span the
    // kernel when the first `rows` singular values are not zero.
    let svd = nalgebra::linalg::SVD::new(c.clone().insert_rows(rows, n - rows, 0.0), false, true);
    let v_t = svd.v_t?;
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| svd.singular_values[b].total_cmp(&svd.singular_values[a]));
    let largest = svd.singular_values[order[0]];
    if !(svd.singular_values[order[rows - 1]] > 1e-12 * largest) {
        return None;
    }
    Some(DMatrix::from_fn(n, n - rows, |i, j| {
        v_t[(order[rows + j], i)]
    }))
}

/// A monodromy matrix of the unconstrained ODE (2n × 2n) restricted to
/// the constrained phase space, whose orthonormal basis at the orbit's
/// start is `basis` (from [`tangent_basis`]): Zᵀ M Z, whose 2(n − k)
/// eigenvalues are the physical Floquet multipliers. The full matrix has
/// 2k more, from the directions across the manifold (the drift of the
/// constraints, multipliers at 1), which mean nothing for the motion.
pub fn restricted_monodromy(monodromy: &DMatrix<f64>, basis: &DMatrix<f64>) -> DMatrix<f64> {
    basis.transpose() * monodromy * basis
}
