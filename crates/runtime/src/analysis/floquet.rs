//! Monodromy matrices and Floquet multipliers of periodic motions.

pub use crate::tangent::monodromy::{monodromies, monodromy};
use nalgebra::DMatrix;

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

/// |det M − 1| up to which a monodromy matrix is taken as a conservative
/// flow's (det M = 1 exactly; damping makes it e^(−∫ friction)).
const CONSERVATIVE_DETERMINANT: f64 = 1e-6;

/// |Im ν| past which multipliers that met off the real axis (a Krein
/// collision) count as having left the unit circle.
const KREIN_SLACK: f64 = 1e-6;

/// A damped flow's largest multiplier ρ counts as stable while its growth
/// per unit time, ln ρ / T, is at most this.
const RATE_SLACK: f64 = 1e-9;

/// A periodic motion's stability from its monodromy matrix `m` over one
/// `period` T, as one number whose sign decides it (≤ 0: stable), with its
/// zero at the stability edge itself however short the period.
///
/// A conservative flow's multipliers come in pairs λ, 1/λ; each pair is one
/// ν = 2 − λ − 1/λ, an eigenvalue (twice) of P = (M − I)(M⁻¹ − I), and the
/// motion is stable where every ν is real in [0, 4]. Where two multipliers
/// meet at 1 (the edge that vibration moves), ν ≈ (ωT)² on the stable side
/// and −(σT)² on the other: its sign changes at the edge, and M's error ε
/// moves the edge by about ε/T in ω². A fixed distance δ from the unit
/// circle moved it by δ²/T², without bound as T → 0. Multipliers that meet
/// off the real axis (a Krein collision) leave it with ν complex.
///
/// A damped flow (det M < 1) is judged by the growth of its largest
/// multiplier per unit time, ln ρ / T.
pub fn stability_margin(m: &DMatrix<f64>, period: f64) -> f64 {
    let n = m.nrows();
    let conservative = (m.determinant() - 1.0).abs() <= CONSERVATIVE_DETERMINANT;
    let inverse = m.clone().try_inverse();
    let (true, Some(inverse)) = (conservative, inverse) else {
        return spectral_radius(&multipliers_of(m)).ln() / period - RATE_SLACK;
    };
    let identity = DMatrix::<f64>::identity(n, n);
    let p = (m - &identity) * (inverse - &identity);
    p.complex_eigenvalues()
        .iter()
        .map(|nu| (-nu.re).max(nu.re - 4.0).max(nu.im.abs() - KREIN_SLACK))
        .fold(f64::NEG_INFINITY, f64::max)
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
    /// [`Verdict::of_monodromy`] of a monodromy matrix as rows.
    pub fn of_rows<const N: usize>(m: &[[f64; N]; N], period: f64) -> Verdict {
        Verdict::of_monodromy(&DMatrix::from_fn(N, N, |i, j| m[i][j]), period)
    }

    /// The verdict of a monodromy matrix `m` over one `period`, on
    /// [`stability_margin`]'s criterion (which holds however short the
    /// period): unstable where the margin is positive; a damped flow's
    /// (det M < 1) stable motion is asymptotically stable.
    pub fn of_monodromy(m: &DMatrix<f64>, period: f64) -> Verdict {
        if !(stability_margin(m, period) <= 0.0) {
            Verdict::Unstable
        } else if m.determinant() < 1.0 - CONSERVATIVE_DETERMINANT {
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
