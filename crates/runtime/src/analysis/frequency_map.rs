//! Laskar's frequency map on a surface of section, or of a period map:
//! over a grid of the section's accessible region at energy E (as the
//! MEGNO map's), or of a plane of the period map (the chaos map's), each
//! orbit's fundamental frequencies (ν₁, ν₂) by NAFF of q_j + i p_j, and
//! its frequency diffusion index, log₁₀ of the largest change of a
//! fundamental frequency between the orbit's first and second halves:
//! near the rounding on KAM tori, large in the chaotic layers. The
//! orbits run in the batch Taylor lanes on all cores.

use super::frequency::{naff, NaffSettings};
use super::section::{SectionError, SectionSettings};
use super::section_map::SectionGrid;
use crate::analysis::Refusal;
use crate::ode::{LaneIntegrator, Method, Orbit};
use crate::plot::{ColorMap, Figure, PanelSpec};
use crate::registry::{Fixed, Model};
use nalgebra::Complex;
use rayon::prelude::*;

/// What a frequency map computes.
#[derive(Clone, Debug)]
pub struct FrequencyMapSettings {
    /// The plane, its crossing direction, the energy and the Taylor
    /// method's tolerance (`crossings` is not used).
    pub section: SectionSettings,
    /// Pixels per side.
    pub pixels: usize,
    /// The time each orbit runs, and the samples taken over it.
    pub t_max: f64,
    pub samples: usize,
    /// The accessible region is searched for in [−extent, extent]².
    pub extent: f64,
    /// Orbits run again at a hundredth of the tolerance to state the
    /// tunes' integration error (0: none).
    pub check: usize,
}

/// The frequency map of a period map reads the chaos map's plane and
/// settings, with its own values: fewer pixels, orbits of 1000 periods (NAFF
/// needs them long), and a tighter tolerance (the tunes to 1e-10).
pub fn period_map_options() -> crate::analysis::chaos_map::ChaosMapOptions {
    crate::analysis::chaos_map::ChaosMapOptions {
        pixels: 100,
        periods: 1000,
        tol: 1e-10,
        ..Default::default()
    }
}

/// A diffusion index below this is a regular orbit (a torus): its
/// frequencies drift by less than 1e-4 between the halves. (Hénon–Heiles
/// at E = 1/8 over T = 2000: 41.7 % of the section regular by it, 42.5 %
/// by MEGNO's ⟨Y⟩ < 4.)
pub const REGULAR_INDEX: f64 = -4.0;

/// A frequency map of a section or of a period map.
#[derive(Debug, serde::Serialize)]
pub struct FrequencyMap {
    pub model: String,
    /// What was sampled: "the section at H = 0.125", "the period map".
    pub surface: String,
    pub axes: [String; 2],
    pub window: [[f64; 2]; 2],
    pub pixels: usize,
    /// The time each orbit ran, and the samples NAFF was given (a period
    /// map's: its iterates, one a period).
    pub t_max: f64,
    pub samples: usize,
    /// Pixels where the energy is accessible, and those whose diffusion
    /// index is below [`REGULAR_INDEX`].
    pub accessible: usize,
    pub regular: usize,
    pub regular_fraction: f64,
    /// Orbits the integrator could not follow (NaN in both maps).
    pub failed: usize,
    /// The tunes' integration error, from a sample rerun at a hundredth
    /// of the tolerance (None: not checked).
    pub tune_check: Option<TuneCheck>,
    /// Whether the `accuracy` asked for was reached, and by which run.
    pub accuracy: Option<String>,
    pub seconds: f64,
    /// (ν₁, ν₂) per pixel, row 0 at the bottom; NaN where the energy is
    /// not accessible (ν₂ NaN for a period map of one degree of freedom).
    #[serde(skip)]
    pub frequencies: Vec<[f64; 2]>,
    /// The diffusion index per pixel.
    #[serde(skip)]
    pub diffusion: Vec<f64>,
}

