//! A constrained model behind a trait object, with states and parameters
//! as slices: what the registry lists and the analyses on constraints
//! (`analysis::on_constraints`) take; one generic adapter over the
//! generated forms ([`crate::constrained::FormsTable`]), compiled once per size.

use nalgebra::{DMatrix, DVector};

use super::recording::Recording;
use super::{iterates_in_lanes, iterates_one_by_one, FliValues, Flows, ModelInfo};
use crate::constrained::averaged::{AveragedOnConstraints, PhaseMeans};
use crate::constrained::{
    position_tolerance, Forms, FormsTable, OnConstraints, Projecting, Statics,
};
use crate::ode::any_size::fixed_state;
use crate::ode::holonomic::{project_holding, tangent_basis, ConstraintError, Projection};
use crate::ode::{states_at, AnySystem, Dual, Integrator, Method, OdeError};
use crate::tangent::lyapunov::fli_of_starts;
use crate::tangent::variational::Variational;

/// A constrained model with states and parameters as slices.
/// Its [`Flows`] run the equations of motion, whose stream projects the
/// state onto the constraints at every segment's end.
pub trait ConstrainedSystems: Flows {
    /// The constraints' names (their reactions' labels).
    fn constraint_names(&self) -> &'static [&'static str];
    /// Which constraints are holonomic.
    fn holonomic(&self) -> Vec<bool>;
    /// The equations that pass singular positions
    /// ([`crate::constrained::PassingSingular`]), their window set by G's
    /// rows at the state `y` where a run starts.
    fn passing_singular(
        &self,
        params: &[f64],
        t: f64,
        y: &[f64],
    ) -> Result<Box<dyn AnySystem>, OdeError>;
    /// The model file's start, [q_start; q'_start] with the rates it
    /// gives and 0 for the others (not yet projected: the others follow
    /// from the velocity constraints, see [`Self::start_held`]).
    fn start(&self, params: &[f64]) -> Vec<f64>;
    /// The components of [`Self::start`] the model file gives as rates:
    /// held when the start is made consistent.
    fn start_held(&self) -> Vec<usize>;
    /// Moves `y` onto the constraints at time t (see [`project`]).
    fn project(&self, params: &[f64], t: f64, y: &mut [f64])
        -> Result<Projection, ConstraintError>;
    /// The multipliers λ at (t, y): the constraints' reactions, in the
    /// units of their rows (for a rod written as |x − x₀|² − l² = 0, λ
    /// times the gradient 2(x − x₀) is the force on the point).
    fn reactions(&self, params: &[f64], t: f64, y: &[f64]) -> Result<Vec<f64>, OdeError>;
    /// (max |g|, max |G q' + c_t|) at (t, y).
    fn residuals(&self, params: &[f64], t: f64, y: &[f64]) -> Result<(f64, f64), OdeError>;
    /// What a run reports at an output time, in one call: the residuals
    /// the integration left at (t, y), then `y` put on the constraints, and
    /// there its reactions and energy.
    fn output(&self, params: &[f64], t: f64, y: &mut [f64]) -> Result<Output, ConstraintError>;
    fn energy(&self, params: &[f64], t: f64, y: &[f64]) -> Result<f64, OdeError>;
    /// The constraints whose reactions the motion does not determine at
    /// (t, q): redundant ones, each in a dependency w of G's rows
    /// (Gᵀw = 0, w_i ≠ 0), whose reactions can trade along w.
    fn indeterminate_reactions(
        &self,
        params: &[f64],
        t: f64,
        y: &[f64],
    ) -> Result<Vec<usize>, OdeError>;
    /// The singular values of the constraints' Jacobian G at (t, q),
    /// largest first: how far the mechanism is from a singular position
    /// (where some of them fall to 0).
    fn constraint_singular_values(
        &self,
        params: &[f64],
        t: f64,
        y: &[f64],
    ) -> Result<Vec<f64>, OdeError>;
    /// An orthonormal basis (columns) of the tangent space of the
    /// constrained phase space at (t, y), or None where the constraints
    /// are degenerate.
    fn tangent_basis(
        &self,
        params: &[f64],
        t: f64,
        y: &[f64],
    ) -> Result<Option<DMatrix<f64>>, OdeError>;
    /// At (t, y): the Jacobian of the equations on the constraints with
    /// respect to the state [q; q'] (2n × 2n), and that of the state's
    /// constraints [g; G q' + c_t] (one row per position constraint, then
    /// one per constraint), both exact by dual numbers.
    fn linearisation(
        &self,
        params: &[f64],
        t: f64,
        y: &[f64],
    ) -> Result<(DMatrix<f64>, DMatrix<f64>), OdeError>;
    /// Whether the constraints are holonomic and fixed and M does not
    /// move with the phase (the averaging's conditions).
    fn stationary(&self) -> bool;
    /// At (t, q): what the averaging reads (see [`Statics`]).
    fn statics(&self, params: &[f64], t: f64, q: &[f64]) -> Result<Statics, OdeError>;
    /// ∇²g of each position constraint at (t, q), exact by dual numbers.
    fn constraint_hessians(
        &self,
        params: &[f64],
        t: f64,
        q: &[f64],
    ) -> Result<Vec<DMatrix<f64>>, OdeError>;
    /// At q, the means over the fast phase of V and b and the vibrational
    /// potential on the constraints (None without a fast phase, or where
    /// the constraints or the mass matrix move with it).
    fn phase_means(&self, params: &[f64], q: &[f64]) -> Result<Option<PhaseMeans>, OdeError>;
    /// The first-order averaged motion's states at `times` from `y0`
    /// (each projected onto the constraints), or None where the model has
    /// no fast phase or its constraints or mass matrix move with it
    /// ([`crate::constrained::averaged`]).
    fn averaged_states(
        &self,
        params: &[f64],
        method: Method,
        y0: &[f64],
        times: &[f64],
    ) -> Result<Option<Vec<Vec<f64>>>, OdeError>;
    /// The state after `period` from `y0` and the monodromy matrix
    /// ∂y(T)/∂y(0) of the full state [q; q'] (2n × 2n).
    fn monodromy(
        &self,
        params: &[f64],
        integrator: &mut Integrator,
        period: f64,
        y0: &[f64],
    ) -> Result<(Vec<f64>, DMatrix<f64>), OdeError>;
    /// Follows the orbit from the consistent state `y0` at t = 0 with
    /// DOP853 and hands each crossing of `plane` (located on the dense
    /// output, then projected onto the constraints) to `keep` until it
    /// returns false or t reaches `plane.t_max`; returns (t, y) where it
    /// stopped. The state is projected at every chunk's end.
    fn crossings(
        &self,
        params: &[f64],
        y0: &[f64],
        plane: &PlaneCrossing,
        keep: &mut dyn FnMut(&[f64]) -> bool,
    ) -> Result<(f64, Vec<f64>), OdeError>;
}

