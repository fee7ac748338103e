//! The section's settings, declared once, and the one call that runs
//! what they ask for: the section's orbits, its MEGNO map and its
//! frequency map, as the `section` scene, the studio and Python return
//! them.

use super::{parse_plane, section, seeds_across, Section, SectionError, SectionSettings};
use crate::analysis::frequency_map::{frequency_map, FrequencyMap, FrequencyMapSettings};
use crate::analysis::section_map::{section_map, SectionMap, SectionMapSettings};
use crate::analysis::Refusal;
use crate::registry::Model;
use crate::settings::Range;

crate::declare_settings! {
    /// A Poincaré section at a fixed energy (models of 2 degrees of
    /// freedom, constrained ones too; with a fast phase, a slice of the
    /// period map): its orbits, and the MEGNO and frequency maps of the
    /// section.
    pub struct SectionOptions for "section" {
        /// The energy H = E of every orbit's seed (H̄, averaged, with a fast
        /// phase).
        energy: f64 = 0.125, Range::Any;
        /// The plane: a linear function of the coordinates ("x", "q1 - q2",
        /// "x + 0.5*y") equal to `value` (auto: the first coordinate).
        plane: Option<String> = None, Range::Any;
        /// The plane's value.
        value: f64 = 0.0, Range::Any;
        /// Crossings with the plane's function increasing (no: decreasing).
        rising: bool = true, Range::Any;
        /// Seeds on the plane: the other coordinate and its momentum, q,p;q,p
        /// (auto: `orbits` seeds across the accessible part of [−extent,
        /// extent]).
        seeds: Option<Vec<[f64; 2]>> = None, Range::Any;
        /// Orbits seeded evenly where `seeds` is auto (0: none).
        orbits: usize = 24, Range::Count { min: 0, max: 10_000 };
        /// Seeds and the maps' pixels are searched for in [−extent, extent].
        extent: f64 = 2.0, Range::Positive;
        /// Points per orbit.
        crossings: usize = 400, Range::Count { min: 1, max: 10_000_000 };
        /// An orbit stops at this time, however few its crossings (auto: 50
        /// time units per crossing).
        t_max: Option<f64> = None, Range::Positive;
        /// Pixels per side of a MEGNO chaos map of the section (0: none).
        map: usize = 0, Range::Count { min: 0, max: 4000 };
        /// Pixels per side of a frequency map (NAFF) of the section (0:
        /// none).
        frequencies: usize = 0, Range::Count { min: 0, max: 4000 };
        /// The time each orbit of the MEGNO and frequency maps runs.
        map_time: f64 = 2000.0, Range::Positive;
        /// Samples of each orbit of the frequency map.
        samples: usize = 4096, Range::Count { min: 64, max: 100_000_000 };
        /// Orbits of each map run again at a hundredth of the tolerance,
        /// spread over it, to state its error: the share of the MEGNO map's
        /// pixels that change class, the frequency map's tunes' change; and
        /// the section's orbits again, for their crossings' error (0:
        /// none).
        check: usize = 256, Range::Count { min: 0, max: 100_000 };
        /// The error wanted (auto: none asked, each states its check): on
        /// the orbits' crossings, the MEGNO map's largest share of pixels
        /// that change class, the frequency map's largest change of a tune.
        /// Given, each is run again with `tol` a hundredfold tighter until
        /// its check is within it, or the result says why not.
        accuracy: Option<f64> = None, Range::Positive;
        /// With a fast phase: the forcing's phase 2πt/T at which the period
        /// map samples.
        phase: f64 = 0.0, Range::Any;
        /// With a fast phase: points of the period map within this of the
        /// plane are kept.
        slab: f64 = 0.05, Range::Positive;
        /// DOP853's tolerance (the maps' Taylor method uses it too).
        tol: f64 = 1e-12, Range::Positive;
    }
    interactive { orbits: 0, extent: 3.0, check: 64 }
}

/// What [`section_study`] finds: each part the settings ask for.
#[derive(Debug, serde::Serialize)]
pub struct SectionStudy {
    pub section: Option<Section>,
    pub megno_map: Option<SectionMap>,
    pub frequency_map: Option<FrequencyMap>,
}

