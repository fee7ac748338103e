//! Taylor-coefficient recurrences from the DAG of a right-hand side.
//!
//! The Taylor method needs the normalised coefficients x^[k] = x^(k)(t0)/k!
//! of the solution through (t0, x0). Every node u of the right-hand side's
//! DAG (see `crates/derive/src/emit.rs`) gets its own coefficients u^[0..p]: order 0 is
//! the ordinary evaluation, order n follows from lower orders by the
//! recurrence of the node's operation (sums termwise, products by Cauchy
//! sums, quotients, sqrt, powers, exp, ln, sin and cos as a pair), and the
//! state's next order is x^[n+1] = f^[n]/(n+1).
//!
//! Nodes that depend on parameters only are plain numbers computed once per
//! step; nodes linear in time (t, the fast phase θ = rate·t) have two
//! non-zero coefficients, so sin and cos of the phase cost O(1) per order.
//! Integer powers become chains of squares and products (the general power
//! recurrence divides by u^[0] and fails at u = 0). The emitted function
//! calls the kernels of `mechlab::ode::series`.

mod jacobian;

use crate::emit::{params_line, Dag, Node};
use crate::error::EmitError;
use std::collections::HashMap;

/// How a node varies over a step.
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Debug)]
enum Class {
    /// Depends on parameters only.
    Constant,
    /// c0 + c1·t.
    Linear,
    /// Anything else.
    Series,
}

#[derive(Clone, Debug, PartialEq, Eq, Hash)]
enum Op {
    Literal(String),
    Parameter(String),
    State(usize),
    Time,
    /// The fast phase θ = rate·t; the child is the (constant) rate.
    Phase(usize),
    Neg(usize),
    Add(usize, usize),
    Sub(usize, usize),
    Mul(usize, usize),
    Div(usize, usize),
    Square(usize),
    Sqrt(usize),
    /// u^α with a constant exponent α.
    Power(usize, usize),
    Exp(usize),
    Ln(usize),
    Sin(usize),
    Cos(usize),
    /// Row `row` of column `column` of X in A X = R, for the system
    /// `Lowering::solves[solve]`; its children are A's entries and R's.
    Solution {
        solve: usize,
        row: usize,
        column: usize,
    },
}

/// A linear system A X = R over lowered nodes.
#[derive(Clone, Debug)]
struct Solve {
    matrix: Vec<Vec<usize>>,
    columns: Vec<Vec<usize>>,
    /// Factorised by `Cholesky::semidefinite` (see `emit::Solve`).
    semidefinite: bool,
    /// Its solution nodes, column by column.
    solutions: Vec<Vec<usize>>,
}

impl Op {
    fn children(&self, solves: &[Solve]) -> Vec<usize> {
        match *self {
            Op::Solution { solve, .. } => {
                let s = &solves[solve];
                s.matrix
                    .iter()
                    .chain(&s.columns)
                    .flatten()
                    .copied()
                    .collect()
            }
            Op::Literal(_) | Op::Parameter(_) | Op::State(_) | Op::Time => vec![],
            Op::Phase(a)
            | Op::Neg(a)
            | Op::Square(a)
            | Op::Sqrt(a)
            | Op::Exp(a)
            | Op::Ln(a)
            | Op::Sin(a)
            | Op::Cos(a) => vec![a],
            Op::Add(a, b) | Op::Sub(a, b) | Op::Mul(a, b) | Op::Div(a, b) | Op::Power(a, b) => {
                vec![a, b]
            }
        }
    }
}

/// What the variables of a right-hand side are.
pub struct Signature {
    /// State components, in order.
    pub state: Vec<String>,
    /// The model's time variable.
    pub time: String,
    /// The fast phase's name and the stage output holding its rate.
    pub phase: Option<(String, String)>,
    pub parameters: Vec<String>,
}

/// The body of a generated Taylor-coefficient function.
pub struct TaylorBody {
    /// `let &Params { .. } = params;`, with parameters whose names the
    /// function needs for itself bound under other names.
    pub params_line: String,
    pub lines: Vec<String>,
    /// The runs of its order-n loop that are functions of their own.
    pub parts: Vec<Part>,
}

/// A run of the recurrences as a function of its own, called once per
/// order (or once, with n = 0, for a run of order 0): `fn name<Num>(n,
/// params, args…)`, its arguments the slots and locals it reads.
pub struct Part {
    pub name: String,
    /// The arguments after `n, params`, as declared (`w3: &mut Coefficients<Num>, k3: Num, …`).
    pub args: String,
    /// Its body after the `params` line.
    pub lines: Vec<String>,
}

/// The longest order-n loop left in one function. Past it the loop's
/// recurrences go in parts of at most this many lines, each a function of
/// its own: LLVM's loop passes (loop rotation above all) take time growing
/// with the square of the loops in one function, and every product or
/// sin/cos recurrence is a loop, so one function holding a 4-link chain's
/// averaged recurrences took two minutes to optimise. A call per part and
/// order costs nothing beside the part's own Cauchy sums.
const PART_LINES: usize = 48;

/// The longest order 0 left in one function when its order-n loop is in
/// parts. A large model's order 0 evaluates every node once (13,000 lines
/// for a 20-link chain's averaged field), and one function of it took LLVM
/// as long as all the parts of the loop: past this it goes in parts too
/// (the 20-link chain's build 287 s → 215 s with its slots passed one by
/// one, [`NAMED_SLOTS`]). Below it order 0 stays whole: in parts, the
/// double pendulum's chaos map ran 1.54–1.61 s instead of 1.21–1.37 s.
const ZERO_PART_LINES: usize = 1000;

/// The most slots a part takes as one array, naming those it reads in a
/// destructuring pattern of them all. A large model has thousands, and
/// those patterns were most of a 20-link chain's generated code (3.9 of
/// 6.3 MB) and of rustc's front end on it (45 s of 210); past this the
/// parts take their slots one by one. Below it the array stays: passed one
/// by one, the double pendulum's slots cost its chaos map about 10 %.
const NAMED_SLOTS: usize = 1000;

/// Names the generated Taylor functions use for themselves (arguments,
/// loop variables, the kernels' module): no node is named so. The time
/// argument carries the model's name for time and is reserved too.
const OWN_NAMES: [&str; 13] = [
    "y", "z", "params", "order", "work", "out", "n", "next", "len", "columns", "column", "offset",
    "series",
];

struct Lowering<'a> {
    dag: &'a Dag,
    signature: &'a Signature,
    outputs: HashMap<&'a str, usize>,
    ops: Vec<Op>,
    classes: Vec<Class>,
    index: HashMap<Op, usize>,
    memo: HashMap<usize, usize>,
    solves: Vec<Solve>,
    /// Lowered systems by the emitter's solve index.
    solve_memo: HashMap<usize, usize>,
    /// Tangent systems by (solve, tangent).
    tangent_solves: HashMap<(usize, usize), Option<usize>>,
}