/// A run's report at one output time ([`ConstrainedSystems::output`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Output {
    /// (max |g|, max |G q' + c_t|) before the projection.
    pub drift: (f64, f64),
    pub projection: Projection,
    pub reactions: Vec<f64>,
    pub energy: f64,
}

/// A coordinate's plane q_c = value crossed in one direction, as a
/// section on the constraints follows it.
#[derive(Clone, Copy, Debug)]
pub struct PlaneCrossing {
    pub coordinate: usize,
    pub value: f64,
    pub rising: bool,
    /// DOP853's tolerance.
    pub tol: f64,
    pub t_max: f64,
}

impl PlaneCrossing {
    /// q_c − value, wrapped to [−π, π) for an angle (whose jump at ±π is
    /// a crossing of the other side, dropped).
    pub fn offset(&self, y: &[f64], periodic: bool) -> f64 {
        let d = y[self.coordinate] - self.value;
        match periodic {
            true => crate::ode::wrap_angle(d),
            false => d,
        }
    }
}

/// A generated model's forms ([`FormsTable`]) at their sizes as
/// [`ConstrainedSystems`] (the model's module holds one in a static).
/// T = 2S is the state with one tangent vector (stable Rust cannot
/// compute it from S).
pub struct Constrained<const N: usize, const K: usize, const S: usize, const T: usize> {
    info: &'static ModelInfo,
    forms: &'static FormsTable<N, K, S>,
}

impl<const N: usize, const K: usize, const S: usize, const T: usize> Constrained<N, K, S, T> {
    pub const fn new(info: &'static ModelInfo, forms: &'static FormsTable<N, K, S>) -> Self {
        Constrained { info, forms }
    }

