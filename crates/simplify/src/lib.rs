//! Readable forms of derived expressions (build time, pure Rust): a crate
//! of its own, compiled optimised while the rest of the derivation is not
//! (docs/building.md), and tested directly (tests/simplify_forms.rs).
//!
//! Symbolica's `together()` returns one fraction N/D but treats sin x and
//! cos x as unrelated variables, so identities such as sin² + cos² = 1 and
//! the addition formulas are never applied: the double pendulum's V_vibr
//! came out as 600 characters of products of sin φ1, sin φ2, cos φ1, cos φ2.
//! This stage makes such expressions canonical and then short:
//!
//! 1. N and D are rewritten in the Fourier basis of the angles (every symbol
//!    found inside a sine or cosine, except the fast phase, which stays a
//!    plain factor so that mean values remain visible): products of sines and
//!    cosines become cos(k·φ), sin(k·φ) with integer k, canonical up to the
//!    sign of k. In this basis sin² + cos² = 1 and every addition formula hold
//!    by construction.
//! 2. The numeric and monomial content of N and D is cancelled and D gets a
//!    positive leading sign.
//! 3. Each of N and D is written in every form generated here (the Fourier
//!    form; half angles, cos 2u = 1 − 2 sin²u or 2 cos²u − 1; products of the
//!    single angles' sines and cosines with sin² or cos² eliminated), grouped
//!    by the key variables (momenta, velocities), then by trigonometric
//!    factors, then by parameters, and the shortest printed form is kept.
//! 4. The numerator is split by the degree in the key variables, so that a
//!    Hamiltonian reads as kinetic quadratic form + linear term + p-free part.
//!
//! Every result is checked against its input at random points by the caller
//! ([`verify`]); a disagreement fails the build naming the expression.

use mechlab_model::expr::{BinOp, EvalError, Expr, ParseError};
use std::collections::BTreeMap;

/// An exact rational number with a positive, reduced denominator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Q {
    n: i128,
    d: i128,
}

fn gcd(a: i128, b: i128) -> i128 {
    let (mut a, mut b) = (a.abs(), b.abs());
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a
}

impl Q {
    fn new(n: i128, d: i128) -> Q {
        assert!(d != 0, "zero denominator");
        if d == 1 {
            return Q { n, d };
        }
        let g = gcd(n, d).max(1) * d.signum();
        Q { n: n / g, d: d / g }
    }
    fn int(n: i128) -> Q {
        Q { n, d: 1 }
    }
    fn is_zero(self) -> bool {
        self.n == 0
    }
    fn add(self, o: Q) -> Q {
        if self.d == 1 && o.d == 1 {
            return Q::int(self.n + o.n);
        }
        Q::new(self.n * o.d + o.n * self.d, self.d * o.d)
    }
    fn mul(self, o: Q) -> Q {
        if self.d == 1 && o.d == 1 {
            return Q::int(self.n * o.n);
        }
        let (g1, g2) = (gcd(self.n, o.d).max(1), gcd(o.n, self.d).max(1));
        Q::new((self.n / g1) * (o.n / g2), (self.d / g2) * (o.d / g1))
    }
    fn neg(self) -> Q {
        Q {
            n: -self.n,
            d: self.d,
        }
    }
    fn inv(self) -> Q {
        Q::new(self.d, self.n)
    }
    fn parse(text: &str) -> Option<Q> {
        match text.split_once('.') {
            None => text.parse().ok().map(Q::int),
            Some((whole, frac)) => {
                let scale = 10i128.checked_pow(frac.len() as u32)?;
                let digits: i128 = format!("{whole}{frac}").parse().ok()?;
                Some(Q::new(digits, scale))
            }
        }
    }
}

/// Exponents per variable index (sparse, only nonzero), sorted by the
/// index: ordered as the map from index to exponent would be, and
/// compared and cloned as one vector.
#[derive(Clone, Debug, Default, PartialEq, Eq, PartialOrd, Ord)]
struct Monomial(Vec<(usize, i32)>);

impl Monomial {
    fn new() -> Monomial {
        Monomial(Vec::new())
    }
    fn iter(&self) -> impl Iterator<Item = (&usize, &i32)> + '_ {
        self.0.iter().map(|(v, e)| (v, e))
    }
    fn get(&self, v: &usize) -> Option<&i32> {
        self.0
            .binary_search_by_key(v, |(w, _)| *w)
            .ok()
            .map(|i| &self.0[i].1)
    }
}

impl FromIterator<(usize, i32)> for Monomial {
    /// Sorted by index, equal indices added, zero exponents dropped.
    fn from_iter<I: IntoIterator<Item = (usize, i32)>>(items: I) -> Monomial {
        let mut entries: Vec<(usize, i32)> = items.into_iter().collect();
        entries.sort_by_key(|(v, _)| *v);
        let mut merged: Vec<(usize, i32)> = Vec::with_capacity(entries.len());
        for (v, e) in entries {
            match merged.last_mut() {
                Some((w, f)) if *w == v => *f += e,
                _ => merged.push((v, e)),
            }
        }
        merged.retain(|(_, e)| *e != 0);
        Monomial(merged)
    }
}

