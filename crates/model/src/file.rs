//! The model file format (`models/<name>.toml`) and its validation.
//!
//! `build.rs` and the library compile this same file, so every message a user
//! can get from a malformed model is also tested in `tests/model_errors.rs`.
//! Validation is complete before any computer algebra runs: names, symbols,
//! functions, the order of definitions, and, numerically at sample states,
//! that the Lagrangian is quadratic in the velocities with a positive definite
//! mass matrix.

use super::expr::{BinOp, Expr};
pub use mechlab_range::{Range, RangeError};
use serde::Deserialize;
use std::collections::{BTreeMap, BTreeSet};
use std::fmt;

/// What a model file says, as written (the format is described in the README, section "Model files").
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelFile {
    pub name: String,
    pub description: String,
    #[serde(default = "default_time")]
    pub time: String,
    pub coordinates: Vec<CoordinateSpec>,
    #[serde(default)]
    pub parameters: Vec<ParameterSpec>,
    pub fast_phase: Option<FastPhaseSpec>,
    /// Named positions (functions of coordinates, time and the fast phase).
    #[serde(default)]
    pub definitions: BTreeMap<String, String>,
    /// L = T − V; with bodies, what their energies leave out (none: 0).
    #[serde(default)]
    pub lagrangian: String,
    /// Non-potential generalised force per coordinate name.
    #[serde(default)]
    pub forces: BTreeMap<String, String>,
    /// Rayleigh dissipation function D(q, q'): generalised forces −∂D/∂q'.
    pub rayleigh: Option<String>,
    /// Coulomb contacts: points sliding along rough guides.
    #[serde(default)]
    pub contacts: Vec<ContactSpec>,
    /// Bodies sliding on the horizontal plane with viscous friction at
    /// their contact (a Rayleigh term derived from the body's geometry).
    #[serde(default)]
    pub sliding: Vec<SlidingSpec>,
    /// Constraints on the coordinates, ideal (their reactions do no work
    /// along the motions they allow): closed loops, rods between points,
    /// moving guides, rolling.
    #[serde(default)]
    pub constraints: Vec<ConstraintSpec>,
    /// Points of the mechanism, for drawing it: each at (x, y), an
    /// expression of the positions, joined by bars to earlier points.
    #[serde(default)]
    pub points: Vec<PointSpec>,
    /// Rigid bodies: each one's kinetic energy is added to the Lagrangian
    /// (see [`crate::bodies`]).
    #[serde(default)]
    pub bodies: Vec<crate::bodies::BodySpec>,
    /// Gravity's acceleration (x, y, z) in the fixed frame: each body gets
    /// the potential −m g·c (none given: the Lagrangian writes its own).
    pub gravity: Option<[NumberSpec; 3]>,
    /// How q' = A⁻¹(p − b) is computed: "symbolic" (cofactors) or
    /// "numeric" (A(q) emitted, solved by Cholesky in the generated code).
    /// Default: symbolic up to [`SYMBOLIC_INVERSE_MAX_DOF`] degrees of freedom.
    pub inverse: Option<String>,
}

/// The largest model file read (bytes): a Lagrangian of a few links is a
/// few kilobytes.
pub const MAX_FILE_BYTES: usize = 256 * 1024;

/// The longest expression of a model file (characters).
pub const MAX_EXPRESSION_CHARS: usize = 10_000;

/// Up to this many degrees of freedom the mass matrix is inverted
/// symbolically by default. Measured: the double pendulum's symbolic form
/// builds in about 2 s and runs as fast as hand-written code; a triple
/// pendulum's took 5 minutes of computer algebra and a 860 KB module.
pub const SYMBOLIC_INVERSE_MAX_DOF: usize = 2;

/// The largest model the build accepts. The analyses run at any size (the
/// equilibrium search samples its grid beyond 8 degrees of freedom), and
/// the generated code of a chain grows like N² (derivatives run at run
/// time over dual numbers), but the build still grows: a 12-link chain
/// adds about 1 minute to a build on 2 cores and a 20-link one about 4.5.
pub const MAX_DOF: usize = 24;

/// How the generated code gets the velocities from the momenta.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Inverse {
    /// q' = A⁻¹(p − b) with A⁻¹ by cofactors, as closed forms.
    Symbolic,
    /// A(q) and b(q, θ) emitted; A q' = p − b solved by Cholesky at run time.
    Numeric,
}

/// A point held on a rough straight guide (Coulomb friction).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// The coordinate along the guide.
    pub slides: String,
    /// The coordinate the guide holds fixed; its Lagrange multiplier is the
    /// normal reaction.
    pub held: String,
    /// The value the guide holds it at (an expression in the parameters).
    pub at: String,
    /// The friction coefficient (an expression in the parameters).
    pub friction: String,
    #[serde(default)]
    pub description: String,
}

/// A body sliding on a horizontal plane at its point `contact`, with
/// viscous friction: the plane pushes on the body's material point there
/// with −`damping` × its horizontal velocity. It adds ½ damping |v|² to
/// the Rayleigh function (the tippe top's sliding).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SlidingSpec {
    pub name: String,
    /// The sliding body's name.
    pub body: String,
    /// Where it touches the plane (x, y, z), in the coordinates.
    pub contact: [NumberSpec; 3],
    /// The friction's coefficient (N s/m), an expression in the parameters.
    pub damping: NumberSpec,
    #[serde(default)]
    pub description: String,
}

/// An ideal constraint: exactly one of `position` (holonomic, an expression
/// of the positions, time and the fast phase that vanishes) and `velocity`
/// (nonholonomic, an expression linear in the velocities that vanishes).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConstraintSpec {
    /// Names the constraint's reaction (its Lagrange multiplier).
    pub name: String,
    pub position: Option<String>,
    pub velocity: Option<String>,
    /// A body rolling without slipping on a horizontal plane at its point
    /// `contact`: the material point there has no horizontal velocity
    /// (two constraints, `<name>_x` and `<name>_y`).
    pub rolling: Option<String>,
    /// Where the rolling body touches the plane (x, y, z), in the
    /// coordinates.
    pub contact: Option<[NumberSpec; 3]>,
    #[serde(default)]
    pub description: String,
}

/// A point of the mechanism's drawing: `at = ["x", "y"]` in the plane of
/// the figure or `at = ["x", "y", "z"]` in space (expressions of the
/// coordinates, parameters, time and fast phase, definitions allowed),
/// `joined_to` the earlier points a bar joins it to.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointSpec {
    pub name: String,
    pub at: Vec<String>,
    #[serde(default)]
    pub joined_to: Vec<String>,
    #[serde(default)]
    pub description: String,
}

/// The most points a drawing may have.
pub const MAX_POINTS: usize = 64;

/// A number in a model file: a value, or an expression in the parameters.
#[derive(Clone, Debug, Deserialize)]
#[serde(untagged)]
pub enum NumberSpec {
    Value(f64),
    Expression(String),
}

fn default_time() -> String {
    "t".into()
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CoordinateSpec {
    pub name: String,
    pub velocity: String,
    #[serde(default)]
    pub periodic: bool,
    #[serde(default)]
    pub description: String,
    /// LaTeX of the name, when the default (Greek names, digits as
    /// subscripts) does not fit.
    pub latex: Option<String>,
    /// The coordinate's value in a configuration that satisfies the
    /// constraints at t = 0 with the default parameters (models with
    /// constraints need one for every coordinate).
    pub start: Option<NumberSpec>,
    /// Its rate at the start: with constraints, held while the other
    /// rates are made to satisfy the velocity constraints (without one, a
    /// rate is what the constraints leave nearest rest); without, the
    /// start's momenta are those of these rates (0 where none is given).
    pub start_rate: Option<NumberSpec>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParameterSpec {
    pub name: String,
    pub default: f64,
    pub description: String,
    /// LaTeX of the name, when the default does not fit.
    pub latex: Option<String>,
    /// The values it may take, as an interval: `"(0, inf)"`, `"[0, 1]"`.
    pub range: Option<String>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FastPhaseSpec {
    pub name: String,
    /// dθ/dt as an expression in the parameters.
    pub rate: String,
    /// The parameter that scales the vibration (the default of the
    /// `stability` analysis), if any.
    pub amplitude: Option<String>,
    #[serde(default)]
    pub description: String,
}

/// A problem in a model file: which file, which key, and why.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ModelError {
    pub file: String,
    pub key: String,
    pub reason: String,
}

impl fmt::Display for ModelError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: key `{}`: {}", self.file, self.key, self.reason)
    }
}

impl std::error::Error for ModelError {}

/// A generalised coordinate.
#[derive(Clone, Debug)]
pub struct Coordinate {
    pub name: String,
    pub velocity: String,
    pub periodic: bool,
    pub description: String,
    /// Explicit LaTeX name, if the model file gives one.
    pub latex: Option<String>,
    /// Its value in the consistent start (models with constraints), an
    /// expression in the parameters.
    pub start: Option<Expr>,
    /// Its rate at the start, an expression in the parameters (with
    /// constraints, held there while the others are made consistent).
    pub start_rate: Option<Expr>,
}

#[derive(Clone, Debug)]
pub struct Parameter {
    pub name: String,
    pub default: f64,
    pub description: String,
    /// Explicit LaTeX name, if the model file gives one.
    pub latex: Option<String>,
    /// The values it may take (all reals unless the file says otherwise).
    pub range: Range,
}

/// The fast phase θ with dθ/dt = rate(parameters); the model is 2π-periodic in θ.
#[derive(Clone, Debug)]
pub struct FastPhase {
    pub name: String,
    pub rate: Expr,
    /// The parameter that scales the vibration, if the file names one.
    pub amplitude: Option<String>,
    pub description: String,
}

