//! Models with ideal constraints at run time: closed loops, rods between
//! points, moving guides, rolling.
//!
//! A constrained model's state is y = [q; q'] over its n coordinates
//! (possibly redundant), and its k constraints read, at the velocity level,
//! G(q, t) q' + c_t(q, t) = 0 (see `crates/derive/src/constraints.rs`).
//! [`OnConstraints`] is the ODE of Lagrange's equations with multipliers,
//! M q'' = F + Gᵀλ, G q'' + h = 0, solved at each state by the Schur
//! complement at the model's own sizes, so that every integrator runs it.
//! That ODE keeps the constraints only up to the integration error, so a
//! run projects its state back onto them (positions by Newton's method in
//! the metric of M, velocities exactly: [`crate::ode::holonomic::project`])
//! at the end of every segment: every output time of [`run`], every period
//! of a stream. The multipliers λ are the constraints' reactions, reported
//! by name.

use std::marker::PhantomData;

use nalgebra::{DMatrix, DVector};

use crate::linalg::Cholesky;
use crate::ode::any_size::fixed_state;
use crate::ode::holonomic::{
    project, restricted_monodromy, tangent_basis, ConstraintError, Holonomic, Projection,
};
use crate::tangent::monodromy::monodromy;
use crate::ode::{
    AnyOptions, AnySolution, AnySystem, Dual, Integrator, Method, OdeError, Scalar, SizedSystem,
    System,
};
use crate::registry::{ModelInfo, ParameterError};

/// What a generated constrained model gives at its own sizes (N
/// coordinates, K constraints), with its parameters: the model's module
/// implements it on its `Forms`.
pub trait ConstraintForms<const N: usize, const K: usize>: Clone + Sync + Send + 'static {
    fn from_values(params: &[f64]) -> Self;
    fn info() -> &'static ModelInfo;
    /// The names of the constraints, whose multipliers are their reactions.
    fn constraint_names() -> &'static [&'static str];
    /// Which constraints are holonomic (position constraints).
    fn holonomic() -> [bool; K];
    /// Which coordinates are angles.
    fn periodic() -> [bool; N];
    /// The model file's starts of the coordinates.
    fn start(&self) -> [f64; N];
    /// The period of the fast phase, if there is one.
    fn phase_period(&self) -> Option<f64>;
    fn mass_matrix(&self, t: f64, q: &[f64; N]) -> [[f64; N]; N];
    fn free_forces(&self, t: f64, q: &[f64; N], v: &[f64; N]) -> [f64; N];
    /// g of each position constraint (0 for a velocity constraint).
    fn position_residuals(&self, t: f64, q: &[f64; N]) -> [f64; K];
    /// G of the velocity forms c = G q' + c_t.
    fn constraint_jacobian(&self, t: f64, q: &[f64; N]) -> [[f64; N]; K];
    /// c_t of the velocity forms.
    fn constraint_rates(&self, t: f64, q: &[f64; N]) -> [f64; K];
    /// h in d/dt c = G q'' + h.
    fn constraint_bias(&self, t: f64, q: &[f64; N], v: &[f64; N]) -> [f64; K];
    /// The energy function Σ q'∂L/∂q' − L.
    fn energy(&self, t: f64, q: &[f64; N], v: &[f64; N]) -> f64;
    /// The forms the accelerations need, over dual numbers (for the
    /// Jacobian of the equations of motion).
    fn mass_matrix_dual(&self, t: f64, q: &[Dual; N]) -> [[Dual; N]; N];
    fn free_forces_dual(&self, t: f64, q: &[Dual; N], v: &[Dual; N]) -> [Dual; N];
    fn constraint_jacobian_dual(&self, t: f64, q: &[Dual; N]) -> [[Dual; N]; K];
    fn constraint_rates_dual(&self, t: f64, q: &[Dual; N]) -> [Dual; K];
    fn constraint_bias_dual(&self, t: f64, q: &[Dual; N], v: &[Dual; N]) -> [Dual; K];
}

