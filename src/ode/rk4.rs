//! The classical fourth-order Runge–Kutta method with a fixed step.

use super::{check_finite, fixed_steps, OdeError, Stats, System};

#[allow(clippy::too_many_arguments)]
pub(super) fn integrate<S: System<N>, const N: usize>(
    system: &S,
    t0: f64,
    y0: &[f64; N],
    t1: f64,
    max_step: f64,
    max_steps: u64,
    stats: &mut Stats,
    observe: &mut dyn FnMut(f64, &[f64; N]),
) -> Result<[f64; N], OdeError> {
    let (n, h) = fixed_steps(t0, t1, max_step, max_steps)?;
    let mut y = *y0;
    for i in 0..n {
        let t = t0 + i as f64 * h;
        let k1 = system.rhs(t, &y);
        let k2 = system.rhs(
            t + 0.5 * h,
            &std::array::from_fn(|j| y[j] + 0.5 * h * k1[j]),
        );
        let k3 = system.rhs(
            t + 0.5 * h,
            &std::array::from_fn(|j| y[j] + 0.5 * h * k2[j]),
        );
        let k4 = system.rhs(t + h, &std::array::from_fn(|j| y[j] + h * k3[j]));
        for j in 0..N {
            y[j] += h / 6.0 * (k1[j] + 2.0 * (k2[j] + k3[j]) + k4[j]);
        }
        let t_next = if i + 1 == n {
            t1
        } else {
            t0 + (i + 1) as f64 * h
        };
        check_finite(t_next, &y)?;
        stats.f_evals += 4;
        stats.steps += 1;
        observe(t_next, &y);
    }
    Ok(y)
}