    fn equations(&self, params: &[f64]) -> OnConstraints<N, K, S> {
        OnConstraints::new(Forms::new(self.forms, params))
    }

    /// G at (t, q) of the state y, at run-time size.
    fn constraint_matrix(
        &self,
        params: &[f64],
        t: f64,
        y: &[f64],
    ) -> Result<DMatrix<f64>, OdeError> {
        let y = fixed_state::<S>(y)?;
        let q: [f64; N] = std::array::from_fn(|i| y[i]);
        let g = self.equations(params).0.constraint_jacobian(t, &q);
        Ok(DMatrix::from_fn(K, N, |r, i| g[r][i]))
    }

    /// The averaged motion, where the averaging applies.
    fn averaged(&self, params: &[f64]) -> Option<AveragedOnConstraints<N, K, S>> {
        let exact = self.equations(params);
        let period = exact.0.phase_period().filter(|_| self.forms.stationary)?;
        Some(AveragedOnConstraints { exact, period })
    }
}

impl<const N: usize, const K: usize, const S: usize, const T: usize> Flows
    for Constrained<N, K, S, T>
{
    fn info(&self) -> &'static ModelInfo {
        self.info
    }
    fn has_fast_phase(&self) -> bool {
        self.forms.has_fast_phase
    }
    fn periodic_state(&self) -> Vec<bool> {
        let periodic = self.forms.periodic;
        (0..S).map(|i| i < N && periodic[i]).collect()
    }
    fn phase_period(&self, params: &[f64]) -> Option<f64> {
        (self.forms.phase_period)(params)
    }
    fn exact(&self, params: &[f64]) -> Box<dyn AnySystem> {
        Box::new(Projecting::new(self.equations(params)))
    }
    fn has_taylor_recurrences(&self) -> bool {
        self.forms.recurrences.is_some()
    }
    fn base_state(&self, params: &[f64]) -> Vec<f64> {
        ConstrainedSystems::start(self, params)
    }
    fn fli(
        &self,
        params: &[f64],
        method: Method,
        period: f64,
        starts: &[f64],
        w0: &[f64],
        periods: usize,
        held: &[usize],
    ) -> Result<FliValues, OdeError> {
        let system = self.equations(params);
        let w0 = DVector::from_column_slice(&fixed_state::<S>(w0)?);
        // Each start on the constraints with its tangent vector on their
        // tangent space, or None where the plane's point has no state.
        let mut on_manifold = Vec::new();
        for start in starts.chunks(S) {
            let mut y = fixed_state::<S>(start)?;
            let tolerance = position_tolerance(&self.forms.periodic, &y);
            let on = project_holding(&system, 0.0, &mut y, tolerance, held).ok();
            let basis = on.and_then(|_| tangent_basis(&system.state_constraints_jacobian(0.0, &y)));
            on_manifold.push(basis.map(|basis| {
                // w0 on the tangent space (its first direction if w0 is normal to it).
                let mut w = &basis * (basis.transpose() * &w0);
                if w.norm() < 1e-8 * w0.norm() {
                    w = basis.column(0).into_owned();
                }
                let w = w.normalize();
                (y, std::array::from_fn(|i| w[i]))
            }));
        }
        let (states, tangents): (Vec<[f64; S]>, Vec<[f64; S]>) =
            on_manifold.iter().flatten().copied().unzip();
        let (mut computed, f_evals) =
            fli_of_starts::<_, S, T>(&system, method, period, &states, &tangents, periods)?;
        let mut computed = computed.drain(..);
        let values = on_manifold
            .iter()
            .map(|on| match on {
                Some(_) => computed
                    .next()
                    .expect("one value per state on the constraints"),
                None => Ok(f64::NAN),
            })
            .collect();
        Ok((values, f_evals))
    }
    /// With the Taylor method, in the batch lanes, each state projected
    /// onto the constraints at every period's end as [`Projecting`]'s
    /// stream does (an orbit whose projection fails stops, None).
    fn iterates(
        &self,
        params: &[f64],
        method: Method,
        period: f64,
        starts: &[f64],
        recording: &Recording,
    ) -> Result<Vec<Option<Vec<Vec<f64>>>>, OdeError> {
        let wrap = Flows::periodic_state(self);
        if !matches!(method, Method::Taylor { .. }) {
            let system = Flows::exact(self, params);
            return iterates_one_by_one(&*system, method, period, starts, recording, &wrap);
        }
        let system = self.equations(params);
        let on_constraints = |t: f64, y: &mut [f64; S]| {
            let tolerance = position_tolerance(&self.forms.periodic, y);
            system.project(t, y, tolerance).is_ok()
        };
        iterates_in_lanes(
            &system,
            method,
            period,
            starts,
            recording,
            &wrap,
            &on_constraints,
        )
    }
    fn consistent(
        &self,
        params: &[f64],
        y: &mut [f64],
        held: &[usize],
    ) -> Result<(), ConstraintError> {
        if y.len() != S {
            return Err(ConstraintError::StateLength {
                given: y.len(),
                coordinates: N,
            });
        }
        let tolerance = position_tolerance(&self.forms.periodic, y);
        project_holding(&self.equations(params), 0.0, y, tolerance, held).map(|_| ())
    }
}

