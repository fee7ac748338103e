//! A Poincaré section orbit from a seed, and the MEGNO map of the
//! section.

use super::*;

/// What `POST /api/section` and `POST /api/section_map` ask: the
/// section's settings (its interactive values where not given): the orbit
/// from the one seed of `seeds`, or the MEGNO map of `map` pixels.
#[derive(Clone, Debug, Deserialize)]
pub struct SectionRequest {
    #[serde(flatten)]
    pub analysis: AnalysisRequest,
}

impl SectionRequest {
    /// The section's parts the request asks for.
    fn study(
        &self,
        catalog: Catalog,
    ) -> Result<mechlab_runtime::analysis::section::SectionStudy, StudioError> {
        use mechlab_runtime::analysis::section::{section_study, SectionOptions};
        let (model, params, options) = self.analysis.resolve::<SectionOptions>(catalog)?;
        Ok(section_study(model, &params, &options, &|_| ())?)
    }
}

/// A section orbit: its points on the plane (the seed first), its full
/// start and its largest drift from H = E.
#[derive(Clone, Debug, Serialize)]
pub struct SectionPoints {
    /// The names of the plane's two axes (Q_o and P_o of its chart).
    pub axes: [String; 2],
    pub points: Vec<[f64; 2]>,
    pub start: Vec<f64>,
    pub energy_drift: f64,
    /// Why the orbit ended (before its crossings: escaped, stopped, t_max).
    pub end: mechlab_runtime::analysis::section::OrbitEnd,
    /// The same, in words, for the page.
    pub end_text: String,
}

/// One orbit of the section map (`analysis::section`) for the studio: the
/// first of the request's seeds.
pub fn section(catalog: Catalog, request: &SectionRequest) -> Result<SectionPoints, StudioError> {
    let study = request.study(catalog)?;
    let Some(mut found) = study.section.filter(|s| !s.orbits.is_empty()) else {
        return Err(StudioError::NoSeed);
    };
    let orbit = found.orbits.remove(0);
    Ok(SectionPoints {
        axes: found.axes,
        points: orbit.points,
        start: orbit.start,
        energy_drift: orbit.energy_drift,
        end_text: orbit.end.to_string(),
        end: orbit.end,
    })
}

/// The MEGNO map of a section: ⟨Y⟩ per pixel (row 0 at the bottom, null
/// where the energy is not accessible) over `window`.
#[derive(Clone, Debug, Serialize)]
pub struct SectionMapView {
    /// The names of the plane's two axes (Q_o and P_o of its chart).
    pub axes: [String; 2],
    pub window: [[f64; 2]; 2],
    pub pixels: usize,
    pub megno: Vec<Option<f64>>,
    pub chaotic_fraction: f64,
    /// The share of pixels a run at a hundredth of the tolerance
    /// reclassifies, from a sample: the fraction's numerical error.
    pub class_check: Option<mechlab_runtime::analysis::check::ClassCheck>,
    pub seconds: f64,
}

/// The MEGNO map of the section (`analysis::section_map`) for the studio.
pub fn section_map(
    catalog: Catalog,
    request: &SectionRequest,
) -> Result<SectionMapView, StudioError> {
    let Some(map) = request.study(catalog)?.megno_map else {
        return Err(StudioError::NoMap);
    };
    Ok(SectionMapView {
        axes: map.axes.clone(),
        window: map.window,
        pixels: map.pixels,
        megno: map
            .megno
            .iter()
            .map(|y| y.is_finite().then_some(*y))
            .collect(),
        chaotic_fraction: map.chaotic_fraction,
        class_check: map.class_check.clone(),
        seconds: map.seconds,
    })
}
