//! Scene `work_precision`: error against cost for every method over a range
//! of tolerances or steps, on mechlab's own systems (issue #3):
//! (a) the Kapitza period map at ε = 0.1, A = 1.5, μ = 0 over 1000 periods,
//!     from a regular orbit (q, p) = (0.3, 0) and a chaotic one (1, 0): the
//!     error of the period map, worst along a 1000-period reference orbit
//!     (each period started from the reference point; the global error of a
//!     chaotic orbit only measures its exponential divergence), plus the
//!     global error of the regular orbit after 1000 periods;
//! (b) the double pendulum on the vibrating base at ν = 100, t ∈ [0, 10];
//! (c) the deformable rod of Study 3 sliding, ε = 0.01 and 0.001, t ∈ [0, 2].
//! Each run is timed (repeated until it has taken `min_seconds`), and the
//! third-party `ode_solvers` DOP853 runs on the same right-hand sides as a
//! peer. Writes one PNG per problem (error vs seconds and vs f-evaluations,
//! with the fitted slopes), runs.csv, and summary.json with the runs and the
//! performance ratios of the issue.

use mechlab::contact::{Mode, Smooth};
use mechlab::models::painleve_klein::{self as painleve, Contacts};
use mechlab::models::{double_pendulum as dp, kapitza, triple_pendulum};
use mechlab::ode::{Integrator, Method, OdeError, System};
use mechlab::plot::{palette, Figure, PanelSpec};
use mechlab::scene::{knob, run, Progress, Scene, SceneError};
use mechlab::studies::painleve::state_with_deformation;
use ode_solvers::{OutputType, SVector};
use std::cell::RefCell;
use std::collections::BTreeMap;
use std::f64::consts::TAU;
use std::hint::black_box;
use std::time::Instant;

/// The peer: `ode_solvers`' DOP853 on one of our systems, made autonomous
/// (state y plus time as component M − 1 = N). ode_solvers 0.6.2 evaluates
/// its 12th stage at the step's start time instead of its end (its table has
/// c₁₂ = 0), which costs it its order on time-dependent right-hand sides;
/// with the time as a state its result is right.
struct Peer<'a, S, const N: usize>(&'a S);

impl<S: System<N>, const N: usize, const M: usize> ode_solvers::System<f64, SVector<f64, M>>
    for Peer<'_, S, N>
{
    fn system(&self, _t: f64, y: &SVector<f64, M>, dy: &mut SVector<f64, M>) {
        let f = self.0.rhs(y[N], &std::array::from_fn(|i| y[i]));
        dy.as_mut_slice()[..N].copy_from_slice(&f);
        dy[N] = 1.0;
    }
}

const PEER: &str = "ode_solvers_dop853";

/// A method of ours, or the peer, with its setting.
#[derive(Clone, Copy)]
enum Solver {
    Ours(Method),
    Peer(f64),
}

