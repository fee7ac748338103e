//! Study 3: the Painlevé–Klein example, closed forms of the rod geometry and
//! of the rigid-rod equation X* = Φ(R) (docs/studies.md).
//!
//! Coordinates: x1, x2 along the guides (point 1 on the guide at distance d);
//! δ = √((x1 − x2)² + d²) − l, δ' = (x1' − x2')(x1 − x2)/(l + δ),
//! cos φ = (x1 − x2)/(l + δ), sin φ = d/(l + δ), R = k ε⁻² δ + ν ε⁻¹ δ'.

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
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reduced {
    pub x_star: f64,
    pub mu1: f64,
    pub mu2: f64,
    pub y1: f64,
    pub y2: f64,
    pub cos_phi0: f64,
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
#[derive(Clone, Copy, Debug, PartialEq)]
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

/// The name of the Painlevé case of a root count.
pub fn painleve_case(roots: usize) -> &'static str {
    match roots {
        0 => "no root: no solution with both points sliding (Painlevé non-existence)",
        1 => "one root: regular, constant acceleration",
        _ => "several roots: the motion is not determined (Painlevé non-uniqueness)",
    }
}
