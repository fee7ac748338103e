//! Rust code from derived expressions: common subexpression elimination.
//!
//! Each generated function evaluates a list of outputs. The outputs are parsed
//! (Symbolica's printed text) into [`Expr`] trees, merged into one DAG with
//! hash-consing, and every shared, non-trivial node becomes a `let` binding.
//! Integer powers become products or `powi`, x^(1/2) becomes `sqrt`, and
//! sin/cos of one argument share a `sin_cos` call. Evaluation may be in stages:
//! the values of an earlier stage (e.g. the velocities) are plain variables of
//! the next.

use crate::error::EmitError;
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
    /// Row `row` of column `column` of the solution X of A X = R, for the
    /// linear system `Emitter::solves[solve]` (A symmetric positive
    /// definite, factorised once per evaluation).
    Solution {
        solve: usize,
        row: usize,
        column: usize,
    },
}

/// A linear system A X = R of the DAG: the matrix entries and the columns of
/// R are nodes; `names` are the stage outputs that receive X, if any.
#[derive(Clone, Debug)]
pub struct Solve {
    pub matrix: Vec<Vec<usize>>,
    pub columns: Vec<Vec<usize>>,
    pub names: Option<Vec<Vec<String>>>,
    /// A positive semidefinite matrix (the constraints' Schur complement,
    /// singular where constraints are redundant): its dependent rows are
    /// skipped, their unknowns 0 (`Cholesky::semidefinite`).
    pub semidefinite: bool,
}

/// One step of a generated function's evaluation.
#[derive(Clone, Debug)]
pub enum Step {
    /// Named expressions (of the inputs and earlier outputs).
    Values(Vec<(String, String)>),
    /// A X = R solved numerically (A symmetric positive definite, or
    /// semidefinite with consistent R): the entries are expressions, X's
    /// columns become the outputs `names`.
    Solve {
        matrix: Vec<Vec<String>>,
        columns: Vec<Vec<String>>,
        names: Vec<Vec<String>>,
        semidefinite: bool,
    },
    /// Named derivatives of earlier outputs: (name, output, the variables
    /// to differentiate by in turn), by forward mode through the DAG.
    Derivatives(Vec<(String, String, Vec<String>)>),
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
    /// Linear systems solved numerically (see [`Node::Solution`]).
    solves: Vec<Solve>,
    /// Stage outputs by name, so that a later stage's use of the name can be
    /// differentiated through its definition.
    outputs: HashMap<String, usize>,
    /// Forward-mode derivatives already built: (node, variable) → node.
    derivatives: HashMap<(usize, String), Option<usize>>,
    /// Derivative solves already built: (solve, variable) → solve.
    solve_derivatives: HashMap<(usize, String), Option<usize>>,
    /// Factorised matrices already bound, by their entries.
    factors: HashMap<Vec<Vec<usize>>, String>,
    /// A conversion (e.g. `crate::ode::HyperDual::from`) around every entry
    /// of the arrays handed to the solves, for code over a number type
    /// other than f64: there, parameter expressions stay f64 while the
    /// state's are of that type, and an array needs one type.
    pub lift: Option<&'static str>,
    /// The type that factorises the solves' matrices, where not
    /// `crate::linalg::Cholesky` (dual numbers have one of their own, which
    /// factorises the values once).
    pub factorisation: Option<&'static str>,
}