impl Solver {
    fn name(&self) -> &'static str {
        match self {
            Solver::Ours(m) => m.name(),
            Solver::Peer(_) => PEER,
        }
    }
    fn setting(&self) -> f64 {
        match *self {
            Solver::Ours(Method::Rk4 { step }) | Solver::Ours(Method::Gauss { step, .. }) => step,
            Solver::Ours(Method::Dop853 { rtol, .. })
            | Solver::Ours(Method::Radau5 { rtol, .. }) => rtol,
            Solver::Ours(Method::Taylor { tol }) => tol,
            Solver::Peer(tol) => tol,
        }
    }

    /// Integrates from t0 to t1; returns the end state and the f-evaluations.
    /// M = N + 1 is the size of the peer's autonomous state.
    fn advance<S: System<N>, const N: usize, const M: usize>(
        &self,
        integrator: &mut Option<Integrator>,
        system: &S,
        t0: f64,
        y0: &[f64; N],
        t1: f64,
    ) -> Result<([f64; N], u64), String> {
        match self {
            Solver::Ours(method) => {
                let integrator = match integrator {
                    Some(i) => i,
                    None => integrator.insert(Integrator::new(*method).map_err(|e| e.to_string())?),
                };
                let before = integrator.stats.f_evals;
                let y = integrator
                    .advance(system, t0, y0, t1)
                    .map_err(|e: OdeError| e.to_string())?;
                Ok((y, integrator.stats.f_evals - before))
            }
            Solver::Peer(tol) => {
                // Its defaults, except: no stiffness test (it misfires on these
                // non-stiff problems), no step limit below ours, sparse output.
                assert_eq!(M, N + 1, "the peer's state is the state and the time");
                let start: [f64; M] = std::array::from_fn(|i| if i < N { y0[i] } else { t0 });
                let mut solver = ode_solvers::Dop853::from_param(
                    Peer::<S, N>(system),
                    t0,
                    t1,
                    t1 - t0,
                    SVector::from(start),
                    *tol,
                    *tol,
                    0.9,
                    0.0,
                    0.333,
                    6.0,
                    t1 - t0,
                    0.0,
                    10_000_000,
                    u32::MAX,
                    OutputType::Sparse,
                );
                let stats = solver.integrate().map_err(|e| e.to_string())?;
                let y = solver.y_out().last().ok_or("peer returned no state")?;
                let y: [f64; N] = std::array::from_fn(|i| y[i]);
                if y.iter().any(|x| !x.is_finite()) {
                    return Err("peer: non-finite state".into());
                }
                Ok((y, stats.num_eval as u64))
            }
        }
    }
}

/// One measured run.
#[derive(serde::Serialize)]
struct Row {
    problem: &'static str,
    method: &'static str,
    tol_or_step: f64,
    error: f64,
    seconds: f64,
    f_evals: u64,
}

/// A run that failed or was skipped, with the reason.
#[derive(serde::Serialize)]
struct Failure {
    problem: &'static str,
    method: &'static str,
    tol_or_step: f64,
    reason: String,
}

/// Fitted slope of error against f-evaluations per method (None: no line).
type Slopes = BTreeMap<String, Option<f64>>;

/// The performance figures of the Kapitza period map (issue targets).
#[derive(serde::Serialize)]
struct Performance {
    bare_rhs_ns: f64,
    bare_rhs_latency_ns: f64,
    overhead_dop853: f64,
    overhead_rk4: f64,
    overhead_dop853_against_latency: f64,
    overhead_rk4_against_latency: f64,
    #[serde(rename = "seconds_to_1e-10")]
    seconds_to_1e_10: BTreeMap<String, f64>,
    #[serde(rename = "peer_seconds_to_1e-10")]
    peer_seconds_to_1e_10: Option<f64>,
    #[serde(rename = "best_method_at_1e-10")]
    best_method_at_1e_10: String,
    #[serde(rename = "periods_per_second_at_1e-10")]
    periods_per_second_at_1e_10: f64,
    #[serde(rename = "speedup_over_peer_at_1e-10")]
    speedup_over_peer_at_1e_10: Option<f64>,
    #[serde(rename = "dop853_speedup_over_peer_dop853_at_1e-10")]
    dop853_speedup_over_peer_dop853_at_1e_10: Option<f64>,
}

