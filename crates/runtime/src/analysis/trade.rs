//! The trade between cost and accuracy of one analysis on one model, as its
//! user meets it: the analysis run over a ladder of methods and
//! tolerances, each run's time beside the numerical error it states on its
//! headline numbers and its distance to the most accurate run; and, where
//! an `accuracy` is asked for, what that request cost against the cheapest
//! hand-chosen run that stated as small an error.

use crate::analysis::declared::{no_progress, Analysis, AnalysisError};
use crate::plot::{palette, Figure, PanelSpec, Rgb};
use crate::registry::Model;
use serde::Serialize;
use std::time::Instant;

/// A headline number of a result and its stated numerical error.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Stated {
    /// What the number is ("λ₁", "q = [3.1416]: lower edge").
    pub what: String,
    /// The kind of number, errors of one kind comparable ("edge", "share
    /// of pixels", "tune"): a run's largest error is of its first kind.
    pub kind: &'static str,
    /// Its value (NaN where the error qualifies many numbers, as a map's
    /// tunes).
    pub value: f64,
    pub error: f64,
}

/// A result's headline numbers, each with its stated numerical error.
pub trait StatedErrors {
    /// Those the result states an error for (empty: none stated, as where
    /// no check ran).
    fn stated(&self) -> Vec<Stated>;
}

/// One run of the analysis in a trade.
#[derive(Clone, Debug, Serialize)]
pub struct TradeRun {
    pub method: String,
    pub tol: f64,
    /// Wall-clock seconds of the run, its checks included.
    pub seconds: f64,
    pub stated: Vec<Stated>,
    /// The largest stated error of the first kind of number stated (the
    /// headline's; NaN where none is stated).
    pub largest_error: f64,
    /// The largest distance of a headline number to the reference run's
    /// (None for the reference, or where none can be compared).
    pub largest_distance: Option<f64>,
}

/// A run of the ladder that gave no result, and why.
#[derive(Debug, Serialize)]
pub struct FailedRun {
    pub method: String,
    pub tol: f64,
    #[serde(serialize_with = "as_text")]
    pub error: AnalysisError,
}

/// The trade of an analysis on a model.
#[derive(Debug, Serialize)]
pub struct Trade {
    pub analysis: &'static str,
    pub model: String,
    /// The ladder's runs that gave a result, in the order run, then the
    /// run that asked for an `accuracy`.
    pub runs: Vec<TradeRun>,
    pub failed: Vec<FailedRun>,
    /// The index in `runs` of the run with the smallest stated error, the
    /// distances' reference.
    pub reference: Option<usize>,
    /// The index in `runs` of the run that asked for an `accuracy` (the
    /// last; its method and tolerance those it started from), where one
    /// did.
    pub requested: Option<usize>,
    /// The `accuracy` asked for, where one was.
    pub accuracy: Option<f64>,
    /// The requested run's time over that of the cheapest run of the
    /// ladder that states an error within the accuracy asked (None where
    /// no run of the ladder does).
    pub cost_ratio: Option<f64>,
}