/// The frequency map of the section of a 2-degree autonomous `model`.
pub fn frequency_map(
    model: &Model,
    params: &[f64],
    settings: &FrequencyMapSettings,
) -> Result<FrequencyMap, SectionError> {
    let name = model.info.name.to_string();
    let bad = |requirement: &'static str| SectionError::from(Refusal::setting(&name, requirement));
    if !(settings.t_max.is_finite() && settings.t_max > 0.0) || settings.samples < 64 {
        return Err(bad("t_max positive and at least 64 samples per orbit"));
    }
    let method = Method::Taylor {
        tol: settings.section.tol,
    };
    method.validate()?;
    let start = std::time::Instant::now();
    let grid = SectionGrid::new(
        model,
        params,
        &settings.section,
        (settings.pixels, settings.extent),
        "a frequency map",
    )?;
    if grid.fixed.has_fast_phase() {
        return Err(Refusal::FastPhase {
            model: name,
            instead: "its frequency map is that of its period map (`period_map_frequencies`: the frequency_map scene's `periods`)",
        }
        .into());
    }
    let n = grid.pixels;
    let system = grid.fixed.exact(params);
    let dt = settings.t_max / settings.samples as f64;
    // The tunes and diffusion index of the pixels `ks` by `method` (None
    // where the energy is not accessible; NaN where the run failed).
    let tunes_of = |ks: &[usize], method| -> Result<Vec<Option<([f64; 2], f64)>>, SectionError> {
        let seeds: Vec<(usize, [f64; 4])> = (ks.iter().enumerate())
            .filter_map(|(i, &k)| grid.seeds[k].map(|y| (i, y)))
            .collect();
        let starts: Vec<[f64; 4]> = seeds.iter().map(|(_, y)| *y).collect();
        let mut states: Vec<Vec<[f64; 4]>> = starts
            .iter()
            .map(|y| {
                let mut v = Vec::with_capacity(settings.samples);
                v.push(*y);
                v
            })
            .collect();
        let mut integrator = LaneIntegrator::new(method)?;
        let orbits = Orbit::of_one_system(&system, dt, &starts);
        let errors = integrator.stream(&orbits, |k, y| {
            states[k].push(*y);
            states[k].len() < settings.samples
        });
        let mut block = vec![None; ks.len()];
        for (((i, _), orbit), error) in seeds.iter().zip(&states).zip(errors) {
            block[*i] = match error {
                None => Some(analyse(orbit, dt)),
                Some(_) => Some(([f64::NAN; 2], f64::NAN)),
            };
        }
        Ok(block)
    };
    let blocks: Vec<Vec<Option<([f64; 2], f64)>>> = super::row_blocks(0..n, n)
        .into_par_iter()
        .map(|rows| tunes_of(&(rows.start * n..rows.end * n).collect::<Vec<_>>(), method))
        .collect::<Result<_, _>>()?;
    let pixels: Vec<Option<([f64; 2], f64)>> = blocks.into_iter().flatten().collect();
    let accessible = pixels.iter().flatten().count();
    let failed = pixels.iter().flatten().filter(|(_, d)| d.is_nan()).count();
    let regular = pixels
        .iter()
        .flatten()
        .filter(|(_, d)| *d < REGULAR_INDEX)
        .count();
    let tune_check = match settings.check {
        0 => None,
        count => {
            let rerun = super::check::rerun_sample(n * n, count, method, |ks, method| {
                tunes_of(ks, method)
            })?;
            // Only the regular orbits' tunes have an integration error.
            let pairs = (rerun.pixels.iter())
                .zip(rerun.values)
                .filter_map(|(&k, again)| Some((pixels[k]?, again?)))
                .filter(|((_, index), _)| *index < REGULAR_INDEX)
                .map(|((nu, _), (again, _))| (nu, again));
            Some(TuneCheck::new(pairs, rerun.runs))
        }
    };
    Ok(FrequencyMap {
        model: name,
        surface: format!(
            "the section at {} = {}",
            grid.energy_of, settings.section.energy
        ),
        axes: grid.axes,
        window: grid.window,
        pixels: n,
        t_max: settings.t_max,
        samples: settings.samples,
        accessible,
        regular,
        regular_fraction: regular as f64 / (accessible - failed).max(1) as f64,
        failed,
        tune_check,
        accuracy: None,
        seconds: start.elapsed().as_secs_f64(),
        frequencies: pixels
            .iter()
            .map(|p| p.map_or([f64::NAN; 2], |(nu, _)| nu))
            .collect(),
        diffusion: pixels
            .iter()
            .map(|p| p.map_or(f64::NAN, |(_, d)| d))
            .collect(),
    })
}

