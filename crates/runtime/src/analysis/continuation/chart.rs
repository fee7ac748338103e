//! A constrained model's period map (or flow) in a chart of its
//! constraint manifold, as the continuation sees a model: the state is
//! 2(n − k) components of [q; q'] (the chart's coordinates), the others
//! following from the constraints. A fixed point's multipliers are those
//! of the map on the manifold, none spurious from the constraint
//! directions.

use super::{Family, FamilyMap};
use crate::ode::holonomic::ConstraintError;
use crate::ode::{AnyOptions, Method, OdeError};
use crate::registry::ConstrainedSystems;
use nalgebra::DMatrix;
use rayon::prelude::*;
use std::sync::Mutex;

pub(super) struct ChartMap {
    model: &'static dyn ConstrainedSystems,
    family: Family,
    /// The state components that are the chart's coordinates.
    held: Vec<usize>,
    periodic: Vec<bool>,
    /// The start on the constraints: the first guess of the orbit
    /// diagram's lifts (deterministic, whatever the threads' order).
    start: Vec<f64>,
    /// The last state put on the constraints: the next one's first guess
    /// (Newton's method then stays on the branch of the closures it is on).
    guess: Mutex<Vec<f64>>,
}

impl ChartMap {
    /// The model at `params` with its parameter `index` free, in the chart
    /// `held` (components of the state), or if None the one that
    /// parametrises its constraints best at `start` (a full state, put on
    /// the constraints first, holding the chart's components).
    pub(super) fn new(
        model: &'static dyn ConstrainedSystems,
        params: &[f64],
        index: usize,
        method: Method,
        start: &[f64],
        held: Option<&[usize]>,
    ) -> Result<Self, OdeError> {
        let mut y = start.to_vec();
        model.consistent(params, &mut y, held.unwrap_or_default())?;
        let basis = model
            .tangent_basis(params, 0.0, &y)?
            .ok_or_else(|| ConstraintError::Singular { q: y.clone() })?;
        let held = match held {
            Some(held) => held.to_vec(),
            None => chart_of(&basis, model.holonomic().iter().all(|&h| h)),
        };
        let periodic = model.periodic_state();
        let distinct = held.iter().enumerate().all(|(i, a)| !held[..i].contains(a));
        if held.len() != basis.ncols() || !distinct || held.iter().any(|&i| i >= y.len()) {
            return Err(ConstraintError::ChartSize {
                held,
                dimension: basis.ncols(),
                state: y.len(),
            }
            .into());
        }
        Ok(ChartMap {
            periodic: held.iter().map(|&i| periodic[i]).collect(),
            model,
            family: Family::new(model, params, index, method),
            held,
            guess: Mutex::new(y.clone()),
            start: y,
        })
        .and_then(|map| {
            // The chart must parametrise the constraints at the start.
            map.lifting(&map.start, params)?;
            Ok(map)
        })
    }

    /// The start, on the constraints.
    pub(super) fn start(&self) -> &[f64] {
        &self.start
    }

    /// The chart's components of the state.
    pub(super) fn held(&self) -> &[usize] {
        &self.held
    }

    /// The chart's coordinates of a full state.
    pub(super) fn chart(&self, y: &[f64]) -> Vec<f64> {
        self.held.iter().map(|&i| y[i]).collect()
    }

    /// The state on the constraints with the chart's coordinates `z`,
    /// Newton's method starting from the last one.
    fn lift(&self, z: &[f64], params: &[f64]) -> Result<Vec<f64>, OdeError> {
        let guess = self.guess.lock().map(|g| g.clone()).unwrap_or_default();
        let y = self.lift_from(guess, z, params)?;
        if let Ok(mut guess) = self.guess.lock() {
            guess.clone_from(&y);
        }
        Ok(y)
    }

    /// The state on the constraints with the chart's coordinates `z`,
    /// Newton's method starting from `guess`.
    fn lift_from(&self, mut y: Vec<f64>, z: &[f64], params: &[f64]) -> Result<Vec<f64>, OdeError> {
        for (&i, &value) in self.held.iter().zip(z) {
            y[i] = value;
        }
        self.model.consistent(params, &mut y, &self.held)?;
        Ok(y)
    }

    /// ∂y/∂z: the tangent vectors whose chart components are the unit
    /// vectors (Z (S Z)⁻¹ with Z a basis of the tangent space and S the
    /// selection of the chart's components).
    fn lifting(&self, y: &[f64], params: &[f64]) -> Result<DMatrix<f64>, OdeError> {
        let singular = || ConstraintError::SingularChart {
            held: self.held.clone(),
            y: y.to_vec(),
        };
        let basis = self
            .model
            .tangent_basis(params, 0.0, y)?
            .ok_or_else(singular)?;
        let selected = DMatrix::from_fn(self.held.len(), basis.ncols(), |r, c| {
            basis[(self.held[r], c)]
        });
        let inverse = selected.try_inverse().ok_or_else(singular)?;
        Ok(basis * inverse)
    }

