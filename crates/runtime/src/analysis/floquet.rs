//! Monodromy matrices and Floquet multipliers of periodic motions.

use super::variational::Variational;
use crate::ode::{Integrator, LaneIntegrator, Method, OdeError, Orbit, Stats, System};
use nalgebra::DMatrix;

/// The state after one period and the monodromy matrix ∂y(T)/∂y(0)
/// (row i, column k), from the variational equations. M = N + N².
pub fn monodromy<S: System<N>, const N: usize, const M: usize>(
    integrator: &mut Integrator,
    system: &S,
    period: f64,
    y0: &[f64; N],
) -> Result<([f64; N], [[f64; N]; N]), OdeError> {
    assert_eq!(M, N + N * N, "monodromy needs M = N + N²");
    let variational = Variational::<S, N, M>::new(system);
    let z0 = Variational::<S, N, M>::pack(y0, &identity::<N>());
    let z = integrator.advance(&variational, 0.0, &z0, period)?;
    Ok(split::<S, N, M>(&z))
}

/// The end state and monodromy matrix of each problem (system, period,
/// start) of a sweep, as [`monodromy`] gives them, and the sweep's
/// statistics: for `taylor` through the lanes of the batch Taylor method,
/// each lane with its own system (its own parameters) and period and equal
/// to its scalar run bit for bit; one at a time for the other methods.
pub fn monodromies<S: System<N>, const N: usize, const M: usize>(
    method: Method,
    problems: &[(S, f64, [f64; N])],
) -> (Vec<Result<([f64; N], [[f64; N]; N]), OdeError>>, Stats) {
    assert_eq!(M, N + N * N, "monodromy needs M = N + N²");
    let mut stats = Stats::default();
    let Method::Taylor { .. } = method else {
        // A fresh integrator each: DOP853 would start from the last step size.
        let results = problems
            .iter()
            .map(|(system, period, y0)| {
                let mut integrator = Integrator::new(method)?;
                let result = monodromy::<S, N, M>(&mut integrator, system, *period, y0);
                stats += integrator.stats;
                result
            })
            .collect();
        return (results, stats);
    };
    let mut lanes = match LaneIntegrator::new(method) {
        Ok(lanes) => lanes,
        Err(e) => return (vec![Err(e); problems.len()], stats),
    };
    let variational: Vec<Variational<S, N, M>> = problems
        .iter()
        .map(|(system, _, _)| Variational::new(system))
        .collect();
    let orbits: Vec<Orbit<_, M>> = problems
        .iter()
        .zip(&variational)
        .map(|((_, period, y0), system)| Orbit {
            system,
            start: Variational::<S, N, M>::pack(y0, &identity::<N>()),
            end: *period,
        })
        .collect();
    let mut ends: Vec<[f64; M]> = orbits.iter().map(|o| o.start).collect();
    let errors = lanes.stream(&orbits, |k, z| {
        ends[k] = *z;
        false
    });
    let results = errors
        .into_iter()
        .zip(ends)
        .map(|(error, z)| match error {
            Some(e) => Err(e),
            None => Ok(split::<S, N, M>(&z)),
        })
        .collect();
    (results, lanes.stats)
}

/// The columns of the N×N identity matrix.
fn identity<const N: usize>() -> Vec<[f64; N]> {
    (0..N)
        .map(|k| std::array::from_fn(|i| f64::from(u8::from(i == k))))
        .collect()
}

/// The state and the matrix of tangent vectors (as columns) of a
/// variational state [y; Φ].
fn split<S: System<N>, const N: usize, const M: usize>(z: &[f64; M]) -> ([f64; N], [[f64; N]; N]) {
    let mut m = [[0.0; N]; N];
    for k in 0..N {
        let column = Variational::<S, N, M>::tangent(z, k);
        for i in 0..N {
            m[i][k] = column[i];
        }
    }
    (Variational::<S, N, M>::state(z), m)
}

/// Eigenvalues of a monodromy matrix, as (re, im), sorted by decreasing modulus.
pub fn floquet_multipliers<const N: usize>(monodromy: &[[f64; N]; N]) -> Vec<(f64, f64)> {
    multipliers_of(&DMatrix::from_fn(N, N, |i, k| monodromy[i][k]))
}

/// [`floquet_multipliers`] of a matrix of any size.
pub fn multipliers_of(m: &DMatrix<f64>) -> Vec<(f64, f64)> {
    let mut values: Vec<(f64, f64)> = m
        .complex_eigenvalues()
        .iter()
        .map(|z| (z.re, z.im))
        .collect();
    values.sort_by(|a, b| b.0.hypot(b.1).total_cmp(&a.0.hypot(a.1)));
    values
}

/// Spectral radius: the largest modulus of the multipliers.
pub fn spectral_radius(multipliers: &[(f64, f64)]) -> f64 {
    multipliers
        .iter()
        .map(|(re, im)| re.hypot(*im))
        .fold(0.0, f64::max)
}

/// Stability of a periodic motion from its multipliers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// Some multiplier outside the unit circle.
    Unstable,
    /// All on the unit circle (linearly stable; conservative case).
    Stable,
    /// All strictly inside: asymptotically stable.
    AsymptoticallyStable,
}

