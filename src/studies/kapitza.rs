//! Study 1, the pendulum with a vibrating pivot: the runs of its scenes
//! (`kapitza_period_map`, `kapitza_stability`, `kapitza_attractor`), each
//! returning its summary with the data its figures are drawn from.

use super::StudyError;
use crate::analysis::dimension::{bounds, box_counting, kaplan_yorke_dimension};
use crate::analysis::floquet::{floquet_multipliers, monodromy, Verdict};
use crate::analysis::lyapunov::lyapunov_spectrum;
use crate::analysis::period_map::{orbit, orbits};
use crate::analysis::stability::{
    stability, stability_chart, ChartSettings, Settings, StabilityChart,
};
use crate::models::kapitza::{self, Exact, Params, PERIODIC_STATE};
use crate::ode::{Integrator, Method};
use crate::plot::{palette, Figure, PanelSpec, BLACK, BLUE, RED};
use rayon::prelude::*;
use std::f64::consts::{PI, SQRT_2};

/// The parameters from the model's values in declaration order (not
/// inlined: the study scenes' declarations call it without taking the
/// generated code into their own codegen unit).
/// The model's description (not inlined, as [`study_params`]).
#[inline(never)]
pub fn info() -> &'static crate::registry::ModelInfo {
    &kapitza::INFO
}

#[inline(never)]
pub fn study_params(values: &[f64]) -> Params {
    Params::from_values(values)
}

/// A portrait for each amplitude of `presets`, the other parameters those
/// of `params`.
#[inline(never)]
pub fn portraits(
    params: Params,
    presets: &[f64],
    seeds: usize,
    periods: usize,
    method: Method,
) -> Result<Vec<Portrait>, StudyError> {
    presets
        .iter()
        .map(|&a| portrait(Params { A: a, ..params }, seeds, periods, method))
        .collect()
}

/// The forcing period 2πε (2π over the generated phase rate).
pub fn period(params: &Params) -> f64 {
    2.0 * PI / kapitza::phase_rate(params)
}

/// The pendulum needs ε > 0, A ≥ 0 and μ ≥ 0.
pub fn check(params: &Params) -> Result<(), StudyError> {
    for (name, value) in kapitza::INFO.parameter_names.iter().zip(params.values()) {
        kapitza::INFO.check_parameter(name, value)?;
    }
    if params.A >= 0.0 {
        return Ok(());
    }
    Err(StudyError::Settings {
        setting: "A",
        requirement: "the study's amplitude is at least 0 (−A is A a half period later)",
    })
}

/// Initial conditions of the portraits: a spread through the lower position
/// q = π, plus points near the separatrix.
pub fn portrait_seeds(count: usize) -> Vec<[f64; 2]> {
    let near = [[PI, 1.98], [PI, 2.02], [0.05, 0.0], [PI, -1.98]];
    let spread = count.saturating_sub(near.len()).max(1);
    let mut points: Vec<[f64; 2]> = (0..spread)
        .map(|i| [PI - 1e-9, 0.1 + 2.9 * i as f64 / (spread - 1).max(1) as f64])
        .collect();
    points.extend(near.iter().take(count.saturating_sub(spread)));
    points
}

/// One portrait of the period map: its orbits from [`portrait_seeds`].
#[allow(non_snake_case)]
#[derive(Debug, serde::Serialize)]
pub struct Portrait {
    pub A: f64,
    pub eps: f64,
    pub mu: f64,
    pub method: &'static str,
    pub orbits: usize,
    pub periods: usize,
    pub seconds: f64,
    pub f_evals: u64,
    /// Per orbit, its points (q, p) period by period.
    #[serde(skip)]
    pub points: Vec<Vec<[f64; 2]>>,
}

