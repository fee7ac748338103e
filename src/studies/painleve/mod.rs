//! Study 3: the Painlevé–Klein example, closed forms of the rod geometry and
//! of the rigid-rod equation X* = Φ(R) (docs/studies.md).
//!
//! Coordinates: x1, x2 along the guides (point 1 on the guide at distance d);
//! δ = √((x1 − x2)² + d²) − l, δ' = (x1' − x2')(x1 − x2)/(l + δ),
//! cos φ = (x1 − x2)/(l + δ), sin φ = d/(l + δ), R = k ε⁻² δ + ν ε⁻¹ δ'.

pub mod deformation;
pub mod graphs;
pub mod impact;
pub mod stiff_limit;

use super::StudyError;
use crate::models::painleve_klein::Params;

/// δ, δ', R, cos φ, sin φ at the state [x1, x2, v1, v2].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rod {
    pub delta: f64,
    pub delta_rate: f64,
    pub reaction: f64,
    pub cos_phi: f64,
    pub sin_phi: f64,
}

pub fn rod(y: &[f64; 4], p: &Params) -> Rod {
    let dx = y[0] - y[1];
    let length = dx.hypot(p.d);
    let delta = length - p.l;
    let delta_rate = (y[2] - y[3]) * dx / length;
    Rod {
        delta,
        delta_rate,
        reaction: p.k / (p.eps * p.eps) * delta + p.nu / p.eps * delta_rate,
        cos_phi: dx / length,
        sin_phi: p.d / length,
    }
}

/// The worked example's initial state for x2(0): x1 = 0, x1' = x2' = 10.
pub fn worked_example_start(x2: f64) -> [f64; 4] {
    [0.0, x2, 10.0, 10.0]
}

/// The reduced quantities of the rigid rod: X* = (X1 − X2)/cos φ0,
/// μi* = μi tan φ0, Y1* = Y1/sin φ0, Y2* = Y2/sin φ0, φ0 = arcsin(d/l).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Reduced {
    pub x_star: f64,
    pub mu1: f64,
    pub mu2: f64,
    pub y1: f64,
    pub y2: f64,
    pub cos_phi0: f64,
}

impl Reduced {
    /// Reduced quantities for drawing the classes: Y1* = 1, cos φ0 = 0.6,
    /// X* = 0 (the examples and the region plots of `painleve_phi`).
    pub fn sample(mu1: f64, mu2: f64, y2: f64) -> Reduced {
        Reduced {
            x_star: 0.0,
            mu1,
            mu2,
            y1: 1.0,
            y2,
            cos_phi0: 0.6,
        }
    }
}

pub fn reduced(p: &Params) -> Reduced {
    let sin0 = p.d / p.l;
    let cos0 = (1.0 - sin0 * sin0).sqrt();
    let tan0 = sin0 / cos0;
    Reduced {
        x_star: (p.X1 - p.X2) / cos0,
        mu1: p.mu1 * tan0,
        mu2: p.mu2 * tan0,
        y1: p.Y1 / sin0,
        y2: p.Y2 / sin0,
        cos_phi0: cos0,
    }
}

/// Φ(R) = 2R + σ(μ1*|R − Y1*| − μ2*|R + Y2*|).
pub fn phi(r: f64, sigma: f64, q: &Reduced) -> f64 {
    2.0 * r + sigma * (q.mu1 * (r - q.y1).abs() - q.mu2 * (r + q.y2).abs())
}

/// Every root R of X* = Φ(R) for the sign σ: Φ is linear between its kinks
/// Y1* and −Y2*, so each of the (at most three) pieces is solved exactly.
pub fn rigid_rod_roots(sigma: f64, q: &Reduced) -> Vec<f64> {
    let mut kinks = [q.y1, -q.y2];
    kinks.sort_by(f64::total_cmp);
    let bounds = [f64::NEG_INFINITY, kinks[0], kinks[1], f64::INFINITY];
    let mut roots: Vec<f64> = Vec::new();
    for w in bounds.windows(2) {
        let (lo, hi) = (w[0], w[1]);
        // A point inside the piece fixes the signs of R − Y1* and R + Y2*.
        let inside = match (lo.is_finite(), hi.is_finite()) {
            (true, true) => 0.5 * (lo + hi),
            (true, false) => lo + 1.0,
            (false, true) => hi - 1.0,
            (false, false) => 0.0,
        };
        let s1 = (inside - q.y1).signum();
        let s2 = (inside + q.y2).signum();
        // Φ = a R + b on this piece.
        let a = 2.0 + sigma * (q.mu1 * s1 - q.mu2 * s2);
        let b = sigma * (-q.mu1 * s1 * q.y1 - q.mu2 * s2 * q.y2);
        if a == 0.0 {
            continue;
        }
        let r = (q.x_star - b) / a;
        if r >= lo && r <= hi && !roots.iter().any(|x| (x - r).abs() < 1e-12) {
            roots.push(r);
        }
    }
    roots
}

