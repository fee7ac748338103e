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

use nalgebra::{Cholesky, DMatrix, DVector, Dyn};

use crate::constrained::{at_rounding, ROUNDING_RESIDUAL};

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
    /// A projection's tolerance that is not finite and positive.
    #[error("the projection's tolerance must be finite and positive, got {value}")]
    Tolerance { value: f64 },
    /// The components held as a chart's coordinates do not parametrise
    /// the constraint manifold at this state.
    #[error("a singular chart: the state components {held:?} do not parametrise the constraints at y = {y:?}")]
    SingularChart { held: Vec<usize>, y: Vec<f64> },
    /// A chart of another size than the constraint manifold's dimension,
    /// or naming a component twice or past the state.
    #[error("a chart of the components {held:?} for a constraint manifold of dimension {dimension} in a state of {state} components: give {dimension} different components")]
    ChartSize {
        held: Vec<usize>,
        dimension: usize,
        state: usize,
    },
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

/// At q: M's Cholesky factor, M⁻¹Gᵀ and the factor of the Schur
/// complement G M⁻¹ Gᵀ, or why they do not exist.
struct Factors {
    m: Cholesky<f64, Dyn>,
    m_inv_gt: DMatrix<f64>,
    schur: Semidefinite,
}

impl Factors {
    fn at(m: &DMatrix<f64>, g: &DMatrix<f64>, q: &[f64]) -> Result<Factors, ConstraintError> {
        let singular = || ConstraintError::Singular { q: q.to_vec() };
        let m = m.clone().cholesky().ok_or_else(singular)?;
        let m_inv_gt = m.solve(&g.transpose());
        let schur = Semidefinite::new(&(g * &m_inv_gt)).ok_or_else(singular)?;
        Ok(Factors { m, m_inv_gt, schur })
    }

    /// The correction −M⁻¹Gᵀ (G M⁻¹ Gᵀ)⁻¹ r of a residual r.
    fn correction(&self, r: &DVector<f64>) -> DVector<f64> {
        -(&self.m_inv_gt * self.schur.solve_vector(r))
    }
}

/// [`crate::linalg::Cholesky::semidefinite`] at run-time sizes: the
/// Schur complement G M⁻¹ Gᵀ of redundant constraints, their rows skipped.
struct Semidefinite {
    lower: DMatrix<f64>,
    inverse_diagonal: DVector<f64>,
}

impl Semidefinite {
    /// None where an entry is not finite, or no row is left (every
    /// constraint degenerate: G = 0).
    fn new(a: &DMatrix<f64>) -> Option<Semidefinite> {
        use crate::ode::Scalar;
        let n = a.nrows();
        let mut lower = DMatrix::zeros(n, n);
        let mut inverse_diagonal = DVector::zeros(n);
        for j in 0..n {
            let row = |i: usize, lower: &DMatrix<f64>| -> f64 {
                (0..j).map(|k| lower[(i, k)] * lower[(j, k)]).sum()
            };
            let d = a[(j, j)] - row(j, &lower);
            let inverse = d.semidefinite_inverse_sqrt(a[(j, j)]);
            inverse_diagonal[j] = inverse;
            for i in j + 1..n {
                lower[(i, j)] = (a[(i, j)] - row(i, &lower)) * inverse;
            }
        }
        let finite =
            a.iter().all(|x| x.is_finite()) && inverse_diagonal.iter().all(|x| x.is_finite());
        let kept = n == 0 || inverse_diagonal.iter().any(|x| *x != 0.0);
        (finite && kept).then_some(Semidefinite {
            lower,
            inverse_diagonal,
        })
    }

    fn solve_vector(&self, b: &DVector<f64>) -> DVector<f64> {
        let n = b.len();
        let mut y = DVector::zeros(n);
        for i in 0..n {
            let earlier: f64 = (0..i).map(|k| self.lower[(i, k)] * y[k]).sum();
            y[i] = (b[i] - earlier) * self.inverse_diagonal[i];
        }
        let mut x = DVector::zeros(n);
        for i in (0..n).rev() {
            let later: f64 = (i + 1..n).map(|k| self.lower[(k, i)] * x[k]).sum();
            x[i] = (y[i] - later) * self.inverse_diagonal[i];
        }
        x
    }

