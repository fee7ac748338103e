//! The FLI chaos map of the period map of any model with a fast phase, by
//! name: every pixel of a plane of two state components (through a given
//! state) shaded by the fast Lyapunov indicator of its orbit. For one degree
//! of freedom the plane is the cylinder (q, p).

use super::check::{rerun_sample, ClassCheck};
use super::lyapunov::{fli_is_chaotic, fli_shading};
use super::tiles::{fingerprint, run_tiles};
pub use super::tiles::{TileError, Tiles};
use crate::analysis::Refusal;
use crate::ode::{Method, OdeError};
use crate::registry::Model;
use crate::settings::{method, resolve_axes, Axis, Declared, Range, METHODS};
use rayon::prelude::*;
use serde::Serialize;
use std::collections::BTreeMap;
use std::f64::consts::PI;

crate::declare_settings! {
    /// The FLI chaos map of the period map: every pixel of a plane of two
    /// state components shaded by the fast Lyapunov indicator of its orbit.
    pub struct ChaosMapOptions for "chaos_map" {
        /// The state components [q; p] along the two axes, by index (0 = the
        /// first coordinate) or name (auto: the first coordinate and its
        /// momentum, or velocity).
        axes: Option<[Axis; 2]> = None, Range::Any;
        /// The state the plane passes through, one value per component (auto:
        /// zero, or a constrained model's start).
        through: Option<Vec<f64>> = None, Range::Any;
        /// The axes' ranges x0,x1,y0,y1 (auto: [−π, π] for an angle,
        /// [−p_max, p_max] otherwise).
        ranges: Option<[[f64; 2]; 2]> = None, Range::Any;
        /// The half-width of an axis that is not an angle, where the ranges
        /// are auto.
        p_max: f64 = 3.0, Range::Positive;
        /// Pixels per side.
        pixels: usize = 300, Range::Count { min: 1, max: 4000 };
        /// Periods of the phase per pixel.
        periods: usize = 180, Range::Count { min: 1, max: 1_000_000 };
        /// The integration method.
        method: String = "taylor".into(), Range::OneOf(METHODS);
        /// Its tolerance (taylor, dop853, radau5) or step size (rk4, gauss4,
        /// gauss6).
        tol: f64 = 1e-6, Range::Positive;
        /// Pixels run again at a hundredth of the tolerance, spread over the
        /// map, to count those whose class (chaotic or regular) changes:
        /// the map's numerical error (0: none).
        check: usize = 256, Range::Count { min: 0, max: 16_000_000 };
        /// The largest share of pixels that may change class in a run at a
        /// hundredth of the tolerance (of a period map's frequency map: the
        /// largest change of a regular orbit's tune) (auto: none asked; the
        /// check is reported). Given, the map is run again a hundredfold
        /// tighter until the check is within it, or the result says why not.
        accuracy: Option<f64> = None, Range::Between { low: 0.0, high: 1.0 };
    }
    interactive { periods: 100, check: 64 }
}

impl ChaosMapOptions {
    /// The settings of [`chaos_map`] for `model`, `auto` resolved; refused
    /// here, before any work, where the analysis does not apply.
    pub fn resolve(&self, model: &Model) -> Result<ChaosMapSettings, ChaosMapError> {
        super::period_map_flows(model)?;
        let method = method(Self::ANALYSIS, &self.method, self.tol)?;
        super::method_applies(model, method)?;
        Ok(ChaosMapSettings {
            axes: resolve_axes(Self::ANALYSIS, model.info, &self.axes)?,
            ranges: self
                .ranges
                .map_or([None, None], |r| r.map(|[low, high]| Some((low, high)))),
            p_max: self.p_max,
            through: self.through.clone(),
            pixels: self.pixels,
            periods: self.periods,
            method,
            check: self.check,
            accuracy: self.accuracy,
            tiles: None,
        })
    }
}

