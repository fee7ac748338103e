//! Tangent recurrences in Jacobian form, the alternative to forward mode.
//!
//! Forward mode gives every node u its tangent δu, a series per tangent
//! column: δ(a·b) = δa·b + a·δb costs two Cauchy sums per column, and a
//! chain such as A·cos q·sin θ·δq multiplies δq by each factor in turn.
//! Here δu is kept as a sum Σ c_j·δx_j over atoms δx_j with coefficients
//! c_j that depend on the solution only: the chain becomes one product of
//! δq with c = A·cos q·sin θ, a node the solution often has already, and
//! the coefficients are computed once per step, whatever the number of
//! columns. Each rate's tangent δf_i is an atom too, once built, for the
//! rates that use f_i (a velocity inside a momentum's rate): its terms
//! are not expanded again. The derivation builds both forms and keeps the
//! one whose recurrences cost less (see [`cost`]).

use super::{Class, Lowering, Op};
use std::collections::HashMap;

/// One term c·atom of a tangent; `coefficient` None is 1.
#[derive(Clone, Copy, Debug)]
struct Term {
    atom: usize,
    coefficient: Option<usize>,
    negative: bool,
}

/// A tangent as a sum of terms over distinct atoms.
type Expansion = Vec<Term>;

/// Builds the tangent rates of the state's rates `roots` (one tangent
/// vector, state components dim + i) in Jacobian form; None where a node
/// has no rule here (the linear solves of mass matrices: forward mode
/// solves once per column, this form would solve once per atom).
pub(super) fn tangent_roots(
    lowering: &mut Lowering,
    dim: usize,
    roots: &[usize],
) -> Option<Vec<usize>> {
    let mut builder = Builder {
        lowering,
        dim,
        roots,
        built: vec![None; roots.len()],
        memo: HashMap::new(),
    };
    (0..roots.len()).map(|i| builder.root(i)).collect()
}

struct Builder<'l, 'a, 'r> {
    lowering: &'l mut Lowering<'a>,
    dim: usize,
    roots: &'r [usize],
    /// The tangent node of each rate, once built.
    built: Vec<Option<usize>>,
    memo: HashMap<usize, Option<Expansion>>,
}

