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
//! at the end of every segment: every output time of a run
//! (`analysis::on_constraints::run`), every period of a stream
//! ([`Projecting`]). The multipliers λ are the constraints' reactions.
//! The registry lists such a model through
//! [`crate::registry::ConstrainedSystems`].

pub mod averaged;

use nalgebra::{DMatrix, DVector};

use crate::linalg::{Cholesky, REDUNDANT};
use crate::ode::any_size::fixed_state;
use crate::ode::holonomic::{ConstraintError, Holonomic, Projection};
use crate::ode::{
    AnyOptions, AnySolution, AnySystem, Dual, Integrator, Lanes, OdeError, Scalar, SizedSystem,
    System, TaylorWork, LANES,
};

/// What a generated constrained model gives, as plain functions of its
/// parameters' values at its sizes (N coordinates, K constraints, the
/// state S = 2N); the model's module holds one in a static (`FORMS`).
/// The runtime takes the forms through this table, not as a type of their
/// own, so its integrators and analyses are compiled once per size, not
/// once per model: adding a model compiles only its own forms.
pub struct FormsTable<const N: usize, const K: usize, const S: usize> {
    /// The constraints' names, whose multipliers are their reactions.
    pub constraint_names: &'static [&'static str],
    /// Which constraints are holonomic (position constraints).
    pub holonomic: [bool; K],
    /// Which coordinates are angles.
    pub periodic: [bool; N],
    pub has_fast_phase: bool,
    /// Whether the constraints are holonomic and fixed and M does not
    /// move with the phase (the averaging's conditions).
    pub stationary: bool,
    /// Whether M is singular at the starts (massless parts): [`Forms`]
    /// then gives M + α GᵀG for M and F − α Gᵀh for F (α = tr M / tr
    /// GᵀG), regular where M is on the constraints' motions, with the
    /// same accelerations and reactions, as the generated field does.
    pub massless: bool,
    /// The model file's starts of the coordinates.
    pub start: fn(&[f64]) -> [f64; N],
    /// Their starting rates (0 where the file gives none), and which the
    /// file gives: those are held when the start is made consistent.
    pub start_rates: fn(&[f64]) -> [f64; N],
    pub rates_given: [bool; N],
    /// The period of the fast phase, if there is one.
    pub phase_period: fn(&[f64]) -> Option<f64>,
    /// The field [q'; q''] at (t, y), its forms evaluated together.
    pub rhs: fn(&[f64], f64, &[f64; S]) -> [f64; S],
    pub mass_matrix: fn(&[f64], f64, &[f64; N]) -> [[f64; N]; N],
    pub free_forces: fn(&[f64], f64, &[f64; N], &[f64; N]) -> [f64; N],
    /// g of each position constraint (0 for a velocity constraint).
    pub position_residuals: fn(&[f64], f64, &[f64; N]) -> [f64; K],
    /// G of the velocity forms c = G q' + c_t.
    pub constraint_jacobian: fn(&[f64], f64, &[f64; N]) -> [[f64; N]; K],
    /// c_t of the velocity forms.
    pub constraint_rates: fn(&[f64], f64, &[f64; N]) -> [f64; K],
    /// h in d/dt c = G q'' + h.
    pub constraint_bias: fn(&[f64], f64, &[f64; N], &[f64; N]) -> [f64; K],
    /// The energy function Σ q'∂L/∂q' − L.
    pub energy: fn(&[f64], f64, &[f64; N], &[f64; N]) -> f64,
    /// V = −L and b = ∂L/∂q' at q' = 0, at time t (for the averaging).
    pub potential: fn(&[f64], f64, &[f64; N]) -> f64,
    pub linear_term: fn(&[f64], f64, &[f64; N]) -> [f64; N],
    /// G and c_t over dual numbers (the derivatives of the velocity forms
    /// and the constraints' curvature).
    pub constraint_jacobian_dual: fn(&[f64], f64, &[Dual; N]) -> [[Dual; N]; K],
    pub constraint_rates_dual: fn(&[f64], f64, &[Dual; N]) -> [Dual; K],
    /// ∂f/∂y of the field, exact to round-off (by dual numbers).
    pub jacobian: fn(&[f64], f64, &[f64; S]) -> [[f64; S]; S],
    /// The generated Taylor recurrences, for a model of at most
    /// `TAYLOR_COORDINATES` (6) coordinates whose recurrences are at most
    /// `TAYLOR_SOURCE_BYTES` (300 kB) long.
    pub recurrences: Option<Recurrences<S>>,
}