impl<'a> IntoIterator for &'a Monomial {
    type Item = (&'a usize, &'a i32);
    type IntoIter = std::iter::Map<
        std::slice::Iter<'a, (usize, i32)>,
        fn(&'a (usize, i32)) -> (&'a usize, &'a i32),
    >;
    fn into_iter(self) -> Self::IntoIter {
        self.0.iter().map(|(v, e)| (v, e))
    }
}

fn mono_mul(a: &Monomial, b: &Monomial) -> Monomial {
    let (a, b) = (&a.0, &b.0);
    let mut m = Vec::with_capacity(a.len() + b.len());
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        match a[i].0.cmp(&b[j].0) {
            std::cmp::Ordering::Less => {
                m.push(a[i]);
                i += 1;
            }
            std::cmp::Ordering::Greater => {
                m.push(b[j]);
                j += 1;
            }
            std::cmp::Ordering::Equal => {
                let e = a[i].1 + b[j].1;
                if e != 0 {
                    m.push((a[i].0, e));
                }
                i += 1;
                j += 1;
            }
        }
    }
    m.extend_from_slice(&a[i..]);
    m.extend_from_slice(&b[j..]);
    Monomial(m)
}

/// cos(k·φ) or sin(k·φ); k is canonical: its first nonzero entry is positive,
/// and k = 0 only with the cosine (the constant 1).
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
struct Harmonic {
    sine: bool,
    k: Vec<i32>,
}

impl Harmonic {
    fn one(angles: usize) -> Harmonic {
        Harmonic {
            sine: false,
            k: vec![0; angles],
        }
    }
    fn is_one(&self) -> bool {
        !self.sine && self.k.iter().all(|&x| x == 0)
    }
    /// The canonical harmonic and the sign it carries, or None for sin(0) = 0.
    fn canonical(sine: bool, mut k: Vec<i32>) -> Option<(Harmonic, i128)> {
        match k.iter().find(|&&x| x != 0) {
            None if sine => None,
            None => Some((Harmonic { sine, k }, 1)),
            Some(&first) if first < 0 => {
                k.iter_mut().for_each(|x| *x = -*x);
                Some((Harmonic { sine, k }, if sine { -1 } else { 1 }))
            }
            Some(_) => Some((Harmonic { sine, k }, 1)),
        }
    }
    /// Product to sums: the harmonics of self·other with their factors.
    fn times(&self, other: &Harmonic) -> Vec<(Harmonic, Q)> {
        if self.is_one() {
            return vec![(other.clone(), Q::int(1))];
        }
        if other.is_one() {
            return vec![(self.clone(), Q::int(1))];
        }
        let sum: Vec<i32> = self.k.iter().zip(&other.k).map(|(a, b)| a + b).collect();
        let diff: Vec<i32> = self.k.iter().zip(&other.k).map(|(a, b)| a - b).collect();
        let half = Q::new(1, 2);
        // (sine of result?, which angle, sign) for the a−b and a+b parts.
        let parts: [(bool, &Vec<i32>, i128); 2] = match (self.sine, other.sine) {
            (false, false) => [(false, &diff, 1), (false, &sum, 1)],
            (true, true) => [(false, &diff, 1), (false, &sum, -1)],
            (true, false) => [(true, &sum, 1), (true, &diff, 1)],
            (false, true) => [(true, &sum, 1), (true, &diff, -1)],
        };
        parts
            .iter()
            .filter_map(|(sine, k, sign)| {
                Harmonic::canonical(*sine, (*k).clone())
                    .map(|(h, s)| (h, half.mul(Q::int(s * sign))))
            })
            .collect()
    }
}

/// A polynomial in variables times harmonics of the angles.
#[derive(Clone, Debug, PartialEq)]
struct Poly(BTreeMap<(Monomial, Harmonic), Q>);

impl Poly {
    fn zero() -> Poly {
        Poly(BTreeMap::new())
    }
    fn term(m: Monomial, h: Harmonic, c: Q) -> Poly {
        let mut p = Poly::zero();
        p.add_term(m, h, c);
        p
    }
    fn constant(c: Q, angles: usize) -> Poly {
        Poly::term(Monomial::new(), Harmonic::one(angles), c)
    }
    fn is_zero(&self) -> bool {
        self.0.is_empty()
    }
    fn add_term(&mut self, m: Monomial, h: Harmonic, c: Q) {
        accumulate(&mut self.0, (m, h), c);
    }
    /// The sum, the smaller added into the larger: a long sum read term
    /// by term stays linear in its length (a clone per term made the
    /// bicycle's Lagrangian quadratic).
    fn add(self, o: Poly) -> Poly {
        let (mut r, o) = match self.0.len() >= o.0.len() {
            true => (self, o),
            false => (o, self),
        };
        for ((m, h), c) in o.0 {
            r.add_term(m, h, c);
        }
        r
    }
    fn scale(&self, c: Q) -> Poly {
        Poly(self.0.iter().map(|(k, v)| (k.clone(), v.mul(c))).collect())
    }
    fn mul(&self, o: &Poly) -> Poly {
        let mut r = Poly::zero();
        for ((m1, h1), c1) in &self.0 {
            for ((m2, h2), c2) in &o.0 {
                let m = mono_mul(m1, m2);
                for (h, f) in h1.times(h2) {
                    r.add_term(m.clone(), h, c1.mul(*c2).mul(f));
                }
            }
        }
        r
    }
    fn pow(&self, k: u32, angles: usize) -> Poly {
        (0..k).fold(Poly::constant(Q::int(1), angles), |acc, _| acc.mul(self))
    }
    /// Numeric content (positive) and the monomial dividing every term.
    fn content(&self) -> (Q, Monomial) {
        let mut n = 0i128;
        let mut d = 1i128;
        let mut mono: Option<Monomial> = None;
        for ((m, _), c) in &self.0 {
            n = gcd(n, c.n);
            d = d / gcd(d, c.d) * c.d;
            mono = Some(match mono {
                None => m.clone(),
                Some(prev) => prev
                    .iter()
                    .filter_map(|(v, &e)| {
                        let f = m.get(v).copied().unwrap_or(0);
                        let low = if e.signum() == f.signum() {
                            e.signum() * e.abs().min(f.abs())
                        } else {
                            0
                        };
                        (low != 0).then_some((*v, low))
                    })
                    .collect(),
            });
        }
        (Q::new(n.max(1), d), mono.unwrap_or_default())
    }
}