/// `let &Params { fields } = params;`, the prelude of a generated function
/// (`..` for a model without parameters, whose `Params` holds only a marker
/// of its number type).
pub fn params_line(fields: &[String]) -> String {
    let fields = if fields.is_empty() {
        "..".to_string()
    } else {
        fields.join(", ")
    };
    format!("let &Params {{ {fields} }} = params;")
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

    fn build(&mut self, e: &Expr) -> Result<usize, EmitError> {
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
                    Some(0.5) => self.intern(Node::Sqrt(b)),
                    Some(-0.5) => {
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
                    other => return Err(EmitError::Function(other.to_string())),
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

    fn children(&self, node: &Node) -> Vec<usize> {
        match node {
            Node::Solution { solve, .. } => {
                let s = &self.solves[*solve];
                s.matrix
                    .iter()
                    .chain(&s.columns)
                    .flatten()
                    .copied()
                    .collect()
            }
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
        match &self.nodes[i] {
            Node::Lit(l) => l.clone(),
            Node::Var(v) => v.clone(),
            Node::Neg(a) => format!("-{}", self.atom(*a)),
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
            Node::Div(a, b) => format!("{} / {}", self.factor(*a), self.atom(*b)),
            Node::Powi(a, 1) => t(*a),
            Node::Powi(a, 2)
                if self.bound.contains_key(a) || matches!(self.nodes[*a], Node::Var(_)) =>
            {
                format!("{} * {}", self.atom(*a), self.atom(*a))
            }
            Node::Powi(a, -1) => format!("1.0 / {}", self.atom(*a)),
            Node::Powi(a, k) => format!("{}.powi({k})", self.receiver(*a)),
            Node::Sqrt(a) => format!("{}.sqrt()", self.receiver(*a)),
            Node::Powf(a, b) => format!("{}.powf({})", self.receiver(*a), t(*b)),
            Node::Call(f, a) => format!("{}.{f}()", self.receiver(*a)),
            Node::Solution { .. } => unreachable!("solutions are bound before use"),
        }
    }

    /// Node j as an operand that binds tighter than any operator: names,
    /// calls and positive literals as they are, anything else parenthesised.
    fn atom(&self, j: usize) -> String {
        let s = self.text(j);
        let bare = self.bound.contains_key(&j)
            || match &self.nodes[j] {
                Node::Var(_) | Node::Call(..) | Node::Sqrt(_) => true,
                Node::Lit(l) => !l.starts_with('-'),
                _ => false,
            };
        if bare {
            s
        } else {
            format!("({s})")
        }
    }

    /// The receiver of a method call: an [`Emitter::atom`], with a literal
    /// typed as f64 (`2.0.sqrt()` does not compile: its float type is
    /// ambiguous).
    fn receiver(&self, j: usize) -> String {
        match &self.nodes[j] {
            Node::Lit(l) if !self.bound.contains_key(&j) => match l.strip_prefix('-') {
                Some(magnitude) => format!("(-{magnitude}_f64)"),
                None => format!("{l}_f64"),
            },
            _ => self.atom(j),
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
    pub fn stage(&mut self, outputs: &[(String, String)]) -> Result<(), EmitError> {
        let mut stage = Vec::new();
        for (name, text) in outputs {
            let e = Expr::parse_printed(text).map_err(|err| EmitError::read(text, err))?;
            stage.push((name.clone(), self.build(&e)?));
        }
        self.stage_nodes(stage);
        Ok(())
    }

    /// Adds one step.
    pub fn apply(&mut self, step: &Step) -> Result<(), EmitError> {
        match step {
            Step::Values(outputs) => self.stage(outputs),
            Step::Solve {
                matrix,
                columns,
                names,
                semidefinite,
            } => self.solve_stage(matrix, columns, names, *semidefinite),
            Step::Derivatives(list) => {
                let mut stage = Vec::new();
                for (name, output, variables) in list {
                    let mut node = Some(
                        self.output(output)
                            .ok_or_else(|| EmitError::NoOutput(output.clone()))?,
                    );
                    for v in variables {
                        node = node.and_then(|k| self.derivative(k, v));
                    }
                    let node = node.unwrap_or_else(|| self.zero());
                    stage.push((name.clone(), node));
                }
                self.stage_nodes(stage);
                Ok(())
            }
        }
    }

    /// Adds a stage of outputs that are already nodes of the DAG.
    pub fn stage_nodes(&mut self, outputs: Vec<(String, usize)>) {
        for (name, root) in &outputs {
            self.outputs.insert(name.clone(), *root);
        }
        self.stages.push(outputs);
    }

    /// The node of an expression over earlier outputs and variables.
    pub fn node(&mut self, text: &str) -> Result<usize, EmitError> {
        let e = Expr::parse_printed(text).map_err(|err| EmitError::read(text, err))?;
        self.build(&e)
    }

    /// Adds a stage solving A X = R numerically: `matrix` and the columns
    /// of R are expressions (usually names of earlier outputs); the columns
    /// of X become the outputs `names`.
    pub fn solve_stage(
        &mut self,
        matrix: &[Vec<String>],
        columns: &[Vec<String>],
        names: &[Vec<String>],
        semidefinite: bool,
    ) -> Result<(), EmitError> {
        let matrix = matrix
            .iter()
            .map(|row| row.iter().map(|t| self.node(t)).collect())
            .collect::<Result<Vec<Vec<usize>>, EmitError>>()?;
        let columns = columns
            .iter()
            .map(|col| col.iter().map(|t| self.node(t)).collect())
            .collect::<Result<Vec<Vec<usize>>, EmitError>>()?;
        let solve = self.add_solve(matrix, columns, Some(names.to_vec()), semidefinite);
        let mut stage = Vec::new();
        for (column, col_names) in names.iter().enumerate() {
            for (row, name) in col_names.iter().enumerate() {
                let node = self.intern(Node::Solution { solve, row, column });
                stage.push((name.clone(), node));
            }
        }
        self.stage_nodes(stage);
        Ok(())
    }

    fn add_solve(
        &mut self,
        matrix: Vec<Vec<usize>>,
        columns: Vec<Vec<usize>>,
        names: Option<Vec<Vec<String>>>,
        semidefinite: bool,
    ) -> usize {
        self.solves.push(Solve {
            matrix,
            columns,
            names,
            semidefinite,
        });
        self.solves.len() - 1
    }

    /// The root node of an earlier output.
    pub fn output(&self, name: &str) -> Option<usize> {
        self.outputs.get(name).copied()
    }

    fn zero(&mut self) -> usize {
        self.intern(Node::Lit("0.0".into()))
    }

    fn lit(&mut self, value: f64) -> usize {
        self.intern(Node::Lit(literal(value)))
    }

    /// The forward-mode derivative of node `i` with respect to the variable
    /// `var` (a coordinate or momentum), through earlier outputs used by
    /// name and through linear solves: δX = A⁻¹(δR − δA·X). `None` where it
    /// vanishes.
    pub fn derivative(&mut self, i: usize, var: &str) -> Option<usize> {
        let key = (i, var.to_string());
        if let Some(&d) = self.derivatives.get(&key) {
            return d;
        }
        let d = match self.nodes[i].clone() {
            Node::Lit(_) => None,
            Node::Var(v) if v == var => Some(self.lit(1.0)),
            Node::Var(v) => match self.outputs.get(&v).copied() {
                Some(root) if root != i => self.derivative(root, var),
                _ => None,
            },
            Node::Neg(a) => self.derivative(a, var).map(|x| self.intern(Node::Neg(x))),
            Node::Add(a, b) | Node::Sub(a, b) => {
                let subtract = matches!(self.nodes[i], Node::Sub(..));
                let (da, db) = (self.derivative(a, var), self.derivative(b, var));
                match (da, db) {
                    (Some(x), Some(y)) => Some(self.intern(if subtract {
                        Node::Sub(x, y)
                    } else {
                        Node::Add(x, y)
                    })),
                    (Some(x), None) => Some(x),
                    (None, Some(y)) if subtract => Some(self.intern(Node::Neg(y))),
                    (None, y) => y,
                }
            }
            Node::Mul(a, b) => {
                let da = self
                    .derivative(a, var)
                    .map(|x| self.intern(Node::Mul(x, b)));
                let db = self
                    .derivative(b, var)
                    .map(|y| self.intern(Node::Mul(a, y)));
                self.add_options(da, db)
            }
            Node::Div(a, b) => {
                // δ(a/b) = δa/b − (a/b)·δb/b.
                let da = self
                    .derivative(a, var)
                    .map(|x| self.intern(Node::Div(x, b)));
                let db = self.derivative(b, var).map(|y| {
                    let q = self.intern(Node::Mul(i, y));
                    let q = self.intern(Node::Div(q, b));
                    self.intern(Node::Neg(q))
                });
                self.add_options(da, db)
            }
            Node::Powi(a, k) => self.derivative(a, var).map(|x| {
                let slope = match k {
                    1 => self.lit(1.0),
                    2 => {
                        let two = self.lit(2.0);
                        self.intern(Node::Mul(two, a))
                    }
                    _ => {
                        let kk = self.lit(f64::from(k));
                        let p = self.intern(Node::Powi(a, k - 1));
                        self.intern(Node::Mul(kk, p))
                    }
                };
                self.intern(Node::Mul(slope, x))
            }),
            Node::Sqrt(a) | Node::Call("sqrt", a) => self.derivative(a, var).map(|x| {
                let two = self.lit(2.0);
                let twice = self.intern(Node::Mul(two, i));
                self.intern(Node::Div(x, twice))
            }),
            Node::Powf(a, b) => {
                // δ(a^b) = a^b (δb ln a + b δa / a).
                let da = self.derivative(a, var).map(|x| {
                    let r = self.intern(Node::Div(x, a));
                    self.intern(Node::Mul(b, r))
                });
                let db = self.derivative(b, var).map(|y| {
                    let ln = self.intern(Node::Call("ln", a));
                    self.intern(Node::Mul(y, ln))
                });
                self.add_options(da, db)
                    .map(|s| self.intern(Node::Mul(i, s)))
            }
            Node::Call(f, a) => self.derivative(a, var).map(|x| {
                let slope = match f {
                    "sin" => self.intern(Node::Call("cos", a)),
                    "cos" => {
                        let s = self.intern(Node::Call("sin", a));
                        self.intern(Node::Neg(s))
                    }
                    "tan" => {
                        let c = self.intern(Node::Call("cos", a));
                        let c2 = self.intern(Node::Powi(c, 2));
                        let one = self.lit(1.0);
                        self.intern(Node::Div(one, c2))
                    }
                    "exp" => i,
                    "ln" => {
                        let one = self.lit(1.0);
                        self.intern(Node::Div(one, a))
                    }
                    other => unreachable!("no derivative rule for '{other}'"),
                };
                self.intern(Node::Mul(slope, x))
            }),
            Node::Solution { solve, row, column } => self.solve_derivative(solve, var).map(|s| {
                self.intern(Node::Solution {
                    solve: s,
                    row,
                    column,
                })
            }),
        };
        self.derivatives.insert(key, d);
        d
    }

    fn add_options(&mut self, a: Option<usize>, b: Option<usize>) -> Option<usize> {
        match (a, b) {
            (Some(x), Some(y)) => Some(self.intern(Node::Add(x, y))),
            (x, None) => x,
            (None, y) => y,
        }
    }

    /// The linear system of the derivative of a solve's solution: same
    /// matrix, right-hand sides δR − δA·X.
    fn solve_derivative(&mut self, solve: usize, var: &str) -> Option<usize> {
        let key = (solve, var.to_string());
        if let Some(&s) = self.solve_derivatives.get(&key) {
            return s;
        }
        let Solve {
            matrix,
            columns,
            semidefinite,
            ..
        } = self.solves[solve].clone();
        let n = matrix.len();
        let d_matrix: Vec<Vec<Option<usize>>> = matrix
            .iter()
            .map(|row| row.iter().map(|&a| self.derivative(a, var)).collect())
            .collect();
        let mut new_columns = Vec::new();
        let mut any = false;
        for (c, column) in columns.iter().enumerate() {
            let mut new_column = Vec::new();
            for r in 0..n {
                let mut acc = self.derivative(column[r], var);
                for (j, da) in d_matrix[r].iter().enumerate() {
                    if let Some(da) = *da {
                        let x = self.intern(Node::Solution {
                            solve,
                            row: j,
                            column: c,
                        });
                        let product = self.intern(Node::Mul(da, x));
                        acc = Some(match acc {
                            Some(a) => self.intern(Node::Sub(a, product)),
                            None => self.intern(Node::Neg(product)),
                        });
                    }
                }
                any |= acc.is_some();
                new_column.push(acc.unwrap_or_else(|| self.zero()));
            }
            new_columns.push(new_column);
        }
        let s = any.then(|| self.add_solve(matrix, new_columns, None, semidefinite));
        self.solve_derivatives.insert(key, s);
        s
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
            for c in self.children(&self.nodes[i]) {
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
                stack.extend(self.children(&self.nodes[i]));
            }
            let roots: Vec<usize> = stage.iter().map(|(_, r)| *r).collect();
            for i in 0..self.nodes.len() {
                if !reachable[i] || self.bound.contains_key(&i) {
                    continue;
                }
                if let Node::Solution { solve, .. } = self.nodes[i] {
                    self.bind_solve(solve);
                    continue;
                }
                if roots.contains(&i) {
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
                if self.bound.get(root) == Some(name) {
                    continue;
                }
                let value = self.text(*root);
                self.lines
                    .push(format!("let {name}{} = {value};", literal_type(&value)));
                self.bound.insert(*root, name.clone());
            }
        }
        self.lines
    }

    /// Binds every solution of a linear system: the matrix is factorised
    /// once (shared by every system with the same matrix), then each column
    /// is solved into its output names or fresh ones.
    fn bind_solve(&mut self, solve: usize) {
        let Solve {
            matrix,
            columns,
            names,
            semidefinite,
        } = self.solves[solve].clone();
        let factor = match self.factors.get(&matrix) {
            Some(f) => f.clone(),
            None => {
                let name = if self.factors.is_empty() {
                    "factor__".to_string()
                } else {
                    format!("factor__{}", self.factors.len() + 1)
                };
                let rows: Vec<String> = matrix
                    .iter()
                    .map(|row| {
                        let cells: Vec<String> =
                            row.iter().map(|&a| self.lifted(self.text(a))).collect();
                        format!("[{}]", cells.join(", "))
                    })
                    .collect();
                self.lines.push(format!(
                    "let {name} = {}::{}([{}]);",
                    self.factorisation.unwrap_or("crate::linalg::Cholesky"),
                    if semidefinite { "semidefinite" } else { "new" },
                    rows.join(", ")
                ));
                self.factors.insert(matrix.clone(), name.clone());
                name
            }
        };
        for (c, column) in columns.iter().enumerate() {
            let outputs: Vec<String> = match &names {
                Some(names) => names[c].clone(),
                None => (0..column.len())
                    .map(|_| {
                        self.counter += 1;
                        format!("cse_x{}", self.counter)
                    })
                    .collect(),
            };
            let rhs: Vec<String> = column.iter().map(|&r| self.lifted(self.text(r))).collect();
            self.lines.push(format!(
                "let [{}] = {factor}.solve([{}]);",
                outputs.join(", "),
                rhs.join(", ")
            ));
            for (row, name) in outputs.into_iter().enumerate() {
                let node = self.intern(Node::Solution {
                    solve,
                    row,
                    column: c,
                });
                self.bound.insert(node, name);
            }
        }
    }

    /// `text` converted by [`Emitter::lift`], if any.
    pub fn lifted(&self, text: String) -> String {
        match self.lift {
            Some(f) => format!("{f}({text})"),
            None => text,
        }
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
                    let arg = self.receiver(a);
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
        self.lines
            .push(format!("let {name}{} = {value};", literal_type(&value)));
        self.bound.insert(i, name);
    }
}

/// The DAG of a function: nodes in evaluation order (children before
/// parents) and the named outputs of each stage. `crates/derive/src/taylor.rs` turns it
/// into Taylor-coefficient recurrences.
pub struct Dag {
    pub nodes: Vec<Node>,
    pub stages: Vec<Vec<(String, usize)>>,
    pub solves: Vec<Solve>,
}

impl Emitter {
    /// The DAG built so far, instead of Rust text.
    pub fn into_dag(self) -> Dag {
        Dag {
            nodes: self.nodes,
            stages: self.stages,
            solves: self.solves,
        }
    }
}

/// Cost of the DAG of `stages` in arithmetic operations (every node but
/// literals and variables; transcendental calls weighted): the measure by
/// which a readable form and a derived form of the same right-hand side are
/// compared.
pub fn operation_count(stages: &[Vec<(String, String)>]) -> Result<usize, EmitError> {
    let steps: Vec<Step> = stages.iter().cloned().map(Step::Values).collect();
    step_operation_count(&steps)
}

/// [`operation_count`] of a function given as steps.
pub fn step_operation_count(steps: &[Step]) -> Result<usize, EmitError> {
    let mut emitter = Emitter::default();
    for step in steps {
        emitter.apply(step)?;
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
            // Forward and back substitution (the factorisation is shared).
            Node::Solution { solve, .. } => 2 * emitter.solves[*solve].matrix.len(),
            // x^k by repeated squaring.
            Node::Powi(_, k) => {
                let k = k.unsigned_abs();
                (32 - k.leading_zeros() + k.count_ones()).saturating_sub(2) as usize + 1
            }
            _ => 1,
        })
        .sum())
}

/// The type a binding of `value` states: a bare literal's, since a method
/// called on the name later (`x.cos()`) would find `{float}` ambiguous.
fn literal_type(value: &str) -> &'static str {
    match value.parse::<f64>() {
        Ok(_) => ": f64",
        Err(_) => "",
    }
}
