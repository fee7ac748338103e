//! The mechanism moving from an orbit's seed.

use super::*;

/// The frames of the mechanism, for the page to play.
#[derive(Clone, Debug, Serialize)]
pub struct MechanismView {
    pub points: Vec<&'static str>,
    pub bars: Vec<[usize; 2]>,
    /// Each body's centre and axes' tips, by index.
    pub body_frames: Vec<[usize; 4]>,
    /// Whether to draw in space (a view the user turns) or in the plane.
    pub in_space: bool,
    /// The way up (a unit vector).
    pub up: [f64; 3],
    pub times: Vec<f64>,
    /// `frames[f][p]`: the point p (x, y, z) at `times[f]`.
    pub frames: Vec<Vec<[f64; 3]>>,
}

/// The mechanism of `request` moving, from the seed put on the constraints
/// as the orbit's is (its axes' components held).
pub fn mechanism(
    catalog: Catalog,
    request: &AnalysisRequest,
) -> Result<MechanismView, StudioError> {
    let (handle, params, request) = request.resolve::<MechanismOptions>(catalog)?;
    let method = (request.method.as_str(), request.tol);
    let setup = Plane::of(handle, params, request.axes, &request.through, method)?;
    if request.seed.iter().any(|x| !x.is_finite()) {
        return Err(setup.bad(RequestProblem::NotFinite { what: "the seed" }));
    }
    let frames = mechlab_runtime::analysis::mechanism::Frames {
        duration: request.duration,
        count: request.frames,
    };
    let animation = mechlab_runtime::analysis::mechanism::animate(
        setup.handle,
        &setup.params,
        setup.method,
        &request.seed,
        &setup.axes,
        frames,
    )?;
    Ok(MechanismView {
        points: animation.points.to_vec(),
        bars: animation.bars.to_vec(),
        body_frames: animation.body_frames.to_vec(),
        in_space: animation.in_space,
        up: animation.up,
        times: animation.times,
        frames: animation.frames,
    })
}