/// The portrait at `params`: `seeds` orbits of `periods` periods, on all cores.
pub fn portrait(
    params: Params,
    seeds: usize,
    periods: usize,
    method: Method,
) -> Result<Portrait, StudyError> {
    check(&params)?;
    let initial = portrait_seeds(seeds);
    let start = std::time::Instant::now();
    let runs = orbits(
        method,
        &Exact { params },
        period(&params),
        &initial,
        periods,
        &PERIODIC_STATE,
    )?;
    let seconds = start.elapsed().as_secs_f64();
    let mut points = Vec::with_capacity(runs.len());
    let mut f_evals = 0;
    for (index, run) in runs.into_iter().enumerate() {
        let (orbit, stats) = run.map_err(|source| StudyError::Orbit {
            index,
            start: initial[index].to_vec(),
            source,
        })?;
        f_evals += stats.f_evals;
        points.push(orbit);
    }
    Ok(Portrait {
        A: params.A,
        eps: params.eps,
        mu: params.mu,
        method: method.name(),
        orbits: initial.len(),
        periods,
        seconds,
        f_evals,
        points,
    })
}

impl Portrait {
    /// The orbits as dots on the cylinder, a colour per orbit.
    pub fn figure(&self) -> Figure {
        let title = format!(
            "Kapitza period map, A = {}, ε = {}, μ = {} ({} periods)",
            self.A, self.eps, self.mu, self.periods
        );
        let spec = PanelSpec::new(&title, "q (0 = upward)", "p", (-PI, PI), (-3.6, 3.6));
        let mut figure = Figure::single(900, 700, spec);
        for (k, orbit) in self.points.iter().enumerate() {
            figure.points(0, orbit.iter().map(|y| (y[0], y[1])), palette(k), 1);
        }
        figure.legend(
            0,
            &[
                (
                    format!("A = {}, ε = {}, μ = {}", self.A, self.eps, self.mu),
                    palette(0),
                ),
                (
                    format!("{} orbits, {}", self.orbits, self.method),
                    palette(1),
                ),
            ],
        );
        figure
    }

    /// Rows (orbit, period, q, p).
    pub fn rows(&self) -> impl Iterator<Item = (usize, usize, f64, f64)> + '_ {
        self.points.iter().enumerate().flat_map(|(k, orbit)| {
            orbit
                .iter()
                .enumerate()
                .map(move |(n, y)| (k, n, y[0], y[1]))
        })
    }
}

/// One orbit and what it cost (the peer benchmarks read this summary).
#[derive(Debug, serde::Serialize)]
pub struct SingleOrbit {
    pub final_state: [f64; 2],
    pub periods: usize,
    pub method: &'static str,
    pub tol: f64,
    /// The fastest of the timed runs.
    pub seconds: f64,
    pub f_evals: u64,
    pub steps: u64,
    pub rejected: u64,
    /// Taylor method: its order (0 for the others).
    pub order: u64,
    #[serde(skip)]
    pub params: Params,
    #[serde(skip)]
    pub points: Vec<[f64; 2]>,
}

/// The orbit from `y0`, timed `repeat` times (the fastest run is reported).
pub fn single_orbit(
    params: Params,
    y0: [f64; 2],
    periods: usize,
    method: Method,
    repeat: usize,
) -> Result<SingleOrbit, StudyError> {
    check(&params)?;
    let mut seconds = f64::INFINITY;
    let (mut points, mut stats) = (Vec::new(), Default::default());
    for _ in 0..repeat.max(1) {
        let mut integrator = Integrator::new(method)?;
        let start = std::time::Instant::now();
        points = orbit(
            &mut integrator,
            &Exact { params },
            period(&params),
            &y0,
            periods,
            &PERIODIC_STATE,
        )?;
        seconds = seconds.min(start.elapsed().as_secs_f64());
        stats = integrator.stats;
    }
    Ok(SingleOrbit {
        final_state: points[points.len() - 1],
        periods,
        method: method.name(),
        tol: method.accuracy(),
        seconds,
        f_evals: stats.f_evals,
        steps: stats.steps,
        rejected: stats.rejected,
        order: stats.order,
        params,
        points,
    })
}

impl SingleOrbit {
    pub fn figure(&self) -> Figure {
        let (lo, hi) = self
            .points
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), y| {
                (lo.min(y[1]), hi.max(y[1]))
            });
        let pad = 0.05 * (hi - lo).max(1e-3);
        let p = &self.params;
        let title = format!("A = {}, ε = {}, μ = {}", p.A, p.eps, p.mu);
        let spec = PanelSpec::new(&title, "q", "p", (-PI, PI), (lo - pad, hi + pad));
        let mut figure = Figure::single(800, 600, spec);
        figure.points(0, self.points.iter().map(|y| (y[0], y[1])), palette(0), 1);
        figure
    }
}

