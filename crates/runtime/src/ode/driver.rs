//! The one stepping loop every method runs in.
//!
//! As in SciPy's `OdeSolver.step`/`_step_impl` or diffsol's
//! `OdeSolverMethod::step`, a method is a [`Stepper`]: it tries one step of
//! a given size and says whether it is accepted and what size to try next.
//! Everything around it is written once, here: the direction of the run,
//! fixed or adaptive step sizes, the last step that lands on t1, the step
//! limit, step-size underflow, non-finite states, the observers (sampling,
//! events, stopping) and the step size carried to the next call.

use super::{Flow, Observer, OdeError, Stats, Step, System};

/// How a method's step sizes are chosen.
#[derive(Clone, Copy, Debug)]
pub(super) enum Schedule {
    /// Equal steps of at most `max_step` covering the interval; the times
    /// are t0 + i·h, so no phase is lost to rounding.
    Fixed { max_step: f64 },
    /// Sizes proposed by the method from step to step.
    Adaptive {
        /// A proposal within this relative distance of the end takes the
        /// rest of the interval (no sliver of a last step).
        snap: f64,
        /// Accumulate the time with Kahan compensation (a million steps lose
        /// no phase).
        compensated: bool,
        /// A step smaller than this times max(|t|, 1) is an underflow (a
        /// step that does not move t always is).
        underflow: f64,
    },
}

/// What a method's attempt at one step gives.
pub(super) enum Attempt<const N: usize> {
    /// The state at the end of the step, and the size (unsigned) it
    /// proposes for the next one.
    Accepted { y: [f64; N], next: f64 },
    /// The step failed its error test; try this size (unsigned) instead.
    Rejected { retry: f64 },
}

/// One integration method: what is particular to it. Its state (stages,
/// workspaces, flags) lives in the value; the driver owns the loop.
pub(super) trait Stepper<S: System<N>, const N: usize> {
    /// The accepted step as observers see it (dense output included).
    type Accepted<'a>: Step<N>
    where
        Self: 'a,
        S: 'a;

    fn schedule(&self) -> Schedule;

    /// An explicit method's name and how far its stability region reaches
    /// along the negative real axis (|h λ| at its edge): a run whose steps
    /// the model's fastest decay holds at that edge is stiff. None for an
    /// implicit method or one whose step follows the local solution.
    #[inline(always)]
    fn stability_reach(&self) -> Option<(&'static str, f64)> {
        None
    }

    /// Prepares a run from (t0, y0) towards t1 and returns the first step
    /// size to try (unsigned; adaptive methods), given the size `carried`
    /// from the previous call. Nothing to prepare by default.
    #[inline(always)]
    fn begin(
        &mut self,
        _system: &S,
        _t0: f64,
        _y0: &[f64; N],
        _t1: f64,
        _carried: Option<f64>,
        _stats: &mut Stats,
    ) -> Result<f64, OdeError> {
        Ok(f64::INFINITY)
    }

    /// The size to try from (t, y) given the proposal: the proposal itself,
    /// or for a method whose step follows from the local solution (Taylor)
    /// its own size (+∞ when the step is exact).
    #[inline(always)]
    fn size(
        &mut self,
        _system: &S,
        _t: f64,
        _y: &[f64; N],
        proposal: f64,
        _stats: &mut Stats,
    ) -> Result<f64, OdeError> {
        Ok(proposal)
    }

    /// Tries one step of signed size `h` from (t, y) to `t_end` (t + h, or
    /// t1 exactly on the last step).
    fn attempt(
        &mut self,
        system: &S,
        t: f64,
        y: &[f64; N],
        h: f64,
        t_end: f64,
        stats: &mut Stats,
    ) -> Result<Attempt<N>, OdeError>;

    /// The step just accepted, from `start` to `end` with signed size `h`.
    fn accepted<'a>(
        &'a mut self,
        system: &'a S,
        start: (f64, [f64; N]),
        end: (f64, [f64; N]),
        h: f64,
        stats: &'a mut Stats,
    ) -> Self::Accepted<'a>;
}

/// Where the next step ends, for the two kinds of [`Schedule`].
enum Clock {
    Fixed {
        t0: f64,
        h: f64,
        steps: u64,
        taken: u64,
    },
    Adaptive {
        snap: f64,
        compensated: bool,
        underflow: f64,
        carry: f64,
    },
}