/// The analysis `base` on `model` at `values` over `ladder` (method name and
/// tolerance; the name only labels the runs of an analysis without a
/// `method` setting; the first run's error where none gives a result) and, where given, `request` (the same settings with an
/// `accuracy`); `progress` hears of each run done.
pub fn trade<T: Analysis>(
    model: &'static Model,
    values: &[f64],
    base: &T,
    ladder: &[(String, f64)],
    request: Option<&T>,
    progress: &dyn Fn(&str),
) -> Result<Trade, AnalysisError>
where
    T::Output: StatedErrors,
{
    // A run under a twentieth of a second is repeated (up to ten times, a
    // quarter of a second in all) and its shortest time kept: such times
    // are otherwise the clock's and the scheduler's noise.
    let timed = |options: &T, method: &str, tol: f64| {
        let (mut seconds, mut spent, mut output) = (f64::INFINITY, 0.0, None);
        for _ in 0..10 {
            let start = Instant::now();
            output = Some(options.run(model, values, &no_progress)?);
            let took = start.elapsed().as_secs_f64();
            seconds = seconds.min(took);
            spent += took;
            if took > 0.05 || spent > 0.25 {
                break;
            }
        }
        progress(&format!("{method} at tol {tol:.1e}: {seconds:.3} s"));
        let stated = output.map_or_else(Vec::new, |o| o.stated());
        Ok::<_, AnalysisError>(TradeRun::new(method, tol, seconds, stated))
    };
    let (mut runs, mut failed) = (Vec::new(), Vec::new());
    for (method, tol) in ladder {
        // An analysis of one method (the section's) takes the tolerance only.
        let tol_text = tol.to_string();
        let mut texts = vec![("tol", tol_text.as_str())];
        if T::names().contains(&"method") {
            texts.push(("method", method.as_str()));
        }
        let options = base.clone().with_texts(texts)?;
        match timed(&options, method, *tol) {
            Ok(run) => runs.push(run),
            Err(error) => failed.push(FailedRun {
                method: method.clone(),
                tol: *tol,
                error: error.located(model, values),
            }),
        }
    }
    // A ladder none of whose runs gave a result has nothing to show: its
    // first run's error is the trade's.
    if runs.is_empty() && !failed.is_empty() {
        return Err(failed.swap_remove(0).error);
    }
    let mut accuracy = None;
    let requested = match request {
        Some(options) => {
            let settings = options.to_json();
            accuracy = settings.get("accuracy").and_then(|a| a.as_f64());
            let method = settings
                .get("method")
                .and_then(|m| m.as_str())
                .unwrap_or("");
            let tol = settings
                .get("tol")
                .and_then(|t| t.as_f64())
                .unwrap_or(f64::NAN);
            runs.push(timed(options, method, tol)?);
            Some(runs.len() - 1)
        }
        None => None,
    };
    let reference = (0..runs.len())
        .filter(|&k| runs[k].largest_error.is_finite())
        .min_by(|&a, &b| {
            (runs[a].largest_error, runs[a].tol)
                .partial_cmp(&(runs[b].largest_error, runs[b].tol))
                .unwrap_or(std::cmp::Ordering::Equal)
        });
    if let Some(r) = reference {
        let stated = runs[r].stated.clone();
        for (k, run) in runs.iter_mut().enumerate() {
            if k != r {
                run.largest_distance = largest_distance(&run.stated, &stated);
            }
        }
    }
    let cost_ratio = requested.zip(accuracy).and_then(|(asked, accuracy)| {
        let ladder = &runs[..asked];
        cheapest_reaching(ladder, accuracy).map(|k| runs[asked].seconds / ladder[k].seconds)
    });
    Ok(Trade {
        analysis: T::ANALYSIS,
        model: model.info.name.to_string(),
        runs,
        failed,
        reference,
        requested,
        accuracy,
        cost_ratio,
    })
}

impl TradeRun {
    fn new(method: &str, tol: f64, seconds: f64, stated: Vec<Stated>) -> TradeRun {
        let largest_error = stated.iter().map(|s| s.error).fold(f64::NAN, f64::max);
        TradeRun {
            method: method.to_string(),
            tol,
            seconds,
            stated,
            largest_error,
            largest_distance: None,
        }
    }
}

/// The largest |value − reference's value| over the numbers of the first
/// kind both state (None where none is comparable).
fn largest_distance(stated: &[Stated], reference: &[Stated]) -> Option<f64> {
    let headline = stated.first().map(|s| s.kind);
    stated
        .iter()
        .filter(|s| Some(s.kind) == headline)
        .filter_map(|s| {
            let r = reference.iter().find(|r| r.what == s.what)?;
            let d = (s.value - r.value).abs();
            d.is_finite().then_some(d)
        })
        .reduce(f64::max)
}

