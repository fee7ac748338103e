//! Each analysis's settings, declared once (`declare_settings!`): every
//! setting's name, type, default, range and help text live in one place,
//! and the front ends are derived from it — the scenes' `--set` knobs and
//! `--help`, the studio's JSON requests and `GET /api/schema`, the Python
//! module's keyword arguments and its type stub, and the reference of the
//! analyses in the docs. A value is checked in one place,
//! [`Declared::validate`], whichever door it came through.
//!
//! Values arrive as command-line text ([`Declared::set_text`]) or as JSON
//! ([`Declared::set_json`]; the studio's requests, and Python's keyword
//! arguments turned into JSON): both parse into the same typed field.

use serde::Serialize;
use serde_json::Value;

/// What values a setting accepts beyond its type.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Range {
    /// Any value of the type (finite, for numbers).
    Any,
    /// A number > 0.
    Positive,
    /// A number ≥ 0.
    NonNegative,
    /// A whole number in `min..=max`.
    Count { min: usize, max: usize },
    /// A number in `[low, high]`.
    Between { low: f64, high: f64 },
    /// One of these names.
    OneOf(&'static [&'static str]),
}

impl std::fmt::Display for Range {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Range::Any => write!(f, "any"),
            Range::Positive => write!(f, "> 0"),
            Range::NonNegative => write!(f, "≥ 0"),
            Range::Count { min, max } => write!(f, "{min} to {max}"),
            Range::Between { low, high } => {
                write!(f, "{} to {}", number_text(*low), number_text(*high))
            }
            Range::OneOf(names) => write!(f, "one of {}", names.join(", ")),
        }
    }
}

impl Range {
    /// Whether the number `x` is in the range (names are checked by
    /// [`Range::admits_name`]).
    pub fn admits(&self, x: f64) -> bool {
        match *self {
            Range::Any | Range::OneOf(_) => x.is_finite(),
            Range::Positive => x > 0.0 && x.is_finite(),
            Range::NonNegative => x >= 0.0 && x.is_finite(),
            Range::Count { min, max } => x >= min as f64 && x <= max as f64 && x.fract() == 0.0,
            Range::Between { low, high } => x >= low && x <= high,
        }
    }

    /// Whether the name `s` is in the range.
    pub fn admits_name(&self, s: &str) -> bool {
        match self {
            Range::OneOf(names) => names.contains(&s),
            _ => true,
        }
    }
}

/// The integration methods by name (`ode::Method::parse`), the range of
/// every `method` setting.
pub const METHODS: &[&str] = &["taylor", "dop853", "rk4", "gauss4", "gauss6", "radau5"];

/// One setting as the front ends show it.
#[derive(Clone, Debug, Serialize)]
pub struct Declaration {
    pub name: &'static str,
    /// The type in words (`whole number`, `number`, `list of numbers`, …).
    pub kind: &'static str,
    /// Whether it takes `auto` (resolved from the model by the analysis).
    pub auto: bool,
    /// Its type in the Python module's stub.
    #[serde(skip)]
    pub python: &'static str,
    /// The default (`"auto"`: resolved from the model by the analysis).
    pub default: Value,
    /// The default as the command line writes it.
    #[serde(skip)]
    pub default_text: String,
    /// The accepted values, in words.
    pub range: String,
    pub help: String,
}

