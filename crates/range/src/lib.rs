//! A parameter's range, the one piece of a model file that the generated
//! code and the runtime keep: a crate of its own, so that the runtime does
//! not compile the model-file reader (and its TOML parser) for a scene.

use std::fmt;

/// The values a parameter may take: an interval whose ends are open or
/// closed, written `"(0, inf)"` or `"[0, 1]"` in a model file. Scenes and
/// the studio refuse a value outside it with an error naming both, so a
/// negative ε never becomes a negative period.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Range {
    pub min: f64,
    pub max: f64,
    pub min_open: bool,
    pub max_open: bool,
}

/// Why a parameter's `range` is not an interval.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum RangeError {
    #[error("'{0}' is not an interval such as \"(0, inf)\" or \"[0, 1]\"")]
    NotAnInterval(String),
    #[error("'{0}' is empty: its lower end must be below its upper end")]
    Empty(String),
}

impl Range {
    /// Every real number.
    pub const ALL: Range = Range {
        min: f64::NEG_INFINITY,
        max: f64::INFINITY,
        min_open: true,
        max_open: true,
    };

    /// Reads `(a, b)`, `[a, b]`, `(a, b]` or `[a, b)`, with `inf` and
    /// `-inf` for unbounded ends; the reason when it cannot.
    pub fn parse(text: &str) -> Result<Range, RangeError> {
        let text = text.trim();
        let bad = || RangeError::NotAnInterval(text.to_string());
        let (min_open, rest) = match text.chars().next() {
            Some('(') => (true, &text[1..]),
            Some('[') => (false, &text[1..]),
            _ => return Err(bad()),
        };
        let (max_open, inner) = match rest.chars().last() {
            Some(')') => (true, &rest[..rest.len() - 1]),
            Some(']') => (false, &rest[..rest.len() - 1]),
            _ => return Err(bad()),
        };
        let (a, b) = inner.split_once(',').ok_or_else(bad)?;
        let number = |x: &str| -> Result<f64, RangeError> {
            match x.trim() {
                "inf" | "+inf" => Ok(f64::INFINITY),
                "-inf" => Ok(f64::NEG_INFINITY),
                x => x
                    .parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(bad),
            }
        };
        let range = Range {
            min: number(a)?,
            max: number(b)?,
            min_open,
            max_open,
        };
        if range.min >= range.max {
            return Err(RangeError::Empty(text.to_string()));
        }
        Ok(range)
    }

    pub fn contains(&self, x: f64) -> bool {
        let above = if self.min_open {
            x > self.min
        } else {
            x >= self.min
        };
        let below = if self.max_open {
            x < self.max
        } else {
            x <= self.max
        };
        above && below
    }
}

impl fmt::Display for Range {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let end = |x: f64| {
            if x.is_infinite() {
                if x > 0.0 {
                    "inf".to_string()
                } else {
                    "-inf".to_string()
                }
            } else {
                x.to_string()
            }
        };
        write!(
            f,
            "{}{}, {}{}",
            if self.min_open { '(' } else { '[' },
            end(self.min),
            end(self.max),
            if self.max_open { ')' } else { ']' }
        )
    }
}