/// The frequency map of `model`'s period map on the chaos map's plane
/// (`settings` as [`super::chaos_map::chaos_map`]'s; `periods` iterates
/// per orbit, at least 64): each orbit's [`tunes`] and diffusion index.
/// `done(k)` is told as blocks of k orbits end. With `accuracy`, the map is
/// run again a hundredfold tighter until its tune check's largest change
/// is within it, or the tolerance reaches the precision floor.
pub fn period_map_frequencies(
    model: &Model,
    params: &[f64],
    settings: &super::chaos_map::ChaosMapSettings,
    done: &(dyn Fn(usize) + Sync),
) -> Result<FrequencyMap, super::period_map::PeriodMapError> {
    let Some(accuracy) = settings.accuracy else {
        return frequencies_once(model, params, settings, done);
    };
    let mut settings = settings.clone();
    settings.check = settings.check.max(256);
    let (mut map, method, largest, reached) = super::check::until_accurate(
        settings.method,
        accuracy,
        |method| {
            let at = super::chaos_map::ChaosMapSettings {
                method,
                ..settings.clone()
            };
            frequencies_once(model, params, &at, done)
        },
        |map| map.tune_check.as_ref().map_or(f64::INFINITY, |c| c.largest),
    )?;
    map.accuracy = Some(format!(
        "accuracy {accuracy:e} {} with {}: a regular orbit's tune changes by at most {largest:.1e}",
        super::check::reached_text(reached),
        method.describe()
    ));
    Ok(map)
}