impl Clock {
    #[inline(always)]
    fn new(schedule: Schedule, t0: f64, t1: f64, max_steps: u64) -> Result<Clock, OdeError> {
        Ok(match schedule {
            Schedule::Fixed { max_step } => {
                let (steps, h) = fixed_steps(t0, t1, max_step, max_steps)?;
                Clock::Fixed {
                    t0,
                    h,
                    steps,
                    taken: 0,
                }
            }
            Schedule::Adaptive {
                snap,
                compensated,
                underflow,
            } => Clock::Adaptive {
                snap,
                compensated,
                underflow,
                carry: 0.0,
            },
        })
    }

    /// The end of a step of signed size `signed` from t (t1 for the last),
    /// and the compensation it leaves if accepted.
    #[inline(always)]
    fn end_of_step(&self, t: f64, signed: f64, last: bool, t1: f64) -> (f64, f64) {
        match *self {
            _ if last => (t1, 0.0),
            Clock::Fixed { t0, h, taken, .. } => (t0 + (taken + 1) as f64 * h, 0.0),
            Clock::Adaptive {
                compensated: true,
                carry,
                ..
            } => {
                let mut carry = carry;
                (compensated_sum(t, signed, &mut carry), carry)
            }
            Clock::Adaptive { .. } => (t + signed, 0.0),
        }
    }

    /// A step was accepted, leaving the compensation `carry`.
    #[inline(always)]
    fn accept(&mut self, carry_new: f64) {
        match self {
            Clock::Fixed { taken, .. } => *taken += 1,
            Clock::Adaptive { carry, .. } => *carry = carry_new,
        }
    }
}

/// Integrates from (t0, y0) to t1 with `stepper`, calling `observe` after
/// every accepted step. `next_step` is the size to start with and, on
/// return, the one to try next (adaptive methods): the proposal, not a last
/// step truncated to reach t1.
#[allow(clippy::too_many_arguments)]
pub(super) fn drive<S: System<N>, M: Stepper<S, N>, const N: usize>(
    stepper: &mut M,
    system: &S,
    t0: f64,
    y0: &[f64; N],
    t1: f64,
    (max_steps, to_the_end): (u64, bool),
    next_step: &mut Option<f64>,
    stats: &mut Stats,
    observe: Observer<'_, N>,
) -> Result<(f64, [f64; N]), OdeError> {
    let direction = (t1 - t0).signum();
    let span = (t1 - t0).abs();
    let mut clock = Clock::new(stepper.schedule(), t0, t1, max_steps)?;
    let mut h = stepper
        .begin(system, t0, y0, t1, *next_step, stats)?
        .min(span);
    let (mut t, mut y) = (t0, *y0);
    let mut attempts = 0u64;
    let mut after_rejection = false;
    loop {
        if attempts >= max_steps {
            return Err(stiff_or(
                stepper,
                system,
                (t, &y, h),
                OdeError::TooManySteps { t, max_steps },
            ));
        }
        if to_the_end {
            check_pace(attempts, max_steps, (t0, t, t1))
                .map_err(|e| stiff_or(stepper, system, (t, &y, h), e))?;
        }
        if super::stop::stop_requested() {
            return Err(OdeError::Stopped { t });
        }
        attempts += 1;
        let (signed, last) = match clock {
            Clock::Fixed {
                h, steps, taken, ..
            } => (h, taken + 1 == steps),
            Clock::Adaptive {
                snap, underflow, ..
            } => {
                let remaining = (t1 - t).abs();
                let size = stepper.size(system, t, &y, h, stats)?;
                let last = size >= remaining * (1.0 - snap);
                let size = if last { remaining } else { size };
                if size < underflow * t.abs().max(1.0) {
                    return Err(OdeError::StepSizeUnderflow {
                        t,
                        h: size,
                        y: y.as_slice().into(),
                    });
                }
                (direction * size, last)
            }
        };
        let size = signed.abs();
        let (t_new, carry_new) = clock.end_of_step(t, signed, last, t1);
        let (y_new, next) = match stepper.attempt(system, t, &y, signed, t_new, stats)? {
            Attempt::Rejected { retry } => {
                stats.rejected += 1;
                after_rejection = true;
                h = retry;
                continue;
            }
            // A step right after a rejection does not propose a larger one.
            Attempt::Accepted { y, next } if after_rejection => (y, next.min(size)),
            Attempt::Accepted { y, next } => (y, next),
        };
        after_rejection = false;
        clock.accept(carry_new);
        check_finite(t, &y, &y_new)?;
        if !last && t_new == t {
            return Err(OdeError::StepSizeUnderflow {
                t,
                h: signed,
                y: y.as_slice().into(),
            });
        }
        stats.steps += 1;
        let flow = {
            let mut step = stepper.accepted(system, (t, y), (t_new, y_new), signed, stats);
            observe(&mut step)?
        };
        let t_new = match flow {
            Flow::Stop { t, y } => {
                *next_step = Some(next);
                return Ok((t, y));
            }
            Flow::Retime { t } => t,
            Flow::Continue => t_new,
        };
        if last {
            *next_step = Some(if size < h { h } else { next });
            return Ok((t1, y_new));
        }
        (t, y, h) = (t_new, y_new, next);
    }
}