fn as_text<E: std::fmt::Display, Z: serde::Serializer>(e: &E, z: Z) -> Result<Z::Ok, Z::Error> {
    z.collect_str(e)
}

/// The index of the cheapest run whose stated error is at most `error`.
pub fn cheapest_reaching(runs: &[TradeRun], error: f64) -> Option<usize> {
    (0..runs.len())
        .filter(|&k| runs[k].largest_error <= error)
        .min_by(|&a, &b| runs[a].seconds.total_cmp(&runs[b].seconds))
}

impl Trade {
    /// Error against time, log–log: per method the stated error (a line)
    /// and the distance to the reference (dots); the requested run as a
    /// black square, the accuracy it asked for as a dashed line.
    pub fn figure(&self) -> Figure {
        let all = self.runs.iter();
        let seconds: Vec<f64> = all.clone().map(|r| r.seconds.max(1e-4)).collect();
        let errors: Vec<f64> = all
            .flat_map(|r| [Some(r.largest_error), r.largest_distance])
            .flatten()
            .chain(self.accuracy)
            .filter(|e| e.is_finite() && *e > 0.0)
            .collect();
        let span = |v: &[f64]| {
            let (lo, hi) = v
                .iter()
                .fold((f64::INFINITY, 0.0f64), |(a, b), &x| (a.min(x), b.max(x)));
            if lo.is_finite() && hi > 0.0 {
                (lo / 2.0, hi * 2.0)
            } else {
                (1e-3, 1.0)
            }
        };
        let headline = self
            .runs
            .iter()
            .find_map(|r| r.stated.first())
            .map_or("headline number", |s| s.kind);
        let title = format!(
            "{} on {}, {headline}: stated error (lines), distance to the most accurate run (dots)",
            self.analysis, self.model,
        );
        let spec =
            PanelSpec::new(&title, "seconds", "error", span(&seconds), span(&errors)).log_log();
        let mut figure = Figure::single(900, 600, spec);
        let ladder = &self.runs[..self.requested.unwrap_or(self.runs.len())];
        let mut methods: Vec<&str> = ladder.iter().map(|r| r.method.as_str()).collect();
        methods.dedup();
        let mut legend = Vec::new();
        for (k, method) in methods.iter().enumerate() {
            let of: Vec<&TradeRun> = ladder.iter().filter(|r| r.method == *method).collect();
            let line: Vec<(f64, f64)> = of
                .iter()
                .map(|r| (r.seconds.max(1e-4), r.largest_error))
                .collect();
            figure.line(0, &line, palette(k));
            figure.points(0, line.iter().copied(), palette(k), 3);
            let dots = of
                .iter()
                .filter_map(|r| Some((r.seconds.max(1e-4), r.largest_distance?)));
            figure.points(0, dots, palette(k), 6);
            legend.push((method.to_string(), palette(k)));
        }
        if let Some(accuracy) = self.accuracy {
            let (left, right) = figure.panel(0).x_range;
            figure.dashed_line(
                0,
                &[(left, accuracy), (right, accuracy)],
                Rgb(120, 120, 120),
            );
        }
        if let Some(asked) = self.requested.map(|k| &self.runs[k]) {
            figure.points(0, [(asked.seconds, asked.largest_error)], Rgb(0, 0, 0), 9);
            if let Some(distance) = asked.largest_distance {
                figure.points(0, [(asked.seconds, distance)], Rgb(0, 0, 0), 6);
            }
            let cost = self
                .cost_ratio
                .map_or("no run of the ladder within it".into(), |ratio| {
                    format!("{ratio:.2}× the cheapest run within it")
                });
            legend.push((format!("accuracy asked: {cost}"), Rgb(0, 0, 0)));
        }
        figure.legend(0, &legend);
        figure
    }
}