/// What [`chaos_map`] draws, resolved for one model from
/// [`ChaosMapOptions`].
#[derive(Clone, Debug)]
pub struct ChaosMapSettings {
    /// The state components ([q; p] indices) along the map's two axes.
    pub axes: [usize; 2],
    /// The range of each axis (None: [−π, π] for an angle, [−p_max, p_max]
    /// otherwise).
    pub ranges: [Option<(f64, f64)>; 2],
    /// The half-width of the default range of an axis that is not an angle.
    pub p_max: f64,
    /// The state the plane passes through (its other components); None: 0.
    pub through: Option<Vec<f64>>,
    /// Pixels per side.
    pub pixels: usize,
    /// Periods of the phase per pixel.
    pub periods: usize,
    pub method: Method,
    /// Pixels rerun at a hundredth of the tolerance to count those whose
    /// class changes (0: none).
    pub check: usize,
    /// The largest share of pixels that may change class (None: the share
    /// is reported, not chosen).
    pub accuracy: Option<f64>,
    /// Cut the map into tiles of whole rows, each written to a file when
    /// done (None: one run in memory).
    pub tiles: Option<Tiles>,
}

/// The map and its key numbers (the FLI values are not serialised: they go
/// to a CSV beside the summary).
#[derive(Clone, Debug, Serialize)]
pub struct ChaosMap {
    pub model: String,
    pub params: BTreeMap<String, f64>,
    /// The names of the two axes' state components.
    pub axes: [String; 2],
    /// The axes in the figures' notation (φ₁, p_φ₁, φ₁′).
    #[serde(skip)]
    pub labels: [String; 2],
    pub ranges: [(f64, f64); 2],
    pub through: Vec<f64>,
    pub pixels: usize,
    pub periods: usize,
    pub method: &'static str,
    /// Share of pixels above twice the regular level (diverged ones too).
    pub chaotic_fraction: f64,
    /// Pixels whose orbit left the model's domain (a non-finite state, or a
    /// step-size underflow at a singular point): their FLI is +∞, shaded as
    /// the most chaotic.
    pub diverged: usize,
    /// Pixels where a constrained model has no state with those two
    /// components (outside its reach, or a chart singular there): their
    /// FLI is NaN, and the figure leaves them blank.
    pub without_state: usize,
    /// ln(periods): the FLI of a regular orbit.
    pub fli_regular_level: f64,
    /// The share of pixels whose class changes in a run at a hundredth of
    /// the tolerance, from a sample of them: the numerical error of
    /// `chaotic_fraction` (None: not checked).
    pub class_check: Option<ClassCheck>,
    /// Whether the `accuracy` asked for was reached, and by which run.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub accuracy: Option<String>,
    pub seconds: f64,
    pub f_evals: u64,
    /// Row-major from the lower left: pixel (i, j) at index j·pixels + i.
    #[serde(skip)]
    pub fli: Vec<f64>,
    /// Grey levels in [0, 1] for the figure (1 = most chaotic).
    #[serde(skip)]
    pub shades: Vec<f64>,
}

impl ChaosMap {
    /// The centre of pixel k (row-major from the lower left).
    pub fn pixel(&self, k: usize) -> (f64, f64) {
        pixel_centre(&self.ranges, self.pixels, k)
    }
}

pub(super) fn pixel_centre(ranges: &[(f64, f64); 2], pixels: usize, k: usize) -> (f64, f64) {
    let (i, j) = (k % pixels, k / pixels);
    let at = |(lo, hi): (f64, f64), i: usize| lo + (hi - lo) * (i as f64 + 0.5) / pixels as f64;
    (at(ranges[0], i), at(ranges[1], j))
}

/// Why [`chaos_map`] cannot run: the errors of the period map's analyses.
pub use super::period_map::PeriodMapError as ChaosMapError;