/// q'' and λ of M q'' = F + Gᵀλ, G q'' + h = 0 by the Schur complement:
/// λ = (G M⁻¹ Gᵀ)⁻¹ (−h − G M⁻¹ F), q'' = M⁻¹ (F + Gᵀλ). NaN where M or
/// G M⁻¹ Gᵀ is not positive definite.
#[inline]
fn solve_constrained<Num: Scalar, const N: usize, const K: usize>(
    mass: [[Num; N]; N],
    g: [[Num; N]; K],
    free: [Num; N],
    h: [Num; K],
) -> ([Num; N], [Num; K]) {
    let mass = Cholesky::new(mass);
    // M⁻¹Gᵀ, column by column.
    let m_inv_gt: [[Num; N]; K] = std::array::from_fn(|r| mass.solve(g[r]));
    let schur: [[Num; K]; K] =
        std::array::from_fn(|r| std::array::from_fn(|c| dot(&g[r], &m_inv_gt[c])));
    let m_inv_f = mass.solve(free);
    let rhs: [Num; K] = std::array::from_fn(|r| -h[r] - dot(&g[r], &m_inv_f));
    let lambda = Cholesky::new(schur).solve(rhs);
    let accelerations = std::array::from_fn(|i| {
        let mut a = m_inv_f[i];
        for r in 0..K {
            a += m_inv_gt[r][i] * lambda[r];
        }
        a
    });
    (accelerations, lambda)
}

/// The equations of motion of constrained forms `F` as an ODE on
/// y = [q; q'] of length S = 2N.
#[derive(Clone, Debug)]
pub struct OnConstraints<F, const N: usize, const K: usize, const S: usize>(pub F);

impl<F: ConstraintForms<N, K>, const N: usize, const K: usize, const S: usize>
    OnConstraints<F, N, K, S>
{
    /// The forms at `params`; S must be 2N.
    pub fn new(forms: F) -> Self {
        const { assert!(S == 2 * N, "the state of a constrained model is [q; q']") };
        OnConstraints(forms)
    }

    fn split(y: &[f64; S]) -> ([f64; N], [f64; N]) {
        (
            std::array::from_fn(|i| y[i]),
            std::array::from_fn(|i| y[N + i]),
        )
    }

    /// The accelerations q'' and the multipliers λ at (t, y), by the Schur
    /// complement: λ = (G M⁻¹ Gᵀ)⁻¹ (−h − G M⁻¹ F), q'' = M⁻¹ (F + Gᵀλ).
    /// NaN where M or G M⁻¹ Gᵀ is not positive definite (the integrators
    /// then stop with the state: a degenerate configuration).
    pub fn accelerations(&self, t: f64, y: &[f64; S]) -> ([f64; N], [f64; K]) {
        let (q, v) = Self::split(y);
        let forms = &self.0;
        solve_constrained(
            forms.mass_matrix(t, &q),
            forms.constraint_jacobian(t, &q),
            forms.free_forces(t, &q, &v),
            forms.constraint_bias(t, &q, &v),
        )
    }

    /// max |g| over the position constraints and max |G q' + c_t| over all.
    pub fn residuals(&self, t: f64, y: &[f64; S]) -> (f64, f64) {
        let (q, v) = Self::split(y);
        let position = self
            .0
            .position_residuals(t, &q)
            .iter()
            .fold(0.0_f64, |m, x| m.max(x.abs()));
        let g = self.0.constraint_jacobian(t, &q);
        let rates = self.0.constraint_rates(t, &q);
        let velocity = (0..K).fold(0.0_f64, |m, r| m.max((dot(&g[r], &v) + rates[r]).abs()));
        (position, velocity)
    }
}

#[inline]
fn dot<Num: Scalar, const N: usize>(a: &[Num; N], b: &[Num; N]) -> Num {
    let mut sum = Num::from(0.0);
    for (x, y) in a.iter().zip(b) {
        sum += *x * *y;
    }
    sum
}

impl<F: ConstraintForms<N, K>, const N: usize, const K: usize, const S: usize> System<S>
    for OnConstraints<F, N, K, S>
{
    #[inline]
    fn rhs(&self, t: f64, y: &[f64; S]) -> [f64; S] {
        let (accelerations, _) = self.accelerations(t, y);
        std::array::from_fn(|i| if i < N { y[N + i] } else { accelerations[i - N] })
    }

    /// Exact to round-off: the accelerations over dual numbers, one
    /// column of the Jacobian a pass.
    fn jacobian(&self, t: f64, y: &[f64; S]) -> Option<[[f64; S]; S]> {
        let forms = &self.0;
        let mut jacobian = [[0.0; S]; S];
        for column in 0..S {
            let seeded =
                |i: usize| Dual::seeded(y[i], if i == column { 1.0 } else { 0.0 });
            let q: [Dual; N] = std::array::from_fn(seeded);
            let v: [Dual; N] = std::array::from_fn(|i| seeded(N + i));
            let (accelerations, _) = solve_constrained(
                forms.mass_matrix_dual(t, &q),
                forms.constraint_jacobian_dual(t, &q),
                forms.free_forces_dual(t, &q, &v),
                forms.constraint_bias_dual(t, &q, &v),
            );
            for i in 0..N {
                jacobian[i][column] = if N + i == column { 1.0 } else { 0.0 };
                jacobian[N + i][column] = accelerations[i].du;
            }
        }
        Some(jacobian)
    }
}