impl crate::outputs::Outputs for Trade {
    fn figures(&self) -> Vec<(String, Figure)> {
        vec![("trade.png".into(), self.figure())]
    }
    fn tables(&self) -> Vec<crate::outputs::Table> {
        let rows = self
            .runs
            .iter()
            .enumerate()
            .map(|(k, r)| (self.requested == Some(k), r))
            .flat_map(|(asked, r)| {
                r.stated.iter().map(move |s| {
                    let reference = self.reference.map(|k| &self.runs[k].stated);
                    let distance = reference
                        .and_then(|stated| largest_distance(std::slice::from_ref(s), stated));
                    (
                        asked, &r.method, r.tol, r.seconds, s.kind, &s.what, s.value, s.error,
                        distance,
                    )
                })
            });
        vec![crate::outputs::Table::new(
            "trade.csv",
            &[
                "accuracy_asked",
                "method",
                "tol",
                "seconds",
                "kind",
                "what",
                "value",
                "stated_error",
                "distance_to_reference",
            ],
            rows,
        )]
    }
}

/// The exact window's edges, each with its error; the multipliers of the
/// orbits the vibration moves equilibria to.
impl StatedErrors for crate::analysis::stability::Stability {
    fn stated(&self) -> Vec<Stated> {
        let mut stated = Vec::new();
        for e in &self.equilibria {
            let (Some(window), Some(errors)) = (e.exact_window, e.exact_window_error) else {
                continue;
            };
            for ((edge, error), side) in window.iter().zip(errors).zip(["lower", "upper"]) {
                if let (Some(value), Some(error)) = (edge, error) {
                    stated.push(Stated {
                        what: format!("q = {:.6?}: {side} edge", e.q),
                        kind: "edge of an exact window",
                        value: *value,
                        error,
                    });
                }
            }
        }
        for moved in &self.moved_by_vibration {
            let Some(error) = moved.multipliers_error else {
                continue;
            };
            for (k, (re, im)) in moved.multipliers.iter().enumerate() {
                stated.push(Stated {
                    what: format!("q = {:.6?} moved: |multiplier {k}|", moved.q),
                    kind: "Floquet multiplier",
                    value: re.hypot(*im),
                    error,
                });
            }
        }
        stated
    }
}

/// The chaotic fraction, its error the share of pixels that change class.
impl StatedErrors for crate::analysis::chaos_map::ChaosMap {
    fn stated(&self) -> Vec<Stated> {
        class_checked("chaotic fraction", self.chaotic_fraction, &self.class_check)
    }
}

fn class_checked(
    what: &str,
    value: f64,
    check: &Option<crate::analysis::check::ClassCheck>,
) -> Vec<Stated> {
    check
        .iter()
        .map(|c| Stated {
            what: what.into(),
            kind: "share of pixels",
            value,
            error: c.fraction.max(c.error),
        })
        .collect()
}

/// The Lyapunov exponents, their error the two starts' difference.
impl StatedErrors for crate::analysis::attractor::Attractor {
    fn stated(&self) -> Vec<Stated> {
        self.lyapunov
            .iter()
            .zip(&self.lyapunov_error)
            .enumerate()
            .map(|(k, (value, error))| Stated {
                what: format!("lambda_{} per period", k + 1),
                kind: "Lyapunov exponent",
                value: *value,
                error: *error,
            })
            .collect()
    }
}

/// The located bifurcations' parameters, then the branches' states.
impl StatedErrors for crate::analysis::continuation::Continuation {
    fn stated(&self) -> Vec<Stated> {
        let bifurcations = self.bifurcations.iter().enumerate().filter_map(|(k, b)| {
            Some(Stated {
                what: format!("bifurcation {k} ({:?}, period {})", b.kind, b.period),
                kind: "bifurcation's parameter",
                value: b.parameter,
                error: b.parameter_error?,
            })
        });
        let branches = self.branches.iter().enumerate().filter_map(|(k, b)| {
            Some(Stated {
                what: format!("branch {k} (period {}): its states", b.period),
                kind: "branch's state",
                value: f64::NAN,
                error: b.state_error?,
            })
        });
        bifurcations.chain(branches).collect()
    }
}