impl Lowering<'_> {
    fn intern(&mut self, op: Op) -> usize {
        if let Some(&k) = self.index.get(&op) {
            return k;
        }
        let class = |k: usize| self.classes[k];
        let c = match op {
            Op::Literal(_) | Op::Parameter(_) => Class::Constant,
            Op::State(_) => Class::Series,
            Op::Time | Op::Phase(_) => Class::Linear,
            Op::Neg(a) => class(a),
            Op::Add(a, b) | Op::Sub(a, b) => class(a).max(class(b)),
            Op::Mul(a, b) => match (class(a), class(b)) {
                (Class::Constant, other) | (other, Class::Constant) => other,
                _ => Class::Series,
            },
            Op::Div(a, b) => match (class(a), class(b)) {
                (other, Class::Constant) => other,
                _ => Class::Series,
            },
            Op::Power(a, b) if class(a) == Class::Constant && class(b) == Class::Constant => {
                Class::Constant
            }
            Op::Power(..) => Class::Series,
            Op::Square(a) | Op::Sqrt(a) | Op::Exp(a) | Op::Ln(a) | Op::Sin(a) | Op::Cos(a) => {
                if class(a) == Class::Constant {
                    Class::Constant
                } else {
                    Class::Series
                }
            }
            Op::Solution { .. } => {
                let constant = op
                    .children(&self.solves)
                    .iter()
                    .all(|&c| class(c) == Class::Constant);
                if constant {
                    Class::Constant
                } else {
                    Class::Series
                }
            }
        };
        self.ops.push(op.clone());
        self.classes.push(c);
        self.index.insert(op, self.ops.len() - 1);
        self.ops.len() - 1
    }

    fn literal(&mut self, value: &str) -> usize {
        self.intern(Op::Literal(value.into()))
    }

    /// u^k for k ≥ 1 by squaring and multiplying.
    fn power_chain(&mut self, u: usize, k: u32) -> usize {
        match k {
            1 => u,
            _ if k.is_multiple_of(2) => {
                let half = self.power_chain(u, k / 2);
                self.intern(Op::Square(half))
            }
            _ => {
                let rest = self.power_chain(u, k - 1);
                self.intern(Op::Mul(rest, u))
            }
        }
    }

    /// sin or cos of u; for a varying u its partner too, since the pair's
    /// recurrences need each other.
    fn trig(&mut self, sine: bool, u: usize) -> usize {
        let s = self.intern(Op::Sin(u));
        let c = self.intern(Op::Cos(u));
        if sine {
            s
        } else {
            c
        }
    }

    fn lower(&mut self, i: usize) -> Result<usize, EmitError> {
        if let Some(&k) = self.memo.get(&i) {
            return Ok(k);
        }
        let k = match self.dag.nodes[i].clone() {
            Node::Lit(l) => self.literal(&l),
            Node::Var(v) => self.variable(&v)?,
            Node::Neg(a) => {
                let a = self.lower(a)?;
                self.intern(Op::Neg(a))
            }
            Node::Add(a, b) | Node::Sub(a, b) | Node::Mul(a, b) | Node::Div(a, b) => {
                let (la, lb) = (self.lower(a)?, self.lower(b)?);
                self.intern(match self.dag.nodes[i] {
                    Node::Add(..) => Op::Add(la, lb),
                    Node::Sub(..) => Op::Sub(la, lb),
                    Node::Mul(..) if la == lb => Op::Square(la),
                    Node::Mul(..) => Op::Mul(la, lb),
                    _ => Op::Div(la, lb),
                })
            }
            Node::Powi(a, k) => {
                let a = self.lower(a)?;
                match k {
                    0 => self.literal("1.0"),
                    k if k > 0 => self.power_chain(a, k.unsigned_abs()),
                    k => {
                        let one = self.literal("1.0");
                        let p = self.power_chain(a, k.unsigned_abs());
                        self.intern(Op::Div(one, p))
                    }
                }
            }
            Node::Sqrt(a) => {
                let a = self.lower(a)?;
                self.intern(Op::Sqrt(a))
            }
            Node::Powf(a, b) => {
                let (a, b) = (self.lower(a)?, self.lower(b)?);
                if let Op::Literal(_) = self.ops[b] {
                    self.intern(Op::Power(a, b))
                } else {
                    // u^v = exp(v ln u) for an exponent that is not a
                    // number (powers take an f64 exponent; a parameter is
                    // a `Num`, a lane's own in a batch).
                    let ln = self.intern(Op::Ln(a));
                    let product = self.intern(Op::Mul(b, ln));
                    self.intern(Op::Exp(product))
                }
            }
            Node::Solution { solve, row, column } => {
                let s = match self.solve_memo.get(&solve) {
                    Some(&s) => s,
                    None => {
                        let source = &self.dag.solves[solve];
                        let mut matrix = Vec::new();
                        for row in source.matrix.clone() {
                            matrix.push(
                                row.iter()
                                    .map(|&a| self.lower(a))
                                    .collect::<Result<Vec<_>, _>>()?,
                            );
                        }
                        let mut columns = Vec::new();
                        for column in self.dag.solves[solve].columns.clone() {
                            columns.push(
                                column
                                    .iter()
                                    .map(|&r| self.lower(r))
                                    .collect::<Result<Vec<_>, _>>()?,
                            );
                        }
                        let semidefinite = self.dag.solves[solve].semidefinite;
                        let s = self.add_solve(matrix, columns, semidefinite);
                        self.solve_memo.insert(solve, s);
                        s
                    }
                };
                self.solves[s].solutions[column][row]
            }
            Node::Call(f, a) => {
                let a = self.lower(a)?;
                match f {
                    "sin" => self.trig(true, a),
                    "cos" => self.trig(false, a),
                    "tan" => {
                        let (s, c) = (self.trig(true, a), self.trig(false, a));
                        self.intern(Op::Div(s, c))
                    }
                    "exp" => self.intern(Op::Exp(a)),
                    "ln" => self.intern(Op::Ln(a)),
                    "sqrt" => self.intern(Op::Sqrt(a)),
                    other => return Err(EmitError::NoRecurrence(other.to_string())),
                }
            }
        };
        self.memo.insert(i, k);
        Ok(k)
    }

    /// Adds a lowered system and interns its solution nodes together (so
    /// that they are consecutive: one place computes them all).
    fn add_solve(
        &mut self,
        matrix: Vec<Vec<usize>>,
        columns: Vec<Vec<usize>>,
        semidefinite: bool,
    ) -> usize {
        let s = self.solves.len();
        let (rows, count) = (matrix.len(), columns.len());
        self.solves.push(Solve {
            matrix,
            columns,
            semidefinite,
            solutions: Vec::new(),
        });
        let solutions = (0..count)
            .map(|column| {
                (0..rows)
                    .map(|row| {
                        self.intern(Op::Solution {
                            solve: s,
                            row,
                            column,
                        })
                    })
                    .collect()
            })
            .collect();
        self.solves[s].solutions = solutions;
        s
    }

    /// The tangent system of a solve: same matrix, right-hand sides
    /// δR − δA·X (forward mode through A X = R).
    fn solve_derivative(
        &mut self,
        solve: usize,
        dim: usize,
        t: usize,
        memo: &mut HashMap<usize, Option<usize>>,
    ) -> Option<usize> {
        if let Some(&d) = self.tangent_solves.get(&(solve, t)) {
            return d;
        }
        let Solve {
            matrix,
            columns,
            solutions,
            semidefinite,
        } = self.solves[solve].clone();
        let d_matrix: Vec<Vec<Option<usize>>> = matrix
            .iter()
            .map(|row| {
                row.iter()
                    .map(|&a| self.derivative(a, dim, t, memo))
                    .collect()
            })
            .collect();
        let mut any = false;
        let mut new_columns = Vec::new();
        for (c, column) in columns.iter().enumerate() {
            let mut new_column = Vec::new();
            for (r, &rhs) in column.iter().enumerate() {
                let mut acc = self.derivative(rhs, dim, t, memo);
                for (j, da) in d_matrix[r].iter().enumerate() {
                    if let Some(da) = *da {
                        let product = self.multiply(da, solutions[c][j]);
                        acc = self.sum(acc, Some(product), true);
                    }
                }
                any |= acc.is_some();
                new_column.push(acc.unwrap_or_else(|| self.literal("0.0")));
            }
            new_columns.push(new_column);
        }
        let d = any.then(|| self.add_solve(matrix, new_columns, semidefinite));
        self.tangent_solves.insert((solve, t), d);
        d
    }

    fn multiply(&mut self, a: usize, b: usize) -> usize {
        self.intern(Op::Mul(a, b))
    }

    fn sum(&mut self, a: Option<usize>, b: Option<usize>, subtract: bool) -> Option<usize> {
        match (a, b) {
            (Some(a), Some(b)) => Some(self.intern(if subtract {
                Op::Sub(a, b)
            } else {
                Op::Add(a, b)
            })),
            (Some(a), None) => Some(a),
            (None, Some(b)) if subtract => Some(self.intern(Op::Neg(b))),
            (None, b) => b,
        }
    }

    /// The forward-mode derivative δk of node k along tangent vector `t`
    /// (state components dim·(1 + t) + i); `None` when it vanishes.
    fn derivative(
        &mut self,
        k: usize,
        dim: usize,
        t: usize,
        memo: &mut HashMap<usize, Option<usize>>,
    ) -> Option<usize> {
        if let Some(&d) = memo.get(&k) {
            return d;
        }
        let d = if self.classes[k] == Class::Constant {
            None
        } else {
            match self.ops[k].clone() {
                Op::State(i) if i < dim => Some(self.intern(Op::State(dim * (1 + t) + i))),
                Op::State(_) => None,
                Op::Literal(_) | Op::Parameter(_) | Op::Time | Op::Phase(_) => None,
                Op::Neg(a) => self
                    .derivative(a, dim, t, memo)
                    .map(|x| self.intern(Op::Neg(x))),
                Op::Add(a, b) | Op::Sub(a, b) => {
                    let (da, db) = (
                        self.derivative(a, dim, t, memo),
                        self.derivative(b, dim, t, memo),
                    );
                    self.sum(da, db, matches!(self.ops[k], Op::Sub(..)))
                }
                Op::Mul(a, b) => {
                    let da = self
                        .derivative(a, dim, t, memo)
                        .map(|x| self.multiply(x, b));
                    let db = self
                        .derivative(b, dim, t, memo)
                        .map(|y| self.multiply(a, y));
                    self.sum(da, db, false)
                }
                Op::Div(a, b) => {
                    // δ(a/b) = (δa − (a/b) δb) / b.
                    let da = self.derivative(a, dim, t, memo);
                    let db = self
                        .derivative(b, dim, t, memo)
                        .map(|y| self.multiply(k, y));
                    self.sum(da, db, true).map(|n| self.intern(Op::Div(n, b)))
                }
                Op::Square(a) => self.derivative(a, dim, t, memo).map(|x| {
                    let two_a = {
                        let two = self.literal("2.0");
                        self.multiply(two, a)
                    };
                    self.multiply(two_a, x)
                }),
                Op::Sqrt(a) => self.derivative(a, dim, t, memo).map(|x| {
                    let two = self.literal("2.0");
                    let two_w = self.multiply(two, k);
                    self.intern(Op::Div(x, two_w))
                }),
                Op::Power(a, alpha) => self.derivative(a, dim, t, memo).map(|x| {
                    // The exponent is a literal (see `lower`), and so is α − 1.
                    let Op::Literal(value) = &self.ops[alpha] else {
                        unreachable!("powers have literal exponents")
                    };
                    let value: f64 = value.parse().expect("a literal is a number");
                    let lowered = self.literal(&format!("{:?}", value - 1.0));
                    let power = self.intern(Op::Power(a, lowered));
                    let slope = self.multiply(alpha, power);
                    self.multiply(slope, x)
                }),
                Op::Exp(a) => self
                    .derivative(a, dim, t, memo)
                    .map(|x| self.multiply(k, x)),
                Op::Ln(a) => self
                    .derivative(a, dim, t, memo)
                    .map(|x| self.intern(Op::Div(x, a))),
                Op::Sin(a) => self.derivative(a, dim, t, memo).map(|x| {
                    let c = self.intern(Op::Cos(a));
                    self.multiply(c, x)
                }),
                Op::Cos(a) => self.derivative(a, dim, t, memo).map(|x| {
                    let s = self.intern(Op::Sin(a));
                    let product = self.multiply(s, x);
                    self.intern(Op::Neg(product))
                }),
                Op::Solution { solve, row, column } => self
                    .solve_derivative(solve, dim, t, memo)
                    .map(|d| self.solves[d].solutions[column][row]),
            }
        };
        memo.insert(k, d);
        d
    }

    fn variable(&mut self, v: &str) -> Result<usize, EmitError> {
        let s = self.signature;
        if let Some(k) = s.state.iter().position(|x| x == v) {
            return Ok(self.intern(Op::State(k)));
        }
        if v == s.time {
            return Ok(self.intern(Op::Time));
        }
        if let Some((phase, rate)) = &s.phase {
            if v == phase {
                let root = *self
                    .outputs
                    .get(rate.as_str())
                    .ok_or_else(|| EmitError::NotAnOutput(rate.to_string()))?;
                let r = self.lower(root)?;
                return Ok(self.intern(Op::Phase(r)));
            }
        }
        if let Some(&root) = self.outputs.get(v) {
            return self.lower(root);
        }
        if s.parameters.iter().any(|p| p == v) {
            return Ok(self.intern(Op::Parameter(v.into())));
        }
        Err(EmitError::UnknownVariable(v.to_string()))
    }
}