/// [`period_map_frequencies`] at the settings' method, its tune check
/// included.
fn frequencies_once(
    model: &Model,
    params: &[f64],
    settings: &super::chaos_map::ChaosMapSettings,
    done: &(dyn Fn(usize) + Sync),
) -> Result<FrequencyMap, super::period_map::PeriodMapError> {
    let flows = super::flows(model)?;

    super::method_applies(model, settings.method)?;
    let info = model.info;
    let period = super::period_map::fast_phase_period(flows, params)?;
    if settings.periods < 64 {
        return Err(Refusal::setting(info.name, "a frequency map needs periods ≥ 64").into());
    }
    let periodic = flows.periodic_state();
    let request = super::chaos_map::request(info, params, settings, flows.base_state(params))?;
    let ranges = super::chaos_map::plane_ranges(settings, &periodic);
    let n = settings.pixels;
    crate::budget::check_map(n).map_err(crate::ode::OdeError::from)?;
    let start = std::time::Instant::now();
    let recording = crate::registry::Recording {
        transient: 0,
        record: settings.periods,
        settle: None,
        known: None,
        done,
    };
    // The tunes and diffusion index of the pixels `ks` by `method`.
    let tunes_of = |ks: &mut dyn Iterator<Item = usize>,
                    method|
     -> Result<Vec<([f64; 2], f64)>, super::period_map::PeriodMapError> {
        let starts: Vec<Option<Vec<f64>>> = ks
            .map(|k| {
                let (x, y) = super::chaos_map::pixel_centre(&ranges, n, k);
                let mut state = request.through.clone();
                (state[settings.axes[0]], state[settings.axes[1]]) = (x, y);
                flows
                    .consistent(params, &mut state, &settings.axes)
                    .ok()
                    .map(|()| state)
            })
            .collect();
        let flat: Vec<f64> = starts.iter().flatten().flatten().copied().collect();
        let mut runs = flows
            .iterates(params, method, period, &flat, &recording)?
            .into_iter();
        Ok(starts
            .iter()
            .map(
                |start| match start.as_ref().and_then(|_| runs.next().flatten()) {
                    Some(run) => {
                        let (nu, index) = tunes(&run, &periodic);
                        ([nu[0], nu.get(1).copied().unwrap_or(f64::NAN)], index)
                    }
                    None => ([f64::NAN; 2], f64::NAN),
                },
            )
            .collect())
    };
    // Rows in blocks: each block's orbits run together and are analysed
    // as they end, so only a block's iterates are held.
    let blocks: Vec<Vec<([f64; 2], f64)>> = super::row_blocks(0..n, n)
        .into_par_iter()
        .map(|rows| tunes_of(&mut (rows.start * n..rows.end * n), settings.method))
        .collect::<Result<_, _>>()?;
    let pixels: Vec<([f64; 2], f64)> = blocks.into_iter().flatten().collect();
    let failed = pixels.iter().filter(|(_, d)| d.is_nan()).count();
    let regular = pixels.iter().filter(|(_, d)| *d < REGULAR_INDEX).count();
    let tune_check = match settings.check {
        0 => None,
        count => {
            let rerun = super::check::rerun_sample(n * n, count, settings.method, |ks, method| {
                tunes_of(&mut ks.iter().copied(), method)
            })?;
            // A chaotic orbit's tunes move with any change of the run:
            // only the regular orbits' tunes have an integration error.
            let pairs = (rerun.pixels.iter())
                .zip(rerun.values)
                .filter(|(&k, _)| pixels[k].1 < REGULAR_INDEX)
                .map(|(&k, (nu, _))| (pixels[k].0, nu));
            Some(TuneCheck::new(pairs, rerun.runs))
        }
    };
    Ok(FrequencyMap {
        model: info.name.into(),
        surface: "the period map".into(),
        axes: request.axes,
        window: ranges.map(|(lo, hi)| [lo, hi]),
        pixels: n,
        t_max: period * settings.periods as f64,
        samples: settings.periods,
        accessible: n * n,
        regular,
        regular_fraction: regular as f64 / (n * n - failed).max(1) as f64,
        failed,
        tune_check,
        accuracy: None,
        seconds: start.elapsed().as_secs_f64(),
        frequencies: pixels.iter().map(|(nu, _)| *nu).collect(),
        diffusion: pixels.iter().map(|(_, d)| *d).collect(),
    })
}

/// The tunes' numerical error: a sample of the map's orbits run again at a
/// hundredth of the tolerance, and how far the regular ones' tunes move
/// (the integration's part; the diffusion index is NAFF's own, and a
/// chaotic orbit's tunes are not defined).
#[derive(Clone, Debug, serde::Serialize)]
pub struct TuneCheck {
    /// Tunes compared (one or two an orbit: the sampled regular orbits'
    /// that both runs have).
    pub sampled: usize,
    /// The median and the largest change of a tune between the runs.
    pub median: f64,
    pub largest: f64,
    /// The two runs ("taylor, tol 1e-10 against taylor, tol 1e-12").
    pub runs: String,
}

impl TuneCheck {
    fn new(pairs: impl Iterator<Item = ([f64; 2], [f64; 2])>, runs: String) -> TuneCheck {
        let mut changes: Vec<f64> = pairs
            .flat_map(|(a, b)| [(a[0] - b[0]).abs(), (a[1] - b[1]).abs()])
            .filter(|d| d.is_finite())
            .collect();
        changes.sort_by(f64::total_cmp);
        TuneCheck {
            sampled: changes.len(),
            median: changes.get(changes.len() / 2).copied().unwrap_or(f64::NAN),
            largest: changes.last().copied().unwrap_or(f64::NAN),
            runs,
        }
    }
}