impl<F: ConstraintForms<N, K>, const N: usize, const K: usize, const S: usize> Holonomic
    for OnConstraints<F, N, K, S>
{
    fn coordinates(&self) -> usize {
        N
    }
    fn residual(&self, t: f64, q: &[f64]) -> DVector<f64> {
        let q = fixed_state::<N>(q).expect("the projection passes n coordinates");
        DVector::from_column_slice(&self.0.position_residuals(t, &q))
    }
    fn jacobian(&self, t: f64, q: &[f64]) -> (DMatrix<f64>, DVector<f64>) {
        let q = fixed_state::<N>(q).expect("the projection passes n coordinates");
        let g = self.0.constraint_jacobian(t, &q);
        (
            DMatrix::from_fn(K, N, |r, c| g[r][c]),
            DVector::from_column_slice(&self.0.constraint_rates(t, &q)),
        )
    }
    fn mass(&self, t: f64, q: &[f64]) -> DMatrix<f64> {
        let q = fixed_state::<N>(q).expect("the projection passes n coordinates");
        let m = self.0.mass_matrix(t, &q);
        DMatrix::from_fn(N, N, |r, c| m[r][c])
    }
}

/// How closely a projection brings a state onto the constraints: Newton's
/// method stops at |g| ≤ 1e-14 times the state's size.
pub const PROJECTION_TOLERANCE: f64 = 1e-14;

impl<F: ConstraintForms<N, K>, const N: usize, const K: usize, const S: usize>
    OnConstraints<F, N, K, S>
{
    /// The Jacobian (2k × 2n) of the state's constraints [g; G q' + c_t]
    /// with respect to [q; q'] (a velocity constraint has no position
    /// row: its row of g is zero), exact by dual numbers.
    pub fn state_constraints_jacobian(&self, t: f64, y: &[f64; S]) -> DMatrix<f64> {
        let (q, v) = Self::split(y);
        let forms = &self.0;
        let holonomic = F::holonomic();
        let g = forms.constraint_jacobian(t, &q);
        let rows: Vec<usize> = (0..K).filter(|&r| holonomic[r]).collect();
        let mut c = DMatrix::zeros(rows.len() + K, S);
        for (row, &r) in rows.iter().enumerate() {
            for j in 0..N {
                c[(row, j)] = g[r][j];
            }
        }
        for j in 0..N {
            let q_dual: [Dual; N] =
                std::array::from_fn(|i| Dual::seeded(q[i], if i == j { 1.0 } else { 0.0 }));
            let g_dual = forms.constraint_jacobian_dual(t, &q_dual);
            let rates = forms.constraint_rates_dual(t, &q_dual);
            for r in 0..K {
                let mut velocity_form = rates[r];
                for (entry, vk) in g_dual[r].iter().zip(&v) {
                    velocity_form += *entry * *vk;
                }
                c[(rows.len() + r, j)] = velocity_form.du;
                c[(rows.len() + r, N + j)] = g[r][j];
            }
        }
        c
    }
}

/// A constrained model's equations as an [`AnySystem`] whose stream
/// projects the state onto the constraints at every segment's end (before
/// the analysis sees it), so that a period map of 10⁵ periods stays on them.
pub struct Projecting<F, const N: usize, const K: usize, const S: usize> {
    system: SizedSystem<OnConstraints<F, N, K, S>, S>,
}

