//! "Continue this orbit": the continuation of the orbit nearest a click.

use super::*;

/// What `POST /api/continuation` asks: the periodic orbit of the period
/// map nearest `seed` (a state), continued in `parameter` from its value
/// to `to`.
#[derive(Clone, Debug, Deserialize)]
pub struct ContinuationRequest {
    /// The page's axes: the branches are drawn on them, and a constrained
    /// model is continued in their chart unless `chart` is given (auto:
    /// the first coordinate and its momentum, or velocity).
    #[serde(default)]
    pub axes: Option<[usize; 2]>,
    /// The continuation's settings (`start` is the clicked state).
    #[serde(flatten)]
    pub analysis: AnalysisRequest,
}

/// Branches on the page's plane: each point (x, y, parameter) with its
/// stability, and the located bifurcations.
#[derive(Clone, Debug, Serialize)]
pub struct BranchesView {
    pub branches: Vec<BranchLine>,
    pub bifurcations: Vec<BifurcationMark>,
    pub seconds: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct BranchLine {
    pub period: usize,
    pub points: Vec<[f64; 3]>,
    pub stable: Vec<bool>,
}

#[derive(Clone, Debug, Serialize)]
pub struct BifurcationMark {
    pub kind: mechlab_runtime::analysis::continuation::BifurcationKind,
    pub parameter: f64,
    pub at: [f64; 2],
    pub located: bool,
}

/// The studio's "continue this orbit" (`analysis::continuation`): the
/// branch of the fixed point of P nearest the seed (the equilibrium, for a
/// model without a fast phase), and those born at its period doublings (up
/// to period 4), projected on the page's axes.
pub fn continuation(
    catalog: Catalog,
    request: &ContinuationRequest,
) -> Result<BranchesView, StudioError> {
    use mechlab_runtime::analysis::continuation::{continuation, ContinuationOptions};
    use mechlab_runtime::settings::{resolve_axes, Axis};
    let (model, params, options) = request.analysis.resolve::<ContinuationOptions>(catalog)?;
    let given = request.axes.map(|a| a.map(Axis::Index));
    let view = resolve_axes(ContinuationOptions::ANALYSIS, model.info, &given)?;
    let mut settings = options.resolve(model, &params)?;
    // A constrained model of one degree of freedom on its constraints is
    // continued in the chart of the plane's axes.
    if model.constrained.is_some() && settings.chart.is_none() {
        settings.chart = Some(view.to_vec());
    }
    let result = continuation(model, &params, &settings)?;
    let periodic = model.dynamic.periodic();
    // The state components of the axes in the branches' states.
    let axes = match &result.chart {
        Some(chart) => view.map(|a| chart.iter().position(|&c| c == a).unwrap_or(a)),
        None => view,
    };
    let place = |y: &[f64]| -> [f64; 2] {
        let at = |k: usize| {
            let axis = view[k];
            let component = axes[k];
            if periodic.get(axis).copied().unwrap_or(false) {
                wrap_angle(y[component])
            } else {
                y[component]
            }
        };
        [at(0), at(1)]
    };
    let branches = result
        .branches
        .iter()
        .map(|b| BranchLine {
            period: b.period,
            points: b
                .points
                .iter()
                .map(|p| {
                    let [x, y] = place(&p.state);
                    [x, y, p.parameter]
                })
                .collect(),
            stable: b.points.iter().map(|p| p.stable).collect(),
        })
        .collect();
    let bifurcations = result
        .bifurcations
        .iter()
        .map(|b| BifurcationMark {
            kind: b.kind,
            parameter: b.parameter,
            at: place(&b.state),
            located: b.located,
        })
        .collect();
    Ok(BranchesView {
        branches,
        bifurcations,
        seconds: result.seconds,
    })
}