/// A validated model.
#[derive(Clone, Debug)]
pub struct Model {
    pub name: String,
    pub description: String,
    pub time: String,
    pub coordinates: Vec<Coordinate>,
    pub parameters: Vec<Parameter>,
    pub fast_phase: Option<FastPhase>,
    /// Definitions in an order in which each uses only earlier ones.
    pub definitions: Vec<(String, Expr)>,
    /// The Lagrangian as written; `dot(x)` is the total time derivative of `x`.
    pub lagrangian: Expr,
    /// One force per coordinate (zero where the file gives none).
    pub forces: Vec<Expr>,
    /// The Rayleigh dissipation function (zero if none), the sliding
    /// contacts' terms included; `dot()` as in L.
    pub rayleigh: Expr,
    pub contacts: Vec<Contact>,
    /// The bodies sliding on the plane (their friction is in `rayleigh`).
    pub sliding: Vec<Sliding>,
    pub constraints: Vec<Constraint>,
    /// The mechanism's points, in the order of the file (empty: no
    /// drawing), then each body's centre and axis tips.
    pub points: Vec<Point>,
    /// Each body's frame in the drawing: the indices of its centre and of
    /// its x, y and z axes' tips in `points`.
    pub body_frames: Vec<[usize; 4]>,
    /// Gravity's acceleration (x, y, z) where the file gives it, in the
    /// parameters: the drawing's way down.
    pub gravity: Option<[Expr; 3]>,
    pub inverse: Inverse,
    /// The definitions resolved (each with the others substituted), made
    /// once: every numerical check expands its expressions with them.
    resolved: std::sync::OnceLock<Vec<(String, Expr)>>,
}

/// A body's inertia tensor about its centre in its axes, as written
/// (None: zero).
type Inertia = [[Option<String>; 3]; 3];

/// The bodies read: each one's kinetic energy (with gravity's potential)
/// as a term of the Lagrangian and its inertia, and gravity's
/// acceleration.
struct ReadBodies {
    energies: Vec<Expr>,
    tensors: Vec<Inertia>,
    gravity: Option<[Expr; 3]>,
}

/// A validated point of the drawing.
#[derive(Clone, Debug)]
pub struct Point {
    pub name: String,
    /// (x, y, z) as written (definitions not yet substituted); z = 0 for a
    /// point given in the plane.
    pub at: [Expr; 3],
    /// Whether the point was given in space (x, y, z).
    pub in_space: bool,
    /// Indices of the earlier points a bar joins it to.
    pub joined_to: Vec<usize>,
    pub description: String,
}

/// A validated ideal constraint.
#[derive(Clone, Debug)]
pub struct Constraint {
    pub name: String,
    pub kind: ConstraintKind,
    pub description: String,
    /// The file's key that gave it (`constraints[2].position`), for messages.
    pub key: String,
    /// A rolling constraint's contact velocity along the plane's normal,
    /// which the body's geometry must hold at zero.
    pub normal: Option<Expr>,
}

/// A validated sliding contact: what the body's geometry must keep on
/// the plane.
#[derive(Clone, Debug)]
pub struct Sliding {
    pub name: String,
    /// The file's key that gave it (`sliding[0].contact`), for messages.
    pub key: String,
    /// The material point's velocity across the plane, which the body's
    /// geometry must hold at zero, and along it (x): the check's scale.
    pub normal: Expr,
    pub along: Expr,
}

/// What vanishes along the motion.
#[derive(Clone, Debug)]
pub enum ConstraintKind {
    /// g(q, t) = 0: holonomic (`dot` not allowed).
    Position(Expr),
    /// a(q, t)·q' + b(q, t) = 0: nonholonomic (velocities and `dot` allowed).
    Velocity(Expr),
}

impl ConstraintKind {
    pub fn expression(&self) -> &Expr {
        match self {
            ConstraintKind::Position(e) | ConstraintKind::Velocity(e) => e,
        }
    }
}

/// A validated Coulomb contact.
#[derive(Clone, Debug)]
pub struct Contact {
    pub slides: String,
    pub held: String,
    pub at: Expr,
    pub friction: Expr,
    pub description: String,
}

/// Rust's keywords, strict and reserved: a model's module and its
/// generated identifiers are named after the model and its names.
const RUST_KEYWORDS: &[&str] = &[
    "as", "break", "const", "continue", "crate", "else", "enum", "extern", "false", "fn", "for",
    "if", "impl", "in", "let", "loop", "match", "mod", "move", "mut", "pub", "ref", "return",
    "self", "Self", "static", "struct", "super", "trait", "true", "type", "unsafe", "use", "where",
    "while", "async", "await", "dyn", "abstract", "become", "box", "do", "final", "macro",
    "override", "priv", "typeof", "unsized", "virtual", "yield", "try", "gen",
];

/// Names that the generated code or the expression reader take for themselves.
const RESERVED: &[&str] = &["params", "pi", "e", "i"];

pub(crate) fn is_identifier(name: &str) -> bool {
    let mut chars = name.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_alphabetic())
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
        && !name.contains("__")
}

impl Model {
    /// Reads and validates a model file's text; `file` names it in errors.
    pub fn parse(file: &str, text: &str) -> Result<Model, ModelError> {
        let err = |key: &str, reason: String| ModelError {
            file: file.to_string(),
            key: key.to_string(),
            reason,
        };
        if text.len() > MAX_FILE_BYTES {
            return Err(err(
                "(file)",
                format!(
                    "{} bytes: a model file may have at most {MAX_FILE_BYTES}",
                    text.len()
                ),
            ));
        }
        let mut spec: ModelFile = toml::from_str(text).map_err(|e| {
            let message = e.message().to_string();
            let key = match e.span() {
                Some(span) => key_at(text, span.start),
                None => "(file)".to_string(),
            };
            err(&key, message)
        })?;
        crate::bodies::declare(&mut spec).map_err(|(key, reason)| err(&key, reason))?;
        spec.validate(file)
    }
}

/// The dotted key whose line contains byte `offset` (best effort, for messages).
fn key_at(text: &str, offset: usize) -> String {
    let mut table = String::new();
    let mut key = String::new();
    for (start, line) in line_starts(text) {
        if start > offset {
            break;
        }
        let trimmed = line.trim();
        if trimmed.starts_with('[') {
            table = trimmed
                .trim_matches(|c| c == '[' || c == ']')
                .trim()
                .to_string();
            key.clear();
        } else if let Some((k, _)) = trimmed.split_once('=') {
            key = k.trim().to_string();
        }
    }
    match (table.is_empty(), key.is_empty()) {
        (true, true) => "(file)".into(),
        (true, false) => key,
        (false, true) => table,
        (false, false) => format!("{table}.{key}"),
    }
}

/// The definitions in an order where each refers only to those before it,
/// or the cycle that prevents one.
fn order_definitions(
    parsed_defs: &BTreeMap<String, Expr>,
    err: &impl Fn(&str, String) -> ModelError,
) -> Result<Vec<(String, Expr)>, ModelError> {
    let definitions: Vec<String> = parsed_defs.keys().cloned().collect();
    let mut ordered: Vec<(String, Expr)> = Vec::new();
    while ordered.len() < parsed_defs.len() {
        let ready = parsed_defs.iter().find(|(name, e)| {
            !ordered.iter().any(|(n, _)| n == *name)
                && e.symbols()
                    .iter()
                    .all(|s| !definitions.contains(s) || ordered.iter().any(|(n, _)| n == s))
        });
        match ready {
            Some((name, e)) => ordered.push((name.clone(), e.clone())),
            None => {
                let stuck: Vec<&String> = parsed_defs
                    .keys()
                    .filter(|n| !ordered.iter().any(|(m, _)| m == *n))
                    .collect();
                return Err(err(
                    "definitions",
                    format!("definitions refer to each other in a cycle: {stuck:?}"),
                ));
            }
        }
    }
    Ok(ordered)
}

fn line_starts(text: &str) -> impl Iterator<Item = (usize, &str)> {
    let mut start = 0;
    text.split_inclusive('\n').map(move |line| {
        let s = start;
        start += line.len();
        (s, line)
    })
}

impl ModelFile {
    /// The model's name, its number of coordinates and the form of its
    /// mass matrix's inverse.
    fn check_name_and_size(
        &self,
        err: &impl Fn(&str, String) -> ModelError,
    ) -> Result<Inverse, ModelError> {
        if !is_identifier(&self.name) || self.name.chars().any(|c| c.is_ascii_uppercase()) {
            return Err(err(
                "name",
                format!(
                    "'{}' is not a lowercase identifier (letters, digits, '_')",
                    self.name
                ),
            ));
        }
        if RUST_KEYWORDS.contains(&self.name.as_str()) {
            return Err(err(
                "name",
                format!(
                    "'{}' is a Rust keyword, and the model's generated module is named after the model: choose another name (e.g. '{}_model')",
                    self.name, self.name
                ),
            ));
        }
        if self.coordinates.is_empty() {
            return Err(err(
                "coordinates",
                "a model needs at least one coordinate".into(),
            ));
        }
        if self.coordinates.len() > MAX_DOF {
            return Err(err(
                "coordinates",
                format!(
                    "{} degrees of freedom: at most {MAX_DOF} are built (a 12-link chain adds about 1 minute to a build on 2 cores, a 20-link one about 4.5)",
                    self.coordinates.len()
                ),
            ));
        }
        let inverse = match self.inverse.as_deref() {
            None if self.coordinates.len() <= SYMBOLIC_INVERSE_MAX_DOF => Inverse::Symbolic,
            None | Some("numeric") => Inverse::Numeric,
            Some("symbolic") if self.coordinates.len() <= 3 => Inverse::Symbolic,
            Some("symbolic") => {
                return Err(err(
                    "inverse",
                    format!(
                        "a symbolic inverse of a {0}×{0} mass matrix is beyond the build's budget (at most 3×3); use \"numeric\"",
                        self.coordinates.len()
                    ),
                ))
            }
            Some(other) => {
                return Err(err(
                    "inverse",
                    format!("'{other}' is neither \"symbolic\" nor \"numeric\""),
                ))
            }
        };
        Ok(inverse)
    }

