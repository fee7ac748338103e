//! The Taylor method over a batch of [`LANES`] independent orbits: the
//! generated recurrences run once for all lanes ([`Lanes`] arithmetic,
//! SIMD), while every lane keeps its own time, step size, step count and
//! error. A lane takes exactly the steps the scalar method would take for
//! it, with the same operations, so its result equals the scalar one bit for
//! bit; a lane that ends early (its run is done, or it diverged) idles
//! without disturbing the others.
//!
//! Sweeps (chaos maps, charts) integrate many orbits over the same interval:
//! they gain the SIMD width and the overlap of independent lanes, where one
//! orbit's recurrences are a chain of dependent operations.

use super::driver::compensated_sum;
use super::lanes::{Lanes, LANES};
use super::taylor::{horner, safety, step_exponent, step_from_exponent, step_to_take};
use super::{check_initial, order_for_tolerance, Method, OdeError, Stats, System, TaylorWork};

/// The result of one lane.
pub type LaneResult<const N: usize> = Result<[f64; N], OdeError>;

/// One orbit of a sweep: the system it follows (a generated model's has its
/// own parameters, so one batch can sweep them), its state at t = 0 and the
/// length `end` of its segments (the time restarts at 0 after each).
#[derive(Debug)]
pub struct Orbit<'a, S, const N: usize> {
    pub system: &'a S,
    pub start: [f64; N],
    pub end: f64,
}

// By hand: a derive would ask `S: Copy`, and an orbit only borrows its system.
impl<S, const N: usize> Clone for Orbit<'_, S, N> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<S, const N: usize> Copy for Orbit<'_, S, N> {}

impl<'a, S, const N: usize> Orbit<'a, S, N> {
    /// Orbits of one system, one from each start, with segments [0, end].
    pub fn of_one_system(system: &'a S, end: f64, starts: &[[f64; N]]) -> Vec<Self> {
        starts
            .iter()
            .map(|&start| Orbit { system, start, end })
            .collect()
    }
}

/// Each lane's system, orbit (its index) and segment length, in a stream.
type LaneOrbits<'a, S> = ([&'a S; LANES], [usize; LANES], [f64; LANES]);

/// The batch Taylor integrator: the method's tolerance, its workspace and the
/// run's statistics, summed over lanes (`steps` and `f_evals` count each
/// lane's steps, as the scalar runs would).
#[derive(Clone, Debug)]
pub struct LaneIntegrator {
    /// The order and step safety factor of the method's tolerance (fixed:
    /// a logarithm and an exponential per step saved).
    order: usize,
    safety: f64,
    work: TaylorWork<Lanes>,
    coefficients: Vec<Lanes>,
    pub stats: Stats,
    /// Upper bound on the steps of one lane per call.
    pub max_steps: u64,
}

impl LaneIntegrator {
    /// The batch integrator for `method`, which must be `taylor` (the other
    /// methods have no batch mode: [`OdeError::NoBatchMode`]).
    pub fn new(method: Method) -> Result<LaneIntegrator, OdeError> {
        let Method::Taylor { tol } = method else {
            return Err(OdeError::NoBatchMode(method.name()));
        };
        method.validate()?;
        let order = order_for_tolerance(tol);
        Ok(LaneIntegrator {
            order,
            safety: safety(order),
            work: TaylorWork::default(),
            coefficients: Vec::new(),
            stats: Stats::default(),
            max_steps: 10_000_000,
        })
    }

