//! Implicit Gauss–Legendre Runge–Kutta methods (2 stages: order 4, 3 stages:
//! order 6), with a fixed step. They are symplectic: on a Hamiltonian period
//! map the energy error stays bounded instead of drifting. The stage
//! equations are solved by fixed-point iteration until the increments reach
//! round-off, and the solution is accumulated with compensated summation so
//! that round-off does not drift over 10⁶ steps either.

use super::{check_finite, fixed_steps, OdeError, Stats, System};

struct Tableau {
    c: [f64; 3],
    a: [[f64; 3]; 3],
    b: [f64; 3],
}

fn tableau(stages: usize) -> Tableau {
    if stages == 2 {
        let r = 3f64.sqrt() / 6.0;
        Tableau {
            c: [0.5 - r, 0.5 + r, 0.0],
            a: [[0.25, 0.25 - r, 0.0], [0.25 + r, 0.25, 0.0], [0.0; 3]],
            b: [0.5, 0.5, 0.0],
        }
    } else {
        let r = 15f64.sqrt();
        Tableau {
            c: [0.5 - r / 10.0, 0.5, 0.5 + r / 10.0],
            a: [
                [5.0 / 36.0, 2.0 / 9.0 - r / 15.0, 5.0 / 36.0 - r / 30.0],
                [5.0 / 36.0 + r / 24.0, 2.0 / 9.0, 5.0 / 36.0 - r / 24.0],
                [5.0 / 36.0 + r / 30.0, 2.0 / 9.0 + r / 15.0, 5.0 / 36.0],
            ],
            b: [5.0 / 18.0, 4.0 / 9.0, 5.0 / 18.0],
        }
    }
}

const MAX_ITERATIONS: u32 = 60;

#[allow(clippy::too_many_arguments)]
pub(super) fn integrate<S: System<N>, const N: usize>(
    system: &S,
    stages: usize,
    t0: f64,
    y0: &[f64; N],
    t1: f64,
    max_step: f64,
    max_steps: u64,
    stats: &mut Stats,
    observe: &mut dyn FnMut(f64, &[f64; N]),
) -> Result<[f64; N], OdeError> {
    let tab = tableau(stages);
    let s = stages;
    let (n, h) = fixed_steps(t0, t1, max_step, max_steps)?;
    let mut y = *y0;
    let mut compensation = [0.0; N];
    // Stage derivatives; the previous step's values start the iteration.
    let f0 = system.rhs(t0, &y);
    stats.f_evals += 1;
    let mut f = [f0; 3];
    for step in 0..n {
        let t = t0 + step as f64 * h;
        let scale = 1.0 + y.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let mut previous = f64::INFINITY;
        let mut converged = false;
        for _ in 0..MAX_ITERATIONS {
            stats.iterations += 1;
            let mut change = 0.0f64;
            let mut next = f;
            for i in 0..s {
                let mut z = y;
                for k in 0..N {
                    let mut acc = 0.0;
                    for j in 0..s {
                        acc += tab.a[i][j] * f[j][k];
                    }
                    z[k] += h * acc;
                }
                next[i] = system.rhs(t + tab.c[i] * h, &z);
                for k in 0..N {
                    change = change.max((h * (next[i][k] - f[i][k])).abs());
                }
            }
            stats.f_evals += s as u64;
            f = next;
            let relative = change / scale;
            if !relative.is_finite() {
                return Err(OdeError::NonFinite { t, y: y.to_vec() });
            }
            // Converged to round-off: no change, or changes stopped shrinking at the round-off level.
            if relative == 0.0 || (relative < 1e-13 && relative >= previous) || relative < 1e-16 {
                converged = true;
                break;
            }
            previous = relative;
        }
        if !converged && previous > 1e-10 {
            return Err(OdeError::NoConvergence {
                t,
                h,
                y: y.to_vec(),
            });
        }
        for k in 0..N {
            let mut increment = 0.0;
            for j in 0..s {
                increment += tab.b[j] * f[j][k];
            }
            let delta = h * increment + compensation[k];
            let updated = y[k] + delta;
            compensation[k] = delta - (updated - y[k]);
            y[k] = updated;
        }
        let t_next = if step + 1 == n {
            t1
        } else {
            t0 + (step + 1) as f64 * h
        };
        check_finite(t_next, &y)?;
        stats.steps += 1;
        observe(t_next, &y);
    }
    Ok(y)
}
