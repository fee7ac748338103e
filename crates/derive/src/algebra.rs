//! The algebra every derivation step shares, over Symbolica atoms: atoms
//! from text, substitution, means over the fast phase and its Fourier
//! modes, determinants and inverses by cofactors, and the [`Recorder`] that
//! keeps each derived expression in its readable form (text and LaTeX).

use crate::latex::Names;
use crate::model::expr::BinOp;
use crate::model::{Expr, Model};
use crate::simplify;
use symbolica::prelude::*;

pub use crate::error::DeriveError;

/// One derived expression, printed.
pub struct Derived {
    /// Stable key, e.g. `hamiltonian` or `mass_matrix[0][1]`.
    pub key: String,
    pub description: String,
    pub text: String,
    pub latex: String,
}

/// Symbolica's atom for an expression's text, its decimal numbers made
/// exact rationals first: read as floats, they carry a precision of their
/// own, and sums of such floats came out scaled by powers of ten
/// (0.0 + 0.05 cos φ as 5 cos φ). The user typed a decimal; the
/// derivation works with the number it names.
pub fn atom(text: &str) -> Result<Atom, DeriveError> {
    let exact = mechlab_model::expr::exact_decimals(text);
    try_parse!(&exact).map_err(|e| DeriveError::Symbolica {
        text: text.to_string(),
        message: e.to_string(),
    })
}

pub fn var(name: &str) -> Atom {
    Atom::var(symbol!(name))
}

pub fn num(n: i64) -> Atom {
    Atom::num(n)
}

pub fn subst(e: &Atom, name: &str, by: &Atom) -> Atom {
    e.replace(var(name).to_pattern()).with(by.to_pattern())
}

pub fn is_zero(e: &Atom) -> bool {
    e.expand().to_string() == "0"
}

/// Momentum symbol of a coordinate.
pub fn momentum_name(coordinate: &str) -> String {
    format!("p_{coordinate}")
}

/// Mean over one period of the phase `phase`, for expressions that contain the
/// phase only through sin(phase) and cos(phase), polynomially: with S = sin,
/// C = cos, mean(S^a C^b) = (a−1)!!(b−1)!!/(a+b)!! for even a, b and 0 otherwise.
/// Coefficients are read off as Taylor coefficients in S and C.
pub(crate) fn phase_mean(e: &Atom, phase: &str) -> Result<Atom, DeriveError> {
    let (s_name, c_name) = ("phase__sin", "phase__cos");
    let replaced = trigonometric_polynomial(e, phase, s_name, c_name)?;
    let mut mean = num(0);
    let mut ds = replaced;
    let mut a = 0i64;
    let mut a_factorial = 1i64;
    while !is_zero(&ds) {
        let mut dsc = ds.clone();
        let mut b = 0i64;
        let mut b_factorial = 1i64;
        while !is_zero(&dsc) {
            if a % 2 == 0 && b % 2 == 0 {
                let coefficient = subst(&subst(&dsc, s_name, &num(0)), c_name, &num(0));
                let (numerator, denominator) = monomial_mean(a, b);
                let weight =
                    Atom::num(numerator) / Atom::num(denominator * a_factorial * b_factorial);
                mean += coefficient * weight;
            }
            dsc = dsc.derivative(symbol!(c_name));
            b += 1;
            b_factorial *= b;
        }
        ds = ds.derivative(symbol!(s_name));
        a += 1;
        a_factorial *= a;
    }
    Ok(mean)
}

/// `e` with sin(phase), cos(phase) replaced by the symbols `s_name`,
/// `c_name`; an error if the phase enters any other way.
pub(crate) fn trigonometric_polynomial(
    e: &Atom,
    phase: &str,
    s_name: &str,
    c_name: &str,
) -> Result<Atom, DeriveError> {
    let replaced = e
        .replace(atom(&format!("sin({phase})"))?.to_pattern())
        .with(var(s_name).to_pattern())
        .replace(atom(&format!("cos({phase})"))?.to_pattern())
        .with(var(c_name).to_pattern());
    if !is_zero(&replaced.derivative(symbol!(phase))) {
        return Err(DeriveError::Model {
            key: "fast_phase".into(),
            reason: format!(
                "the phase '{phase}' enters other than through sin({phase}) and cos({phase}); rewrite multiple angles with addition formulas"
            ),
        });
    }
    Ok(replaced)
}

/// mean over θ of sin(θ)^a cos(θ)^b as a fraction: (a−1)!!(b−1)!!/(a+b)!!
/// for even a and b, 0 otherwise.
pub fn monomial_mean(a: i64, b: i64) -> (i64, i64) {
    fn double_factorial(n: i64) -> i64 {
        if n <= 0 {
            1
        } else {
            n * double_factorial(n - 2)
        }
    }
    if a % 2 != 0 || b % 2 != 0 {
        return (0, 1);
    }
    (
        double_factorial(a - 1) * double_factorial(b - 1),
        double_factorial(a + b),
    )
}