    /// Every name of the file declared once, as an identifier that is not
    /// reserved, and every parameter's default finite and in its range.
    fn declare_names(&self, err: &impl Fn(&str, String) -> ModelError) -> Result<(), ModelError> {
        // Every name, once, as an identifier.
        let mut seen = BTreeSet::new();
        let mut declare = |key: &str, name: &str| -> Result<(), ModelError> {
            if !is_identifier(name) {
                return Err(err(key, format!("'{name}' is not an identifier (a letter, then letters, digits or single '_')")));
            }
            if RESERVED.contains(&name)
                || RUST_KEYWORDS.contains(&name)
                || super::expr::FUNCTIONS.iter().any(|(f, _)| *f == name)
            {
                return Err(err(key, format!("'{name}' is a reserved name")));
            }
            if name.starts_with("cse_") {
                return Err(err(
                    key,
                    format!(
                        "'{name}': names beginning with 'cse_' are reserved for the generated code"
                    ),
                ));
            }
            if !seen.insert(name.to_string()) {
                return Err(err(key, format!("'{name}' is declared twice")));
            }
            Ok(())
        };
        declare("time", &self.time)?;
        for (i, c) in self.coordinates.iter().enumerate() {
            declare(&format!("coordinates[{i}].name"), &c.name)?;
            declare(&format!("coordinates[{i}].velocity"), &c.velocity)?;
        }
        for (i, p) in self.parameters.iter().enumerate() {
            declare(&format!("parameters[{i}].name"), &p.name)?;
            if !p.default.is_finite() {
                return Err(err(
                    &format!("parameters[{i}].default"),
                    format!("default of '{}' is not finite", p.name),
                ));
            }
            if let Some(text) = &p.range {
                let range = Range::parse(text)
                    .map_err(|reason| err(&format!("parameters[{i}].range"), reason.to_string()))?;
                if !range.contains(p.default) {
                    return Err(err(
                        &format!("parameters[{i}].default"),
                        format!(
                            "the default {} of '{}' is outside its range {range}",
                            p.default, p.name
                        ),
                    ));
                }
            }
        }
        if let Some(phase) = &self.fast_phase {
            declare("fast_phase.name", &phase.name)?;
        }
        for name in self.definitions.keys() {
            declare(&format!("definitions.{name}"), name)?;
        }
        Ok(())
    }

    fn validate(self, file: &str) -> Result<Model, ModelError> {
        let err = |key: &str, reason: String| ModelError {
            file: file.to_string(),
            key: key.to_string(),
            reason,
        };
        let inverse = self.check_name_and_size(&err)?;
        self.declare_names(&err)?;
        let reader = Reader::new(&self, file);
        let names = &reader.names;
        let parse = |key: &str, text: &str, allowed: &[&Vec<String>], dot_allowed: bool| {
            reader.parse(key, text, allowed, dot_allowed)
        };
        let fast_phase = match &self.fast_phase {
            Some(p) => {
                if let Some(a) = p
                    .amplitude
                    .as_ref()
                    .filter(|a| !names.parameters.contains(a))
                {
                    return Err(err(
                        "fast_phase.amplitude",
                        format!("'{a}' is not a parameter of the model"),
                    ));
                }
                Some(FastPhase {
                    name: p.name.clone(),
                    rate: parse("fast_phase.rate", &p.rate, &[&names.parameters], false)?,
                    amplitude: p.amplitude.clone(),
                    description: p.description.clone(),
                })
            }
            None => None,
        };
        let bodies = self.validate_bodies(file, names, &parse)?;
        // Definitions are positions: no velocities, and no cycles.
        let mut parsed_defs = BTreeMap::new();
        for (name, text) in &self.definitions {
            let positions = names.positions();
            let e = parse(&format!("definitions.{name}"), text, &positions, false)?;
            parsed_defs.insert(name.clone(), e);
        }
        let definitions = order_definitions(&parsed_defs, &err)?;
        let all = names.all();
        let lagrangian = match self.lagrangian.trim() {
            "" if bodies.energies.is_empty() => {
                return Err(err(
                    "lagrangian",
                    "missing: give L = T − V, or the model's [[bodies]]".into(),
                ))
            }
            "" => Expr::num(0),
            text => parse("lagrangian", text, &all, true)?,
        };
        let lagrangian = Expr::sum(
            std::iter::once(lagrangian)
                .chain(bodies.energies.iter().cloned())
                .collect(),
        );
        if let Some(name) = self.forces.keys().find(|n| !names.coordinates.contains(n)) {
            return Err(err(
                &format!("forces.{name}"),
                format!("'{name}' is not a coordinate"),
            ));
        }
        let forces = names
            .coordinates
            .iter()
            .map(|c| match self.forces.get(c) {
                Some(text) => parse(&format!("forces.{c}"), text, &all, false),
                None => Ok(Expr::num(0)),
            })
            .collect::<Result<Vec<_>, _>>()?;
        let rayleigh = match &self.rayleigh {
            Some(text) => parse("rayleigh", text, &all, true)?,
            None => Expr::num(0),
        };
        let (sliding, friction) = self.validate_sliding(file, names, &parse)?;
        let rayleigh = Expr::sum(std::iter::once(rayleigh).chain(friction).collect());
        let contacts =
            self.validate_contacts(file, &names.coordinates, &names.parameters, &parse)?;
        let (constraints, starts, rates) = self.validate_constraints(file, names, &parse)?;
        let (mut points, body_frames) = self.body_frames(names, &parse, &bodies.tensors)?;
        self.validate_points(file, names, &parse, &mut points)?;
        let mut coordinates: Vec<Coordinate> =
            self.coordinates.into_iter().map(Coordinate::from).collect();
        for ((c, start), rate) in coordinates.iter_mut().zip(starts).zip(rates) {
            c.start = start;
            c.start_rate = rate;
        }
        let model = Model {
            name: self.name,
            description: self.description,
            time: self.time,
            coordinates,
            parameters: self.parameters.into_iter().map(Parameter::from).collect(),
            fast_phase,
            definitions,
            lagrangian,
            forces,
            rayleigh,
            contacts,
            sliding,
            constraints,
            points,
            body_frames,
            gravity: bodies.gravity,
            inverse,
            resolved: std::sync::OnceLock::new(),
        };
        model
            .check_numerically()
            .and_then(|()| model.check_constraints_numerically())
            .and_then(|()| model.check_sliding_without_constraints())
            .map_err(|(key, reason)| err(&key, reason))?;
        Ok(model)
    }
}

impl From<CoordinateSpec> for Coordinate {
    fn from(c: CoordinateSpec) -> Coordinate {
        Coordinate {
            name: c.name,
            velocity: c.velocity,
            periodic: c.periodic,
            description: c.description,
            latex: c.latex,
            start: None,
            start_rate: None,
        }
    }
}

impl From<ParameterSpec> for Parameter {
    /// (The range was checked by `check_name_and_size`.)
    fn from(p: ParameterSpec) -> Parameter {
        Parameter {
            range: p
                .range
                .as_deref()
                .map_or(Ok(Range::ALL), Range::parse)
                .expect("checked above"),
            name: p.name,
            default: p.default,
            description: p.description,
            latex: p.latex,
        }
    }
}

/// The names a model file declares, by kind: what its expressions may use.
struct Names {
    coordinates: Vec<String>,
    velocities: Vec<String>,
    parameters: Vec<String>,
    phase: Vec<String>,
    /// The time's name, unless there is a fast phase: explicit time then
    /// enters only through it (so averaging is well defined).
    time: Vec<String>,
    definitions: Vec<String>,
}

impl Names {
    /// What a position may use: coordinates, parameters, the fast phase,
    /// time and definitions (no velocities).
    fn positions(&self) -> [&Vec<String>; 5] {
        [
            &self.coordinates,
            &self.parameters,
            &self.phase,
            &self.time,
            &self.definitions,
        ]
    }

    /// Whether a name may move with the motion: a coordinate or a
    /// definition (a body's turn about it has a rate; a parameter's none).
    fn moves(&self, name: &str) -> bool {
        self.coordinates
            .iter()
            .chain(&self.definitions)
            .any(|n| n == name)
    }

    /// Every kind: what the Lagrangian, forces and Rayleigh function may use.
    fn all(&self) -> [&Vec<String>; 6] {
        [
            &self.coordinates,
            &self.velocities,
            &self.parameters,
            &self.phase,
            &self.time,
            &self.definitions,
        ]
    }
}

/// Parses the expressions of one model file against its declared names.
struct Reader<'f> {
    file: &'f str,
    names: Names,
    /// The time's name, for the hint when a fast phase hides it.
    time_name: &'f str,
}