/// The MEGNO map's chaotic fraction, the frequency map's tunes and the
/// orbits' crossings.
impl StatedErrors for crate::analysis::section::SectionStudy {
    fn stated(&self) -> Vec<Stated> {
        let mut stated = Vec::new();
        if let Some(map) = &self.megno_map {
            stated.extend(class_checked(
                "chaotic fraction (MEGNO)",
                map.chaotic_fraction,
                &map.class_check,
            ));
        }
        if let Some(check) = self
            .frequency_map
            .as_ref()
            .and_then(|m| m.tune_check.as_ref())
        {
            stated.push(Stated {
                what: "tunes (largest change)".into(),
                kind: "tune",
                value: f64::NAN,
                error: check.largest,
            });
        }
        if let Some(section) = &self.section {
            for (k, error) in section.crossing_errors.iter().enumerate() {
                stated.push(Stated {
                    what: format!("orbit {k}: its crossings"),
                    kind: "crossing",
                    value: f64::NAN,
                    error: *error,
                });
            }
        }
        stated
    }
}

/// Each basin's fraction, its error the grid's or the class check's.
impl StatedErrors for crate::analysis::basins::Basins {
    fn stated(&self) -> Vec<Stated> {
        (self.attractors.iter())
            .enumerate()
            .map(|(k, a)| Stated {
                what: format!("attractor {} ({}): fraction", k + 1, a.kind),
                kind: "basin's fraction",
                value: a.fraction,
                error: a.fraction_error,
            })
            .collect()
    }
}

/// Each checked orbit's drawn points.
impl StatedErrors for crate::analysis::period_map::Portrait {
    fn stated(&self) -> Vec<Stated> {
        (self.checks.iter())
            .map(|c| Stated {
                what: format!("orbit {}: its points", c.orbit),
                kind: "point of an orbit",
                value: f64::NAN,
                error: c.error,
            })
            .collect()
    }
}

/// Each deviation between the exact and the averaged runs.
impl StatedErrors for crate::analysis::averaging::AveragingConvergence {
    fn stated(&self) -> Vec<Stated> {
        let mut stated = Vec::new();
        for (c, errors) in self.deviation_error.iter().enumerate() {
            for (k, error) in errors.iter().enumerate() {
                stated.push(Stated {
                    what: format!(
                        "{} at nu = {}: max deviation",
                        self.coordinates[c], self.frequencies[k]
                    ),
                    kind: "deviation",
                    value: self.max_deviation[c][k],
                    error: *error,
                });
            }
        }
        stated
    }
}

/// The exact windows' edges on the constraints.
impl StatedErrors for crate::analysis::on_constraints::vibration::Linkage {
    fn stated(&self) -> Vec<Stated> {
        use crate::analysis::on_constraints::vibration::Exact;
        let Exact::Periodic {
            windows,
            window_errors,
            ..
        } = &self.stability.exact
        else {
            return Vec::new();
        };
        let mut stated = Vec::new();
        for (k, (window, errors)) in windows.iter().zip(window_errors).enumerate() {
            for (side, name) in [(0, "lower"), (1, "upper")] {
                if let Some(error) = errors[side] {
                    stated.push(Stated {
                        what: format!("window {k}: {name} edge"),
                        kind: "edge of an exact window",
                        value: window[side],
                        error,
                    });
                }
            }
        }
        stated
    }
}

/// The lobe area.
impl StatedErrors for crate::analysis::separatrix::Splitting {
    fn stated(&self) -> Vec<Stated> {
        let (Some(value), Some(error)) = (self.lobe_area(), self.lobe_area_error) else {
            return Vec::new();
        };
        vec![Stated {
            what: "lobe area".into(),
            kind: "lobe area",
            value,
            error,
        }]
    }
}