/// Variables by index, and the angles.
struct Context {
    vars: Vec<String>,
    angles: Vec<String>,
    /// Variables that group the output (momenta, velocities).
    keys: Vec<String>,
}

impl Context {
    fn var(&mut self, name: &str) -> usize {
        match self.vars.iter().position(|v| v == name) {
            Some(i) => i,
            None => {
                self.vars.push(name.to_string());
                self.vars.len() - 1
            }
        }
    }
    fn var_poly(&mut self, name: &str) -> Poly {
        let i = self.var(name);
        Poly::term(
            [(i, 1)].into_iter().collect(),
            Harmonic::one(self.angles.len()),
            Q::int(1),
        )
    }
}

/// A fraction N/D of polynomials.
#[derive(Clone)]
struct Fraction {
    num: Poly,
    den: Poly,
}

fn as_integer(e: &Expr) -> Option<i128> {
    match e {
        Expr::Num(n) => n.parse().ok(),
        Expr::Neg(a) => as_integer(a).map(|x| -x),
        _ => None,
    }
}

/// The integer coefficients of a linear combination of angles, if `e` is one.
fn angle_combination(e: &Expr, angles: &[String]) -> Option<Vec<i32>> {
    let n = angles.len();
    match e {
        Expr::Sym(s) => {
            let i = angles.iter().position(|a| a == s)?;
            let mut k = vec![0; n];
            k[i] = 1;
            Some(k)
        }
        Expr::Neg(a) => Some(angle_combination(a, angles)?.iter().map(|x| -x).collect()),
        Expr::Bin(op @ (BinOp::Add | BinOp::Sub), a, b) => {
            let (x, y) = (angle_combination(a, angles)?, angle_combination(b, angles)?);
            let s = if *op == BinOp::Add { 1 } else { -1 };
            Some(x.iter().zip(&y).map(|(p, q)| p + s * q).collect())
        }
        Expr::Bin(BinOp::Mul, a, b) => {
            let (c, rest) = match (as_integer(a), as_integer(b)) {
                (Some(c), _) => (c, b),
                (_, Some(c)) => (c, a),
                _ => return None,
            };
            let k = angle_combination(rest, angles)?;
            Some(k.iter().map(|x| x * c as i32).collect())
        }
        _ => None,
    }
}

fn to_fraction(e: &Expr, cx: &mut Context) -> Fraction {
    let n = cx.angles.len();
    let one = || Poly::constant(Q::int(1), n);
    let whole = |p: Poly| Fraction { num: p, den: one() };
    match e {
        Expr::Num(text) => match Q::parse(text) {
            Some(q) => whole(Poly::constant(q, n)),
            None => whole(cx.var_poly(text)),
        },
        Expr::Sym(s) => whole(cx.var_poly(s)),
        Expr::Neg(a) => {
            let f = to_fraction(a, cx);
            Fraction {
                num: f.num.scale(Q::int(-1)),
                den: f.den,
            }
        }
        Expr::Bin(op, a, b) => {
            if *op == BinOp::Pow {
                if let Some(k) = as_integer(b) {
                    let f = to_fraction(a, cx);
                    let (num, den) = (
                        f.num.pow(k.unsigned_abs() as u32, n),
                        f.den.pow(k.unsigned_abs() as u32, n),
                    );
                    return if k >= 0 {
                        Fraction { num, den }
                    } else {
                        Fraction { num: den, den: num }
                    };
                }
                return whole(cx.var_poly(&e.to_string()));
            }
            let (x, y) = (to_fraction(a, cx), to_fraction(b, cx));
            match op {
                BinOp::Add | BinOp::Sub => {
                    let y_num = if *op == BinOp::Sub {
                        y.num.scale(Q::int(-1))
                    } else {
                        y.num
                    };
                    if x.den == y.den {
                        Fraction {
                            num: x.num.add(y_num),
                            den: x.den,
                        }
                    } else {
                        Fraction {
                            num: x.num.mul(&y.den).add(y_num.mul(&x.den)),
                            den: x.den.mul(&y.den),
                        }
                    }
                }
                BinOp::Mul => Fraction {
                    num: x.num.mul(&y.num),
                    den: x.den.mul(&y.den),
                },
                BinOp::Div => Fraction {
                    num: x.num.mul(&y.den),
                    den: x.den.mul(&y.num),
                },
                BinOp::Pow => unreachable!(),
            }
        }
        Expr::Call(name, args) if (name == "sin" || name == "cos") && args.len() == 1 => {
            match angle_combination(&args[0], &cx.angles) {
                Some(k) => match Harmonic::canonical(name == "sin", k) {
                    Some((h, sign)) => whole(Poly::term(Monomial::new(), h, Q::int(sign))),
                    None => whole(Poly::zero()),
                },
                None => whole(cx.var_poly(&e.to_string())),
            }
        }
        Expr::Call(..) => whole(cx.var_poly(&e.to_string())),
    }
}