/// The FLI map of `model` with parameter values `params`
/// (declaration order); `row_done` is called for each row as the block of
/// rows holding it is finished (from the worker threads) and returns
/// whether to go on: once it says false, blocks not yet started are
/// skipped and the map ends with
/// [`ChaosMapError::Cancelled`] (nobody is waiting for it any more).
pub fn chaos_map(
    model: &Model,
    params: &[f64],
    settings: &ChaosMapSettings,
    row_done: &(dyn Fn() -> bool + Sync),
) -> Result<ChaosMap, ChaosMapError> {
    let Some(accuracy) = settings.accuracy else {
        return map_once(model, params, settings, row_done);
    };
    let mut settings = settings.clone();
    settings.check = super::check::pixels_to_state(settings.check.max(256), accuracy);
    let (mut map, method, check, reached) = super::check::until_accurate(
        settings.method,
        accuracy,
        |method| {
            map_once(
                model,
                params,
                &ChaosMapSettings {
                    method,
                    ..settings.clone()
                },
                row_done,
            )
        },
        |map| {
            map.class_check
                .as_ref()
                .map_or(f64::INFINITY, |c| c.fraction.max(c.error))
        },
    )?;
    map.accuracy = Some(format!(
        "accuracy {accuracy} {} with {}: a share {check} of the checked pixels changes class",
        super::check::reached_text(reached),
        method.describe()
    ));
    Ok(map)
}

/// [`chaos_map`] at the settings' method, its class check included.
fn map_once(
    model: &Model,
    params: &[f64],
    settings: &ChaosMapSettings,
    row_done: &(dyn Fn() -> bool + Sync),
) -> Result<ChaosMap, ChaosMapError> {
    let systems = crate::analysis::flows(model)?;
    crate::analysis::method_applies(model, settings.method)?;
    let info = systems.info();
    let period = super::period_map::fast_phase_period(systems, params)?;
    let periodic = systems.periodic_state();
    let Request {
        params: named,
        axes,
        labels,
        through,
    } = request(info, params, settings, systems.base_state(params))?;
    let ranges = plane_ranges(settings, &periodic);
    crate::budget::check_map(settings.pixels).map_err(OdeError::from)?;
    let plane = Plane {
        systems,
        params,
        settings,
        period,
        ranges,
        // √(1/n): for n = 2 exactly FRAC_1_SQRT_2, the Kapitza scene's vector.
        w0: vec![(1.0 / through.len() as f64).sqrt(); through.len()],
        through: &through,
    };
    let pixels = settings.pixels;
    let stopped = std::sync::atomic::AtomicBool::new(false);
    let block = |rows: std::ops::Range<usize>| -> Result<(Vec<f64>, u64), OdeError> {
        if stopped.load(std::sync::atomic::Ordering::Relaxed) {
            return Ok((Vec::new(), 0));
        }
        let (values, f_evals) = plane.fli_of(
            &mut (rows.start * pixels..rows.end * pixels),
            settings.method,
        )?;
        for _ in rows {
            if !row_done() {
                stopped.store(true, std::sync::atomic::Ordering::Relaxed);
            }
        }
        Ok((values, f_evals))
    };
    // Rows in blocks ([`super::row_blocks`]); a lane equals its orbit's
    // scalar run bit for bit, so the map does not depend on how the rows
    // are grouped (nor on tiles).
    let rows_of = |range: std::ops::Range<usize>| -> Result<(Vec<f64>, u64), ChaosMapError> {
        let rows: Vec<(Vec<f64>, u64)> = super::row_blocks(range, pixels)
            .into_par_iter()
            .map(block)
            .collect::<Result<_, _>>()?;
        if stopped.load(std::sync::atomic::Ordering::Relaxed) {
            return Err(ChaosMapError::Cancelled);
        }
        Ok(rows
            .into_iter()
            .fold((Vec::new(), 0), |(mut all, evals), (values, e)| {
                all.extend(values);
                (all, evals + e)
            }))
    };
    let start = std::time::Instant::now();
    let (fli, f_evals) = match &settings.tiles {
        None => rows_of(0..pixels)?,
        Some(tiles) => {
            let key = format!(
                "{} {:?} {:?} {:?} {:?} {} {} {:?} {}",
                info.name,
                params,
                settings.axes,
                ranges,
                through,
                pixels,
                settings.periods,
                settings.method,
                tiles.rows
            );
            match run_tiles(tiles, fingerprint(&key), (pixels, pixels, "rows"), &rows_of)? {
                Some(map) => map,
                None => return Err(ChaosMapError::Partial),
            }
        }
    };
    let class_check = match settings.check {
        0 => None,
        count => Some(class_check(&fli, count, &plane)?),
    };
    let seconds = start.elapsed().as_secs_f64();
    let shading = fli_shading(&fli, settings.periods);
    Ok(ChaosMap {
        model: info.name.into(),
        params: named,
        axes,
        labels,
        ranges,
        through,
        pixels,
        periods: settings.periods,
        method: settings.method.name(),
        chaotic_fraction: shading.chaotic_fraction,
        diverged: fli.iter().filter(|f| f.is_infinite()).count(),
        without_state: fli.iter().filter(|f| f.is_nan()).count(),
        fli_regular_level: shading.regular_level,
        class_check,
        accuracy: None,
        seconds,
        f_evals,
        fli,
        shades: shading.shades,
    })
}