    /// Advances the states `y0[l]` of the lanes with `active[l]` from `t0` to
    /// `t1`; inactive lanes return their state unchanged.
    pub fn advance<S: System<N>, const N: usize>(
        &mut self,
        system: &S,
        t0: f64,
        y0: &[[f64; N]; LANES],
        active: [bool; LANES],
        t1: f64,
    ) -> [LaneResult<N>; LANES] {
        let mut results: [LaneResult<N>; LANES] = std::array::from_fn(|l| Ok(y0[l]));
        let mut run = Run::new(t0, y0, t1);
        run.running = active;
        for l in (0..LANES).filter(|&l| active[l]) {
            if let Err(e) = check_initial(t0, &y0[l], t1) {
                (results[l], run.running[l]) = (Err(e), false);
            }
        }
        if t1 == t0 {
            return results;
        }
        while run.running.iter().any(|&r| r) {
            let Some(ends) = self.step_lanes([system; LANES], &mut run) else {
                return std::array::from_fn(|_| Err(OdeError::TaylorUnavailable));
            };
            for (l, end) in ends.into_iter().enumerate() {
                if let Some(result) = end {
                    (results[l], run.running[l]) = (result, false);
                }
            }
        }
        self.stats.steps += run.steps.iter().sum::<u64>();
        results
    }

    /// Integrates every orbit over consecutive segments of time `end`, the
    /// time restarting at 0 after each (as a period map's does: the field
    /// must be the same there), [`LANES`] orbits at a time, each lane
    /// exactly as the scalar
    /// [`Integrator::advance_segments`](super::Integrator::advance_segments)
    /// would: the steps run across the segments' ends, and the state at
    /// each end is sampled from the step's polynomial (as heyoka's
    /// `propagate_grid` does), so no step is cut short to land on one.
    /// After each segment `after_segment(k, y)` may change orbit k's state
    /// (its run then restarts from it there) and says whether it goes on.
    /// A lane whose orbit ends takes the next orbit at once: no lane waits
    /// for a slower one. Returns each orbit's error, if it ended with one.
    pub fn stream<'a, S: System<N>, const N: usize>(
        &mut self,
        orbits: &[Orbit<'a, S, N>],
        mut after_segment: impl FnMut(usize, &mut [f64; N]) -> bool,
    ) -> Vec<Option<OdeError>> {
        let mut errors: Vec<Option<OdeError>> = vec![None; orbits.len()];
        let Some(first) = orbits.first() else {
            return errors;
        };
        // Each lane's system, orbit and segment length.
        let mut lanes = ([first.system; LANES], [0usize; LANES], [0.0; LANES]);
        let mut queue = 0..orbits.len();
        let mut run = Run::new(0.0, &[[0.0; N]; LANES], 0.0);
        run.running = [false; LANES];
        // Gives lane `l` the next orbit that starts well, or leaves it idle.
        let mut load = |run: &mut Run<N>,
                        (systems, orbit_of, segment): &mut LaneOrbits<'a, S>,
                        l: usize,
                        errors: &mut [Option<OdeError>]| {
            for k in queue.by_ref() {
                let orbit = &orbits[k];
                match check_initial(0.0, &orbit.start, orbit.end) {
                    // No segment to run: it ends where it starts, as the
                    // scalar `advance` over [0, 0] returns its start.
                    Ok(()) if orbit.end == 0.0 => {}
                    Ok(()) => {
                        (systems[l], orbit_of[l], segment[l]) = (orbit.system, k, orbit.end);
                        run.restart(l, 0.0, &orbit.start);
                        return;
                    }
                    Err(e) => errors[k] = Some(e),
                }
            }
            run.running[l] = false;
        };
        for l in 0..LANES {
            load(&mut run, &mut lanes, l, &mut errors);
        }
        while run.running.iter().any(|&r| r) {
            let mut starts = run.t;
            let Some(ends) = self.step_lanes(lanes.0, &mut run) else {
                return vec![Some(OdeError::TaylorUnavailable); orbits.len()];
            };
            let (c, _) = self.coefficients.as_chunks::<N>();
            for (l, end) in ends.into_iter().enumerate() {
                let (k, segment) = (lanes.1[l], lanes.2[l]);
                // How its orbit ends with this step, if it does: Some(None)
                // when done, Some(Some(e)) with an error.
                let mut outcome = match end {
                    Some(Err(e)) => Some(Some(e)),
                    None if !run.running[l] => continue,
                    // Reached the horizon (an exact series: its segment
                    // ends are all sampled from this one step) or not.
                    _ => None,
                };
                // Each segment end the step reached, the time restarting
                // at 0 there.
                while outcome.is_none() && segment <= run.t[l] {
                    let mut y = if segment == run.t[l] {
                        run.state(l)
                    } else {
                        lane_horner(c, l, segment - starts[l])
                    };
                    starts[l] -= segment;
                    run.t[l] -= segment;
                    let sampled = y;
                    if !after_segment(k, &mut y) {
                        outcome = Some(None);
                    } else if changed(&y, &sampled) {
                        self.stats.steps += run.steps[l];
                        match check_initial(0.0, &y, run.end[l]) {
                            Ok(()) => run.restart(l, 0.0, &y),
                            Err(e) => outcome = Some(Some(e)),
                        }
                    }
                }
                let Some(error) = outcome else { continue };
                self.stats.steps += run.steps[l];
                if error.is_some() {
                    errors[k] = error;
                }
                load(&mut run, &mut lanes, l, &mut errors);
            }
        }
        errors
    }