impl Builder<'_, '_, '_> {
    /// The tangent node of rate i, δf_i = Σ c_j·δx_j.
    fn root(&mut self, i: usize) -> Option<usize> {
        if let Some(node) = self.built[i] {
            return Some(node);
        }
        let expansion = self.expand_op(self.roots[i])?;
        let node = self.combine(&expansion);
        self.built[i] = Some(node);
        Some(node)
    }

    /// The expansion of node k as a child: a rate's own tangent where k is
    /// a rate (one atom), else its terms.
    fn expand(&mut self, k: usize) -> Option<Expansion> {
        if self.lowering.classes[k] == Class::Constant {
            return Some(Vec::new());
        }
        if let Some(i) = self.roots.iter().position(|&r| r == k) {
            let atom = self.root(i)?;
            return Some(vec![Term {
                atom,
                coefficient: None,
                negative: false,
            }]);
        }
        if let Some(e) = self.memo.get(&k) {
            return e.clone();
        }
        let e = self.expand_op(k);
        self.memo.insert(k, e.clone());
        e
    }

    /// The expansion of node k from its operation.
    fn expand_op(&mut self, k: usize) -> Option<Expansion> {
        if self.lowering.classes[k] == Class::Constant {
            return Some(Vec::new());
        }
        let atom = |atom| {
            vec![Term {
                atom,
                coefficient: None,
                negative: false,
            }]
        };
        Some(match self.lowering.ops[k].clone() {
            Op::State(i) if i < self.dim => atom(self.lowering.intern(Op::State(self.dim + i))),
            Op::State(_) | Op::Literal(_) | Op::Parameter(_) | Op::Time | Op::Phase(_) => {
                Vec::new()
            }
            Op::Solution { .. } => return None,
            Op::Neg(a) => negate(self.expand(a)?),
            Op::Add(a, b) | Op::Sub(a, b) => {
                let subtract = matches!(self.lowering.ops[k], Op::Sub(..));
                let (ea, eb) = (self.expand(a)?, self.expand(b)?);
                self.add(ea, eb, subtract)
            }
            Op::Mul(a, b) => {
                let (ea, eb) = (self.expand(a)?, self.expand(b)?);
                let (ea, eb) = (self.scale(ea, b), self.scale(eb, a));
                self.add(ea, eb, false)
            }
            Op::Div(a, b) => {
                // δ(a/b) = (δa − (a/b)·δb)/b.
                let (ea, eb) = (self.expand(a)?, self.expand(b)?);
                let eb = self.scale(eb, k);
                let numerator = self.add(ea, eb, true);
                self.divide(numerator, b)
            }
            Op::Square(a) => {
                let two = self.lowering.literal("2.0");
                let slope = self.multiply(two, a);
                let ea = self.expand(a)?;
                self.scale(ea, slope)
            }
            Op::Sqrt(a) => {
                let two = self.lowering.literal("2.0");
                let twice = self.multiply(two, k);
                let ea = self.expand(a)?;
                self.divide(ea, twice)
            }
            Op::Power(a, alpha) => {
                let Op::Literal(value) = &self.lowering.ops[alpha] else {
                    unreachable!("powers have literal exponents")
                };
                let value: f64 = value.parse().expect("a literal is a number");
                let lowered = self.lowering.literal(&format!("{:?}", value - 1.0));
                let power = self.lowering.intern(Op::Power(a, lowered));
                let slope = self.multiply(alpha, power);
                let ea = self.expand(a)?;
                self.scale(ea, slope)
            }
            Op::Exp(a) => {
                let ea = self.expand(a)?;
                self.scale(ea, k)
            }
            Op::Ln(a) => {
                let ea = self.expand(a)?;
                self.divide(ea, a)
            }
            Op::Sin(a) => {
                let cos = self.lowering.intern(Op::Cos(a));
                let ea = self.expand(a)?;
                self.scale(ea, cos)
            }
            Op::Cos(a) => {
                let sin = self.lowering.intern(Op::Sin(a));
                let ea = self.expand(a)?;
                negate(self.scale(ea, sin))
            }
        })
    }

    /// a·b, the node the lowering has already if it has b·a.
    fn multiply(&mut self, a: usize, b: usize) -> usize {
        let l = &mut *self.lowering;
        if a == b {
            return l.intern(Op::Square(a));
        }
        match l.index.get(&Op::Mul(b, a)) {
            Some(&k) => k,
            None => l.intern(Op::Mul(a, b)),
        }
    }

    /// Every coefficient times `factor`.
    fn scale(&mut self, e: Expansion, factor: usize) -> Expansion {
        e.into_iter()
            .map(|t| Term {
                coefficient: Some(match t.coefficient {
                    None => factor,
                    Some(c) => self.multiply(c, factor),
                }),
                ..t
            })
            .collect()
    }

    /// Every coefficient over `divisor`.
    fn divide(&mut self, e: Expansion, divisor: usize) -> Expansion {
        e.into_iter()
            .map(|t| {
                let l = &mut *self.lowering;
                let numerator = t.coefficient.unwrap_or_else(|| l.literal("1.0"));
                Term {
                    coefficient: Some(l.intern(Op::Div(numerator, divisor))),
                    ..t
                }
            })
            .collect()
    }

    /// a ± b, the terms of a shared atom merged.
    fn add(&mut self, a: Expansion, b: Expansion, subtract: bool) -> Expansion {
        let mut sum = a;
        for mut t in b {
            t.negative ^= subtract;
            match sum.iter().position(|s| s.atom == t.atom) {
                None => sum.push(t),
                Some(j) => {
                    let s = sum[j];
                    let l = &mut *self.lowering;
                    let value =
                        |c: Option<usize>, l: &mut Lowering| c.unwrap_or_else(|| l.literal("1.0"));
                    let (x, y) = (value(s.coefficient, l), value(t.coefficient, l));
                    // ±x ± y as a node and a sign.
                    let (node, negative) = match (s.negative, t.negative) {
                        (false, false) => (l.intern(Op::Add(x, y)), false),
                        (false, true) => (l.intern(Op::Sub(x, y)), false),
                        (true, false) => (l.intern(Op::Sub(y, x)), false),
                        (true, true) => (l.intern(Op::Add(x, y)), true),
                    };
                    sum[j] = Term {
                        atom: s.atom,
                        coefficient: Some(node),
                        negative,
                    };
                }
            }
        }
        sum
    }

    /// Σ ±c·atom as one node (0 for no terms).
    fn combine(&mut self, e: &Expansion) -> usize {
        let mut total: Option<(usize, bool)> = None;
        for t in e {
            let product = match t.coefficient {
                None => t.atom,
                Some(c) => self.multiply(c, t.atom),
            };
            let l = &mut *self.lowering;
            total = Some(match total {
                None => (product, t.negative),
                Some((acc, false)) if t.negative => (l.intern(Op::Sub(acc, product)), false),
                Some((acc, false)) => (l.intern(Op::Add(acc, product)), false),
                Some((acc, true)) if t.negative => (l.intern(Op::Add(acc, product)), true),
                Some((acc, true)) => (l.intern(Op::Sub(product, acc)), false),
            });
        }
        let l = &mut *self.lowering;
        match total {
            None => l.literal("0.0"),
            Some((node, false)) => node,
            Some((node, true)) => l.intern(Op::Neg(node)),
        }
    }
}

fn negate(e: Expansion) -> Expansion {
    e.into_iter()
        .map(|t| Term {
            negative: !t.negative,
            ..t
        })
        .collect()
}

/// The recurrences' work per order for the nodes in `needed`, one tangent
/// column, in Cauchy sums of the order's length: a product of two series
/// 1, a square or square root ½, a quotient 1, sin and cos 1 each, exp,
/// ln and powers 1, a solve its rows², linear steps (sums, negations,
/// products with constants) 0.1 (a pass over a vector each).
pub(super) fn cost(lowering: &Lowering, needed: &[bool]) -> f64 {
    let series = |k: usize| lowering.classes[k] == Class::Series;
    let mut total = 0.0;
    for (k, op) in lowering.ops.iter().enumerate() {
        if !needed[k] || lowering.classes[k] == Class::Constant {
            continue;
        }
        total += match *op {
            Op::Mul(a, b) if series(a) && series(b) => 1.0,
            Op::Div(_, b) if series(b) => 1.0,
            Op::Square(_) | Op::Sqrt(_) => 0.5,
            Op::Sin(_) | Op::Cos(_) | Op::Exp(_) | Op::Ln(_) | Op::Power(..) => 1.0,
            Op::Solution { solve, .. } => lowering.solves[solve].matrix.len() as f64,
            _ => 0.1,
        };
    }
    total
}
