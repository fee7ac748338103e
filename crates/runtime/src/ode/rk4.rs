//! The classical fourth-order Runge–Kutta method with a fixed step.

use super::{check_finite, fixed_steps, Flow, Observer, OdeError, Stats, Step, System};

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
struct Rk4Step<'a, S, const N: usize> {
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

#[allow(clippy::too_many_arguments)]
pub(super) fn integrate<S: System<N>, const N: usize>(
    system: &S,
    t0: f64,
    y0: &[f64; N],
    t1: f64,
    max_step: f64,
    max_steps: u64,
    stats: &mut Stats,
    observe: Observer<'_, N>,
) -> Result<(f64, [f64; N]), OdeError> {
    let (n, h) = fixed_steps(t0, t1, max_step, max_steps)?;
    let mut y = *y0;
    for i in 0..n {
        let t = t0 + i as f64 * h;
        let y_new = step(system, t, &y, h);
        let t_next = if i + 1 == n {
            t1
        } else {
            t0 + (i + 1) as f64 * h
        };
        check_finite(t_next, &y_new)?;
        stats.f_evals += 4;
        stats.steps += 1;
        let mut view = Rk4Step {
            system,
            t0: t,
            y0: y,
            t1: t_next,
            y1: y_new,
            stats,
        };
        if let Flow::Stop { t, y } = observe(&mut view)? {
            return Ok((t, y));
        }
        y = y_new;
    }
    Ok((t1, y))
}