impl SectionOptions {
    /// The section's plane and orbits' settings for `model`, `auto`
    /// resolved.
    pub fn resolve(&self, model: &Model) -> Result<SectionSettings, SectionError> {
        let coordinates = model.info.coordinates;
        let plane = parse_plane(self.plane.as_deref().unwrap_or(coordinates[0]), coordinates)?;
        Ok(SectionSettings {
            plane,
            value: self.value,
            rising: self.rising,
            energy: self.energy,
            crossings: self.crossings,
            t_max: self.t_max.unwrap_or(50.0 * self.crossings as f64),
            tol: self.tol,
            phase: self.phase,
            slab: self.slab,
        })
    }
}

/// The section of `model` that `options` ask for: its orbits (from the
/// seeds, or `orbits` seeds across; none when 0), its MEGNO map and its
/// frequency map (where their pixels are not 0); `say` hears what starts.
pub fn section_study(
    model: &Model,
    params: &[f64],
    options: &SectionOptions,
    say: &dyn Fn(String),
) -> Result<SectionStudy, SectionError> {
    let settings = options.resolve(model)?;
    let seeds = match &options.seeds {
        Some(seeds) => seeds.clone(),
        None if options.orbits == 0 => Vec::new(),
        None => seeds_across(model, params, &settings, options.extent, options.orbits),
    };
    // (Where no seed is accessible, or the model is refused, `section`
    // says so.)
    let section = if options.orbits == 0 && options.seeds.is_none() {
        None
    } else {
        say(format!(
            "{} orbits at H = {} …",
            seeds.len(),
            settings.energy
        ));
        Some(checked_section(model, params, &seeds, &settings, options)?)
    };
    let frequency_map = match options.frequencies {
        0 => None,
        pixels => {
            say(format!("frequency map, {pixels}² orbits …"));
            let map = |tol: f64| FrequencyMapSettings {
                section: SectionSettings {
                    tol,
                    ..settings.clone()
                },
                pixels,
                t_max: options.map_time,
                samples: options.samples,
                extent: options.extent,
                check: options.check,
            };
            let (mut result, said) = to_accuracy(
                settings.tol,
                options.accuracy,
                |tol| frequency_map(model, params, &map(tol)),
                |result| {
                    result
                        .tune_check
                        .as_ref()
                        .map_or(f64::INFINITY, |c| c.largest)
                },
            )?;
            if said.is_some() {
                result.accuracy = said;
            }
            Some(result)
        }
    };
    let megno_map = match options.map {
        0 => None,
        pixels => {
            say(format!("MEGNO map, {pixels}² orbits …"));
            let check = match options.accuracy {
                Some(accuracy) => crate::analysis::check::pixels_to_state(options.check, accuracy),
                None => options.check,
            };
            let map = |tol: f64| SectionMapSettings {
                section: SectionSettings {
                    tol,
                    ..settings.clone()
                },
                pixels,
                t_max: options.map_time,
                extent: options.extent,
                check,
            };
            let (mut result, said) = to_accuracy(
                settings.tol,
                options.accuracy,
                |tol| section_map(model, params, &map(tol)),
                |result| {
                    (result.class_check.as_ref()).map_or(f64::INFINITY, |c| c.fraction.max(c.error))
                },
            )?;
            result.accuracy = said;
            Some(result)
        }
    };
    Ok(SectionStudy {
        section,
        megno_map,
        frequency_map,
    })
}

/// The section's orbits with their crossings' errors (where `check` is
/// not 0: the same seeds again at a hundredth of the tolerance); with an
/// `accuracy`, the tolerance tightened a hundredfold until every crossing's
/// error is within it.
fn checked_section(
    model: &Model,
    params: &[f64],
    seeds: &[[f64; 2]],
    settings: &SectionSettings,
    options: &SectionOptions,
) -> Result<Section, SectionError> {
    let at = |tol: f64| {
        let settings = SectionSettings {
            tol,
            ..settings.clone()
        };
        section(model, params, seeds, &settings)
    };
    let name = model.info.name;
    Refusal::accuracy_within_reach(name, "the crossings", options.accuracy, options.extent)?;
    let (mut result, checked) = crate::analysis::check::checked_run(
        crate::ode::Method::Dop853 {
            rtol: settings.tol,
            atol: settings.tol,
        },
        options.check > 0,
        options.accuracy,
        |method| at(method.accuracy()),
        Section::checked_against,
        Section::largest_crossing_error,
    )?;
    if let Some(checked) = checked {
        (result.crossing_check, result.accuracy) = (Some(checked.runs), checked.accuracy);
    }
    Ok(result)
}