/// The tunes of an orbit of a period map (its states one a period, angles
/// wrapped or not), one per degree of freedom in turns per period, and its
/// diffusion index: NAFF of q_j − i p_j less its mean, where an angle is
/// first unwrapped along the orbit; of e^{i q_j} for an angle that
/// circulates (its unwrapped range passes 2π). A libration turns
/// clockwise in (q, p), as Hamilton's equations turn it (q′ = p), so
/// q − i p makes its tune positive; a circulation's sign is its direction.
pub fn tunes(run: &[Vec<f64>], periodic: &[bool]) -> (Vec<f64>, f64) {
    let dof = periodic.len() / 2;
    let signals: Vec<Vec<Complex<f64>>> = (0..dof)
        .map(|j| {
            let mut q: Vec<f64> = run.iter().map(|y| y[j]).collect();
            if periodic[j] {
                unwrap(&mut q);
            }
            let (low, high) = q
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
                    (a.min(x), b.max(x))
                });
            let signal: Vec<Complex<f64>> = if periodic[j] && high - low > std::f64::consts::TAU {
                q.iter().map(|&x| Complex::from_polar(1.0, x)).collect()
            } else {
                q.iter()
                    .zip(run)
                    .map(|(&x, y)| Complex::new(x, -y[j + dof]))
                    .collect()
            };
            // Less its mean: a constant term would be the largest.
            let mean = signal.iter().sum::<Complex<f64>>() / signal.len() as f64;
            signal.iter().map(|z| z - mean).collect()
        })
        .collect();
    // Angular frequencies per period of 1, in turns.
    let (nu, index) = fundamentals(&signals, 1.0);
    (
        nu.iter().map(|w| w / std::f64::consts::TAU).collect(),
        index,
    )
}

/// Adds multiples of 2π to make each step of the angles `q` less than π.
fn unwrap(q: &mut [f64]) {
    use std::f64::consts::{PI, TAU};
    let mut shift = 0.0;
    for k in 1..q.len() {
        let raw = q[k] + shift;
        let step = raw - q[k - 1];
        shift -= TAU * ((step + PI) / TAU).floor();
        q[k] += shift;
    }
}

/// An orbit's fundamental frequencies (q_j − i p_j, the largest term:
/// positive for the clockwise turn of a libration in (q, p))
/// over the whole orbit, and its diffusion index between its halves.
fn analyse(orbit: &[[f64; 4]], dt: f64) -> ([f64; 2], f64) {
    let signals: Vec<Vec<Complex<f64>>> = (0..2)
        .map(|j| {
            orbit
                .iter()
                .map(|y| Complex::new(y[j], -y[j + 2]))
                .collect()
        })
        .collect();
    let (nu, index) = fundamentals(&signals, dt);
    ([nu[0], nu[1]], index)
}

/// Each signal's fundamental frequency (its largest NAFF term) over its
/// whole length (NaN where it has none), and the diffusion index: log₁₀
/// of the largest change of one between the signals' first and second
/// halves (a change of exactly 0 counts as 1e-16).
fn fundamentals(signals: &[Vec<Complex<f64>>], dt: f64) -> (Vec<f64>, f64) {
    let settings = NaffSettings {
        terms: 1,
        window_order: 1,
    };
    let fundamental = |signal: &[Complex<f64>]| {
        naff(signal, dt, &settings)
            .ok()
            .and_then(|terms| terms.first().map(|t| t.frequency))
            .unwrap_or(f64::NAN)
    };
    let nu = signals.iter().map(|s| fundamental(s)).collect();
    let drift = signals
        .iter()
        .map(|s| {
            let half = s.len() / 2;
            (fundamental(&s[..half]) - fundamental(&s[half..])).abs()
        })
        .fold(0.0_f64, f64::max);
    (nu, drift.max(1e-16).log10())
}

