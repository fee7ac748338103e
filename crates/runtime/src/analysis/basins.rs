//! Basins of attraction of a period map: every start of a grid on a plane
//! of the state run past a transient, then its next iterates recorded;
//! the attractors found from those records without being told them
//! (starts whose recorded iterates share a cell of the state space are on
//! one attractor, by union–find over the cells), each with its kind (a
//! cycle of period k, or aperiodic), a representative point and the
//! number of starts that reached it; starts whose orbit diverged form a
//! class of their own, never assigned to an attractor.

use super::Refusal;
use crate::ode::{Method, OdeError};
use crate::plot::{palette, Figure, PanelSpec};
use crate::registry::Model;
use rayon::prelude::*;
use std::collections::HashMap;

/// What a basin map computes.
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
}

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
}

/// An attractor found.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Attractor {
    /// "period k" for a cycle of P (to 1e-6 of the cell), else "aperiodic".
    pub kind: String,
    /// Its last recorded iterate from the first start that reached it.
    pub representative: Vec<f64>,
    pub starts: usize,
    /// Reached from a second start too (an attractor seen once may be a
    /// transient not yet settled).
    pub confirmed: bool,
    /// The share of the grid's starts, and its standard error.
    pub fraction: f64,
    pub fraction_error: f64,
}

/// A basin map.
#[derive(Debug, serde::Serialize)]
pub struct Basins {
    pub model: String,
    pub axes: [String; 2],
    pub ranges: [(f64, f64); 2],
    pub pixels: usize,
    pub attractors: Vec<Attractor>,
    /// Starts whose orbit left the model's domain or diverged.
    pub diverged: usize,
    pub seconds: f64,
    /// Each pixel's attractor (an index of `attractors`, or [`DIVERGED`]),
    /// row 0 at the bottom.
    #[serde(skip)]
    pub labels: Vec<i32>,
    /// The attractors' recorded iterates on the map's axes, for the figure.
    #[serde(skip)]
    pub points: Vec<Vec<[f64; 2]>>,
}

/// The basins of `model`'s period map at `params`.
pub fn basins(
    model: &Model,
    params: &[f64],
    settings: &BasinSettings,
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
    let wrap = flows.periodic_state();
    // Each start on the plane (None where the model has no state there).
    let starts: Vec<Option<Vec<f64>>> = (0..n * n)
        .into_par_iter()
        .map(|k| {
            let at = |(lo, hi): (f64, f64), i: usize| lo + (hi - lo) * (i as f64 + 0.5) / n as f64;
            let mut y = base.clone();
            y[settings.axes[0]] = at(settings.ranges[0], k % n);
            y[settings.axes[1]] = at(settings.ranges[1], k / n);
            flows
                .consistent(params, &mut y, &settings.axes)
                .ok()
                .map(|()| y)
        })
        .collect();
    let flat: Vec<f64> = starts.iter().flatten().flatten().copied().collect();
    let mut runs = flows
        .iterates(
            params,
            settings.method,
            period,
            &flat,
            (settings.transient, settings.record),
        )?
        .into_iter();
    // Each start's recorded iterates, angles wrapped, or None.
    let records: Vec<Option<Vec<Vec<f64>>>> = starts
        .iter()
        .map(|start| {
            let run = start.as_ref().and_then(|_| runs.next().flatten())?;
            Some(run.iter().map(|y| wrapped(y, &wrap)).collect())
        })
        .collect();
    let (labels, attractors, points) = identify(&records, settings);
    let diverged = labels.iter().filter(|&&l| l == DIVERGED).count();
    Ok(Basins {
        model: name.into(),
        axes,
        ranges: settings.ranges,
        pixels: n,
        attractors,
        diverged,
        seconds: start.elapsed().as_secs_f64(),
        labels,
        points,
    })
}

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
/// iterates visit; each start's label, the attractors, their iterates on
/// the axes.
fn identify(
    records: &[Option<Vec<Vec<f64>>>],
    settings: &BasinSettings,
) -> (Vec<i32>, Vec<Attractor>, Vec<Vec<[f64; 2]>>) {
    let mut parent: Vec<usize> = Vec::new();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let mut owner: HashMap<Vec<i64>, usize> = HashMap::new();
    let mut first_set: Vec<usize> = Vec::with_capacity(records.len());
    for record in records {
        let Some(record) = record else {
            first_set.push(usize::MAX);
            continue;
        };
        let cells: Vec<Vec<i64>> = record
            .iter()
            .map(|y| {
                y.iter()
                    .map(|x| (x / settings.cell).floor() as i64)
                    .collect()
            })
            .collect();
        let set = parent.len();
        parent.push(set);
        for cell in cells {
            match owner.get(&cell) {
                Some(&other) => {
                    let (a, b) = (root(&mut parent, other), root(&mut parent, set));
                    parent[a.max(b)] = a.min(b);
                }
                None => {
                    owner.insert(cell, set);
                }
            }
        }
        first_set.push(set);
    }
    // Attractors in order of their first start.
    let mut index_of: HashMap<usize, usize> = HashMap::new();
    let mut attractors: Vec<Attractor> = Vec::new();
    let mut points: Vec<Vec<[f64; 2]>> = Vec::new();
    let mut labels = Vec::with_capacity(records.len());
    for (record, &set) in records.iter().zip(&first_set) {
        let Some(record) = record else {
            labels.push(DIVERGED);
            continue;
        };
        let r = root(&mut parent, set);
        let next = attractors.len();
        let index = *index_of.entry(r).or_insert(next);
        if index == next {
            attractors.push(Attractor {
                kind: kind_of(record, settings.cell * 1e-6),
                representative: record.last().cloned().unwrap_or_default(),
                starts: 0,
                confirmed: false,
                fraction: 0.0,
                fraction_error: 0.0,
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
        a.fraction_error = (a.fraction * (1.0 - a.fraction) / total).sqrt();
    }
    (labels, attractors, points)
}

/// "period k" if the record repeats with the least such k (within
/// `tolerance` in every component), else "aperiodic".
fn kind_of(record: &[Vec<f64>], tolerance: f64) -> String {
    let close = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tolerance);
    (1..=record.len() / 2)
        .find(|&k| (k..record.len()).all(|i| close(&record[i], &record[i - k])))
        .map_or_else(|| "aperiodic".to_string(), |k| format!("period {k}"))
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
        let title = format!("{}: basins ({})", self.model, summary.join(", "));
        let spec = PanelSpec::new(
            &title,
            &self.axes[0],
            &self.axes[1],
            self.ranges[0],
            self.ranges[1],
        );
        let mut figure = Figure::single(760, 700, spec);
        let (w, h) = (
            (self.ranges[0].1 - self.ranges[0].0) / self.pixels as f64,
            (self.ranges[1].1 - self.ranges[1].0) / self.pixels as f64,
        );
        for index in 0..self.attractors.len() {
            let cells = self
                .labels
                .iter()
                .enumerate()
                .filter(|(_, &l)| l == index as i32)
                .map(|(k, _)| {
                    let (i, j) = (k % self.pixels, k / self.pixels);
                    (
                        self.ranges[0].0 + (i as f64 + 0.5) * w,
                        self.ranges[1].0 + (j as f64 + 0.5) * h,
                    )
                });
            let size = (760.0 / self.pixels as f64).ceil().max(1.0) as i64;
            figure.points(0, cells, palette(index), size);
        }
        for attractor in &self.points {
            figure.points(
                0,
                attractor.iter().map(|p| (p[0], p[1])),
                crate::plot::BLACK,
                3,
            );
        }
        figure
    }
}
