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
use super::taylor::{horner, safety, step_exponent, step_from_exponent};
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
            let Some(ended) = self.step_lanes([system; LANES], &mut run) else {
                return std::array::from_fn(|_| Err(OdeError::TaylorUnavailable));
            };
            for l in members(ended) {
                results[l] = match run.errors[l].take() {
                    Some(e) => Err(e),
                    None => Ok(run.state(l)),
                };
                run.running[l] = false;
            }
        }
        self.stats.steps += run.steps.iter().sum::<u64>();
        results
    }

    /// Integrates every orbit over consecutive segments of time `end`, the
    /// time restarting at 0 after each (as a period map's does: the field
    /// must be the same there), [`LANES`] orbits at a time, each lane
    /// exactly as the scalar
    /// [`Integrator::stream`](super::Integrator::stream)
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
            let Some(ended) = self.step_lanes(lanes.0, &mut run) else {
                return vec![Some(OdeError::TaylorUnavailable); orbits.len()];
            };
            // The running lanes whose step reached their segment's end.
            let crossed = lane_set(std::array::from_fn(|l| {
                run.running[l] && lanes.2[l] <= run.t[l]
            }));
            let (c, _) = self.coefficients.as_chunks::<N>();
            for l in members(ended | crossed) {
                let (k, segment) = (lanes.1[l], lanes.2[l]);
                // How its orbit ends with this step, if it does: Some(None)
                // when done, Some(Some(e)) with an error. A lane that ended
                // without one reached the horizon (an exact series: its
                // segment ends are all sampled from this one step).
                let mut outcome = run.errors[l].take().map(Some);
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
    /// towards its end: the lanes whose run ends with it, at its end or with
    /// an error (left in `run.errors`); `None` when the system has no Taylor
    /// recurrences. The step rule, the steps and the new states are taken
    /// for all lanes at once (branch-free loops over the lanes, which the
    /// compiler vectorises); only a lane in trouble is handled on its own.
    fn step_lanes<S: System<N>, const N: usize>(
        &mut self,
        systems: [&S; LANES],
        run: &mut Run<N>,
    ) -> Option<LaneSet> {
        if super::stop::stop_requested() {
            let running = lane_set(run.running);
            for l in members(running) {
                run.errors[l] = Some(OdeError::Stopped { t: run.t[l] });
            }
            return Some(running);
        }
        let (order, safety) = (self.order, self.safety);
        self.stats.order = self.stats.order.max(order as u64);
        self.coefficients.resize((order + 1) * N, Lanes::default());
        let (c, _) = self.coefficients.as_chunks_mut::<N>();
        if !S::taylor_lanes(systems, Lanes(run.t), &run.y, order, &mut self.work, c) {
            return None;
        }
        let running = lane_set(run.running);
        self.stats.f_evals += order as u64 * u64::from(running.count_ones());
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
        // The step rule and the step the scalar driver takes from it (cut to
        // the end it reaches), lane by lane with the same operations, as
        // selects instead of branches.
        let (mut h, mut last, mut sizes) = ([0.0; LANES], [false; LANES], [0.0; LANES]);
        let (mut non_finite, mut underflow) = ([false; LANES], [false; LANES]);
        for l in 0..LANES {
            let exponent = step_exponent(y_norm.0[l], [top[0].0[l], top[1].0[l]], order);
            let step = step_from_exponent(exponent, safety);
            let (t, t1) = (run.t[l], run.end[l]);
            let remaining = (t1 - t).abs();
            // No step (None): the series is exact, and covers the rest.
            let size = step.unwrap_or(remaining);
            sizes[l] = size;
            non_finite[l] = !size.is_finite();
            underflow[l] = size <= 0.0 && remaining > 0.0;
            last[l] = size >= remaining;
            h[l] = (if last[l] { remaining } else { size }) * (t1 - t).signum();
        }
        let troubled = running & (lane_set(non_finite) | lane_set(underflow));
        for l in members(troubled) {
            run.errors[l] = Some(if non_finite[l] {
                OdeError::NonFinite {
                    t: run.t[l],
                    y: run.state(l).to_vec(),
                }
            } else {
                OdeError::StepSizeUnderflow {
                    t: run.t[l],
                    h: sizes[l],
                    y: run.state(l).into(),
                }
            });
        }
        let stepping = running & !troubled;
        let y_new = horner(c, Lanes(h));
        // x − x is 0 for finite x, NaN otherwise: one vector pass.
        let mut check = Lanes::splat(0.0);
        #[allow(clippy::eq_op)] // (x − x is the point)
        for row in &y_new {
            check += *row - *row;
        }
        let (ended, failed, t_new) = run.step(stepping, &y_new, check, (h, last), self.max_steps);
        for l in members(failed) {
            run.errors[l] = Some(if check.0[l] != 0.0 {
                OdeError::NonFinite {
                    t: t_new[l],
                    y: (0..N).map(|i| y_new[i].0[l]).collect(),
                }
            } else {
                OdeError::StepSizeUnderflow {
                    t: run.t[l],
                    h: h[l],
                    y: run.state(l).into(),
                }
            });
        }
        Some(troubled | ended | failed)
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

/// Lanes as a set: bit l for lane l.
type LaneSet = u32;

fn lane_set(flags: [bool; LANES]) -> LaneSet {
    flags
        .iter()
        .enumerate()
        .fold(0, |set, (l, &f)| set | (LaneSet::from(f) << l))
}

/// The lanes of a set, in order.
fn members(mut set: LaneSet) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        (set != 0).then(|| {
            let l = set.trailing_zeros() as usize;
            set &= set - 1;
            l
        })
    })
}