/// The exact A* at which the upper position becomes stable (the lower edge
/// of its window in (0, 4]) and the second-order averaged threshold, both
/// from the generic `stability`.
pub fn critical_amplitude(eps: f64, mu: f64, method: Method) -> Result<AStar, StudyError> {
    let settings = Settings {
        amplitude: "A".into(),
        a_max: Some(4.0),
        samples: 400,
        edge_tolerance: 1e-10,
        method,
        max_windows: crate::analysis::stability::MAX_WINDOWS,
        accuracy: None,
        first: Default::default(),
    };
    let params = Params { A: SQRT_2, eps, mu };
    let result = stability(&kapitza::MODEL, &params.values(), &settings)?;
    let upper = result.equilibria.iter().find(|e| e.q[0].abs() < 1e-9);
    Ok(AStar {
        eps,
        a_star: upper.and_then(|e| e.exact_window).and_then(|[low, _]| low),
        a_star_second_order: upper.and_then(|e| e.a_star_second_order),
    })
}

/// What `kapitza_stability` computes.
pub struct UpperPositionSettings {
    pub params: Params,
    /// Periods of each orbit near q = 0.
    pub periods: usize,
    /// Chart: ε values, samples in A, largest A.
    pub chart_eps: usize,
    pub chart_a: usize,
    pub chart_a_max: f64,
    pub method: Method,
}

/// A* at one ε: exact (Floquet) and from the second-order averaged system
/// (√2 + 7√2/16 ε² + O(ε⁴)).
#[derive(Debug, serde::Serialize)]
pub struct AStar {
    pub eps: f64,
    pub a_star: Option<f64>,
    pub a_star_second_order: Option<f64>,
}