impl<'f> Reader<'f> {
    fn new(spec: &'f ModelFile, file: &'f str) -> Reader<'f> {
        Reader {
            file,
            names: Names {
                coordinates: spec.coordinates.iter().map(|c| c.name.clone()).collect(),
                velocities: spec
                    .coordinates
                    .iter()
                    .map(|c| c.velocity.clone())
                    .collect(),
                parameters: spec.parameters.iter().map(|p| p.name.clone()).collect(),
                phase: spec.fast_phase.iter().map(|p| p.name.clone()).collect(),
                time: match spec.fast_phase {
                    Some(_) => vec![],
                    None => vec![spec.time.clone()],
                },
                definitions: spec.definitions.keys().cloned().collect(),
            },
            time_name: &spec.time,
        }
    }

    fn error(&self, key: &str, reason: String) -> ModelError {
        ModelError {
            file: self.file.to_string(),
            key: key.to_string(),
            reason,
        }
    }

    /// One expression of the file at `key`: its length, syntax, calls and
    /// symbols (from the `allowed` sets), and where `dot()` may appear.
    fn parse(
        &self,
        key: &str,
        text: &str,
        allowed: &[&Vec<String>],
        dot_allowed: bool,
    ) -> Result<Expr, ModelError> {
        let length = text.chars().count();
        if length > MAX_EXPRESSION_CHARS {
            return Err(self.error(
                key,
                format!(
                    "{length} characters: an expression may have at most {MAX_EXPRESSION_CHARS}"
                ),
            ));
        }
        let expr = Expr::parse(text).map_err(|e| {
            let quoted: String = text.chars().take(60).collect();
            let more = if length > 60 { "…" } else { "" };
            self.error(key, format!("cannot parse '{quoted}{more}': {e}"))
        })?;
        expr.check_calls()
            .map_err(|reason| self.error(key, reason.to_string()))?;
        let expr = with_builtins(expr);
        if let Some(symbol) = expr
            .symbols()
            .into_iter()
            .find(|symbol| !allowed.iter().any(|set| set.contains(symbol)))
        {
            let hint = match self.names.phase.first() {
                Some(phase) if symbol == self.time_name => {
                    format!(" (time enters only through the fast phase '{phase}')")
                }
                _ if symbol == "pi" => " (π is not built in: declare a parameter such as `Pi` with default 3.141592653589793)".to_string(),
                _ => String::new(),
            };
            return Err(self.error(key, format!("unknown symbol '{symbol}'{hint}")));
        }
        match self.dot_problem(&expr, dot_allowed) {
            Some(reason) => Err(self.error(key, reason)),
            None => Ok(expr),
        }
    }

    /// Why a `dot()` in `expr` is not allowed, if one is not.
    fn dot_problem(&self, expr: &Expr, dot_allowed: bool) -> Option<String> {
        let mut problem = None;
        expr.rewrite_calls(&mut |name, args| {
            if name == "dot" && problem.is_none() {
                problem = match (&args[0], dot_allowed) {
                    (_, false) => Some("dot() is only allowed in the Lagrangian, the Rayleigh function and velocity constraints".to_string()),
                    (Expr::Sym(s), true)
                        if self.names.definitions.contains(s)
                            || self.names.coordinates.contains(s) =>
                    {
                        None
                    }
                    (arg, true) => Some(format!(
                        "dot() takes the name of a definition or coordinate, not '{arg}'"
                    )),
                };
            }
            None
        });
        problem
    }
}

/// tan(u) as sin(u)/cos(u), so that the computer algebra's derivatives
/// stay in the sines and cosines the rest of the pipeline reads.
fn with_builtins(expr: Expr) -> Expr {
    expr.rewrite_calls(&mut |name, args| {
        (name == "tan").then(|| {
            let call = |f: &str| Expr::Call(f.into(), args.to_vec());
            Expr::Bin(BinOp::Div, Box::new(call("sin")), Box::new(call("cos")))
        })
    })
}

/// Parses one expression of the file: (key, text, allowed symbol sets, dot() allowed).
/// A validator's errors: in `file`, at a key, for a reason.
fn error_at(file: &str) -> impl Fn(String, String) -> ModelError + '_ {
    move |key, reason| ModelError {
        file: file.to_string(),
        key,
        reason,
    }
}

type ExprParser<'a> = dyn Fn(&str, &str, &[&Vec<String>], bool) -> Result<Expr, ModelError> + 'a;

impl ModelFile {
    /// Contacts: each slides along one coordinate and holds another, every
    /// coordinate takes part in exactly one contact (the contact runtime
    /// integrates the sliding coordinates only), no fast phase.
    fn validate_contacts(
        &self,
        file: &str,
        coordinates: &[String],
        parameters: &Vec<String>,
        parse: &ExprParser,
    ) -> Result<Vec<Contact>, ModelError> {
        let err = error_at(file);
        if self.contacts.is_empty() {
            return Ok(Vec::new());
        }
        if self.fast_phase.is_some() {
            return Err(err(
                "contacts".into(),
                "contacts and a fast phase cannot be combined".into(),
            ));
        }
        let mut used: Vec<&str> = Vec::new();
        let mut contacts = Vec::new();
        for (i, c) in self.contacts.iter().enumerate() {
            for (field, name) in [("slides", &c.slides), ("held", &c.held)] {
                let key = format!("contacts[{i}].{field}");
                if !coordinates.contains(name) {
                    return Err(err(key, format!("'{name}' is not a coordinate")));
                }
                if used.contains(&name.as_str()) {
                    return Err(err(
                        key,
                        format!("'{name}' already takes part in a contact"),
                    ));
                }
                used.push(name);
            }
            contacts.push(Contact {
                slides: c.slides.clone(),
                held: c.held.clone(),
                at: parse(&format!("contacts[{i}].at"), &c.at, &[parameters], false)?,
                friction: parse(
                    &format!("contacts[{i}].friction"),
                    &c.friction,
                    &[parameters],
                    false,
                )?,
                description: c.description.clone(),
            });
        }
        if let Some(free) = coordinates.iter().find(|c| !used.contains(&c.as_str())) {
            return Err(err(
                "contacts".into(),
                format!("coordinate '{free}' takes part in no contact; a model with contacts needs every coordinate to slide or be held"),
            ));
        }
        Ok(contacts)
    }
}

impl ModelFile {
    /// Points: identifiers named once, each at two position expressions,
    /// joined only to earlier points; not with contacts (whose state is not
    /// the coordinates).
    fn validate_points(
        &self,
        file: &str,
        names: &Names,
        parse: &ExprParser,
        points: &mut Vec<Point>,
    ) -> Result<(), ModelError> {
        let err = error_at(file);
        if self.points.is_empty() {
            return Ok(());
        }
        if !self.contacts.is_empty() {
            return Err(err(
                "points".into(),
                "a model with contacts cannot be drawn yet (its state holds the sliding coordinates only)".into(),
            ));
        }
        if self.points.len() > MAX_POINTS {
            return Err(err(
                "points".into(),
                format!(
                    "{} points: a drawing has at most {MAX_POINTS}",
                    self.points.len()
                ),
            ));
        }
        let positions = names.positions();
        for (i, p) in self.points.iter().enumerate() {
            if !is_identifier(&p.name) {
                return Err(err(
                    format!("points[{i}].name"),
                    format!("'{}' is not an identifier", p.name),
                ));
            }
            if points.iter().any(|q| q.name == p.name) {
                return Err(err(
                    format!("points[{i}].name"),
                    format!("'{}' names two points (each body is drawn as its frame: points named as the body and <body>_axis_x, _y, _z)", p.name),
                ));
            }
            let (x, y, z) = match p.at.as_slice() {
                [x, y] => (x, y, "0"),
                [x, y, z] => (x, y, z.as_str()),
                _ => {
                    return Err(err(
                        format!("points[{i}].at"),
                        format!(
                            "give the point '{}' as [x, y] or [x, y, z]: {} expressions given",
                            p.name,
                            p.at.len()
                        ),
                    ))
                }
            };
            let key = format!("points[{i}].at");
            let at = [
                parse(&key, x, &positions, false)?,
                parse(&key, y, &positions, false)?,
                parse(&key, z, &positions, false)?,
            ];
            let joined_to = p
                .joined_to
                .iter()
                .map(|other| {
                    points.iter().position(|q| &q.name == other).ok_or_else(|| {
                        err(
                            format!("points[{i}].joined_to"),
                            format!("'{other}' is not a point declared before '{}'", p.name),
                        )
                    })
                })
                .collect::<Result<Vec<_>, _>>()?;
            points.push(Point {
                name: p.name.clone(),
                at,
                in_space: p.at.len() == 3,
                joined_to,
                description: p.description.clone(),
            });
        }
        Ok(())
    }

    /// Each body drawn as its frame: its centre (named as the body) and
    /// its axes' tips (`<body>_axis_x`, …), the first points of the
    /// drawing (the file's points may join them), and the frames' indices.
    /// (A model with contacts is not drawn: its state holds the sliding
    /// coordinates only.)
    fn body_frames(
        &self,
        names: &Names,
        parse: &ExprParser,
        tensors: &[Inertia],
    ) -> Result<(Vec<Point>, Vec<[usize; 4]>), ModelError> {
        let positions = names.positions();
        let (mut points, mut frames) = (Vec::new(), Vec::new());
        if !self.contacts.is_empty() {
            return Ok((points, frames));
        }
        for (k, (body, tensor)) in self.bodies.iter().zip(tensors).enumerate() {
            let key = format!("bodies[{k}]");
            let frame = crate::bodies::frame(body, tensor);
            let named = [
                body.name.clone(),
                format!("{}_axis_x", body.name),
                format!("{}_axis_y", body.name),
                format!("{}_axis_z", body.name),
            ];
            let mut indices = [0; 4];
            for ((name, at), index) in named.into_iter().zip(frame).zip(&mut indices) {
                let at = at
                    .iter()
                    .map(|c| parse(&format!("{key}.position"), c, &positions, false))
                    .collect::<Result<Vec<_>, _>>()?;
                *index = points.len();
                points.push(Point {
                    name,
                    at: [at[0].clone(), at[1].clone(), at[2].clone()],
                    in_space: true,
                    joined_to: Vec::new(),
                    description: format!("the frame of the body '{}'", body.name),
                });
            }
            frames.push(indices);
        }
        Ok((points, frames))
    }

