//! Monodromy matrices and Floquet multipliers of periodic motions.

use super::variational::Variational;
use crate::ode::{Integrator, OdeError, System};
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
    let identity: Vec<[f64; N]> = (0..N)
        .map(|k| std::array::from_fn(|i| f64::from(u8::from(i == k))))
        .collect();
    let variational = Variational::<S, N, M>::new(system);
    let z0 = Variational::<S, N, M>::pack(y0, &identity);
    let z = integrator.advance(&variational, 0.0, &z0, period)?;
    let mut m = [[0.0; N]; N];
    for (k, column) in (0..N)
        .map(|k| Variational::<S, N, M>::tangent(&z, k))
        .enumerate()
    {
        for i in 0..N {
            m[i][k] = column[i];
        }
    }
    Ok((Variational::<S, N, M>::state(&z), m))
}

/// Eigenvalues of a monodromy matrix, as (re, im), sorted by decreasing modulus.
pub fn floquet_multipliers<const N: usize>(monodromy: &[[f64; N]; N]) -> Vec<(f64, f64)> {
    let m = DMatrix::from_fn(N, N, |i, k| monodromy[i][k]);
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
    let mut previous = (lo, margin(lo)?);
    for i in 1..=samples {
        let a = lo + (hi - lo) * i as f64 / samples as f64;
        let g = margin(a)?;
        if previous.1 > 0.0 && g <= 0.0 {
            let (mut left, mut right) = (previous.0, a);
            while right - left > tolerance {
                let mid = 0.5 * (left + right);
                if margin(mid)? > 0.0 {
                    left = mid;
                } else {
                    right = mid;
                }
            }
            return Ok(Some(0.5 * (left + right)));
        }
        previous = (a, g);
    }
    Ok(None)
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
    let Some(low) = first_stability_onset(margin, lo, hi, samples, tolerance)? else {
        return Ok(None);
    };
    let rest = ((hi - low) / (hi - lo) * samples as f64).ceil().max(1.0) as usize;
    let flipped = |a: f64| margin(a).map(|m| -m);
    let high = first_stability_onset(&flipped, low + tolerance, hi, rest, tolerance)?;
    Ok(Some((low, high)))
}