/// `run(tol)` at `tol`, and where an `accuracy` is asked, again a
/// hundredfold tighter while its `error` is larger, down to the precision
/// floor ([`crate::analysis::check::until_accurate`], the maps' Taylor
/// method): the result, and what was reached at which tolerance.
fn to_accuracy<T>(
    tol: f64,
    accuracy: Option<f64>,
    mut run: impl FnMut(f64) -> Result<T, SectionError>,
    error: impl Fn(&T) -> f64,
) -> Result<(T, Option<String>), SectionError> {
    let Some(accuracy) = accuracy else {
        return Ok((run(tol)?, None));
    };
    let (result, method, reached, within) = crate::analysis::check::until_accurate(
        crate::ode::Method::Taylor { tol },
        accuracy,
        |method| run(method.accuracy()),
        error,
    )?;
    let said = format!(
        "accuracy {accuracy:e} {} at tol {:e}: the check's error is {reached:.1e}",
        crate::analysis::check::reached_text(within),
        method.accuracy()
    );
    Ok((result, Some(said)))
}

/// The section's figure and table, its MEGNO map's and its frequency
/// map's, each where it was asked for.
impl crate::outputs::Outputs for SectionStudy {
    fn figures(&self) -> Vec<(String, crate::plot::Figure)> {
        let mut figures = Vec::new();
        if let Some(section) = &self.section {
            figures.push(("section.png".into(), section.figure()));
        }
        if let Some(map) = &self.frequency_map {
            figures.extend(map.figures());
        }
        if let Some(map) = &self.megno_map {
            figures.push(("section_megno.png".into(), map.figure()));
        }
        figures
    }
    fn tables(&self) -> Vec<crate::outputs::Table> {
        use crate::outputs::Table;
        let mut tables = Vec::new();
        if let Some(section) = &self.section {
            let rows = section
                .orbits
                .iter()
                .enumerate()
                .flat_map(|(k, o)| o.points.iter().map(move |p| (k, p[0], p[1])));
            let header = ["orbit", section.axes[0].as_str(), section.axes[1].as_str()];
            tables.push(Table::new("section.csv", &header, rows));
        }
        if let Some(map) = &self.frequency_map {
            tables.extend(map.tables());
        }
        if let Some(map) = &self.megno_map {
            let (window, pixels) = (map.window, map.pixels);
            let at = move |k: usize, range: [f64; 2]| {
                range[0] + (range[1] - range[0]) * (k as f64 + 0.5) / pixels as f64
            };
            let rows = map
                .megno
                .iter()
                .enumerate()
                .map(move |(k, v)| (at(k % pixels, window[0]), at(k / pixels, window[1]), *v));
            let header = [map.axes[0].as_str(), map.axes[1].as_str(), "megno"];
            tables.push(Table::new("section_megno.csv", &header, rows));
        }
        tables
    }
    fn lines(&self) -> Vec<String> {
        let mut lines = Vec::new();
        if let Some(section) = &self.section {
            lines.push(format!(
                "largest |{} − E| on the section {:.1e}, largest distance from the plane {:.1e}",
                section.energy_of, section.largest_energy_drift, section.largest_plane_distance
            ));
            if let Some(check) = &section.crossing_check {
                let worst = section.largest_crossing_error();
                let line = crate::analysis::check::error_line("the crossings' error", worst, check);
                lines.push(line);
            }
            lines.extend(section.accuracy.clone());
            lines.extend(section.ended_early().map(|(k, end)| {
                let o = &section.orbits[k];
                format!(
                    "orbit {k} (seed {:?}) ended after {} points: {end}",
                    o.points[0], o.crossings
                )
            }));
        }
        if let Some(map) = &self.frequency_map {
            lines.extend(map.lines());
        }
        if let Some(map) = &self.megno_map {
            let check = map
                .class_check
                .as_ref()
                .map_or(String::new(), |c| c.describe());
            lines.push(format!(
                "MEGNO map: {} orbits, chaotic fraction {:.4}{check}, in {:.1} s",
                map.accessible, map.chaotic_fraction, map.seconds
            ));
        }
        lines
    }
}
