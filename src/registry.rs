//! What every generated model exposes about itself: its file, names,
//! parameters and derived expressions (for reports and snapshot tests).

use std::fmt;

/// One derived expression in its readable form (checked at build time
/// against Symbolica's result), as text and LaTeX.
#[derive(Clone, Copy, Debug)]
pub struct DerivedExpression {
    /// Stable key, e.g. `hamiltonian` or `mass_matrix[0][1]`.
    pub key: &'static str,
    pub description: &'static str,
    pub text: &'static str,
    pub latex: &'static str,
}

/// A generated model, described.
#[derive(Clone, Copy, Debug)]
pub struct ModelInfo {
    pub name: &'static str,
    /// The model file's text.
    pub source: &'static str,
    pub source_file: &'static str,
    pub coordinates: &'static [&'static str],
    pub momenta: &'static [&'static str],
    pub parameter_names: &'static [&'static str],
    pub parameter_descriptions: &'static [&'static str],
    pub derivations: &'static [DerivedExpression],
    /// Cost of the right-hand sides after CSE (arithmetic operations,
    /// transcendental calls weighted 20, divisions 4): (function, as derived
    /// by Symbolica, in the readable form, emitted).
    pub operation_counts: &'static [(&'static str, usize, usize, usize)],
    /// The generated Rust module.
    pub generated_code: &'static str,
}

/// Finds a model by name.
pub fn find(name: &str) -> Option<&'static ModelInfo> {
    crate::models::ALL.iter().find(|m| m.name == name)
}

/// A parameter that cannot be set.
#[derive(Clone, Debug, PartialEq)]
pub enum ParameterError {
    Unknown {
        model: &'static str,
        name: String,
        known: &'static [&'static str],
    },
    NotFinite {
        model: &'static str,
        name: String,
        value: f64,
    },
}

impl fmt::Display for ParameterError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ParameterError::Unknown { model, name, known } => {
                write!(
                    f,
                    "model '{model}' has no parameter '{name}' (known: {})",
                    known.join(", ")
                )
            }
            ParameterError::NotFinite { model, name, value } => {
                write!(
                    f,
                    "parameter '{name}' of model '{model}' must be finite, got {value}"
                )
            }
        }
    }
}

impl std::error::Error for ParameterError {}