/// The body of a function computing x^[0..=order] of the solution of
/// x' = f into `out`, where f is the list `outputs` (stage output names of
/// `dag`, one per component of x). If the state is longer than f, the rest
/// are K tangent vectors v with v' = (∂f/∂x) v, each as long as x: their
/// rates are the forward-mode derivatives of f's nodes (δ(a·b) = δa·b +
/// a·δb, δ sin u = cos u·δu, ...), extra nodes of the same DAG.
pub fn recurrences(
    function: &str,
    dag: &Dag,
    signature: &Signature,
    outputs: &[String],
) -> Result<TaylorBody, EmitError> {
    let dim = outputs.len();
    if dim == 0 || !signature.state.len().is_multiple_of(dim) {
        return Err(EmitError::Shape {
            outputs: outputs.len(),
            state: signature.state.len(),
        });
    }
    let tangents = signature.state.len() / dim - 1;
    if tangents > 1 {
        return Err(EmitError::Tangents(tangents));
    }
    let mut lowering = Lowering {
        dag,
        signature,
        outputs: dag
            .stages
            .iter()
            .flatten()
            .map(|(name, root)| (name.as_str(), *root))
            .collect(),
        ops: Vec::new(),
        classes: Vec::new(),
        index: HashMap::new(),
        memo: HashMap::new(),
        solves: Vec::new(),
        solve_memo: HashMap::new(),
        tangent_solves: HashMap::new(),
    };
    // Every state component has coefficients, used or not.
    for k in 0..signature.state.len() {
        lowering.intern(Op::State(k));
    }
    let mut roots = Vec::new();
    for name in outputs {
        let root = *lowering
            .outputs
            .get(name.as_str())
            .ok_or_else(|| EmitError::NotAnOutput(name.to_string()))?;
        roots.push(lowering.lower(root)?);
    }
    let mut jacobian_form = false;
    if tangents == 1 {
        let mut memo = HashMap::new();
        let forward: Vec<usize> = (0..dim)
            .map(|i| match lowering.derivative(roots[i], dim, 0, &mut memo) {
                Some(r) => r,
                None => lowering.literal("0.0"),
            })
            .collect();
        // The cheaper of forward mode and the Jacobian form (ties: forward).
        let cost = |lowering: &Lowering, tangent: &[usize]| {
            let all: Vec<usize> = roots.iter().chain(tangent).copied().collect();
            let needed = reachable(&lowering.ops, &lowering.index, &lowering.solves, &all);
            jacobian::cost(lowering, &needed)
        };
        let forward_cost = cost(&lowering, &forward);
        let chosen = match jacobian::tangent_roots(&mut lowering, dim, &roots) {
            Some(j) if cost(&lowering, &j) < forward_cost => {
                jacobian_form = true;
                j
            }
            _ => forward,
        };
        roots.extend(chosen);
    }
    let needed = reachable(&lowering.ops, &lowering.index, &lowering.solves, &roots);
    let names = names(&lowering, dag, &needed);
    // Parameters bound under their node's name (another where the function
    // needs the parameter's name for itself), unused ones not at all.
    let fields: Vec<String> = signature
        .parameters
        .iter()
        .map(|p| match lowering.index.get(&Op::Parameter(p.clone())) {
            Some(&k) if names[k] == *p => p.clone(),
            Some(&k) => format!("{p}: {}", names[k]),
            None => format!("{p}: _"),
        })
        .collect();
    let params_line = params_line(&fields);
    Ok(Writer {
        ops: &lowering.ops,
        classes: &lowering.classes,
        names: &names,
        needed: &needed,
        index: &lowering.index,
        solves: &lowering.solves,
        declared: Default::default(),
        time: &signature.time,
        function,
    }
    .body(
        &roots,
        dim,
        (tangents == 1).then_some(jacobian_form),
        params_line,
    ))
}

