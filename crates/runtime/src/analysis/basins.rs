//! Basins of attraction of a period map: every start of a grid on a plane
//! of the state run past a transient, then its next iterates recorded;
//! the attractors found from those records without being told them
//! (starts whose recorded iterates share a cell of the state space are on
//! one attractor, by union–find over the cells), each with its kind (a
//! cycle of period k, or aperiodic), a representative point and the
//! number of starts that reached it; starts whose orbit diverged form a
//! class of their own, never assigned to an attractor.

use super::tiles::{fingerprint, run_tiles, TileError, Tiles};
use super::Refusal;
use crate::ode::{Method, OdeError};
use crate::plot::{palette, Figure, PanelSpec};
use crate::registry::{distance, within, Cells, KnownAttractors, Model, Recording};
use crate::settings::{method, resolve_axes, Axis, Declared, Range, SettingError, METHODS};
use rayon::prelude::*;
use std::collections::HashMap;

crate::declare_settings! {
    /// The basins of attraction of the period map: every start of a plane
    /// coloured by the attractor its orbit ends on, the attractors found
    /// from the orbits.
    pub struct BasinsOptions for "basins" {
        /// The state components along the map's axes, by index or name
        /// (auto: the first coordinate and its momentum, or velocity).
        axes: Option<[Axis; 2]> = None, Range::Any;
        /// The axes' ranges x0,x1,y0,y1.
        ranges: [[f64; 2]; 2] = [[-2.0, 2.0], [-2.0, 2.0]], Range::Any;
        /// The state the plane passes through (auto: the model's base state).
        through: Option<Vec<f64>> = None, Range::Any;
        /// Pixels per side.
        pixels: usize = 200, Range::Count { min: 2, max: 4000 };
        /// Periods run before the record.
        transient: usize = 300, Range::Count { min: 0, max: 1_000_000 };
        /// Periods recorded to identify the attractor.
        record: usize = 16, Range::Count { min: 2, max: 4096 };
        /// The side of the state-space cells that identify attractors.
        cell: f64 = 0.05, Range::Positive;
        /// Stop an orbit once it has settled on a cycle or in a known
        /// attractor (no: run every orbit its whole length, slower).
        stop_early: bool = true, Range::Any;
        /// The integration method.
        method: String = "taylor".into(), Range::OneOf(METHODS);
        /// Its tolerance (taylor, dop853, radau5) or step size (rk4, gauss4,
        /// gauss6).
        tol: f64 = 1e-10, Range::Positive;
        /// Starts run again at a hundredth of the tolerance, spread over the
        /// map, to count those that end on another attractor: the
        /// fractions' numerical error (0: none).
        check: usize = 256, Range::Count { min: 0, max: 16_000_000 };
        /// The error wanted on every basin's fraction (auto: none asked,
        /// each fraction comes with its error). Given, `tol` is tightened a
        /// hundredfold while the check's share of starts that change
        /// attractor is above it, and the pixels per side are raised while
        /// the grid's error is, or the result says why not.
        accuracy: Option<f64> = None, Range::Between { low: 0.0, high: 1.0 };
    }
    interactive { transient: 200, check: 64 }
}

impl BasinsOptions {
    /// The settings of [`basins`] for `model`, `auto` resolved; refused
    /// here, before any work, where the analysis does not apply.
    pub fn resolve(&self, model: &Model) -> Result<BasinSettings, BasinsError> {
        super::period_map_flows(model)?;
        let method = method(Self::ANALYSIS, &self.method, self.tol)?;
        super::method_applies(model, method)?;
        Ok(BasinSettings {
            axes: resolve_axes(Self::ANALYSIS, model.info, &self.axes)?,
            ranges: self.ranges.map(|[low, high]| (low, high)),
            through: self.through.clone(),
            pixels: self.pixels,
            transient: self.transient,
            record: self.record,
            cell: self.cell,
            method,
            stop_early: self.stop_early,
            check: self.check,
            accuracy: self.accuracy,
            tiles: None,
        })
    }
}

/// What a basin map computes, resolved for one model from
/// [`BasinsOptions`].
#[derive(Clone, Debug)]
pub struct BasinSettings {
    /// The state components along the map's axes, and their ranges.
    pub axes: [usize; 2],
    pub ranges: [(f64, f64); 2],
    /// The state the plane passes through (its other components); None:
    /// the model's base state.
    pub through: Option<Vec<f64>>,
    /// Pixels per side.
    pub pixels: usize,
    /// Periods run before the record, then periods recorded.
    pub transient: usize,
    pub record: usize,
    /// The side of the cells of the state space that identify attractors.
    pub cell: f64,
    pub method: Method,
    /// Stop an orbit early: once it has settled on a cycle of period
    /// ≤ record/2 (its iterate back within 1e-8 of a cell of the one k
    /// periods before; its record completed by the cycle), or once
    /// `record` consecutive iterates lie in cells of an attractor that
    /// scouts (every 4th start each way, run first) found from two
    /// starts (its record then that attractor's). False runs every orbit
    /// its whole length: the same labels but for starts that shadow an
    /// attractor for `record` periods and then leave it, slower.
    pub stop_early: bool,
    /// Starts rerun at a hundredth of the tolerance to count those that
    /// end on another attractor (0: none).
    pub check: usize,
    /// The error wanted on the fractions (None: stated, not chosen).
    pub accuracy: Option<f64>,
    /// Rows of starts in tiles written as they are done (resume, job
    /// arrays, MPI ranks).
    pub tiles: Option<Tiles>,
}

