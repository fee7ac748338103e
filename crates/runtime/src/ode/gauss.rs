//! Implicit Gauss–Legendre Runge–Kutta methods (2 stages: order 4, 3 stages:
//! order 6), with a fixed step. They are symplectic: on a Hamiltonian period
//! map the energy error stays bounded instead of drifting. The stage
//! equations are solved by fixed-point iteration until the increments reach
//! round-off, and the solution is accumulated with compensated summation so
//! that round-off does not drift over 10⁶ steps either.

use super::{check_finite, fixed_steps, Flow, Observer, OdeError, Stats, Step, System};

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

/// Solves the stage equations of one step of size h from (t, y) by fixed-point
/// iteration to round-off; `f` holds the starting guess and receives the stage
/// derivatives.
#[allow(clippy::too_many_arguments)]
fn solve_stages<S: System<N>, const N: usize>(
    system: &S,
    tab: &Tableau,
    stages: usize,
    t: f64,
    y: &[f64; N],
    h: f64,
    f: &mut [[f64; N]; 3],
    stats: &mut Stats,
) -> Result<(), OdeError> {
    let scale = 1.0 + y.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let mut previous = f64::INFINITY;
    for _ in 0..MAX_ITERATIONS {
        stats.iterations += 1;
        let mut change = 0.0f64;
        let mut next = *f;
        for i in 0..stages {
            let mut z = *y;
            for k in 0..N {
                let acc: f64 = tab.a[i][..stages]
                    .iter()
                    .zip(f.iter())
                    .map(|(a, fj)| a * fj[k])
                    .sum();
                z[k] += h * acc;
            }
            next[i] = system.rhs(t + tab.c[i] * h, &z);
            for k in 0..N {
                change = change.max((h * (next[i][k] - f[i][k])).abs());
            }
        }
        stats.f_evals += stages as u64;
        *f = next;
        let relative = change / scale;
        if !relative.is_finite() {
            return Err(OdeError::NonFinite { t, y: y.to_vec() });
        }
        // Converged to round-off: no change, or changes stopped shrinking at the round-off level.
        if relative == 0.0 || (relative < 1e-13 && relative >= previous) || relative < 1e-16 {
            return Ok(());
        }
        previous = relative;
    }
    if previous > 1e-10 {
        return Err(OdeError::NoConvergence {
            t,
            h,
            y: y.to_vec(),
        });
    }
    Ok(())
}

/// h Σ b_j f_j, the increment of one step.
fn increment<const N: usize>(
    tab: &Tableau,
    stages: usize,
    h: f64,
    f: &[[f64; N]; 3],
    k: usize,
) -> f64 {
    let acc: f64 = tab.b[..stages].iter().zip(f).map(|(b, fj)| b * fj[k]).sum();
    h * acc
}

/// An accepted Gauss–Legendre step; inside it, states come from a fresh
/// Gauss step of the partial length (the method's own order).
struct GaussStep<'a, S, const N: usize> {
    system: &'a S,
    tab: &'a Tableau,
    stages: usize,
    t0: f64,
    y0: [f64; N],
    t1: f64,
    y1: [f64; N],
    f: [[f64; N]; 3],
    stats: &'a mut Stats,
}

impl<S: System<N>, const N: usize> Step<N> for GaussStep<'_, S, N> {
    fn start(&self) -> (f64, &[f64; N]) {
        (self.t0, &self.y0)
    }
    fn end(&self) -> (f64, &[f64; N]) {
        (self.t1, &self.y1)
    }
    fn state_at(&mut self, t: f64) -> Result<[f64; N], OdeError> {
        let h = t - self.t0;
        let mut f = self.f;
        solve_stages(
            self.system,
            self.tab,
            self.stages,
            self.t0,
            &self.y0,
            h,
            &mut f,
            self.stats,
        )?;
        Ok(std::array::from_fn(|k| {
            self.y0[k] + increment(self.tab, self.stages, h, &f, k)
        }))
    }
}

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
    observe: Observer<'_, N>,
) -> Result<(f64, [f64; N]), OdeError> {
    let tab = tableau(stages);
    let (n, h) = fixed_steps(t0, t1, max_step, max_steps)?;
    let mut y = *y0;
    let mut compensation = [0.0; N];
    // Stage derivatives; the previous step's values start the iteration.
    let f0 = system.rhs(t0, &y);
    stats.f_evals += 1;
    let mut f = [f0; 3];
    for step in 0..n {
        let t = t0 + step as f64 * h;
        solve_stages(system, &tab, stages, t, &y, h, &mut f, stats)?;
        let mut y_new = y;
        for k in 0..N {
            let delta = increment(&tab, stages, h, &f, k) + compensation[k];
            y_new[k] = y[k] + delta;
            compensation[k] = delta - (y_new[k] - y[k]);
        }
        let t_next = if step + 1 == n {
            t1
        } else {
            t0 + (step + 1) as f64 * h
        };
        check_finite(t_next, &y_new)?;
        stats.steps += 1;
        let mut view = GaussStep {
            system,
            tab: &tab,
            stages,
            t0: t,
            y0: y,
            t1: t_next,
            y1: y_new,
            f,
            stats,
        };
        if let Flow::Stop { t, y } = observe(&mut view)? {
            return Ok((t, y));
        }
        y = y_new;
    }
    Ok((t1, y))
}
