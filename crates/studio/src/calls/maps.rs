//! Requests of declared analyses, and the maps of a view drawn coarse
//! first: the FLI chaos map and the basins.

use super::*;

/// A request of a declared analysis: the model, its parameters (the model
/// file's values where not given), and the analysis's settings by the
/// names of its declaration (the analysis's `interactive` preset where not
/// given), each checked by the declaration.
#[derive(Clone, Debug, Deserialize)]
pub struct AnalysisRequest {
    pub model: String,
    #[serde(default)]
    pub params: BTreeMap<String, f64>,
    /// The analysis's settings (an unknown name is refused by name).
    #[serde(flatten)]
    pub settings: serde_json::Map<String, serde_json::Value>,
}

impl AnalysisRequest {
    /// The model, its parameter values and the settings, checked.
    pub fn resolve<T: Declared>(
        &self,
        catalog: Catalog,
    ) -> Result<(&'static Model, Vec<f64>, T), StudioError> {
        let handle = mechlab_runtime::registry::lookup(catalog, &self.model)?;
        let params = handle.values_with(&self.params)?;
        let settings = T::interactive().with_json(&self.settings)?;
        Ok((handle, params, settings))
    }
}

/// A map of the current view drawn coarse first (the chaos map, the
/// basins): the analysis's settings, at each number of pixels per side
/// of `levels`.
#[derive(Clone, Debug, Deserialize)]
pub struct LevelsRequest {
    /// Pixels per side of each refinement, in order (1 to 8 of them).
    pub levels: Vec<usize>,
    #[serde(flatten)]
    pub analysis: AnalysisRequest,
}

impl LevelsRequest {
    /// The request checked: the model, its parameters, and the settings of
    /// each level, checked by the declaration and resolved for the model
    /// by `resolve`.
    pub fn check<T: Declared, S, E>(
        &self,
        catalog: Catalog,
        resolve: impl Fn(&T, &Model) -> Result<S, E>,
    ) -> Result<(&'static Model, Vec<f64>, Vec<S>), StudioError>
    where
        StudioError: From<E>,
    {
        let (model, params, options) = self.analysis.resolve::<T>(catalog)?;
        if self.levels.is_empty() || self.levels.len() > 8 {
            return Err(StudioError::Levels {
                got: self.levels.len(),
            });
        }
        let levels = self
            .levels
            .iter()
            .map(|&pixels| {
                let mut level = options.clone();
                level.set_json("pixels", &pixels.into())?;
                level.validate()?;
                Ok(resolve(&level, model)?)
            })
            .collect::<Result<_, StudioError>>()?;
        Ok((model, params, levels))
    }
}

/// The chaos map's request checked, each level's settings resolved.
pub fn chaos_levels(
    catalog: Catalog,
    request: &LevelsRequest,
) -> Result<(&'static Model, Vec<f64>, Vec<ChaosMapSettings>), StudioError> {
    request.check(catalog, ChaosMapOptions::resolve)
}

/// One refinement of the chaos map.
#[derive(Clone, Debug, Serialize)]
pub struct ChaosLevel {
    pub pixels: usize,
    /// Grey levels in [0, 1] (1 = most chaotic), row-major from the lower left.
    pub shades: Vec<f64>,
    /// The FLI of each pixel (null: the orbit left the model's domain).
    pub fli: Vec<Option<f64>>,
    /// ln(periods): the FLI of a regular orbit.
    pub regular_level: f64,
    pub chaotic_fraction: f64,
    /// The share of pixels a run at a hundredth of the tolerance
    /// reclassifies, from a sample: the fraction's numerical error.
    pub class_check: Option<mechlab_runtime::analysis::check::ClassCheck>,
    pub seconds: f64,
}

/// The FLI map of the view at each resolution of `request.levels` (rows
/// on all cores; the Taylor method in batches), each handed to `sink` when
/// done; `sink` returns false to stop before the next, and once `listening`
/// says false a level stops between blocks of rows (ending with
/// `PeriodMapError::Cancelled`).
pub fn chaos(
    catalog: Catalog,
    request: &LevelsRequest,
    sink: &mut dyn FnMut(ChaosLevel) -> bool,
    listening: &(dyn Fn() -> bool + Sync),
) -> Result<(), StudioError> {
    let (model, params, levels) = chaos_levels(catalog, request)?;
    for settings in &levels {
        let map = chaos_map(model, &params, settings, listening)?;
        let level = ChaosLevel {
            pixels: settings.pixels,
            shades: map.shades,
            fli: map
                .fli
                .iter()
                .map(|v| v.is_finite().then_some(*v))
                .collect(),
            regular_level: map.fli_regular_level,
            chaotic_fraction: map.chaotic_fraction,
            class_check: map.class_check,
            seconds: map.seconds,
        };
        if !sink(level) {
            break;
        }
    }
    Ok(())
}

/// The basins' request (`POST /api/basins`) checked, each level's
/// settings resolved.
pub fn basins_levels(
    catalog: Catalog,
    request: &LevelsRequest,
) -> Result<(&'static Model, Vec<f64>, Vec<BasinSettings>), StudioError> {
    request.check(catalog, BasinsOptions::resolve)
}

/// One refinement of the basins.
#[derive(Clone, Debug, Serialize)]
pub struct BasinsLevel {
    pub pixels: usize,
    /// Each pixel's attractor (an index of `attractors`, −1: diverged),
    /// row-major from the lower left.
    pub labels: Vec<i32>,
    pub attractors: Vec<mechlab_runtime::analysis::basins::Attractor>,
    /// Each attractor's recorded iterates on the view's axes.
    pub points: Vec<Vec<[f64; 2]>>,
    pub boundary: mechlab_runtime::analysis::basins::Boundary,
    /// The share of starts that end elsewhere in a run at a hundredth of
    /// the tolerance, from a sample: the fractions' numerical error.
    pub class_check: Option<mechlab_runtime::analysis::check::ClassCheck>,
    pub seconds: f64,
}

/// Streams the basins of the view at each resolution of the request to
/// `sink`, until it returns false.
pub fn basins(
    catalog: Catalog,
    request: &LevelsRequest,
    sink: &mut dyn FnMut(BasinsLevel) -> bool,
) -> Result<(), StudioError> {
    let (model, params, levels) = basins_levels(catalog, request)?;
    for settings in &levels {
        let map = mechlab_runtime::analysis::basins::basins(model, &params, settings, &|_| ())?;
        let level = BasinsLevel {
            pixels: settings.pixels,
            labels: map.labels,
            attractors: map.attractors,
            points: map.points,
            boundary: map.boundary,
            class_check: map.class_check,
            seconds: map.seconds,
        };
        if !sink(level) {
            break;
        }
    }
    Ok(())
}
