//! Fractal dimensions of attractors of planar maps: box counting on a point
//! set, and the Kaplan–Yorke (Lyapunov) dimension from the exponents.

use std::collections::HashSet;

/// The result of a box count: occupied boxes for each box side (in units of
/// the set's extent) and the slope of ln N against ln(1/side).
#[derive(Clone, Debug, PartialEq)]
pub struct BoxCounting {
    pub sides: Vec<f64>,
    pub boxes: Vec<usize>,
    pub dimension: f64,
    /// Intercept of the fitted line, for drawing it.
    pub intercept: f64,
}

/// Counts occupied boxes of the given sides (fractions of the bounding box)
/// and fits the dimension over `fit` (a range of indices into `sides`): the
/// coarsest boxes see the set's outline, the finest are not filled by a
/// finite sample.
pub fn box_counting(
    points: &[[f64; 2]],
    sides: &[f64],
    fit: std::ops::Range<usize>,
) -> BoxCounting {
    let (lo, hi) = bounds(points);
    let span = [
        (hi[0] - lo[0]).max(f64::MIN_POSITIVE),
        (hi[1] - lo[1]).max(f64::MIN_POSITIVE),
    ];
    let boxes: Vec<usize> = sides
        .iter()
        .map(|&side| {
            // The upper edge belongs to the last box, not to a new one.
            let last = (1.0 / side).ceil() as i64 - 1;
            let index =
                |x: f64, lo: f64, span: f64| (((x - lo) / (span * side)).floor() as i64).min(last);
            points
                .iter()
                .map(|p| (index(p[0], lo[0], span[0]), index(p[1], lo[1], span[1])))
                .collect::<HashSet<_>>()
                .len()
        })
        .collect();
    let line: Vec<(f64, f64)> = fit
        .map(|k| ((1.0 / sides[k]).ln(), (boxes[k] as f64).ln()))
        .collect();
    let fit = super::fit::least_squares(&line);
    let (dimension, intercept) = (fit.slope, fit.intercept);
    BoxCounting {
        sides: sides.to_vec(),
        boxes,
        dimension,
        intercept,
    }
}

/// The Kaplan–Yorke dimension j + (λ₁ + … + λⱼ)/|λⱼ₊₁|, j the largest index
/// with a non-negative partial sum (exponents in decreasing order).
pub fn kaplan_yorke_dimension(exponents: &[f64]) -> f64 {
    let mut sum = 0.0;
    for (j, &l) in exponents.iter().enumerate() {
        if sum + l < 0.0 {
            return j as f64 + sum / l.abs();
        }
        sum += l;
    }
    exponents.len() as f64
}

/// Lower-left and upper-right corners of the points.
pub fn bounds(points: &[[f64; 2]]) -> ([f64; 2], [f64; 2]) {
    points.iter().fold(
        ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]),
        |(lo, hi), p| {
            (
                [lo[0].min(p[0]), lo[1].min(p[1])],
                [hi[0].max(p[0]), hi[1].max(p[1])],
            )
        },
    )
}
