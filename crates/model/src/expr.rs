//! The small expression language of model files.
//!
//! It is shared by `build.rs` and the library: the build script uses it to
//! validate model files before any computer algebra runs, to split sums, and to
//! turn Symbolica's printed results into Rust code; the library uses it so
//! that the same validation (and its error messages) can be tested without
//! Symbolica. It parses the usual infix syntax (`+ - * / ^`, calls such as
//! `sin(q)`), evaluates numerically and differentiates symbolically (without
//! simplification: enough for numerical checks).

use std::collections::BTreeSet;
use std::fmt;

/// Functions an expression may call, with their arity.
pub const FUNCTIONS: &[(&str, usize)] = &[
    ("sin", 1),
    ("cos", 1),
    ("tan", 1),
    ("exp", 1),
    ("log", 1),
    ("sqrt", 1),
    ("dot", 1),
];

/// Binary operators, in the order of their precedence classes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BinOp {
    Add,
    Sub,
    Mul,
    Div,
    Pow,
}

/// An expression tree.
#[derive(Clone, Debug, PartialEq)]
pub enum Expr {
    /// A numeric literal, kept as written so that printing it back is exact.
    Num(String),
    Sym(String),
    Neg(Box<Expr>),
    Bin(BinOp, Box<Expr>, Box<Expr>),
    Call(String, Vec<Expr>),
}

/// A call of a function the language does not have, or with the wrong
/// number of arguments.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum CallError {
    #[error("unknown function '{0}'")]
    UnknownFunction(String),
    #[error("function '{name}' takes {expected} argument(s), got {got}")]
    Arity {
        name: String,
        expected: usize,
        got: usize,
    },
}

/// Why an expression has no value.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum EvalError {
    #[error("malformed number '{0}'")]
    MalformedNumber(String),
    #[error("no value for '{0}'")]
    NoValue(String),
    #[error("cannot evaluate function '{0}'")]
    UnknownFunction(String),
}

/// A parse error with the byte offset where it was found.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ParseError {
    pub offset: usize,
    pub message: String,
}

impl fmt::Display for ParseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} (at character {})", self.message, self.offset + 1)
    }
}

impl std::error::Error for ParseError {}

#[derive(Clone, Debug, PartialEq)]
enum Token {
    Num(String),
    Ident(String),
    Op(char),
    LParen,
    RParen,
    Comma,
}

fn tokenize(text: &str) -> Result<Vec<(usize, Token)>, ParseError> {
    let bytes = text.as_bytes();
    let mut tokens = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let c = bytes[i] as char;
        if c.is_ascii_whitespace() {
            i += 1;
        } else if c.is_ascii_digit()
            || (c == '.' && i + 1 < bytes.len() && bytes[i + 1].is_ascii_digit())
        {
            let start = i;
            while i < bytes.len() && (bytes[i].is_ascii_digit() || bytes[i] == b'.') {
                i += 1;
            }
            if i < bytes.len() && (bytes[i] == b'e' || bytes[i] == b'E') {
                let mut j = i + 1;
                if j < bytes.len() && (bytes[j] == b'+' || bytes[j] == b'-') {
                    j += 1;
                }
                if j < bytes.len() && bytes[j].is_ascii_digit() {
                    i = j;
                    while i < bytes.len() && bytes[i].is_ascii_digit() {
                        i += 1;
                    }
                }
            }
            let literal = &text[start..i];
            if literal.parse::<f64>().is_err() {
                return Err(ParseError {
                    offset: start,
                    message: format!("malformed number '{literal}'"),
                });
            }
            tokens.push((start, Token::Num(literal.to_string())));
        } else if c.is_ascii_alphabetic() || c == '_' {
            let start = i;
            while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_') {
                i += 1;
            }
            tokens.push((start, Token::Ident(text[start..i].to_string())));
        } else {
            let token = match c {
                '+' | '-' | '*' | '/' | '^' => Token::Op(c),
                '(' => Token::LParen,
                ')' => Token::RParen,
                ',' => Token::Comma,
                _ => {
                    return Err(ParseError {
                        offset: i,
                        message: format!("unexpected character '{c}'"),
                    })
                }
            };
            tokens.push((i, token));
            i += c.len_utf8();
        }
    }
    Ok(tokens)
}

