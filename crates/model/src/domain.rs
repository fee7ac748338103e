//! Where a model file's expressions stop being real: the definition,
//! constraint or force that is not finite at a state, so that a run that
//! leaves the model's domain (a square root of a negative number, a
//! chart's edge) can name the expression that failed.

use crate::file::{ConstraintKind, Model};
use std::collections::BTreeMap;

/// An expression of a model file that is not finite at a state.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{key} = {expression} is {value} there")]
pub struct Undefined {
    /// Where the file gives it: `definitions.y`, `constraints[1]`, `forces.x`.
    pub key: String,
    /// As written in the file.
    pub expression: String,
    pub value: f64,
}

impl Model {
    /// The first of the file's definitions (in the order they use each
    /// other), position constraints and forces that is not finite where
    /// `values` gives the symbols (coordinates, parameters, time and phase;
    /// velocities where known). Those that need a symbol `values` does not
    /// give are passed over. None: every one that could be evaluated is
    /// finite.
    pub fn undefined_at(&self, values: &dyn Fn(&str) -> Option<f64>) -> Option<Undefined> {
        let mut defined: BTreeMap<&str, f64> = BTreeMap::new();
        let undefined = |key: String, e: &crate::Expr, value: f64| Undefined {
            key,
            expression: e.to_string(),
            value,
        };
        for (name, e) in &self.definitions {
            let value = e.eval(&|s| defined.get(s).copied().or_else(|| values(s)));
            match value {
                Ok(v) if !v.is_finite() => {
                    return Some(undefined(format!("definitions.{name}"), e, v))
                }
                Ok(v) => {
                    defined.insert(name, v);
                }
                Err(_) => {}
            }
        }
        let env = |s: &str| defined.get(s).copied().or_else(|| values(s));
        let constraints = self
            .constraints
            .iter()
            .enumerate()
            .filter_map(|(i, c)| match &c.kind {
                ConstraintKind::Position(e) => Some((format!("constraints[{i}] ({})", c.name), e)),
                ConstraintKind::Velocity(_) => None,
            });
        let forces = self
            .coordinates
            .iter()
            .zip(&self.forces)
            .map(|(c, e)| (format!("forces.{}", c.name), e));
        for (key, e) in constraints.chain(forces) {
            if let Ok(v) = e.eval(&env) {
                if !v.is_finite() {
                    return Some(undefined(key, e, v));
                }
            }
        }
        None
    }
}