/// The kind of an attractor whose record is not a cycle of period
/// ≤ record/2 and whose longer run could not be told (it stopped, or
/// its frequencies could not be found).
pub const APERIODIC: &str = "aperiodic";
/// The kinds a longer run tells an aperiodic record's attractor apart by.
pub const QUASI_PERIODIC: &str = "quasi-periodic";
pub const CHAOTIC: &str = "chaotic";
/// Neither a cycle, nor chaotic, nor shown quasi-periodic by its longer
/// run (a cycle approached too slowly, say): a longer transient tells.
pub const NOT_SETTLED: &str = "not settled";

/// How many periods the representative of an aperiodic attractor runs to
/// find the other pieces of its set.
const EXTENSION: usize = 4096;

/// How far a run's start is moved to see whether nearby orbits close in
/// on it, and the e-folds of closing in over [`EXTENSION`] periods that
/// mark a cycle still being approached (not a torus).
const NUDGE: f64 = 1e-6;
const CLOSING: f64 = 5.0;

/// The label of a start whose orbit diverged or left the model's domain.
pub const DIVERGED: i32 = -1;

/// Why a basin map cannot be made.
#[derive(Debug, thiserror::Error)]
pub enum BasinsError {
    #[error(transparent)]
    Refused(#[from] Refusal),
    /// The method cannot run (its setting), before any orbit.
    #[error(transparent)]
    Ode(#[from] OdeError),
    #[error(transparent)]
    Tile(#[from] TileError),
    /// Only some tiles were asked for: they are written, there is no map.
    #[error("the tiles asked for are written; run without `only` to merge them into the basins")]
    Partial,
    /// A declared setting's value refused.
    #[error(transparent)]
    Setting(#[from] SettingError),
}

/// An attractor found.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Attractor {
    /// "period k" for a cycle of P (to 1e-6 of the cell), else what a
    /// longer run shows: a cycle of a longer period, [`CHAOTIC`],
    /// [`QUASI_PERIODIC`], [`NOT_SETTLED`], or [`APERIODIC`] when that run
    /// stopped.
    pub kind: String,
    /// Its last recorded iterate from the first start that reached it.
    pub representative: Vec<f64>,
    pub starts: usize,
    /// Reached from a second start too (an attractor seen once may be a
    /// transient not yet settled).
    pub confirmed: bool,
    /// The share of the grid's starts, and its stated error: the larger
    /// of the grid's (`grid_error`) and the numerical one (the class
    /// check's share of starts that change attractor, where checked).
    pub fraction: f64,
    pub fraction_error: f64,
    /// The grid's error on the fraction: twice the largest difference
    /// between it and the fraction on one of the four interleaved grids of
    /// half the pixels per side (whose mean it is), at least one pixel's
    /// share where the map has more than one basin.
    pub grid_error: f64,
}

/// A basin map.
#[derive(Debug, serde::Serialize)]
pub struct Basins {
    pub model: String,
    pub axes: [String; 2],
    /// The axes in the figures' notation (φ₁, p_φ₁, φ₁′).
    #[serde(skip)]
    pub labels_of_axes: [String; 2],
    pub ranges: [(f64, f64); 2],
    pub pixels: usize,
    pub attractors: Vec<Attractor>,
    /// Starts whose orbit left the model's domain or diverged.
    pub diverged: usize,
    /// The basins' boundary: its uncertainty exponent and box dimension.
    pub boundary: Boundary,
    /// The share of starts that end on another attractor in a run at a
    /// hundredth of the tolerance, from a sample of them: the fractions'
    /// numerical error (None: not checked).
    pub class_check: Option<super::check::ClassCheck>,
    /// Whether the `accuracy` asked for was reached, and by which run.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub accuracy: Option<String>,
    pub seconds: f64,
    /// Each pixel's attractor (an index of `attractors`, or [`DIVERGED`]),
    /// row 0 at the bottom.
    #[serde(skip)]
    pub labels: Vec<i32>,
    /// The attractors' recorded iterates on the map's axes, for the figure.
    #[serde(skip)]
    pub points: Vec<Vec<[f64; 2]>>,
}

/// The basins of `model`'s period map at `params`; `done(k)` is told as
/// each block of k orbits ends (progress). With an `accuracy`, the map is
/// run again, a hundredfold tighter while its class check is above it and
/// with more pixels while its grid error is, until every fraction's error
/// is within it.
pub fn basins(
    model: &Model,
    params: &[f64],
    settings: &BasinSettings,
    done: &(dyn Fn(usize) + Sync),
) -> Result<Basins, BasinsError> {
    let Some(accuracy) = settings.accuracy else {
        return basins_once(model, params, settings, done);
    };
    let mut settings = settings.clone();
    settings.check = super::check::pixels_to_state(settings.check.max(256), accuracy);
    loop {
        let mut map = basins_once(model, params, &settings, done)?;
        let numerical = map
            .class_check
            .as_ref()
            .map_or(f64::INFINITY, |c| c.fraction.max(c.error));
        let grid = (map.attractors.iter())
            .map(|a| a.grid_error)
            .fold(0.0, f64::max);
        let tighter = settings.method.tighter();
        let why_not = if numerical > accuracy {
            if tighter.is_tighter_than(&settings.method) {
                settings.method = tighter;
                continue;
            }
            Some("the tolerance is at the precision floor".to_string())
        } else if grid > accuracy {
            // The grid's error falls as the pixel's side to the power of
            // the boundary's uncertainty exponent (1 for a smooth one).
            let alpha = map.boundary.exponent.unwrap_or(1.0).clamp(0.05, 1.0);
            let wanted = settings.pixels as f64 * (grid / accuracy).powf(1.0 / alpha);
            let pixels = (wanted.ceil() as usize).max(2 * settings.pixels);
            if pixels <= MAX_PIXELS {
                settings.pixels = pixels;
                continue;
            }
            Some(format!(
                "the grid's error {grid:.2e} at {} pixels per side would take about {wanted:.0} (more than {MAX_PIXELS}; the boundary's uncertainty exponent {alpha:.2})",
                settings.pixels
            ))
        } else {
            None
        };
        let error = numerical.max(grid);
        map.accuracy = Some(match why_not {
            None => format!(
                "accuracy {accuracy} reached with {} at {} pixels per side: every fraction within {error:.2e}",
                settings.method.describe(),
                settings.pixels
            ),
            Some(why) => format!("accuracy {accuracy} NOT reached: {why}"),
        });
        return Ok(map);
    }
}

/// The most pixels per side an `accuracy` may ask for (the setting's range).
const MAX_PIXELS: usize = 4000;

/// [`basins`] at the settings' method and pixels, its check included.
fn basins_once(
    model: &Model,
    params: &[f64],
    settings: &BasinSettings,
    done: &(dyn Fn(usize) + Sync),
) -> Result<Basins, BasinsError> {
    let name = model.info.name;
    let flows = super::flows(model)?;
    super::method_applies(model, settings.method)?;
    Refusal::named_values(model.info, params)?;
    let period = flows
        .phase_period(params)
        .filter(|_| flows.has_fast_phase())
        .ok_or_else(|| Refusal::no_fast_phase(name))?;
    let axes = super::period_map::plane_names(model.info, settings.axes)
        .map_err(|_| Refusal::setting(name, "the axes must be two different state components"))?;
    let ok_range = |(lo, hi): (f64, f64)| lo.is_finite() && hi.is_finite() && lo < hi;
    if settings.pixels < 2
        || settings.record < 2
        || !(settings.cell > 0.0)
        || !settings.ranges.iter().all(|&r| ok_range(r))
    {
        return Err(Refusal::setting(
            name,
            "pixels ≥ 2, record ≥ 2, a positive cell and finite ranges low < high",
        )
        .into());
    }
    let base = match &settings.through {
        Some(y) if y.len() == flows.periodic_state().len() => y.clone(),
        Some(_) => {
            let what = "`through` must be a full state of the model";
            return Err(Refusal::setting(name, what).into());
        }
        None => flows.base_state(params),
    };
    let start = std::time::Instant::now();
    let n = settings.pixels;
    crate::budget::check(
        || format!("the records of {n} × {n} starts"),
        (n as u128).pow(2),
        8 * base.len() * settings.record,
    )
    .map_err(OdeError::from)?;
    let grid = Grid {
        flows,
        params,
        settings,
        period,
        wrap: flows.periodic_state(),
        cells: Cells::new(settings.cell, &flows.periodic_state()),
        base,
        done,
    };
    let Some(records) = grid.all_records(name)? else {
        return Err(BasinsError::Partial);
    };
    let (labels, mut attractors, points) = grid.find(&records)?;
    let class_check = match settings.check {
        0 => None,
        count => Some(grid.class_check(&records, &labels, count)?),
    };
    stated_errors(&mut attractors, &labels, n, class_check.as_ref());
    let diverged = labels.iter().filter(|&&l| l == DIVERGED).count();
    Ok(Basins {
        model: name.into(),
        axes,
        labels_of_axes: settings.axes.map(|a| model.info.label(a)),
        ranges: settings.ranges,
        pixels: n,
        attractors,
        diverged,
        boundary: Boundary::of_labels(&labels, n),
        class_check,
        accuracy: None,
        seconds: start.elapsed().as_secs_f64(),
        labels,
        points,
    })
}

/// A start's recorded iterates (angles wrapped), or None for a start with
/// no state of the model there or whose orbit stopped.
type Record = Option<Vec<Vec<f64>>>;

/// What the orbits of one basin map share.
struct Grid<'a> {
    flows: &'a dyn crate::registry::Flows,
    params: &'a [f64],
    settings: &'a BasinSettings,
    period: f64,
    /// The state the plane passes through, and which components are angles.
    base: Vec<f64>,
    wrap: Vec<bool>,
    /// The cells that identify attractors.
    cells: Cells,
    done: &'a (dyn Fn(usize) + Sync),
}

impl Grid<'_> {
    /// The start of pixel k (row-major, row 0 at the bottom), put on a
    /// constrained model's constraints; None where the model has no state.
    fn start(&self, k: usize) -> Option<Vec<f64>> {
        let settings = self.settings;
        let mut y = self.base.clone();
        (y[settings.axes[0]], y[settings.axes[1]]) =
            super::chaos_map::pixel_centre(&settings.ranges, settings.pixels, k);
        self.flows
            .consistent(self.params, &mut y, &settings.axes)
            .ok()
            .map(|()| y)
    }

    /// The records of the starts `pixels` by `method`, stopped early on the
    /// `known` attractors if any.
    fn records(
        &self,
        pixels: &[usize],
        known: Option<&KnownAttractors>,
        method: Method,
    ) -> Result<Vec<Record>, BasinsError> {
        let settings = self.settings;
        let starts: Vec<Option<Vec<f64>>> = pixels.par_iter().map(|&k| self.start(k)).collect();
        let flat: Vec<f64> = starts.iter().flatten().flatten().copied().collect();
        let recording = Recording {
            transient: settings.transient,
            record: settings.record,
            settle: settings.stop_early.then_some(settings.cell * 1e-8),
            known,
            done: self.done,
        };
        let mut runs = self
            .flows
            .iterates(self.params, method, self.period, &flat, &recording)?
            .into_iter();
        Ok(starts
            .iter()
            .map(|start| {
                let run = start.as_ref().and_then(|_| runs.next().flatten())?;
                Some(run.iter().map(|y| wrapped(y, &self.wrap)).collect())
            })
            .collect())
    }

    /// The attractors of records. Aperiodic ones found apart may be pieces
    /// of one chaotic set: each one's representative runs [`EXTENSION`]
    /// periods further, the cells it visits join the pieces they touch,
    /// and that run tells what the attractor is ([`Grid::kinds_of_runs`]).
    fn find(&self, records: &[Record]) -> Result<Found, BasinsError> {
        let (labels, attractors, points) =
            identify(records, &[], self.settings, (&self.cells, &self.wrap));
        let pieces: Vec<usize> = (0..attractors.len())
            .filter(|&i| attractors[i].kind == APERIODIC)
            .collect();
        if pieces.is_empty() {
            return Ok((labels, attractors, points));
        }
        let starts: Vec<f64> = (pieces.iter())
            .flat_map(|&i| attractors[i].representative.clone())
            .collect();
        let recording = Recording {
            transient: 0,
            record: EXTENSION,
            settle: None,
            known: None,
            done: &|_| (),
        };
        let runs = (self.flows).iterates(
            self.params,
            self.settings.method,
            self.period,
            &starts,
            &recording,
        )?;
        let kinds = self.kinds_of_runs(&starts, &runs)?;
        let runs: Vec<Option<Vec<Vec<f64>>>> = (runs.into_iter())
            .map(|run| Some(run?.iter().map(|y| wrapped(y, &self.wrap)).collect()))
            .collect();
        let extras: Vec<Vec<Vec<f64>>> = runs.iter().flatten().cloned().collect();
        let (merged_labels, mut merged, mut points) =
            identify(records, &extras, self.settings, (&self.cells, &self.wrap));
        // Each piece's kind goes to the attractor it is now part of
        // (chaotic if any piece is), and its run to the attractor's points.
        let axes = self.settings.axes;
        for ((piece, kind), run) in pieces.iter().zip(kinds).zip(&runs) {
            let first = labels.iter().position(|&l| l == *piece as i32);
            let (Some(first), Some(kind), Some(run)) = (first, kind, run) else {
                continue;
            };
            let index = merged_labels[first] as usize;
            let attractor = &mut merged[index];
            if attractor.kind == APERIODIC || kind == CHAOTIC {
                attractor.kind = kind;
            }
            points[index].extend(run.iter().map(|y| [y[axes[0]], y[axes[1]]]));
        }
        Ok((merged_labels, merged, points))
    }

    /// What long runs on attractors (from `starts`, one after the other)
    /// show them to be: a cycle of period k ≤ the run's length / 4 (its
    /// second half repeats with period k, to 1e-6 of a cell); else chaotic
    /// when the fast Lyapunov indicator over as many periods from its
    /// start says so by the chaos maps' criterion (FLI > 2 ln N: a positive
    /// Lyapunov exponent); else quasi-periodic when its frequencies keep
    /// between its halves (a diffusion index below the frequency maps'
    /// regular one) and the run from its start moved by [`NUDGE`] ends
    /// less than [`CLOSING`] e-folds closer to it (an attracting torus
    /// keeps the nudge along it; a cycle still being approached, of any
    /// period, draws nearby orbits in); else [`NOT_SETTLED`]. None: the
    /// run stopped.
    fn kinds_of_runs(
        &self,
        starts: &[f64],
        runs: &[Option<Vec<Vec<f64>>>],
    ) -> Result<Vec<Option<String>>, BasinsError> {
        let dim = self.wrap.len();
        let w0 = vec![(1.0 / dim as f64).sqrt(); dim];
        let (fli, _) = self.flows.fli(
            self.params,
            self.settings.method,
            self.period,
            starts,
            &w0,
            EXTENSION,
            &self.settings.axes,
        )?;
        // Each run again from its start moved by NUDGE: where it ends
        // against the run tells whether nearby orbits close in.
        let nudged: Vec<f64> = starts.iter().map(|x| x + NUDGE).collect();
        let last = Recording {
            transient: EXTENSION - 1,
            record: 1,
            settle: None,
            known: None,
            done: &|_| (),
        };
        let ends = self.flows.iterates(
            self.params,
            self.settings.method,
            self.period,
            &nudged,
            &last,
        )?;
        Ok(runs
            .iter()
            .zip(fli)
            .zip(ends)
            .map(|((run, fli), end)| {
                let run = run.as_ref()?;
                // (kind_of compares angles modulo 2π: no wrapping needed.)
                let tail = &run[run.len() / 2..];
                let cycle = kind_of(tail, &self.wrap, self.settings.cell * 1e-6);
                if cycle != APERIODIC {
                    return Some(cycle);
                }
                if crate::tangent::lyapunov::fli_is_chaotic(fli.ok()?, EXTENSION) {
                    return Some(CHAOTIC.into());
                }
                // Quasi-periodic only on evidence: its frequencies keep
                // (NAFF), and a nudged orbit does not close in on it (on
                // an attracting torus the nudge along it stays; towards a
                // cycle still being approached, of any period, it dies).
                let (_, index) = super::frequency_map::tunes(run, &self.wrap);
                let apart = distance(end?.last()?, &run[run.len() - 1], &self.wrap);
                let keeps = apart > NUDGE * (-CLOSING).exp();
                let regular = index < super::frequency_map::REGULAR_INDEX;
                Some(
                    if regular && keeps {
                        QUASI_PERIODIC
                    } else {
                        NOT_SETTLED
                    }
                    .to_string(),
                )
            })
            .collect())
    }

    /// The fractions' numerical error: `count` starts spread over the map
    /// run again at a hundredth of the tolerance, each labelled by the
    /// attractor whose cells (or cells touching them) its record visits
    /// most, [`DIVERGED`] where its orbit stopped, and a label of its own
    /// where it visits none (an attractor the map did not find).
    fn class_check(
        &self,
        records: &[Record],
        labels: &[i32],
        count: usize,
    ) -> Result<super::check::ClassCheck, BasinsError> {
        const ELSEWHERE: i32 = -2;
        let mut owner: HashMap<Vec<i64>, i32> = HashMap::new();
        for (record, &label) in records.iter().zip(labels) {
            for y in record.iter().flatten() {
                let mut key = Vec::new();
                self.cells.of(y, &mut key);
                owner.insert(key, label);
            }
        }
        let label_of = |record: &Record| -> i32 {
            let Some(record) = record else {
                return DIVERGED;
            };
            let mut votes: HashMap<i32, usize> = HashMap::new();
            for y in record {
                let mut key = Vec::new();
                self.cells.of(y, &mut key);
                let mut found = owner.get(&key).copied();
                if found.is_none() {
                    self.cells.touching(&key, |neighbour| {
                        found = found.or_else(|| owner.get(neighbour).copied());
                    });
                }
                if let Some(label) = found {
                    *votes.entry(label).or_default() += 1;
                }
            }
            (votes.into_iter())
                .max_by_key(|&(label, n)| (n, -label))
                .map_or(ELSEWHERE, |(label, _)| label)
        };
        let rerun = super::check::rerun_sample(
            labels.len(),
            count,
            self.settings.method,
            |pixels, method| {
                let records = self.records(pixels, None, method)?;
                Ok::<_, BasinsError>(records.iter().map(label_of).collect::<Vec<_>>())
            },
        )?;
        let pairs = (rerun.pixels.iter())
            .zip(&rerun.values)
            .map(|(&k, &label)| (Some(labels[k]), Some(label)));
        Ok(super::check::ClassCheck::new(
            pairs,
            rerun.runs,
            rerun.census,
        ))
    }

    /// Whether pixel k is a scout: with early stops, every 4th start each
    /// way runs first, and the attractors the scouts confirm are known to
    /// the other orbits, which stop once on one of them.
    fn is_scout(&self, k: usize) -> bool {
        let n = self.settings.pixels;
        self.settings.stop_early
            && n >= 16
            && (k % n).is_multiple_of(4)
            && (k / n).is_multiple_of(4)
    }

    /// The scouts' records, and the attractors they confirm.
    fn scout(&self) -> Result<(Vec<Record>, KnownAttractors), BasinsError> {
        let n = self.settings.pixels;
        let scouts: Vec<usize> = (0..n * n).filter(|&k| self.is_scout(k)).collect();
        let records = self.records(&scouts, None, self.settings.method)?;
        let mut known = KnownAttractors::new(self.cells.clone());
        let (labels, attractors, _) = self.find(&records)?;
        for (index, _) in attractors.iter().enumerate().filter(|(_, a)| a.confirmed) {
            let on_it: Vec<&Vec<Vec<f64>>> = labels
                .iter()
                .zip(&records)
                .filter(|(&l, _)| l == index as i32)
                .filter_map(|(_, record)| record.as_ref())
                .collect();
            known.add(&on_it);
        }
        Ok((records, known))
    }

    /// Every start's record, the rows in tiles if asked for; None when
    /// only some tiles were asked for (they are written).
    fn all_records(&self, name: &str) -> Result<Option<Vec<Record>>, BasinsError> {
        let (settings, n, dim) = (self.settings, self.settings.pixels, self.base.len());
        let (scout_records, known) = self.scout()?;
        let known = (!known.is_empty()).then_some(&known);
        // The records of a range of rows, each start's `record` iterates
        // one after the other, NaN for None (a tile's values).
        let rows_of = |rows: std::ops::Range<usize>| -> Result<(Vec<f64>, u64), BasinsError> {
            let pixels = rows.start * n..rows.end * n;
            let others: Vec<usize> = pixels.clone().filter(|&k| !self.is_scout(k)).collect();
            let mut runs = self.records(&others, known, settings.method)?.into_iter();
            let mut values = Vec::with_capacity(pixels.len() * settings.record * dim);
            for k in pixels {
                let record = if self.is_scout(k) {
                    scout_records[(k / n / 4) * n.div_ceil(4) + (k % n) / 4].clone()
                } else {
                    runs.next().flatten()
                };
                match record {
                    Some(run) => values.extend(run.iter().flatten()),
                    None => values.resize(values.len() + settings.record * dim, f64::NAN),
                }
            }
            Ok((values, 0))
        };
        let values = match &settings.tiles {
            None => rows_of(0..n)?.0,
            Some(tiles) => {
                let key = format!(
                    "basins {name} {:?} {:?} {:?} {:?} {n} {} {} {} {:?} {} {}",
                    self.params,
                    settings.axes,
                    settings.ranges,
                    self.base,
                    settings.transient,
                    settings.record,
                    settings.cell,
                    settings.method,
                    settings.stop_early,
                    tiles.rows
                );
                let row = (n, n * settings.record * dim, "rows");
                match run_tiles(tiles, fingerprint(&key), row, &rows_of)? {
                    Some((values, _)) => values,
                    None => return Ok(None),
                }
            }
        };
        Ok(Some(
            values
                .chunks(settings.record * dim)
                .map(|record| {
                    record[0]
                        .is_finite()
                        .then(|| record.chunks(dim).map(<[f64]>::to_vec).collect())
                })
                .collect(),
        ))
    }
}

/// Each start's label, the attractors, their iterates on the axes.
type Found = (Vec<i32>, Vec<Attractor>, Vec<Vec<[f64; 2]>>);

/// A state with its angles in [−π, π).
fn wrapped(y: &[f64], wrap: &[bool]) -> Vec<f64> {
    y.iter()
        .zip(wrap)
        .map(|(&x, &w)| {
            if w {
                super::period_map::wrap_angle(x)
            } else {
                x
            }
        })
        .collect()
}

/// The attractors of the records: union–find over the cells their
/// iterates visit, cells that touch being one; each start's label, the
/// attractors, their iterates on the axes.
/// `extras` are records of no start (they join the sets they touch).
fn identify(
    records: &[Record],
    extras: &[Vec<Vec<f64>>],
    settings: &BasinSettings,
    (cells, wrap): (&Cells, &[bool]),
) -> Found {
    let mut parent: Vec<usize> = Vec::new();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    fn unite(parent: &mut [usize], a: usize, b: usize) {
        let (a, b) = (root(parent, a), root(parent, b));
        parent[a.max(b)] = a.min(b);
    }
    let mut owner: HashMap<Vec<i64>, usize> = HashMap::new();
    let mut first_set: Vec<usize> = Vec::with_capacity(records.len());
    for record in records
        .iter()
        .map(Option::as_ref)
        .chain(extras.iter().map(Some))
    {
        let Some(record) = record else {
            first_set.push(usize::MAX);
            continue;
        };
        let cells: Vec<Vec<i64>> = record
            .iter()
            .map(|y| {
                let mut key = Vec::new();
                cells.of(y, &mut key);
                key
            })
            .collect();
        let set = parent.len();
        parent.push(set);
        for cell in cells {
            match owner.get(&cell) {
                Some(&other) => unite(&mut parent, other, set),
                None => {
                    owner.insert(cell, set);
                }
            }
        }
        first_set.push(set);
    }
    // Cells that touch (a face or a corner) hold one attractor: a cycle
    // on a cell's boundary has its records on both sides of it.
    let claimed: Vec<(Vec<i64>, usize)> = owner.iter().map(|(c, &s)| (c.clone(), s)).collect();
    for (cell, set) in &claimed {
        cells.touching(cell, |neighbour| {
            if let Some(&other) = owner.get(neighbour) {
                unite(&mut parent, other, *set);
            }
        });
    }
    // Attractors in order of their first start.
    let mut index_of: HashMap<usize, usize> = HashMap::new();
    let mut attractors: Vec<Attractor> = Vec::new();
    let mut points: Vec<Vec<[f64; 2]>> = Vec::new();
    let mut labels = Vec::with_capacity(records.len());
    for (record, &set) in records.iter().zip(&first_set[..records.len()]) {
        let Some(record) = record else {
            labels.push(DIVERGED);
            continue;
        };
        let r = root(&mut parent, set);
        let next = attractors.len();
        let index = *index_of.entry(r).or_insert(next);
        if index == next {
            attractors.push(Attractor {
                kind: kind_of(record, wrap, settings.cell * 1e-6),
                representative: record.last().cloned().unwrap_or_default(),
                starts: 0,
                confirmed: false,
                fraction: 0.0,
                fraction_error: 0.0,
                grid_error: 0.0,
            });
            points.push(
                record
                    .iter()
                    .map(|y| [y[settings.axes[0]], y[settings.axes[1]]])
                    .collect(),
            );
        }
        attractors[index].starts += 1;
        labels.push(index as i32);
    }
    let total = records.len() as f64;
    for a in &mut attractors {
        a.confirmed = a.starts >= 2;
        a.fraction = a.starts as f64 / total;
    }
    (labels, attractors, points)
}

/// Each attractor's grid error ([`Attractor::grid_error`]) and its stated
/// error, the larger of that and the class check's share.
fn stated_errors(
    attractors: &mut [Attractor],
    labels: &[i32],
    n: usize,
    check: Option<&super::check::ClassCheck>,
) {
    let numerical = check.map_or(0.0, |c| c.fraction.max(c.error));
    let basins = attractors.len() + usize::from(labels.contains(&DIVERGED));
    let pixel = if basins > 1 {
        1.0 / labels.len() as f64
    } else {
        0.0
    };
    for (index, a) in attractors.iter_mut().enumerate() {
        let mut spread: f64 = 0.0;
        for (di, dj) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
            let (mut on, mut all) = (0usize, 0usize);
            for j in (dj..n).step_by(2) {
                for i in (di..n).step_by(2) {
                    all += 1;
                    on += usize::from(labels[j * n + i] == index as i32);
                }
            }
            if all > 0 {
                spread = spread.max((on as f64 / all as f64 - a.fraction).abs());
            }
        }
        // Twice the spread: one sample of the error, as the exact window's
        // edges (measured on the double well's areas: docs/accuracy.md).
        let grid = (2.0 * spread).max(pixel);
        a.grid_error = grid;
        a.fraction_error = grid.max(numerical);
    }
}

