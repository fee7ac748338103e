//! The classical fourth-order Runge–Kutta method with a fixed step.

use super::driver::{Attempt, Schedule, Stepper};
use super::{OdeError, Stats, Step, System};

/// One RK4 step of size h from (t, y).
#[inline(always)]
fn step<S: System<N>, const N: usize>(system: &S, t: f64, y: &[f64; N], h: f64) -> [f64; N] {
    let k1 = system.rhs(t, y);
    let k2 = system.rhs(
        t + 0.5 * h,
        &std::array::from_fn(|j| y[j] + 0.5 * h * k1[j]),
    );
    let k3 = system.rhs(
        t + 0.5 * h,
        &std::array::from_fn(|j| y[j] + 0.5 * h * k2[j]),
    );
    let k4 = system.rhs(t + h, &std::array::from_fn(|j| y[j] + h * k3[j]));
    std::array::from_fn(|j| y[j] + h / 6.0 * (k1[j] + 2.0 * (k2[j] + k3[j]) + k4[j]))
}

/// An accepted RK4 step; inside it, states come from a fresh RK4 step of the
/// partial length, so they carry the method's own order.
pub(super) struct Rk4Step<'a, S, const N: usize> {
    system: &'a S,
    t0: f64,
    y0: [f64; N],
    t1: f64,
    y1: [f64; N],
    stats: &'a mut Stats,
}

impl<S: System<N>, const N: usize> Step<N> for Rk4Step<'_, S, N> {
    fn start(&self) -> (f64, &[f64; N]) {
        (self.t0, &self.y0)
    }
    fn end(&self) -> (f64, &[f64; N]) {
        (self.t1, &self.y1)
    }
    fn state_at(&mut self, t: f64) -> Result<[f64; N], OdeError> {
        self.stats.f_evals += 4;
        Ok(step(self.system, self.t0, &self.y0, t - self.t0))
    }
}

/// The method's state: none beyond the step.
pub(super) struct Rk4 {
    pub max_step: f64,
}

impl<S: System<N>, const N: usize> Stepper<S, N> for Rk4 {
    type Accepted<'a>
        = Rk4Step<'a, S, N>
    where
        S: 'a;

    fn schedule(&self) -> Schedule {
        Schedule::Fixed {
            max_step: self.max_step,
        }
    }

    /// The classical Runge–Kutta method's region reaches −2.785.
    fn stability_reach(&self) -> Option<(&'static str, f64)> {
        Some(("rk4", 2.785))
    }

    fn attempt(
        &mut self,
        system: &S,
        t: f64,
        y: &[f64; N],
        h: f64,
        _t_end: f64,
        stats: &mut Stats,
    ) -> Result<Attempt<N>, OdeError> {
        stats.f_evals += 4;
        Ok(Attempt::Accepted {
            y: step(system, t, y, h),
            next: self.max_step,
        })
    }

    fn accepted<'a>(
        &'a mut self,
        system: &'a S,
        (t0, y0): (f64, [f64; N]),
        (t1, y1): (f64, [f64; N]),
        _h: f64,
        stats: &'a mut Stats,
    ) -> Rk4Step<'a, S, N> {
        Rk4Step {
            system,
            t0,
            y0,
            t1,
            y1,
            stats,
        }
    }
}