impl<F: ConstraintForms<N, K>, const N: usize, const K: usize, const S: usize> AnySystem
    for Projecting<F, N, K, S>
{
    fn dim(&self) -> usize {
        S
    }
    fn rhs(&self, t: f64, y: &[f64]) -> Result<Vec<f64>, OdeError> {
        self.system.rhs(t, y)
    }
    fn jacobian(&self, t: f64, y: &[f64]) -> Result<Option<DMatrix<f64>>, OdeError> {
        self.system.jacobian(t, y)
    }
    fn solve(
        &self,
        integrator: &mut Integrator,
        t0: f64,
        y0: &[f64],
        t1: f64,
        options: AnyOptions<'_>,
    ) -> Result<AnySolution, OdeError> {
        self.system.solve(integrator, t0, y0, t1, options)
    }
    fn stream(
        &self,
        integrator: &mut Integrator,
        y0: &[f64],
        segment: f64,
        segments: usize,
        after: &mut dyn FnMut(&mut [f64]) -> bool,
    ) -> Result<(), OdeError> {
        let mut t = 0.0;
        let equations = &self.system.0;
        let mut failure = None;
        self.system.stream(integrator, y0, segment, segments, &mut |y| {
            t += segment;
            if let Err(e) = project(equations, t, y, PROJECTION_TOLERANCE * size(y)) {
                failure = Some(e);
                return false;
            }
            after(y)
        })?;
        match failure {
            Some(ConstraintError::NoConvergence { .. }) | Some(ConstraintError::Singular { .. }) => {
                Err(OdeError::NonFinite {
                    t,
                    y: vec![f64::NAN; S],
                })
            }
            _ => Ok(()),
        }
    }
}

/// 1 + the largest |component| of a state: the scale of its residuals.
fn size(y: &[f64]) -> f64 {
    1.0 + y.iter().fold(0.0_f64, |m, x| m.max(x.abs()))
}

/// A constrained model with states and parameters as slices: what the
/// registry lists and [`run`] and the analyses by name take.
pub trait ConstrainedSystems: Sync {
    fn info(&self) -> &'static ModelInfo;
    /// The constraints' names (their reactions' labels).
    fn constraint_names(&self) -> &'static [&'static str];
    /// Which constraints are holonomic.
    fn holonomic(&self) -> Vec<bool>;
    /// Which components of the state [q; q'] are angles.
    fn periodic_state(&self) -> Vec<bool>;
    /// The model file's start at rest, [q_start; 0] (not yet projected:
    /// a moving constraint may need velocities).
    fn start(&self, params: &[f64]) -> Vec<f64>;
    /// The period of the fast phase, if there is one.
    fn phase_period(&self, params: &[f64]) -> Option<f64>;
    /// The equations of motion; their stream projects at segments' ends.
    fn exact(&self, params: &[f64]) -> Box<dyn AnySystem>;
    /// Moves `y` onto the constraints at time t (see [`project`]).
    fn project(
        &self,
        params: &[f64],
        t: f64,
        y: &mut [f64],
    ) -> Result<Projection, ConstraintError>;
    /// The multipliers λ at (t, y): the constraints' reactions, in the
    /// units of their rows (for a rod written as |x − x₀|² − l² = 0, λ
    /// times the gradient 2(x − x₀) is the force on the point).
    fn reactions(&self, params: &[f64], t: f64, y: &[f64]) -> Result<Vec<f64>, OdeError>;
    /// (max |g|, max |G q' + c_t|) at (t, y).
    fn residuals(&self, params: &[f64], t: f64, y: &[f64]) -> Result<(f64, f64), OdeError>;
    fn energy(&self, params: &[f64], t: f64, y: &[f64]) -> Result<f64, OdeError>;
    /// An orthonormal basis (columns) of the tangent space of the
    /// constrained phase space at (t, y), or None where the constraints
    /// are degenerate.
    fn tangent_basis(
        &self,
        params: &[f64],
        t: f64,
        y: &[f64],
    ) -> Result<Option<DMatrix<f64>>, OdeError>;
    /// The state after `period` from `y0` and the monodromy matrix
    /// ∂y(T)/∂y(0) of the full state [q; q'] (2n × 2n).
    fn monodromy(
        &self,
        params: &[f64],
        integrator: &mut Integrator,
        period: f64,
        y0: &[f64],
    ) -> Result<(Vec<f64>, DMatrix<f64>), OdeError>;
}

/// The generated forms `F` at their sizes as [`ConstrainedSystems`] (the
/// model's module holds one in a static).
/// V = S + S² is the state with its monodromy's columns.
pub struct Constrained<F, const N: usize, const K: usize, const S: usize, const V: usize>(
    PhantomData<fn() -> F>,
);