    /// One step of every running lane, lane l of the system `systems[l]`,
    /// towards its end: for each lane whose run ends with it (at its end, or
    /// with an error), how; `None` when the system has no Taylor
    /// recurrences (for these lanes).
    fn step_lanes<S: System<N>, const N: usize>(
        &mut self,
        systems: [&S; LANES],
        run: &mut Run<N>,
    ) -> Option<[Option<LaneResult<N>>; LANES]> {
        let (order, safety) = (self.order, self.safety);
        self.stats.order = self.stats.order.max(order as u64);
        self.coefficients.resize((order + 1) * N, Lanes::default());
        let mut ends: [Option<LaneResult<N>>; LANES] = std::array::from_fn(|_| None);
        let (c, _) = self.coefficients.as_chunks_mut::<N>();
        if !S::taylor_lanes(systems, Lanes(run.t), &run.y, order, &mut self.work, c) {
            return None;
        }
        // As the scalar `norm_with`: NaN once a component is not finite.
        #[allow(clippy::eq_op)] // (x − x is the point)
        let row_norms = |row: &[Lanes; N]| {
            row.iter()
                .fold(Lanes::splat(0.0), |m, &x| m.max(x.abs()) + (x - x))
        };
        let (y_norm, top) = (
            row_norms(&run.y),
            [row_norms(&c[order - 1]), row_norms(&c[order])],
        );
        // The step rule for all lanes at once (vectorised), then lane by lane.
        let mut steps = [None; LANES];
        for (l, step) in steps.iter_mut().enumerate() {
            let exponent = step_exponent(y_norm.0[l], [top[0].0[l], top[1].0[l]], order);
            *step = step_from_exponent(exponent, safety);
        }
        let mut h = [0.0; LANES];
        let mut last = [false; LANES];
        let mut stepping = run.running;
        for l in (0..LANES).filter(|&l| run.running[l]) {
            self.stats.f_evals += order as u64;
            let (t, t1) = (run.t[l], run.end[l]);
            let direction = (t1 - t).signum();
            match step_to_take(steps[l], (t1 - t).abs(), t, || run.state(l)) {
                Ok((step, is_last)) => (h[l], last[l]) = (step * direction, is_last),
                Err(e) => (ends[l], stepping[l]) = (Some(Err(e)), false),
            }
        }
        let y_new = horner(c, Lanes(h));
        // x − x is 0 for finite x, NaN otherwise: one vector pass.
        let mut check = Lanes::splat(0.0);
        #[allow(clippy::eq_op)] // (x − x is the point)
        for row in &y_new {
            check += *row - *row;
        }
        for l in (0..LANES).filter(|&l| stepping[l]) {
            ends[l] = run.step(
                l,
                &y_new,
                check.0[l] == 0.0,
                (h[l], last[l]),
                self.max_steps,
            );
        }
        Some(ends)
    }
}