fn max_difference<const N: usize>(a: &[f64; N], b: &[f64; N]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// Runs `work` once, then repeats it until `min_seconds` have passed; returns
/// its result and the mean time of one run.
fn timed<T>(
    min_seconds: f64,
    mut work: impl FnMut() -> Result<T, String>,
) -> Result<(T, f64), String> {
    let start = Instant::now();
    let result = work()?;
    let mut runs = 1u32;
    while start.elapsed().as_secs_f64() < min_seconds {
        black_box(work()?);
        runs += 1;
    }
    Ok((result, start.elapsed().as_secs_f64() / runs as f64))
}

/// How a problem's error is measured.
enum Measure<const N: usize> {
    /// Max-norm error of the state after `periods` applications of the map
    /// over `period` (one application over the whole span for plain runs).
    EndState {
        period: f64,
        periods: usize,
        reference: [f64; N],
    },
    /// Worst error of one period map along a reference orbit.
    PeriodMap { period: f64, orbit: Vec<[f64; N]> },
}

/// `periods` applications of the map over `period` from `y0`.
fn end_state<S: System<N>, const N: usize, const M: usize>(
    solver: Solver,
    system: &S,
    y0: &[f64; N],
    period: f64,
    periods: usize,
) -> Result<([f64; N], u64), String> {
    let mut integrator = None;
    let (mut y, mut evals) = (*y0, 0);
    for _ in 0..periods {
        let (next, e) = solver.advance::<S, N, M>(&mut integrator, system, 0.0, &y, period)?;
        y = next;
        evals += e;
    }
    Ok((y, evals))
}

fn measure<S: System<N>, const N: usize, const M: usize>(
    solver: Solver,
    system: &S,
    y0: &[f64; N],
    how: &Measure<N>,
) -> Result<(f64, u64), String> {
    match how {
        Measure::EndState {
            period,
            periods,
            reference,
        } => {
            let (y, evals) = end_state::<S, N, M>(solver, system, y0, *period, *periods)?;
            Ok((max_difference(&y, reference), evals))
        }
        Measure::PeriodMap { period, orbit } => {
            let mut integrator = None;
            let (mut worst, mut evals) = (0.0f64, 0u64);
            for w in orbit.windows(2) {
                let (y, e) =
                    solver.advance::<S, N, M>(&mut integrator, system, 0.0, &w[0], *period)?;
                worst = worst.max(max_difference(&y, &w[1]));
                evals += e;
            }
            Ok((worst, evals))
        }
    }
}

/// The reference end state (DOP853 at 1e-14) and its distance to a second,
/// independent method's, reported in the summary.
fn reference_end<S: System<N>, const N: usize, const M: usize>(
    system: &S,
    y0: &[f64; N],
    period: f64,
    periods: usize,
    check: Method,
) -> Result<(Measure<N>, f64), SceneError> {
    let best = Solver::Ours(Method::parse("dop853", 1e-14)?);
    let (reference, _) =
        end_state::<S, N, M>(best, system, y0, period, periods).map_err(SceneError::Numerical)?;
    let (other, _) = end_state::<S, N, M>(Solver::Ours(check), system, y0, period, periods)
        .map_err(SceneError::Numerical)?;
    let agreement = max_difference(&reference, &other);
    Ok((
        Measure::EndState {
            period,
            periods,
            reference,
        },
        agreement,
    ))
}

/// A reference orbit of the period map, each point checked by a second method.
fn reference_orbit<S: System<N>, const N: usize>(
    system: &S,
    y0: &[f64; N],
    period: f64,
    periods: usize,
    check: Method,
) -> Result<(Measure<N>, f64), SceneError> {
    let mut best = Integrator::new(Method::parse("dop853", 1e-14)?)?;
    let mut other = Integrator::new(check)?;
    let mut orbit = vec![*y0];
    let mut worst = 0.0f64;
    for _ in 0..periods {
        let y = orbit.last().unwrap();
        let next = best.advance(system, 0.0, y, period)?;
        worst = worst.max(max_difference(
            &next,
            &other.advance(system, 0.0, y, period)?,
        ));
        orbit.push(next);
    }
    Ok((Measure::PeriodMap { period, orbit }, worst))
}

fn solvers(fixed_steps: &[f64], stiff: bool) -> Vec<Solver> {
    let mut list = Vec::new();
    for k in 3..=13 {
        list.push(Solver::Ours(
            Method::parse("dop853", 10f64.powi(-k)).unwrap(),
        ));
        list.push(Solver::Peer(10f64.powi(-k)));
    }
    for k in 3..=12 {
        list.push(Solver::Ours(
            Method::parse("radau5", 10f64.powi(-k)).unwrap(),
        ));
    }
    // Taylor needs generated recurrences: the smooth problems' models have
    // them, the rod's mode-combined contact field does not.
    if !stiff {
        for k in 3..=16 {
            list.push(Solver::Ours(Method::Taylor {
                tol: 10f64.powi(-k),
            }));
        }
    }
    for &h in fixed_steps {
        list.push(Solver::Ours(Method::Rk4 { step: h }));
        if !stiff {
            list.push(Solver::Ours(Method::Gauss { stages: 2, step: h }));
            list.push(Solver::Ours(Method::Gauss { stages: 3, step: h }));
        }
    }
    list
}

#[allow(clippy::too_many_arguments)]
fn sweep<S: System<N>, const N: usize, const M: usize>(
    problem: &'static str,
    system: &S,
    y0: &[f64; N],
    how: &Measure<N>,
    list: &[Solver],
    min_seconds: f64,
    budget: f64,
    rows: &mut Vec<Row>,
    failures: &mut Vec<Failure>,
) {
    let progress = Progress::new(problem, list.len());
    let start = Instant::now();
    // A method whose run took longer than the budget is not run at tighter settings.
    let mut over_budget: Vec<&'static str> = Vec::new();
    for (i, solver) in list.iter().enumerate() {
        if over_budget.contains(&solver.name()) {
            failures.push(Failure {
                problem,
                method: solver.name(),
                tol_or_step: solver.setting(),
                reason: format!("skipped: a looser setting took over {budget} s"),
            });
            progress.update(i + 1);
            continue;
        }
        let run_start = Instant::now();
        match timed(min_seconds, || measure::<S, N, M>(*solver, system, y0, how)) {
            Ok(((error, f_evals), seconds)) => rows.push(Row {
                problem,
                method: solver.name(),
                tol_or_step: solver.setting(),
                error,
                seconds,
                f_evals,
            }),
            Err(reason) => failures.push(Failure {
                problem,
                method: solver.name(),
                tol_or_step: solver.setting(),
                reason: reason.to_string(),
            }),
        }
        if run_start.elapsed().as_secs_f64() > budget {
            over_budget.push(solver.name());
        }
        progress.update(i + 1);
    }
    eprintln!("{problem}: {:.1} s", start.elapsed().as_secs_f64());
}

/// A pendulum on a base vibrating at `nu`, t ∈ [0, 10]: every method against
/// a DOP853 reference checked with Gauss 6; returns the references' agreement.
fn vibrating_base<S: System<N>, const N: usize, const M: usize>(
    problem: &'static str,
    system: &S,
    y0: &[f64; N],
    nu: f64,
    (min_seconds, budget): (f64, f64),
    rows: &mut Vec<Row>,
    failures: &mut Vec<Failure>,
) -> Result<f64, SceneError> {
    let forcing = TAU / nu;
    let steps: Vec<f64> = [4, 8, 16, 32, 64, 128, 256]
        .iter()
        .map(|&k| forcing / k as f64)
        .collect();
    let list = solvers(&steps, false);
    let check = Method::Gauss {
        stages: 3,
        step: forcing / 256.0,
    };
    let (how, agreement) = reference_end::<_, N, M>(system, y0, 10.0, 1, check)?;
    sweep::<_, N, M>(
        problem,
        system,
        y0,
        &how,
        &list,
        min_seconds,
        budget,
        rows,
        failures,
    );
    Ok(agreement)
}

/// Least-squares slope of log(error) against log(cost), over the points
/// above the method's round-off floor (10× its smallest error) and below 1e-2;
/// none if they do not lie on a line (r² < 0.9).
fn slope(points: &[(f64, f64)]) -> Option<f64> {
    let floor = points.iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
    let pts: Vec<(f64, f64)> = points
        .iter()
        .filter(|(c, e)| *e > 10.0 * floor && *e < 1e-2 && *c > 0.0)
        .map(|(c, e)| (c.ln(), e.ln()))
        .collect();
    if pts.len() < 3 {
        return None;
    }
    let fit = mechlab::analysis::fit::least_squares(&pts);
    // No slope where the points do not lie on a line (stability-limited runs).
    (fit.r_squared > 0.9).then_some(fit.slope)
}

/// Seconds needed to reach `target` error, interpolated log-log along a method's runs.
fn seconds_at(rows: &[&Row], target: f64) -> Option<f64> {
    let mut pts: Vec<(f64, f64)> = rows.iter().map(|r| (r.error, r.seconds)).collect();
    pts.sort_by(|a, b| b.0.total_cmp(&a.0));
    pts.windows(2).find_map(|w| {
        let ((e0, s0), (e1, s1)) = (w[0], w[1]);
        (e0 >= target && e1 <= target && e0 > e1).then(|| {
            let x = (target.ln() - e0.ln()) / (e1.ln() - e0.ln());
            (s0.ln() + x * (s1.ln() - s0.ln())).exp()
        })
    })
}

const METHODS: [&str; 7] = [
    "rk4", "gauss4", "gauss6", "dop853", "radau5", PEER, "taylor",
];

/// Time of dop853 over time of taylor at equal error, per smooth problem and
/// target error (log-log interpolated along each method's runs).
fn taylor_speedups(rows: &[Row]) -> BTreeMap<String, BTreeMap<String, Option<f64>>> {
    let mut out = BTreeMap::new();
    for problem in [
        "kapitza_regular",
        "kapitza_regular_global",
        "kapitza_chaotic",
        "double_pendulum",
        "triple_pendulum",
    ] {
        let of = |method: &str| -> Vec<&Row> {
            rows.iter()
                .filter(|r| r.problem == problem && r.method == method)
                .collect()
        };
        let (dop, taylor) = (of("dop853"), of("taylor"));
        let ratios = [1e-6, 1e-8, 1e-10]
            .into_iter()
            .map(|target| {
                let ratio = seconds_at(&dop, target)
                    .zip(seconds_at(&taylor, target))
                    .map(|(d, t)| d / t);
                (format!("{target:e}"), ratio)
            })
            .collect();
        out.insert(problem.to_string(), ratios);
    }
    out
}

fn plot_problem(scene: &Scene, problem: &str, rows: &[&Row]) -> Result<Slopes, SceneError> {
    let floor = 1e-16;
    let range = |f: &dyn Fn(&Row) -> f64| {
        let (lo, hi) = rows
            .iter()
            .map(|r| f(r))
            .fold((f64::INFINITY, 0.0f64), |(a, b), x| (a.min(x), b.max(x)));
        (lo / 2.0, hi * 2.0)
    };
    let errors = range(&|r| r.error.max(floor));
    let title_time = format!("{problem}: error vs time");
    let title_evals = format!("{problem}: error vs f evaluations");
    let mut figure = Figure::grid(
        2,
        1,
        640,
        480,
        &[
            PanelSpec::new(
                &title_time,
                "seconds",
                "max error",
                range(&|r| r.seconds),
                errors,
            )
            .log_log(),
            PanelSpec::new(
                &title_evals,
                "f evaluations",
                "max error",
                range(&|r| r.f_evals as f64),
                errors,
            )
            .log_log(),
        ],
    );
    let mut legend = Vec::new();
    let mut slopes = Slopes::new();
    for (k, method) in METHODS.iter().enumerate() {
        let mut mine: Vec<&Row> = rows
            .iter()
            .copied()
            .filter(|r| r.method == *method)
            .collect();
        if mine.is_empty() {
            continue;
        }
        mine.sort_by_key(|r| r.f_evals);
        let color = palette(k);
        let by_time: Vec<(f64, f64)> = mine
            .iter()
            .map(|r| (r.seconds, r.error.max(floor)))
            .collect();
        let by_evals: Vec<(f64, f64)> = mine
            .iter()
            .map(|r| (r.f_evals as f64, r.error.max(floor)))
            .collect();
        for (panel, pts) in [(0, &by_time), (1, &by_evals)] {
            figure.line(panel, pts, color);
            figure.points(panel, pts.iter().copied(), color, 5);
        }
        let s = slope(&by_evals);
        slopes.insert(method.to_string(), s);
        let label = match s {
            Some(s) => format!("{method} slope {s:.1}"),
            None => method.to_string(),
        };
        legend.push((label, color));
    }
    figure.legend_at(1, &legend, true);
    figure.legend_at(0, &legend, true);
    scene.save_figure(&figure, &format!("{problem}.png"))?;
    Ok(slopes)
}

fn main() {
    run(|| {
        let scene = Scene::from_args(
            "work_precision",
            "error against cost for every method on the Kapitza, double-pendulum and rod problems",
            &[
                knob(
                    "min_seconds",
                    "0.02",
                    "each run is repeated until it has taken this long",
                ),
                knob("periods", "1000", "periods of the Kapitza map"),
                knob(
                    "budget",
                    "1",
                    "seconds: a method slower than this is not run at tighter settings",
                ),
            ],
        )?;
        let min_seconds = scene.non_negative("min_seconds")?;
        let periods = scene.count("periods")?;
        let budget = scene.positive("budget")?;
        let mut rows: Vec<Row> = Vec::new();
        let mut failures = Vec::new();
        let mut agreements: BTreeMap<String, f64> = BTreeMap::new();
        let mut record = |name: &str, agreement: f64| {
            agreements.insert(name.to_string(), agreement);
        };

        // (a) The Kapitza period map.
        let kp = kapitza::Params {
            A: 1.5,
            eps: 0.1,
            mu: 0.0,
        };
        let kapitza_system = kapitza::Exact { params: kp };
        let period = TAU * kp.eps;
        let per_period =
            |n: &[usize], span: f64| n.iter().map(|&k| span / k as f64).collect::<Vec<_>>();
        let check = Method::Gauss {
            stages: 3,
            step: period / 512.0,
        };
        let list = solvers(
            &per_period(&[8, 16, 32, 64, 128, 256, 512, 1024], period),
            false,
        );
        let (regular, chaotic) = ([0.3, 0.0], [1.0, 0.0]);
        let kapitza_problems = [
            (
                "kapitza_regular",
                regular,
                reference_orbit(&kapitza_system, &regular, period, periods, check)?,
            ),
            (
                "kapitza_regular_global",
                regular,
                reference_end::<_, 2, 3>(&kapitza_system, &regular, period, periods, check)?,
            ),
            (
                "kapitza_chaotic",
                chaotic,
                reference_orbit(&kapitza_system, &chaotic, period, periods, check)?,
            ),
        ];
        for (problem, y0, (how, agreement)) in &kapitza_problems {
            record(problem, *agreement);
            sweep::<_, 2, 3>(
                problem,
                &kapitza_system,
                y0,
                how,
                &list,
                min_seconds,
                budget,
                &mut rows,
                &mut failures,
            );
        }

        // (b) Pendulums on the vibrating base, t ∈ [0, 10]: the double pendulum
        // at ν = 100 (symbolic inverse), the triple at ν = 200 (numeric solve).
        let settings = (min_seconds, budget);
        let pp = dp::Params {
            nu: 100.0,
            ..Default::default()
        };
        let y0 = [0.3, -0.2, 0.0, 0.0];
        let agreement = vibrating_base::<_, 4, 5>(
            "double_pendulum",
            &dp::Exact { params: pp },
            &y0,
            pp.nu,
            settings,
            &mut rows,
            &mut failures,
        )?;
        record("double_pendulum", agreement);
        let tp = triple_pendulum::Params {
            nu: 200.0,
            ..Default::default()
        };
        let y0 = [0.3, -0.2, 0.1, 0.0, 0.0, 0.0];
        let agreement = vibrating_base::<_, 6, 7>(
            "triple_pendulum",
            &triple_pendulum::Exact { params: tp },
            &y0,
            tp.nu,
            settings,
            &mut rows,
            &mut failures,
        )?;
        record("triple_pendulum", agreement);

        // (c) The sliding deformable rod, ε = 0.01 and 0.001, t ∈ [0, 2], from R(0) = 3.
        for (problem, eps) in [("rod_eps_0.01", 1e-2), ("rod_eps_0.001", 1e-3)] {
            let model = Contacts {
                params: painleve::Params {
                    eps,
                    ..Default::default()
                },
            };
            // Both points sliding right: the smooth phase of the contact model.
            let rod = Smooth {
                model: &model,
                modes: [Mode::Slide(1); 2],
            };
            let y0 = state_with_deformation(&model.params, 3.0 * eps * eps, 10.0);
            let list = solvers(
                &per_period(&[64, 128, 256, 512, 1024, 2048, 4096, 8192, 16384], 2.0),
                true,
            );
            let (how, agreement) =
                reference_end::<_, 4, 5>(&rod, &y0, 2.0, 1, Method::parse("radau5", 1e-13)?)?;
            record(problem, agreement);
            sweep::<_, 4, 5>(
                problem,
                &rod,
                &y0,
                &how,
                &list,
                min_seconds,
                budget,
                &mut rows,
                &mut failures,
            );
        }

        // Figures and slopes.
        let mut slopes: BTreeMap<&str, Slopes> = BTreeMap::new();
        for problem in [
            "kapitza_regular",
            "kapitza_regular_global",
            "kapitza_chaotic",
            "double_pendulum",
            "triple_pendulum",
            "rod_eps_0.01",
            "rod_eps_0.001",
        ] {
            let mine: Vec<&Row> = rows.iter().filter(|r| r.problem == problem).collect();
            slopes.insert(problem, plot_problem(&scene, problem, &mine)?);
        }

        // Performance ratios on the regular Kapitza orbit.
        let ratios = performance(&kapitza_system, &regular, period, periods, &rows)?;
        println!("{}", serde_json::to_string_pretty(&ratios).unwrap());
        let speedups = taylor_speedups(&rows);
        println!(
            "dop853 time / taylor time at equal error: {}",
            serde_json::to_string_pretty(&speedups).unwrap()
        );

        scene.write_csv(
            "runs.csv",
            &[
                "problem",
                "method",
                "tol_or_step",
                "error",
                "seconds",
                "f_evals",
            ],
            rows.iter().map(|r| {
                (
                    &r.problem,
                    &r.method,
                    r.tol_or_step,
                    r.error,
                    r.seconds,
                    r.f_evals,
                )
            }),
        )?;
        #[derive(serde::Serialize)]
        struct Summary<'a> {
            runs: &'a [Row],
            failed: Vec<Failure>,
            slopes_error_vs_f_evals: BTreeMap<&'a str, Slopes>,
            reference_agreement: BTreeMap<String, f64>,
            performance: Performance,
            /// dop853 seconds / taylor seconds at equal error (1e-6, 1e-8, 1e-10).
            taylor_speedup_over_dop853: BTreeMap<String, BTreeMap<String, Option<f64>>>,
        }
        scene.write_summary(&Summary {
            runs: &rows,
            failed: failures,
            slopes_error_vs_f_evals: slopes,
            reference_agreement: agreements,
            performance: ratios,
            taylor_speedup_over_dop853: speedups,
        })?;
        Ok(())
    })
}