fn reachable(
    ops: &[Op],
    index: &HashMap<Op, usize>,
    solves: &[Solve],
    roots: &[usize],
) -> Vec<bool> {
    let mut needed = vec![false; ops.len()];
    let mut stack: Vec<usize> = roots.to_vec();
    stack.extend(
        ops.iter()
            .enumerate()
            .filter(|(_, op)| matches!(op, Op::State(_)))
            .map(|(k, _)| k),
    );
    while let Some(k) = stack.pop() {
        if needed[k] {
            continue;
        }
        needed[k] = true;
        stack.extend(ops[k].children(solves));
        // The solutions of one system are computed together.
        if let Op::Solution { solve, .. } = ops[k] {
            stack.extend(solves[solve].solutions.iter().flatten());
        }
        // The recurrence of sin needs cos and vice versa.
        if let Op::Sin(u) | Op::Cos(u) = ops[k] {
            for partner in [Op::Sin(u), Op::Cos(u)] {
                if let Some(&k) = index.get(&partner) {
                    stack.push(k);
                }
            }
        }
    }
    needed
}

/// A readable name for every needed node: state names, the stage outputs'
/// names (qd, dp0, j_0_1, ...), sin_q / cos_q / q_sq, else x1, x2, ...
/// (constants k1, k2, ...).
fn names(lowering: &Lowering, dag: &Dag, needed: &[bool]) -> Vec<String> {
    let mut names: Vec<Option<String>> = vec![None; lowering.ops.len()];
    let mut taken: std::collections::HashSet<String> = OWN_NAMES
        .iter()
        .map(|s| s.to_string())
        .chain([lowering.signature.time.clone()])
        .collect();
    let mut give = |names: &mut Vec<Option<String>>, k: usize, name: String| {
        if names[k].is_none() && !taken.contains(&name) {
            taken.insert(name.clone());
            names[k] = Some(name);
        }
    };
    for (k, op) in lowering.ops.iter().enumerate() {
        match op {
            Op::State(i) => give(&mut names, k, lowering.signature.state[*i].clone()),
            Op::Parameter(p) => give(&mut names, k, p.clone()),
            Op::Time => give(&mut names, k, "time".into()),
            _ => {}
        }
    }
    for (name, root) in dag.stages.iter().flatten() {
        if let Some(&k) = lowering.memo.get(root) {
            give(&mut names, k, name.clone());
        }
    }
    if let Some((phase, _)) = &lowering.signature.phase {
        if let Some(k) = lowering.ops.iter().position(|o| matches!(o, Op::Phase(_))) {
            give(&mut names, k, phase.clone());
        }
    }
    let mut counter = 0;
    for k in 0..lowering.ops.len() {
        if !needed[k] || names[k].is_some() {
            continue;
        }
        let readable = match &lowering.ops[k] {
            Op::Sin(a) | Op::Cos(a) | Op::Square(a) => names[*a]
                .as_ref()
                .filter(|_| {
                    matches!(
                        lowering.ops[*a],
                        Op::State(_) | Op::Phase(_) | Op::Time | Op::Parameter(_)
                    )
                })
                .map(|n| match lowering.ops[k] {
                    Op::Sin(_) => format!("sin_{n}"),
                    Op::Cos(_) => format!("cos_{n}"),
                    _ => format!("{n}_sq"),
                }),
            _ => None,
        };
        if let Some(r) = readable {
            give(&mut names, k, r);
        }
        let prefix = if lowering.classes[k] == Class::Constant {
            "k"
        } else {
            "x"
        };
        while names[k].is_none() {
            counter += 1;
            give(&mut names, k, format!("{prefix}{counter}"));
        }
    }
    names.into_iter().map(|n| n.unwrap_or_default()).collect()
}

struct Writer<'a> {
    ops: &'a [Op],
    classes: &'a [Class],
    names: &'a [String],
    needed: &'a [bool],
    index: &'a HashMap<Op, usize>,
    solves: &'a [Solve],
    /// Factorisations already declared in the emitted body, by name.
    declared: std::cell::RefCell<std::collections::HashSet<String>>,
    /// The time argument's name (the model's).
    time: &'a str,
    /// The generated function's name (its parts' names start with it).
    function: &'a str,
}

/// The lines of one [`Writer::orders`]: order 0, the order-n recurrences
/// node by node, and the lines storing the state's next order.
struct Orders {
    zero: Vec<String>,
    recurrences: Vec<Vec<String>>,
    store: Vec<String>,
}