struct Parser {
    tokens: Vec<(usize, Token)>,
    pos: usize,
    end: usize,
    /// Current nesting (signs, parentheses, calls, exponents).
    depth: usize,
}

/// The deepest nesting the parser accepts: every nesting is a level of
/// recursion here and in every later pass over the tree, so it is bounded
/// (a model file nested deeper gets an error, not a stack overflow).
pub const MAX_NESTING: usize = 100;

impl Parser {
    fn peek(&self) -> Option<&Token> {
        self.tokens.get(self.pos).map(|(_, t)| t)
    }
    fn offset(&self) -> usize {
        self.tokens.get(self.pos).map_or(self.end, |(o, _)| *o)
    }
    fn error<T>(&self, message: impl Into<String>) -> Result<T, ParseError> {
        Err(ParseError {
            offset: self.offset(),
            message: message.into(),
        })
    }
    fn expect(&mut self, token: Token, what: &str) -> Result<(), ParseError> {
        if self.peek() == Some(&token) {
            self.pos += 1;
            Ok(())
        } else {
            self.error(format!("expected {what}"))
        }
    }

    fn sum(&mut self) -> Result<Expr, ParseError> {
        let mut lhs = self.product()?;
        while let Some(Token::Op(op @ ('+' | '-'))) = self.peek().cloned() {
            self.pos += 1;
            let rhs = self.product()?;
            let op = if op == '+' { BinOp::Add } else { BinOp::Sub };
            lhs = Expr::Bin(op, Box::new(lhs), Box::new(rhs));
        }
        Ok(lhs)
    }

    fn product(&mut self) -> Result<Expr, ParseError> {
        let mut lhs = self.unary()?;
        while let Some(Token::Op(op @ ('*' | '/'))) = self.peek().cloned() {
            self.pos += 1;
            let rhs = self.unary()?;
            let op = if op == '*' { BinOp::Mul } else { BinOp::Div };
            lhs = Expr::Bin(op, Box::new(lhs), Box::new(rhs));
        }
        Ok(lhs)
    }

    fn unary(&mut self) -> Result<Expr, ParseError> {
        if self.depth >= MAX_NESTING {
            return self.error(format!("nested more than {MAX_NESTING} levels deep"));
        }
        self.depth += 1;
        let result = self.signed();
        self.depth -= 1;
        result
    }

    fn signed(&mut self) -> Result<Expr, ParseError> {
        match self.peek() {
            Some(Token::Op('-')) => {
                self.pos += 1;
                Ok(Expr::Neg(Box::new(self.unary()?)))
            }
            Some(Token::Op('+')) => {
                self.pos += 1;
                self.unary()
            }
            _ => self.power(),
        }
    }

    fn power(&mut self) -> Result<Expr, ParseError> {
        let base = self.atom()?;
        if self.peek() == Some(&Token::Op('^')) {
            self.pos += 1;
            let exponent = self.unary()?;
            return Ok(Expr::Bin(BinOp::Pow, Box::new(base), Box::new(exponent)));
        }
        Ok(base)
    }

    fn atom(&mut self) -> Result<Expr, ParseError> {
        match self.peek().cloned() {
            Some(Token::Num(n)) => {
                self.pos += 1;
                Ok(Expr::Num(n))
            }
            Some(Token::Ident(name)) => {
                self.pos += 1;
                if self.peek() == Some(&Token::LParen) {
                    self.pos += 1;
                    let mut args = vec![self.sum()?];
                    while self.peek() == Some(&Token::Comma) {
                        self.pos += 1;
                        args.push(self.sum()?);
                    }
                    self.expect(Token::RParen, "')' closing the arguments of a function")?;
                    Ok(Expr::Call(name, args))
                } else {
                    Ok(Expr::Sym(name))
                }
            }
            Some(Token::LParen) => {
                self.pos += 1;
                let inner = self.sum()?;
                self.expect(Token::RParen, "')'")?;
                Ok(inner)
            }
            Some(_) => self.error("expected a number, a name or '('"),
            None => self.error("unexpected end of expression"),
        }
    }
}

