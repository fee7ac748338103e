//! A linearisation's eigenvalues with their numerical errors, and the
//! verdict they allow.
//!
//! A is exact to rounding (the field's Jacobian by dual numbers, the
//! constraints solved by an SVD), so its error is taken as
//! δ = 64 ε max(‖A‖_F, s), s the size of the entries A was made from (the
//! field's Jacobian: A may be small or zero by cancellation). A simple eigenvalue then moves by at most about
//! κ δ, with κ = ‖x‖ ‖y‖ / |yᴴx| its condition number (x, y its right and
//! left eigenvectors, found by inverse iteration). A defective pair (a
//! Jordan block of two, such as the zero of a neighbouring steady motion)
//! splits by about √(δ ‖A‖) instead, which caps the stated error where κ
//! is unbounded.

use nalgebra::{Complex, DMatrix, DVector};
use serde::Serialize;

/// The eigenvalues (re, im) of `a` by decreasing real part, and each one's
/// error bound; `made_from`: the size of the entries `a` was computed from.
pub fn eigenvalues_with_errors(a: &DMatrix<f64>, made_from: f64) -> (Vec<(f64, f64)>, Vec<f64>) {
    let mut values: Vec<(f64, f64)> = a
        .complex_eigenvalues()
        .iter()
        .map(|z| (z.re, z.im))
        .collect();
    values.sort_by(|p, q| q.0.total_cmp(&p.0).then(p.1.total_cmp(&q.1)));
    let norm = a.norm().max(made_from);
    let delta = 64.0 * f64::EPSILON * norm.max(f64::MIN_POSITIVE);
    let cap = 2.0 * (delta * norm.max(f64::MIN_POSITIVE)).sqrt();
    let errors = values
        .iter()
        .map(|&(re, im)| {
            let kappa = condition(a, Complex::new(re, im), delta);
            (kappa * delta).min(cap).max(delta)
        })
        .collect();
    (values, errors)
}

/// The condition number of the eigenvalue `lambda` of `a` (infinite when
/// inverse iteration finds no eigenvector pair: a defective eigenvalue).
fn condition(a: &DMatrix<f64>, lambda: Complex<f64>, delta: f64) -> f64 {
    let n = a.nrows();
    // The shift is moved off the eigenvalue by a little more than its
    // error, so that the shifted matrix factorises.
    let shift = lambda + Complex::new(delta, 0.7 * delta);
    let shifted = DMatrix::from_fn(n, n, |i, j| {
        Complex::new(a[(i, j)], 0.0)
            - if i == j {
                shift
            } else {
                Complex::new(0.0, 0.0)
            }
    });
    let iterate = |m: DMatrix<Complex<f64>>| -> Option<DVector<Complex<f64>>> {
        let lu = m.lu();
        // A start with every component, not orthogonal to any eigenvector
        // in practice.
        let mut v = DVector::from_fn(n, |i, _| Complex::new(1.0 + 0.31 * i as f64, 0.17));
        for _ in 0..3 {
            v = lu.solve(&v)?;
            let size = v.norm();
            if !(size.is_finite() && size > 0.0) {
                return None;
            }
            v /= Complex::new(size, 0.0);
        }
        Some(v)
    };
    let (Some(x), Some(y)) = (iterate(shifted.clone()), iterate(shifted.adjoint())) else {
        return f64::INFINITY;
    };
    let overlap = y.dotc(&x).norm();
    if overlap > 0.0 {
        1.0 / overlap
    } else {
        f64::INFINITY
    }
}

/// What the linearisation says of the steady motion's stability.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// Every eigenvalue's real part is negative by more than its error.
    AsymptoticallyStable,
    /// This eigenvalue's real part is positive by more than its error.
    Unstable { eigenvalue: (f64, f64) },
    /// No eigenvalue is surely to the right, but some lie on the
    /// imaginary axis within their errors (a conservative motion, a
    /// neighbouring steady motion): the first order cannot decide.
    InconclusiveAtFirstOrder { on_axis: usize },
}

impl Verdict {
    /// The verdict of eigenvalues with these errors.
    pub fn of(values: &[(f64, f64)], errors: &[f64]) -> Verdict {
        if let Some((&value, _)) = values
            .iter()
            .zip(errors)
            .filter(|(v, e)| v.0 > **e)
            .max_by(|a, b| a.0 .0.total_cmp(&b.0 .0))
        {
            return Verdict::Unstable { eigenvalue: value };
        }
        match values
            .iter()
            .zip(errors)
            .filter(|(v, e)| v.0 >= -**e)
            .count()
        {
            0 => Verdict::AsymptoticallyStable,
            on_axis => Verdict::InconclusiveAtFirstOrder { on_axis },
        }
    }

    pub fn is_unstable(&self) -> bool {
        matches!(self, Verdict::Unstable { .. })
    }
}

impl std::fmt::Display for Verdict {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Verdict::AsymptoticallyStable => f.write_str("asymptotically stable"),
            Verdict::Unstable { eigenvalue: (re, im) } => {
                write!(f, "unstable (eigenvalue {re:.6} {im:+.6}i)")
            }
            Verdict::InconclusiveAtFirstOrder { on_axis } => write!(
                f,
                "inconclusive at first order ({on_axis} eigenvalue(s) on the imaginary axis within their errors)"
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The errors bound the true error of a known spectrum after a
    /// similarity that makes it non-normal, and a Jordan block's split.
    #[test]
    fn errors_bound_a_known_spectrum() {
        let d = DMatrix::from_diagonal(&DVector::from_vec(vec![-3.0, -1.0, 0.5, 2.0]));
        let t = DMatrix::from_fn(4, 4, |i, j| {
            1.0 / (1.0 + i as f64 + 2.0 * j as f64) + if i == j { 1.0 } else { 0.0 }
        });
        let a = &t * d * t.clone().try_inverse().unwrap();
        let (values, errors) = eigenvalues_with_errors(&a, 0.0);
        for ((value, error), exact) in values.iter().zip(&errors).zip([2.0, 0.5, -1.0, -3.0]) {
            let missed = (value.0 - exact).hypot(value.1);
            assert!(
                missed <= *error && *error < 1e-11,
                "{value:?} vs {exact}: {missed:e} > {error:e}"
            );
        }
        // A Jordan block of two at 0, rounded: the split is within the cap.
        let jordan = DMatrix::from_row_slice(2, 2, &[1e-17, 1.0, 1e-16, 0.0]);
        let (values, errors) = eigenvalues_with_errors(&jordan, 0.0);
        for (value, error) in values.iter().zip(&errors) {
            assert!(value.0.hypot(value.1) <= *error, "{value:?}: {error:e}");
        }
        assert_eq!(
            Verdict::of(&values, &errors),
            Verdict::InconclusiveAtFirstOrder { on_axis: 2 }
        );
    }
}
