//! A constrained model's steady motion linearised: the declared
//! `steady_motion` analysis, its result as the scene's summary.

use super::*;
use mechlab_runtime::analysis::declared::{no_progress, Analysis};
use mechlab_runtime::analysis::on_constraints::steady::study::{SteadyMotionOptions, SteadyStudy};

/// The steady motion of `request` (the `steady_motion` declaration's
/// settings): eigenvalues with their errors, verdict, and the sweep.
pub fn steady_motion(
    catalog: Catalog,
    request: &AnalysisRequest,
) -> Result<SteadyStudy, StudioError> {
    let (handle, params, options) = request.resolve::<SteadyMotionOptions>(catalog)?;
    options
        .run(handle, &params, &no_progress)
        .map_err(|e| StudioError::Analysis(Box::new(e.located(handle, &params))))
}