    fn solve(&self, b: &DMatrix<f64>) -> DMatrix<f64> {
        let columns: Vec<DVector<f64>> = b
            .column_iter()
            .map(|c| self.solve_vector(&c.into_owned()))
            .collect();
        DMatrix::from_columns(&columns)
    }
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
    let factors = Factors::at(m, g, q)?;
    let m_inv_f = factors.m.solve(f);
    let lambda = factors.schur.solve_vector(&(-h - g * &m_inv_f));
    Ok((m_inv_f + &factors.m_inv_gt * &lambda, lambda))
}

/// Projects the state `y` = [q; q̇] at time t onto the manifold g = 0,
/// G q̇ + g_t = 0 in the metric of M: positions by Newton's method until
/// |g| ≤ `tolerance`, or its steps reach the coordinates' rounding and |g|
/// stops falling within [`ROUNDING_RESIDUAL`] times it (at most 20
/// steps), then velocities exactly.
pub fn project(
    system: &dyn Holonomic,
    t: f64,
    y: &mut [f64],
    tolerance: f64,
) -> Result<Projection, ConstraintError> {
    project_holding(system, t, y, tolerance, &[])
}

/// [`project`] moving only the components of `y` not in `held` (indices
/// into [q; q̇]): the held ones are a chart's coordinates, the others
/// follow from the constraints (in the metric of M restricted to them).
/// [`ConstraintError::Singular`] where the free components cannot satisfy
/// the constraints (a chart that is singular there).
pub fn project_holding(
    system: &dyn Holonomic,
    t: f64,
    y: &mut [f64],
    tolerance: f64,
    held: &[usize],
) -> Result<Projection, ConstraintError> {
    let n = system.coordinates();
    if !(tolerance.is_finite() && tolerance > 0.0) {
        return Err(ConstraintError::Tolerance { value: tolerance });
    }
    if y.len() != 2 * n {
        return Err(ConstraintError::StateLength {
            given: y.len(),
            coordinates: n,
        });
    }
    // The metric restricted to the free components: held ones get an
    // overwhelming mass, so that the correction leaves them where they are.
    let restricted = |mut m: DMatrix<f64>, offset: usize| {
        let scale = 1e12 * (1.0 + m.amax());
        for &h in held.iter().filter(|&&h| h >= offset && h < offset + n) {
            m[(h - offset, h - offset)] += scale;
        }
        m
    };
    const MAX_STEPS: usize = 20;
    let (q, v) = y.split_at_mut(n);
    let mut newton_steps = 0;
    let (mut rounded, mut previous) = (false, f64::INFINITY);
    let position_residual = loop {
        let residual = system.residual(t, q);
        let size = residual.amax();
        let stalled = rounded && size > previous / 2.0;
        if size <= tolerance || (stalled && size <= ROUNDING_RESIDUAL * tolerance) {
            break size;
        }
        previous = size;
        if newton_steps == MAX_STEPS || !size.is_finite() {
            return Err(ConstraintError::NoConvergence {
                residual: size,
                iterations: newton_steps,
            });
        }
        let (g, _) = system.jacobian(t, q);
        let m = restricted(system.mass(t, q), 0);
        let step = Factors::at(&m, &g, q)?.correction(&residual);
        rounded = at_rounding(q, step.as_slice());
        for (i, (x, d)) in q.iter_mut().zip(step.iter()).enumerate() {
            if !held.contains(&i) {
                *x += d;
            }
        }
        newton_steps += 1;
    };
    let (g, g_t) = system.jacobian(t, q);
    let factors = Factors::at(&restricted(system.mass(t, q), n), &g, q)?;
    // Exact in one pass without held components; a second pass removes
    // what their (tiny, skipped) share of the correction left.
    for _ in 0..if held.is_empty() { 1 } else { 2 } {
        let velocity = DVector::from_column_slice(v);
        let step = factors.correction(&(&g * &velocity + &g_t));
        for (i, (x, d)) in v.iter_mut().zip(step.iter()).enumerate() {
            if !held.contains(&(n + i)) {
                *x += d;
            }
        }
    }
    let velocity = DVector::from_column_slice(v);
    let scale = 1.0 + g.amax() * velocity.amax() + g_t.amax();
    let velocity_residual = (&g * velocity + g_t).amax();
    // Held velocities the free ones cannot make consistent (the road's
    // constraint at t = 0 fixes the very component held): a singular chart,
    // not a start the run would drift from.
    if !held.is_empty() && !(velocity_residual <= 1e-9 * scale) {
        return Err(ConstraintError::SingularChart {
            held: held.to_vec(),
            y: y.to_vec(),
        });
    }
    Ok(Projection {
        newton_steps,
        position_residual,
        velocity_residual,
    })
}