/// The modes of a vector of trigonometric polynomials in the phase:
/// v = Σ_s sin(θ)^{a_s} cos(θ)^{b_s} g_s, returned as ((a_s, b_s), g_s)
/// for every monomial with a non-zero coefficient in some component.
pub fn phase_modes(v: &[Atom], phase: &str) -> Result<Vec<((i64, i64), Vec<Atom>)>, DeriveError> {
    let (s_name, c_name) = ("mode__sin", "mode__cos");
    let mut modes: Vec<((i64, i64), Vec<Atom>)> = Vec::new();
    for (i, e) in v.iter().enumerate() {
        let mut ds = trigonometric_polynomial(e, phase, s_name, c_name)?;
        let (mut a, mut a_factorial) = (0i64, 1i64);
        while !is_zero(&ds) {
            let (mut dsc, mut b, mut b_factorial) = (ds.clone(), 0i64, 1i64);
            while !is_zero(&dsc) {
                let coefficient = subst(&subst(&dsc, s_name, &num(0)), c_name, &num(0)).expand()
                    / Atom::num(a_factorial * b_factorial);
                if !is_zero(&coefficient) {
                    let slot = match modes.iter().position(|(k, _)| *k == (a, b)) {
                        Some(slot) => slot,
                        None => {
                            modes.push(((a, b), vec![num(0); v.len()]));
                            modes.len() - 1
                        }
                    };
                    modes[slot].1[i] = coefficient.expand();
                }
                dsc = dsc.derivative(symbol!(c_name));
                b += 1;
                b_factorial *= b;
            }
            ds = ds.derivative(symbol!(s_name));
            a += 1;
            a_factorial *= a;
        }
    }
    modes.sort_by_key(|(k, _)| *k);
    Ok(modes)
}

/// Determinant by cofactor expansion (the systems here have 1–3 degrees of freedom).
fn determinant(m: &[Vec<Atom>]) -> Atom {
    let n = m.len();
    if n == 1 {
        return m[0][0].clone();
    }
    let mut det = num(0);
    for j in 0..n {
        let minor: Vec<Vec<Atom>> = m[1..]
            .iter()
            .map(|row| {
                row.iter()
                    .enumerate()
                    .filter(|(k, _)| *k != j)
                    .map(|(_, a)| a.clone())
                    .collect()
            })
            .collect();
        let term = &m[0][j] * &determinant(&minor);
        det = if j % 2 == 0 { det + term } else { det - term };
    }
    det
}

/// Inverse by cofactors over the expanded determinant.
pub(crate) fn inverse(m: &[Vec<Atom>]) -> (Atom, Vec<Vec<Atom>>) {
    let n = m.len();
    let det = determinant(m).expand();
    let inv = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| {
                    // (A⁻¹)_ij = cofactor_ji / det
                    let cofactor = if n == 1 {
                        num(1)
                    } else {
                        let minor: Vec<Vec<Atom>> = m
                            .iter()
                            .enumerate()
                            .filter(|(r, _)| *r != j)
                            .map(|(_, row)| {
                                row.iter()
                                    .enumerate()
                                    .filter(|(k, _)| *k != i)
                                    .map(|(_, a)| a.clone())
                                    .collect()
                            })
                            .collect();
                        let d = determinant(&minor).expand();
                        if (i + j) % 2 == 0 {
                            d
                        } else {
                            -d
                        }
                    };
                    cofactor / &det
                })
                .collect()
        })
        .collect();
    (det, inv)
}

/// Canonical form modulo sin²x + cos²x = 1 for the angle `x`: as a
/// polynomial in S = sin x, every S^k becomes S^(k mod 2) (1 − C²)^(k div 2).
/// Applied to the Lagrangian and the Rayleigh function, so that everything
/// derived from them is free of sin² + cos² leftovers. A part that is not
/// polynomial in S and C (a root, a quotient, another function of the
/// angle) is reduced inside and held as one symbol while the polynomial
/// around it is reduced: a spring's length written in the fixed frame,
/// √(cos²x a² + sin²x a² + …), loses its turn under the root, and the
/// reduction ends for any expression.
pub(crate) fn reduce_pythagorean(e: &Atom, angle: &str) -> Result<Atom, DeriveError> {
    let parsed = read_back(e)?;
    if !parsed.symbols().contains(angle) {
        return Ok(e.clone());
    }
    let mut held = Vec::new();
    let polynomial = hold_non_polynomial(&parsed, angle, &mut held)?;
    let mut reduced = reduce_polynomial(&atom(&polynomial.to_string())?, angle)?;
    for (name, part) in held.iter().rev() {
        reduced = subst(&reduced, name, part);
    }
    Ok(reduced)
}