/// The generated Taylor recurrences of the motion on the constraints
/// through (t, y), y = [q; q'] (see `crate::ode::System::taylor`), in f64
/// (a batch runs them lane by lane), and with tangent vectors z = [y; V]
/// (see `crate::ode::System::taylor_variational`).
pub struct Recurrences<const S: usize> {
    pub taylor: TaylorOf<f64, S>,
    pub taylor_variational: fn(&[f64], f64, &[f64], usize, &mut TaylorWork<f64>, &mut [f64]),
}

thread_local! {
    /// The f64 workspace a batch's lanes share, one after the other.
    static LANE_WORK: std::cell::RefCell<TaylorWork<f64>> = Default::default();
}

/// A model's Taylor recurrences in the number type `Num`.
pub type TaylorOf<Num, const S: usize> =
    fn(&[f64], Num, &[Num; S], usize, &mut TaylorWork<Num>, &mut [[Num; S]]);

/// A constrained model's forms at its parameters' values.
#[derive(Clone)]
pub struct Forms<const N: usize, const K: usize, const S: usize> {
    pub table: &'static FormsTable<N, K, S>,
    pub params: Vec<f64>,
}

impl<const N: usize, const K: usize, const S: usize> std::fmt::Debug for Forms<N, K, S> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Forms")
            .field("constraints", &self.table.constraint_names)
            .field("params", &self.params)
            .finish()
    }
}

impl<const N: usize, const K: usize, const S: usize> Forms<N, K, S> {
    pub fn new(table: &'static FormsTable<N, K, S>, params: &[f64]) -> Self {
        Forms {
            table,
            params: params.to_vec(),
        }
    }
    pub fn start(&self) -> [f64; N] {
        (self.table.start)(&self.params)
    }
    pub fn phase_period(&self) -> Option<f64> {
        (self.table.phase_period)(&self.params)
    }
    /// M, or M + α GᵀG for a model with massless parts.
    #[inline]
    pub fn mass_matrix(&self, t: f64, q: &[f64; N]) -> [[f64; N]; N] {
        let mut mass = (self.table.mass_matrix)(&self.params, t, q);
        if self.table.massless {
            let (alpha, g) = self.augmentation(t, q, &mass);
            for (i, row) in mass.iter_mut().enumerate() {
                for (j, m) in row.iter_mut().enumerate() {
                    *m += alpha * g.iter().map(|r| r[i] * r[j]).sum::<f64>();
                }
            }
        }
        mass
    }
    /// α = tr M / tr GᵀG at (t, q) with M the model's own `mass`, and G:
    /// the weight of GᵀG added to a singular M, of M's size whatever the
    /// constraints' units (the generated field's `augmentation`).
    fn augmentation(&self, t: f64, q: &[f64; N], mass: &[[f64; N]; N]) -> (f64, [[f64; N]; K]) {
        let g = self.constraint_jacobian(t, q);
        let trace: f64 = (0..N).map(|i| mass[i][i]).sum();
        (trace / g.iter().flatten().map(|x| x * x).sum::<f64>(), g)
    }
    /// F, or F − α Gᵀh for a model with massless parts.
    #[inline]
    pub fn free_forces(&self, t: f64, q: &[f64; N], v: &[f64; N]) -> [f64; N] {
        let mut free = (self.table.free_forces)(&self.params, t, q, v);
        if self.table.massless {
            let mass = (self.table.mass_matrix)(&self.params, t, q);
            let (alpha, g) = self.augmentation(t, q, &mass);
            let h = self.constraint_bias(t, q, v);
            for (i, f) in free.iter_mut().enumerate() {
                *f -= alpha * g.iter().zip(&h).map(|(r, h)| r[i] * h).sum::<f64>();
            }
        }
        free
    }
    #[inline]
    pub fn position_residuals(&self, t: f64, q: &[f64; N]) -> [f64; K] {
        (self.table.position_residuals)(&self.params, t, q)
    }
    #[inline]
    pub fn constraint_jacobian(&self, t: f64, q: &[f64; N]) -> [[f64; N]; K] {
        (self.table.constraint_jacobian)(&self.params, t, q)
    }
    #[inline]
    pub fn constraint_rates(&self, t: f64, q: &[f64; N]) -> [f64; K] {
        (self.table.constraint_rates)(&self.params, t, q)
    }
    #[inline]
    pub fn constraint_bias(&self, t: f64, q: &[f64; N], v: &[f64; N]) -> [f64; K] {
        (self.table.constraint_bias)(&self.params, t, q, v)
    }
    pub fn energy(&self, t: f64, q: &[f64; N], v: &[f64; N]) -> f64 {
        (self.table.energy)(&self.params, t, q, v)
    }
    pub fn potential(&self, t: f64, q: &[f64; N]) -> f64 {
        (self.table.potential)(&self.params, t, q)
    }
    pub fn linear_term(&self, t: f64, q: &[f64; N]) -> [f64; N] {
        (self.table.linear_term)(&self.params, t, q)
    }
    pub fn constraint_jacobian_dual(&self, t: f64, q: &[Dual; N]) -> [[Dual; N]; K] {
        (self.table.constraint_jacobian_dual)(&self.params, t, q)
    }
    pub fn constraint_rates_dual(&self, t: f64, q: &[Dual; N]) -> [Dual; K] {
        (self.table.constraint_rates_dual)(&self.params, t, q)
    }

