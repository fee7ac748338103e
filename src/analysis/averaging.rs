//! Exact against averaged systems (the averaging theorems).
//!
//! Theorem 2 of the averaging method: started from the same state, the exact
//! solution of a system with a fast phase of frequency ν and the solution of
//! its averaged system stay within c/ν of each other on times of order one.
//! These functions run both systems from one state on one time grid and
//! measure the deviation.

use super::fit::{log_log, LineFit};
use crate::ode::{Integrator, Method, OdeError, System};
use rayon::prelude::*;

/// Both systems on one time grid, from the same initial state.
#[derive(Clone, Debug)]
pub struct Comparison<const N: usize> {
    pub times: Vec<f64>,
    pub exact: Vec<[f64; N]>,
    pub averaged: Vec<[f64; N]>,
}

impl<const N: usize> Comparison<N> {
    /// max over the grid of |exact − averaged| for each of the components `components`.
    pub fn max_deviation(&self, components: std::ops::Range<usize>) -> Vec<f64> {
        components
            .map(|i| {
                self.exact
                    .iter()
                    .zip(&self.averaged)
                    .map(|(e, a)| (e[i] - a[i]).abs())
                    .fold(0.0, f64::max)
            })
            .collect()
    }
}

/// A grid on [0, t_end] fine enough to resolve the fast oscillation of
/// period `fast_period` (`per_period` samples each), and at least `minimum`.
pub fn time_grid(t_end: f64, fast_period: f64, per_period: usize, minimum: usize) -> Vec<f64> {
    let n = ((t_end / fast_period) * per_period as f64).ceil() as usize;
    let n = n.max(minimum).max(1);
    (0..=n).map(|k| t_end * k as f64 / n as f64).collect()
}

/// Runs the exact and the averaged system from `y0` and samples both on
/// `times` (dense output, so the steps stay those the accuracy needs).
pub fn compare<E: System<N>, A: System<N>, const N: usize>(
    method: Method,
    exact: &E,
    averaged: &A,
    y0: &[f64; N],
    times: &[f64],
) -> Result<Comparison<N>, OdeError> {
    let exact_states = Integrator::new(method)?.advance_sampled(exact, 0.0, y0, times)?;
    let averaged_states = Integrator::new(method)?.advance_sampled(averaged, 0.0, y0, times)?;
    Ok(Comparison {
        times: times.to_vec(),
        exact: exact_states,
        averaged: averaged_states,
    })
}

/// The maximal deviation of each coordinate over [0, t_obs] for each
/// frequency, and the fitted exponent of each coordinate's deviation against
/// the frequency (−1 where Theorem 2 holds). `systems(ν)` builds both systems.
pub struct Convergence {
    pub frequencies: Vec<f64>,
    /// [coordinate][frequency]
    pub max_deviation: Vec<Vec<f64>>,
    pub fits: Vec<LineFit>,
}

pub fn deviation_against_frequency<E, A, const N: usize>(
    method: Method,
    systems: &(dyn Fn(f64) -> (E, A) + Sync),
    y0: &[f64; N],
    t_obs: f64,
    frequencies: &[f64],
    coordinates: usize,
) -> Result<Convergence, OdeError>
where
    E: System<N>,
    A: System<N>,
{
    let per_frequency: Vec<Vec<f64>> = frequencies
        .par_iter()
        .map(|&nu| {
            let (exact, averaged) = systems(nu);
            let grid = time_grid(t_obs, 2.0 * std::f64::consts::PI / nu, 32, 2000);
            compare(method, &exact, &averaged, y0, &grid).map(|c| c.max_deviation(0..coordinates))
        })
        .collect::<Result<_, _>>()?;
    let max_deviation: Vec<Vec<f64>> = (0..coordinates)
        .map(|i| per_frequency.iter().map(|d| d[i]).collect())
        .collect();
    let fits = max_deviation
        .iter()
        .map(|devs| {
            let points: Vec<(f64, f64)> = frequencies
                .iter()
                .copied()
                .zip(devs.iter().copied())
                .collect();
            log_log(&points)
        })
        .collect();
    Ok(Convergence {
        frequencies: frequencies.to_vec(),
        max_deviation,
        fits,
    })
}