/// The lanes' times, ends, Kahan carries, states, step counts (of the
/// current run from t0), whether each is running, and the error each
/// lane's run ended with.
struct Run<const N: usize> {
    t: [f64; LANES],
    end: [f64; LANES],
    carry: [f64; LANES],
    y: [Lanes; N],
    steps: [u64; LANES],
    running: [bool; LANES],
    errors: [Option<OdeError>; LANES],
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
            errors: std::array::from_fn(|_| None),
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
        self.errors[l] = None;
    }

    fn state(&self, l: usize) -> [f64; N] {
        std::array::from_fn(|i| self.y[i].0[l])
    }

    /// Moves the `stepping` lanes by their steps (h, last) to the states
    /// `y_new` (`check` is 0 in the lanes where they are finite), as the
    /// scalar method does. Returns the lanes whose run ends there (at its
    /// end, or out of steps with the error in `errors`), those whose step
    /// failed (a non-finite state, or a step too small to move t: left
    /// where they were), and the time each step reached.
    fn step(
        &mut self,
        stepping: LaneSet,
        y_new: &[Lanes; N],
        check: Lanes,
        (h, last): ([f64; LANES], [bool; LANES]),
        max_steps: u64,
    ) -> (LaneSet, LaneSet, [f64; LANES]) {
        let mut t_new = [0.0; LANES];
        let (mut moved, mut out_of_steps) = ([false; LANES], [false; LANES]);
        for l in 0..LANES {
            let t = self.t[l];
            let mut carry = self.carry[l];
            let sum = compensated_sum(t, h[l], &mut carry);
            t_new[l] = if last[l] { self.end[l] } else { sum };
            moved[l] = stepping >> l & 1 == 1 && check.0[l] == 0.0 && (last[l] || t_new[l] != t);
            if moved[l] {
                self.t[l] = t_new[l];
                if !last[l] {
                    self.carry[l] = carry;
                }
                self.steps[l] += 1;
            }
            out_of_steps[l] = !last[l] && self.steps[l] >= max_steps;
        }
        for (row, new) in self.y.iter_mut().zip(y_new) {
            for l in 0..LANES {
                row.0[l] = if moved[l] { new.0[l] } else { row.0[l] };
            }
        }
        let moved = lane_set(moved);
        let out_of_steps = moved & lane_set(out_of_steps);
        for l in members(out_of_steps) {
            self.errors[l] = Some(OdeError::TooManySteps {
                t: t_new[l],
                max_steps,
            });
        }
        let ended = moved & (lane_set(last) | out_of_steps);
        (ended, stepping & !moved, t_new)
    }
}