/// Symbolica's printed form of `e` read back as a model-file expression.
fn read_back(e: &Atom) -> Result<Expr, DeriveError> {
    let text = e.to_string();
    Expr::parse_printed(&text).map_err(|err| DeriveError::Model {
        key: "lagrangian".into(),
        reason: format!("cannot read back '{text}': {err}"),
    })
}

/// `e` with each part that is not polynomial in sin and cos of `angle`
/// and holds the angle replaced by a symbol `held__k`, its reduced value
/// kept in `held`.
fn hold_non_polynomial(
    e: &Expr,
    angle: &str,
    held: &mut Vec<(String, Atom)>,
) -> Result<Expr, DeriveError> {
    let holds_angle = |x: &Expr| x.symbols().contains(angle);
    let hold = |part: Expr, held: &mut Vec<(String, Atom)>| -> Result<Expr, DeriveError> {
        let name = format!("held__{}", held.len());
        held.push((name.clone(), atom(&part.to_string())?));
        Ok(Expr::Sym(name))
    };
    let reduced = |x: &Expr| -> Result<Expr, DeriveError> {
        read_back(&reduce_pythagorean(&atom(&x.to_string())?, angle)?)
    };
    Ok(match e {
        _ if !holds_angle(e) => e.clone(),
        Expr::Num(_) | Expr::Sym(_) => e.clone(),
        Expr::Neg(a) => Expr::Neg(Box::new(hold_non_polynomial(a, angle, held)?)),
        Expr::Bin(BinOp::Pow, base, exponent) if matches!(&**exponent, Expr::Num(n) if n.parse::<u32>().is_ok()) =>
        {
            let base = hold_non_polynomial(base, angle, held)?;
            Expr::Bin(BinOp::Pow, Box::new(base), exponent.clone())
        }
        Expr::Bin(BinOp::Div, a, b) if holds_angle(b) => {
            let a = hold_non_polynomial(a, angle, held)?;
            let inverse = Expr::Bin(BinOp::Div, Box::new(Expr::num(1)), Box::new(reduced(b)?));
            Expr::Bin(BinOp::Mul, Box::new(a), Box::new(hold(inverse, held)?))
        }
        Expr::Bin(BinOp::Pow, base, exponent) => {
            let part = Expr::Bin(
                BinOp::Pow,
                Box::new(reduced(base)?),
                Box::new(reduced(exponent)?),
            );
            hold(part, held)?
        }
        Expr::Bin(op, a, b) => Expr::Bin(
            *op,
            Box::new(hold_non_polynomial(a, angle, held)?),
            Box::new(hold_non_polynomial(b, angle, held)?),
        ),
        Expr::Call(name, args)
            if (name == "sin" || name == "cos") && args == &[Expr::Sym(angle.to_string())] =>
        {
            e.clone()
        }
        Expr::Call(name, args) => {
            let args = args.iter().map(reduced).collect::<Result<Vec<_>, _>>()?;
            hold(Expr::Call(name.clone(), args), held)?
        }
    })
}

/// [`reduce_pythagorean`] of an expression polynomial in sin and cos of
/// `angle` (its Taylor coefficients in S end).
fn reduce_polynomial(e: &Atom, angle: &str) -> Result<Atom, DeriveError> {
    let (s_name, c_name) = ("angle__sin", "angle__cos");
    let sin = atom(&format!("sin({angle})"))?;
    let cos = atom(&format!("cos({angle})"))?;
    let replaced = e
        .replace(sin.to_pattern())
        .with(var(s_name).to_pattern())
        .replace(cos.to_pattern())
        .with(var(c_name).to_pattern());
    let one_minus_c2 = num(1) - var(c_name) * var(c_name);
    let mut result = num(0);
    let mut derivative = replaced;
    let mut k = 0i64;
    let mut factorial = 1i64;
    while !is_zero(&derivative) {
        let coefficient = subst(&derivative, s_name, &num(0)) / num(factorial);
        let mut power = if k % 2 == 1 { var(s_name) } else { num(1) };
        for _ in 0..k / 2 {
            power *= &one_minus_c2;
        }
        result += coefficient * power;
        derivative = derivative.derivative(symbol!(s_name));
        k += 1;
        factorial *= k;
    }
    Ok(subst(&subst(&result, s_name, &sin), c_name, &cos).expand())
}

/// Drops the terms of an expanded sum that depend on none of `symbols`.
pub(crate) fn drop_terms_without(e: &Atom, symbols: &[String]) -> Result<Atom, DeriveError> {
    let text = e.expand().to_string();
    let parsed = Expr::parse_printed(&text).map_err(|err| DeriveError::Model {
        key: "lagrangian".into(),
        reason: format!("cannot read back '{text}': {err}"),
    })?;
    let kept: Vec<Expr> = parsed
        .terms()
        .into_iter()
        .filter(|t| t.symbols().iter().any(|s| symbols.contains(s)))
        .collect();
    atom(&Expr::sum(kept).to_string())
}