impl Verdict {
    /// `tolerance` absorbs the integration error on |λ| = 1.
    pub fn from_multipliers(multipliers: &[(f64, f64)], tolerance: f64) -> Verdict {
        let radius = spectral_radius(multipliers);
        if radius > 1.0 + tolerance {
            Verdict::Unstable
        } else if radius < 1.0 - tolerance {
            Verdict::AsymptoticallyStable
        } else {
            Verdict::Stable
        }
    }

    pub fn name(&self) -> &'static str {
        match self {
            Verdict::Unstable => "unstable",
            Verdict::Stable => "stable",
            Verdict::AsymptoticallyStable => "asymptotically stable",
        }
    }
}

/// For a 2×2 monodromy matrix: |tr M| − 1 − det M. Both multipliers lie in the
/// closed unit disc iff this is ≤ 0 (and det M ≤ 1), the Jury criterion.
pub fn jury_margin(m: &[[f64; 2]; 2]) -> f64 {
    let trace = m[0][0] + m[1][1];
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    trace.abs() - 1.0 - det
}

/// The first parameter value in (lo, hi] where `margin` changes from positive
/// to ≤ 0: bracketed on `samples` equal steps, then bisected to `tolerance`.
pub fn first_stability_onset<E>(
    margin: &dyn Fn(f64) -> Result<f64, E>,
    lo: f64,
    hi: f64,
    samples: usize,
    tolerance: f64,
) -> Result<Option<f64>, E> {
    let margins = |values: &[f64]| values.iter().map(|&a| margin(a)).collect();
    first_onset_in_batches(&margins, 1, lo, hi, samples, tolerance)
}

/// [`first_stability_onset`] with `margins` evaluating up to `width`
/// values at once (the lanes of the batch Taylor method,
/// [`Method::batch_width`]): the samples are taken `width` at a time, and
/// each narrowing step cuts the bracket into width + 1 parts. Width 1 is
/// the bisection, step for step.
pub fn first_onset_in_batches<E>(
    margins: &dyn Fn(&[f64]) -> Result<Vec<f64>, E>,
    width: usize,
    lo: f64,
    hi: f64,
    samples: usize,
    tolerance: f64,
) -> Result<Option<f64>, E> {
    let width = width.max(1);
    let mut previous = (lo, margins(&[lo])?[0]);
    for first in (1..=samples).step_by(width) {
        let values: Vec<f64> = (first..=(first + width - 1).min(samples))
            .map(|i| lo + (hi - lo) * i as f64 / samples as f64)
            .collect();
        for (a, g) in values.iter().copied().zip(margins(&values)?) {
            if previous.1 > 0.0 && g <= 0.0 {
                return narrow(margins, width, previous.0, a, tolerance).map(Some);
            }
            previous = (a, g);
        }
    }
    Ok(None)
}

/// The middle of a bracket [left, right] (margin > 0 at left, ≤ 0 at right)
/// narrowed to `tolerance` by `width` points per step: the first of them
/// with margin ≤ 0 and the one before it bound the next bracket.
fn narrow<E>(
    margins: &dyn Fn(&[f64]) -> Result<Vec<f64>, E>,
    width: usize,
    mut left: f64,
    mut right: f64,
    tolerance: f64,
) -> Result<f64, E> {
    while right - left > tolerance {
        let points: Vec<f64> = if width == 1 {
            vec![0.5 * (left + right)]
        } else {
            (1..=width)
                .map(|j| left + (right - left) * j as f64 / (width + 1) as f64)
                .collect()
        };
        let values = margins(&points)?;
        match values.iter().position(|&g| g <= 0.0) {
            Some(0) => right = points[0],
            Some(j) => (left, right) = (points[j - 1], points[j]),
            None => left = points[width - 1],
        }
    }
    Ok(0.5 * (left + right))
}

/// The first interval of a parameter in (lo, hi] on which `margin` ≤ 0
/// (e.g. spectral radius − 1 − tolerance: stable), as (lower edge, upper
/// edge); the upper edge is None if the interval reaches `hi`. Edges are
/// bracketed on `samples` equal steps over (lo, hi] and bisected to `tolerance`.
pub fn stability_window<E>(
    margin: &dyn Fn(f64) -> Result<f64, E>,
    lo: f64,
    hi: f64,
    samples: usize,
    tolerance: f64,
) -> Result<Option<(f64, Option<f64>)>, E> {
    let margins = |values: &[f64]| values.iter().map(|&a| margin(a)).collect();
    window_in_batches(&margins, 1, lo, hi, samples, tolerance)
}

/// [`stability_window`] with `margins` evaluating up to `width` values at
/// once, as [`first_onset_in_batches`].
pub fn window_in_batches<E>(
    margins: &dyn Fn(&[f64]) -> Result<Vec<f64>, E>,
    width: usize,
    lo: f64,
    hi: f64,
    samples: usize,
    tolerance: f64,
) -> Result<Option<(f64, Option<f64>)>, E> {
    let Some(low) = first_onset_in_batches(margins, width, lo, hi, samples, tolerance)? else {
        return Ok(None);
    };
    let rest = ((hi - low) / (hi - lo) * samples as f64).ceil().max(1.0) as usize;
    let flipped = |values: &[f64]| -> Result<Vec<f64>, E> {
        Ok(margins(values)?.into_iter().map(|m| -m).collect())
    };
    let high = first_onset_in_batches(&flipped, width, low + tolerance, hi, rest, tolerance)?;
    Ok(Some((low, high)))
}
