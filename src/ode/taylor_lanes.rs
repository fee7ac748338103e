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

use super::lanes::{Lanes, LANES};
use super::taylor::{
    compensated_sum, horner, safety, step_exponent, step_from_exponent, step_to_take,
};
use super::{
    check_finite, check_initial, order_for_tolerance, Method, OdeError, Stats, System, TaylorWork,
};

/// The result of one lane.
pub type LaneResult<const N: usize> = Result<[f64; N], OdeError>;

/// The batch Taylor integrator: the method's tolerance, its workspace and the
/// run's statistics, summed over lanes (`steps` and `f_evals` count each
/// lane's steps, as the scalar runs would).
#[derive(Clone, Debug)]
pub struct LaneIntegrator {
    tol: f64,
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
        Ok(LaneIntegrator {
            tol,
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
        let mut running = active;
        for l in (0..LANES).filter(|&l| active[l]) {
            if let Err(e) = check_initial(t0, &y0[l], t1) {
                (results[l], running[l]) = (Err(e), false);
            }
        }
        if t1 == t0 {
            return results;
        }
        let order = order_for_tolerance(self.tol);
        self.stats.order = self.stats.order.max(order as u64);
        self.coefficients.resize((order + 1) * N, Lanes::default());
        let direction = (t1 - t0).signum();
        let safety = safety(order);
        let mut lanes = Run {
            t: [t0; LANES],
            carry: [0.0; LANES],
            y: std::array::from_fn(|i| Lanes(std::array::from_fn(|l| y0[l][i]))),
            steps: [0; LANES],
        };
        while running.iter().any(|&r| r) {
            let (c, _) = self.coefficients.as_chunks_mut::<N>();
            if !system.taylor(Lanes(lanes.t), &lanes.y, order, &mut self.work, c) {
                return std::array::from_fn(|_| Err(OdeError::TaylorUnavailable));
            }
            let row_norms =
                |row: &[Lanes; N]| row.iter().fold(Lanes::splat(0.0), |m, x| m.max(x.abs()));
            let (y_norm, top) = (
                row_norms(&lanes.y),
                [row_norms(&c[order - 1]), row_norms(&c[order])],
            );
            // The step rule for all lanes at once (vectorised), then lane by lane.
            let mut exponents = [0.0; LANES];
            for (l, exponent) in exponents.iter_mut().enumerate() {
                *exponent = step_exponent(y_norm.0[l], [top[0].0[l], top[1].0[l]], order);
            }
            let mut h = [0.0; LANES];
            let mut last = [false; LANES];
            let stepping = running;
            for l in (0..LANES).filter(|&l| stepping[l]) {
                self.stats.f_evals += order as u64;
                let y = lanes.state(l);
                let step = step_from_exponent(exponents[l], safety);
                match step_to_take(step, (t1 - lanes.t[l]).abs(), lanes.t[l], &y) {
                    Ok((step, is_last)) => (h[l], last[l]) = (step * direction, is_last),
                    Err(e) => (results[l], running[l]) = (Err(e), false),
                }
            }
            let y_new = horner(c, Lanes(h));
            let stepping = running;
            for l in (0..LANES).filter(|&l| stepping[l]) {
                if let Some(result) = lanes.step(l, y_new, h[l], last[l], t1, self.max_steps) {
                    (results[l], running[l]) = (result, false);
                }
            }
        }
        self.stats.steps += lanes.steps.iter().sum::<u64>();
        results
    }
}

/// The lanes' times, Kahan carries, states and step counts.
struct Run<const N: usize> {
    t: [f64; LANES],
    carry: [f64; LANES],
    y: [Lanes; N],
    steps: [u64; LANES],
}

impl<const N: usize> Run<N> {
    fn state(&self, l: usize) -> [f64; N] {
        std::array::from_fn(|i| self.y[i].0[l])
    }

    /// Moves lane `l` to the end of its step; its result when its run ends
    /// there (reached t1, diverged, or out of steps).
    fn step(
        &mut self,
        l: usize,
        y_new: [Lanes; N],
        h: f64,
        last: bool,
        t1: f64,
        max_steps: u64,
    ) -> Option<LaneResult<N>> {
        let t = self.t[l];
        let t_new = if last {
            t1
        } else {
            compensated_sum(t, h, &mut self.carry[l])
        };
        let y: [f64; N] = std::array::from_fn(|i| y_new[i].0[l]);
        if let Err(e) = check_finite(t_new, &y) {
            return Some(Err(e));
        }
        if !last && t_new == t {
            return Some(Err(OdeError::StepSizeUnderflow { t, h }));
        }
        for (i, x) in y.iter().enumerate() {
            self.y[i].0[l] = *x;
        }
        self.t[l] = t_new;
        self.steps[l] += 1;
        if last {
            return Some(Ok(y));
        }
        (self.steps[l] >= max_steps).then_some(Err(OdeError::TooManySteps {
            t: t_new,
            max_steps,
        }))
    }
}