/// Adds c to the coefficient of `key`, dropping it where the sum is zero;
/// one lookup of the key.
fn accumulate<K: Ord>(map: &mut BTreeMap<K, Q>, key: K, c: Q) {
    use std::collections::btree_map::Entry;
    match map.entry(key) {
        Entry::Occupied(mut entry) => {
            let value = entry.get().add(c);
            match value.is_zero() {
                true => drop(entry.remove()),
                false => *entry.get_mut() = value,
            }
        }
        Entry::Vacant(entry) => {
            if !c.is_zero() {
                entry.insert(c);
            }
        }
    }
}

/// A plain polynomial over (extended) variables, for printing.
type Plain = BTreeMap<Monomial, Q>;

fn plain_add(p: &mut Plain, m: Monomial, c: Q) {
    accumulate(p, m, c);
}

fn plain_mul(a: &Plain, b: &Plain) -> Plain {
    let mut r = Plain::new();
    for (m1, c1) in a {
        for (m2, c2) in b {
            plain_add(&mut r, mono_mul(m1, m2), c1.mul(*c2));
        }
    }
    r
}

fn plain_var(cx: &mut Context, name: &str) -> Plain {
    [([(cx.var(name), 1)].into_iter().collect(), Q::int(1))]
        .into_iter()
        .collect()
}

fn plain_const(c: Q) -> Plain {
    [(Monomial::new(), c)].into_iter().collect()
}

/// How a harmonic is written.
#[derive(Clone, Copy, PartialEq)]
enum Form {
    /// cos(k·φ), sin(k·φ).
    Fourier,
    /// Even harmonics through half angles, cos 2u = 1 − 2 sin²u.
    HalfSine,
    /// Even harmonics through half angles, cos 2u = 2 cos²u − 1.
    HalfCosine,
    /// Products of single-angle sines and cosines, sin² eliminated.
    ProductCosine,
    /// Products of single-angle sines and cosines, cos² eliminated.
    ProductSine,
}

const FORMS: [Form; 5] = [
    Form::Fourier,
    Form::HalfSine,
    Form::HalfCosine,
    Form::ProductCosine,
    Form::ProductSine,
];

fn angle_text(k: &[i32], angles: &[String]) -> String {
    let mut terms: Vec<Expr> = Vec::new();
    for (c, a) in k.iter().zip(angles) {
        let sym = Expr::Sym(a.clone());
        let t = match c.abs() {
            0 => continue,
            1 => sym,
            m => Expr::Bin(BinOp::Mul, Box::new(Expr::num(m as i64)), Box::new(sym)),
        };
        terms.push(if *c < 0 { Expr::Neg(Box::new(t)) } else { t });
    }
    Expr::sum(terms).to_string()
}

fn trig_var(cx: &mut Context, sine: bool, k: &[i32]) -> Plain {
    let name = format!(
        "{}({})",
        if sine { "sin" } else { "cos" },
        angle_text(k, &cx.angles)
    );
    plain_var(cx, &name)
}

/// One harmonic in the given form.
fn harmonic_plain(h: &Harmonic, form: Form, cx: &mut Context) -> Plain {
    if h.is_one() {
        return plain_const(Q::int(1));
    }
    let even = h.k.iter().all(|x| x % 2 == 0);
    match form {
        Form::HalfSine | Form::HalfCosine if even => {
            let half: Vec<i32> = h.k.iter().map(|x| x / 2).collect();
            let s = trig_var(cx, true, &half);
            let c = trig_var(cx, false, &half);
            if h.sine {
                plain_mul(&plain_mul(&s, &c), &plain_const(Q::int(2)))
            } else {
                let (u, sign) = if form == Form::HalfSine {
                    (s, -2)
                } else {
                    (c, 2)
                };
                let mut r = plain_mul(&plain_mul(&u, &u), &plain_const(Q::int(sign)));
                plain_add(&mut r, Monomial::new(), Q::int(-sign / 2));
                r
            }
        }
        Form::ProductCosine | Form::ProductSine => {
            // e^{i k·φ} = Π (cos φ_j + i sin φ_j)^{k_j}: real part cos, imaginary sin.
            let (mut re, mut im) = (plain_const(Q::int(1)), Plain::new());
            for (j, &kj) in h.k.iter().enumerate() {
                let mut unit = vec![0; h.k.len()];
                unit[j] = 1;
                let c = trig_var(cx, false, &unit);
                let s0 = trig_var(cx, true, &unit);
                let s = if kj < 0 {
                    plain_mul(&s0, &plain_const(Q::int(-1)))
                } else {
                    s0
                };
                for _ in 0..kj.abs() {
                    let new_re = plain_mul(&re, &c);
                    let mut minus = plain_mul(&im, &s);
                    minus.values_mut().for_each(|v| *v = v.neg());
                    let new_re = minus.into_iter().fold(new_re, |mut acc, (m, v)| {
                        plain_add(&mut acc, m, v);
                        acc
                    });
                    let new_im = plain_mul(&re, &s).into_iter().fold(
                        plain_mul(&im, &c),
                        |mut acc, (m, v)| {
                            plain_add(&mut acc, m, v);
                            acc
                        },
                    );
                    re = new_re;
                    im = new_im;
                }
            }
            let r = if h.sine { im } else { re };
            reduce_squares(&r, form == Form::ProductCosine, h.k.len(), cx)
        }
        _ => trig_var(cx, h.sine, &h.k),
    }
}