impl Expr {
    /// Parses infix text. Function names are not checked here (see [`Expr::check_calls`]).
    pub fn parse(text: &str) -> Result<Expr, ParseError> {
        let tokens = tokenize(text)?;
        if tokens.is_empty() {
            return Err(ParseError {
                offset: 0,
                message: "empty expression".into(),
            });
        }
        let mut parser = Parser {
            tokens,
            pos: 0,
            end: text.len(),
            depth: 0,
        };
        let expr = parser.sum()?;
        if parser.pos != parser.tokens.len() {
            return parser.error("unexpected text after the end of the expression");
        }
        Ok(expr)
    }

    /// Parses Symbolica's printed form: the model-file language, except
    /// that Symbolica writes exp(x) as 𝑒^x (Euler's number to a power),
    /// read back here as `exp(x)`.
    pub fn parse_printed(text: &str) -> Result<Expr, ParseError> {
        const EULER: &str = "euler__e";
        if !text.contains('𝑒') {
            return Expr::parse(text);
        }
        let parsed = Expr::parse(&text.replace('𝑒', EULER))?;
        Ok(parsed.euler_powers_as_exp(EULER))
    }

    /// `e^x` as `exp(x)` and a bare `e` as `exp(1)`, for the symbol `e`.
    fn euler_powers_as_exp(&self, e: &str) -> Expr {
        let exp = |x: Expr| Expr::Call("exp".into(), vec![x]);
        match self {
            Expr::Sym(s) if s == e => exp(Expr::num(1)),
            Expr::Num(_) | Expr::Sym(_) => self.clone(),
            Expr::Bin(BinOp::Pow, base, power) if matches!(&**base, Expr::Sym(s) if s == e) => {
                exp(power.euler_powers_as_exp(e))
            }
            Expr::Neg(a) => Expr::Neg(Box::new(a.euler_powers_as_exp(e))),
            Expr::Bin(op, a, b) => Expr::Bin(
                *op,
                Box::new(a.euler_powers_as_exp(e)),
                Box::new(b.euler_powers_as_exp(e)),
            ),
            Expr::Call(name, args) => Expr::Call(
                name.clone(),
                args.iter().map(|a| a.euler_powers_as_exp(e)).collect(),
            ),
        }
    }

    pub fn num(value: i64) -> Expr {
        Expr::Num(value.to_string())
    }

    /// Every symbol (not function name) used.
    pub fn symbols(&self) -> BTreeSet<String> {
        let mut out = BTreeSet::new();
        self.visit(&mut |e| {
            if let Expr::Sym(s) = e {
                out.insert(s.clone());
            }
        });
        out
    }

    /// Checks that every call names a known function with the right number of arguments.
    pub fn check_calls(&self) -> Result<(), CallError> {
        let mut problem = None;
        self.visit(&mut |e| {
            if let Expr::Call(name, args) = e {
                match FUNCTIONS.iter().find(|(f, _)| f == name) {
                    None if problem.is_none() => {
                        problem = Some(CallError::UnknownFunction(name.clone()))
                    }
                    Some((_, arity)) if *arity != args.len() && problem.is_none() => {
                        problem = Some(CallError::Arity {
                            name: name.clone(),
                            expected: *arity,
                            got: args.len(),
                        })
                    }
                    _ => {}
                }
            }
        });
        problem.map_or(Ok(()), Err)
    }

    fn visit(&self, f: &mut impl FnMut(&Expr)) {
        f(self);
        match self {
            Expr::Num(_) | Expr::Sym(_) => {}
            Expr::Neg(a) => a.visit(f),
            Expr::Bin(_, a, b) => {
                a.visit(f);
                b.visit(f);
            }
            Expr::Call(_, args) => args.iter().for_each(|a| a.visit(f)),
        }
    }

    /// Replaces every symbol for which `map` returns an expression.
    pub fn substitute(&self, map: &dyn Fn(&str) -> Option<Expr>) -> Expr {
        match self {
            Expr::Num(_) => self.clone(),
            Expr::Sym(s) => map(s).unwrap_or_else(|| self.clone()),
            Expr::Neg(a) => Expr::Neg(Box::new(a.substitute(map))),
            Expr::Bin(op, a, b) => Expr::Bin(
                *op,
                Box::new(a.substitute(map)),
                Box::new(b.substitute(map)),
            ),
            Expr::Call(name, args) => Expr::Call(
                name.clone(),
                args.iter().map(|a| a.substitute(map)).collect(),
            ),
        }
    }