/// Why a setting's value was refused: it names the analysis, the setting,
/// the value and what the setting accepts.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SettingError {
    #[error("{analysis}: no setting '{name}' (settings: {})", known.join(", "))]
    Unknown {
        analysis: &'static str,
        name: String,
        known: Vec<&'static str>,
    },
    #[error("{analysis}: {name} = {value} is not a {kind}")]
    NotA {
        analysis: &'static str,
        name: &'static str,
        value: String,
        kind: &'static str,
    },
    #[error("{analysis}: {name} = {value} is outside its range ({range})")]
    OutOfRange {
        analysis: &'static str,
        name: &'static str,
        value: String,
        range: String,
    },
    /// A method that does not take this tolerance or step.
    #[error("{analysis}: {source}")]
    Method {
        analysis: &'static str,
        source: crate::ode::OdeError,
    },
    /// Axes that are not two different state components of the model.
    #[error("{analysis}: axes = {given}: model '{model}' has the state components 0..{} ({})", known.len(), known.join(", "))]
    Axes {
        analysis: &'static str,
        model: &'static str,
        given: String,
        known: Vec<String>,
    },
    /// `parameter = auto` where the model names no amplitude to take.
    #[error("{analysis}: {name} = auto: model '{model}' names no [fast_phase] amplitude: name the parameter ({})", known.join(", "))]
    NoAmplitude {
        analysis: &'static str,
        name: &'static str,
        model: &'static str,
        known: &'static [&'static str],
    },
    /// A coordinate's name the model does not have.
    #[error("{analysis}: {name} = {value}: model '{model}' has no such coordinate ({})", known.join(", "))]
    UnknownCoordinate {
        analysis: &'static str,
        name: &'static str,
        value: String,
        model: &'static str,
        known: &'static [&'static str],
    },
    /// Values that are each valid but do not fit together.
    #[error("{analysis}: {names}: {reason}")]
    Inconsistent {
        analysis: &'static str,
        names: &'static str,
        reason: &'static str,
    },
}

/// A type a setting can have: read from text and JSON, written as both,
/// and checked against a [`Range`].
pub trait SettingValue: Sized {
    const KIND: &'static str;
    /// Whether `auto` is a value (resolved from the model).
    const AUTO: bool = false;
    const PYTHON: &'static str;
    fn from_text(text: &str) -> Option<Self>;
    fn from_json(value: &Value) -> Option<Self>;
    fn to_json(&self) -> Value;
    fn to_text(&self) -> String;
    /// Whether the value is in `range`.
    fn within(&self, range: &Range) -> bool;
}

