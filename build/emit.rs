//! Rust code from derived expressions: common subexpression elimination.
//!
//! Each generated function evaluates a list of outputs. The outputs are parsed
//! (Symbolica's printed text) into [`Expr`] trees, merged into one DAG with
//! hash-consing, and every shared, non-trivial node becomes a `let` binding.
//! Integer powers become products or `powi`, x^(1/2) becomes `sqrt`, and
//! sin/cos of one argument share a `sin_cos` call. Evaluation may be in stages:
//! the values of an earlier stage (e.g. the velocities) are plain variables of
//! the next.

use crate::model::expr::{BinOp, Expr};
use std::collections::HashMap;

/// One operation of the DAG; children are indices of earlier nodes.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Node {
    Lit(String),
    Var(String),
    Neg(usize),
    Add(usize, usize),
    Sub(usize, usize),
    Mul(usize, usize),
    Div(usize, usize),
    Powi(usize, i32),
    Sqrt(usize),
    Powf(usize, usize),
    Call(&'static str, usize),
}

/// Builds the DAG of one function body.
#[derive(Default)]
pub struct Emitter {
    nodes: Vec<Node>,
    index: HashMap<Node, usize>,
    /// Lines already emitted (earlier stages).
    lines: Vec<String>,
    /// Nodes already bound to a name.
    bound: HashMap<usize, String>,
    counter: usize,
    /// Named outputs (root nodes) of each stage.
    stages: Vec<Vec<(String, usize)>>,
    /// Keep sin/cos of an angle combination (φ1 − φ2) as one call instead of
    /// products of each angle's sin and cos: cheaper for Taylor
    /// recurrences, where a product costs as much as a sin/cos pair.
    pub whole_angles: bool,
}

fn literal(value: f64) -> String {
    let s = format!("{value:?}");
    if s.contains('.') || s.contains('e') || s.contains("inf") || s.contains("NaN") {
        s
    } else {
        format!("{s}.0")
    }
}

fn as_number(e: &Expr) -> Option<f64> {
    match e {
        Expr::Num(n) => n.parse().ok(),
        Expr::Neg(a) => as_number(a).map(|x| -x),
        Expr::Bin(BinOp::Div, a, b) => Some(as_number(a)? / as_number(b)?),
        Expr::Bin(BinOp::Mul, a, b) => Some(as_number(a)? * as_number(b)?),
        _ => None,
    }
}

/// The angles and integer coefficients of a linear combination such as
/// `2*phi1-phi2`, if `e` is one.
fn angle_combination(e: &Expr) -> Option<Vec<(String, i64)>> {
    fn collect(e: &Expr, sign: i64, out: &mut Vec<(String, i64)>) -> Option<()> {
        match e {
            Expr::Sym(s) => {
                match out.iter_mut().find(|(a, _)| a == s) {
                    Some(entry) => entry.1 += sign,
                    None => out.push((s.clone(), sign)),
                }
                Some(())
            }
            Expr::Neg(a) => collect(a, -sign, out),
            Expr::Bin(BinOp::Add, a, b) => {
                collect(a, sign, out)?;
                collect(b, sign, out)
            }
            Expr::Bin(BinOp::Sub, a, b) => {
                collect(a, sign, out)?;
                collect(b, -sign, out)
            }
            Expr::Bin(BinOp::Mul, a, b) => match (as_number(a), as_number(b)) {
                (Some(k), _) if k == k.round() && k.abs() <= 8.0 => {
                    collect(b, sign * k as i64, out)
                }
                (_, Some(k)) if k == k.round() && k.abs() <= 8.0 => {
                    collect(a, sign * k as i64, out)
                }
                _ => None,
            },
            _ => None,
        }
    }
    let mut out = Vec::new();
    collect(e, 1, &mut out)?;
    out.retain(|(_, k)| *k != 0);
    (!out.is_empty()).then_some(out)
}

impl Emitter {
    fn intern(&mut self, node: Node) -> usize {
        if let Some(&i) = self.index.get(&node) {
            return i;
        }
        self.nodes.push(node.clone());
        self.index.insert(node, self.nodes.len() - 1);
        self.nodes.len() - 1
    }

