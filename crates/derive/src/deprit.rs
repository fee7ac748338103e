//! Averaging to second order in closed form: the Lie series of
//! `crates/derive/src/lie.rs` over Symbolica atoms, for models whose Hamiltonian is an
//! expression in (q, p, θ).
//!
//! The averaged Hamiltonian to second order is K̄ = H̄ + εK̄₁ + ε²K̄₂; the
//! map to first order is y = y′ + ε J∇χ₁(y′, θ) (J the symplectic unit:
//! q = q′ + ε ∂χ₁/∂p, p = p′ − ε ∂χ₁/∂q).

use crate::algebra::{num, phase_modes, DeriveError};
use crate::lie::{monomial, Coefficients, Harmonic, Series};
use symbolica::prelude::*;

/// Coefficients as Symbolica atoms; brackets over the coordinates `q` and
/// momenta `p`.
pub struct Atoms<'a> {
    pub q: &'a [String],
    pub p: &'a [String],
}

impl Coefficients for Atoms<'_> {
    type C = Atom;
    fn zero(&mut self) -> Atom {
        num(0)
    }
    fn add(&mut self, a: &Atom, b: &Atom) -> Atom {
        a + b
    }
    fn scale(&mut self, c: &Atom, numerator: i64, denominator: i64) -> Atom {
        c * &(Atom::num(numerator) / Atom::num(denominator))
    }
    fn bracket(&mut self, f: &Atom, g: &Atom) -> Atom {
        let mut sum = num(0);
        for (qi, pi) in self.q.iter().zip(self.p) {
            let (qs, ps) = (symbol!(qi.as_str()), symbol!(pi.as_str()));
            sum = sum + f.derivative(qs) * g.derivative(ps) - f.derivative(ps) * g.derivative(qs);
        }
        sum
    }
}

/// The Fourier series of a trigonometric polynomial in `phase`.
pub fn fourier(e: &Atom, phase: &str) -> Result<Series<Atom>, DeriveError> {
    let mut series = Series::new();
    let mut atoms = Atoms { q: &[], p: &[] };
    for ((a, b), coefficients) in phase_modes(std::slice::from_ref(e), phase)? {
        for (h, n, d) in monomial(a, b) {
            let term = atoms.scale(&coefficients[0], n, d);
            crate::lie::add_to(&mut atoms, &mut series, h, term);
        }
    }
    Ok(series)
}

/// The series as an expression in θ.
fn to_atom(series: &Series<Atom>, phase: &str) -> Result<Atom, DeriveError> {
    let mut sum = num(0);
    for (h, c) in series {
        let term = match h {
            Harmonic::Cos(0) => c.clone(),
            Harmonic::Cos(k) => c * &crate::algebra::atom(&format!("cos({k}*{phase})"))?,
            Harmonic::Sin(k) => c * &crate::algebra::atom(&format!("sin({k}*{phase})"))?,
        };
        sum += term;
    }
    Ok(sum)
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
    rec: &mut crate::algebra::Recorder,
) -> Result<SecondOrderForm, DeriveError> {
    let series = fourier(hamiltonian, phase)?;
    let terms = crate::lie::second_order(&mut Atoms { q, p }, &series);
    let first = terms.first.together();
    // Not brought over a common denominator here: recording does it, and
    // for the double pendulum each pass took 1.5 s.
    let second = terms.second;
    let generator = to_atom(&terms.generator, phase)?;
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
        &generator,
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