/// A chaos map's plane of starts in a model's state space.
struct Plane<'a> {
    systems: &'static dyn crate::registry::Flows,
    params: &'a [f64],
    settings: &'a ChaosMapSettings,
    period: f64,
    ranges: [(f64, f64); 2],
    through: &'a [f64],
    /// The tangent vector every orbit starts with.
    w0: Vec<f64>,
}

impl Plane<'_> {
    /// The FLI of the pixels `ks` by `method`, and the f-evaluations spent.
    fn fli_of(
        &self,
        ks: &mut dyn Iterator<Item = usize>,
        method: Method,
    ) -> Result<(Vec<f64>, u64), OdeError> {
        let settings = self.settings;
        let mut starts = Vec::new();
        for k in ks {
            let (x, y) = pixel_centre(&self.ranges, settings.pixels, k);
            let at = starts.len();
            starts.extend_from_slice(self.through);
            starts[at + settings.axes[0]] = x;
            starts[at + settings.axes[1]] = y;
        }
        let (values, f_evals) = self.systems.fli(
            self.params,
            method,
            self.period,
            &starts,
            &self.w0,
            settings.periods,
            &settings.axes,
        )?;
        let values = values
            .into_iter()
            .map(pixel_value)
            .collect::<Result<_, _>>()?;
        Ok((values, f_evals))
    }
}

/// The map's [`ClassCheck`]: `count` of its pixels spread over it run
/// again by `fli_of` at a hundredth of the tolerance, on all cores, and
/// their classes (chaotic or regular; none without a state) compared.
fn class_check(fli: &[f64], count: usize, plane: &Plane) -> Result<ClassCheck, OdeError> {
    let periods = plane.settings.periods;
    let rerun = rerun_sample(fli.len(), count, plane.settings.method, |ks, method| {
        plane
            .fli_of(&mut ks.iter().copied(), method)
            .map(|(values, _)| values)
    })?;
    let class = |f: f64| (!f.is_nan()).then(|| fli_is_chaotic(f, periods));
    let census = rerun.census;
    let pairs = (rerun.pixels.iter())
        .zip(rerun.values)
        .map(|(&k, f)| (class(fli[k]), class(f)));
    Ok(ClassCheck::new(pairs, rerun.runs, census))
}

/// The request read against the model: its parameters by name, the
/// plane's axes and the state the plane passes through (by default
/// `base`: zero, or a constrained model's start).
pub(super) fn request(
    info: &'static crate::registry::ModelInfo,
    params: &[f64],
    settings: &ChaosMapSettings,
    base: Vec<f64>,
) -> Result<Request, ChaosMapError> {
    let n = base.len();
    let named = Refusal::named_values(info, params)?;
    let axes = super::period_map::plane_names(info, settings.axes)?;
    let through = match &settings.through {
        Some(y) if y.len() != n => {
            let what = "state the plane passes through";
            return Err(Refusal::state_length(info.name, what, y.len(), n).into());
        }
        Some(y) => y.clone(),
        // The zero state, or a constrained model's start.
        None => base,
    };
    Ok(Request {
        params: named,
        axes,
        labels: settings.axes.map(|a| info.label(a)),
        through,
    })
}

