//! The Lie series of second-order averaging over any coefficient
//! arithmetic: Symbolica atoms where the Hamiltonian has a closed form
//! (`crates/derive/src/deprit.rs`), named nodes of the emitter's DAG where A⁻¹ is only
//! known through numeric solves (`crates/derive/src/numeric.rs`).
//!
//! In the extended phase space (q, θ; p, I) the system is
//! K = I/ε + H(q, p, θ), H = H̄ + H̃ with H̄ the mean over θ. The new
//! variables y are y = exp(L_χ) y′ with L_χ f = {f, χ} and the generator
//! χ = εχ₁ + ε²χ₂ + …; collecting powers of ε in exp(L_χ) K (with
//! {I/ε, εⁿ⁺¹χₙ₊₁} = −εⁿ ∂χₙ₊₁/∂θ) and choosing each χ with zero mean so
//! that every order is independent of θ:
//!
//! - ε⁰: ∂χ₁/∂θ = H̃, K̄₀ = H̄;
//! - ε¹: R₁ = {H̄, χ₁} + ½{H̃, χ₁}, K̄₁ = mean R₁, ∂χ₂/∂θ = R₁ − K̄₁;
//! - ε²: K̄₂ = mean(½{H̃, χ₂} − ½{R₁, χ₁} + ½{{H̄, χ₁}, χ₁} + ⅓{{H̃, χ₁}, χ₁}).
//!
//! (χ₃ only cancels the oscillating part of order ε²: it does not enter K̄.)
//! The brackets are over (q, p) only. H is a trigonometric polynomial in θ,
//! so every quantity is a finite Fourier series in θ with coefficients that
//! are functions of (q, p): antiderivatives in θ are exact (sin kθ/k,
//! −cos kθ/k), products of harmonics follow the product formulas, and means
//! are the constant terms.

use std::collections::BTreeMap;

/// A harmonic: cos kθ or sin kθ.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Harmonic {
    Cos(i64),
    Sin(i64),
}

/// A finite Fourier series in θ with coefficients in (q, p).
pub type Series<C> = BTreeMap<Harmonic, C>;

/// The arithmetic of the series' coefficients (functions of q and p).
pub trait Coefficients {
    type C: Clone;
    fn zero(&mut self) -> Self::C;
    fn add(&mut self, a: &Self::C, b: &Self::C) -> Self::C;
    /// (numerator/denominator)·c.
    fn scale(&mut self, c: &Self::C, numerator: i64, denominator: i64) -> Self::C;
    /// The Poisson bracket {f, g} over (q, p).
    fn bracket(&mut self, f: &Self::C, g: &Self::C) -> Self::C;
}

/// sin(θ)^a cos(θ)^b as a Fourier series with rational coefficients
/// (harmonic, numerator, denominator): with z = e^{iθ}, it is
/// (−i)^a/2^{a+b} · (z − 1/z)^a (z + 1/z)^b.
pub fn monomial(a: i64, b: i64) -> Vec<(Harmonic, i64, i64)> {
    let degree = (a + b) as usize;
    // Coefficients of z^m, m = −degree..=degree, at index m + degree.
    let mut poly = vec![0i64; 2 * degree + 1];
    poly[degree] = 1;
    let mut multiply = |sign: i64| {
        let mut next = vec![0i64; poly.len()];
        for (m, c) in poly.iter().enumerate() {
            if *c != 0 {
                next[m + 1] += c;
                next[m - 1] += sign * c;
            }
        }
        poly = next;
    };
    for _ in 0..a {
        multiply(-1);
    }
    for _ in 0..b {
        multiply(1);
    }
    let denominator = 1i64 << (a + b);
    let sign = if (a / 2) % 2 == 0 { 1 } else { -1 };
    let mut terms = Vec::new();
    for k in 0..=degree {
        let (plus, minus) = (poly[degree + k], poly[degree - k]);
        if a % 2 == 0 {
            let c = if k == 0 { plus } else { plus + minus };
            if c != 0 {
                terms.push((Harmonic::Cos(k as i64), sign * c, denominator));
            }
        } else if k > 0 && plus - minus != 0 {
            terms.push((Harmonic::Sin(k as i64), sign * (plus - minus), denominator));
        }
    }
    terms
}

/// Adds `value` to the coefficient of harmonic `h`.
pub fn add_to<A: Coefficients>(alg: &mut A, series: &mut Series<A::C>, h: Harmonic, value: A::C) {
    let sum = match series.get(&h) {
        Some(slot) => alg.add(slot, &value),
        None => value,
    };
    series.insert(h, sum);
}

/// The harmonics of the product of two harmonics, each with weight ±½.
fn product(x: Harmonic, y: Harmonic) -> [(Harmonic, i64); 2] {
    use Harmonic::{Cos, Sin};
    // sin(−k) = −sin k, cos(−k) = cos k.
    let sin = |k: i64, s: i64| if k < 0 { (Sin(-k), -s) } else { (Sin(k), s) };
    match (x, y) {
        (Cos(a), Cos(b)) => [(Cos((a - b).abs()), 1), (Cos(a + b), 1)],
        (Sin(a), Sin(b)) => [(Cos((a - b).abs()), 1), (Cos(a + b), -1)],
        (Sin(a), Cos(b)) => [sin(a - b, 1), (Sin(a + b), 1)],
        (Cos(a), Sin(b)) => [sin(b - a, 1), (Sin(a + b), 1)],
    }
}