/// "period k" if the record repeats with the least such k (within
/// `tolerance` in every component, the angles `wrap` modulo 2π), else
/// "aperiodic".
fn kind_of(record: &[Vec<f64>], wrap: &[bool], tolerance: f64) -> String {
    let close = |a: &[f64], b: &[f64]| within(a, b, wrap, tolerance);
    (1..=record.len() / 2)
        .find(|&k| (k..record.len()).all(|i| close(&record[i], &record[i - k])))
        .map_or_else(|| APERIODIC.to_string(), |k| format!("period {k}"))
}

/// The basins' boundary, measured on the grid by final-state
/// sensitivity (Grebogi, McDonald, Ott and Yorke): the fraction f(ε) of
/// starts whose neighbours ε away along either axis end elsewhere (another
/// attractor, or diverged), at ε = 1, 2, 4, … pixels up to 1/32 of the
/// side (where f is still far from 1). f(ε) ∝ ε^α, α the uncertainty
/// exponent, and the boundary's box dimension is 2 − α: 1 for a smooth
/// curve, more for a fractal one. The grid sees no structure finer than a
/// pixel: α is that of the scales it has.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Boundary {
    /// ε as a fraction of each axis' range, and the fraction of uncertain
    /// starts there.
    pub epsilon: Vec<f64>,
    pub uncertain: Vec<f64>,
    /// α from the least-squares slope of log f against log ε, with its
    /// standard error, and 2 − α; None with the reason in `why_not`.
    pub exponent: Option<f64>,
    pub exponent_error: Option<f64>,
    pub dimension: Option<f64>,
    pub why_not: Option<&'static str>,
}