    fn build(&mut self, e: &Expr) -> Result<usize, String> {
        if let Some(x) = as_number(e) {
            return Ok(self.intern(Node::Lit(literal(x))));
        }
        Ok(match e {
            Expr::Num(_) => unreachable!("numbers are folded above"),
            Expr::Sym(s) => self.intern(Node::Var(s.clone())),
            Expr::Neg(a) => {
                let a = self.build(a)?;
                self.intern(Node::Neg(a))
            }
            Expr::Bin(BinOp::Pow, base, exponent) => {
                let b = self.build(base)?;
                match as_number(exponent) {
                    Some(k) if k == k.round() && k.abs() <= 64.0 => {
                        self.intern(Node::Powi(b, k as i32))
                    }
                    Some(k) if k == 0.5 => self.intern(Node::Sqrt(b)),
                    Some(k) if k == -0.5 => {
                        let s = self.intern(Node::Sqrt(b));
                        let one = self.intern(Node::Lit("1.0".into()));
                        self.intern(Node::Div(one, s))
                    }
                    _ => {
                        let x = self.build(exponent)?;
                        self.intern(Node::Powf(b, x))
                    }
                }
            }
            Expr::Bin(op, a, b) => {
                let (a, b) = (self.build(a)?, self.build(b)?);
                self.intern(match op {
                    BinOp::Add => Node::Add(a, b),
                    BinOp::Sub => Node::Sub(a, b),
                    BinOp::Mul => Node::Mul(a, b),
                    BinOp::Div => Node::Div(a, b),
                    BinOp::Pow => unreachable!(),
                })
            }
            Expr::Call(name, args) if matches!(name.as_str(), "sin" | "cos") => {
                match angle_combination(&args[0]) {
                    Some(k) if !self.whole_angles && (k.len() > 1 || k[0].1.abs() > 1) => {
                        let (c, s) = self.sin_cos_of_combination(&k);
                        if name == "sin" {
                            s
                        } else {
                            c
                        }
                    }
                    _ => {
                        let a = self.build(&args[0])?;
                        self.intern(Node::Call(if name == "sin" { "sin" } else { "cos" }, a))
                    }
                }
            }
            Expr::Call(name, args) => {
                let f: &'static str = match name.as_str() {
                    "sin" => "sin",
                    "cos" => "cos",
                    "tan" => "tan",
                    "exp" => "exp",
                    "log" => "ln",
                    "sqrt" => "sqrt",
                    other => return Err(format!("cannot emit function '{other}'")),
                };
                let a = self.build(&args[0])?;
                self.intern(Node::Call(f, a))
            }
        })
    }

    /// cos and sin of Σ k_j φ_j from the sin_cos of each φ_j by complex
    /// multiplication: one transcendental pair per angle, shared by every
    /// combination (sin(φ1 − φ2), cos(2φ1 − φ2), ...) in the function.
    fn sin_cos_of_combination(&mut self, k: &[(String, i64)]) -> (usize, usize) {
        let mut acc: Option<(usize, usize)> = None;
        for (angle, coefficient) in k {
            let v = self.intern(Node::Var(angle.clone()));
            let c1 = self.intern(Node::Call("cos", v));
            let s1 = self.intern(Node::Call("sin", v));
            let mut power = (c1, s1);
            for _ in 1..coefficient.unsigned_abs() {
                power = self.complex_product(power, (c1, s1));
            }
            if *coefficient < 0 {
                power = (power.0, self.intern(Node::Neg(power.1)));
            }
            acc = Some(match acc {
                None => power,
                Some(a) => self.complex_product(a, power),
            });
        }
        acc.expect("a combination has at least one angle")
    }

    /// (cos a, sin a)·(cos b, sin b) = (cos(a + b), sin(a + b)).
    fn complex_product(&mut self, a: (usize, usize), b: (usize, usize)) -> (usize, usize) {
        let cc = self.intern(Node::Mul(a.0, b.0));
        let ss = self.intern(Node::Mul(a.1, b.1));
        let sc = self.intern(Node::Mul(a.1, b.0));
        let cs = self.intern(Node::Mul(a.0, b.1));
        (
            self.intern(Node::Sub(cc, ss)),
            self.intern(Node::Add(sc, cs)),
        )
    }

    fn children(node: &Node) -> Vec<usize> {
        match node {
            Node::Lit(_) | Node::Var(_) => vec![],
            Node::Neg(a) | Node::Powi(a, _) | Node::Sqrt(a) | Node::Call(_, a) => vec![*a],
            Node::Add(a, b)
            | Node::Sub(a, b)
            | Node::Mul(a, b)
            | Node::Div(a, b)
            | Node::Powf(a, b) => vec![*a, *b],
        }
    }

    fn name_for(&mut self, i: usize) -> String {
        let readable = match &self.nodes[i] {
            Node::Call(f, a) => match &self.nodes[*a] {
                Node::Var(v) => Some(format!("{f}_{v}")),
                _ => None,
            },
            Node::Powi(a, 2) => match &self.nodes[*a] {
                Node::Var(v) => Some(format!("{v}_sq")),
                _ => None,
            },
            _ => None,
        };
        let name = match readable {
            Some(r) if !self.bound.values().any(|b| *b == r) => r,
            _ => {
                self.counter += 1;
                format!("x{}", self.counter)
            }
        };
        format!("cse_{name}")
    }

    /// Rust text of node `i`, inlining unbound children.
    fn text(&self, i: usize) -> String {
        if let Some(name) = self.bound.get(&i) {
            return name.clone();
        }
        let t = |j: usize| self.text(j);
        let atom = |j: usize| {
            let s = self.text(j);
            if self.bound.contains_key(&j)
                || matches!(self.nodes[j], Node::Var(_) | Node::Call(..) | Node::Sqrt(_))
            {
                s
            } else if let Node::Lit(l) = &self.nodes[j] {
                if l.starts_with('-') {
                    format!("({s})")
                } else {
                    s
                }
            } else {
                format!("({s})")
            }
        };
        match &self.nodes[i] {
            Node::Lit(l) => l.clone(),
            Node::Var(v) => v.clone(),
            Node::Neg(a) => format!("-{}", atom(*a)),
            Node::Add(a, b) => format!("{} + {}", t(*a), t(*b)),
            Node::Sub(a, b) => {
                let right = match self.nodes[*b] {
                    Node::Add(..) | Node::Sub(..) if !self.bound.contains_key(b) => {
                        format!("({})", t(*b))
                    }
                    _ => t(*b),
                };
                format!("{} - {}", t(*a), right)
            }
            Node::Mul(a, b) => format!("{} * {}", self.factor(*a), self.factor(*b)),
            Node::Div(a, b) => format!("{} / {}", self.factor(*a), atom(*b)),
            Node::Powi(a, 1) => t(*a),
            Node::Powi(a, 2)
                if self.bound.contains_key(a) || matches!(self.nodes[*a], Node::Var(_)) =>
            {
                format!("{} * {}", atom(*a), atom(*a))
            }
            Node::Powi(a, -1) => format!("1.0 / {}", atom(*a)),
            Node::Powi(a, k) => format!("{}.powi({k})", atom(*a)),
            Node::Sqrt(a) => format!("{}.sqrt()", atom(*a)),
            Node::Powf(a, b) => format!("{}.powf({})", atom(*a), t(*b)),
            Node::Call(f, a) => format!("{}.{f}()", atom(*a)),
        }
    }

    /// A factor of a product: sums are parenthesised, products and quotients are not.
    fn factor(&self, j: usize) -> String {
        let s = self.text(j);
        if self.bound.contains_key(&j) {
            return s;
        }
        match &self.nodes[j] {
            Node::Add(..) | Node::Sub(..) | Node::Neg(_) => format!("({s})"),
            Node::Lit(l) if l.starts_with('-') => format!("({s})"),
            _ => s,
        }
    }

    /// Adds a stage: named outputs evaluated after the earlier stages, whose
    /// names later stages may use as variables.
    pub fn stage(&mut self, outputs: &[(String, String)]) -> Result<(), String> {
        let mut stage = Vec::new();
        for (name, text) in outputs {
            let e = Expr::parse(text).map_err(|err| format!("cannot read '{text}': {err}"))?;
            stage.push((name.clone(), self.build(&e)?));
        }
        self.stages.push(stage);
        Ok(())
    }

    /// Emits every stage: shared nodes (counted over all stages) become `let`
    /// bindings at the first stage that needs them, outputs are bound last.
    pub fn finish(mut self) -> Vec<String> {
        let mut uses = vec![0usize; self.nodes.len()];
        let mut seen = vec![false; self.nodes.len()];
        let mut stack: Vec<usize> = self.stages.iter().flatten().map(|(_, r)| *r).collect();
        for &(_, r) in self.stages.iter().flatten() {
            uses[r] += 1;
        }
        while let Some(i) = stack.pop() {
            if seen[i] {
                continue;
            }
            seen[i] = true;
            for c in Self::children(&self.nodes[i]) {
                uses[c] += 1;
                stack.push(c);
            }
        }
        let stages = std::mem::take(&mut self.stages);
        for stage in &stages {
            let mut reachable = vec![false; self.nodes.len()];
            let mut stack: Vec<usize> = stage.iter().map(|(_, r)| *r).collect();
            while let Some(i) = stack.pop() {
                if reachable[i] || self.bound.contains_key(&i) {
                    continue;
                }
                reachable[i] = true;
                stack.extend(Self::children(&self.nodes[i]));
            }
            let roots: Vec<usize> = stage.iter().map(|(_, r)| *r).collect();
            for i in 0..self.nodes.len() {
                if !reachable[i] || self.bound.contains_key(&i) || roots.contains(&i) {
                    continue;
                }
                let trivial = matches!(
                    self.nodes[i],
                    Node::Lit(_) | Node::Var(_) | Node::Neg(_) | Node::Powi(_, 1)
                );
                if uses[i] > 1 && !trivial {
                    self.bind(i, &reachable);
                }
            }
            for (name, root) in stage {
                let value = self.text(*root);
                self.lines.push(format!("let {name} = {value};"));
                self.bound.insert(*root, name.clone());
            }
        }
        self.lines
    }

    /// Binds node `i` to a new name; sin and cos of one argument share `sin_cos`.
    fn bind(&mut self, i: usize, reachable: &[bool]) {
        if self.bound.contains_key(&i) {
            return;
        }
        if let Node::Call(f @ ("sin" | "cos"), a) = self.nodes[i] {
            let partner = if f == "sin" { "cos" } else { "sin" };
            if let Some(&j) = self.index.get(&Node::Call(partner, a)) {
                if reachable[j] && !self.bound.contains_key(&j) {
                    let (s, c) = if f == "sin" { (i, j) } else { (j, i) };
                    let (sn, cn) = (self.name_for(s), self.name_for(c));
                    let arg = self.text(a);
                    let arg =
                        if self.bound.contains_key(&a) || matches!(self.nodes[a], Node::Var(_)) {
                            arg
                        } else {
                            format!("({arg})")
                        };
                    self.lines
                        .push(format!("let ({sn}, {cn}) = {arg}.sin_cos();"));
                    self.bound.insert(s, sn);
                    self.bound.insert(c, cn);
                    return;
                }
            }
        }
        let name = self.name_for(i);
        let value = self.text(i);
        self.lines.push(format!("let {name} = {value};"));
        self.bound.insert(i, name);
    }
}