/// A number as the command line writes it: whole numbers without a
/// point, small and large ones in exponent form.
pub fn number_text(x: f64) -> String {
    if x.fract() == 0.0 && x.abs() < 1e15 {
        format!("{x}")
    } else if x != 0.0 && (x.abs() < 1e-3 || x.abs() >= 1e6) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

fn finite(x: f64) -> Option<f64> {
    x.is_finite().then_some(x)
}

impl SettingValue for f64 {
    const KIND: &'static str = "number";
    const PYTHON: &'static str = "float";
    fn from_text(text: &str) -> Option<Self> {
        text.trim().parse().ok().and_then(finite)
    }
    fn from_json(value: &Value) -> Option<Self> {
        value.as_f64().and_then(finite)
    }
    fn to_json(&self) -> Value {
        serde_json::json!(self)
    }
    fn to_text(&self) -> String {
        number_text(*self)
    }
    fn within(&self, range: &Range) -> bool {
        range.admits(*self)
    }
}

impl SettingValue for usize {
    const KIND: &'static str = "whole number";
    const PYTHON: &'static str = "int";
    fn from_text(text: &str) -> Option<Self> {
        text.trim().parse().ok()
    }
    fn from_json(value: &Value) -> Option<Self> {
        value.as_u64().map(|v| v as usize).or_else(|| {
            // 3.0 from a language without integers.
            value
                .as_f64()
                .filter(|x| *x >= 0.0 && x.fract() == 0.0 && *x < 1e15)
                .map(|x| x as usize)
        })
    }
    fn to_json(&self) -> Value {
        serde_json::json!(self)
    }
    fn to_text(&self) -> String {
        self.to_string()
    }
    fn within(&self, range: &Range) -> bool {
        range.admits(*self as f64)
    }
}

impl SettingValue for bool {
    const KIND: &'static str = "yes or no";
    const PYTHON: &'static str = "bool";
    fn from_text(text: &str) -> Option<Self> {
        match text.trim() {
            "yes" | "true" => Some(true),
            "no" | "false" => Some(false),
            _ => None,
        }
    }
    fn from_json(value: &Value) -> Option<Self> {
        value.as_bool()
    }
    fn to_json(&self) -> Value {
        Value::Bool(*self)
    }
    fn to_text(&self) -> String {
        if *self { "yes" } else { "no" }.into()
    }
    fn within(&self, _: &Range) -> bool {
        true
    }
}

impl SettingValue for String {
    const KIND: &'static str = "name";
    const PYTHON: &'static str = "str";
    fn from_text(text: &str) -> Option<Self> {
        Some(text.trim().to_string())
    }
    fn from_json(value: &Value) -> Option<Self> {
        value.as_str().map(str::to_string)
    }
    fn to_json(&self) -> Value {
        Value::String(self.clone())
    }
    fn to_text(&self) -> String {
        self.clone()
    }
    fn within(&self, range: &Range) -> bool {
        range.admits_name(self)
    }
}

/// Names, comma-separated on the command line (a model's coordinates).
impl SettingValue for Vec<String> {
    const KIND: &'static str = "list of names";
    const PYTHON: &'static str = "Sequence[str]";
    fn from_text(text: &str) -> Option<Self> {
        let names: Vec<String> = text.split(',').map(|n| n.trim().to_string()).collect();
        names.iter().all(|n| !n.is_empty()).then_some(names)
    }
    fn from_json(value: &Value) -> Option<Self> {
        match value {
            Value::Array(items) => items.iter().map(String::from_json).collect(),
            Value::String(text) => Self::from_text(text),
            _ => None,
        }
    }
    fn to_json(&self) -> Value {
        serde_json::json!(self)
    }
    fn to_text(&self) -> String {
        self.join(",")
    }
    fn within(&self, range: &Range) -> bool {
        self.iter().all(|n| range.admits_name(n))
    }
}

impl SettingValue for Vec<f64> {
    const KIND: &'static str = "list of numbers";
    const PYTHON: &'static str = "Sequence[float]";
    fn from_text(text: &str) -> Option<Self> {
        let values: Option<Vec<f64>> = text.split(',').map(f64::from_text).collect();
        values.filter(|v| !v.is_empty())
    }
    fn from_json(value: &Value) -> Option<Self> {
        match value {
            Value::Array(items) => items.iter().map(f64::from_json).collect(),
            // A single number is a list of one (`through=0` on the
            // command line reads the same).
            Value::Number(_) => f64::from_json(value).map(|x| vec![x]),
            _ => None,
        }
    }
    fn to_json(&self) -> Value {
        serde_json::json!(self)
    }
    fn to_text(&self) -> String {
        self.iter()
            .map(|x| number_text(*x))
            .collect::<Vec<_>>()
            .join(",")
    }
    fn within(&self, range: &Range) -> bool {
        self.iter().all(|x| range.admits(*x))
    }
}

/// A point of a plane: `q,p` on the command line, `[q, p]` in JSON.
impl SettingValue for [f64; 2] {
    const KIND: &'static str = "point (two numbers)";
    const PYTHON: &'static str = "tuple[float, float]";
    fn from_text(text: &str) -> Option<Self> {
        Vec::<f64>::from_text(text)?.try_into().ok()
    }
    fn from_json(value: &Value) -> Option<Self> {
        Vec::<f64>::from_json(value)?.try_into().ok()
    }
    fn to_json(&self) -> Value {
        serde_json::json!(self)
    }
    fn to_text(&self) -> String {
        self.to_vec().to_text()
    }
    fn within(&self, range: &Range) -> bool {
        self.iter().all(|x| range.admits(*x))
    }
}

/// Points of a plane: `q,p;q,p` on the command line, `[[q, p], …]` in
/// JSON.
impl SettingValue for Vec<[f64; 2]> {
    const KIND: &'static str = "points (q,p;q,p…)";
    const PYTHON: &'static str = "Sequence[tuple[float, float]]";
    fn from_text(text: &str) -> Option<Self> {
        text.split(';').map(<[f64; 2]>::from_text).collect()
    }
    fn from_json(value: &Value) -> Option<Self> {
        value
            .as_array()?
            .iter()
            .map(<[f64; 2]>::from_json)
            .collect()
    }
    fn to_json(&self) -> Value {
        serde_json::json!(self)
    }
    fn to_text(&self) -> String {
        self.iter()
            .map(|p| p.to_text())
            .collect::<Vec<_>>()
            .join(";")
    }
    fn within(&self, range: &Range) -> bool {
        self.iter().all(|p| p.within(range))
    }
}

/// States: `q,p;q,p` on the command line, `[[q, p], …]` in JSON.
impl SettingValue for Vec<Vec<f64>> {
    const KIND: &'static str = "states (q,p;q,p…)";
    const PYTHON: &'static str = "Sequence[Sequence[float]]";
    fn from_text(text: &str) -> Option<Self> {
        text.split(';').map(Vec::<f64>::from_text).collect()
    }
    fn from_json(value: &Value) -> Option<Self> {
        value
            .as_array()?
            .iter()
            .map(Vec::<f64>::from_json)
            .collect()
    }
    fn to_json(&self) -> Value {
        serde_json::json!(self)
    }
    fn to_text(&self) -> String {
        self.iter()
            .map(|y| y.to_text())
            .collect::<Vec<_>>()
            .join(";")
    }
    fn within(&self, range: &Range) -> bool {
        self.iter().all(|y| y.within(range))
    }
}

/// Values of a parameter: a list `a,b,c`, or `geometric:first,last,count`
/// (JSON: a list, or that text).
#[derive(Clone, Debug, PartialEq)]
pub enum Values {
    List(Vec<f64>),
    Geometric { first: f64, last: f64, count: usize },
}

impl Values {
    /// The values, in order.
    pub fn values(&self) -> Vec<f64> {
        match *self {
            Values::List(ref v) => v.clone(),
            Values::Geometric { first, last, count } => (0..count)
                .map(|k| first * (last / first).powf(k as f64 / (count - 1) as f64))
                .collect(),
        }
    }
}

impl SettingValue for Values {
    const KIND: &'static str = "values: a,b,c or geometric:first,last,count";
    const PYTHON: &'static str = "Sequence[float] | str";
    fn from_text(text: &str) -> Option<Self> {
        let Some(spec) = text.trim().strip_prefix("geometric:") else {
            return Vec::<f64>::from_text(text).map(Values::List);
        };
        match Vec::<f64>::from_text(spec)?[..] {
            [first, last, count]
                if first > 0.0 && last > 0.0 && count >= 2.0 && count.fract() == 0.0 =>
            {
                Some(Values::Geometric {
                    first,
                    last,
                    count: count as usize,
                })
            }
            _ => None,
        }
    }
    fn from_json(value: &Value) -> Option<Self> {
        match value {
            Value::String(text) => Self::from_text(text),
            _ => Vec::<f64>::from_json(value).map(Values::List),
        }
    }
    fn to_json(&self) -> Value {
        match self {
            Values::List(v) => v.to_json(),
            Values::Geometric { .. } => Value::String(self.to_text()),
        }
    }
    fn to_text(&self) -> String {
        match self {
            Values::List(v) => v.to_text(),
            Values::Geometric { first, last, count } => format!(
                "geometric:{},{},{count}",
                number_text(*first),
                number_text(*last)
            ),
        }
    }
    fn within(&self, range: &Range) -> bool {
        self.values().iter().all(|x| range.admits(*x))
    }
}

impl SettingValue for Vec<usize> {
    const KIND: &'static str = "list of indices";
    const PYTHON: &'static str = "Sequence[int]";
    fn from_text(text: &str) -> Option<Self> {
        text.split(',').map(usize::from_text).collect()
    }
    fn from_json(value: &Value) -> Option<Self> {
        value.as_array()?.iter().map(usize::from_json).collect()
    }
    fn to_json(&self) -> Value {
        serde_json::json!(self)
    }
    fn to_text(&self) -> String {
        self.iter()
            .map(usize::to_string)
            .collect::<Vec<_>>()
            .join(",")
    }
    fn within(&self, range: &Range) -> bool {
        self.iter().all(|x| x.within(range))
    }
}

impl<const N: usize> SettingValue for [usize; N] {
    const KIND: &'static str = "indices";
    const PYTHON: &'static str = "Sequence[int]";
    fn from_text(text: &str) -> Option<Self> {
        let values: Option<Vec<usize>> = text.split(',').map(usize::from_text).collect();
        values?.try_into().ok()
    }
    fn from_json(value: &Value) -> Option<Self> {
        let values: Option<Vec<usize>> = value.as_array()?.iter().map(usize::from_json).collect();
        values?.try_into().ok()
    }
    fn to_json(&self) -> Value {
        serde_json::json!(self.as_slice())
    }
    fn to_text(&self) -> String {
        self.iter()
            .map(usize::to_string)
            .collect::<Vec<_>>()
            .join(",")
    }
    fn within(&self, range: &Range) -> bool {
        self.iter().all(|x| x.within(range))
    }
}

/// The ranges of the two axes of a plane: `x0,x1,y0,y1` on the command
/// line, `[[x0, x1], [y0, y1]]` in JSON; each low < high.
impl SettingValue for [[f64; 2]; 2] {
    const KIND: &'static str = "pair of intervals, low < high";
    const PYTHON: &'static str = "tuple[tuple[float, float], tuple[float, float]]";
    fn from_text(text: &str) -> Option<Self> {
        match Vec::<f64>::from_text(text)?[..] {
            [a, b, c, d] if a < b && c < d => Some([[a, b], [c, d]]),
            _ => None,
        }
    }
    fn from_json(value: &Value) -> Option<Self> {
        let pairs = value.as_array()?;
        let pair = |v: &Value| -> Option<[f64; 2]> {
            match Vec::<f64>::from_json(v)?[..] {
                [a, b] if a < b => Some([a, b]),
                _ => None,
            }
        };
        match &pairs[..] {
            [x, y] => Some([pair(x)?, pair(y)?]),
            _ => None,
        }
    }
    fn to_json(&self) -> Value {
        serde_json::json!(self)
    }
    fn to_text(&self) -> String {
        self.concat().to_vec().to_text()
    }
    fn within(&self, range: &Range) -> bool {
        self.iter().flatten().all(|x| range.admits(*x))
    }
}

/// `auto` (or JSON `null`): the analysis resolves it from the model.
impl<T: SettingValue> SettingValue for Option<T> {
    const KIND: &'static str = T::KIND;
    const AUTO: bool = true;
    const PYTHON: &'static str = T::PYTHON;
    fn from_text(text: &str) -> Option<Self> {
        if text.trim() == "auto" {
            return Some(None);
        }
        T::from_text(text).map(Some)
    }
    fn from_json(value: &Value) -> Option<Self> {
        match value {
            Value::Null => Some(None),
            Value::String(s) if s == "auto" => Some(None),
            _ => T::from_json(value).map(Some),
        }
    }
    fn to_json(&self) -> Value {
        self.as_ref()
            .map_or(Value::String("auto".into()), T::to_json)
    }
    fn to_text(&self) -> String {
        self.as_ref().map_or("auto".into(), T::to_text)
    }
    fn within(&self, range: &Range) -> bool {
        self.as_ref().is_none_or(|v| v.within(range))
    }
}

/// The settings of one analysis, declared by [`declare_settings!`].
pub trait Declared: Default + Clone {
    /// The analysis's name (the scene's, the studio's route's, the Python
    /// method's).
    const ANALYSIS: &'static str;
    /// One line on what the analysis computes.
    fn about() -> String;
    /// Every setting, with the values of `self` as its defaults.
    fn declarations(&self) -> Vec<Declaration>;
    /// Sets one setting from command-line text (not yet validated).
    fn set_text(&mut self, name: &str, text: &str) -> Result<(), SettingError>;
    /// Sets one setting from JSON (not yet validated).
    fn set_json(&mut self, name: &str, value: &Value) -> Result<(), SettingError>;
    /// Checks every setting against its range, then the ones that must fit
    /// together ([`Declared::consistent`]): the only place values are
    /// checked.
    fn validate(&self) -> Result<(), SettingError>;
    /// Settings that are each valid but must fit together.
    fn consistent(&self) -> Result<(), SettingError> {
        Ok(())
    }
    /// The lighter defaults the studio starts from, where it wants them
    /// (a click should answer in about a second).
    fn interactive() -> Self {
        Self::default()
    }
    /// The settings as JSON (for summaries and the schema).
    fn to_json(&self) -> serde_json::Map<String, Value>;

    /// `self` with each `(name, value)` of `values` set, then validated.
    fn with_json<'a>(
        mut self,
        values: impl IntoIterator<Item = (&'a String, &'a Value)>,
    ) -> Result<Self, SettingError> {
        for (name, value) in values {
            self.set_json(name, value)?;
        }
        self.validate()?;
        Ok(self)
    }

    /// `self` with each `(name, text)` of `values` set, then validated.
    fn with_texts<'a>(
        mut self,
        values: impl IntoIterator<Item = (&'a str, &'a str)>,
    ) -> Result<Self, SettingError> {
        for (name, text) in values {
            self.set_text(name, text)?;
        }
        self.validate()?;
        Ok(self)
    }

    /// The names of the settings.
    fn names() -> Vec<&'static str> {
        Self::default()
            .declarations()
            .iter()
            .map(|d| d.name)
            .collect()
    }
}