/// A chaos map's request as the model reads it.
pub(super) struct Request {
    pub params: BTreeMap<String, f64>,
    pub axes: [String; 2],
    pub labels: [String; 2],
    pub through: Vec<f64>,
}

/// The ranges of the map's axes: the settings', or [−π, π] for an angle
/// and [−p_max, p_max] for any other component.
pub(super) fn plane_ranges(settings: &ChaosMapSettings, periodic: &[bool]) -> [(f64, f64); 2] {
    std::array::from_fn(|k| {
        let axis = settings.axes[k];
        settings.ranges[k].unwrap_or(if periodic.get(axis) == Some(&true) {
            (-PI, PI)
        } else {
            (-settings.p_max, settings.p_max)
        })
    })
}

/// A pixel's FLI; an orbit that left the model's domain or ran into a
/// singular point (a non-finite state, or steps shrinking to nothing) is
/// infinitely chaotic, counted; other errors end the map.
fn pixel_value(fli: Result<f64, OdeError>) -> Result<f64, OdeError> {
    match fli {
        Err(OdeError::NonFinite { .. } | OdeError::StepSizeUnderflow { .. }) => Ok(f64::INFINITY),
        other => other,
    }
}
impl ChaosMap {
    /// The map in grey and in viridis (the chaotic layer dark in grey,
    /// bright in viridis), axes in the model's notation.
    pub fn figures(&self) -> [crate::plot::Figure; 2] {
        use crate::plot::{ColorMap, Figure, PanelSpec};
        use crate::registry::display_name;
        let params: Vec<String> = self
            .params
            .iter()
            .map(|(k, v)| format!("{} = {v}", display_name(k)))
            .collect();
        // The parameters fit in the title of a small model only (all are in
        // the summary).
        let title = match params.len() {
            0..=4 => format!(
                "{}: FLI map, {}, {} periods",
                self.model,
                params.join(", "),
                self.periods
            ),
            _ => format!("{}: FLI map, {} periods", self.model, self.periods),
        };
        let [x, y] = self.labels.clone();
        let side = self.pixels.max(360);
        let spec = PanelSpec::new(&title, &x, &y, self.ranges[0], self.ranges[1]);
        let label = "FLI: regular level (0) to the 99th percentile (1)";
        [ColorMap::Grey, ColorMap::Viridis].map(|colors| {
            let mut figure = Figure::single(side + 90, side + 75, spec);
            figure.shaded_map(0, self.pixels, self.pixels, &self.shades, colors, label);
            figure
        })
    }
}

impl crate::outputs::Outputs for ChaosMap {
    fn figures(&self) -> Vec<(String, crate::plot::Figure)> {
        let [grey, viridis] = self.figures();
        vec![
            ("chaos_map.png".into(), grey),
            ("chaos_map_viridis.png".into(), viridis),
        ]
    }
    fn tables(&self) -> Vec<crate::outputs::Table> {
        let rows = self.fli.iter().enumerate().map(|(k, fli)| {
            let (a, b) = self.pixel(k);
            (a, b, *fli)
        });
        let header = [self.axes[0].as_str(), self.axes[1].as_str(), "fli"];
        vec![crate::outputs::Table::new("chaos_map.csv", &header, rows)]
    }
    fn lines(&self) -> Vec<String> {
        let check = self
            .class_check
            .as_ref()
            .map_or(String::new(), ClassCheck::describe);
        let mut lines = vec![format!(
            "chaotic fraction {:.4}{check}",
            self.chaotic_fraction
        )];
        lines.extend(self.accuracy.clone());
        lines
    }
}