/// An orthonormal basis (as columns) of the tangent space of the
/// constrained phase space at a state: the kernel of the Jacobian `c`
/// (2k × 2n) of the state's constraints [g; G q̇ + g_t]. Redundant
/// constraints leave its rank r below 2k: the kernel has 2n − r columns,
/// r the singular values above 1e-10 of the largest. None where nothing is
/// left to move.
pub fn tangent_basis(c: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    let (rows, n) = c.shape();
    if rows == 0 {
        return Some(DMatrix::identity(n, n));
    }
    // The full SVD's right singular vectors: those past the rank span the
    // kernel.
    let padded = match rows < n {
        true => c.clone().insert_rows(rows, n - rows, 0.0),
        false => c.clone(),
    };
    let svd = nalgebra::linalg::SVD::new(padded, false, true);
    let v_t = svd.v_t?;
    let mut order: Vec<usize> = (0..svd.singular_values.len()).collect();
    order.sort_by(|&a, &b| svd.singular_values[b].total_cmp(&svd.singular_values[a]));
    let largest = svd.singular_values[order[0]];
    if !largest.is_finite() {
        return None;
    }
    let rank = order
        .iter()
        .take_while(|&&i| svd.singular_values[i] > 1e-10 * largest)
        .count();
    if rank >= n || v_t.nrows() < n {
        return None;
    }
    Some(DMatrix::from_fn(n, n - rank, |i, j| {
        v_t[(order[rank + j], i)]
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

/// P = M⁻¹ − M⁻¹Gᵀ (G M⁻¹ Gᵀ)⁻¹ G M⁻¹ at q: the inverse mass matrix on the
/// tangent space of the constraints (J A⁻¹ Jᵀ for any parametrisation
/// q = φ(u), J = ∂φ/∂u, A = Jᵀ M J), which averaging needs without one.
pub fn tangent_inverse_mass(
    m: &DMatrix<f64>,
    g: &DMatrix<f64>,
    q: &[f64],
) -> Result<DMatrix<f64>, ConstraintError> {
    let factors = Factors::at(m, g, q)?;
    let correction = &factors.m_inv_gt * factors.schur.solve(&factors.m_inv_gt.transpose());
    Ok(factors.m.inverse() - correction)
}

/// The vibrational potential V_vibr = ½ mean⟨P β, β⟩ (Study 2's in
/// redundant coordinates) from β = ∂⟨m r, ẇ⟩/∂q sampled at equally
/// spaced phases of a period (exact for β linear in the base's velocity
/// with three or more samples).
pub fn vibrational_potential(p: &DMatrix<f64>, betas: &[DVector<f64>]) -> f64 {
    let sum: f64 = betas.iter().map(|b| b.dot(&(p * b))).sum();
    0.5 * sum / betas.len().max(1) as f64
}

/// The second-order test at an equilibrium q* of a potential U on the
/// manifold (∇U = Gᵀμ there): the multipliers μ and the matrices
/// A_T = Zᵀ M Z and C_T = Zᵀ (∇²U − Σ μᵢ ∇²gᵢ) Z on an orthonormal basis Z
/// of ker G. The multiplier term is the manifold's curvature: without it
/// a point on a rod held upright would look neutral instead of unstable.
pub struct TangentStability {
    pub multipliers: DVector<f64>,
    pub mass: DMatrix<f64>,
    pub stiffness: DMatrix<f64>,
}

/// [`TangentStability`] from M, G, ∇U, ∇²U and each constraint's Hessian
/// ∇²gᵢ at q*. None where G is rank-deficient or the Hessians are not one
/// per constraint.
pub fn tangent_stability(
    m: &DMatrix<f64>,
    g: &DMatrix<f64>,
    gradient: &DVector<f64>,
    hessian: &DMatrix<f64>,
    constraint_hessians: &[DMatrix<f64>],
) -> Option<TangentStability> {
    if constraint_hessians.len() != g.nrows() {
        return None;
    }
    let z = tangent_basis(g)?;
    // μ from Gᵀμ = ∇U, by least squares (exact at an equilibrium); of
    // least norm where constraints are redundant (any μ gives the same C_T).
    let multipliers = g
        .transpose()
        .svd(true, true)
        .solve(gradient, 1e-12 * g.norm())
        .ok()?;
    let mut curvature = hessian.clone();
    for (mu, h) in multipliers.iter().zip(constraint_hessians) {
        curvature -= h * *mu;
    }
    Some(TangentStability {
        mass: z.transpose() * m * &z,
        stiffness: z.transpose() * curvature * &z,
        multipliers,
    })
}