    /// The recurrences in `Num` where the model has them and `Num` is f64
    /// (false otherwise). The coefficients go through a buffer of f64, a
    /// copy small beside the recurrences.
    fn taylor<Num: Scalar>(
        &self,
        t: Num,
        y: &[Num; S],
        order: usize,
        work: &mut TaylorWork<Num>,
        out: &mut [[Num; S]],
    ) -> bool {
        use std::any::Any;
        let (Some(recurrences), Some(&t), Some(y), Some(work)) = (
            &self.table.recurrences,
            (&t as &dyn Any).downcast_ref::<f64>(),
            (y as &dyn Any).downcast_ref::<[f64; S]>(),
            (work as &mut dyn Any).downcast_mut::<TaylorWork<f64>>(),
        ) else {
            return false;
        };
        let mut coefficients = vec![[0.0; S]; out.len()];
        (recurrences.taylor)(&self.params, t, y, order, work, &mut coefficients);
        for (row, computed) in out.iter_mut().zip(coefficients) {
            if let Some(row) = (row as &mut dyn Any).downcast_mut::<[f64; S]>() {
                *row = computed;
            }
        }
        true
    }
}

/// q'' and λ of M q'' = F + Gᵀλ, G q'' + h = 0 by the Schur complement:
/// λ = (G M⁻¹ Gᵀ)⁻¹ (−h − G M⁻¹ F), q'' = M⁻¹ (F + Gᵀλ); redundant
/// constraints' rows skipped (their λ 0). NaN where M is not positive
/// definite.
#[inline]
pub(crate) fn solve_constrained<Num: Scalar, const N: usize, const K: usize>(
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
    let lambda = Cholesky::semidefinite(schur).solve(rhs);
    let accelerations = std::array::from_fn(|i| {
        let mut a = m_inv_f[i];
        for r in 0..K {
            a += m_inv_gt[r][i] * lambda[r];
        }
        a
    });
    (accelerations, lambda)
}

/// The equations of motion of a constrained model's forms as an ODE on
/// y = [q; q'] of length S = 2N.
#[derive(Clone, Debug)]
pub struct OnConstraints<const N: usize, const K: usize, const S: usize>(pub Forms<N, K, S>);

impl<const N: usize, const K: usize, const S: usize> OnConstraints<N, K, S> {
    /// The forms at `params`; S must be 2N.
    pub fn new(forms: Forms<N, K, S>) -> Self {
        const { assert!(S == 2 * N, "the state of a constrained model is [q; q']") };
        OnConstraints(forms)
    }

