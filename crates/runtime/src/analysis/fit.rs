//! Least-squares lines, for convergence orders and scaling laws.

/// A fitted line y = slope·x + intercept and how well the points lie on it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LineFit {
    pub slope: f64,
    pub intercept: f64,
    /// Coefficient of determination (1: on a line).
    pub r_squared: f64,
}

/// Least-squares line through (x, y); NaN slope for fewer than two distinct x.
pub fn least_squares(points: &[(f64, f64)]) -> LineFit {
    let n = points.len() as f64;
    let mx = points.iter().map(|p| p.0).sum::<f64>() / n;
    let my = points.iter().map(|p| p.1).sum::<f64>() / n;
    let sxy: f64 = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = points.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let syy: f64 = points.iter().map(|p| (p.1 - my).powi(2)).sum();
    let slope = sxy / sxx;
    LineFit {
        slope,
        intercept: my - slope * mx,
        r_squared: if syy > 0.0 {
            sxy * sxy / (sxx * syy)
        } else {
            1.0
        },
    }
}

/// The least-squares line through (ln x, ln y): the exponent of a power law.
pub fn log_log(points: &[(f64, f64)]) -> LineFit {
    let logs: Vec<(f64, f64)> = points.iter().map(|(x, y)| (x.ln(), y.ln())).collect();
    least_squares(&logs)
}