/// Where a stream's lanes run towards: never reached by a step of a
/// series that is not exact (an exact one takes it in one step, its
/// polynomial then covering every segment end).
pub(super) const HORIZON: f64 = f64::MAX;

/// Whether a segment's callback changed the state sampled (bit for bit, so
/// that a NaN left alone is no change): the run then restarts from it.
pub(super) fn changed<const N: usize>(state: &[f64; N], sampled: &[f64; N]) -> bool {
    state
        .iter()
        .zip(sampled)
        .any(|(a, b)| a.to_bits() != b.to_bits())
}

/// Σ_k c[k] τ^k of lane `l` alone: as [`horner`] computes it for that
/// lane, and as the scalar method's dense output does.
fn lane_horner<const N: usize>(c: &[[Lanes; N]], l: usize, tau: f64) -> [f64; N] {
    let (last, lower) = c.split_last().expect("at least order 0");
    let mut y: [f64; N] = std::array::from_fn(|i| last[i].0[l]);
    for row in lower.iter().rev() {
        for i in 0..N {
            y[i] = super::series::fused(y[i], tau, row[i].0[l]);
        }
    }
    y
}

/// The lanes' times, ends, Kahan carries, states, step counts (of the
/// current run from t0) and whether each is running.
struct Run<const N: usize> {
    t: [f64; LANES],
    end: [f64; LANES],
    carry: [f64; LANES],
    y: [Lanes; N],
    steps: [u64; LANES],
    running: [bool; LANES],
}

impl<const N: usize> Run<N> {
    fn new(t0: f64, y0: &[[f64; N]; LANES], t1: f64) -> Run<N> {
        Run {
            t: [t0; LANES],
            end: [t1; LANES],
            carry: [0.0; LANES],
            y: std::array::from_fn(|i| Lanes(std::array::from_fn(|l| y0[l][i]))),
            steps: [0; LANES],
            running: [true; LANES],
        }
    }

    /// Starts lane `l` afresh at time `t` from `y`, towards the horizon
    /// (a stream's lanes run on until their orbit is done).
    fn restart(&mut self, l: usize, t: f64, y: &[f64; N]) {
        for (i, x) in y.iter().enumerate() {
            self.y[i].0[l] = *x;
        }
        (self.t[l], self.carry[l], self.steps[l], self.running[l]) = (t, 0.0, 0, true);
        self.end[l] = HORIZON;
    }

    fn state(&self, l: usize) -> [f64; N] {
        std::array::from_fn(|i| self.y[i].0[l])
    }

    /// Moves lane `l` to the end of its step (`finite`: whether its new
    /// state is); its result when its run ends there (reached t1, diverged,
    /// or out of steps).
    #[inline(always)]
    fn step(
        &mut self,
        l: usize,
        y_new: &[Lanes; N],
        finite: bool,
        (h, last): (f64, bool),
        max_steps: u64,
    ) -> Option<LaneResult<N>> {
        let t = self.t[l];
        let t_new = if last {
            self.end[l]
        } else {
            compensated_sum(t, h, &mut self.carry[l])
        };
        if !finite {
            let y: [f64; N] = std::array::from_fn(|i| y_new[i].0[l]);
            return Some(Err(OdeError::NonFinite {
                t: t_new,
                y: y.to_vec(),
            }));
        }
        if !last && t_new == t {
            return Some(Err(OdeError::StepSizeUnderflow { t, h }));
        }
        for (i, row) in y_new.iter().enumerate() {
            self.y[i].0[l] = row.0[l];
        }
        self.t[l] = t_new;
        self.steps[l] += 1;
        if last {
            return Some(Ok(self.state(l)));
        }
        (self.steps[l] >= max_steps).then_some(Err(OdeError::TooManySteps {
            t: t_new,
            max_steps,
        }))
    }
}