    /// The material velocity (x, y, z) of the body named at `body_key` at
    /// its point `contact` (read with `contact_key`): a rolling
    /// constraint's or a sliding contact's.
    fn contact_velocity(
        &self,
        (body_key, contact_key): (&str, &str),
        body: &str,
        contact: &[NumberSpec; 3],
        file: &str,
        names: &Names,
        parse: &ExprParser,
    ) -> Result<[Expr; 3], ModelError> {
        let err = error_at(file);
        let Some(k) = self.bodies.iter().position(|b| b.name == body) else {
            return Err(err(
                body_key.to_string(),
                format!("'{body}' is not one of the model's [[bodies]]"),
            ));
        };
        let contact = contact.clone().map(|p| crate::bodies::text(&p));
        for p in &contact {
            parse(contact_key, p, &names.positions(), false)?;
        }
        let moves = |s: &str| names.moves(s);
        let velocity = crate::bodies::point_velocity(&self.bodies[k], &contact, &moves);
        let mut parsed = Vec::new();
        for v in velocity {
            parsed.push(parse(contact_key, &v, &names.all(), true)?);
        }
        Ok(parsed.try_into().expect("three components"))
    }

    /// The sliding contacts, and their friction's terms of the Rayleigh
    /// function, ½ damping (v_x² + v_y²) of each contact's material velocity.
    fn validate_sliding(
        &self,
        file: &str,
        names: &Names,
        parse: &ExprParser,
    ) -> Result<(Vec<Sliding>, Vec<Expr>), ModelError> {
        let err = error_at(file);
        let (mut sliding, mut terms) = (Vec::new(), Vec::new());
        for (i, s) in self.sliding.iter().enumerate() {
            let clash = match is_identifier(&s.name) {
                false => Some("is not an identifier"),
                true if self.sliding[..i].iter().any(|o| o.name == s.name) => {
                    Some("names two sliding contacts")
                }
                true => None,
            };
            if let Some(why) = clash {
                return Err(err(
                    format!("sliding[{i}].name"),
                    format!("'{}' {why}", s.name),
                ));
            }
            let key = format!("sliding[{i}].contact");
            let [x, y, normal] = self.contact_velocity(
                (&format!("sliding[{i}].body"), &key),
                &s.body,
                &s.contact,
                file,
                names,
                parse,
            )?;
            let damping = parse(
                &format!("sliding[{i}].damping"),
                &crate::bodies::text(&s.damping),
                &[&names.parameters],
                false,
            )?;
            let bin = |op, a: Expr, b: Expr| Expr::Bin(op, Box::new(a), Box::new(b));
            let square = |v: Expr| bin(BinOp::Pow, v, Expr::num(2));
            let speed = Expr::sum(vec![square(x.clone()), square(y)]);
            let half = bin(BinOp::Div, damping, Expr::num(2));
            terms.push(bin(BinOp::Mul, half, speed));
            sliding.push(Sliding {
                name: s.name.clone(),
                key,
                normal,
                along: x,
            });
        }
        Ok((sliding, terms))
    }

    /// Bodies: each one's parts read with its own key, then its kinetic
    /// energy and gravity's potential as terms of the Lagrangian.
    fn validate_bodies(
        &self,
        file: &str,
        names: &Names,
        parse: &ExprParser,
    ) -> Result<ReadBodies, ModelError> {
        let err = error_at(file);
        let parameters = [&names.parameters];
        let positions = names.positions();
        if self.gravity.is_some() && self.bodies.is_empty() {
            return Err(err("gravity".into(), "gravity acts on the model's [[bodies]] and this model has none: write its potential in the Lagrangian".into()));
        }
        let gravity = match &self.gravity {
            Some([x, y, z]) => {
                let read = |c| parse("gravity", &crate::bodies::text(c), &parameters, false);
                Some([read(x)?, read(y)?, read(z)?])
            }
            None => None,
        };
        let (mut energies, mut tensors) = (Vec::new(), Vec::new());
        for (k, body) in self.bodies.iter().enumerate() {
            let key = |part: &str| format!("bodies[{k}].{part}");
            if !is_identifier(&body.name) {
                return Err(err(
                    key("name"),
                    format!("'{}' is not an identifier", body.name),
                ));
            }
            if self.bodies[..k].iter().any(|b| b.name == body.name) {
                return Err(err(
                    key("name"),
                    format!("'{}' names two bodies", body.name),
                ));
            }
            parse(
                &key("mass"),
                &crate::bodies::text(&body.mass),
                &parameters,
                false,
            )?;
            let tensor = crate::bodies::inertia(&body.inertia)
                .map_err(|(part, reason)| err(key(part), reason))?;
            for moment in tensor.iter().flatten().flatten() {
                parse(&key("inertia"), moment, &parameters, false)?;
            }
            for at in &body.position {
                parse(
                    &key("position"),
                    &crate::bodies::text(at),
                    &positions,
                    false,
                )?;
            }
            for turn in &body.turns {
                parse(&key("rotation"), &turn.angle, &positions, false)?;
            }
            for at in body.centre.iter().flatten() {
                parse(&key("centre"), &crate::bodies::text(at), &parameters, false)?;
            }
            for (point, offset) in &body.points {
                let part = format!("points.{point}");
                if !is_identifier(point) {
                    return Err(err(key(&part), format!("'{point}' is not an identifier")));
                }
                for at in offset {
                    parse(&key(&part), &crate::bodies::text(at), &parameters, false)?;
                }
            }
            if let Some(e) = &body.quaternion {
                if !body.rotation.trim().is_empty() {
                    return Err(err(key("quaternion"), "give the orientation once: a `rotation` sequence or the `quaternion`'s four coordinates".into()));
                }
                if let Some(c) = e.iter().find(|c| !names.coordinates.contains(c)) {
                    return Err(err(key("quaternion"), format!("'{c}' is not a coordinate: the Euler parameters are four of the model's coordinates")));
                }
            }
            let moves = |s: &str| names.moves(s);
            let energy = crate::bodies::energy(body, &tensor, self.gravity.as_ref(), &moves);
            let energy = Expr::parse(&energy).map_err(|e| {
                err(
                    key("name"),
                    format!("its kinetic energy cannot be read back ({e})"),
                )
            })?;
            energies.push(energy);
            tensors.push(tensor);
        }
        Ok(ReadBodies {
            energies,
            tensors,
            gravity,
        })
    }

    /// Constraints: each a position or a velocity expression, named once;
    /// fewer than the coordinates; not with contacts; and a start for
    /// every coordinate. Returns them, the coordinates' starts and their
    /// starting rates.
    #[allow(clippy::type_complexity)]
    fn validate_constraints(
        &self,
        file: &str,
        names: &Names,
        parse: &ExprParser,
    ) -> Result<(Vec<Constraint>, Vec<Option<Expr>>, Vec<Option<Expr>>), ModelError> {
        let err = error_at(file);
        let number = |key: String, spec: &NumberSpec, what: String| match spec {
            NumberSpec::Value(v) if !v.is_finite() => {
                Err(err(key, format!("{what} is not finite")))
            }
            NumberSpec::Value(v) => Ok(Expr::Num(format!("{v:?}"))),
            NumberSpec::Expression(text) => parse(&key, text, &[&names.parameters], false),
        };
        let starts = self
            .coordinates
            .iter()
            .enumerate()
            .map(|(i, c)| {
                let key = format!("coordinates[{i}].start");
                match &c.start {
                    None if !self.constraints.is_empty() => Err(err(key, format!("a model with constraints needs a start for '{}': its value in a configuration that satisfies the constraints at t = 0 with the default parameters", c.name))),
                    None => Ok(None),
                    Some(spec) => number(key, spec, format!("the start of '{}'", c.name)).map(Some),
                }
            })
            .collect::<Result<Vec<_>, _>>()?;
        let rates = self
            .coordinates
            .iter()
            .enumerate()
            .map(|(i, c)| {
                let key = format!("coordinates[{i}].start_rate");
                match &c.start_rate {
                    None => Ok(None),
                    Some(_) if !self.contacts.is_empty() => Err(err(key, format!("a starting rate of '{}' is not read by a model with contacts, whose runs start from the state they are given", c.name))),
                    Some(spec) => number(key, spec, format!("the starting rate of '{}'", c.name)).map(Some),
                }
            })
            .collect::<Result<Vec<_>, _>>()?;
        if self.constraints.is_empty() {
            return Ok((Vec::new(), starts, rates));
        }
        if !self.contacts.is_empty() {
            return Err(err(
                "constraints".into(),
                "constraints and contacts cannot be combined (a contact's guide is its constraint)"
                    .into(),
            ));
        }
        let positions = names.positions();
        let mut constraints = Vec::new();
        for (i, c) in self.constraints.iter().enumerate() {
            if !is_identifier(&c.name) {
                return Err(err(
                    format!("constraints[{i}].name"),
                    format!("'{}' is not an identifier", c.name),
                ));
            }
            if self.constraints[..i].iter().any(|d| d.name == c.name) {
                return Err(err(
                    format!("constraints[{i}].name"),
                    format!("'{}' names two constraints", c.name),
                ));
            }
            let made = |kind, name: String, normal| Constraint {
                key: match (&kind, &c.rolling) {
                    (_, Some(_)) => format!("constraints[{i}].rolling"),
                    (ConstraintKind::Position(_), None) => format!("constraints[{i}].position"),
                    (ConstraintKind::Velocity(_), None) => format!("constraints[{i}].velocity"),
                },
                name,
                kind,
                description: c.description.clone(),
                normal,
            };
            let kind = match (&c.position, &c.velocity, &c.rolling, &c.contact) {
                (Some(text), None, None, None) => ConstraintKind::Position(parse(
                    &format!("constraints[{i}].position"),
                    text,
                    &positions,
                    false,
                )?),
                (None, Some(text), None, None) => ConstraintKind::Velocity(parse(
                    &format!("constraints[{i}].velocity"),
                    text,
                    &names.all(),
                    true,
                )?),
                (None, None, Some(body), Some(contact)) => {
                    let [along_x, along_y, normal] = self.contact_velocity(
                        (&format!("constraints[{i}].rolling"), &format!("constraints[{i}].contact")),
                        body,
                        contact,
                        file,
                        names,
                        parse,
                    )?;
                    constraints.push(made(ConstraintKind::Velocity(along_x), format!("{}_x", c.name), None));
                    constraints.push(made(ConstraintKind::Velocity(along_y), format!("{}_y", c.name), Some(normal)));
                    continue;
                }
                _ => {
                    return Err(err(
                        format!("constraints[{i}]"),
                        "give exactly one of `position` (an expression of the positions that vanishes), `velocity` (one linear in the velocities that vanishes) and `rolling` (a body's name) with `contact` (where it touches the plane)".into(),
                    ))
                }
            };
            constraints.push(made(kind, c.name.clone(), None));
        }
        Ok((constraints, starts, rates))
    }
}