/// Eliminates sin² (keep_cosine) or cos² of every single angle with sin² + cos² = 1.
fn reduce_squares(p: &Plain, keep_cosine: bool, angles: usize, cx: &mut Context) -> Plain {
    let mut r = p.clone();
    for j in 0..angles {
        let mut unit = vec![0; angles];
        unit[j] = 1;
        let s = trig_var(cx, true, &unit);
        let c = trig_var(cx, false, &unit);
        let (drop, keep) = if keep_cosine { (s, c) } else { (c, s) };
        let drop_index = drop.keys().next().unwrap().0[0].0;
        // 1 − keep²
        let mut one_minus = plain_mul(&keep, &keep);
        one_minus.values_mut().for_each(|v| *v = v.neg());
        plain_add(&mut one_minus, Monomial::new(), Q::int(1));
        let mut out = Plain::new();
        for (m, c) in &r {
            let e = m.get(&drop_index).copied().unwrap_or(0);
            let odd = (e % 2 == 1).then_some((drop_index, 1));
            let rest: Monomial = m
                .iter()
                .filter(|(v, _)| **v != drop_index)
                .map(|(v, e)| (*v, *e))
                .chain(odd)
                .collect();
            let mut term: Plain = [(rest, *c)].into_iter().collect();
            for _ in 0..e / 2 {
                term = plain_mul(&term, &one_minus);
            }
            for (m, v) in term {
                plain_add(&mut out, m, v);
            }
        }
        r = out;
    }
    r
}

fn to_plain(p: &Poly, form: Form, cx: &mut Context) -> Plain {
    let mut out = Plain::new();
    for ((m, h), c) in &p.0 {
        let hp = harmonic_plain(h, form, cx);
        for (hm, hc) in hp {
            plain_add(&mut out, mono_mul(m, &hm), c.mul(hc));
        }
    }
    out
}

// ---------------------------------------------------------------- printing

/// a·b, kept left-associated so that products print without parentheses.
fn mul(a: Expr, b: Expr) -> Expr {
    match b {
        Expr::Bin(BinOp::Mul, b1, b2) => mul(mul(a, *b1), *b2),
        b => Expr::Bin(BinOp::Mul, Box::new(a), Box::new(b)),
    }
}

fn is_one(e: &Expr) -> bool {
    matches!(e, Expr::Num(n) if n == "1")
}

/// The product of the variables of a monomial (positive exponents only), or 1.
fn monomial_expr(m: &Monomial, cx: &Context) -> Expr {
    let mut factors: Vec<(&String, i32)> = m
        .iter()
        .filter(|(_, &e)| e > 0)
        .map(|(&v, &e)| (&cx.vars[v], e))
        .collect();
    // Parameters first, then trigonometric factors, as in a textbook.
    factors.sort_by_key(|(name, _)| (name.contains('('), name.as_str().to_owned()));
    factors
        .into_iter()
        .map(|(name, e)| {
            let base = Expr::parse(name).unwrap_or_else(|_| Expr::Sym(name.clone()));
            if e == 1 {
                base
            } else {
                Expr::Bin(BinOp::Pow, Box::new(base), Box::new(Expr::num(e as i64)))
            }
        })
        .reduce(mul)
        .unwrap_or_else(|| Expr::num(1))
}

/// c·x written as (n x)/d, with the sign returned separately.
fn scaled(c: Q, x: Expr) -> (bool, Expr) {
    let n = Expr::num(c.n.abs() as i64);
    let top = if c.n.abs() == 1 {
        x
    } else if is_one(&x) {
        n
    } else {
        mul(n, x)
    };
    let e = if c.d == 1 {
        top
    } else {
        Expr::Bin(BinOp::Div, Box::new(top), Box::new(Expr::num(c.d as i64)))
    };
    (c.n < 0, e)
}

fn signed_sum(terms: Vec<(bool, Expr)>) -> Expr {
    let mut terms = terms;
    // Start with a positive term when there is one.
    if let Some(i) = terms.iter().position(|(negative, _)| !negative) {
        let first = terms.remove(i);
        terms.insert(0, first);
    }
    Expr::sum(
        terms
            .into_iter()
            .map(|(neg, e)| if neg { Expr::Neg(Box::new(e)) } else { e })
            .collect(),
    )
}