impl FrequencyMap {
    /// The diffusion index over the section (−12 to 0, white where the
    /// energy is not accessible) beside the frequency map ν₂ against ν₁,
    /// each orbit a dot coloured by its index: the tori's frequencies
    /// fill curves, the resonances show as lines through them, chaotic
    /// orbits scatter.
    pub fn figure(&self) -> Figure {
        let t_max = format!("{:.4}", self.t_max);
        let title = format!(
            "{}: diffusion index on {}, T = {}; regular (< {REGULAR_INDEX}): {:.1} %",
            self.model,
            self.surface,
            t_max.trim_end_matches('0').trim_end_matches('.'),
            100.0 * self.regular_fraction
        );
        // One degree of freedom: its frequency against the first axis.
        let one = self.frequencies.iter().all(|nu| nu[1].is_nan());
        let (w, n) = (self.window[0], self.pixels);
        let pair = |k: usize, nu: [f64; 2]| match one {
            true => [
                w[0] + (w[1] - w[0]) * ((k % n) as f64 + 0.5) / n as f64,
                nu[0],
            ],
            false => nu,
        };
        let shown: Vec<[f64; 2]> = (self.frequencies.iter().enumerate())
            .map(|(k, &nu)| pair(k, nu))
            .collect();
        let finite: Vec<[f64; 2]> = (shown.iter().copied())
            .filter(|nu| nu.iter().all(|x| x.is_finite()))
            .collect();
        let range = |j: usize| {
            finite
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), nu| {
                    (a.min(nu[j]), b.max(nu[j]))
                })
        };
        let specs = [
            PanelSpec::new(
                &title,
                &self.axes[0],
                &self.axes[1],
                (self.window[0][0], self.window[0][1]),
                (self.window[1][0], self.window[1][1]),
            ),
            match one {
                true => PanelSpec::new(
                    "frequency against the first axis (colour: diffusion index)",
                    &self.axes[0],
                    "ν₁",
                    range(0),
                    range(1),
                ),
                false => PanelSpec::new(
                    "frequency map (colour: diffusion index)",
                    "ν₁",
                    "ν₂",
                    range(0),
                    range(1),
                ),
            },
        ];
        let mut figure = Figure::grid(2, 1, 660, 620, &specs);
        let shade = |d: f64| ((d + 12.0) / 12.0).clamp(0.0, 1.0);
        let shades: Vec<f64> = self.diffusion.iter().map(|&d| shade(d)).collect();
        figure.shaded_map(
            0,
            self.pixels,
            self.pixels,
            &shades,
            ColorMap::Viridis,
            "(index + 12) / 12",
        );
        // Ten bands of the index, each its colour.
        for band in 0..10 {
            let points = (shown.iter())
                .zip(&self.diffusion)
                .filter(|(_, &d)| ((shade(d) * 10.0) as usize).min(9) == band)
                .map(|(nu, _)| (nu[0], nu[1]));
            let colour = ColorMap::Viridis.rgb((band as f64 + 0.5) / 10.0);
            figure.points(1, points, colour, 1);
        }
        figure
    }
}

impl crate::outputs::Outputs for FrequencyMap {
    fn figures(&self) -> Vec<(String, crate::plot::Figure)> {
        vec![("frequency_map.png".into(), self.figure())]
    }
    fn tables(&self) -> Vec<crate::outputs::Table> {
        let pixels = self.pixels;
        let rows = (0..pixels * pixels).filter_map(|k| {
            let [nu1, nu2] = self.frequencies[k];
            nu1.is_finite()
                .then_some((k % pixels, k / pixels, nu1, nu2, self.diffusion[k]))
        });
        let header = ["column", "row", "nu1", "nu2", "diffusion_index"];
        vec![crate::outputs::Table::new(
            "frequency_map.csv",
            &header,
            rows,
        )]
    }
    fn lines(&self) -> Vec<String> {
        let mut lines = vec![format!(
            "{} orbits, {:.1} % regular, in {:.1} s",
            self.accessible,
            100.0 * self.regular_fraction,
            self.seconds
        )];
        if let Some(c) = &self.tune_check {
            lines.push(format!(
                "regular orbits' tunes, integration error: median {:.1e}, largest {:.1e} over {} tunes rerun ({})",
                c.median, c.largest, c.sampled, c.runs
            ));
        }
        lines.extend(self.accuracy.clone());
        lines
    }
}