impl Model {
    pub fn dof(&self) -> usize {
        self.coordinates.len()
    }

    /// A parameter's default value by name (None for another name).
    fn default_of(&self, name: &str) -> Option<f64> {
        self.parameters
            .iter()
            .find(|p| p.name == name)
            .map(|p| p.default)
    }

    /// The coordinates' starts at the default parameters, 0 where a file
    /// gives none (or one that is not finite there): where the numerical
    /// checks sample the model.
    pub fn start_or_zero(&self) -> Vec<f64> {
        let defaults = |s: &str| self.default_of(s);
        self.coordinates
            .iter()
            .map(|c| {
                c.start
                    .as_ref()
                    .and_then(|e| e.eval(&defaults).ok())
                    .filter(|x| x.is_finite())
                    .unwrap_or(0.0)
            })
            .collect()
    }

    /// The Lagrangian with definitions substituted and `dot` expanded as a
    /// total time derivative: Σ ∂x/∂q_i q'_i + rate ∂x/∂θ + ∂x/∂t.
    /// Unsimplified; used for numerical checks (the build derives it again with Symbolica).
    pub fn expanded_lagrangian(&self) -> Expr {
        self.expanded(&self.lagrangian)
    }

    /// An expression of the file with definitions substituted and `dot`
    /// expanded as in [`Model::expanded_lagrangian`].
    pub fn expanded(&self, e: &Expr) -> Expr {
        let resolved = self.resolved.get_or_init(|| self.resolved_definitions());
        let lookup = |s: &str| {
            resolved
                .iter()
                .find(|(n, _)| n == s)
                .map(|(_, e)| e.clone())
        };
        let total_derivative = |x: &Expr| {
            let mut terms: Vec<Expr> = self
                .coordinates
                .iter()
                .map(|c| {
                    Expr::Bin(
                        super::expr::BinOp::Mul,
                        Box::new(x.derivative(&c.name)),
                        Box::new(Expr::Sym(c.velocity.clone())),
                    )
                })
                .collect();
            if let Some(p) = &self.fast_phase {
                terms.push(Expr::Bin(
                    super::expr::BinOp::Mul,
                    Box::new(p.rate.clone()),
                    Box::new(x.derivative(&p.name)),
                ));
            } else {
                terms.push(x.derivative(&self.time));
            }
            Expr::sum(terms)
        };
        // Each name's rate derived once (a body's centre appears in its
        // energy once per axis and again in every contact).
        let mut rates: BTreeMap<String, Expr> = BTreeMap::new();
        e.rewrite_calls(&mut |name, args| match (name, &args[0]) {
            ("dot", Expr::Sym(s)) => Some(
                rates
                    .entry(s.clone())
                    .or_insert_with(|| {
                        total_derivative(&lookup(s).unwrap_or_else(|| Expr::Sym(s.clone())))
                    })
                    .clone(),
            ),
            _ => None,
        })
        .substitute(&lookup)
    }

    /// Definitions with every other definition substituted.
    pub fn resolved_definitions(&self) -> Vec<(String, Expr)> {
        let mut resolved: Vec<(String, Expr)> = Vec::new();
        for (name, e) in &self.definitions {
            let r = e.substitute(&|s| {
                resolved
                    .iter()
                    .find(|(n, _)| n == s)
                    .map(|(_, e)| e.clone())
            });
            resolved.push((name.clone(), r));
        }
        resolved
    }

    /// Checks at sample states that L is finite, quadratic in the velocities,
    /// with a positive definite mass matrix; and that the phase rate is finite and non-zero.
    fn check_numerically(&self) -> Result<(), (String, String)> {
        let n = self.dof();
        let lagrangian = self.expanded_lagrangian();
        // Massless parts: M may be singular, not indefinite; the
        // constraints' check asks it to be regular on their motions.
        let massless = self.has_massless_parts();
        let mut random = uniform(0x9E37_79B9_7F4A_7C15);
        let params = |s: &str| self.default_of(s);
        if let Some(p) = &self.fast_phase {
            let rate = p
                .rate
                .eval(&params)
                .map_err(|e| ("fast_phase.rate".to_string(), e.to_string()))?;
            if !rate.is_finite() || rate == 0.0 {
                return Err((
                    "fast_phase.rate".into(),
                    format!(
                        "rate is {rate} at the default parameters; it must be finite and non-zero"
                    ),
                ));
            }
        }
        // Samples around the coordinates' starts (0 where a file gives
        // none), as far as 3 from them; a point where L is not finite lies
        // outside the model's domain (a square root of a negative number, a
        // chart's edge) and is replaced by one nearer the start, so that a
        // model defined only near its start is checked there, not refused.
        let centre = self.start_or_zero();
        let (mut spread, mut checked, mut outside) = (3.0, 0, 0);
        while checked < 5 {
            let q: Vec<f64> = centre.iter().map(|c| c + spread * random()).collect();
            let v: Vec<f64> = (0..n).map(|_| random()).collect();
            let phase = 3.0 * random();
            let time = random();
            let at = |velocity: &[f64]| {
                Sample {
                    model: self,
                    q: q.clone(),
                    v: velocity.to_vec(),
                    phase,
                    time,
                }
                .try_eval(&lagrangian)
            };
            let scaled = |s: f64| v.iter().map(|x| s * x).collect::<Vec<_>>();
            let l: Vec<f64> = [-1.0, 0.0, 1.0, 2.0]
                .iter()
                .map(|&s| at(&scaled(s)))
                .collect::<Result<_, _>>()
                .map_err(|e| ("lagrangian".to_string(), e.to_string()))?;
            if l.iter().any(|x| !x.is_finite()) {
                outside += 1;
                if outside == 40 {
                    return Err((
                        "lagrangian".into(),
                        format!("not finite at any of 40 points near the start q = {centre:?} (the last at q = {q:?}, q' = {v:?}); give each coordinate a `start` where the model is defined"),
                    ));
                }
                spread /= 2.0;
                continue;
            }
            checked += 1;
            let third_difference = l[3] - 3.0 * l[2] + 3.0 * l[1] - l[0];
            let scale = l.iter().map(|x| x.abs()).fold(1.0, f64::max);
            if third_difference.abs() > 1e-8 * scale {
                return Err(("lagrangian".into(), "is not quadratic in the velocities (its third derivative along a velocity direction is non-zero)".into()));
            }
            let mass = polarised_mass(n, |w| at(w).unwrap_or(f64::NAN));
            if massless && !semidefinite(&mass) {
                return Err(("lagrangian".into(), format!("mass matrix ∂²L/∂q'² = {mass:?} at q = {q:?} is not positive semidefinite: a kinetic energy that is negative along some velocity")));
            }
            if !massless && !cholesky_ok(&mass) {
                return Err(("lagrangian".into(), format!("mass matrix ∂²L/∂q'² = {mass:?} at q = {q:?} is singular or not positive definite")));
            }
        }
        Ok(())
    }
}

/// A model's expressions evaluated at coordinates, velocities, phase and
/// time with the default parameters (for the numerical checks).
#[derive(Clone)]
struct Sample<'m> {
    model: &'m Model,
    q: Vec<f64>,
    v: Vec<f64>,
    phase: f64,
    time: f64,
}

impl Sample<'_> {
    fn value(&self, s: &str) -> Option<f64> {
        let model = self.model;
        if let Some(i) = model.coordinates.iter().position(|c| c.name == s) {
            return Some(self.q[i]);
        }
        if let Some(i) = model.coordinates.iter().position(|c| c.velocity == s) {
            return Some(self.v[i]);
        }
        if model.fast_phase.as_ref().is_some_and(|p| p.name == s) {
            return Some(self.phase);
        }
        if s == model.time {
            return Some(self.time);
        }
        model
            .parameters
            .iter()
            .find(|p| p.name == s)
            .map(|p| p.default)
    }

    fn try_eval(&self, e: &Expr) -> Result<f64, crate::expr::EvalError> {
        e.eval(&|s| self.value(s))
    }

    fn eval(&self, e: &Expr) -> f64 {
        self.try_eval(e).unwrap_or(f64::NAN)
    }

    /// ∂e/∂q_j here (forward mode; NaN where e cannot be evaluated).
    fn rate_along(&self, e: &Expr, j: usize) -> f64 {
        let name = &self.model.coordinates[j].name;
        e.eval_rate(&|s| {
            self.value(s)
                .map(|x| (x, if s == name { 1.0 } else { 0.0 }))
        })
        .map_or(f64::NAN, |(_, rate)| rate)
    }
}