    /// Rewrites every call `name(args)` with `f`, innermost first.
    pub fn rewrite_calls(&self, f: &mut dyn FnMut(&str, &[Expr]) -> Option<Expr>) -> Expr {
        match self {
            Expr::Num(_) | Expr::Sym(_) => self.clone(),
            Expr::Neg(a) => Expr::Neg(Box::new(a.rewrite_calls(f))),
            Expr::Bin(op, a, b) => Expr::Bin(
                *op,
                Box::new(a.rewrite_calls(f)),
                Box::new(b.rewrite_calls(f)),
            ),
            Expr::Call(name, args) => {
                let args: Vec<Expr> = args.iter().map(|a| a.rewrite_calls(f)).collect();
                f(name, &args).unwrap_or_else(|| Expr::Call(name.clone(), args))
            }
        }
    }

    /// Numerical value; `env` gives the value of each symbol.
    pub fn eval(&self, env: &dyn Fn(&str) -> Option<f64>) -> Result<f64, EvalError> {
        Ok(match self {
            Expr::Num(n) => n
                .parse::<f64>()
                .map_err(|_| EvalError::MalformedNumber(n.clone()))?,
            Expr::Sym(s) => env(s).ok_or_else(|| EvalError::NoValue(s.clone()))?,
            Expr::Neg(a) => -a.eval(env)?,
            Expr::Bin(op, a, b) => {
                let (x, y) = (a.eval(env)?, b.eval(env)?);
                match op {
                    BinOp::Add => x + y,
                    BinOp::Sub => x - y,
                    BinOp::Mul => x * y,
                    BinOp::Div => x / y,
                    BinOp::Pow => x.powf(y),
                }
            }
            Expr::Call(name, args) => {
                let x = args[0].eval(env)?;
                match name.as_str() {
                    "sin" => x.sin(),
                    "cos" => x.cos(),
                    "tan" => x.tan(),
                    "exp" => x.exp(),
                    "log" => x.ln(),
                    "sqrt" => x.sqrt(),
                    _ => return Err(EvalError::UnknownFunction(name.clone())),
                }
            }
        })
    }

    /// The value and the derivative along one direction (forward mode):
    /// `env` gives each symbol's value and rate. A numerical check's
    /// gradient without the symbolic derivative's tree.
    pub fn eval_rate(
        &self,
        env: &dyn Fn(&str) -> Option<(f64, f64)>,
    ) -> Result<(f64, f64), EvalError> {
        Ok(match self {
            Expr::Num(_) => (self.eval(&|_| None)?, 0.0),
            Expr::Sym(s) => env(s).ok_or_else(|| EvalError::NoValue(s.clone()))?,
            Expr::Neg(a) => {
                let (x, dx) = a.eval_rate(env)?;
                (-x, -dx)
            }
            Expr::Bin(op, a, b) => {
                let ((x, dx), (y, dy)) = (a.eval_rate(env)?, b.eval_rate(env)?);
                match op {
                    BinOp::Add => (x + y, dx + dy),
                    BinOp::Sub => (x - y, dx - dy),
                    BinOp::Mul => (x * y, dx * y + x * dy),
                    BinOp::Div => (x / y, (dx * y - x * dy) / (y * y)),
                    BinOp::Pow if dy == 0.0 => (x.powf(y), y * x.powf(y - 1.0) * dx),
                    BinOp::Pow => {
                        let p = x.powf(y);
                        (p, p * (dy * x.ln() + y * dx / x))
                    }
                }
            }
            Expr::Call(name, args) => {
                let (x, dx) = args[0].eval_rate(env)?;
                match name.as_str() {
                    "sin" => (x.sin(), x.cos() * dx),
                    "cos" => (x.cos(), -x.sin() * dx),
                    "tan" => (x.tan(), dx / (x.cos() * x.cos())),
                    "exp" => (x.exp(), x.exp() * dx),
                    "log" => (x.ln(), dx / x),
                    "sqrt" => (x.sqrt(), dx / (2.0 * x.sqrt())),
                    _ => return Err(EvalError::UnknownFunction(name.clone())),
                }
            }
        })
    }