impl<F, const N: usize, const K: usize, const S: usize, const V: usize> Constrained<F, N, K, S, V> {
    pub const fn new() -> Self {
        Constrained(PhantomData)
    }
}

impl<F, const N: usize, const K: usize, const S: usize, const V: usize> Default
    for Constrained<F, N, K, S, V>
{
    fn default() -> Self {
        Self::new()
    }
}

impl<F: ConstraintForms<N, K>, const N: usize, const K: usize, const S: usize, const V: usize>
    Constrained<F, N, K, S, V>
{
    fn equations(params: &[f64]) -> OnConstraints<F, N, K, S> {
        OnConstraints::new(F::from_values(params))
    }
}

impl<F: ConstraintForms<N, K>, const N: usize, const K: usize, const S: usize, const V: usize>
    ConstrainedSystems for Constrained<F, N, K, S, V>
{
    fn info(&self) -> &'static ModelInfo {
        F::info()
    }
    fn constraint_names(&self) -> &'static [&'static str] {
        F::constraint_names()
    }
    fn holonomic(&self) -> Vec<bool> {
        F::holonomic().to_vec()
    }
    fn periodic_state(&self) -> Vec<bool> {
        let periodic = F::periodic();
        (0..S).map(|i| i < N && periodic[i]).collect()
    }
    fn start(&self, params: &[f64]) -> Vec<f64> {
        let mut y = F::from_values(params).start().to_vec();
        y.resize(S, 0.0);
        y
    }
    fn phase_period(&self, params: &[f64]) -> Option<f64> {
        F::from_values(params).phase_period()
    }
    fn exact(&self, params: &[f64]) -> Box<dyn AnySystem> {
        Box::new(Projecting {
            system: SizedSystem(Self::equations(params)),
        })
    }
    fn project(
        &self,
        params: &[f64],
        t: f64,
        y: &mut [f64],
    ) -> Result<Projection, ConstraintError> {
        if y.len() != S {
            return Err(ConstraintError::StateLength {
                given: y.len(),
                coordinates: N,
            });
        }
        let tolerance = PROJECTION_TOLERANCE * size(y);
        project(&Self::equations(params), t, y, tolerance)
    }
    fn reactions(&self, params: &[f64], t: f64, y: &[f64]) -> Result<Vec<f64>, OdeError> {
        let y = fixed_state::<S>(y)?;
        Ok(Self::equations(params).accelerations(t, &y).1.to_vec())
    }
    fn residuals(&self, params: &[f64], t: f64, y: &[f64]) -> Result<(f64, f64), OdeError> {
        let y = fixed_state::<S>(y)?;
        Ok(Self::equations(params).residuals(t, &y))
    }
    fn energy(&self, params: &[f64], t: f64, y: &[f64]) -> Result<f64, OdeError> {
        let y = fixed_state::<S>(y)?;
        let (q, v) = OnConstraints::<F, N, K, S>::split(&y);
        Ok(F::from_values(params).energy(t, &q, &v))
    }
    fn tangent_basis(
        &self,
        params: &[f64],
        t: f64,
        y: &[f64],
    ) -> Result<Option<DMatrix<f64>>, OdeError> {
        let y = fixed_state::<S>(y)?;
        let c = Self::equations(params).state_constraints_jacobian(t, &y);
        Ok(tangent_basis(&c))
    }
    fn monodromy(
        &self,
        params: &[f64],
        integrator: &mut Integrator,
        period: f64,
        y0: &[f64],
    ) -> Result<(Vec<f64>, DMatrix<f64>), OdeError> {
        let y0 = fixed_state::<S>(y0)?;
        let system = Self::equations(params);
        let (end, m) = monodromy::<_, S, V>(integrator, &system, period, &y0)?;
        Ok((end.to_vec(), DMatrix::from_fn(S, S, |i, k| m[i][k])))
    }
}