/// Which group a variable belongs to when printing.
#[derive(Clone, Copy, PartialEq)]
enum Class {
    Key,
    Trig,
    Parameter,
}

fn class_of(name: &str, cx: &Context) -> Class {
    if cx.keys.iter().any(|k| k == name) {
        Class::Key
    } else if name.starts_with("sin(") || name.starts_with("cos(") {
        Class::Trig
    } else {
        Class::Parameter
    }
}

/// Numeric content (positive) and the monomial dividing every term.
fn plain_content(p: &Plain) -> (Q, Monomial) {
    Poly(
        p.iter()
            .map(|(m, c)| ((m.clone(), Harmonic::one(0)), *c))
            .collect(),
    )
    .content()
}

fn plain_divide(p: &Plain, c: Q, m: &Monomial) -> Plain {
    let inverse: Monomial = m.iter().map(|(v, e)| (*v, -e)).collect();
    p.iter()
        .map(|(mm, v)| (mono_mul(mm, &inverse), v.mul(c.inv())))
        .collect()
}

/// Prints a polynomial grouped by the classes in `order`: terms sharing their
/// part in the first class are collected, and so on; the last level factors
/// out its numeric and monomial content. Returns (negative, |expression|).
fn print_grouped(p: &Plain, order: &[Class], cx: &Context) -> (bool, Expr) {
    if p.is_empty() {
        return (false, Expr::num(0));
    }
    let Some((&first, rest)) = order.split_first() else {
        return print_with_content(p, cx);
    };
    if rest.is_empty() {
        return print_with_content(p, cx);
    }
    // The content of the whole level first, then its groups.
    let (content, content_mono) = plain_content(p);
    let p = &plain_divide(p, content, &content_mono);
    let mut groups: BTreeMap<Monomial, Plain> = BTreeMap::new();
    for (m, c) in p {
        let (inside, outside): (Vec<(usize, i32)>, Vec<(usize, i32)>) =
            m.0.iter()
                .partition(|(v, _)| class_of(&cx.vars[*v], cx) == first);
        let (inside, outside) = (Monomial(inside), Monomial(outside));
        plain_add(groups.entry(inside).or_default(), outside, *c);
    }
    let mut ordered: Vec<(Monomial, Plain)> = groups.into_iter().collect();
    // Keys by falling degree (p² before p), other factors by rising degree
    // (m1 + m2 sin²Δ), then by name.
    let direction = if first == Class::Key { -1 } else { 1 };
    ordered.sort_by_key(|(m, _)| {
        (
            direction * m.0.iter().map(|(_, e)| e).sum::<i32>(),
            monomial_expr(m, cx).to_string(),
        )
    });
    // A polynomial factor common to every group's coefficient is taken out:
    // m1 (m1 + m2) sin²φ1 + m2 (m1 + m2) sin²Δ = (m1 + m2)(m1 sin²φ1 + m2 sin²Δ).
    let reduced: Vec<(Q, Monomial, Plain)> = ordered
        .iter()
        .map(|(_, coefficient)| {
            let (c, m) = plain_content(coefficient);
            (c, m.clone(), plain_divide(coefficient, c, &m))
        })
        .collect();
    let common = &reduced[0].2;
    let shared = ordered.len() > 1
        && common.len() > 1
        && reduced
            .iter()
            .all(|(_, _, r)| r == common || *r == plain_negate(common));
    let (factor, negative, body) = if shared {
        let mut rest_poly = Plain::new();
        for ((m, _), (c, cm, r)) in ordered.iter().zip(&reduced) {
            let sign = if r == common { Q::int(1) } else { Q::int(-1) };
            plain_add(&mut rest_poly, mono_mul(m, cm), c.mul(sign));
        }
        let (negative_common, common_expr) = print_with_content(common, cx);
        let (negative_rest, rest_expr) = print_grouped(&rest_poly, order, cx);
        (
            Some(common_expr),
            negative_common != negative_rest,
            rest_expr,
        )
    } else {
        let terms: Vec<(bool, Expr)> = ordered
            .into_iter()
            .map(|(m, coefficient)| {
                let (negative, c) = print_grouped(&coefficient, rest, cx);
                let x = monomial_expr(&m, cx);
                let e = if is_one(&x) {
                    c
                } else if is_one(&c) {
                    x
                } else {
                    mul(c, x)
                };
                (negative, e)
            })
            .collect();
        if terms.len() == 1 {
            let (negative, e) = terms.into_iter().next().unwrap();
            (None, negative, e)
        } else {
            let negative = 2 * terms.iter().filter(|(n, _)| *n).count() > terms.len();
            let terms = terms.into_iter().map(|(n, e)| (n != negative, e)).collect();
            (None, negative, signed_sum(terms))
        }
    };
    let whole = [monomial_expr(&content_mono, cx)]
        .into_iter()
        .chain(factor)
        .chain([body])
        .filter(|x| !is_one(x))
        .reduce(mul)
        .unwrap_or_else(|| Expr::num(1));
    (negative, scaled(content, whole).1)
}

fn plain_negate(p: &Plain) -> Plain {
    p.iter().map(|(m, c)| (m.clone(), c.neg())).collect()
}

