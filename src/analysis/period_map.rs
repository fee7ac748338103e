//! The period map of a T-periodic system and its orbits.

use crate::ode::{Integrator, Method, OdeError, Stats, System};
use rayon::prelude::*;

/// Wraps an angle into [−π, π).
pub fn wrap_angle(x: f64) -> f64 {
    let two_pi = std::f64::consts::TAU;
    let w = (x + std::f64::consts::PI).rem_euclid(two_pi) - std::f64::consts::PI;
    // rem_euclid can return two_pi for tiny negative inputs.
    if w >= std::f64::consts::PI {
        w - two_pi
    } else {
        w
    }
}

/// Advances `y` by one forcing period. The system is T-periodic, so every
/// period is integrated over [0, T]: no large times, no loss of phase accuracy.
pub fn period_map<S: System<N>, const N: usize>(
    integrator: &mut Integrator,
    system: &S,
    period: f64,
    y: &[f64; N],
) -> Result<[f64; N], OdeError> {
    integrator.advance(system, 0.0, y, period)
}

/// `periods` iterates of the period map from `y0` (y0 first), with the
/// coordinates flagged in `wrap` kept in [−π, π) (exact: the field is 2π-periodic in them).
pub fn orbit<S: System<N>, const N: usize>(
    integrator: &mut Integrator,
    system: &S,
    period: f64,
    y0: &[f64; N],
    periods: usize,
    wrap: &[bool],
) -> Result<Vec<[f64; N]>, OdeError> {
    let mut points = Vec::with_capacity(periods + 1);
    let mut y = *y0;
    points.push(y);
    for _ in 0..periods {
        y = period_map(integrator, system, period, &y)?;
        for (x, w) in y.iter_mut().zip(wrap) {
            if *w {
                *x = wrap_angle(*x);
            }
        }
        points.push(y);
    }
    Ok(points)
}

/// Orbits of many initial conditions in parallel, in input order, each with its statistics.
pub fn orbits<S: System<N> + Sync, const N: usize>(
    method: Method,
    system: &S,
    period: f64,
    initial: &[[f64; N]],
    periods: usize,
    wrap: &[bool],
) -> Vec<Result<(Vec<[f64; N]>, Stats), OdeError>> {
    initial
        .par_iter()
        .map(|y0| {
            let mut integrator = Integrator::new(method)?;
            let points = orbit(&mut integrator, system, period, y0, periods, wrap)?;
            Ok((points, integrator.stats))
        })
        .collect()
}
