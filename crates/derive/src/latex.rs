//! LaTeX in the conventions of a mechanics text (build time).
//!
//! Greek names become Greek letters (`eps` → ε, `phi1` → φ₁ as `\varphi_1`),
//! trailing digits become subscripts, momenta read p_{φ₁}, velocities are
//! dotted, `\sin\varphi_1` needs no parentheses, powers of functions read
//! `\sin^2\varphi`, quotients are `\frac`. A model file may give any
//! coordinate or parameter an explicit LaTeX name.

use crate::model::expr::{BinOp, Expr};
use std::collections::HashMap;

const GREEK: &[(&str, &str)] = &[
    ("alpha", "\\alpha"),
    ("beta", "\\beta"),
    ("gamma", "\\gamma"),
    ("delta", "\\delta"),
    ("epsilon", "\\varepsilon"),
    ("eps", "\\varepsilon"),
    ("zeta", "\\zeta"),
    ("eta", "\\eta"),
    ("theta", "\\theta"),
    ("kappa", "\\kappa"),
    ("lambda", "\\lambda"),
    ("mu", "\\mu"),
    ("nu", "\\nu"),
    ("xi", "\\xi"),
    ("rho", "\\rho"),
    ("sigma", "\\sigma"),
    ("tau", "\\tau"),
    ("phi", "\\varphi"),
    ("chi", "\\chi"),
    ("psi", "\\psi"),
    ("omega", "\\omega"),
    ("Gamma", "\\Gamma"),
    ("Delta", "\\Delta"),
    ("Theta", "\\Theta"),
    ("Phi", "\\Phi"),
    ("Psi", "\\Psi"),
    ("Omega", "\\Omega"),
];

/// The default LaTeX of a name: Greek letters, digits and `_x` as subscripts.
pub fn default_name(name: &str) -> String {
    let (base, subscript) = match name.split_once('_') {
        Some((b, s)) => (b, s.to_string()),
        None => match greek_then_capitals(name) {
            // `thetaR`: θ_R, a Greek letter and a capital suffix.
            Some((b, s)) => (b, s.to_string()),
            None => {
                let digits = name.len() - name.trim_end_matches(|c: char| c.is_ascii_digit()).len();
                let (b, s) = name.split_at(name.len() - digits);
                (b, s.to_string())
            }
        },
    };
    let base = GREEK
        .iter()
        .find(|(g, _)| *g == base)
        .map(|(_, l)| l.to_string())
        .unwrap_or_else(|| {
            if base.chars().count() > 1 {
                format!("\\mathrm{{{base}}}")
            } else {
                base.to_string()
            }
        });
    match subscript.as_str() {
        "" => base,
        s if s.chars().count() == 1 => format!("{base}_{s}"),
        // A number (`phi10`): as it is. Read as a name, "10" would be
        // split into no base and the subscript "10" again, forever.
        s if s.chars().all(|c| c.is_ascii_digit()) => format!("{base}_{{{s}}}"),
        s => format!("{base}_{{{}}}", default_name(s)),
    }
}

/// A Greek letter's name followed by capitals and digits (`thetaR`,
/// `phiB2`), split after the letter.
fn greek_then_capitals(name: &str) -> Option<(&str, &str)> {
    GREEK.iter().find_map(|(greek, _)| {
        let rest = name.strip_prefix(greek)?;
        let capital = rest.chars().next()?.is_ascii_uppercase();
        (capital
            && rest
                .chars()
                .all(|c| c.is_ascii_uppercase() || c.is_ascii_digit()))
        .then(|| name.split_at(greek.len()))
    })
}

/// LaTeX names of the symbols of one model.
pub struct Names(HashMap<String, String>);

impl Names {
    /// `coordinates`: (name, velocity, momentum, explicit LaTeX);
    /// `others`: (name, explicit LaTeX) of parameters and the phase.
    pub fn new(
        coordinates: &[(String, String, String, Option<String>)],
        others: &[(String, Option<String>)],
    ) -> Names {
        let mut map = HashMap::new();
        for (name, latex) in others {
            map.insert(
                name.clone(),
                latex.clone().unwrap_or_else(|| default_name(name)),
            );
        }
        for (name, velocity, momentum, latex) in coordinates {
            let q = latex.clone().unwrap_or_else(|| default_name(name));
            map.insert(velocity.clone(), format!("\\dot{{{q}}}"));
            map.insert(momentum.clone(), format!("p_{{{q}}}"));
            map.insert(name.clone(), q);
        }
        Names(map)
    }

    fn name(&self, s: &str) -> String {
        self.0.get(s).cloned().unwrap_or_else(|| default_name(s))
    }

    /// The LaTeX of an expression.
    pub fn latex(&self, e: &Expr) -> String {
        self.print(e, 0)
    }

    fn is_simple_argument(e: &Expr) -> bool {
        matches!(e, Expr::Sym(_) | Expr::Num(_))
    }

    /// `context`: 0 anywhere, 1 a factor of a product, 2 a base of a power.
    fn print(&self, e: &Expr, context: u8) -> String {
        let wrapped = |s: String, needed: bool| {
            if needed {
                format!("\\left({s}\\right)")
            } else {
                s
            }
        };
        match e {
            Expr::Num(n) => n.clone(),
            Expr::Sym(s) => self.name(s),
            Expr::Neg(a) => wrapped(format!("-{}", self.print(a, 1)), context > 0),
            Expr::Bin(BinOp::Add | BinOp::Sub, ..) => {
                let mut out = String::new();
                for (i, t) in e.terms().iter().enumerate() {
                    let s = self.print(t, 0);
                    if i > 0 && !s.starts_with('-') {
                        out.push_str(" + ");
                    } else if i > 0 {
                        out.push_str(" - ");
                        out.push_str(&s[1..]);
                        continue;
                    }
                    out.push_str(&s);
                }
                wrapped(out, context > 0)
            }
            Expr::Bin(BinOp::Mul, a, b) => {
                let left = self.print(a, 1);
                let right = self.print(b, 1);
                let separator = if right.starts_with(|c: char| c.is_ascii_digit()) {
                    " \\cdot "
                } else {
                    " "
                };
                wrapped(format!("{left}{separator}{right}"), context > 1)
            }
            Expr::Bin(BinOp::Div, a, b) => {
                let s = format!("\\frac{{{}}}{{{}}}", self.print(a, 0), self.print(b, 0));
                wrapped(s, context > 1)
            }
            Expr::Bin(BinOp::Pow, base, exponent) => {
                let exp = self.print(exponent, 0);
                if let Expr::Call(f, args) = base.as_ref() {
                    if matches!(f.as_str(), "sin" | "cos" | "tan") {
                        return wrapped(
                            format!("\\{f}^{{{exp}}}{}", self.argument(&args[0])),
                            context > 1,
                        );
                    }
                }
                format!("{}^{{{exp}}}", self.print(base, 2))
            }
            Expr::Call(f, args) => match f.as_str() {
                "sqrt" => format!("\\sqrt{{{}}}", self.print(&args[0], 0)),
                "sin" | "cos" | "tan" | "exp" | "log" => {
                    let name = if f == "log" { "ln" } else { f };
                    wrapped(format!("\\{name}{}", self.argument(&args[0])), context > 1)
                }
                _ => format!(
                    "\\operatorname{{{f}}}\\left({}\\right)",
                    args.iter()
                        .map(|a| self.print(a, 0))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            },
        }
    }

    fn argument(&self, a: &Expr) -> String {
        if Self::is_simple_argument(a) {
            format!(" {}", self.print(a, 0))
        } else {
            format!("\\left({}\\right)", self.print(a, 0))
        }
    }
}