/// The stability of the upper position: A*, the multipliers at the given A,
/// orbits near q = 0 either side of A*, the averaged portraits, the chart.
#[allow(non_snake_case)]
#[derive(serde::Serialize)]
pub struct UpperPosition {
    pub eps: f64,
    pub mu: f64,
    pub A: f64,
    pub a_star: Option<f64>,
    pub a_star_averaged: f64,
    /// The threshold of the system averaged to second order in ε.
    pub a_star_second_order: Option<f64>,
    pub multipliers: Vec<[f64; 2]>,
    pub determinant: f64,
    pub determinant_expected: f64,
    pub verdict: &'static str,
    pub a_star_by_eps: Vec<AStar>,
    /// (A, μ, label) of the three orbit panels, and their orbits.
    #[serde(skip)]
    pub cases: Vec<(f64, f64, &'static str, Orbits)>,
    #[serde(skip)]
    pub chart: StabilityChart,
}

/// Orbits of the period map, each a list of states (q, p).
pub type Orbits = Vec<Vec<[f64; 2]>>;

/// Starts of the orbits near the upper position.
const NEAR_UPPER: [[f64; 2]; 4] = [[0.05, 0.0], [0.15, 0.0], [0.3, 0.0], [0.0, 0.25]];

pub fn upper_position(s: &UpperPositionSettings) -> Result<UpperPosition, StudyError> {
    check(&s.params)?;
    let Params { A: a, eps, mu } = s.params;
    let period = period(&s.params);
    let critical = critical_amplitude(eps, mu, s.method)?;
    let a_star = critical.a_star;
    let mut integrator = Integrator::new(s.method)?;
    let (_, m) = monodromy::<_, 2, 6>(
        &mut integrator,
        &Exact { params: s.params },
        period,
        &[0.0; 2],
    )?;
    let multipliers = floquet_multipliers(&m);
    // On the criterion that holds however short the period (a fixed
    // distance of |λ| from 1 moved the verdict as ε fell).
    let verdict = Verdict::of_rows(&m, period);

    let a_ref = a_star.unwrap_or(SQRT_2);
    let cases = [
        (a_ref - 0.15, mu, "below A*"),
        (a_ref + 0.15, mu, "above A*"),
        (a_ref + 0.15, mu.max(0.1), "above A*, with friction"),
    ]
    .into_iter()
    .map(|(a, mu, label)| {
        let system = Exact {
            params: Params { A: a, eps, mu },
        };
        let runs = NEAR_UPPER
            .iter()
            .map(|y0| {
                let mut integrator = Integrator::new(s.method)?;
                orbit(
                    &mut integrator,
                    &system,
                    period,
                    y0,
                    s.periods,
                    &PERIODIC_STATE,
                )
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok((a, mu, label, runs))
    })
    .collect::<Result<Vec<_>, StudyError>>()?;

    let (ne, na) = (s.chart_eps, s.chart_a);
    let chart_settings = ChartSettings {
        q: vec![0.0],
        x: "eps".into(),
        x_values: (0..ne)
            .map(|i| 0.02 + 0.48 * i as f64 / (ne - 1).max(1) as f64)
            .collect(),
        y: "A".into(),
        y_max: s.chart_a_max,
        y_samples: na,
        edge_tolerance: 1e-6,
        method: s.method,
        tiles: None,
    };
    let chart = stability_chart(&kapitza::MODEL, &s.params.values(), &chart_settings)?;

    let a_star_by_eps = [0.02, 0.05, 0.1, 0.15, 0.2, 0.3]
        .par_iter()
        .map(|&eps| critical_amplitude(eps, 0.0, s.method))
        .collect::<Result<_, _>>()?;
    Ok(UpperPosition {
        eps,
        mu,
        A: a,
        a_star,
        a_star_averaged: SQRT_2,
        a_star_second_order: critical.a_star_second_order,
        multipliers: multipliers.iter().map(|(re, im)| [*re, *im]).collect(),
        determinant: m[0][0] * m[1][1] - m[0][1] * m[1][0],
        determinant_expected: (-mu * period).exp(),
        verdict: verdict.name(),
        a_star_by_eps,
        cases,
        chart,
    })
}

impl UpperPosition {
    /// Orbits near q = 0 below and above A*, and with friction above.
    pub fn orbits_figure(&self) -> Figure {
        let titles: Vec<String> = self
            .cases
            .iter()
            .map(|(a, mu, label, _)| format!("{label}: A = {a:.3}, μ = {mu}"))
            .collect();
        let specs: Vec<PanelSpec> = titles
            .iter()
            .map(|t| PanelSpec::new(t, "q", "p", (-1.0, 1.0), (-1.0, 1.0)))
            .collect();
        let mut figure = Figure::grid(3, 1, 460, 460, &specs);
        for (k, (_, mu, _, runs)) in self.cases.iter().enumerate() {
            for (s, points) in runs.iter().enumerate() {
                let size = if *mu > 0.0 { 2 } else { 1 };
                figure.points(k, points.iter().map(|y| (y[0], y[1])), palette(s), size);
            }
        }
        figure
    }

    /// Rows (A, μ, orbit, period, q, p) of the orbits near q = 0.
    pub fn orbit_rows(&self) -> impl Iterator<Item = (f64, f64, usize, usize, f64, f64)> + '_ {
        self.cases.iter().flat_map(|(a, mu, _, runs)| {
            runs.iter().enumerate().flat_map(move |(s, points)| {
                points
                    .iter()
                    .enumerate()
                    .map(move |(n, y)| (*a, *mu, s, n, y[0], y[1]))
            })
        })
    }

    /// Level sets of the averaged Hamiltonian just below and above √2.
    pub fn averaged_figure(&self) -> Figure {
        let amplitudes = [SQRT_2 - 0.3, SQRT_2 + 0.3];
        let titles: Vec<String> = amplitudes
            .iter()
            .map(|a| format!("levels of the averaged Hamiltonian, A = {a:.3}"))
            .collect();
        let specs: Vec<PanelSpec> = titles
            .iter()
            .map(|t| PanelSpec::new(t, "q", "p", (-PI, PI), (-2.5, 2.5)))
            .collect();
        let mut figure = Figure::grid(2, 1, 560, 460, &specs);
        for (k, a) in amplitudes.iter().enumerate() {
            let params = Params {
                A: *a,
                eps: self.eps,
                mu: 0.0,
            };
            let h_top = kapitza::averaged_hamiltonian(&[0.0, 0.0], &params);
            let h = |q, p| kapitza::averaged_hamiltonian(&[q, p], &params);
            figure.contours(k, &h, 0.15, BLUE, h_top, RED);
        }
        figure
    }

    /// The (ε, A) chart with the averaged threshold √2.
    pub fn chart_figure(&self) -> Figure {
        let mut figure = self.chart.figure();
        let (first, last) = (self.chart.x_values[0], *self.chart.x_values.last().unwrap());
        figure.line(0, &[(first, SQRT_2), (last, SQRT_2)], RED);
        let second = self
            .a_star_by_eps
            .iter()
            .filter_map(|s| Some((s.eps, s.a_star_second_order?)));
        figure.points(0, second, BLACK, 6);
        figure.legend(
            0,
            &[
                ("averaged A* = √2".into(), RED),
                ("second-order averaged A*".into(), BLACK),
                ("exact boundaries".into(), BLUE),
            ],
        );
        figure
    }

    /// Rows (ε, A on a boundary) of the chart.
    pub fn chart_rows(&self) -> impl Iterator<Item = (f64, f64)> + '_ {
        self.chart
            .boundaries
            .iter()
            .zip(&self.chart.x_values)
            .flat_map(|(edges, e)| edges.iter().map(move |a| (*e, *a)))
    }
}

/// The window of the attractor's zoom.
#[derive(Debug, serde::Serialize)]
pub struct Window {
    pub q: [f64; 2],
    pub p: [f64; 2],
}

/// A strange attractor of the dissipative period map.
#[allow(non_snake_case)]
#[derive(serde::Serialize)]
pub struct Attractor {
    pub A: f64,
    pub eps: f64,
    pub mu: f64,
    pub lyapunov: Vec<f64>,
    pub lyapunov_sum_expected: f64,
    pub lyapunov_sum: f64,
    pub dimension: f64,
    pub kaplan_yorke_dimension: f64,
    pub points: usize,
    pub zoom_window: Window,
    pub seconds: f64,
    /// The box sides, their counts, and the fit's intercept.
    pub box_sides: Vec<f64>,
    pub boxes: Vec<usize>,
    pub box_intercept: f64,
    #[serde(skip)]
    pub orbit: Vec<[f64; 2]>,
}

/// What `kapitza_attractor` computes.
pub struct AttractorSettings {
    pub params: Params,
    pub points: usize,
    pub transient: usize,
    pub lyapunov_periods: usize,
    /// The zoom shows 1/zoom of the attractor's extent.
    pub zoom: f64,
    pub method: Method,
}

/// The attractor after the transient from (1, 0.3), its Lyapunov exponents
/// (their sum is −μT) and its box-counting dimension (box sides 1/4 …
/// 1/256 of the extent; the fit leaves out the coarsest and the finest,
/// which 10⁵ points cannot fill).
pub fn attractor(s: &AttractorSettings) -> Result<Attractor, StudyError> {
    check(&s.params)?;
    let system = Exact { params: s.params };
    let period = period(&s.params);
    let wrap = PERIODIC_STATE;
    let mut integrator = Integrator::new(s.method)?;
    let start = std::time::Instant::now();
    let transient = orbit(
        &mut integrator,
        &system,
        period,
        &[1.0, 0.3],
        s.transient,
        &wrap,
    )?;
    let settled = transient[transient.len() - 1];
    let points = orbit(&mut integrator, &system, period, &settled, s.points, &wrap)?;
    let seconds = start.elapsed().as_secs_f64();

    let mut integrator = Integrator::new(s.method)?;
    let (lyapunov, _) = lyapunov_spectrum::<_, 2, 6>(
        &mut integrator,
        &system,
        period,
        &settled,
        0,
        s.lyapunov_periods,
        &wrap,
    )?;
    let sides: Vec<f64> = (2..=8).map(|k| 0.5f64.powi(k)).collect();
    let counted = box_counting(&points, &sides, 1..sides.len() - 1);

    let (lo, hi) = bounds(&points);
    let centre = densest_cell(&points, 8);
    let half = [
        0.5 * (hi[0] - lo[0]) / s.zoom,
        0.5 * (hi[1] - lo[1]) / s.zoom,
    ];
    Ok(Attractor {
        A: s.params.A,
        eps: s.params.eps,
        mu: s.params.mu,
        lyapunov_sum_expected: -s.params.mu * period,
        lyapunov_sum: lyapunov.iter().sum(),
        kaplan_yorke_dimension: kaplan_yorke_dimension(&lyapunov),
        lyapunov,
        dimension: counted.dimension,
        points: s.points,
        zoom_window: Window {
            q: [centre[0] - half[0], centre[0] + half[0]],
            p: [centre[1] - half[1], centre[1] + half[1]],
        },
        seconds,
        box_sides: sides,
        boxes: counted.boxes,
        box_intercept: counted.intercept,
        orbit: points,
    })
}

/// The centre of the most populated cell of a coarse grid: where the zoom
/// shows the most layers.
fn densest_cell(points: &[[f64; 2]], cells: usize) -> [f64; 2] {
    let (lo, hi) = bounds(points);
    let mut counts = vec![0usize; cells * cells];
    let index = |p: &[f64; 2], d: usize| {
        (((p[d] - lo[d]) / (hi[d] - lo[d]) * cells as f64) as usize).min(cells - 1)
    };
    for p in points {
        counts[index(p, 1) * cells + index(p, 0)] += 1;
    }
    let best = (0..counts.len()).max_by_key(|&k| counts[k]).unwrap_or(0);
    let (i, j) = (best % cells, best / cells);
    [
        lo[0] + (i as f64 + 0.5) * (hi[0] - lo[0]) / cells as f64,
        lo[1] + (j as f64 + 0.5) * (hi[1] - lo[1]) / cells as f64,
    ]
}

impl Attractor {
    /// The attractor with the zoom window, and the zoom on its layers.
    pub fn figure(&self) -> Figure {
        let (lo, hi) = bounds(&self.orbit);
        let title = format!(
            "attractor, A = {}, ε = {}, μ = {}, {} points",
            self.A, self.eps, self.mu, self.points
        );
        let zoom = (hi[0] - lo[0]) / (self.zoom_window.q[1] - self.zoom_window.q[0]);
        let zoom_title = format!("zoom ×{zoom:.0}: layers");
        let pad = 0.05 * (hi[1] - lo[1]);
        let [q0, q1] = self.zoom_window.q;
        let [p0, p1] = self.zoom_window.p;
        let specs = [
            PanelSpec::new(&title, "q", "p", (-PI, PI), (lo[1] - pad, hi[1] + pad)),
            PanelSpec::new(&zoom_title, "q", "p", (q0, q1), (p0, p1)),
        ];
        let mut figure = Figure::grid(2, 1, 700, 700, &specs);
        let xy = || self.orbit.iter().map(|p| (p[0], p[1]));
        figure.points(0, xy(), BLACK, 1);
        figure.points(1, xy(), BLACK, 2);
        figure.line(0, &[(q0, p0), (q1, p0), (q1, p1), (q0, p1), (q0, p0)], RED);
        figure
    }