/// The DAG of a function: nodes in evaluation order (children before
/// parents) and the named outputs of each stage. `build/taylor.rs` turns it
/// into Taylor-coefficient recurrences.
pub struct Dag {
    pub nodes: Vec<Node>,
    pub stages: Vec<Vec<(String, usize)>>,
}

impl Emitter {
    /// The DAG built so far, instead of Rust text.
    pub fn into_dag(self) -> Dag {
        Dag {
            nodes: self.nodes,
            stages: self.stages,
        }
    }
}

/// Cost of the DAG of `stages` in arithmetic operations (every node but
/// literals and variables; transcendental calls weighted): the measure by
/// which a readable form and a derived form of the same right-hand side are
/// compared.
pub fn operation_count(stages: &[Vec<(String, String)>]) -> Result<usize, String> {
    let mut emitter = Emitter::default();
    for stage in stages {
        emitter.stage(stage)?;
    }
    Ok(emitter
        .nodes
        .iter()
        .map(|node| match node {
            Node::Lit(_) | Node::Var(_) => 0,
            // A transcendental call costs about as much as 20 arithmetic
            // operations; a sin and cos of one argument share one `sin_cos`.
            Node::Call("cos", a) if emitter.index.contains_key(&Node::Call("sin", *a)) => 0,
            Node::Call(..) | Node::Sqrt(_) | Node::Powf(..) => 20,
            // A division takes several multiplications' time; a negation is
            // folded into the neighbouring addition.
            Node::Div(..) => 4,
            Node::Neg(_) => 0,
            // x^k by repeated squaring.
            Node::Powi(_, k) => {
                let k = k.unsigned_abs();
                (32 - k.leading_zeros() + k.count_ones()).saturating_sub(2) as usize + 1
            }
            _ => 1,
        })
        .sum())
}