    /// The rows of a matrix at the chart's components.
    fn select(&self, m: &DMatrix<f64>) -> DMatrix<f64> {
        DMatrix::from_fn(self.held.len(), m.ncols(), |r, c| m[(self.held[r], c)])
    }
}

/// The chart at a state with tangent basis `basis` (2n × m): with every
/// constraint holonomic, the m/2 coordinates that parametrise the
/// positions best (chosen by pivoting on the basis's position rows) with
/// their velocities; otherwise the m state components chosen by pivoting
/// on all its rows.
fn chart_of(basis: &DMatrix<f64>, holonomic: bool) -> Vec<usize> {
    let (rows, m) = basis.shape();
    let n = rows / 2;
    let (candidates, count) = match holonomic {
        true => ((0..n).collect::<Vec<_>>(), m / 2),
        false => ((0..rows).collect(), m),
    };
    let mut residual = basis.clone();
    let mut chosen: Vec<usize> = Vec::new();
    for _ in 0..count {
        let best = candidates
            .iter()
            .copied()
            .filter(|i| !chosen.contains(i))
            .max_by(|&a, &b| residual.row(a).norm().total_cmp(&residual.row(b).norm()))
            .expect("fewer coordinates chosen than candidates");
        let pivot = residual.row(best).transpose() / residual.row(best).norm();
        // Remove the chosen row's direction from every row.
        let projections = &residual * &pivot;
        residual -= projections * pivot.transpose();
        chosen.push(best);
    }
    chosen.sort_unstable();
    if holonomic {
        let velocities: Vec<usize> = chosen.iter().map(|i| i + n).collect();
        chosen.extend(velocities);
    }
    chosen
}

impl FamilyMap for ChartMap {
    fn family(&self) -> &Family {
        &self.family
    }

    fn periodic(&self) -> &[bool] {
        &self.periodic
    }

    fn field(&self, z: &[f64], p: f64) -> (Vec<f64>, DMatrix<f64>) {
        self.family.count(1);
        let params = self.family.with(p);
        let m = self.held.len();
        let nan = || (vec![f64::NAN; m], DMatrix::from_element(m, m, f64::NAN));
        let Ok(y) = self.lift(z, &params) else {
            return nan();
        };
        let system = self.model.exact(&params);
        let (Ok(f), Ok(Some(jacobian)), Ok(lifting)) = (
            system.rhs(0.0, &y),
            system.jacobian(0.0, &y),
            self.lifting(&y, &params),
        ) else {
            return nan();
        };
        let f = self.chart(&f);
        (f, self.select(&(jacobian * lifting)))
    }

    fn once(
        &self,
        z: &[f64],
        p: f64,
        jacobian: bool,
    ) -> Result<(Vec<f64>, Option<DMatrix<f64>>), OdeError> {
        let (params, period, mut integrator) = self.family.period_at(p)?;
        let y = self.lift(z, &params)?;
        if jacobian {
            let (image, monodromy) = self.model.monodromy(&params, &mut integrator, period, &y)?;
            let lifting = self.lifting(&y, &params)?;
            Ok((
                self.chart(&image),
                Some(self.select(&(monodromy * lifting))),
            ))
        } else {
            let system = self.model.exact(&params);
            let end = system.solve(&mut integrator, 0.0, &y, period, AnyOptions::default())?;
            Ok((self.chart(&end.y), None))
        }
    }

    fn diagram(
        &self,
        values: &[f64],
        start: &[f64],
        transient: usize,
        iterates: usize,
    ) -> Vec<Result<Vec<Vec<f64>>, OdeError>> {
        self.family.count(values.len() * (transient + iterates));
        let wrap = self.model.periodic_state();
        values
            .par_iter()
            .map(|&p| {
                let params = self.family.with(p);
                let y = self.lift_from(self.start.clone(), start, &params)?;
                let problem = [(self.model.exact(&params), self.family.period(&params))];
                let states = super::diagram::iterates(
                    self.family.method,
                    &problem,
                    &y,
                    &wrap,
                    transient,
                    iterates,
                )
                .pop()
                .expect("one problem, one result")?;
                Ok(states.iter().map(|y| self.chart(y)).collect())
            })
            .collect()
    }
}