impl Boundary {
    /// The boundary of the `labels` of a `pixels`² grid.
    pub fn of_labels(labels: &[i32], pixels: usize) -> Boundary {
        let n = pixels;
        let label = |i: usize, j: usize| labels[j * n + i];
        let mut scales = Vec::new();
        let mut s = 1;
        while 32 * s <= n {
            scales.push(s);
            s *= 2;
        }
        let uncertain: Vec<f64> = scales
            .iter()
            .map(|&s| {
                let inner = s..n - s;
                let (mut count, mut total) = (0usize, 0usize);
                for j in inner.clone() {
                    for i in inner.clone() {
                        let l = label(i, j);
                        let differs = label(i - s, j) != l
                            || label(i + s, j) != l
                            || label(i, j - s) != l
                            || label(i, j + s) != l;
                        count += usize::from(differs);
                        total += 1;
                    }
                }
                count as f64 / total as f64
            })
            .collect();
        let epsilon: Vec<f64> = scales.iter().map(|&s| s as f64 / n as f64).collect();
        let refused = |why| Boundary {
            epsilon: epsilon.clone(),
            uncertain: uncertain.clone(),
            exponent: None,
            exponent_error: None,
            dimension: None,
            why_not: Some(why),
        };
        if scales.len() < 3 {
            return refused("fewer than 3 scales from one pixel to 1/32 of the side: 128 pixels or more are needed");
        }
        if uncertain.iter().all(|&f| f == 0.0) {
            return refused("every start ends on one attractor: there is no boundary");
        }
        if uncertain.contains(&0.0) {
            return refused(
                "no uncertain start at the finest scales: the boundary is not resolved by the grid",
            );
        }
        let points: Vec<(f64, f64)> = epsilon
            .iter()
            .copied()
            .zip(uncertain.iter().copied())
            .collect();
        let fit = super::fit::log_log(&points);
        let slope = fit.slope;
        // The slope's standard error from the fit's r².
        let m = points.len() as f64;
        let error = slope.abs() * ((1.0 / fit.r_squared - 1.0).max(0.0) / (m - 2.0)).sqrt();
        Boundary {
            exponent: Some(slope),
            exponent_error: Some(error),
            dimension: Some(2.0 - slope),
            why_not: None,
            epsilon,
            uncertain,
        }
    }
}

