//! Implicit Gauss–Legendre Runge–Kutta methods (2 stages: order 4, 3 stages:
//! order 6), with a fixed step. They are symplectic: on a Hamiltonian period
//! map the energy error stays bounded instead of drifting. The stage
//! equations are solved by fixed-point iteration until the increments reach
//! round-off, and the solution is accumulated with compensated summation so
//! that round-off does not drift over 10⁶ steps either.

use super::driver::{Attempt, Schedule, Stepper};
use super::{OdeError, Stats, Step, System};

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
pub(super) struct GaussStep<'a, S, const N: usize> {
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

/// The method's state: its tableau, the stage derivatives of the last step
/// (which start the next step's iteration) and the compensation of the
/// summed increments.
pub(super) struct Gauss<const N: usize> {
    tab: Tableau,
    stages: usize,
    max_step: f64,
    f: [[f64; N]; 3],
    compensation: [f64; N],
}

impl<const N: usize> Gauss<N> {
    pub fn new(stages: usize, max_step: f64) -> Gauss<N> {
        Gauss {
            tab: tableau(stages),
            stages,
            max_step,
            f: [[0.0; N]; 3],
            compensation: [0.0; N],
        }
    }
}

impl<S: System<N>, const N: usize> Stepper<S, N> for Gauss<N> {
    type Accepted<'a>
        = GaussStep<'a, S, N>
    where
        S: 'a;

    fn schedule(&self) -> Schedule {
        Schedule::Fixed {
            max_step: self.max_step,
        }
    }

    fn begin(
        &mut self,
        system: &S,
        t0: f64,
        y0: &[f64; N],
        _t1: f64,
        _carried: Option<f64>,
        stats: &mut Stats,
    ) -> Result<f64, OdeError> {
        self.f = [system.rhs(t0, y0); 3];
        stats.f_evals += 1;
        self.compensation = [0.0; N];
        Ok(self.max_step)
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
        solve_stages(system, &self.tab, self.stages, t, y, h, &mut self.f, stats)?;
        let mut y_new = *y;
        for k in 0..N {
            let delta = increment(&self.tab, self.stages, h, &self.f, k) + self.compensation[k];
            y_new[k] = y[k] + delta;
            self.compensation[k] = delta - (y_new[k] - y[k]);
        }
        Ok(Attempt::Accepted {
            y: y_new,
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
    ) -> GaussStep<'a, S, N> {
        GaussStep {
            system,
            tab: &self.tab,
            stages: self.stages,
            t0,
            y0,
            t1,
            y1,
            f: self.f,
            stats,
        }
    }
}