pub struct Recorder {
    derived: Vec<Derived>,
    vocabulary: simplify::Vocabulary,
    names: Names,
    /// The model's start and default parameters, near which a readable form
    /// is checked where random points fall outside the model's domain.
    start: simplify::Start,
}

impl Recorder {
    /// A recorder with the model's LaTeX names; readable forms are grouped
    /// by `keys` (momenta, velocities).
    pub fn for_model(model: &Model, keys: Vec<String>) -> Recorder {
        let phase = model.fast_phase.as_ref().map(|f| f.name.clone());
        let names = Names::new(
            &model
                .coordinates
                .iter()
                .map(|c| {
                    (
                        c.name.clone(),
                        c.velocity.clone(),
                        momentum_name(&c.name),
                        c.latex.clone(),
                    )
                })
                .collect::<Vec<_>>(),
            &model
                .parameters
                .iter()
                .map(|x| (x.name.clone(), x.latex.clone()))
                .chain(phase.iter().map(|th| (th.clone(), None)))
                .collect::<Vec<_>>(),
        );
        let start = model
            .coordinates
            .iter()
            .zip(model.start_or_zero())
            .flat_map(|(c, q)| [(c.name.clone(), q), (c.velocity.clone(), 0.0)])
            .chain(model.parameters.iter().map(|p| (p.name.clone(), p.default)))
            .chain(phase.iter().map(|th| (th.clone(), 0.0)))
            .chain([(model.time.clone(), 0.0)])
            .collect();
        Recorder {
            derived: Vec::new(),
            start,
            vocabulary: simplify::Vocabulary {
                keys,
                phase,
                coordinates: model.coordinates.iter().map(|c| c.name.clone()).collect(),
            },
            names,
        }
    }

    /// Everything recorded, in order.
    pub fn finish(self) -> Vec<Derived> {
        self.derived
    }

    /// Records the readable form of `e`; returns its text.
    pub fn record(
        &mut self,
        key: impl Into<String>,
        description: impl Into<String>,
        e: &Atom,
    ) -> Result<String, DeriveError> {
        self.record_sum(key, description, std::slice::from_ref(e))
    }

    /// Records the sum of `parts`, each simplified on its own (so that, e.g.,
    /// H reads as its kinetic part plus V rather than one long fraction).
    pub fn record_sum(
        &mut self,
        key: impl Into<String>,
        description: impl Into<String>,
        parts: &[Atom],
    ) -> Result<String, DeriveError> {
        let key = key.into();
        let failure = |source| DeriveError::Readable {
            key: key.clone(),
            source,
        };
        let mut derived = Vec::new();
        let mut readable = Vec::new();
        for part in parts {
            let text = part.together().to_string();
            readable.push(simplify::simplify(&text, &self.vocabulary).map_err(&failure)?);
            derived.push(format!("({text})"));
        }
        let readable = simplify::sum(readable);
        let seed = key.bytes().fold(self.derived.len() as u64, |h, b| {
            h.wrapping_mul(31).wrapping_add(u64::from(b))
        });
        simplify::verify(&derived.join("+"), &readable, seed, &self.start).map_err(&failure)?;
        let text = readable.to_string();
        self.derived.push(Derived {
            key,
            description: description.into(),
            text: text.clone(),
            latex: self.names.latex(&readable),
        });
        Ok(text)
    }
}

/// Of two equivalent sets of right-hand sides, the readable one unless it
/// costs more than 10 % more operations after CSE than the derived one (the
/// emitted code should be what the snapshots show; the count is only a rough
/// model of time, e.g. it cannot see latency chains). Returns the last
/// stage's texts, both counts and the chosen one.
pub(crate) fn cheaper(
    derived: Vec<Vec<(String, String)>>,
    readable: Vec<Vec<(String, String)>>,
) -> Result<(Vec<String>, usize, usize, usize), DeriveError> {
    let count = |stages: &[Vec<(String, String)>]| {
        crate::emit::operation_count(stages).map_err(|e| e.in_function("(operation count)"))
    };
    let (before, after) = (count(&derived)?, count(&readable)?);
    let readable_chosen = 10 * after <= 11 * before;
    let chosen = if readable_chosen { readable } else { derived };
    let last = chosen.last().cloned().unwrap_or_default();
    Ok((
        last.into_iter().map(|(_, t)| t).collect(),
        before,
        after,
        if readable_chosen { after } else { before },
    ))
}

pub(crate) fn matrix_text(m: &[Vec<Atom>]) -> Vec<Vec<String>> {
    m.iter()
        .map(|row| row.iter().map(|a| a.to_string()).collect())
        .collect()
}