/// Number of equal fixed steps of at most `step` covering `t0..t1`, and
/// their signed size.
/// `error` (a run past its step limit), or where an explicit method's
/// step `h` at (t, y) is held at the edge of its stability region by the
/// model's fastest rate (the spectral radius of ∂f/∂y, where the system
/// knows it, at least half the reach over h): the verdict that the run is
/// stiff there, with the implicit method to choose.
fn stiff_or<S: System<N>, M: Stepper<S, N>, const N: usize>(
    stepper: &M,
    system: &S,
    (t, y, h): (f64, &[f64; N], f64),
    error: OdeError,
) -> OdeError {
    let Some((method, reach)) = stepper.stability_reach() else {
        return error;
    };
    let Some(jacobian) = system.jacobian(t, y) else {
        return error;
    };
    let matrix = nalgebra::DMatrix::from_fn(N, N, |i, j| jacobian[i][j]);
    let rate = matrix
        .complex_eigenvalues()
        .iter()
        .filter(|z| z.re < 0.0)
        .map(|z| z.norm())
        .fold(0.0, f64::max);
    if rate.is_finite() && rate * h.abs() >= 0.5 * reach {
        OdeError::Stiff {
            method,
            t,
            step: h.abs(),
            rate,
            source: Box::new(error),
        }
    } else {
        error
    }
}

/// After a hundredth of the step limit, the steps a run would take to its
/// end at its pace so far: more than a hundred times the limit (a run to
/// t = 1e9, a tolerance the arithmetic cannot hold) stops it with that
/// forecast, in a hundredth of the time the limit would take.
fn check_pace(attempts: u64, max_steps: u64, (t0, t, t1): (f64, f64, f64)) -> Result<(), OdeError> {
    if max_steps < 100 || attempts != max_steps / 100 {
        return Ok(());
    }
    let forecast = attempts as f64 * ((t1 - t0) / (t - t0)).abs();
    if forecast > 100.0 * max_steps as f64 {
        return Err(OdeError::TooLong {
            t,
            t_end: t1,
            forecast,
            max_steps,
        });
    }
    Ok(())
}

fn fixed_steps(t0: f64, t1: f64, step: f64, max_steps: u64) -> Result<(u64, f64), OdeError> {
    let n = ((t1 - t0).abs() / step).ceil().max(1.0);
    if n > max_steps as f64 {
        return Err(OdeError::TooManySteps { t: t0, max_steps });
    }
    let n = n as u64;
    Ok((n, (t1 - t0) / n as f64))
}

/// t + h with Kahan compensation (`carry`).
#[inline(always)]
pub(super) fn compensated_sum(t: f64, h: f64, carry: &mut f64) -> f64 {
    let increment = h - *carry;
    let sum = t + increment;
    *carry = (sum - t) - increment;
    sum
}

/// A step from `y` at `t` to `y_new`: an error naming the last finite
/// state (where a model defined only near its start can say which of its
/// expressions stops being real) if `y_new` is not finite.
pub(super) fn check_finite<const N: usize>(
    t: f64,
    y: &[f64; N],
    y_new: &[f64; N],
) -> Result<(), OdeError> {
    if y_new.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(OdeError::NonFinite { t, y: y.to_vec() })
    }
}