impl Basins {
    /// Each start coloured by its attractor (white: diverged), the
    /// attractors' iterates drawn on top in black.
    pub fn figure(&self) -> Figure {
        let summary: Vec<String> = self
            .attractors
            .iter()
            .map(|a| format!("{} {:.3}±{:.3}", a.kind, a.fraction, a.fraction_error))
            .collect();
        let boundary = match self.boundary.dimension {
            Some(d) => format!("; boundary dimension {d:.2}"),
            None => String::new(),
        };
        let title = format!("{}: basins ({}){boundary}", self.model, summary.join(", "));
        let spec = PanelSpec::new(
            &title,
            &self.labels_of_axes[0],
            &self.labels_of_axes[1],
            self.ranges[0],
            self.ranges[1],
        );
        let mut figure = Figure::single(760, 700, spec);
        let colors = self
            .labels
            .iter()
            .map(|&l| (l >= 0).then(|| palette(l as usize)))
            .collect();
        figure.cells(0, self.pixels, self.pixels, colors);
        for attractor in &self.points {
            figure.points(
                0,
                attractor.iter().map(|p| (p[0], p[1])),
                crate::plot::BLACK,
                2,
            );
        }
        figure
    }
}

impl crate::outputs::Outputs for Basins {
    fn figures(&self) -> Vec<(String, crate::plot::Figure)> {
        vec![("basins.png".into(), self.figure())]
    }
    fn tables(&self) -> Vec<crate::outputs::Table> {
        let n = self.pixels;
        let rows = self
            .labels
            .iter()
            .enumerate()
            .map(|(k, l)| (k % n, k / n, *l));
        let header = ["column", "row", "attractor"];
        vec![crate::outputs::Table::new("basins.csv", &header, rows)]
    }
    fn lines(&self) -> Vec<String> {
        let mut lines: Vec<String> = self
            .attractors
            .iter()
            .map(|a| {
                let seen = if a.confirmed { "" } else { " (one start only)" };
                format!(
                    "{}: {:.4} ± {:.4} of the starts, at {:?}{seen}",
                    a.kind, a.fraction, a.fraction_error, a.representative
                )
            })
            .collect();
        lines.push(format!(
            "diverged: {}; {:.1} s",
            self.diverged, self.seconds
        ));
        lines.push(match &self.class_check {
            Some(check) => format!(
                "fractions' error: the grid's (four interleaved half grids) and the numerical{}",
                (check.describe())
                    .replace("pixels change class", "starts change attractor")
                    .replace("pixels changes class", "starts changes attractor")
            ),
            None => "fractions' error: the grid's (four interleaved half grids); no numerical check (check = 0)".into(),
        });
        lines.extend(self.accuracy.clone());
        let b = &self.boundary;
        lines.push(match (b.exponent, b.exponent_error, b.dimension) {
            (Some(alpha), Some(error), Some(dimension)) => format!(
                "boundary: uncertainty exponent {alpha:.3} ± {error:.3}, box dimension {dimension:.3}"
            ),
            _ => format!("boundary: {}", b.why_not.unwrap_or("not measured")),
        });
        lines
    }
}