    /// The coordinates and velocities of a state.
    pub fn split(y: &[f64; S]) -> ([f64; N], [f64; N]) {
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
pub(crate) fn dot<Num: Scalar, const N: usize>(a: &[Num; N], b: &[Num; N]) -> Num {
    let mut sum = Num::from(0.0);
    for (x, y) in a.iter().zip(b) {
        sum += *x * *y;
    }
    sum
}

impl<const N: usize, const K: usize, const S: usize> System<S> for OnConstraints<N, K, S> {
    #[inline]
    fn rhs(&self, t: f64, y: &[f64; S]) -> [f64; S] {
        (self.0.table.rhs)(&self.0.params, t, y)
    }

    /// Exact to round-off, by dual numbers (the model's table says how).
    fn jacobian(&self, t: f64, y: &[f64; S]) -> Option<[[f64; S]; S]> {
        Some((self.0.table.jacobian)(&self.0.params, t, y))
    }

    #[inline]
    fn taylor<Num: Scalar>(
        &self,
        t: Num,
        y: &[Num; S],
        order: usize,
        work: &mut TaylorWork<Num>,
        out: &mut [[Num; S]],
    ) -> bool {
        self.0.taylor(t, y, order, work, out)
    }

    #[inline]
    fn taylor_lanes(
        lanes: [&Self; LANES],
        t: Lanes,
        y: &[Lanes; S],
        order: usize,
        work: &mut TaylorWork<Lanes>,
        out: &mut [[Lanes; S]],
    ) -> bool {
        let Some(recurrences) = &lanes[0].0.table.recurrences else {
            return false;
        };
        // Each lane's recurrences in turn, in f64: generated over the lanes'
        // number type, the constrained solve's recurrences took 11 of a
        // slider–crank's 22 s of build, and a batch's cost is its steps.
        let _ = work;
        let mut lane_y = [0.0; S];
        let mut lane_out = vec![[0.0; S]; out.len()];
        LANE_WORK.with_borrow_mut(|lane_work| {
            for (l, system) in lanes.iter().enumerate() {
                for (x, v) in lane_y.iter_mut().zip(y) {
                    *x = v.0[l];
                }
                (recurrences.taylor)(
                    &system.0.params,
                    t.0[l],
                    &lane_y,
                    order,
                    lane_work,
                    &mut lane_out,
                );
                for (row, computed) in out.iter_mut().zip(&lane_out) {
                    for (o, c) in row.iter_mut().zip(computed) {
                        o.0[l] = *c;
                    }
                }
            }
        });
        true
    }

    #[inline]
    fn taylor_variational<Num: Scalar>(
        &self,
        t: Num,
        z: &[Num],
        order: usize,
        work: &mut TaylorWork<Num>,
        out: &mut [Num],
    ) -> bool {
        use std::any::Any;
        let Some(recurrences) = &self.0.table.recurrences else {
            return false;
        };
        if z.len() < 2 * S || !z.len().is_multiple_of(S) {
            return false;
        }
        // f64 only: the tangent recurrences are not asked in other types.
        let (Some(&t), Some(work)) = (
            (&t as &dyn Any).downcast_ref::<f64>(),
            (work as &mut dyn Any).downcast_mut::<TaylorWork<f64>>(),
        ) else {
            return false;
        };
        let mut flat = vec![0.0; out.len()];
        let z: Vec<f64> = z
            .iter()
            .map(|x| {
                (x as &dyn Any)
                    .downcast_ref::<f64>()
                    .copied()
                    .unwrap_or(f64::NAN)
            })
            .collect();
        (recurrences.taylor_variational)(&self.0.params, t, &z, order, work, &mut flat);
        for (slot, x) in out.iter_mut().zip(flat) {
            if let Some(slot) = (slot as &mut dyn Any).downcast_mut::<f64>() {
                *slot = x;
            }
        }
        true
    }

    #[inline]
    fn taylor_variational_lanes(
        lanes: [&Self; LANES],
        t: Lanes,
        z: &[Lanes],
        order: usize,
        _work: &mut TaylorWork<Lanes>,
        out: &mut [Lanes],
    ) -> bool {
        let Some(recurrences) = &lanes[0].0.table.recurrences else {
            return false;
        };
        if z.len() < 2 * S || !z.len().is_multiple_of(S) {
            return false;
        }
        crate::ode::dual::lane_by_lane(z, out, |l, z, out| {
            let forms = &lanes[l].0;
            (recurrences.taylor_variational)(
                &forms.params,
                t.0[l],
                z,
                order,
                &mut TaylorWork::default(),
                out,
            )
        });
        true
    }
}

impl<const N: usize, const K: usize, const S: usize> Holonomic for OnConstraints<N, K, S> {
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

/// How closely a projection brings a state onto the constraints (relative
/// to the coordinates' scale, see [`OnConstraints::position_tolerance`]).
pub const PROJECTION_TOLERANCE: f64 = 1e-14;

/// Whether a Newton step moves every coordinate by at most a few units in
/// the last place of the largest: if the residual then stops falling, the
/// positions are as close to the constraints as floating point puts them. An angle turned many times (a
/// coupler at 256 rad, whose last place is 5.7e-14) leaves a residual
/// above [`PROJECTION_TOLERANCE`] that no step can remove, and Newton's
/// method spreads its correction over every coordinate.
pub fn at_rounding(q: &[f64], step: &[f64]) -> bool {
    let largest = q.iter().fold(1.0_f64, |m, x| m.max(x.abs()));
    step.iter().all(|d| d.abs() <= 4.0 * f64::EPSILON * largest)
}

/// How many times the projection's tolerance a residual may stay when
/// Newton's steps have reached the coordinates' rounding ([`at_rounding`]):
/// beyond it, a step that small means rows skipped as dependent, not
/// rounding, and the state is refused.
pub const ROUNDING_RESIDUAL: f64 = 1e4;

impl<const N: usize, const K: usize, const S: usize> OnConstraints<N, K, S> {
    /// The Jacobian (2k × 2n) of the state's constraints [g; G q' + c_t]
    /// with respect to [q; q'] (a velocity constraint has no position
    /// row: its row of g is zero), exact by dual numbers.
    pub fn state_constraints_jacobian(&self, t: f64, y: &[f64; S]) -> DMatrix<f64> {
        let (q, v) = Self::split(y);
        let forms = &self.0;
        let holonomic = forms.table.holonomic;
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

/// At q: M's factor, M⁻¹Gᵀ and the factor of the Schur complement
/// G M⁻¹ Gᵀ, a row within `dependent` of the earlier rows' span skipped
/// ([`Cholesky::semidefinite_within`]): what a correction along the
/// constraints' normals, in the metric of M, takes.
struct Normals<const N: usize, const K: usize> {
    mass: Cholesky<f64, N>,
    m_inv_gt: [[f64; N]; K],
    schur: Cholesky<f64, K>,
    /// Each row's squared sine to the earlier kept rows' span, in the
    /// metric of M⁻¹ (0 for a vanished row).
    sines: [f64; K],
}

impl<const N: usize, const K: usize> Normals<N, K> {
    fn new(mass: [[f64; N]; N], g: &[[f64; N]; K], dependent: f64) -> Self {
        let mass = Cholesky::new(mass);
        let m_inv_gt: [[f64; N]; K] = std::array::from_fn(|r| mass.solve(g[r]));
        let schur: [[f64; K]; K] =
            std::array::from_fn(|r| std::array::from_fn(|c| dot(&g[r], &m_inv_gt[c])));
        let (schur, sines) = Cholesky::semidefinite_with_sines(schur, dependent);
        Normals {
            mass,
            m_inv_gt,
            schur,
            sines,
        }
    }

    /// M⁻¹Gᵀ (G M⁻¹ Gᵀ)⁻¹ r.
    fn along(&self, r: [f64; K]) -> [f64; N] {
        let mu = self.schur.solve(r);
        std::array::from_fn(|i| (0..K).map(|row| self.m_inv_gt[row][i] * mu[row]).sum())
    }
}

impl<const N: usize, const K: usize, const S: usize> OnConstraints<N, K, S> {
    /// [`crate::ode::holonomic::project`] at the model's sizes, without
    /// allocating (a run projects every reported state): positions by
    /// Newton's method in the metric of M until |g| ≤ `tolerance` (or its
    /// steps reach the coordinates' rounding, [`at_rounding`]), then
    /// velocities exactly.
    pub fn project(
        &self,
        t: f64,
        y: &mut [f64; S],
        tolerance: f64,
    ) -> Result<Projection, ConstraintError> {
        if !(tolerance.is_finite() && tolerance > 0.0) {
            return Err(ConstraintError::Tolerance { value: tolerance });
        }
        let forms = &self.0;
        // The correction −M⁻¹Gᵀ (G M⁻¹ Gᵀ)⁻¹ r, or why it does not exist.
        let correction = |q: &[f64; N], r: [f64; K]| -> Result<[f64; N], ConstraintError> {
            let g = forms.constraint_jacobian(t, q);
            let normals = Normals::new(forms.mass_matrix(t, q), &g, REDUNDANT);
            let step = normals.along(r).map(|x| -x);
            // No row left (G = 0) with a residual to remove: degenerate.
            let stalled = K > 0 && normals.schur.rank() == 0 && r.iter().any(|x| *x != 0.0);
            match step.iter().all(|x| x.is_finite()) && !stalled {
                true => Ok(step),
                false => Err(ConstraintError::Singular { q: q.to_vec() }),
            }
        };
        const MAX_STEPS: usize = 20;
        let (mut q, mut v) = Self::split(y);
        let mut newton_steps = 0;
        let (mut rounded, mut previous) = (false, f64::INFINITY);
        let position_residual = loop {
            let residual = forms.position_residuals(t, &q);
            let size = residual.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
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
            let step = correction(&q, residual)?;
            rounded = at_rounding(&q, &step);
            for (x, d) in q.iter_mut().zip(step) {
                *x += d;
            }
            newton_steps += 1;
        };
        let g = forms.constraint_jacobian(t, &q);
        let rates = forms.constraint_rates(t, &q);
        let velocity_form: [f64; K] = std::array::from_fn(|r| dot(&g[r], &v) + rates[r]);
        let step = correction(&q, velocity_form)?;
        for (x, d) in v.iter_mut().zip(step) {
            *x += d;
        }
        let velocity_residual =
            (0..K).fold(0.0_f64, |m, r| m.max((dot(&g[r], &v) + rates[r]).abs()));
        y[..N].copy_from_slice(&q);
        y[N..].copy_from_slice(&v);
        Ok(Projection {
            newton_steps,
            position_residual,
            velocity_residual,
        })
    }
}

/// The equations of motion made to pass singular positions, where rows
/// of G vanish or fall into the span of others (a parallelogram's links
/// aligned). There the accelerations of [`OnConstraints`] are ill
/// conditioned: a position off the constraints by δ moves them by about
/// δ/σ² (σ the vanishing singular value), and δ itself is known only to
/// the rounding of g divided by σ, so their noise grows as 1/σ³ and the
/// step size collapses before σ reaches 0. Here each evaluation
/// 1. projects the positions onto g = 0 (Newton's method in the metric
///    of M) and the velocities onto G q' + c_t = 0, so that a drift of the
///    integrated state never feeds the accelerations;
/// 2. takes G's rows at unit length, and lets a row whose length has
///    fallen below [`SINGULAR_WINDOW`] of its length at the run's start,
///    or whose direction lies within that angle of the earlier rows'
///    span, exert no reaction (its row is skipped).
///
/// The window is crossed in a time of about [`SINGULAR_WINDOW`] over the
/// mechanism's angular speed, in which the skipped reaction acts on the
/// motion only across the constraints, which the next evaluation's
/// projection takes back.
#[derive(Clone, Debug)]
pub struct PassingSingular<const N: usize, const K: usize, const S: usize> {
    pub equations: OnConstraints<N, K, S>,
    /// Below these lengths a row of G exerts no reaction.
    pub floors: [f64; K],
}

/// How far a singular position's window reaches: a row of G shorter than
/// this fraction of its length at the start, or within this angle (in
/// radians) of the earlier rows' span, is skipped. Narrower windows cost
/// more steps (the noise outside grows as the inverse cube of it), wider
/// ones more error: on the parallel cranks, 1e-3 kept the pendulum to
/// 6e-12 in 3,800 steps over 10 s, 3e-4 to 1.6e-11 in 35,000, 1e-2 to
/// only 3e-6.
pub const SINGULAR_WINDOW: f64 = 1e-3;

/// The tightest tolerance the passing equations are integrated at. Near
/// a singular position their noise grows as 1/σ³ (the rounding of g
/// divided by σ sets the positions, and the velocities and accelerations
/// divide by σ again), and at tighter tolerances DOP853 shrinks its steps
/// to resolve that noise: on the IFToMM N-four-bar over 10 s, six starts,
/// 1e-13 took up to 82,000 steps and once lost 1.6e-7 of the energy,
/// 3e-12 at most 2,400 steps and 4e-10, 1e-11 lost 1.4e-7 once.
pub const PASSING_TOLERANCE: f64 = 3e-12;

/// Over this many windows ([`SINGULAR_WINDOW`]) a row nearing a singular
/// position has its reaction faded out, so that the field stays smooth.
pub const SINGULAR_FADE: f64 = 2.0;

impl<const N: usize, const K: usize, const S: usize> PassingSingular<N, K, S> {
    /// G at q with its rows at unit length (their lengths returned), a
    /// row shorter than its floor times `widen` set to 0 (its length
    /// returned as 0).
    fn unit_rows(&self, t: f64, q: &[f64; N], widen: f64) -> ([[f64; N]; K], [f64; K]) {
        let mut g = self.equations.0.constraint_jacobian(t, q);
        let mut lengths = [0.0; K];
        for (r, row) in g.iter_mut().enumerate() {
            let length = dot(row, row).sqrt();
            // A NaN row stays NaN: never skipped as if it had vanished.
            lengths[r] = if length > widen * self.floors[r] || length.is_nan() {
                length
            } else {
                0.0
            };
            let scale = per_length(&lengths, r, 1.0);
            row.iter_mut().for_each(|x| *x *= scale);
        }
        (g, lengths)
    }

    /// The normals of the rows `g` kept at q, within the window times
    /// `widen`.
    fn normals(&self, t: f64, q: &[f64; N], g: &[[f64; N]; K], widen: f64) -> Normals<N, K> {
        let window = (widen * SINGULAR_WINDOW).powi(2);
        Normals::new(self.equations.0.mass_matrix(t, q), g, window)
    }

    /// Newton's method onto g = 0 from q, at most four steps, until a
    /// step is below the projections' tolerance: near a singular position
    /// the residual is below rounding while the positions are still off.
    fn onto_positions(&self, t: f64, q: &mut [f64; N], tolerance: f64) {
        for _ in 0..4 {
            let residual = self.equations.0.position_residuals(t, q);
            if residual.iter().all(|r| *r == 0.0) {
                return;
            }
            let (g, lengths) = self.unit_rows(t, q, 1.0);
            let scaled: [f64; K] = std::array::from_fn(|r| per_length(&lengths, r, residual[r]));
            let step = self.normals(t, q, &g, 1.0).along(scaled);
            let mut largest = 0.0_f64;
            for (x, d) in q.iter_mut().zip(step) {
                *x -= d;
                largest = largest.max(d.abs());
            }
            if largest <= tolerance {
                return;
            }
        }
    }

    /// [q'; q''] at (t, q, v), q on the constraints, with the rows kept
    /// within the window times `widen`; and how far (in windows) the
    /// nearest kept row is from being skipped (its length over its floor,
    /// or its sine to the earlier rows over the window).
    fn field(&self, t: f64, q: &[f64; N], v: &[f64; N], widen: f64) -> ([f64; S], f64) {
        let forms = &self.equations.0;
        let (g, lengths) = self.unit_rows(t, q, widen);
        let normals = self.normals(t, q, &g, widen);
        let rates = forms.constraint_rates(t, q);
        let broken: [f64; K] =
            std::array::from_fn(|r| dot(&g[r], v) + per_length(&lengths, r, rates[r]));
        let off = normals.along(broken);
        let v: [f64; N] = std::array::from_fn(|i| v[i] - off[i]);
        let free = normals.mass.solve(forms.free_forces(t, q, &v));
        let h = forms.constraint_bias(t, q, &v);
        let rhs: [f64; K] =
            std::array::from_fn(|r| -per_length(&lengths, r, h[r]) - dot(&g[r], &free));
        let reaction = normals.along(rhs);
        let mut out = [0.0; S];
        for i in 0..N {
            out[i] = v[i];
            out[N + i] = free[i] + reaction[i];
        }
        let nearest = (0..K)
            .filter(|&r| lengths[r] > 0.0 && normals.sines[r] > SINGULAR_WINDOW.powi(2))
            .map(|r| (lengths[r] / self.floors[r]).min(normals.sines[r].sqrt() / SINGULAR_WINDOW))
            .fold(f64::INFINITY, f64::min);
        (out, nearest)
    }
}

impl<const N: usize, const K: usize, const S: usize> System<S> for PassingSingular<N, K, S> {
    /// The field with the rows within the window skipped, faded smoothly
    /// into the one with the rows within [`SINGULAR_FADE`] windows skipped
    /// as a row nears its window: skipped at once, a row's reaction would
    /// jump, and DOP853 would shrink its steps to resolve the jump each
    /// time an evaluation fell inside the window.
    fn rhs(&self, t: f64, y: &[f64; S]) -> [f64; S] {
        let (mut q, v) = OnConstraints::<N, K, S>::split(y);
        self.onto_positions(t, &mut q, self.equations.position_tolerance(y));
        let (kept, nearest) = self.field(t, &q, &v, 1.0);
        if !(nearest < SINGULAR_FADE) {
            return kept;
        }
        let (skipped, _) = self.field(t, &q, &v, SINGULAR_FADE);
        // 0 at the window, 1 at SINGULAR_FADE windows, with zero first and
        // second derivatives at both ends.
        let x = ((nearest - 1.0) / (SINGULAR_FADE - 1.0)).clamp(0.0, 1.0);
        let weight = x * x * x * (10.0 - 15.0 * x + 6.0 * x * x);
        std::array::from_fn(|i| skipped[i] + weight * (kept[i] - skipped[i]))
    }
}

/// A row's entry `x` over the row's length, for rows taken at unit
/// length; 0 for a row skipped (its length 0).
fn per_length<const K: usize>(lengths: &[f64; K], r: usize, x: f64) -> f64 {
    match lengths[r] {
        0.0 => 0.0,
        length => x / length,
    }
}

/// A constrained model's equations as an [`AnySystem`] whose stream
/// projects the state onto the constraints at every segment's end (before
/// the analysis sees it), so that a period map of 10⁵ periods stays on them.
pub struct Projecting<const N: usize, const K: usize, const S: usize> {
    system: SizedSystem<OnConstraints<N, K, S>, S>,
}

impl<const N: usize, const K: usize, const S: usize> Projecting<N, K, S> {
    pub fn new(equations: OnConstraints<N, K, S>) -> Self {
        Projecting {
            system: SizedSystem(equations),
        }
    }
}

impl<const N: usize, const K: usize, const S: usize> AnySystem for Projecting<N, K, S> {
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
        self.system
            .stream(integrator, y0, segment, segments, &mut |y| {
                t += segment;
                let tolerance = equations.position_tolerance(y);
                let state: &mut [f64; S] = y.try_into().expect("a state of the system's length");
                if let Err(e) = equations.project(t, state, tolerance) {
                    failure = Some(e);
                    return false;
                }
                after(y)
            })?;
        match failure {
            Some(ConstraintError::NoConvergence { .. })
            | Some(ConstraintError::Singular { .. }) => Err(OdeError::NonFinite {
                t,
                y: vec![f64::NAN; S],
            }),
            _ => Ok(()),
        }
    }
}

impl<const N: usize, const K: usize, const S: usize> OnConstraints<N, K, S> {
    /// Where Newton's method stops on a state: |g| ≤ 1e-14 (1 + the largest
    /// |coordinate| that is not an angle), the scale of the residuals (an
    /// angle's turns do not change it).
    pub fn position_tolerance(&self, y: &[f64]) -> f64 {
        position_tolerance(&self.0.table.periodic, y)
    }
}

/// Where Newton's method stops on a state: |g| ≤ 1e-14 (1 + the largest
/// |coordinate| that is not an angle), the scale of the residuals (an
/// angle's turns do not change it).
pub fn position_tolerance<const N: usize>(periodic: &[bool; N], y: &[f64]) -> f64 {
    let largest = (0..N)
        .filter(|&i| !periodic[i])
        .fold(0.0_f64, |m, i| m.max(y[i].abs()));
    PROJECTION_TOLERANCE * (1.0 + largest)
}

/// A constrained model at (t, q): the mass matrix, and the position
/// constraints' values and Jacobian (their rows only).
#[derive(Clone, Debug, PartialEq)]
pub struct Statics {
    pub mass: DMatrix<f64>,
    pub residual: DVector<f64>,
    pub jacobian: DMatrix<f64>,
}