    /// Symbolic partial derivative (unsimplified, for numerical checks).
    pub fn derivative(&self, var: &str) -> Expr {
        use BinOp::*;
        let zero = || Expr::num(0);
        let bin = |op, a: Expr, b: Expr| Expr::Bin(op, Box::new(a), Box::new(b));
        match self {
            Expr::Num(_) => zero(),
            Expr::Sym(s) => Expr::num(i64::from(s == var)),
            Expr::Neg(a) => Expr::Neg(Box::new(a.derivative(var))),
            // A sum's terms are not cloned: a long sum is a deep tree, and
            // a clone at each of its nodes made the derivative quadratic.
            Expr::Bin(op @ (Add | Sub), a, b) => bin(*op, a.derivative(var), b.derivative(var)),
            Expr::Bin(op, a, b) => {
                let (a, b) = (a.as_ref().clone(), b.as_ref().clone());
                let (da, db) = (a.derivative(var), b.derivative(var));
                match op {
                    Add | Sub => unreachable!("sums are differentiated above"),
                    Mul => bin(Add, bin(Mul, da, b), bin(Mul, a, db)),
                    Div => bin(
                        Div,
                        bin(Sub, bin(Mul, da, b.clone()), bin(Mul, a, db)),
                        bin(Mul, b.clone(), b),
                    ),
                    // d(a^b) = a^b (b' ln a + b a'/a); for a constant exponent only the second term.
                    Pow if b.symbols().is_empty() => bin(
                        Mul,
                        bin(Mul, b.clone(), bin(Pow, a, bin(Sub, b, Expr::num(1)))),
                        da,
                    ),
                    Pow => bin(
                        Mul,
                        self.clone(),
                        bin(
                            Add,
                            bin(Mul, db, Expr::Call("log".into(), vec![a.clone()])),
                            bin(Div, bin(Mul, b, da), a),
                        ),
                    ),
                }
            }
            Expr::Call(name, args) => {
                let a = args[0].clone();
                let da = a.derivative(var);
                let outer = match name.as_str() {
                    "sin" => Expr::Call("cos".into(), vec![a]),
                    "cos" => Expr::Neg(Box::new(Expr::Call("sin".into(), vec![a]))),
                    "tan" => bin(
                        Div,
                        Expr::num(1),
                        bin(Pow, Expr::Call("cos".into(), vec![a]), Expr::num(2)),
                    ),
                    "exp" => self.clone(),
                    "log" => bin(Div, Expr::num(1), a),
                    "sqrt" => bin(Div, Expr::num(1), bin(Mul, Expr::num(2), self.clone())),
                    // `dot` is expanded before anything is differentiated.
                    _ => Expr::Call(format!("d_{name}"), vec![a]),
                };
                bin(Mul, outer, da)
            }
        }
    }

    /// The terms of a sum, each with its sign folded in (`a - b` gives `a`, `-b`).
    pub fn terms(&self) -> Vec<Expr> {
        match self {
            Expr::Bin(BinOp::Add, a, b) => {
                let mut t = a.terms();
                t.extend(b.terms());
                t
            }
            Expr::Bin(BinOp::Sub, a, b) => {
                let mut t = a.terms();
                t.extend(b.terms().into_iter().map(|x| Expr::Neg(Box::new(x))));
                t
            }
            _ => vec![self.clone()],
        }
    }

    /// Sum of terms (`0` for none).
    pub fn sum(terms: Vec<Expr>) -> Expr {
        terms
            .into_iter()
            .reduce(|a, b| match b {
                Expr::Neg(b) => Expr::Bin(BinOp::Sub, Box::new(a), b),
                b => Expr::Bin(BinOp::Add, Box::new(a), Box::new(b)),
            })
            .unwrap_or_else(|| Expr::num(0))
    }

    fn precedence(&self) -> u8 {
        match self {
            Expr::Bin(BinOp::Add | BinOp::Sub, ..) => 1,
            Expr::Bin(BinOp::Mul | BinOp::Div, ..) | Expr::Neg(_) => 2,
            Expr::Bin(BinOp::Pow, ..) => 3,
            Expr::Num(_) | Expr::Sym(_) | Expr::Call(..) => 4,
        }
    }
}

