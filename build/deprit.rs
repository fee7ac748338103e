//! Averaging to second order by a near-identity canonical transformation
//! (a Lie series in the small parameter ε = 1/rate of the fast phase).
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
//!
//! The averaged Hamiltonian to second order is K̄ = H̄ + εK̄₁ + ε²K̄₂; the
//! map to first order is y = y′ + ε J∇χ₁(y′, θ) (J the symplectic unit:
//! q = q′ + ε ∂χ₁/∂p, p = p′ − ε ∂χ₁/∂q).

use crate::derive::{num, phase_modes, DeriveError};
use std::collections::BTreeMap;
use symbolica::prelude::*;

/// A harmonic: cos kθ or sin kθ.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Harmonic {
    Cos(i64),
    Sin(i64),
}

/// A finite Fourier series in θ with coefficients in (q, p).
type Series = BTreeMap<Harmonic, Atom>;

/// What the second-order averaging gives.
pub struct SecondOrder {
    /// K̄₁ (zero for the vibrations of the studies) and K̄₂.
    pub first: Atom,
    pub second: Atom,
    /// χ₁(q, p, θ), the generator of the first-order map.
    pub generator: Atom,
}

/// sin(θ)^a cos(θ)^b as a Fourier series with rational coefficients:
/// with z = e^{iθ}, it is (−i)^a/2^{a+b} · (z − 1/z)^a (z + 1/z)^b.
fn monomial(a: i64, b: i64) -> Vec<(Harmonic, i64, i64)> {
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

fn add_to(series: &mut Series, h: Harmonic, value: Atom) {
    match series.get_mut(&h) {
        Some(slot) => *slot = &*slot + &value,
        None => {
            series.insert(h, value);
        }
    }
}

/// The Fourier series of a trigonometric polynomial in `phase`.
fn fourier(e: &Atom, phase: &str) -> Result<Series, DeriveError> {
    let mut series = Series::new();
    for ((a, b), coefficients) in phase_modes(std::slice::from_ref(e), phase)? {
        for (h, n, d) in monomial(a, b) {
            add_to(
                &mut series,
                h,
                &coefficients[0] * &(Atom::num(n) / Atom::num(d)),
            );
        }
    }
    Ok(series)
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

/// {f, g} over (q, p).
fn bracket_atoms(f: &Atom, g: &Atom, q: &[String], p: &[String]) -> Atom {
    let mut sum = num(0);
    for (qi, pi) in q.iter().zip(p) {
        let (qs, ps) = (symbol!(qi.as_str()), symbol!(pi.as_str()));
        sum = sum + f.derivative(qs) * g.derivative(ps) - f.derivative(ps) * g.derivative(qs);
    }
    sum
}

/// The Poisson bracket of two series, harmonic by harmonic.
fn bracket(f: &Series, g: &Series, q: &[String], p: &[String]) -> Series {
    let mut out = Series::new();
    for (hf, cf) in f {
        for (hg, cg) in g {
            let b = bracket_atoms(cf, cg, q, p);
            for (h, sign) in product(*hf, *hg) {
                if !matches!(h, Harmonic::Sin(0)) {
                    add_to(&mut out, h, &b * &(Atom::num(sign) / num(2)));
                }
            }
        }
    }
    out
}

/// Σ weight · series.
fn combine(terms: &[(Atom, &Series)]) -> Series {
    let mut out = Series::new();
    for (weight, series) in terms {
        for (h, c) in series.iter() {
            add_to(&mut out, *h, c * weight);
        }
    }
    out
}

fn mean(series: &Series) -> Atom {
    series
        .get(&Harmonic::Cos(0))
        .cloned()
        .unwrap_or_else(|| num(0))
}

fn oscillating(series: &Series) -> Series {
    series
        .iter()
        .filter(|(h, _)| !matches!(h, Harmonic::Cos(0) | Harmonic::Sin(0)))
        .map(|(h, c)| (*h, c.clone()))
        .collect()
}

/// The zero-mean antiderivative in θ of an oscillating series.
fn antiderivative(series: &Series) -> Series {
    oscillating(series)
        .into_iter()
        .map(|(h, c)| match h {
            Harmonic::Cos(k) => (Harmonic::Sin(k), c / num(k)),
            Harmonic::Sin(k) => (Harmonic::Cos(k), -c / num(k)),
        })
        .collect()
}

/// The series as an expression in θ.
fn to_atom(series: &Series, phase: &str) -> Result<Atom, DeriveError> {
    let mut sum = num(0);
    for (h, c) in series {
        let term = match h {
            Harmonic::Cos(0) => c.clone(),
            Harmonic::Cos(k) => c * &crate::derive::atom(&format!("cos({k}*{phase})"))?,
            Harmonic::Sin(k) => c * &crate::derive::atom(&format!("sin({k}*{phase})"))?,
        };
        sum += term;
    }
    Ok(sum)
}

/// K̄₁, K̄₂ and χ₁ of the Hamiltonian `h` (coordinates `q`, momenta `p`,
/// fast phase `phase`).
pub fn second_order(
    h: &Atom,
    phase: &str,
    q: &[String],
    p: &[String],
) -> Result<SecondOrder, DeriveError> {
    let series = fourier(h, phase)?;
    let mean_part: Series = [(Harmonic::Cos(0), mean(&series))].into_iter().collect();
    let varying = oscillating(&series);
    let chi1 = antiderivative(&varying);
    let half = num(1) / num(2);
    let third = num(1) / num(3);
    let mean_chi1 = bracket(&mean_part, &chi1, q, p);
    let varying_chi1 = bracket(&varying, &chi1, q, p);
    let r1 = combine(&[(num(1), &mean_chi1), (half.clone(), &varying_chi1)]);
    let first = mean(&r1);
    let chi2 = antiderivative(&r1);
    let second = mean(&combine(&[
        (half.clone(), &bracket(&varying, &chi2, q, p)),
        (-half.clone(), &bracket(&oscillating(&r1), &chi1, q, p)),
        (half, &bracket(&mean_chi1, &chi1, q, p)),
        (third, &bracket(&varying_chi1, &chi1, q, p)),
    ]));
    Ok(SecondOrder {
        first,
        second,
        generator: to_atom(&chi1, phase)?,
    })
}

/// The second-order averaged system as the code generator needs it (its
/// derivatives are taken by forward mode through the emitted DAG, which
/// shares what Symbolica's expanded derivatives would repeat).
pub struct SecondOrderForm {
    /// K̄ = H̄ + εK̄₁ + ε²K̄₂, ε = 1/rate, in (q, p).
    pub hamiltonian: String,
    /// The first-order mean forces P̄.
    pub forces: Vec<String>,
    /// εχ₁(q, p, θ): the map is y = y′ + J∇(εχ₁).
    pub generator: String,
}

/// Derives and records K̄₁, K̄₂ and χ₁ (readable forms, checked at random
/// points against Symbolica's) and the pieces of [`SecondOrderForm`].
pub fn second_order_form(
    hamiltonian: &Atom,
    averaged_hamiltonian: &Atom,
    averaged_forces: &[Atom],
    (phase, rate): (&str, &Atom),
    q: &[String],
    p: &[String],
    rec: &mut crate::derive::Recorder,
) -> Result<SecondOrderForm, DeriveError> {
    let terms = second_order(hamiltonian, phase, q, p)?;
    let first = terms.first.together();
    let second = terms.second.together();
    rec.record(
        "averaged_hamiltonian_first_order",
        "K̄₁ = mean(½{H̃, χ₁}): the correction of order ε = 1/rate to H̄",
        &first,
    )?;
    let second_text = rec.record(
        "averaged_hamiltonian_second_order",
        "K̄₂: the correction of order ε² to H̄ (second-order averaging, K̄ = H̄ + εK̄₁ + ε²K̄₂)",
        &second,
    )?;
    let generator_text = rec.record(
        "generator_first_order",
        "χ₁ = ∫H̃ dθ (zero mean): the generator of the map y = y′ + ε J∇χ₁",
        &terms.generator,
    )?;
    let eps = format!("(1/({rate}))");
    Ok(SecondOrderForm {
        hamiltonian: format!(
            "({}) + {eps}*({}) + {eps}^2*({second_text})",
            averaged_hamiltonian, first
        ),
        forces: averaged_forces.iter().map(|f| f.to_string()).collect(),
        generator: format!("{eps}*({generator_text})"),
    })
}