/// Φ'(R) away from the kinks.
pub fn phi_slope(r: f64, sigma: f64, q: &Reduced) -> f64 {
    2.0 + sigma * (q.mu1 * (r - q.y1).signum() - q.mu2 * (r + q.y2).signum())
}

/// The constant acceleration of the rigid rod sliding with σ at the rod
/// force R: x1'' = X1 − R cos φ0 − σ μ1 |Y1 − R sin φ0| (= x2'' at a root).
pub fn rigid_acceleration(r: f64, sigma: f64, p: &Params) -> f64 {
    let sin0 = p.d / p.l;
    let cos0 = (1.0 - sin0 * sin0).sqrt();
    p.X1 - r * cos0 - sigma * p.mu1 * (p.Y1 - r * sin0).abs()
}

/// The slopes of Φ on its three pieces, left to right (the middle piece lies
/// between the kinks Y1* and −Y2*, whichever comes first).
pub fn segment_slopes(sigma: f64, q: &Reduced) -> [f64; 3] {
    let delta = q.mu2 - q.mu1;
    let sum = q.mu1 + q.mu2;
    let order = if q.y1 < -q.y2 { 1.0 } else { -1.0 };
    [
        2.0 + sigma * delta,
        2.0 + sigma * order * sum,
        2.0 - sigma * delta,
    ]
}

/// The qualitative class of the graph of Φ: the signs of its slopes, e.g. "+-+".
pub fn slope_signs(sigma: f64, q: &Reduced) -> String {
    segment_slopes(sigma, q)
        .iter()
        .map(|s| {
            if *s > 0.0 {
                '+'
            } else if *s < 0.0 {
                '-'
            } else {
                '0'
            }
        })
        .collect()
}

/// One qualitatively different graph of Φ: its slope signs, the region of
/// the parameters where it occurs (Δ = μ2* − μ1*, S = μ1* + μ2*, o = +1 if
/// Y1* < −Y2* else −1), and what X* = Φ(R) can have as roots.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct GraphClass {
    pub signs: &'static str,
    pub region: &'static str,
    pub roots: &'static str,
}

/// Every class that occurs (the boundaries, where a slope is zero, are
/// degenerate and left out). Derived from the slopes 2 + σΔ, 2 + σoS, 2 − σΔ:
/// with σo = +1 the middle slope is positive; with σo = −1 it is negative
/// iff S > 2, and |Δ| > 2 forces S > 2.
pub const GRAPH_CLASSES: [GraphClass; 6] = [
    GraphClass {
        signs: "+++",
        region: "|Δ| < 2 and (σo = +1 or S < 2)",
        roots: "exactly one root for every X*",
    },
    GraphClass {
        signs: "-++",
        region: "σo = +1 and σΔ < −2",
        roots: "no root below the minimum of Φ, two above it (Painlevé: non-existence or non-uniqueness)",
    },
    GraphClass {
        signs: "++-",
        region: "σo = +1 and σΔ > 2",
        roots: "two roots below the maximum of Φ, none above it",
    },
    GraphClass {
        signs: "+-+",
        region: "σo = −1, |Δ| < 2 and S > 2",
        roots: "three roots between the local extremes, one elsewhere (non-uniqueness)",
    },
    GraphClass {
        signs: "--+",
        region: "σo = −1 and σΔ < −2 (so S > 2)",
        roots: "no root below the minimum, two above it",
    },
    GraphClass {
        signs: "+--",
        region: "σo = −1 and σΔ > 2 (so S > 2)",
        roots: "two roots below the maximum, none above it",
    },
];

/// An example of the class `GRAPH_CLASSES[k]` for σ = +1 (reduced
/// quantities, Y1* = 1, cos φ0 = 0.6), with X* near the kink where Φ turns
/// so that every root of X* = Φ(R) lies close to the kinks.
pub fn class_example(k: usize) -> Reduced {
    let (mu1, mu2, y2) = [
        (0.5, 0.5, -3.0),
        (3.0, 0.3, -3.0),
        (0.3, 3.0, -3.0),
        (1.5, 1.5, 0.0),
        (3.5, 0.5, 0.0),
        (0.5, 3.5, 0.0),
    ][k];
    let mut e = Reduced::sample(mu1, mu2, y2);
    let kinks = [e.y1.min(-e.y2), e.y1.max(-e.y2)];
    let b = GRAPH_CLASSES[k].signs.as_bytes();
    let weight = match (b[0] != b[1], b[1] != b[2]) {
        (true, false) => 0.95,
        (false, true) => 0.05,
        _ => 0.5,
    };
    e.x_star = weight * phi(kinks[0], 1.0, &e) + (1.0 - weight) * phi(kinks[1], 1.0, &e);
    e
}

