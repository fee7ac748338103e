//! The mechanism moving: the points its model file names (`[[points]]`)
//! and its bodies' frames along a motion of the exact system, frame by
//! frame, in the plane or in space, for the studio's drawing.

use super::Refusal;
use crate::ode::holonomic::ConstraintError;
use crate::ode::{Method, OdeError};
use crate::registry::Model;

/// The most frames one animation computes (60 s at 60 frames per second).
pub const MAX_FRAMES: usize = 3600;

/// The mechanism's points at equally spaced times of one motion.
#[derive(Clone, Debug, PartialEq)]
pub struct Animation {
    pub model: &'static str,
    pub points: &'static [&'static str],
    /// Bars between points, by index.
    pub bars: &'static [[usize; 2]],
    /// Each body's frame: its centre's and its axes' tips' indices.
    pub body_frames: &'static [[usize; 4]],
    /// Whether the mechanism moves in space (else in the plane z = 0).
    pub in_space: bool,
    /// The way up, a unit vector: against gravity where the model file
    /// gives it, else z in space and y in the plane.
    pub up: [f64; 3],
    pub times: Vec<f64>,
    /// `frames[f][p]`: the point p at `times[f]`, (x, y, z).
    pub frames: Vec<Vec<[f64; 3]>>,
    /// The start the motion left from (on the constraints for a
    /// constrained model).
    pub start: Vec<f64>,
}

/// Why a mechanism cannot be drawn moving.
#[derive(Debug, thiserror::Error)]
pub enum MechanismError {
    #[error("model '{model}' names no points: give its model file [[points]] entries (name, at = [x, y] or [x, y, z], joined_to) or [[bodies]] to draw it")]
    NotDrawn { model: String },
    #[error(transparent)]
    Refused(#[from] Refusal),
    #[error("model '{model}': the start is not a state of the model: {source}")]
    Inconsistent {
        model: String,
        source: ConstraintError,
    },
    #[error("model '{model}': the point '{point}' is not finite at t = {time} (its expression is singular there)")]
    NotFinite {
        model: String,
        point: &'static str,
        time: f64,
    },
    #[error(transparent)]
    Ode(#[from] OdeError),
}

/// What to draw: how long, how many frames.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frames {
    pub duration: f64,
    pub count: usize,
}

impl Frames {
    /// `count` frames over `duration` time units, first at t = 0.
    pub fn times(&self) -> Vec<f64> {
        let last = (self.count - 1) as f64;
        (0..self.count)
            .map(|f| self.duration * f as f64 / last)
            .collect()
    }
}

/// The mechanism of `model` moving from `start` (the full state, put on the
/// constraints holding the components `held` for a constrained model) with
/// the parameters' values `params` (declaration order), integrated by
/// `method` and drawn at the `frames`.
pub fn animate(
    model: &Model,
    params: &[f64],
    method: Method,
    start: &[f64],
    held: &[usize],
    frames: Frames,
) -> Result<Animation, MechanismError> {
    let info = model.info;
    let name = info.name;
    let drawing = info
        .drawing
        .ok_or_else(|| MechanismError::NotDrawn { model: name.into() })?;
    Refusal::named_values(info, params)?;
    let flows = super::flows(model)?;
    super::method_applies(model, method)?;
    if !(frames.duration.is_finite() && frames.duration > 0.0) {
        return Err(
            Refusal::setting(name, "the animation's duration must be finite and positive").into(),
        );
    }
    if !(2..=MAX_FRAMES).contains(&frames.count) {
        return Err(Refusal::setting(name, "an animation has from 2 to 3600 frames").into());
    }
    let dim = flows.periodic_state().len();
    if held.iter().any(|&h| h >= dim) {
        return Err(Refusal::setting(
            name,
            "the components held on the constraints must be components of the state",
        )
        .into());
    }
    if start.len() != dim {
        return Err(Refusal::StateLength {
            model: name.into(),
            what: "start",
            given: start.len(),
            expected: dim,
        }
        .into());
    }
    let mut start = start.to_vec();
    flows
        .consistent(params, &mut start, held)
        .map_err(|source| MechanismError::Inconsistent {
            model: name.into(),
            source,
        })?;
    let times = frames.times();
    let states = flows.exact(params).states_at(method, 0.0, &start, &times)?;
    let n = info.coordinates.len();
    let frames = times
        .iter()
        .zip(&states)
        .map(|(&t, y)| {
            let points = (drawing.at)(t, &y[..n], params);
            match points.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
                Some(p) => Err(MechanismError::NotFinite {
                    model: name.into(),
                    point: drawing.points[p],
                    time: t,
                }),
                None => Ok(points),
            }
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Animation {
        model: name,
        points: drawing.points,
        bars: drawing.bars,
        body_frames: drawing.body_frames,
        in_space: drawing.in_space,
        up: up(drawing, params),
        times,
        frames,
        start,
    })
}

/// The drawing's way up: against gravity where the model gives a nonzero
/// one, else z in space and y in the plane.
fn up(drawing: &crate::registry::Drawing, params: &[f64]) -> [f64; 3] {
    let g = drawing.gravity.map(|g| g(params)).unwrap_or_default();
    let size = g.iter().map(|c| c * c).sum::<f64>().sqrt();
    match (size > 0.0 && size.is_finite(), drawing.in_space) {
        // (+ 0.0: no −0 in what is written.)
        (true, _) => g.map(|c| -c / size + 0.0),
        (false, true) => [0.0, 0.0, 1.0],
        (false, false) => [0.0, 1.0, 0.0],
    }
}