    /// ln(boxes) against ln(1/side), with the fitted line.
    pub fn box_counting_figure(&self) -> Figure {
        let log_points: Vec<(f64, f64)> = self
            .box_sides
            .iter()
            .zip(&self.boxes)
            .map(|(s, n)| ((1.0 / s).ln(), (*n as f64).ln()))
            .collect();
        let (x_lo, x_hi) = (
            log_points[0].0 - 0.3,
            log_points[log_points.len() - 1].0 + 0.3,
        );
        let ys = log_points.iter().map(|p| p.1);
        let y_lo = ys.clone().fold(f64::INFINITY, f64::min) - 0.5;
        let y_hi = ys.fold(f64::NEG_INFINITY, f64::max) + 0.5;
        let title = format!("box counting: dimension {:.3}", self.dimension);
        let spec = PanelSpec::new(
            &title,
            "ln(1/box side)",
            "ln(boxes)",
            (x_lo, x_hi),
            (y_lo, y_hi),
        );
        let mut figure = Figure::single(640, 480, spec);
        figure.points(0, log_points.iter().copied(), BLUE, 6);
        let fit = |x: f64| (x, self.box_intercept + self.dimension * x);
        figure.line(0, &[fit(x_lo), fit(x_hi)], RED);
        figure
    }
}