/// Checks one field against its range (the generated `validate`).
pub fn check<T: SettingValue>(
    analysis: &'static str,
    name: &'static str,
    value: &T,
    range: &Range,
) -> Result<(), SettingError> {
    if value.within(range) {
        Ok(())
    } else {
        Err(SettingError::OutOfRange {
            analysis,
            name,
            value: value.to_text(),
            range: range.to_string(),
        })
    }
}

/// Declares an analysis's settings: a struct with one field per setting,
/// its `Default`, and its [`Declared`] implementation. Each setting is
/// written `/// help` `name: Type = default, range;`; the doc comments
/// are the help the front ends show. An optional `interactive { name:
/// value, … }` gives the studio's lighter defaults.
#[macro_export]
macro_rules! declare_settings {
    (
        $(#[doc = $about:literal])*
        pub struct $name:ident for $analysis:literal {
            $(
                $(#[doc = $help:literal])+
                $field:ident : $ty:ty = $default:expr, $range:expr;
            )+
        }
        $(interactive { $($ifield:ident : $ivalue:expr),* $(,)? })?
    ) => {
        $(#[doc = $about])*
        #[derive(Clone, Debug, PartialEq)]
        pub struct $name {
            $(
                $(#[doc = $help])+
                pub $field: $ty,
            )+
        }

        impl Default for $name {
            fn default() -> Self {
                Self { $($field: $default,)+ }
            }
        }

        impl $crate::settings::Declared for $name {
            const ANALYSIS: &'static str = $analysis;

            fn about() -> String {
                concat!($($about),*).trim().to_string()
            }

            fn declarations(&self) -> Vec<$crate::settings::Declaration> {
                use $crate::settings::SettingValue;
                vec![$(
                    $crate::settings::Declaration {
                        name: stringify!($field),
                        kind: <$ty as SettingValue>::KIND,
                        auto: <$ty as SettingValue>::AUTO,
                        python: <$ty as SettingValue>::PYTHON,
                        default: SettingValue::to_json(&self.$field),
                        default_text: SettingValue::to_text(&self.$field),
                        range: ($range).to_string(),
                        help: concat!($($help),+).trim().to_string(),
                    },
                )+]
            }

            fn set_text(&mut self, name: &str, text: &str) -> Result<(), $crate::settings::SettingError> {
                use $crate::settings::SettingValue;
                match name {
                    $(stringify!($field) => {
                        self.$field = <$ty as SettingValue>::from_text(text).ok_or_else(|| {
                            $crate::settings::SettingError::NotA {
                                analysis: $analysis,
                                name: stringify!($field),
                                value: text.to_string(),
                                kind: <$ty as SettingValue>::KIND,
                            }
                        })?;
                    })+
                    _ => return Err(self.unknown(name)),
                }
                Ok(())
            }

            fn set_json(&mut self, name: &str, value: &serde_json::Value) -> Result<(), $crate::settings::SettingError> {
                use $crate::settings::SettingValue;
                match name {
                    $(stringify!($field) => {
                        self.$field = <$ty as SettingValue>::from_json(value).ok_or_else(|| {
                            $crate::settings::SettingError::NotA {
                                analysis: $analysis,
                                name: stringify!($field),
                                value: value.to_string(),
                                kind: <$ty as SettingValue>::KIND,
                            }
                        })?;
                    })+
                    _ => return Err(self.unknown(name)),
                }
                Ok(())
            }

            $(fn interactive() -> Self {
                Self { $($ifield: $ivalue,)* ..Self::default() }
            })?

            fn validate(&self) -> Result<(), $crate::settings::SettingError> {
                $($crate::settings::check($analysis, stringify!($field), &self.$field, &$range)?;)+
                self.consistent()
            }

            fn to_json(&self) -> serde_json::Map<String, serde_json::Value> {
                use $crate::settings::SettingValue;
                let mut map = serde_json::Map::new();
                $(map.insert(stringify!($field).into(), SettingValue::to_json(&self.$field));)+
                map
            }
        }

        impl $name {
            fn unknown(&self, name: &str) -> $crate::settings::SettingError {
                $crate::settings::SettingError::Unknown {
                    analysis: $analysis,
                    name: name.to_string(),
                    known: vec![$(stringify!($field)),+],
                }
            }
        }
    };
}

/// Every declared analysis's settings, with their defaults and the
/// studio's interactive ones: the studio's `GET /api/schema`, and what
/// the docs' reference and the Python stub are checked against.
#[derive(Clone, Debug, Serialize)]
pub struct Schema {
    pub analysis: &'static str,
    pub about: String,
    pub settings: Vec<Declaration>,
    /// The values the studio starts from where they differ from the
    /// defaults (its `interactive` preset).
    pub interactive: serde_json::Map<String, Value>,
}

impl Schema {
    pub fn of<T: Declared>() -> Schema {
        let defaults = T::default().to_json();
        let interactive = T::interactive()
            .to_json()
            .into_iter()
            .filter(|(k, v)| defaults.get(k) != Some(v))
            .collect();
        Schema {
            analysis: T::ANALYSIS,
            about: T::about(),
            settings: T::default().declarations(),
            interactive,
        }
    }
}

/// The schemas of every analysis declared so far, in the docs' order.
pub fn schemas() -> Vec<Schema> {
    use crate::analysis::on_constraints::steady::study::SteadyMotionOptions;
    use crate::analysis::on_constraints::vibration::LinkageOptions;
    use crate::analysis::{
        attractor, averaging, basins, chaos_map, continuation, period_map, section, separatrix,
        stability,
    };
    vec![
        Schema::of::<chaos_map::ChaosMapOptions>(),
        Schema::of::<basins::BasinsOptions>(),
        Schema::of::<continuation::ContinuationOptions>(),
        Schema::of::<separatrix::SplittingOptions>(),
        Schema::of::<section::SectionOptions>(),
        Schema::of::<stability::StabilityOptions>(),
        Schema::of::<LinkageOptions>(),
        Schema::of::<SteadyMotionOptions>(),
        Schema::of::<attractor::AttractorOptions>(),
        Schema::of::<averaging::AveragingOptions>(),
        Schema::of::<period_map::PeriodMapOptions>(),
        Schema::of::<crate::explore::ExploreOptions>(),
    ]
}

impl Declaration {
    /// The setting as a keyword argument of the Python module's stub:
    /// `name: type = default` (`None` for `auto`).
    pub fn python_argument(&self) -> String {
        fn literal(value: &Value) -> String {
            match value {
                Value::Bool(true) => "True".into(),
                Value::Bool(false) => "False".into(),
                Value::Number(n) if n.is_f64() => {
                    let x = n.as_f64().expect("a number");
                    if x.fract() == 0.0 && x.abs() < 1e15 {
                        format!("{x:.1}")
                    } else {
                        format!("{x:?}")
                    }
                }
                Value::Number(n) => n.to_string(),
                Value::String(s) => format!("{s:?}"),
                Value::Array(items) => format!(
                    "({}{})",
                    items.iter().map(literal).collect::<Vec<_>>().join(", "),
                    if items.len() == 1 { "," } else { "" }
                ),
                _ => "None".into(),
            }
        }
        let (python, default) = match (self.auto, &self.default) {
            (true, Value::String(s)) if s == "auto" => {
                (format!("Optional[{}]", self.python), "None".to_string())
            }
            (true, value) => (format!("Optional[{}]", self.python), literal(value)),
            (false, value) => (self.python.to_string(), literal(value)),
        };
        format!("{}: {python} = {default}", self.name)
    }
}

/// The method of a `method`/`tol` pair of settings.
pub fn method(
    analysis: &'static str,
    name: &str,
    tol: f64,
) -> Result<crate::ode::Method, SettingError> {
    crate::ode::Method::parse(name, tol).map_err(|source| SettingError::Method { analysis, source })
}

/// A state component on a plane's axis: its index in [q; p] (0 = the
/// first coordinate) or its name (`phi1`, `p_phi1`, or as the figures
/// write it).
#[derive(Clone, Debug, PartialEq)]
pub enum Axis {
    Index(usize),
    Name(String),
}

impl Axis {
    fn text(&self) -> String {
        match self {
            Axis::Index(i) => i.to_string(),
            Axis::Name(name) => name.clone(),
        }
    }

    fn from_text(text: &str) -> Option<Axis> {
        let text = text.trim();
        if text.is_empty() {
            return None;
        }
        Some(match text.parse() {
            Ok(i) => Axis::Index(i),
            Err(_) => Axis::Name(text.to_string()),
        })
    }

    fn from_json(value: &Value) -> Option<Axis> {
        match value {
            Value::String(name) => Axis::from_text(name),
            _ => usize::from_json(value).map(Axis::Index),
        }
    }
}

/// Two state components: `0,2` or `phi1,phi2` on the command line,
/// `[0, 2]` or `["phi1", "phi2"]` in JSON.
impl SettingValue for [Axis; 2] {
    const KIND: &'static str = "two state components";
    const PYTHON: &'static str = "tuple[int | str, int | str]";
    fn from_text(text: &str) -> Option<Self> {
        match text
            .split(',')
            .map(Axis::from_text)
            .collect::<Option<Vec<_>>>()?[..]
        {
            [ref a, ref b] => Some([a.clone(), b.clone()]),
            _ => None,
        }
    }
    fn from_json(value: &Value) -> Option<Self> {
        match &value.as_array()?[..] {
            [a, b] => Some([Axis::from_json(a)?, Axis::from_json(b)?]),
            _ => None,
        }
    }
    fn to_json(&self) -> Value {
        Value::Array(
            self.iter()
                .map(|a| match a {
                    Axis::Index(i) => serde_json::json!(i),
                    Axis::Name(n) => Value::String(n.clone()),
                })
                .collect(),
        )
    }
    fn to_text(&self) -> String {
        format!("{},{}", self[0].text(), self[1].text())
    }
    fn within(&self, _: &Range) -> bool {
        true
    }
}

/// The state components of `axes` for `model` (`auto`: the first
/// coordinate and its momentum, or a constrained model's velocity, the
/// plane every model has), two different ones of its state.
pub fn resolve_axes(
    analysis: &'static str,
    info: &crate::registry::ModelInfo,
    axes: &Option<[Axis; 2]>,
) -> Result<[usize; 2], SettingError> {
    let n = info.coordinates.len();
    let Some(axes) = axes else {
        return Ok([0, n]);
    };
    let names = info.state_names();
    let index = |axis: &Axis| match axis {
        Axis::Index(i) => (*i < 2 * n).then_some(*i),
        Axis::Name(name) => {
            (0..2 * n).find(|&i| names[i] == name.as_str() || info.label(i) == *name)
        }
    };
    let bad = || SettingError::Axes {
        analysis,
        model: info.name,
        given: axes.to_text(),
        known: names.iter().map(|s| s.to_string()).collect(),
    };
    let [a, b] = [
        index(&axes[0]).ok_or_else(bad)?,
        index(&axes[1]).ok_or_else(bad)?,
    ];
    if a == b {
        return Err(bad());
    }
    Ok([a, b])
}