/// What every part of one function shares: the slots' destructuring
/// pattern and count, and the locals a part may read.
struct Slots {
    pattern: String,
    /// The slots' names, in order.
    names: Vec<String>,
    count: usize,
    locals: Vec<Local>,
}

/// A local of the generated function, as a part's argument.
struct Local {
    name: String,
    /// Its type in the part's signature.
    kind: String,
    /// The expression the call passes.
    pass: String,
}

impl Slots {
    /// `let [names…] = work.slots::<count>();`
    fn bind(&self) -> String {
        format!("let {} = work.slots::<{}>();", self.pattern, self.count)
    }

    /// Whether parts take the slots they read one by one (past
    /// [`NAMED_SLOTS`]) rather than the array of all of them.
    fn by_name(&self) -> bool {
        self.count > NAMED_SLOTS
    }
}

/// The identifiers (and numbers) a run of lines mentions.
fn words(lines: &[String]) -> std::collections::HashSet<&str> {
    lines
        .iter()
        .flat_map(|line| {
            line.split(|c: char| !(c.is_alphanumeric() || c == '_'))
                .filter(|word| !word.is_empty())
        })
        .collect()
}

impl Orders {
    fn recurrence_lines(&self) -> usize {
        self.recurrences.iter().map(Vec::len).sum()
    }
}

