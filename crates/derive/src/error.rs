//! The derivation's errors, one tree: a build that fails names the model
//! file and the [`DeriveError`] (which quantity of the file, or which
//! generated function, and why).

use mechlab_model::expr::ParseError;

/// Why a model cannot be derived or its module cannot be written.
#[derive(Debug, thiserror::Error)]
pub enum DeriveError {
    /// A quantity of the model file, named by its key, that has no
    /// derivation (a name clash, a mass matrix that is not invertible, ...).
    #[error("key `{key}`: {reason}")]
    Model { key: String, reason: String },
    /// A text built by the derivation that Symbolica cannot read.
    #[error("Symbolica cannot parse '{text}': {message}")]
    Symbolica { text: String, message: String },
    /// A readable form that could not be made or that disagrees with the
    /// derived expression.
    #[error("derived `{key}`: {source}")]
    Readable {
        key: String,
        source: mechlab_simplify::SimplifyError,
    },
    /// A generated function whose code cannot be emitted.
    #[error("generated function {function}: {source}")]
    Emit { function: String, source: EmitError },
    /// A generated function of q alone whose code reads another symbol.
    #[error("generated function {function} depends on '{symbol}', but should depend on the coordinates only")]
    Dependency { function: String, symbol: String },
    /// A template that does not render.
    #[error("template {template}: {source:?}")]
    Template {
        template: &'static str,
        source: tera::Error,
    },
}

/// Why an expression cannot become code (a DAG, its Taylor recurrences).
#[derive(Debug, thiserror::Error)]
pub enum EmitError {
    #[error("cannot read '{text}': {source}")]
    Read { text: String, source: ParseError },
    #[error("cannot emit function '{0}'")]
    Function(String),
    #[error("no output '{0}' to differentiate")]
    NoOutput(String),
    #[error("'{0}' is not a stage output")]
    NotAnOutput(String),
    #[error("no Taylor recurrence for '{0}'")]
    NoRecurrence(String),
    #[error("unknown variable '{0}'")]
    UnknownVariable(String),
    #[error("{outputs} right-hand sides for {state} state components")]
    Shape { outputs: usize, state: usize },
    #[error("{0} tangent vectors: the recurrences are generated for one and looped over the columns at run time")]
    Tangents(usize),
}

impl EmitError {
    /// The error of reading `text`.
    pub fn read(text: &str, source: ParseError) -> EmitError {
        EmitError::Read {
            text: text.to_string(),
            source,
        }
    }

    /// This error in generated function `function`.
    pub fn in_function(self, function: &str) -> DeriveError {
        DeriveError::Emit {
            function: function.to_string(),
            source: self,
        }
    }
}