impl fmt::Display for Expr {
    /// Prints in the same infix syntax, with only the parentheses needed.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let wrap = |f: &mut fmt::Formatter<'_>, e: &Expr, min: u8| {
            if e.precedence() < min {
                write!(f, "({e})")
            } else {
                write!(f, "{e}")
            }
        };
        match self {
            Expr::Num(n) => write!(f, "{n}"),
            Expr::Sym(s) => write!(f, "{s}"),
            Expr::Neg(a) => {
                write!(f, "-")?;
                wrap(f, a, 2)
            }
            Expr::Bin(op, a, b) => {
                let (sym, left_min, right_min) = match op {
                    BinOp::Add => ("+", 1, 2),
                    BinOp::Sub => ("-", 1, 2),
                    BinOp::Mul => ("*", 2, 3),
                    BinOp::Div => ("/", 2, 3),
                    BinOp::Pow => ("^", 4, 4),
                };
                wrap(f, a, left_min)?;
                write!(f, "{sym}")?;
                wrap(f, b, right_min)
            }
            Expr::Call(name, args) => {
                write!(f, "{name}(")?;
                for (i, a) in args.iter().enumerate() {
                    if i > 0 {
                        write!(f, ", ")?;
                    }
                    write!(f, "{a}")?;
                }
                write!(f, ")")
            }
        }
    }
}

/// `text` with each decimal literal (a point or an exponent: `0.05`,
/// `5.e-2`, `8e5`) written as the exact rational it names, `(5/100)`,
/// `800000`; names (`x1e5`) and integers are left as they are.
pub fn exact_decimals(text: &str) -> String {
    let bytes = text.as_bytes();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    while i < bytes.len() {
        let c = bytes[i];
        if c.is_ascii_alphabetic() || c == b'_' {
            let start = i;
            while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_') {
                i += 1;
            }
            out.push_str(&text[start..i]);
        } else if c.is_ascii_digit()
            || (c == b'.' && bytes.get(i + 1).is_some_and(u8::is_ascii_digit))
        {
            let start = i;
            while i < bytes.len() && (bytes[i].is_ascii_digit() || bytes[i] == b'.') {
                i += 1;
            }
            let mantissa_end = i;
            let mut exponent = 0_i64;
            if i < bytes.len() && (bytes[i] == b'e' || bytes[i] == b'E') {
                let mut j = i + 1;
                if j < bytes.len() && (bytes[j] == b'+' || bytes[j] == b'-') {
                    j += 1;
                }
                if j < bytes.len() && bytes[j].is_ascii_digit() {
                    while j < bytes.len() && bytes[j].is_ascii_digit() {
                        j += 1;
                    }
                    exponent = text[i + 1..j].parse().unwrap_or(0);
                    i = j;
                }
            }
            let mantissa = &text[start..mantissa_end];
            if i == mantissa_end && !mantissa.contains('.') {
                out.push_str(mantissa);
            } else {
                out.push_str(&rational(mantissa, exponent));
            }
        } else {
            out.push(c as char);
            i += 1;
        }
    }
    out
}

/// The decimal `mantissa` × 10^`exponent` as an integer or `(p/10^k)`.
fn rational(mantissa: &str, exponent: i64) -> String {
    let (whole, fraction) = mantissa.split_once('.').unwrap_or((mantissa, ""));
    let fraction = fraction.trim_end_matches('0');
    let digits = format!("{whole}{fraction}");
    let numerator = digits.trim_start_matches('0');
    if numerator.is_empty() {
        return "0".into();
    }
    let scale = (exponent - fraction.len() as i64).clamp(-400, 400);
    match scale >= 0 {
        true => format!("{numerator}{}", "0".repeat(scale as usize)),
        false => format!("({numerator}/1{})", "0".repeat((-scale) as usize)),
    }
}

#[cfg(test)]
mod decimal_tests {
    use super::exact_decimals;

    /// Decimals become the exact rationals they name; names and integers
    /// stay.
    #[test]
    fn decimals_are_written_as_exact_rationals() {
        assert_eq!(
            exact_decimals("0.0 + 0.05*cos(x1e5)"),
            "0 + (5/100)*cos(x1e5)"
        );
        assert_eq!(
            exact_decimals("8e5*k - 2.5e-3 + 12"),
            "800000*k - (25/10000) + 12"
        );
        assert_eq!(
            exact_decimals("5.e-2 + .5 + 1.250125e+2"),
            "(5/100) + (5/10) + (1250125/10000)"
        );
        assert_eq!(exact_decimals("3.0^2"), "3^2");
    }
}
