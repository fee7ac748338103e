//! The harness: our methods and the peer behind one `Solver`, timing, the
//! error measures, the sweeps over settings, slopes and figures.

use mechlab::contact::ContactError;
use mechlab::ode::{Integrator, Method, OdeError, System};
use mechlab::plot::{palette, Figure, PanelSpec};
use mechlab::scene::{Progress, Scene, SceneError};
use ode_solvers::{OutputType, SVector};
use std::collections::BTreeMap;
use std::hint::black_box;
use std::time::Instant;

/// Why one run failed.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    #[error(transparent)]
    Ours(#[from] OdeError),
    #[error("peer: {0}")]
    Peer(#[from] ode_solvers::dop_shared::IntegrationError),
    #[error("peer: returned no state")]
    PeerNoState,
    #[error("peer: non-finite state")]
    PeerNotFinite,
}

/// Why the benchmark stopped.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    #[error(transparent)]
    Scene(#[from] SceneError),
    #[error(transparent)]
    Run(#[from] RunError),
    #[error(transparent)]
    Ode(#[from] OdeError),
    #[error(transparent)]
    Contact(#[from] ContactError),
    #[error("no method reached the error {0:e} on the regular Kapitza orbit")]
    NotReached(f64),
}

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

pub const PEER: &str = "ode_solvers_dop853";

/// A method of ours, or the peer, with its setting.
#[derive(Clone, Copy)]
pub enum Solver {
    Ours(Method),
    Peer(f64),
}

impl Solver {
    pub fn name(&self) -> &'static str {
        match self {
            Solver::Ours(m) => m.name(),
            Solver::Peer(_) => PEER,
        }
    }
    pub fn setting(&self) -> f64 {
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
    pub fn advance<S: System<N>, const N: usize, const M: usize>(
        &self,
        integrator: &mut Option<Integrator>,
        system: &S,
        t0: f64,
        y0: &[f64; N],
        t1: f64,
    ) -> Result<([f64; N], u64), RunError> {
        match self {
            Solver::Ours(method) => {
                let integrator = match integrator {
                    Some(i) => i,
                    None => integrator.insert(Integrator::new(*method)?),
                };
                let before = integrator.stats.f_evals;
                let y = integrator.advance(system, t0, y0, t1)?;
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
                let stats = solver.integrate()?;
                let y = solver.y_out().last().ok_or(RunError::PeerNoState)?;
                let y: [f64; N] = std::array::from_fn(|i| y[i]);
                if y.iter().any(|x| !x.is_finite()) {
                    return Err(RunError::PeerNotFinite);
                }
                Ok((y, stats.num_eval as u64))
            }
        }
    }
}

/// One measured run.
#[derive(serde::Serialize)]
pub struct Row {
    pub problem: &'static str,
    pub method: &'static str,
    pub tol_or_step: f64,
    pub error: f64,
    pub seconds: f64,
    pub f_evals: u64,
}

/// A run that failed or was skipped, with the reason.
#[derive(serde::Serialize)]
pub struct Failure {
    pub problem: &'static str,
    pub method: &'static str,
    pub tol_or_step: f64,
    pub reason: String,
}

/// Fitted slope of error against f-evaluations per method (None: no line).
pub type Slopes = BTreeMap<String, Option<f64>>;

pub fn max_difference<const N: usize>(a: &[f64; N], b: &[f64; N]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// Runs `work` once, then repeats it until `min_seconds` have passed; returns
/// its result and the mean time of one run.
pub fn timed<T>(
    min_seconds: f64,
    mut work: impl FnMut() -> Result<T, RunError>,
) -> Result<(T, f64), RunError> {
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
pub enum Measure<const N: usize> {
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
pub fn end_state<S: System<N>, const N: usize, const M: usize>(
    solver: Solver,
    system: &S,
    y0: &[f64; N],
    period: f64,
    periods: usize,
) -> Result<([f64; N], u64), RunError> {
    let mut integrator = None;
    let (mut y, mut evals) = (*y0, 0);
    for _ in 0..periods {
        let (next, e) = solver.advance::<S, N, M>(&mut integrator, system, 0.0, &y, period)?;
        y = next;
        evals += e;
    }
    Ok((y, evals))
}

pub fn measure<S: System<N>, const N: usize, const M: usize>(
    solver: Solver,
    system: &S,
    y0: &[f64; N],
    how: &Measure<N>,
) -> Result<(f64, u64), RunError> {
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
pub fn reference_end<S: System<N>, const N: usize, const M: usize>(
    system: &S,
    y0: &[f64; N],
    period: f64,
    periods: usize,
    check: Method,
) -> Result<(Measure<N>, f64), BenchError> {
    let best = Solver::Ours(Method::parse("dop853", 1e-14)?);
    let (reference, _) = end_state::<S, N, M>(best, system, y0, period, periods)?;
    let (other, _) = end_state::<S, N, M>(Solver::Ours(check), system, y0, period, periods)?;
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
pub fn reference_orbit<S: System<N>, const N: usize>(
    system: &S,
    y0: &[f64; N],
    period: f64,
    periods: usize,
    check: Method,
) -> Result<(Measure<N>, f64), BenchError> {
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

pub fn solvers(fixed_steps: &[f64], stiff: bool) -> Vec<Solver> {
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
pub fn sweep<S: System<N>, const N: usize, const M: usize>(
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

/// Least-squares slope of log(error) against log(cost), over the points
/// above the method's round-off floor (10× its smallest error) and below 1e-2;
/// none if they do not lie on a line (r² < 0.9).
pub fn slope(points: &[(f64, f64)]) -> Option<f64> {
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
pub fn seconds_at(rows: &[&Row], target: f64) -> Option<f64> {
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

pub const METHODS: [&str; 8] = [
    "rk4",
    "gauss4",
    "gauss6",
    "dop853",
    "radau5",
    PEER,
    "taylor",
    "taylor_lanes",
];

/// Time of method `slow` over time of method `fast` at equal error, per
/// problem with runs of both and target error (log-log interpolated along
/// each method's runs).
pub fn speedups(
    rows: &[Row],
    problems: &[&str],
    (slow, fast): (&str, &str),
) -> BTreeMap<String, BTreeMap<String, Option<f64>>> {
    let mut out = BTreeMap::new();
    for &problem in problems {
        let of = |method: &str| -> Vec<&Row> {
            rows.iter()
                .filter(|r| r.problem == problem && r.method == method)
                .collect()
        };
        let (dop, taylor) = (of(slow), of(fast));
        if dop.is_empty() || taylor.is_empty() {
            continue;
        }
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

pub fn plot_problem(scene: &Scene, problem: &str, rows: &[&Row]) -> Result<Slopes, SceneError> {
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