/// The monodromy matrix of the periodic orbit through the consistent state
/// `y0` restricted to the constraints' tangent space (2(n − k) for k
/// holonomic constraints): Zᵀ Φ Z with Z an orthonormal basis there, whose
/// eigenvalues are the Floquet multipliers on the constraints, without the
/// spurious ones of the directions the constraints forbid. Also the state
/// after the period.
pub fn monodromy_on_constraints(
    model: &dyn ConstrainedSystems,
    params: &[f64],
    method: Method,
    period: f64,
    y0: &[f64],
) -> Result<(Vec<f64>, DMatrix<f64>), ConstrainedError> {
    let name = model.info().name;
    let mut integrator = Integrator::new(method)?;
    let (end, full) = model.monodromy(params, &mut integrator, period, y0)?;
    let basis = model
        .tangent_basis(params, 0.0, y0)?
        .ok_or_else(|| ConstrainedError::Constraint {
            model: name,
            t: 0.0,
            source: ConstraintError::Singular { q: y0.to_vec() },
        })?;
    Ok((end, restricted_monodromy(&full, &basis)))
}

/// Why a constrained run stopped.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ConstrainedError {
    #[error(transparent)]
    Ode(#[from] OdeError),
    /// No consistent state near the start, or degenerate constraints on
    /// the way (with the time).
    #[error("model '{model}' at t = {t}: {source}")]
    Constraint {
        model: &'static str,
        t: f64,
        source: ConstraintError,
    },
    #[error(transparent)]
    Parameter(#[from] ParameterError),
    /// Output times that do not increase from the start.
    #[error("the output times must increase from t0 = {t0} and be finite")]
    Times { t0: f64 },
}

/// A run on the constraints: at each output time the state (projected),
/// the reactions, the energy function, and the residuals the integration
/// had left before that projection (the drift one segment allows).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ConstrainedRun {
    pub model: &'static str,
    pub constraint_names: Vec<&'static str>,
    /// The start after its projection onto the constraints.
    pub start: Vec<f64>,
    pub times: Vec<f64>,
    pub states: Vec<Vec<f64>>,
    pub reactions: Vec<Vec<f64>>,
    pub energy: Vec<f64>,
    /// Largest (|g|, |G q' + c_t|) found at a segment's end before its
    /// projection.
    pub largest_drift: (f64, f64),
    /// Largest residuals after the projections.
    pub largest_residual: (f64, f64),
    pub steps: u64,
}

/// Runs `model` from `y0` (the model file's start at rest if None; made
/// consistent by projection) at t0 = times[0] through the output `times`,
/// projecting at each of them.
pub fn run(
    model: &dyn ConstrainedSystems,
    params: &[f64],
    y0: Option<&[f64]>,
    method: Method,
    times: &[f64],
) -> Result<ConstrainedRun, ConstrainedError> {
    let name = model.info().name;
    let t0 = times.first().copied().unwrap_or(0.0);
    if times.iter().any(|t| !t.is_finite()) || times.windows(2).any(|w| !(w[1] > w[0])) {
        return Err(ConstrainedError::Times { t0 });
    }
    let constraint = |t: f64| move |source| ConstrainedError::Constraint { model: name, t, source };
    let mut y = match y0 {
        Some(y0) => y0.to_vec(),
        None => model.start(params),
    };
    if y.iter().any(|x| !x.is_finite()) {
        return Err(OdeError::NonFiniteInitialState { t: t0, y }.into());
    }
    model.project(params, t0, &mut y).map_err(constraint(t0))?;
    let system = model.exact(params);
    let mut integrator = Integrator::new(method)?;
    let mut result = ConstrainedRun {
        model: name,
        constraint_names: model.constraint_names().to_vec(),
        start: y.clone(),
        times: Vec::new(),
        states: Vec::new(),
        reactions: Vec::new(),
        energy: Vec::new(),
        largest_drift: (0.0, 0.0),
        largest_residual: (0.0, 0.0),
        steps: 0,
    };
    let mut t = t0;
    for &t1 in times {
        if t1 > t {
            y = system
                .solve(&mut integrator, t, &y, t1, AnyOptions::default())?
                .y;
            let drift = model.residuals(params, t1, &y)?;
            result.largest_drift = larger(result.largest_drift, drift);
            model.project(params, t1, &mut y).map_err(constraint(t1))?;
            t = t1;
        }
        result.largest_residual = larger(result.largest_residual, model.residuals(params, t, &y)?);
        result.times.push(t);
        result.reactions.push(model.reactions(params, t, &y)?);
        result.energy.push(model.energy(params, t, &y)?);
        result.states.push(y.clone());
    }
    result.steps = integrator.stats.steps;
    Ok(result)
}

fn larger(a: (f64, f64), b: (f64, f64)) -> (f64, f64) {
    (a.0.max(b.0), a.1.max(b.1))
}