impl Writer<'_> {
    fn constant(&self, k: usize) -> bool {
        self.classes[k] == Class::Constant
    }

    /// Value of a constant, or order-0 coefficient of a varying node.
    fn value(&self, k: usize) -> String {
        match &self.ops[k] {
            Op::Literal(l) if l.starts_with('-') => format!("({l})"),
            Op::Literal(l) => l.clone(),
            _ if self.constant(k) => self.names[k].clone(),
            _ => format!("{}[0]", self.names[k]),
        }
    }

    /// Order-n coefficient of a varying node.
    fn at(&self, k: usize, n: &str) -> String {
        format!("{}[{n}]", self.names[k])
    }

    /// The scalar expression of a node from its children's values.
    fn scalar(&self, k: usize) -> String {
        let v = |c: usize| self.value(c);
        match &self.ops[k] {
            Op::Literal(l) => l.clone(),
            Op::Parameter(_) => self.names[k].clone(),
            Op::State(i) => format!("y[{i}]"),
            Op::Time => self.time.to_string(),
            Op::Phase(r) => format!("{} * {}", self.time, v(*r)),
            Op::Neg(a) => format!("-{}", self.value_num(*a)),
            Op::Add(a, b) => self.binary(*a, "+", *b),
            Op::Sub(a, b) => self.binary(*a, "-", *b),
            Op::Mul(a, b) => self.binary(*a, "*", *b),
            Op::Div(a, b) => self.binary(*a, "/", *b),
            Op::Square(a) => format!("{} * {}", self.value_num(*a), v(*a)),
            Op::Sqrt(a) => format!("{}.sqrt()", self.value_num(*a)),
            Op::Power(a, b) => format!("{}.powf({})", self.value_num(*a), v(*b)),
            Op::Exp(a) => format!("{}.exp()", self.value_num(*a)),
            Op::Ln(a) => format!("{}.ln()", self.value_num(*a)),
            Op::Sin(a) => format!("{}.sin()", self.value_num(*a)),
            Op::Cos(a) => format!("{}.cos()", self.value_num(*a)),
            Op::Solution { .. } => unreachable!("solutions are computed by `solve_lines`"),
        }
    }

    /// `a op b` from the children's values. Parameters are of the
    /// recurrences' number type `Num` (a batch may give each lane its own),
    /// literals are f64, and `Num` takes f64 on the right only: a literal
    /// left of a `Num` is swapped to the right of + and × (the same
    /// rounding), and made a `Num` before − and / or another literal.
    fn binary(&self, a: usize, op: &str, b: usize) -> String {
        let (x, y) = (self.value(a), self.value(b));
        match (self.is_literal(a), self.is_literal(b), op) {
            (true, false, "+" | "*") => format!("{y} {op} {x}"),
            (true, _, _) => format!("Num::from({x}) {op} {y}"),
            (false, _, _) => format!("{x} {op} {y}"),
        }
    }

    /// Whether node k is a literal (f64; every other node is a `Num`).
    fn is_literal(&self, k: usize) -> bool {
        matches!(self.ops[k], Op::Literal(_))
    }

    /// [`Writer::value`] as the recurrences' number type `Num`: a literal
    /// wrapped (for a method call on it, or among `Num` entries of one
    /// array; parameters are `Num` already).
    fn value_num(&self, k: usize) -> String {
        if self.is_literal(k) {
            let value = self.value(k);
            let bare = value
                .strip_prefix('(')
                .and_then(|v| v.strip_suffix(')'))
                .unwrap_or(&value);
            format!("Num::from({bare})")
        } else {
            self.value(k)
        }
    }

    /// Whether node k is the first solution of its system (where the
    /// system's lines go), and the system.
    fn first_solution(&self, k: usize) -> Option<&Solve> {
        match self.ops[k] {
            Op::Solution { solve, .. } => {
                let s = &self.solves[solve];
                (s.solutions[0][0] == k).then_some(s)
            }
            _ => None,
        }
    }

    /// The factor's name of a system: that of the first system with the
    /// same matrix, from its first solution's name.
    fn factor_name(&self, s: &Solve) -> String {
        format!(
            "factor_{}",
            self.names[self.factor_owner(s).solutions[0][0]]
        )
    }

    /// Declares a system's factorisation unless it is declared already.
    fn declare_factor(&self, s: &Solve, lines: &mut Vec<String>) {
        if self.declared.borrow_mut().insert(self.factor_name(s)) {
            lines.push(self.factor_line(s));
        }
    }

    /// `let factor = Cholesky::new(A at order 0);`
    fn factor_line(&self, s: &Solve) -> String {
        let rows: Vec<String> = s
            .matrix
            .iter()
            .map(|row| {
                let cells: Vec<String> = row.iter().map(|&a| self.value_num(a)).collect();
                format!("[{}]", cells.join(", "))
            })
            .collect();
        format!(
            "let {} = crate::linalg::Cholesky::{}([{}]);",
            self.factor_name(s),
            if s.semidefinite {
                "semidefinite"
            } else {
                "new"
            },
            rows.join(", ")
        )
    }

    /// Order 0 (or a constant system): factorise A (unless a system with
    /// the same matrix did, or it is constant) and solve each column.
    fn solve_lines(&self, s: &Solve, lines: &mut Vec<String>) {
        let constant = self.constant(s.solutions[0][0]);
        let factor = self.factor_name(s);
        if constant || !self.constant_matrix(s) {
            self.declare_factor(s, lines);
        }
        for (column, solutions) in s.columns.iter().zip(&s.solutions) {
            let rhs: Vec<String> = column.iter().map(|&r| self.value_num(r)).collect();
            let targets: Vec<String> = solutions
                .iter()
                .map(|&x| {
                    if constant {
                        self.names[x].clone()
                    } else {
                        format!("{}[0]", self.names[x])
                    }
                })
                .collect();
            lines.push(format!(
                "{}[{}] = {factor}.solve([{}]);",
                if constant { "let " } else { "" },
                targets.join(", "),
                rhs.join(", ")
            ));
        }
    }

    /// Order n of a varying system: x^[n] = (A^[0])⁻¹ (r^[n] − Σ_{k≥1} A^[k] x^[n−k]).
    fn solve_recurrence(&self, s: &Solve, lines: &mut Vec<String>) {
        let factor = self.factor_name(s);
        for (column, solutions) in s.columns.iter().zip(&s.solutions) {
            let rhs: Vec<String> = column
                .iter()
                .enumerate()
                .map(|(r, &rhs)| {
                    let mut terms = vec![if self.constant(rhs) {
                        "Num::from(0.0)".to_string()
                    } else {
                        self.at(rhs, "n")
                    }];
                    for (j, &a) in s.matrix[r].iter().enumerate() {
                        if !self.constant(a) {
                            terms.push(format!(
                                "series::product_tail({}, {}, n)",
                                self.names[a], self.names[solutions[j]]
                            ));
                        }
                    }
                    terms.join(" - ")
                })
                .collect();
            let targets: Vec<String> = solutions.iter().map(|&x| self.at(x, "n")).collect();
            lines.push(format!(
                "[{}] = {factor}.solve([{}]);",
                targets.join(", "),
                rhs.join(", ")
            ));
        }
    }

    /// The sin/cos partner of node k, if k is one of a pair.
    fn partner(&self, k: usize) -> Option<(usize, usize)> {
        match self.ops[k] {
            Op::Sin(u) | Op::Cos(u) => Some((self.index[&Op::Sin(u)], self.index[&Op::Cos(u)])),
            _ => None,
        }
    }

    /// Whether a series recurrence reads all coefficients of node k (sin and
    /// cos of a linear node, and other linear nodes, read orders 0 and 1 only).
    fn read_as_series(&self, k: usize) -> bool {
        (0..self.ops.len()).any(|parent| {
            self.needed[parent]
                && self.classes[parent] == Class::Series
                && !matches!(self.ops[parent], Op::Sin(_) | Op::Cos(_))
                && self.ops[parent].children(self.solves).contains(&k)
        })
    }

    /// Order-1 coefficient of a node linear in time.
    fn slope(&self, k: usize) -> String {
        let s = |c: usize| -> Option<String> { (!self.constant(c)).then(|| self.at(c, "1")) };
        match self.ops[k] {
            Op::Time => "Num::from(1.0)".into(),
            Op::Phase(r) => self.value_num(r),
            Op::Neg(a) => format!("-{}", self.at(a, "1")),
            Op::Add(a, b) | Op::Sub(a, b) => match (s(a), s(b), &self.ops[k]) {
                (Some(x), Some(y), Op::Add(..)) => format!("{x} + {y}"),
                (Some(x), Some(y), _) => format!("{x} - {y}"),
                (Some(x), None, _) => x,
                (None, Some(y), Op::Add(..)) => y,
                (None, Some(y), _) => format!("-{y}"),
                (None, None, _) => unreachable!("a linear node varies"),
            },
            Op::Mul(a, b) if self.constant(a) => format!("{} * {}", self.at(b, "1"), self.value(a)),
            Op::Mul(a, b) => format!("{} * {}", self.at(a, "1"), self.value(b)),
            Op::Div(a, b) => format!("{} / {}", self.at(a, "1"), self.value(b)),
            _ => unreachable!("not a linear node"),
        }
    }

    /// Line(s) computing the order-n coefficient of a series node.
    fn recurrence(&self, k: usize, lines: &mut Vec<String>) {
        let w = &self.names[k];
        let at = |c: usize| self.at(c, "n");
        let name = |c: usize| self.names[c].clone();
        let expression = match self.ops[k] {
            Op::State(_) => return,
            Op::Solution { .. } => {
                if let Some(s) = self.first_solution(k) {
                    self.solve_recurrence(s, lines);
                }
                return;
            }
            Op::Neg(a) => format!("-{}", at(a)),
            Op::Add(a, b) | Op::Sub(a, b) => {
                let plus = matches!(self.ops[k], Op::Add(..));
                match (self.constant(a), self.constant(b)) {
                    (false, false) => {
                        format!("{} {} {}", at(a), if plus { "+" } else { "-" }, at(b))
                    }
                    (false, true) => at(a),
                    (true, false) if plus => at(b),
                    (true, false) => format!("-{}", at(b)),
                    (true, true) => unreachable!("a series node varies"),
                }
            }
            Op::Mul(a, b) => match (self.constant(a), self.constant(b)) {
                (true, _) => format!("{} * {}", at(b), self.value(a)),
                (_, true) => format!("{} * {}", at(a), self.value(b)),
                _ => format!("series::product({}, {}, n)", name(a), name(b)),
            },
            Op::Div(a, b) => match (self.constant(a), self.constant(b)) {
                (_, true) => format!("{} / {}", at(a), self.value(b)),
                (true, false) => format!("series::quotient({w}, Num::from(0.0), {}, n)", name(b)),
                _ => format!("series::quotient({w}, {}, {}, n)", at(a), name(b)),
            },
            Op::Square(a) => format!("series::square({}, n)", name(a)),
            Op::Sqrt(a) => format!("series::sqrt({w}, {}, n)", at(a)),
            Op::Power(a, b) => format!("series::power({w}, {}, {}, n)", name(a), self.value(b)),
            Op::Exp(a) => format!("series::exp({w}, {}, n)", name(a)),
            Op::Ln(a) => format!("series::ln({w}, {}, n)", name(a)),
            Op::Sin(u) | Op::Cos(u) => {
                let (s, c) = self.partner(k).expect("sin and cos come in pairs");
                if k != s.min(c) {
                    return;
                }
                let (sn, cn) = (name(s), name(c));
                if self.classes[u] == Class::Linear {
                    let rate = match self.slope(u) {
                        simple if !simple.contains(' ') => simple,
                        sum => format!("({sum})"),
                    };
                    lines.push(format!(
                        "{sn}[n] = {cn}[n - 1] * ({rate} * Num::inverse(n));"
                    ));
                    lines.push(format!(
                        "{cn}[n] = -({sn}[n - 1] * ({rate} * Num::inverse(n)));"
                    ));
                } else {
                    lines.push(format!(
                        "({sn}[n], {cn}[n]) = series::sin_cos({sn}, {cn}, {}, n);",
                        name(u)
                    ));
                }
                return;
            }
            Op::Literal(_) | Op::Parameter(_) | Op::Time | Op::Phase(_) => {
                unreachable!("constants and linear nodes have no recurrence")
            }
        };
        lines.push(format!("{w}[n] = {expression};"));
    }

    /// The solve whose factorisation system `s` uses: the first one with
    /// the same matrix (a tangent system reuses its base system's factor).
    fn factor_owner<'s>(&'s self, s: &'s Solve) -> &'s Solve {
        self.solves
            .iter()
            .find(|o| o.matrix == s.matrix && self.needed[o.solutions[0][0]])
            .unwrap_or(s)
    }

    /// Whether every entry of a system's matrix is constant over the step.
    fn constant_matrix(&self, s: &Solve) -> bool {
        s.matrix.iter().flatten().all(|&a| self.constant(a))
    }

    /// Whether node k depends on the tangent vector (state components ≥ dim).
    fn tangent_dependence(&self, dim: usize) -> Vec<bool> {
        let mut dependent = vec![false; self.ops.len()];
        for k in 0..self.ops.len() {
            dependent[k] = match self.ops[k] {
                Op::State(i) => i >= dim,
                ref op => op.children(self.solves).iter().any(|&c| dependent[c]),
            };
        }
        dependent
    }

    /// The body of a Taylor-coefficient function. Without tangents the state
    /// is `y: &[f64; DIM]` and `out` rows `[f64; DIM]`. With one tangent
    /// (state [y; v] in the lowering) the function is variational: `z` holds
    /// y and any number of tangent columns, `out` is flat with rows of
    /// z.len(); the base recurrences run once, then the tangent
    /// recurrences once per column (a run-time loop, so the generated code
    /// does not grow with the number of tangents).
    /// `tangent_form`: None without tangents, else whether the tangent
    /// recurrences are in Jacobian form (see [`jacobian`]) or forward mode.
    fn body(
        &self,
        roots: &[usize],
        dim: usize,
        tangent_form: Option<bool>,
        params_line: String,
    ) -> TaylorBody {
        let variational = tangent_form.is_some();
        let mut lines = Vec::new();
        let live: Vec<usize> = (0..self.ops.len()).filter(|&k| self.needed[k]).collect();
        let varying: Vec<usize> = live
            .iter()
            .copied()
            .filter(|&k| !self.constant(k))
            .collect();
        lines.push("// Constants of the step (parameters only).".into());
        for &k in &live {
            if !self.constant(k) || matches!(self.ops[k], Op::Literal(_) | Op::Parameter(_)) {
                continue;
            }
            match self.ops[k] {
                Op::Solution { .. } => {
                    if let Some(s) = self.first_solution(k) {
                        self.solve_lines(s, &mut lines);
                    }
                }
                _ => lines.push(format!("let {} = {};", self.names[k], self.scalar(k))),
            }
        }
        // Factors of constant matrices are constants too.
        for s in self.solves {
            if self.needed[s.solutions[0][0]] && self.constant_matrix(s) {
                self.declare_factor(s, &mut lines);
            }
        }
        let slot_names: Vec<&str> = varying.iter().map(|&k| self.names[k].as_str()).collect();
        let slots = Slots {
            pattern: format!("[{}]", slot_names.join(", ")),
            names: slot_names.iter().map(|s| s.to_string()).collect(),
            count: varying.len(),
            locals: self.locals(&live, dim, variational),
        };
        let dependent = if variational {
            self.tangent_dependence(dim)
        } else {
            vec![false; self.ops.len()]
        };
        let base: Vec<usize> = varying.iter().copied().filter(|&k| !dependent[k]).collect();
        let tangent: Vec<usize> = varying.iter().copied().filter(|&k| dependent[k]).collect();
        let base_roots = if variational { &roots[..dim] } else { roots };
        let base_orders = self.orders(&base, base_roots, if variational { "0" } else { "" });
        let tangent_orders = variational.then(|| self.orders(&tangent, &roots[dim..], "offset"));
        let split = std::iter::once(&base_orders)
            .chain(&tangent_orders)
            .any(|o| o.recurrence_lines() > PART_LINES);
        // Unsplit, the slots are bound to their names once; split, each
        // run of orders binds them again (its parts are passed them).
        if !split {
            lines.push(slots.bind());
        }
        let mut parts = Vec::new();
        if variational {
            lines.push("let len = z.len();".into());
            lines.push(format!("let columns = len / {dim} - 1;"));
            lines.push(format!(
                "assert!(order >= 1 && order <= series::MAX_ORDER && columns >= 1 && len == {dim} * (1 + columns) && out.len() > order * len);"
            ));
            lines.push("out[..len].copy_from_slice(z);".into());
            lines.push("// The solution.".into());
            self.emit_orders(base_orders, split, &slots, &mut lines, &mut parts);
            lines.push(match tangent_form {
                Some(true) => "// Each tangent vector in turn, in Jacobian form: δf_i = Σ_j c_ij·δx_j, the coefficients c_ij among the solution's nodes.".into(),
                _ => "// Each tangent vector in turn, in forward mode: the derivatives of the solution's nodes.".into(),
            });
            lines.push("for column in 0..columns {".into());
            lines.push(format!("let offset = {dim} * (1 + column);"));
            let tangent_orders = tangent_orders.expect("variational");
            self.emit_orders(tangent_orders, split, &slots, &mut lines, &mut parts);
            lines.push("}".into());
        } else {
            lines.push(
                "assert!(order >= 1 && order <= series::MAX_ORDER && out.len() > order);".into(),
            );
            lines.push("out[0] = *y;".into());
            self.emit_orders(base_orders, split, &slots, &mut lines, &mut parts);
        }
        TaylorBody {
            params_line,
            lines,
            parts,
        }
    }

    /// The locals of the function a part may read, with their types and how
    /// they are passed: the time, the constants, the factorisations, `out`
    /// and the variational function's row length and column offset.
    fn locals(&self, live: &[usize], dim: usize, variational: bool) -> Vec<Local> {
        let local = |name: &str, kind: &str, pass: String| Local {
            name: name.to_string(),
            kind: kind.to_string(),
            pass,
        };
        let mut locals = vec![
            local(self.time, "Num", self.time.to_string()),
            local("order", "usize", "order".into()),
        ];
        for &k in live {
            if self.constant(k) && !matches!(self.ops[k], Op::Literal(_) | Op::Parameter(_)) {
                locals.push(local(&self.names[k], "Num", self.names[k].clone()));
            }
        }
        for s in self.solves {
            let name = self.factor_name(s);
            if self.needed[s.solutions[0][0]] && !locals.iter().any(|l| l.name == name) {
                let kind = format!("&crate::linalg::Cholesky<Num, {}>", s.matrix.len());
                locals.push(local(&name, &kind, format!("&{name}")));
            }
        }
        if variational {
            locals.push(local("out", "&mut [Num]", "out".into()));
            locals.push(local("len", "usize", "len".into()));
            locals.push(local("offset", "usize", "offset".into()));
        } else {
            let kind = format!("&mut [[Num; {dim}]]");
            locals.push(local("out", &kind, "out".into()));
        }
        locals
    }

    /// Writes one run of orders: order 0, then the loop over orders n, its
    /// recurrences inline or, past [`PART_LINES`], in parts called in turn
    /// (the last one also storing the state's next order). A very long
    /// order 0 goes in parts too, called once.
    fn emit_orders(
        &self,
        orders: Orders,
        split: bool,
        slots: &Slots,
        lines: &mut Vec<String>,
        parts: &mut Vec<Part>,
    ) {
        let long = orders.recurrence_lines() > PART_LINES;
        if split {
            lines.push(slots.bind());
        }
        if long && slots.by_name() && orders.zero.len() > ZERO_PART_LINES {
            self.emit_zero_in_parts(orders.zero, slots, lines, parts);
        } else {
            lines.extend(orders.zero);
        }
        if !long {
            lines.push("for n in 1..order {".into());
            lines.extend(orders.recurrences.into_iter().flatten());
            lines.extend(orders.store);
            lines.push("}".into());
            return;
        }
        let mut runs: Vec<Vec<String>> = vec![Vec::new()];
        for node in orders.recurrences {
            let run = runs.last_mut().expect("one run at least");
            if !run.is_empty() && run.len() + node.len() > PART_LINES {
                runs.push(node);
            } else {
                run.extend(node);
            }
        }
        runs.last_mut().expect("one run").extend(orders.store);
        if !slots.by_name() {
            lines.push(format!("let slots = work.slots::<{}>();", slots.count));
        }
        lines.push("for n in 1..order {".into());
        for run in runs {
            let name = format!("{}_part_{}", self.function, parts.len() + 1);
            let (call, part) = Self::part(name, run, slots, "n");
            lines.push(call);
            parts.push(part);
        }
        lines.push("}".into());
    }

    /// Order 0 in parts of at most [`PART_LINES`] lines, called in turn
    /// with n = 0 (past [`ZERO_PART_LINES`]). The declarations
    /// (`let` factorisations, which later parts and the loop read) stay in
    /// the function.
    fn emit_zero_in_parts(
        &self,
        zero: Vec<String>,
        slots: &Slots,
        lines: &mut Vec<String>,
        parts: &mut Vec<Part>,
    ) {
        let mut run: Vec<String> = Vec::new();
        let mut flush = |run: &mut Vec<String>, lines: &mut Vec<String>| {
            if run.is_empty() {
                return;
            }
            let name = format!("{}_zero_part_{}", self.function, parts.len() + 1);
            let (call, part) = Self::part(name, std::mem::take(run), slots, "0");
            lines.push(call);
            parts.push(part);
        };
        for line in zero {
            if line.starts_with("let ") {
                flush(&mut run, lines);
                lines.push(line);
            } else {
                if run.len() >= PART_LINES {
                    flush(&mut run, lines);
                }
                run.push(line);
            }
        }
        flush(&mut run, lines);
    }

    /// A run of lines as a part `name`, and the line that calls it at
    /// order `n` with the slots and the locals the run reads. A part takes the array of
    /// slots and names those it reads in a pattern; past [`NAMED_SLOTS`]
    /// slots it takes them one by one, as the function bound them.
    fn part(name: String, run: Vec<String>, slots: &Slots, n: &str) -> (String, Part) {
        let read = words(&run);
        let named: Vec<&str> = slots
            .names
            .iter()
            .map(String::as_str)
            .filter(|name| read.contains(name))
            .collect();
        let used: Vec<&Local> = slots
            .locals
            .iter()
            .filter(|l| read.contains(l.name.as_str()))
            .collect();
        let mut call = vec![n.to_string(), "params".into()];
        let (mut args, mut body) = (Vec::new(), Vec::new());
        if slots.by_name() {
            args.extend(
                named
                    .iter()
                    .map(|name| format!("{name}: &mut crate::ode::series::Coefficients<Num>")),
            );
            call.extend(named.iter().map(|name| name.to_string()));
        } else {
            let pattern: Vec<&str> = slots
                .names
                .iter()
                .map(|name| match read.contains(name.as_str()) {
                    true => name.as_str(),
                    false => "_",
                })
                .collect();
            args.push(format!(
                "slots: &mut [crate::ode::series::Coefficients<Num>; {}]",
                slots.count
            ));
            call.push("slots".into());
            body.push(format!("let [{}] = slots;", pattern.join(", ")));
        }
        args.extend(used.iter().map(|l| format!("{}: {}", l.name, l.kind)));
        call.extend(used.iter().map(|l| l.pass.clone()));
        body.extend(run);
        let call = format!("{name}({});", call.join(", "));
        let part = Part {
            name,
            args: args.join(", "),
            lines: body,
        };
        (call, part)
    }

    /// Order 0, then orders 1..order of the nodes `nodes` (in evaluation
    /// order, their state components first), whose rates are `roots`. The
    /// state's coefficients are written to `out` at column `offset` (flat
    /// rows of `len`), or to `out[n][i]` when `offset` is empty.
    fn orders(&self, nodes: &[usize], roots: &[usize], offset: &str) -> Orders {
        let dim = roots.len();
        let cell = |n: &str, i: usize| -> String {
            match offset {
                "" => format!("out[{n}][{i}]"),
                "0" => format!("out[({n}) * len + {i}]"),
                o => format!("out[({n}) * len + {o} + {i}]"),
            }
        };
        let mut zero = vec!["// Order 0: the values at t.".to_string()];
        for (i, &k) in nodes.iter().enumerate().take(dim) {
            zero.push(format!("{}[0] = {};", self.names[k], cell("0", i)));
        }
        for &k in &nodes[dim..] {
            self.order_zero(k, &mut zero);
        }
        let rates = |n: &str, scale: &str| -> Vec<String> {
            roots
                .iter()
                .map(|&r| {
                    if self.constant(r) {
                        if n == "0" {
                            format!("{}{scale}", self.value_num(r))
                        } else {
                            "Num::from(0.0)".into()
                        }
                    } else {
                        format!("{}{scale}", self.at(r, n))
                    }
                })
                .collect()
        };
        let store = |lines: &mut Vec<String>, row: &str, values: Vec<String>| {
            if offset.is_empty() {
                lines.push(format!("out[{row}] = [{}];", values.join(", ")));
            } else {
                for (i, v) in values.into_iter().enumerate() {
                    lines.push(format!("{} = {v};", cell(row, i)));
                }
            }
            for (i, &k) in nodes.iter().enumerate().take(dim) {
                debug_assert!(matches!(self.ops[k], Op::State(_)));
                lines.push(format!("{}[{row}] = {};", self.names[k], cell(row, i)));
            }
        };
        store(&mut zero, "1", rates("0", ""));
        let recurrences = nodes[dim..]
            .iter()
            .filter(|&&k| self.classes[k] == Class::Series)
            .map(|&k| {
                let mut node = Vec::new();
                self.recurrence(k, &mut node);
                node
            })
            .filter(|node| !node.is_empty())
            .collect();
        let mut next = vec!["let next = Num::inverse(n + 1);".to_string()];
        store(&mut next, "n + 1", rates("n", " * next"));
        Orders {
            zero,
            recurrences,
            store: next,
        }
    }

    /// The order-0 line(s) of a varying node that is not a state component.
    fn order_zero(&self, k: usize, lines: &mut Vec<String>) {
        let w = &self.names[k];
        match self.ops[k] {
            Op::Sin(_) | Op::Cos(_) => {
                let (s, c) = self.partner(k).expect("a pair");
                if k == s.min(c) {
                    let Op::Sin(u) = self.ops[s] else {
                        unreachable!()
                    };
                    lines.push(format!(
                        "({}[0], {}[0]) = {}.sin_cos();",
                        self.names[s],
                        self.names[c],
                        self.value(u)
                    ));
                }
            }
            Op::Solution { .. } => {
                if let Some(s) = self.first_solution(k) {
                    self.solve_lines(s, lines);
                }
            }
            _ => lines.push(format!("{w}[0] = {};", self.scalar(k))),
        }
        if self.classes[k] == Class::Linear {
            lines.push(format!("{w}[1] = {};", self.slope(k)));
            if self.read_as_series(k) {
                lines.push(format!("{w}[2..=order].fill(Num::from(0.0));"));
            }
        }
    }
}