impl<const N: usize, const K: usize, const S: usize, const T: usize> ConstrainedSystems
    for Constrained<N, K, S, T>
{
    fn constraint_names(&self) -> &'static [&'static str] {
        self.forms.constraint_names
    }
    fn passing_singular(
        &self,
        params: &[f64],
        t: f64,
        y: &[f64],
    ) -> Result<Box<dyn AnySystem>, OdeError> {
        use crate::constrained::{PassingSingular, SINGULAR_WINDOW};
        let g = self.constraint_matrix(params, t, y)?;
        let lengths: Vec<f64> = g.row_iter().map(|row| row.norm()).collect();
        let longest = lengths.iter().copied().fold(0.0, f64::max);
        // A row (all but) vanished at the start takes the longest's scale.
        let floors =
            std::array::from_fn(|r| SINGULAR_WINDOW * lengths[r].max(SINGULAR_WINDOW * longest));
        Ok(Box::new(crate::ode::SizedSystem(PassingSingular {
            equations: self.equations(params),
            floors,
        })))
    }
    fn holonomic(&self) -> Vec<bool> {
        self.forms.holonomic.to_vec()
    }
    fn start(&self, params: &[f64]) -> Vec<f64> {
        let mut y = (self.forms.start)(params).to_vec();
        y.extend((self.forms.start_rates)(params));
        y
    }
    fn start_held(&self) -> Vec<usize> {
        (0..N)
            .filter(|&i| self.forms.rates_given[i])
            .map(|i| N + i)
            .collect()
    }
    fn project(
        &self,
        params: &[f64],
        t: f64,
        y: &mut [f64],
    ) -> Result<Projection, ConstraintError> {
        let given = y.len();
        let state: &mut [f64; S] = y.try_into().map_err(|_| ConstraintError::StateLength {
            given,
            coordinates: N,
        })?;
        let tolerance = position_tolerance(&self.forms.periodic, state);
        self.equations(params).project(t, state, tolerance)
    }
    fn reactions(&self, params: &[f64], t: f64, y: &[f64]) -> Result<Vec<f64>, OdeError> {
        let y = fixed_state::<S>(y)?;
        Ok(self.equations(params).accelerations(t, &y).1.to_vec())
    }
    fn residuals(&self, params: &[f64], t: f64, y: &[f64]) -> Result<(f64, f64), OdeError> {
        let y = fixed_state::<S>(y)?;
        Ok(self.equations(params).residuals(t, &y))
    }
    fn output(&self, params: &[f64], t: f64, y: &mut [f64]) -> Result<Output, ConstraintError> {
        let given = y.len();
        let state: &mut [f64; S] = y.try_into().map_err(|_| ConstraintError::StateLength {
            given,
            coordinates: N,
        })?;
        let equations = self.equations(params);
        let drift = equations.residuals(t, state);
        let tolerance = position_tolerance(&self.forms.periodic, state);
        let projection = equations.project(t, state, tolerance)?;
        let reactions = equations.accelerations(t, state).1.to_vec();
        let (q, v) = OnConstraints::<N, K, S>::split(state);
        Ok(Output {
            drift,
            projection,
            reactions,
            energy: (self.forms.energy)(params, t, &q, &v),
        })
    }
    fn energy(&self, params: &[f64], t: f64, y: &[f64]) -> Result<f64, OdeError> {
        let y = fixed_state::<S>(y)?;
        let (q, v) = OnConstraints::<N, K, S>::split(&y);
        Ok((self.forms.energy)(params, t, &q, &v))
    }
    fn linearisation(
        &self,
        params: &[f64],
        t: f64,
        y: &[f64],
    ) -> Result<(DMatrix<f64>, DMatrix<f64>), OdeError> {
        use crate::ode::System;
        let y = fixed_state::<S>(y)?;
        let equations = self.equations(params);
        let field = equations
            .jacobian(t, &y)
            .expect("the equations on the constraints have an exact Jacobian");
        Ok((
            DMatrix::from_fn(S, S, |i, k| field[i][k]),
            equations.state_constraints_jacobian(t, &y),
        ))
    }
    fn stationary(&self) -> bool {
        self.forms.stationary
    }
    fn statics(&self, params: &[f64], t: f64, q: &[f64]) -> Result<Statics, OdeError> {
        let q = fixed_state::<N>(q)?;
        let forms = Forms::new(self.forms, params);
        let rows: Vec<usize> = (0..K).filter(|&r| self.forms.holonomic[r]).collect();
        let m = forms.mass_matrix(t, &q);
        let g = forms.constraint_jacobian(t, &q);
        let residual = forms.position_residuals(t, &q);
        Ok(Statics {
            mass: DMatrix::from_fn(N, N, |i, k| m[i][k]),
            residual: DVector::from_iterator(rows.len(), rows.iter().map(|&r| residual[r])),
            jacobian: DMatrix::from_fn(rows.len(), N, |i, k| g[rows[i]][k]),
        })
    }
    fn constraint_hessians(
        &self,
        params: &[f64],
        t: f64,
        q: &[f64],
    ) -> Result<Vec<DMatrix<f64>>, OdeError> {
        let q = fixed_state::<N>(q)?;
        let forms = Forms::new(self.forms, params);
        let rows: Vec<usize> = (0..K).filter(|&r| self.forms.holonomic[r]).collect();
        let mut hessians = vec![DMatrix::zeros(N, N); rows.len()];
        for j in 0..N {
            let seeded: [Dual; N] =
                std::array::from_fn(|i| Dual::seeded(q[i], if i == j { 1.0 } else { 0.0 }));
            let g = forms.constraint_jacobian_dual(t, &seeded);
            for (h, &r) in hessians.iter_mut().zip(&rows) {
                for i in 0..N {
                    h[(i, j)] = g[r][i].du;
                }
            }
        }
        Ok(hessians)
    }
    fn indeterminate_reactions(
        &self,
        params: &[f64],
        t: f64,
        y: &[f64],
    ) -> Result<Vec<usize>, OdeError> {
        let g = self.constraint_matrix(params, t, y)?;
        // The dependencies: eigenvectors of G Gᵀ at eigenvalue 0.
        let gram = nalgebra::SymmetricEigen::new(&g * g.transpose());
        let largest = gram.eigenvalues.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        let mut indeterminate = Vec::new();
        for (k, value) in gram.eigenvalues.iter().enumerate() {
            if value.abs() <= crate::linalg::REDUNDANT * largest {
                let w = gram.eigenvectors.column(k);
                let scale = w.norm();
                indeterminate.extend((0..K).filter(|&i| w[i].abs() > 1e-8 * scale));
            }
        }
        indeterminate.sort_unstable();
        indeterminate.dedup();
        Ok(indeterminate)
    }
    fn constraint_singular_values(
        &self,
        params: &[f64],
        t: f64,
        y: &[f64],
    ) -> Result<Vec<f64>, OdeError> {
        let g = self.constraint_matrix(params, t, y)?;
        let mut values: Vec<f64> = g.singular_values().iter().copied().collect();
        values.sort_by(|a, b| b.total_cmp(a));
        Ok(values)
    }
    fn tangent_basis(
        &self,
        params: &[f64],
        t: f64,
        y: &[f64],
    ) -> Result<Option<DMatrix<f64>>, OdeError> {
        let y = fixed_state::<S>(y)?;
        let c = self.equations(params).state_constraints_jacobian(t, &y);
        Ok(tangent_basis(&c))
    }
    fn phase_means(&self, params: &[f64], q: &[f64]) -> Result<Option<PhaseMeans>, OdeError> {
        let q = fixed_state::<N>(q)?;
        Ok(self
            .averaged(params)
            .map(|averaged| averaged.phase_means(&q)))
    }
    fn averaged_states(
        &self,
        params: &[f64],
        method: Method,
        y0: &[f64],
        times: &[f64],
    ) -> Result<Option<Vec<Vec<f64>>>, OdeError> {
        let y0 = fixed_state::<S>(y0)?;
        let Some(averaged) = self.averaged(params) else {
            return Ok(None);
        };
        let t0 = times.first().copied().unwrap_or(0.0);
        let mut states = states_at(method, &averaged, t0, &y0, times)?;
        for y in &mut states {
            let tolerance = position_tolerance(&self.forms.periodic, y);
            // A failed projection leaves the state as the integration left it.
            let _ = averaged.exact.project(0.0, y, tolerance);
        }
        Ok(Some(states.iter().map(|y| y.to_vec()).collect()))
    }
    fn monodromy(
        &self,
        params: &[f64],
        integrator: &mut Integrator,
        period: f64,
        y0: &[f64],
    ) -> Result<(Vec<f64>, DMatrix<f64>), OdeError> {
        // Column by column, with one tangent vector at a time: the
        // variational system of S + S² numbers would be compiled for every
        // model at its size (420 numbers for a chain of ten rods).
        let y0 = fixed_state::<S>(y0)?;
        let system = self.equations(params);
        let variational = Variational::<_, S, T>::new(&system);
        let mut matrix = DMatrix::zeros(S, S);
        let mut end = y0;
        for k in 0..S {
            let unit: [f64; S] = std::array::from_fn(|i| if i == k { 1.0 } else { 0.0 });
            let z0 = Variational::<OnConstraints<N, K, S>, S, T>::pack(&y0, &[unit]);
            let z = integrator.advance(&variational, 0.0, &z0, period)?;
            end = Variational::<OnConstraints<N, K, S>, S, T>::state(&z);
            let column = Variational::<OnConstraints<N, K, S>, S, T>::tangent(&z, 0);
            for i in 0..S {
                matrix[(i, k)] = column[i];
            }
        }
        Ok((end.to_vec(), matrix))
    }
    fn crossings(
        &self,
        params: &[f64],
        y0: &[f64],
        plane: &PlaneCrossing,
        keep: &mut dyn FnMut(&[f64]) -> bool,
    ) -> Result<(f64, Vec<f64>), OdeError> {
        use crate::ode::{Direction, Event, EventSettings, Options};
        let system = self.equations(params);
        let periodic = self.forms.periodic[plane.coordinate];
        let condition = |_: f64, y: &[f64; S]| plane.offset(y, periodic);
        let direction = match plane.rising {
            true => Direction::Rising,
            false => Direction::Falling,
        };
        let events = [Event::new(&condition).direction(direction).non_terminal()];
        let mut integrator = Integrator::new(Method::parse("dop853", plane.tol)?)?;
        let (mut t, mut y) = (0.0, fixed_state::<S>(y0)?);
        let chunk = CHUNK;
        while t < plane.t_max {
            let t1 = (t + chunk).min(plane.t_max);
            let run = integrator.solve(
                &system,
                t,
                &y,
                t1,
                Options::default().events(&events, EventSettings::default()),
            )?;
            for hit in run
                .hits
                .iter()
                .filter(|hit| plane.offset(&hit.y, periodic).abs() < 1e-6)
            {
                let mut state = hit.y;
                let tolerance = position_tolerance(&self.forms.periodic, &state);
                // A failed projection keeps the located state as it is.
                let _ = system.project(hit.t, &mut state, tolerance);
                if !keep(&state) {
                    return Ok((hit.t, state.to_vec()));
                }
            }
            (t, y) = (run.t, run.y);
            let tolerance = position_tolerance(&self.forms.periodic, &y);
            system
                .project(t, &mut y, tolerance)
                .map_err(|_| OdeError::NonFinite { t, y: y.to_vec() })?;
        }
        Ok((t, y.to_vec()))
    }
}

/// The time between projections of a section's orbit: the drift of the
/// equations at the level of accelerations grows between them, and with
/// it |H − E| (1.6e-8 with chunks of t_max/64 on a double pendulum of
/// points, 9.8e-10 with 1, as the angle model's, at the same cost).
const CHUNK: f64 = 1.0;