/// content · (remaining sum), the sign returned separately.
fn print_with_content(p: &Plain, cx: &Context) -> (bool, Expr) {
    let (c, m) = plain_content(p);
    let (negative, body) = print_reduced(&plain_divide(p, c, &m), cx);
    let mono = monomial_expr(&m, cx);
    let body = match (is_one(&mono), is_one(&body)) {
        (true, _) => body,
        (false, true) => mono,
        (false, false) => mul(mono, body),
    };
    (negative, scaled(c, body).1)
}

/// A content-free polynomial as a plain sum, sign flipped if mostly negative.
fn print_reduced(p: &Plain, cx: &Context) -> (bool, Expr) {
    let negative = 2 * p.values().filter(|c| c.n < 0).count() > p.len();
    let mut terms: Vec<(String, (bool, Expr))> = p
        .iter()
        .map(|(m, v)| {
            let v = if negative { v.neg() } else { *v };
            let x = monomial_expr(m, cx);
            (x.to_string(), scaled(v, x))
        })
        .collect();
    terms.sort_by(|a, b| a.0.cmp(&b.0));
    let terms: Vec<(bool, Expr)> = terms.into_iter().map(|(_, t)| t).collect();
    if terms.len() == 1 && !terms[0].0 && is_one(&terms[0].1) {
        return (negative, Expr::num(1));
    }
    (negative, signed_sum(terms))
}

/// A polynomial's shortest printed form: (content, monomial content,
/// negative, body) with body free of both contents.
fn shortest(p: &Poly, cx: &mut Context) -> (Q, Monomial, bool, Expr) {
    let orders: [&[Class]; 2] = [
        &[Class::Key, Class::Trig, Class::Parameter],
        &[Class::Key, Class::Parameter, Class::Trig],
    ];
    let mut best: Option<(usize, (Q, Monomial, bool, Expr))> = None;
    for form in FORMS {
        let plain = to_plain(p, form, cx);
        let (c, m) = plain_content(&plain);
        let reduced = plain_divide(&plain, c, &m);
        for order in orders {
            let (negative, e) = print_grouped(&reduced, order, cx);
            let whole = [monomial_expr(&m, cx), e.clone()]
                .into_iter()
                .filter(|x| !is_one(x))
                .reduce(mul)
                .unwrap_or_else(|| Expr::num(1));
            let len = scaled(c, whole).1.to_string().len();
            if best.as_ref().is_none_or(|(l, _)| len < *l) {
                best = Some((len, (c, m.clone(), negative, e)));
            }
        }
    }
    best.map(|(_, b)| b)
        .unwrap_or((Q::int(1), Monomial::new(), false, Expr::num(0)))
}

/// N/D with contents cancelled, each in its shortest form.
fn print_fraction(num: &Poly, den: &Poly, cx: &mut Context) -> Expr {
    if num.is_zero() {
        return Expr::num(0);
    }
    let one = Poly::constant(Q::int(1), cx.angles.len());
    let (cn, mn, negative_n, n_expr) = shortest(num, cx);
    let (cd, md, negative_d, d_expr) = if den == &one {
        (Q::int(1), Monomial::new(), false, Expr::num(1))
    } else {
        shortest(den, cx)
    };
    let (n_expr, d_expr) = if n_expr == d_expr {
        (Expr::num(1), Expr::num(1))
    } else {
        (n_expr, d_expr)
    };
    let c = cn.mul(cd.inv());
    let negative = negative_n != negative_d;
    // The monomial factor mn/md, exponents of either sign.
    let ratio = mono_mul(&mn, &md.iter().map(|(v, e)| (*v, -e)).collect());
    let top_mono = monomial_expr(&ratio, cx);
    let bottom_mono = monomial_expr(
        &ratio
            .iter()
            .filter(|(_, e)| **e < 0)
            .map(|(v, e)| (*v, -e))
            .collect(),
        cx,
    );
    let top = [Expr::num(c.n as i64), top_mono, n_expr]
        .into_iter()
        .filter(|e| !is_one(e))
        .reduce(mul)
        .unwrap_or_else(|| Expr::num(1));
    let bottom = [Expr::num(c.d as i64), bottom_mono, d_expr]
        .into_iter()
        .filter(|e| !is_one(e))
        .reduce(mul);
    let e = match bottom {
        None => top,
        Some(b) => Expr::Bin(BinOp::Div, Box::new(top), Box::new(b)),
    };
    if negative {
        Expr::Neg(Box::new(e))
    } else {
        e
    }
}

/// Symbols inside sines and cosines, except `phase`.
fn trig_symbols(e: &Expr, phase: Option<&str>, out: &mut Vec<String>) {
    match e {
        Expr::Call(name, args) if name == "sin" || name == "cos" => {
            for s in args[0].symbols() {
                if Some(s.as_str()) != phase && !out.contains(&s) {
                    out.push(s);
                }
            }
        }
        Expr::Call(_, args) => args.iter().for_each(|a| trig_symbols(a, phase, out)),
        Expr::Neg(a) => trig_symbols(a, phase, out),
        Expr::Bin(_, a, b) => {
            trig_symbols(a, phase, out);
            trig_symbols(b, phase, out);
        }
        Expr::Num(_) | Expr::Sym(_) => {}
    }
}

