//! Systems whose state's length is known at run time.
//!
//! The integrators work on `[f64; N]`, so that a step allocates nothing and
//! the compiler unrolls the stage sums. An analysis need not: it holds an
//! [`AnySystem`] (a system at its own N behind a trait object) and states
//! as slices, so it is compiled once for every model, whatever the length
//! of the model's state, while each run's loops (the steps, the Taylor
//! recurrences) still run at the system's own size. The cost is one
//! indirect call and a copy of the state per request (a period, a run),
//! not per step.

use nalgebra::DMatrix;

use super::{Direction, Event, EventSettings, Integrator, Method, OdeError, Options, System};

/// A system behind a trait object whose state is a slice of [`AnySystem::dim`]
/// numbers. Every method refuses a state of another length with
/// [`OdeError::StateLength`].
pub trait AnySystem: Sync {
    /// The length of the state.
    fn dim(&self) -> usize;
    /// y' at (t, y).
    fn rhs(&self, t: f64, y: &[f64]) -> Result<Vec<f64>, OdeError>;
    /// ∂y'/∂y at (t, y), when the system knows it.
    fn jacobian(&self, t: f64, y: &[f64]) -> Result<Option<DMatrix<f64>>, OdeError>;
    /// [`Integrator::solve`]: from (t0, y0) towards t1 with the options.
    fn solve(
        &self,
        integrator: &mut Integrator,
        t0: f64,
        y0: &[f64],
        t1: f64,
        options: AnyOptions<'_>,
    ) -> Result<AnySolution, OdeError>;
    /// [`super::states_at`]: the states at `times` of a fresh run of
    /// `method` from (t0, y0), up to the last of them.
    fn states_at(
        &self,
        method: Method,
        t0: f64,
        y0: &[f64],
        times: &[f64],
    ) -> Result<Vec<Vec<f64>>, OdeError> {
        let t1 = times.last().copied().unwrap_or(t0);
        let options = AnyOptions::default().times(times);
        let mut integrator = Integrator::new(method)?;
        Ok(self.solve(&mut integrator, t0, y0, t1, options)?.samples)
    }
    /// The states at `times` from `y0` at times[0]: y0 itself, then
    /// [`AnySystem::states_at`] the later times.
    fn states_from(
        &self,
        method: Method,
        y0: &[f64],
        times: &[f64],
    ) -> Result<Vec<Vec<f64>>, OdeError> {
        let mut states = vec![y0.to_vec()];
        if let Some((&t0, later)) = times.split_first().filter(|(_, later)| !later.is_empty()) {
            states.extend(self.states_at(method, t0, y0, later)?);
        }
        Ok(states)
    }
    /// [`Integrator::stream`]: `segments` segments of time `segment` from
    /// (0, y0), `after` called with each end's state (which it may change)
    /// and saying whether to go on.
    fn stream(
        &self,
        integrator: &mut Integrator,
        y0: &[f64],
        segment: f64,
        segments: usize,
        after: &mut dyn FnMut(&mut [f64]) -> bool,
    ) -> Result<(), OdeError>;
}

/// [`Options`] with states as slices: the output times, and a condition
/// that stops the run where it falls through 0. (Observers and more
/// events, which the fixed-size [`Options`] take, are not asked for
/// through this interface yet.)
#[derive(Default)]
pub struct AnyOptions<'o> {
    times: &'o [f64],
    stop_below: Option<&'o dyn Fn(f64, &[f64]) -> f64>,
}

impl<'o> AnyOptions<'o> {
    /// [`Options::times`].
    pub fn times(mut self, times: &'o [f64]) -> Self {
        self.times = times;
        self
    }

    /// Stop the run just past where `condition(t, y)` falls from positive
    /// to negative (a terminal [`Event`] of direction falling).
    pub fn stop_below(mut self, condition: &'o dyn Fn(f64, &[f64]) -> f64) -> Self {
        self.stop_below = Some(condition);
        self
    }
}

/// [`super::Solution`] with states as vectors.
#[derive(Clone, Debug, PartialEq)]
pub struct AnySolution {
    pub t: f64,
    pub y: Vec<f64>,
    /// The states at the first `samples.len()` of the times asked for:
    /// all of them unless the stop condition ended the run before the last.
    pub samples: Vec<Vec<f64>>,
    /// True if the stop condition ended the run (at `t`, before t1).
    pub stopped: bool,
}

/// A [`System`] at its own size N as an [`AnySystem`].
pub struct SizedSystem<S, const N: usize>(pub S);

/// The state `y` at length N, or the error naming both lengths.
pub fn fixed_state<const N: usize>(y: &[f64]) -> Result<[f64; N], OdeError> {
    y.try_into().map_err(|_| OdeError::StateLength {
        given: y.len(),
        expected: N,
    })
}

impl<S: System<N> + Sync, const N: usize> AnySystem for SizedSystem<S, N> {
    fn dim(&self) -> usize {
        N
    }

    fn rhs(&self, t: f64, y: &[f64]) -> Result<Vec<f64>, OdeError> {
        Ok(self.0.rhs(t, &fixed_state::<N>(y)?).to_vec())
    }

    fn jacobian(&self, t: f64, y: &[f64]) -> Result<Option<DMatrix<f64>>, OdeError> {
        let j = self.0.jacobian(t, &fixed_state::<N>(y)?);
        Ok(j.map(|j| DMatrix::from_fn(N, N, |i, k| j[i][k])))
    }

    fn solve(
        &self,
        integrator: &mut Integrator,
        t0: f64,
        y0: &[f64],
        t1: f64,
        options: AnyOptions<'_>,
    ) -> Result<AnySolution, OdeError> {
        let y0 = fixed_state::<N>(y0)?;
        let condition = |t: f64, y: &[f64; N]| options.stop_below.map_or(1.0, |c| c(t, y));
        let events = [Event::new(&condition).direction(Direction::Falling)];
        let events = match options.stop_below {
            Some(_) => &events[..],
            None => &[],
        };
        let options = Options::default()
            .times(options.times)
            .events(events, EventSettings::default());
        let solution = integrator.solve(&self.0, t0, &y0, t1, options)?;
        Ok(AnySolution {
            t: solution.t,
            y: solution.y.to_vec(),
            samples: solution.samples.iter().map(|y| y.to_vec()).collect(),
            stopped: solution.terminated,
        })
    }

    fn stream(
        &self,
        integrator: &mut Integrator,
        y0: &[f64],
        segment: f64,
        segments: usize,
        after: &mut dyn FnMut(&mut [f64]) -> bool,
    ) -> Result<(), OdeError> {
        let y0 = fixed_state::<N>(y0)?;
        integrator.stream(&self.0, &y0, segment, segments, &mut |y: &mut [f64; N]| {
            after(y)
        })
    }
}