/// The Poisson bracket of two series, harmonic by harmonic.
fn bracket<A: Coefficients>(alg: &mut A, f: &Series<A::C>, g: &Series<A::C>) -> Series<A::C> {
    let mut out = Series::new();
    for (hf, cf) in f {
        for (hg, cg) in g {
            let b = alg.bracket(cf, cg);
            for (h, sign) in product(*hf, *hg) {
                if !matches!(h, Harmonic::Sin(0)) {
                    let term = alg.scale(&b, sign, 2);
                    add_to(alg, &mut out, h, term);
                }
            }
        }
    }
    out
}

/// The mean of the bracket of two series: only the pairs of harmonics
/// whose product has a constant term (cos kθ·cos kθ, sin kθ·sin kθ).
fn mean_bracket<A: Coefficients>(alg: &mut A, f: &Series<A::C>, g: &Series<A::C>) -> A::C {
    let mut sum = alg.zero();
    for (hf, cf) in f {
        for (hg, cg) in g {
            for (h, sign) in product(*hf, *hg) {
                if h == Harmonic::Cos(0) {
                    let b = alg.bracket(cf, cg);
                    let term = alg.scale(&b, sign, 2);
                    sum = alg.add(&sum, &term);
                }
            }
        }
    }
    sum
}

/// Σ (numerator/denominator) · series.
fn combine<A: Coefficients>(alg: &mut A, terms: &[(i64, i64, &Series<A::C>)]) -> Series<A::C> {
    let mut out = Series::new();
    for (numerator, denominator, series) in terms {
        for (h, c) in series.iter() {
            let term = alg.scale(c, *numerator, *denominator);
            add_to(alg, &mut out, *h, term);
        }
    }
    out
}

/// The mean over θ: the constant term.
pub fn mean<A: Coefficients>(alg: &mut A, series: &Series<A::C>) -> A::C {
    match series.get(&Harmonic::Cos(0)) {
        Some(c) => c.clone(),
        None => alg.zero(),
    }
}

fn oscillating<C: Clone>(series: &Series<C>) -> Series<C> {
    series
        .iter()
        .filter(|(h, _)| !matches!(h, Harmonic::Cos(0) | Harmonic::Sin(0)))
        .map(|(h, c)| (*h, c.clone()))
        .collect()
}

/// The zero-mean antiderivative in θ of an oscillating series.
fn antiderivative<A: Coefficients>(alg: &mut A, series: &Series<A::C>) -> Series<A::C> {
    oscillating(series)
        .into_iter()
        .map(|(h, c)| match h {
            Harmonic::Cos(k) => (Harmonic::Sin(k), alg.scale(&c, 1, k)),
            Harmonic::Sin(k) => (Harmonic::Cos(k), alg.scale(&c, -1, k)),
        })
        .collect()
}

/// What the second-order averaging gives.
pub struct SecondOrder<C> {
    /// K̄₁ (zero for the vibrations of the studies) and K̄₂.
    pub first: C,
    pub second: C,
    /// χ₁(q, p, θ), the generator of the first-order map, as a series.
    pub generator: Series<C>,
}

/// K̄₁, K̄₂ and χ₁ of the Hamiltonian whose Fourier series in the fast
/// phase is `series`. χ₁ is computed before any bracket, so with the DAG's
/// arithmetic it needs none of the bracket's steps.
pub fn second_order<A: Coefficients>(alg: &mut A, series: &Series<A::C>) -> SecondOrder<A::C> {
    let mean_value = mean(alg, series);
    let mean_part: Series<A::C> = [(Harmonic::Cos(0), mean_value)].into_iter().collect();
    let varying = oscillating(series);
    let chi1 = antiderivative(alg, &varying);
    let mean_chi1 = bracket(alg, &mean_part, &chi1);
    let varying_chi1 = bracket(alg, &varying, &chi1);
    let r1 = combine(alg, &[(1, 1, &mean_chi1), (1, 2, &varying_chi1)]);
    let first = mean(alg, &r1);
    let chi2 = antiderivative(alg, &r1);
    let oscillating_r1 = oscillating(&r1);
    let terms = [
        (1, 2, mean_bracket(alg, &varying, &chi2)),
        (-1, 2, mean_bracket(alg, &oscillating_r1, &chi1)),
        (1, 2, mean_bracket(alg, &mean_chi1, &chi1)),
        (1, 3, mean_bracket(alg, &varying_chi1, &chi1)),
    ];
    let mut second = alg.zero();
    for (numerator, denominator, term) in &terms {
        let scaled = alg.scale(term, *numerator, *denominator);
        second = alg.add(&second, &scaled);
    }
    SecondOrder {
        first,
        second,
        generator: chi1,
    }
}