/// What the simplifier needs to know of a model's symbols.
pub struct Vocabulary {
    /// Variables the result is grouped by (momenta, velocities).
    pub keys: Vec<String>,
    /// The fast phase: its sine and cosine stay plain factors.
    pub phase: Option<String>,
    /// Angles written first in sums and differences (the coordinates).
    pub coordinates: Vec<String>,
}

/// The readable form of `text` (one of Symbolica's printed results): a sum
/// over the degrees in the key variables of reduced fractions, each in its
/// shortest form.
pub fn simplify(text: &str, vocabulary: &Vocabulary) -> Result<Expr, SimplifyError> {
    let e = Expr::parse_printed(text).map_err(|source| SimplifyError::Read {
        text: text.to_string(),
        source,
    })?;
    let mut angles = Vec::new();
    trig_symbols(&e, vocabulary.phase.as_deref(), &mut angles);
    let rank = |a: &String| {
        let position = vocabulary.coordinates.iter().position(|c| c == a);
        (position.unwrap_or(usize::MAX), a.clone())
    };
    angles.sort_by_key(rank);
    let keys = &vocabulary.keys;
    let mut cx = Context {
        vars: Vec::new(),
        angles,
        keys: keys.to_vec(),
    };
    let f = to_fraction(&e, &mut cx);
    let key_indices: Vec<usize> = keys
        .iter()
        .filter_map(|k| cx.vars.iter().position(|v| v == k))
        .collect();
    let mut by_degree: BTreeMap<i32, Poly> = BTreeMap::new();
    for ((m, h), c) in &f.num.0 {
        let degree: i32 = key_indices
            .iter()
            .map(|i| m.get(i).copied().unwrap_or(0))
            .sum();
        by_degree
            .entry(-degree)
            .or_insert_with(Poly::zero)
            .add_term(m.clone(), h.clone(), *c);
    }
    let parts: Vec<Expr> = by_degree
        .values()
        .map(|num| print_fraction(num, &f.den, &mut cx))
        .collect();
    Ok(sum(parts))
}

/// A sum of expressions with nested sums flattened (a + b − c, not a + (b − c)).
pub fn sum(parts: Vec<Expr>) -> Expr {
    Expr::sum(parts.iter().flat_map(|p| p.terms()).collect())
}

/// Why a readable form could not be made or checked.
#[derive(Debug, thiserror::Error)]
pub enum SimplifyError {
    #[error("cannot read '{text}': {source}")]
    Read { text: String, source: ParseError },
    #[error("cannot evaluate it at a random point: {0}")]
    Eval(#[from] EvalError),
    #[error("the simplified form differs from the derived one at point {point}: {derived} against {simplified}")]
    Differs {
        point: usize,
        derived: f64,
        simplified: f64,
    },
    #[error("the derived form is not finite at any of {tried} points, the last ones near the model's start")]
    Undefined { tried: usize },
}

/// Values of a model's symbols at its start (coordinates, velocities,
/// parameters at their defaults, phase and time), near which [`verify`]
/// samples where random points fall outside the model's domain.
pub type Start = BTreeMap<String, f64>;

/// Checks at six points that `simplified` equals `original`. The points
/// are random, each symbol in [0.3, 1.7]; a point where the derived form is
/// not finite lies outside the model's domain (a square root of a negative
/// number), and the points after it are drawn near `start`, each nearer
/// than the last, so that a model defined only near its start is checked
/// there. Where the derived form is finite, the simplified one must equal
/// it (where it is not, the simplified form may extend it).
pub fn verify(
    original: &str,
    simplified: &Expr,
    seed: u64,
    start: &Start,
) -> Result<(), SimplifyError> {
    let original = Expr::parse_printed(original).map_err(|source| SimplifyError::Read {
        text: original.to_string(),
        source,
    })?;
    let mut symbols = original.symbols();
    symbols.extend(simplified.symbols());
    let mut state = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407)
        | 1;
    let (mut checked, mut tried) = (0, 0);
    // None: random points; Some(spread): near the start.
    let mut near_start: Option<f64> = None;
    while checked < 6 {
        let values: BTreeMap<String, f64> = symbols
            .iter()
            .map(|s| {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                let u = (state >> 11) as f64 / (1u64 << 53) as f64;
                let value = match (near_start, start.get(s)) {
                    (Some(spread), Some(&c)) => {
                        c + spread * (2.0 * u - 1.0) * (0.1 + 0.1 * c.abs())
                    }
                    _ => 0.3 + 1.4 * u,
                };
                (s.clone(), value)
            })
            .collect();
        tried += 1;
        let env = |s: &str| values.get(s).copied();
        let a = original.eval(&env)?;
        if !a.is_finite() {
            if tried == 64 {
                return Err(SimplifyError::Undefined { tried });
            }
            near_start = Some(near_start.map_or(1.0, |spread| spread / 2.0));
            continue;
        }
        let b = simplified.eval(&env)?;
        if !((a - b).abs() <= 1e-9 * (1.0 + a.abs().max(b.abs()))) {
            return Err(SimplifyError::Differs {
                point: checked,
                derived: a,
                simplified: b,
            });
        }
        checked += 1;
    }
    Ok(())
}