impl Model {
    /// At the starts (t = 0, default parameters): every position
    /// constraint vanishes, every velocity constraint is linear in the
    /// velocities and not integrable, and together their rows
    /// (∂g/∂q for a position constraint, ∂c/∂q' for a velocity one) have
    /// full rank: none is redundant or inconsistent with the others.
    fn check_constraints_numerically(&self) -> Result<(), (String, String)> {
        if self.constraints.is_empty() {
            return Ok(());
        }
        let n = self.dof();
        let defaults = |s: &str| self.default_of(s);
        let mut start = Vec::new();
        for (i, c) in self.coordinates.iter().enumerate() {
            let value = c
                .start
                .as_ref()
                .map(|e| e.eval(&defaults))
                .transpose()
                .map_err(|e| (format!("coordinates[{i}].start"), e.to_string()))?
                .unwrap_or(f64::NAN);
            if !value.is_finite() {
                return Err((
                    format!("coordinates[{i}].start"),
                    format!(
                        "the start of '{}' is {value} with the default parameters",
                        c.name
                    ),
                ));
            }
            start.push(value);
        }
        let at_start = Sample {
            model: self,
            q: start.clone(),
            v: vec![0.0; n],
            phase: 0.0,
            time: 0.0,
        };
        let size = 1.0 + start.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        let mut rows = Vec::new();
        for (r, constraint) in self.constraints.iter().enumerate() {
            let expanded = self.expanded(constraint.kind.expression());
            let row: Vec<Expr> = match &constraint.kind {
                ConstraintKind::Position(_) => self
                    .coordinates
                    .iter()
                    .map(|c| expanded.derivative(&c.name))
                    .collect(),
                ConstraintKind::Velocity(_) => self
                    .coordinates
                    .iter()
                    .map(|c| expanded.derivative(&c.velocity))
                    .collect(),
            };
            let values: Vec<f64> = row.iter().map(|e| at_start.eval(e)).collect();
            let gradient = values.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
            match &constraint.kind {
                ConstraintKind::Position(_) => {
                    let residual = at_start.eval(&expanded);
                    if !(residual.abs() <= 1e-9 * size * gradient.max(1.0)) {
                        return Err((
                            constraint.key.clone(),
                            format!("the coordinates' starts violate '{}': its value there is {residual:.3e} (t = 0, default parameters); give starts that satisfy every position constraint", constraint.name),
                        ));
                    }
                }
                ConstraintKind::Velocity(_) => {
                    self.check_velocity_constraint(r, &expanded, &row, &at_start)?
                }
            }
            rows.push(values);
        }
        self.check_contacts_stay_on_the_plane(&at_start)?;
        // Redundant constraints are kept (the runtime skips their rows);
        // inconsistent ones, or ones that leave no motion, are not.
        let rank_of_rows = rank(rows.clone());
        let augmented: Vec<Vec<f64>> = rows
            .iter()
            .zip(&self.constraints)
            .map(|(row, c)| {
                let mut row = row.clone();
                row.push(at_start.eval(&self.constraint_rate(c)));
                row
            })
            .collect();
        if rank(augmented) > rank_of_rows {
            return Err((
                "constraints".into(),
                format!("the constraints are inconsistent at the starts: their rows (∂g/∂q of a position constraint, ∂c/∂q' of a velocity one) have rank {rank_of_rows}, but with their rates (∂g/∂t, the velocity constraints' terms free of velocities) more: no velocity satisfies them all"),
            ));
        }
        if rank_of_rows >= n {
            return Err((
                "constraints".into(),
                format!("the constraints leave no motion: at the starts they fix all {n} coordinates (their rows have rank {rank_of_rows}); a model needs fewer independent constraints than coordinates"),
            ));
        }
        self.check_start_rates(&rows, &at_start)?;
        if let Some(mass) = self.mass_matrix_at_start().filter(|m| !cholesky_ok(m)) {
            if !cholesky_ok(&augmented_mass(&mass, &rows)) {
                return Err((
                    "lagrangian".into(),
                    format!("the mass matrix ∂²L/∂q'² = {mass:?} at the starts is singular along a motion the constraints allow: a massless part must be held by the constraints (M positive definite on the velocities they leave)"),
                ));
            }
        }
        Ok(())
    }

    /// The starting rates the file gives leave the velocity constraints
    /// solvable for the others at the starts: G_free v_free = −(c_t +
    /// G_given v_given) has a solution (`rows` are G's rows there).
    fn check_start_rates(
        &self,
        rows: &[Vec<f64>],
        at_start: &Sample,
    ) -> Result<(), (String, String)> {
        let defaults = |s: &str| self.default_of(s);
        let mut given = Vec::new();
        for (i, c) in self.coordinates.iter().enumerate() {
            if let Some(rate) = &c.start_rate {
                let value = rate
                    .eval(&defaults)
                    .map_err(|e| (format!("coordinates[{i}].start_rate"), e.to_string()))?;
                given.push((i, value));
            }
        }
        if given.is_empty() {
            return Ok(());
        }
        let free: Vec<usize> = (0..self.dof())
            .filter(|i| given.iter().all(|(j, _)| j != i))
            .collect();
        let reduced: Vec<Vec<f64>> = rows
            .iter()
            .map(|row| free.iter().map(|&i| row[i]).collect())
            .collect();
        let augmented: Vec<Vec<f64>> = rows
            .iter()
            .zip(&self.constraints)
            .zip(&reduced)
            .map(|((row, c), reduced)| {
                let rest = at_start.eval(&self.constraint_rate(c))
                    + given.iter().map(|&(i, v)| row[i] * v).sum::<f64>();
                let mut reduced = reduced.clone();
                reduced.push(rest);
                reduced
            })
            .collect();
        if rank(augmented) > rank(reduced) {
            let (i, _) = given[0];
            return Err((
                format!("coordinates[{i}].start_rate"),
                "the starting rates given leave no velocity of the other coordinates that satisfies the constraints at the starts (default parameters): give fewer, or rates the constraints allow".into(),
            ));
        }
        Ok(())
    }

    /// M = ∂²L/∂q'² at the coordinates' starts (t = 0, the fast phase 0,
    /// the default parameters), by polarisation; None where L is not
    /// finite there.
    pub fn mass_matrix_at_start(&self) -> Option<Vec<Vec<f64>>> {
        let lagrangian = self.expanded_lagrangian();
        let n = self.dof();
        let q = self.start_or_zero();
        let mass = polarised_mass(n, |v| {
            Sample {
                model: self,
                q: q.clone(),
                v: v.to_vec(),
                phase: 0.0,
                time: 0.0,
            }
            .try_eval(&lagrangian)
            .unwrap_or(f64::NAN)
        });
        mass.iter().flatten().all(|x| x.is_finite()).then_some(mass)
    }

    /// Whether the model has massless parts: constraints, and a mass
    /// matrix that is singular at the starts. Its equations are then
    /// solved with M + α GᵀG in place of M and F − α Gᵀh in place of F
    /// (α = tr M / tr GᵀG), which gives the same accelerations and
    /// reactions wherever M is regular on the constraints' motions.
    pub fn has_massless_parts(&self) -> bool {
        !self.constraints.is_empty()
            && self
                .mass_matrix_at_start()
                .is_some_and(|mass| !cholesky_ok(&mass))
    }

    /// What a constraint's velocity form has besides the velocities: ∂g/∂t
    /// (with the fast phase's rate) of a position constraint, the terms
    /// free of velocities of a velocity one (evaluated with q' = 0).
    fn constraint_rate(&self, constraint: &Constraint) -> Expr {
        let expanded = self.expanded(constraint.kind.expression());
        match &constraint.kind {
            ConstraintKind::Velocity(_) => expanded,
            ConstraintKind::Position(_) => {
                let mut rate = expanded.derivative(&self.time);
                if let Some(phase) = &self.fast_phase {
                    rate = Expr::sum(vec![
                        rate,
                        Expr::Bin(
                            crate::expr::BinOp::Mul,
                            Box::new(phase.rate.clone()),
                            Box::new(expanded.derivative(&phase.name)),
                        ),
                    ]);
                }
                rate
            }
        }
    }

    /// A sliding contact's plane, in a model without constraints: checked
    /// as a rolling one's, at its start (or 0).
    fn check_sliding_without_constraints(&self) -> Result<(), (String, String)> {
        if self.sliding.is_empty() || !self.constraints.is_empty() {
            return Ok(());
        }
        let at_start = Sample {
            model: self,
            q: self.start_or_zero(),
            v: vec![0.0; self.dof()],
            phase: 0.0,
            time: 0.0,
        };
        self.check_contacts_stay_on_the_plane(&at_start)
    }