/// The name of the Painlevé case of a root count.
pub fn painleve_case(roots: usize) -> &'static str {
    match roots {
        0 => "no root: no solution with both points sliding (Painlevé non-existence)",
        1 => "one root: regular, constant acceleration",
        _ => "several roots: the motion is not determined (Painlevé non-uniqueness)",
    }
}

/// The deformation equation (25) of the rod sliding with σ:
/// δ'' = cos²φ0 (X* − Φ(R)), R = k ε⁻² δ + ν ε⁻¹ δ'.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeformationEquation {
    pub reduced: Reduced,
    pub sigma: f64,
    pub k: f64,
    pub nu: f64,
    pub eps: f64,
}

/// An equilibrium of (25): δ* = ε² R*/k, δ' = 0, and its linearisation.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct DeformationEquilibrium {
    pub root: f64,
    pub delta: f64,
    /// Φ'(R*).
    pub slope: f64,
    /// Roots of λ² + c Φ' ν/ε λ + c Φ' k/ε² = 0, c = cos²φ0, as (re, im).
    pub eigenvalues: [(f64, f64); 2],
    /// Both eigenvalues in the open left half-plane.
    pub asymptotically_stable: bool,
}

impl DeformationEquation {
    pub fn reaction(&self, delta: f64, rate: f64) -> f64 {
        self.k / (self.eps * self.eps) * delta + self.nu / self.eps * rate
    }

    /// δ'' at (δ, δ').
    pub fn acceleration(&self, delta: f64, rate: f64) -> f64 {
        let c = self.reduced.cos_phi0 * self.reduced.cos_phi0;
        c * (self.reduced.x_star - phi(self.reaction(delta, rate), self.sigma, &self.reduced))
    }

    /// Every equilibrium (one per root of X* = Φ(R)) with its eigenvalues.
    pub fn equilibria(&self) -> Vec<DeformationEquilibrium> {
        let c = self.reduced.cos_phi0 * self.reduced.cos_phi0;
        rigid_rod_roots(self.sigma, &self.reduced)
            .into_iter()
            .map(|root| {
                let slope = phi_slope(root, self.sigma, &self.reduced);
                let (b, k) = (
                    c * slope * self.nu / self.eps,
                    c * slope * self.k / (self.eps * self.eps),
                );
                let disc = b * b - 4.0 * k;
                let eigenvalues = if disc >= 0.0 {
                    [
                        (0.5 * (-b + disc.sqrt()), 0.0),
                        (0.5 * (-b - disc.sqrt()), 0.0),
                    ]
                } else {
                    [
                        (-0.5 * b, 0.5 * (-disc).sqrt()),
                        (-0.5 * b, -0.5 * (-disc).sqrt()),
                    ]
                };
                DeformationEquilibrium {
                    root,
                    delta: self.eps * self.eps * root / self.k,
                    slope,
                    eigenvalues,
                    asymptotically_stable: eigenvalues.iter().all(|(re, _)| *re < 0.0),
                }
            })
            .collect()
    }
}

impl crate::ode::System<2> for DeformationEquation {
    fn rhs(&self, _t: f64, y: &[f64; 2]) -> [f64; 2] {
        [y[1], self.acceleration(y[0], y[1])]
    }
}

/// A state with both points at speed `v` and the rod deformed by δ; x1 = 0.
pub fn state_with_deformation(p: &Params, delta: f64, v: f64) -> [f64; 4] {
    let dx = ((p.l + delta).powi(2) - p.d * p.d).sqrt();
    [0.0, -dx, v, v]
}

/// The rod's parameters from the model's `values`: 0 < d < l, ε, k > 0,
/// friction ≥ 0.
/// The model's description (not inlined, as [`study_params`]).
#[inline(never)]
pub fn info() -> &'static crate::registry::ModelInfo {
    &crate::models::painleve_klein::INFO
}

#[inline(never)]
pub fn study_params(values: &[f64]) -> Result<Params, StudyError> {
    let p = Params::from_values(values);
    if !(p.d > 0.0
        && p.d < p.l
        && p.eps > 0.0
        && p.k > 0.0
        && p.mu1 >= 0.0
        && p.mu2 >= 0.0
        && p.nu >= 0.0)
    {
        return Err(StudyError::Settings {
            setting: "d, l, eps, k, nu, mu1, mu2",
            requirement:
                "the rod needs 0 < d < l, ε > 0, k > 0, ν ≥ 0 and friction coefficients ≥ 0",
        });
    }
    Ok(p)
}