/// Records every (t, y) at which an integrator evaluates f.
struct Recording<'a, S> {
    inner: &'a S,
    calls: RefCell<Vec<(f64, [f64; 2])>>,
}

impl<S: System<2>> System<2> for Recording<'_, S> {
    fn rhs(&self, t: f64, y: &[f64; 2]) -> [f64; 2] {
        self.calls.borrow_mut().push((t, *y));
        self.inner.rhs(t, y)
    }
}

/// Time per f-evaluation inside an integration over the time of one bare f,
/// timed as throughput (independent calls) and as latency (dependent calls).
struct Overhead {
    against_throughput: f64,
    against_latency: f64,
    bare: f64,
    latency: f64,
}

/// The performance figures, all measured in this run.
fn performance(
    system: &kapitza::Exact,
    y0: &[f64; 2],
    period: f64,
    periods: usize,
    rows: &[Row],
) -> Result<Performance, SceneError> {
    // Overhead: integration time / (f-evaluations × time of one bare f), the
    // bare f timed on exactly the (t, y) at which the integrator called it.
    let overhead = |method: Method| -> Result<Overhead, SceneError> {
        let recording = Recording {
            inner: system,
            calls: RefCell::new(Vec::new()),
        };
        end_state::<_, 2, 3>(Solver::Ours(method), &recording, y0, period, periods)
            .map_err(SceneError::Numerical)?;
        let calls = recording.calls.into_inner();
        let ((_, evals), seconds) = timed(0.3, || {
            end_state::<_, 2, 3>(Solver::Ours(method), system, y0, period, periods)
        })
        .map_err(SceneError::Numerical)?;
        // Throughput: independent evaluations, which the CPU overlaps.
        let (_, throughput_total) = timed(0.3, || {
            let mut sum = 0.0;
            for (t, y) in &calls {
                sum += system.rhs(black_box(*t), black_box(y))[1];
            }
            Ok(black_box(sum))
        })
        .map_err(SceneError::Numerical)?;
        // Latency: each evaluation waits for the previous one, as the stages
        // of a Runge–Kutta step do (0 × previous result keeps the dependency).
        let (_, latency_total) = timed(0.3, || {
            let mut previous = 0.0;
            for (t, y) in &calls {
                let input = [y[0] + 0.0 * previous, y[1]];
                previous = system.rhs(*t, &input)[1];
            }
            Ok(black_box(previous))
        })
        .map_err(SceneError::Numerical)?;
        let bare = throughput_total / calls.len() as f64;
        let latency = latency_total / calls.len() as f64;
        let per_eval = seconds / evals as f64;
        Ok(Overhead {
            against_throughput: per_eval / bare,
            against_latency: per_eval / latency,
            bare,
            latency,
        })
    };
    let dop853 = overhead(Method::parse("dop853", 1e-10)?)?;
    let rk4 = overhead(Method::Rk4 {
        step: period / 64.0,
    })?;
    let regular: Vec<&Row> = rows
        .iter()
        .filter(|r| r.problem == "kapitza_regular")
        .collect();
    let at = |method: &str| {
        let mine: Vec<&Row> = regular
            .iter()
            .copied()
            .filter(|r| r.method == method)
            .collect();
        seconds_at(&mine, 1e-10)
    };
    let ours: Vec<(&str, f64)> = ["rk4", "gauss4", "gauss6", "dop853", "radau5"]
        .iter()
        .filter_map(|m| at(m).map(|s| (*m, s)))
        .collect();
    let (best_method, best_seconds) = ours
        .iter()
        .copied()
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .ok_or_else(|| SceneError::Numerical("no method reached 1e-10".into()))?;
    let peer = at(PEER);
    Ok(Performance {
        bare_rhs_ns: dop853.bare * 1e9,
        bare_rhs_latency_ns: dop853.latency * 1e9,
        overhead_dop853: dop853.against_throughput,
        overhead_rk4: rk4.against_throughput,
        overhead_dop853_against_latency: dop853.against_latency,
        overhead_rk4_against_latency: rk4.against_latency,
        seconds_to_1e_10: ours.iter().map(|(m, s)| (m.to_string(), *s)).collect(),
        peer_seconds_to_1e_10: peer,
        best_method_at_1e_10: best_method.to_string(),
        periods_per_second_at_1e_10: periods as f64 / best_seconds,
        speedup_over_peer_at_1e_10: peer.map(|p| p / best_seconds),
        dop853_speedup_over_peer_dop853_at_1e_10: match (peer, at("dop853")) {
            (Some(p), Some(d)) => Some(p / d),
            _ => None,
        },
    })
}