    /// A rolling or sliding body's contact point is where it touches the
    /// plane: its material velocity along the normal vanishes for every
    /// motion the constraints allow (their rows' null space, at random), at
    /// the start and, where no position constraint pins the configuration,
    /// near it.
    fn check_contacts_stay_on_the_plane(&self, at_start: &Sample) -> Result<(), (String, String)> {
        let rolling = self.constraints.iter().filter_map(|c| {
            let normal = c.normal.as_ref()?;
            Some((
                c.key.replace(".rolling", ".contact"),
                normal,
                c.kind.expression(),
            ))
        });
        let sliding = self
            .sliding
            .iter()
            .map(|s| (s.key.clone(), &s.normal, &s.along));
        let on_planes: Vec<(String, &Expr, &Expr)> = rolling.chain(sliding).collect();
        if on_planes.is_empty() {
            return Ok(());
        }
        let n = self.dof();
        let rows: Vec<Vec<Expr>> = self
            .constraints
            .iter()
            .map(|c| {
                let expanded = self.expanded(c.kind.expression());
                self.coordinates
                    .iter()
                    .map(|q| match &c.kind {
                        ConstraintKind::Position(_) => expanded.derivative(&q.name),
                        ConstraintKind::Velocity(_) => expanded.derivative(&q.velocity),
                    })
                    .collect()
            })
            .collect();
        let pinned = self
            .constraints
            .iter()
            .any(|c| matches!(c.kind, ConstraintKind::Position(_)));
        // Each contact's velocity across the plane and along it, and their
        // gradients in the velocities (the scale), derived once.
        let contacts: Vec<(String, Expr, Vec<(Expr, Expr)>)> = on_planes
            .into_iter()
            .map(|(key, normal, along)| {
                let normal = self.expanded(normal);
                let along = self.expanded(along);
                let gradients = self
                    .coordinates
                    .iter()
                    .map(|c| {
                        (
                            normal.derivative(&c.velocity),
                            along.derivative(&c.velocity),
                        )
                    })
                    .collect();
                (key, normal, gradients)
            })
            .collect();
        let mut random = uniform(0x9E37_79B9_7F4A_7C15);
        for sample in 0..4 {
            let q: Vec<f64> = at_start
                .q
                .iter()
                .map(|x| {
                    if sample == 0 || pinned {
                        *x
                    } else {
                        x + 0.5 * random()
                    }
                })
                .collect();
            let point = Sample {
                q,
                ..at_start.clone()
            };
            let values: Vec<Vec<f64>> = rows
                .iter()
                .map(|row| row.iter().map(|e| point.eval(e)).collect())
                .collect();
            let v = project_out(&values, (0..n).map(|_| random()).collect());
            let moving = Sample { v, ..point.clone() };
            for (key, normal, gradients) in &contacts {
                // The scale: the contact's velocity along the plane and
                // across it, per unit speed.
                let gradient: f64 = gradients
                    .iter()
                    .map(|(across, on)| {
                        let (across, on) = (point.eval(across), point.eval(on));
                        across * across + on * on
                    })
                    .sum::<f64>()
                    .sqrt();
                let speed = moving.v.iter().map(|x| x * x).sum::<f64>().sqrt();
                let off = moving.eval(normal);
                if !(off.abs() <= 1e-8 * gradient * speed) {
                    return Err((
                        key.clone(),
                        format!("the body's material point at the contact moves off the plane (normal velocity {off:.3e} in a motion the constraints allow near the start): `contact` is not where the body touches the plane"),
                    ));
                }
            }
        }
        Ok(())
    }

    /// A velocity constraint c = a(q)·q' + b: linear in the velocities, and
    /// not integrable (the 1-form a·dq has a·dq ∧ d(a·dq) ≠ 0 somewhere
    /// near the start; otherwise it is a position constraint in disguise).
    fn check_velocity_constraint(
        &self,
        r: usize,
        expanded: &Expr,
        row: &[Expr],
        at_start: &Sample,
    ) -> Result<(), (String, String)> {
        let key = self.constraints[r].key.clone();
        let name = &self.constraints[r].name;
        let n = self.dof();
        let mut random = uniform(0x2545_F491_4F6C_DD1D);
        let mut integrable = true;
        for sample in 0..4 {
            let q: Vec<f64> = at_start
                .q
                .iter()
                .map(|x| if sample == 0 { *x } else { x + 0.3 * random() })
                .collect();
            let v: Vec<f64> = (0..n).map(|_| random()).collect();
            let along = |s: f64| {
                Sample {
                    model: self,
                    q: q.clone(),
                    v: v.iter().map(|x| s * x).collect(),
                    phase: 0.0,
                    time: 0.0,
                }
                .eval(expanded)
            };
            let c: Vec<f64> = [-1.0, 0.0, 1.0].iter().map(|&s| along(s)).collect();
            let scale = c.iter().fold(1.0_f64, |m, x| m.max(x.abs()));
            if !((c[2] - 2.0 * c[1] + c[0]).abs() <= 1e-9 * scale) {
                return Err((
                    key,
                    format!("'{name}' is not linear in the velocities (a velocity constraint is a(q, t)·q' + b(q, t))"),
                ));
            }
            // One sample where the 1-form is not closed suffices: the
            // others check linearity only.
            if !integrable {
                continue;
            }
            let point = Sample {
                model: self,
                q,
                v: vec![0.0; n],
                phase: 0.0,
                time: 0.0,
            };
            let a: Vec<f64> = row.iter().map(|e| point.eval(e)).collect();
            // ∂a_k/∂q_j, by forward mode along each coordinate.
            let da: Vec<Vec<f64>> = row
                .iter()
                .map(|e| (0..n).map(|j| point.rate_along(e, j)).collect())
                .collect();
            // a·dq ∧ d(a·dq), component (i, j, k): a_i (∂_j a_k − ∂_k a_j) + cyclic.
            for i in 0..n {
                for j in i + 1..n {
                    for k in j + 1..n {
                        let terms = [
                            a[i] * (da[k][j] - da[j][k]),
                            a[j] * (da[i][k] - da[k][i]),
                            a[k] * (da[j][i] - da[i][j]),
                        ];
                        let total: f64 = terms.iter().sum();
                        let scale: f64 = terms.iter().map(|t| t.abs()).sum();
                        if total.abs() > 1e-9 * scale {
                            integrable = false;
                        }
                    }
                }
            }
        }
        if integrable {
            return Err((
                key,
                format!("'{name}' is integrable (its 1-form a·dq has a·dq ∧ d(a·dq) = 0 near the start): it holds a function of the positions constant, so write that function as a `position` constraint"),
            ));
        }
        Ok(())
    }
}

/// The numerical rank of a matrix given by rows (Gaussian elimination with
/// partial pivoting, relative tolerance 1e-9).
fn rank(mut rows: Vec<Vec<f64>>) -> usize {
    let scale = rows.iter().flatten().fold(0.0_f64, |m, x| m.max(x.abs()));
    let columns = rows.first().map_or(0, Vec::len);
    let mut rank = 0;
    for column in 0..columns {
        let Some(pivot) = (rank..rows.len())
            .max_by(|&a, &b| rows[a][column].abs().total_cmp(&rows[b][column].abs()))
        else {
            break;
        };
        if !(rows[pivot][column].abs() > 1e-9 * scale) {
            continue;
        }
        rows.swap(rank, pivot);
        for r in rank + 1..rows.len() {
            let factor = rows[r][column] / rows[rank][column];
            for c in column..columns {
                rows[r][c] -= factor * rows[rank][c];
            }
        }
        rank += 1;
    }
    rank
}

/// `v` less its components along `rows` (modified Gram–Schmidt): a
/// vector of their null space.
fn project_out(rows: &[Vec<f64>], mut v: Vec<f64>) -> Vec<f64> {
    let mut basis: Vec<Vec<f64>> = Vec::new();
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    for row in rows {
        let mut u = row.clone();
        for b in &basis {
            let along = dot(&u, b);
            u.iter_mut().zip(b).for_each(|(x, y)| *x -= along * y);
        }
        let length = dot(&u, &u).sqrt();
        if length > 1e-9 * dot(row, row).sqrt() {
            basis.push(u.iter().map(|x| x / length).collect());
        }
    }
    for _ in 0..2 {
        for b in &basis {
            let along = dot(&v, b);
            v.iter_mut().zip(b).for_each(|(x, y)| *x -= along * y);
        }
    }
    v
}

/// A reproducible stream of numbers uniform in [−1, 1) (xorshift), for the
/// sample states of the numerical checks.
fn uniform(mut seed: u64) -> impl FnMut() -> f64 {
    move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }
}

/// The mass matrix of a Lagrangian quadratic in the velocities, by
/// polarisation of its values `at` velocities (exact for a quadratic).
fn polarised_mass(n: usize, at: impl Fn(&[f64]) -> f64) -> Vec<Vec<f64>> {
    let unit = |i: usize, j: usize, si: f64, sj: f64| {
        let mut w = vec![0.0; n];
        w[i] += si;
        w[j] += sj;
        at(&w)
    };
    let mut mass = vec![vec![0.0; n]; n];
    for i in 0..n {
        for j in 0..n {
            mass[i][j] = if i == j {
                unit(i, i, 1.0, 0.0) + unit(i, i, -1.0, 0.0) - 2.0 * unit(i, i, 0.0, 0.0)
            } else {
                (unit(i, j, 1.0, 1.0) - unit(i, j, 1.0, -1.0) - unit(i, j, -1.0, 1.0)
                    + unit(i, j, -1.0, -1.0))
                    / 4.0
            };
        }
    }
    mass
}

/// M + α GᵀG with α = tr M / tr GᵀG (`rows` the rows of G): positive
/// definite exactly where M is on the velocities the rows leave.
fn augmented_mass(mass: &[Vec<f64>], rows: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let n = mass.len();
    let trace: f64 = (0..n).map(|i| mass[i][i]).sum();
    let norm: f64 = rows.iter().flatten().map(|x| x * x).sum();
    let alpha = if norm > 0.0 { trace / norm } else { 0.0 };
    (0..n)
        .map(|i| {
            (0..n)
                .map(|j| mass[i][j] + alpha * rows.iter().map(|r| r[i] * r[j]).sum::<f64>())
                .collect()
        })
        .collect()
}

/// Positive semidefinite to round-off: positive definite once a
/// millionth of its largest diagonal entry is added to the diagonal.
fn semidefinite(a: &[Vec<f64>]) -> bool {
    let scale = (0..a.len()).map(|i| a[i][i].abs()).fold(0.0, f64::max);
    let mut shifted = a.to_vec();
    for (i, row) in shifted.iter_mut().enumerate() {
        row[i] += 1e-6 * scale.max(f64::MIN_POSITIVE);
    }
    cholesky_ok(&shifted)
}

fn cholesky_ok(a: &[Vec<f64>]) -> bool {
    let n = a.len();
    let scale = (0..n).map(|i| a[i][i].abs()).fold(0.0, f64::max);
    let mut l = vec![vec![0.0; n]; n];
    for i in 0..n {
        for j in 0..=i {
            let s: f64 = (0..j).map(|k| l[i][k] * l[j][k]).sum();
            if i == j {
                let d = a[i][i] - s;
                if !(d > 1e-10 * scale) {
                    return false;
                }
                l[i][i] = d.sqrt();
            } else {
                l[i][j] = (a[i][j] - s) / l[j][j];
            }
        }
    }
    true
}
