//! Study 2: the double pendulum on a vertically vibrating base.
//!
//! The base moves as w = (a/ν) cos ν t, so ẇ = −a sin ν t and
//! mean(h²) = mean(sin²) = ½. The equilibria are φ1, φ2 ∈ {0, π} (angles from
//! the upward vertical). At each, with s_i = cos φ_i = ±1, the roots of
//! det(C − λA) = 0 are (docs/studies.md)
//!
//!   λ± = g (m1 + m2) / (2 m1 l1 l2) · (−S ± √R),
//!   S = s1 l2 + s2 l1,   R = l1² + l2² + 2 s1 s2 l1 l2 (m2 − m1)/(m1 + m2),
//!
//! and criterion a² > g²/(mean(h²)|λ*|) reads a*² = 4 g m1 l1 l2 / ((m1 + m2) K)
//! with K = −2 m1 l1 l2 λ*/(g (m1 + m2)) > 0: K = S − √R at (0, 0) (both
//! roots negative, the smaller in modulus), K = S + √R where s1 s2 = −1.

use super::StudyError;
use crate::analysis::averaging::{compare, time_grid};
use crate::analysis::floquet::{floquet_multipliers, monodromy, spectral_radius, stability_window};
use crate::analysis::vibrational_stability::linearization_eigenvalues;
use crate::analysis::vibrational_stability::{
    generalized_eigenvalues, stabilization, Stabilization,
};
use crate::models::double_pendulum::Averaged;
use crate::models::double_pendulum::{self as model, Exact, Params};
use crate::ode::{states_at, Integrator, Method, OdeError};
use crate::plot::{Figure, PanelSpec, BLACK, BLUE, GREY, RED};
use rayon::prelude::*;
use std::f64::consts::PI;

/// mean(h²) of the base velocity profile h = −sin.
pub const MEAN_H2: f64 = 0.5;

/// The four equilibria (φ1, φ2), upright first.
pub const EQUILIBRIA: [(f64, f64); 4] = [(0.0, 0.0), (0.0, PI), (PI, 0.0), (PI, PI)];

/// Everything criterion (11) says about one equilibrium.
#[derive(Clone, Debug)]
pub struct EquilibriumAnalysis {
    pub phi: (f64, f64),
    /// Roots of det(C − λA) = 0, ascending.
    pub lambdas: [f64; 2],
    pub stable_without_vibration: bool,
    pub stabilization: Stabilization,
}

/// Roots and verdict from the generated mass matrix and potential Hessian.
pub fn analyse_equilibrium(params: &Params, phi: (f64, f64)) -> EquilibriumAnalysis {
    let q = [phi.0, phi.1];
    let a = model::mass_matrix(&q, params);
    let c = model::potential_hessian(&q, params);
    let lambdas = generalized_eigenvalues(&a, &c).expect("the mass matrix is positive definite");
    EquilibriumAnalysis {
        phi,
        lambdas,
        stable_without_vibration: lambdas.iter().all(|l| *l > 0.0),
        stabilization: stabilization(&lambdas, params.g, MEAN_H2),
    }
}

/// The threshold a* in closed form (see the module documentation), or None
/// where the equilibrium is stable without vibration.
pub fn threshold_closed_form(params: &Params, phi: (f64, f64)) -> Option<f64> {
    let Params {
        m1, m2, l1, l2, g, ..
    } = *params;
    let (s1, s2) = (phi.0.cos().round(), phi.1.cos().round());
    let s = s1 * l2 + s2 * l1;
    let r = (l1 * l1 + l2 * l2 + 2.0 * s1 * s2 * l1 * l2 * (m2 - m1) / (m1 + m2)).sqrt();
    let k = match (s1 > 0.0, s2 > 0.0) {
        (true, true) => s - r,
        (false, false) => return None,
        _ => s + r,
    };
    Some((4.0 * g * m1 * l1 * l2 / ((m1 + m2) * k)).sqrt())
}

/// The closed form of a* at an equilibrium as (text, LaTeX), or None where
/// the equilibrium is stable without vibration.
pub fn threshold_formula(phi: (f64, f64)) -> Option<(String, String)> {
    let (s1, s2) = (phi.0.cos().round(), phi.1.cos().round());
    let sign = if s1 * s2 > 0.0 { "+" } else { "-" };
    let root = format!("sqrt(l1^2 + l2^2 {sign} 2*l1*l2*(m2 - m1)/(m1 + m2))");
    let root_tex =
        format!("\\sqrt{{l_1^2 + l_2^2 {sign} \\frac{{2 l_1 l_2 (m_2 - m_1)}}{{m_1 + m_2}}}}");
    let (k, k_tex) = match (s1 > 0.0, s2 > 0.0) {
        (true, true) => (
            format!("l1 + l2 - {root}"),
            format!("l_1 + l_2 - {root_tex}"),
        ),
        (false, false) => return None,
        (true, false) => (
            format!("l2 - l1 + {root}"),
            format!("l_2 - l_1 + {root_tex}"),
        ),
        (false, true) => (
            format!("l1 - l2 + {root}"),
            format!("l_1 - l_2 + {root_tex}"),
        ),
    };
    Some((
        format!("a* = sqrt(4*g*m1*l1*l2 / ((m1 + m2)*({k})))"),
        format!("a^* = \\sqrt{{\\frac{{4 g m_1 l_1 l_2}}{{(m_1 + m_2)\\left({k_tex}\\right)}}}}"),
    ))
}

/// Spectral radius of the exact system's monodromy matrix at an equilibrium
/// (a 2π/ν-periodic solution for every a), with its multipliers.
pub fn exact_multipliers(
    params: &Params,
    phi: (f64, f64),
    tol: f64,
) -> Result<(f64, Vec<(f64, f64)>), OdeError> {
    let mut integrator = Integrator::new(Method::parse("dop853", tol)?)?;
    let period = 2.0 * PI / params.nu;
    let y0 = [phi.0, phi.1, 0.0, 0.0];
    let (_, m) = monodromy::<_, 4, 20>(&mut integrator, &Exact { params: *params }, period, &y0)?;
    let multipliers = floquet_multipliers(&m);
    Ok((spectral_radius(&multipliers), multipliers))
}

/// The first interval of a ∈ (0, a_max] on which the exact system's
/// equilibrium is stable (all multipliers within 1 + 1e-6 of the unit
/// circle): its lower edge close to a* for large ν, its upper edge where
/// parametric resonance destabilises it again (None if beyond a_max).
pub fn exact_stability_window(
    params: &Params,
    phi: (f64, f64),
    a_max: f64,
    samples: usize,
    tol: f64,
) -> Result<Option<(f64, Option<f64>)>, OdeError> {
    let margin = |a: f64| -> Result<f64, OdeError> {
        let p = Params { a, ..*params };
        exact_multipliers(&p, phi, tol).map(|(r, _)| r - 1.0 - 1e-6)
    };
    stability_window(&margin, 0.0, a_max, samples, 1e-11 * a_max)
}

/// The pendulum's parameters from the model's `values`: masses, lengths, g
/// and ν positive, a and μ not negative.
/// The model's description (not inlined, as [`study_params`]).
#[inline(never)]
pub fn info() -> &'static crate::registry::ModelInfo {
    &model::INFO
}

#[inline(never)]
pub fn study_params(values: &[f64]) -> Result<Params, StudyError> {
    for (name, value) in Params::NAMES.iter().zip(values) {
        let fine = match *name {
            "a" | "mu" => *value >= 0.0,
            _ => *value > 0.0,
        };
        if !fine {
            return Err(StudyError::Settings {
                setting: "m1, m2, l1, l2, g, a, nu, mu",
                requirement: "masses, lengths, g and ν positive; a and μ not negative",
            });
        }
    }
    Ok(Params::from_values(values))
}

/// Limits of a set of values, widened a little (and never empty).
fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(v), h.max(v)));
    let pad = 0.05 * (hi - lo).max(1e-9);
    (lo - pad, hi + pad)
}

/// Theorem 2 on a grid of cases (`double_pendulum_averaging`): for each
/// amplitude and start, exact and limiting runs from the same (q, p).
pub struct AveragingSettings {
    pub params: Params,
    pub amplitudes: Vec<f64>,
    /// (φ1(0), φ2(0)) of each start, p(0) = 0.
    pub starts: Vec<[f64; 2]>,
    pub t_end: f64,
    pub method: Method,
}

/// One case: amplitude, start, deviations, and its series.
#[derive(Debug, serde::Serialize)]
pub struct AveragingCase {
    pub a: f64,
    pub phi0: [f64; 2],
    pub max_deviation: Vec<f64>,
    pub nu_times_max_deviation: [f64; 2],
    pub max_velocity_difference: Vec<f64>,
    #[serde(skip)]
    pub times: Vec<f64>,
    /// Per time: exact (φ1, φ2), limiting (φ1, φ2), and both systems'
    /// velocities (φ1', φ2').
    #[serde(skip)]
    pub exact: Vec<[f64; 2]>,
    #[serde(skip)]
    pub limit: Vec<[f64; 2]>,
    #[serde(skip)]
    pub exact_velocity: Vec<[f64; 2]>,
    #[serde(skip)]
    pub limit_velocity: Vec<[f64; 2]>,
}

#[derive(Debug, serde::Serialize)]
pub struct AveragingCases {
    pub nu: f64,
    pub t_end: f64,
    pub cases: Vec<AveragingCase>,
}

pub fn averaging_cases(s: &AveragingSettings) -> Result<AveragingCases, StudyError> {
    let grid = time_grid(s.t_end, 2.0 * PI / s.params.nu, 16, 2000);
    let mut cases = Vec::new();
    for &a in &s.amplitudes {
        for start in &s.starts {
            let params = Params { a, ..s.params };
            let y0 = [start[0], start[1], 0.0, 0.0];
            let c = compare(
                s.method,
                &Exact { params },
                &Averaged { params },
                &y0,
                &grid,
            )?;
            let exact_velocity: Vec<[f64; 2]> = c
                .times
                .iter()
                .zip(&c.exact)
                .map(|(t, y)| model::velocities(*t, y, &params))
                .collect();
            let limit_velocity: Vec<[f64; 2]> = c
                .averaged
                .iter()
                .map(|y| {
                    let f = model::averaged_rhs(y, &params);
                    [f[0], f[1]]
                })
                .collect();
            let deviation = c.max_deviation(0..2);
            let max_velocity_difference = (0..2)
                .map(|i| {
                    exact_velocity
                        .iter()
                        .zip(&limit_velocity)
                        .map(|(e, v)| (e[i] - v[i]).abs())
                        .fold(0.0, f64::max)
                })
                .collect();
            let angles = |ys: &[[f64; 4]]| ys.iter().map(|y| [y[0], y[1]]).collect();
            cases.push(AveragingCase {
                a,
                phi0: *start,
                nu_times_max_deviation: [deviation[0] * params.nu, deviation[1] * params.nu],
                max_deviation: deviation,
                max_velocity_difference,
                exact: angles(&c.exact),
                limit: angles(&c.averaged),
                times: c.times,
                exact_velocity,
                limit_velocity,
            });
        }
    }
    Ok(AveragingCases {
        nu: s.params.nu,
        t_end: s.t_end,
        cases,
    })
}

impl AveragingCases {
    /// Per case a row of three panels: φ of both systems, |exact − limit|,
    /// and the velocities (which differ by O(1): weak convergence only).
    pub fn figure(&self) -> Figure {
        let mut titles = Vec::new();
        for c in &self.cases {
            let case = format!(
                "a = {}, φ(0) = ({}, {}), same (q, p)",
                c.a, c.phi0[0], c.phi0[1]
            );
            titles.push(format!("{case}: φ₁, φ₂"));
            titles.push(format!("{case}: |exact − limit|"));
            titles.push(format!("{case}: velocities"));
        }
        let specs: Vec<PanelSpec> = titles
            .iter()
            .enumerate()
            .map(|(k, title)| {
                let c = &self.cases[k / 3];
                let values: Vec<f64> = match k % 3 {
                    0 => c.exact.iter().chain(&c.limit).flatten().copied().collect(),
                    1 => c.deviations().flatten().chain([0.0]).collect(),
                    _ => c
                        .exact_velocity
                        .iter()
                        .chain(&c.limit_velocity)
                        .flatten()
                        .copied()
                        .collect(),
                };
                let y_label = ["angle", "deviation", "velocity"][k % 3];
                PanelSpec::new(
                    title,
                    "t",
                    y_label,
                    (0.0, self.t_end),
                    range(values.into_iter()),
                )
            })
            .collect();
        let mut figure = Figure::grid(3, self.cases.len(), 560, 300, &specs);
        for (case, c) in self.cases.iter().enumerate() {
            let curve = |values: &dyn Fn(usize) -> f64| -> Vec<(f64, f64)> {
                c.times
                    .iter()
                    .enumerate()
                    .map(|(k, t)| (*t, values(k)))
                    .collect()
            };
            let panel = 3 * case;
            for (i, color) in [(0, BLUE), (1, RED)] {
                figure.line(panel, &curve(&|k| c.exact[k][i]), color);
                figure.line(panel, &curve(&|k| c.limit[k][i]), BLACK);
                figure.line(
                    panel + 1,
                    &curve(&|k| (c.exact[k][i] - c.limit[k][i]).abs()),
                    color,
                );
                figure.line(panel + 2, &curve(&|k| c.exact_velocity[k][i]), color);
                figure.line(panel + 2, &curve(&|k| c.limit_velocity[k][i]), BLACK);
            }
            let limit = ("limit".to_string(), BLACK);
            figure.legend(
                panel,
                &[
                    ("exact φ₁".into(), BLUE),
                    ("exact φ₂".into(), RED),
                    limit.clone(),
                ],
            );
            figure.legend(panel + 1, &[("φ₁".into(), BLUE), ("φ₂".into(), RED)]);
            figure.legend(
                panel + 2,
                &[("exact φ₁′".into(), BLUE), ("exact φ₂′".into(), RED), limit],
            );
        }
        figure
    }

    /// Rows (case, t, [φ exact, φ limit], [velocities exact, limit]).
    pub fn rows(&self) -> impl Iterator<Item = (usize, f64, [f64; 4], [f64; 4])> + '_ {
        self.cases.iter().enumerate().flat_map(|(case, c)| {
            (0..c.times.len()).map(move |k| {
                let (e, l) = (c.exact[k], c.limit[k]);
                let (ev, lv) = (c.exact_velocity[k], c.limit_velocity[k]);
                (
                    case,
                    c.times[k],
                    [e[0], e[1], l[0], l[1]],
                    [ev[0], ev[1], lv[0], lv[1]],
                )
            })
        })
    }
}

impl AveragingCase {
    fn deviations(&self) -> impl Iterator<Item = [f64; 2]> + '_ {
        self.exact
            .iter()
            .zip(&self.limit)
            .map(|(e, l)| [(e[0] - l[0]).abs(), (e[1] - l[1]).abs()])
    }
}

/// What `double_pendulum_stabilization` computes.
pub struct StabilizationSettings {
    pub params: Params,
    /// Initial distance of the long runs from the equilibrium.
    pub offset: f64,
    pub t_long: f64,
    /// The long runs use a = (1 ± margin) a*.
    pub margin: f64,
    /// The exact window is searched for a up to this × a*.
    pub a_max_factor: f64,
    pub chart_points: usize,
    pub method: Method,
}

/// What the summary says of one equilibrium (null where not applicable),
/// and, for an unstable one, what its figure panels show.
#[derive(serde::Serialize)]
pub struct EquilibriumEntry {
    pub phi1: f64,
    pub phi2: f64,
    pub lambdas: [f64; 2],
    pub stable_without_vibration: bool,
    pub a_star: Option<f64>,
    /// The threshold of the system averaged to second order in 1/ν.
    pub a_star_second_order: Option<f64>,
    pub a_star_formula: Option<String>,
    pub a_star_formula_latex: Option<String>,
    /// [lower edge, upper edge or null] of the exact system at ν.
    pub exact_window: Option<(f64, Option<f64>)>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<&'static str>,
    #[serde(skip)]
    pub panels: Option<ThresholdPanels>,
}

/// The limiting runs slightly above and below a* (φ − φ_eq against t, per
/// coordinate) and the exact spectral radius against a.
pub struct ThresholdPanels {
    pub above: Vec<Vec<(f64, f64)>>,
    pub below: Vec<Vec<(f64, f64)>>,
    pub chart: Vec<(f64, f64)>,
}

#[derive(serde::Serialize)]
pub struct StabilizationParams {
    pub m1: f64,
    pub m2: f64,
    pub l1: f64,
    pub l2: f64,
    pub g: f64,
    pub mu: f64,
}

/// Which equilibria vibration stabilises, from which amplitude on.
#[derive(serde::Serialize)]
pub struct EquilibriaStabilization {
    pub params: StabilizationParams,
    pub nu: f64,
    pub mean_h2: f64,
    pub equilibria: Vec<EquilibriumEntry>,
    #[serde(skip)]
    pub margin: f64,
    #[serde(skip)]
    pub offset: f64,
    #[serde(skip)]
    pub t_long: f64,
}

/// A long run of the limiting system at amplitude `a` from `y0`: the
/// coordinates' distances from the equilibrium against t.
fn limiting_run(
    method: Method,
    params: &Params,
    phi: (f64, f64),
    y0: &[f64; 4],
    t_long: f64,
) -> Result<Vec<Vec<(f64, f64)>>, OdeError> {
    let grid: Vec<f64> = (0..=3000).map(|i| t_long * i as f64 / 3000.0).collect();
    let system = Averaged { params: *params };
    let states = states_at(method, &system, 0.0, y0, &grid)?;
    Ok([phi.0, phi.1]
        .iter()
        .enumerate()
        .map(|(i, eq)| {
            states
                .iter()
                .zip(&grid)
                .map(|(y, t)| (*t, y[i] - eq))
                .collect()
        })
        .collect())
}

/// For every equilibrium: the roots of det(C − λA) = 0, stability without
/// vibration, a* (number and closed formula), the exact window at ν, long
/// limiting runs either side of a*, and the exact spectral radius against a.
pub fn stabilization_study(
    s: &StabilizationSettings,
    progress: &(dyn Fn(usize) + Sync),
) -> Result<EquilibriaStabilization, StudyError> {
    let params = s.params;
    let tol = s.method.accuracy();
    let mut equilibria = Vec::new();
    for (k, phi) in EQUILIBRIA.iter().enumerate() {
        let analysis = analyse_equilibrium(&params, *phi);
        let mut entry = EquilibriumEntry {
            phi1: phi.0,
            phi2: phi.1,
            lambdas: analysis.lambdas,
            stable_without_vibration: analysis.stable_without_vibration,
            a_star: None,
            a_star_second_order: None,
            a_star_formula: None,
            a_star_formula_latex: None,
            exact_window: None,
            reason: None,
            panels: None,
        };
        match analysis.stabilization {
            Stabilization::AlreadyStable => {}
            Stabilization::Degenerate => {
                entry.reason = Some("a root of det(C − λA) is zero: the criterion does not apply")
            }
            Stabilization::Threshold { a_star, .. } => {
                let (text, latex) =
                    threshold_formula(*phi).expect("unstable equilibria have a formula");
                let a_max = s.a_max_factor * a_star;
                entry.exact_window = exact_stability_window(&params, *phi, a_max, 240, tol)?;
                entry.a_star = Some(a_star);
                entry.a_star_second_order = crate::analysis::stability::averaged_stability(
                    &model::MODEL,
                    &params.values(),
                    "a",
                    &[phi.0, phi.1],
                )?
                .a_star_second_order;
                entry.a_star_formula = Some(text);
                entry.a_star_formula_latex = Some(latex);
                let y0 = [phi.0 + s.offset, phi.1 - s.offset, 0.0, 0.0];
                let at = |a: f64| Params { a, ..params };
                let above = limiting_run(
                    s.method,
                    &at((1.0 + s.margin) * a_star),
                    *phi,
                    &y0,
                    s.t_long,
                )?;
                let below = limiting_run(
                    s.method,
                    &at((1.0 - s.margin) * a_star),
                    *phi,
                    &y0,
                    s.t_long,
                )?;
                let chart = (1..=s.chart_points)
                    .into_par_iter()
                    .map(|i| {
                        let a = a_max * i as f64 / s.chart_points as f64;
                        exact_multipliers(&at(a), *phi, tol).map(|(r, _)| (a, r))
                    })
                    .collect::<Result<_, _>>()?;
                entry.panels = Some(ThresholdPanels {
                    above,
                    below,
                    chart,
                });
            }
        }
        equilibria.push(entry);
        progress(k + 1);
    }
    Ok(EquilibriaStabilization {
        params: StabilizationParams {
            m1: params.m1,
            m2: params.m2,
            l1: params.l1,
            l2: params.l2,
            g: params.g,
            mu: params.mu,
        },
        nu: params.nu,
        mean_h2: MEAN_H2,
        equilibria,
        margin: s.margin,
        offset: s.offset,
        t_long: s.t_long,
    })
}

/// "(0, π)" for an equilibrium.
fn equilibrium_name(phi1: f64, phi2: f64) -> String {
    let angle = |x: f64| if x == 0.0 { "0" } else { "π" };
    format!("({}, {})", angle(phi1), angle(phi2))
}

impl EquilibriaStabilization {
    /// Per unstable equilibrium a row: the limiting runs above and below
    /// a*, and the exact spectral radius against a with a* marked.
    pub fn figure(&self) -> Figure {
        let unstable: Vec<(&EquilibriumEntry, &ThresholdPanels, f64)> = self
            .equilibria
            .iter()
            .filter_map(|e| Some((e, e.panels.as_ref()?, e.a_star?)))
            .collect();
        let mut titles = Vec::new();
        for (e, _, a_star) in &unstable {
            let name = equilibrium_name(e.phi1, e.phi2);
            let m = self.margin;
            titles.push(format!(
                "{name} limit, a = (1 + {m}) a* = {:.3}: stays",
                (1.0 + m) * a_star
            ));
            titles.push(format!(
                "{name} limit, a = (1 − {m}) a* = {:.3}: leaves",
                (1.0 - m) * a_star
            ));
            titles.push(format!("{name} exact, ν = {}: spectral radius", self.nu));
        }
        let extent = |runs: &Vec<Vec<(f64, f64)>>| {
            let m = runs
                .iter()
                .flatten()
                .fold(self.offset.abs(), |m, (_, y)| m.max(y.abs()));
            m.min(3.5) * 1.1
        };
        let mut specs = Vec::new();
        for (p, (_, panels, _)) in unstable.iter().enumerate() {
            let (ea, eb) = (extent(&panels.above), extent(&panels.below));
            let r_max = panels
                .chart
                .iter()
                .fold(1.0f64, |m, (_, r)| m.max(*r))
                .min(3.0);
            let a_end = panels.chart.last().map_or(1.0, |c| c.0);
            let deviation = "angle − equilibrium";
            specs.push(PanelSpec::new(
                &titles[3 * p],
                "t",
                deviation,
                (0.0, self.t_long),
                (-ea, ea),
            ));
            specs.push(PanelSpec::new(
                &titles[3 * p + 1],
                "t",
                deviation,
                (0.0, self.t_long),
                (-eb, eb),
            ));
            specs.push(PanelSpec::new(
                &titles[3 * p + 2],
                "a",
                "spectral radius ρ",
                (0.0, a_end),
                (0.95, r_max * 1.02),
            ));
        }
        let mut figure = Figure::grid(3, unstable.len(), 520, 340, &specs);
        for (p, (_, panels, a_star)) in unstable.iter().enumerate() {
            for (i, color) in [(0, BLUE), (1, RED)] {
                figure.line(3 * p, &panels.above[i], color);
                figure.line(3 * p + 1, &panels.below[i], color);
            }
            let top = figure.panel(3 * p + 2).y_range.1;
            figure.line(3 * p + 2, &[(*a_star, 0.95), (*a_star, top)], GREY);
            figure.line(3 * p + 2, &panels.chart, BLACK);
            figure.points(3 * p + 2, panels.chart.iter().copied(), BLACK, 3);
            figure.legend(3 * p, &[("φ₁".into(), BLUE), ("φ₂".into(), RED)]);
            figure.legend(
                3 * p + 2,
                &[("exact".into(), BLACK), ("a* (limit)".into(), GREY)],
            );
        }
        figure
    }

    /// Rows (panel, a, spectral radius) of the exact charts.
    pub fn chart_rows(&self) -> impl Iterator<Item = (usize, f64, f64)> + '_ {
        self.equilibria
            .iter()
            .filter_map(|e| e.panels.as_ref())
            .enumerate()
            .flat_map(|(p, panels)| panels.chart.iter().map(move |(a, r)| (p, *a, *r)))
    }
}

/// What `double_pendulum_friction` computes.
pub struct FrictionSettings {
    pub params: Params,
    pub equilibrium: (f64, f64),
    /// Initial perturbation of both angles.
    pub offset: f64,
    pub t_end: f64,
    /// Frequencies for the exact multipliers.
    pub nus: Vec<f64>,
    pub method: Method,
}

/// The exact system's multipliers at one frequency.
#[derive(serde::Serialize)]
pub struct ExactMultipliers {
    pub nu: f64,
    pub spectral_radius: f64,
    /// exp(max Re λ · 2π/ν) from the averaged eigenvalues.
    pub predicted: f64,
    pub multipliers: Vec<[f64; 2]>,
}

/// Theorem 3: the stabilised equilibrium with friction, averaged and exact.
#[derive(serde::Serialize)]
pub struct Friction {
    pub equilibrium: [f64; 2],
    pub mu: f64,
    pub a: f64,
    pub nu: f64,
    pub averaged_eigenvalues: Vec<[f64; 2]>,
    pub max_real_part: f64,
    pub exact: Vec<ExactMultipliers>,
    /// (t, distance to the equilibrium) of the exact and limiting runs.
    #[serde(skip)]
    pub exact_decay: Vec<(f64, f64)>,
    #[serde(skip)]
    pub limit_decay: Vec<(f64, f64)>,
    #[serde(skip)]
    pub offset: f64,
    #[serde(skip)]
    pub t_end: f64,
}

pub fn friction(s: &FrictionSettings) -> Result<Friction, StudyError> {
    let (params, phi) = (s.params, s.equilibrium);
    let y_eq = [phi.0, phi.1, 0.0, 0.0];
    let eigenvalues = linearization_eigenvalues(&model::averaged_jacobian(&y_eq, &params));
    let max_re = eigenvalues.iter().fold(f64::MIN, |m, (re, _)| m.max(*re));
    if !max_re.is_finite() {
        return Err(StudyError::NoFiniteEigenvalues {
            equilibrium: vec![phi.0, phi.1],
        });
    }
    let y0 = [phi.0 + s.offset, phi.1 - s.offset, 0.0, 0.0];
    let grid = time_grid(s.t_end, 2.0 * PI / params.nu, 8, 2000);
    let c = compare(
        s.method,
        &Exact { params },
        &Averaged { params },
        &y0,
        &grid,
    )?;
    let distance = |ys: &[[f64; 4]]| -> Vec<(f64, f64)> {
        c.times
            .iter()
            .zip(ys)
            .map(|(t, y)| (*t, (y[0] - phi.0).hypot(y[1] - phi.1)))
            .collect()
    };
    let exact = s
        .nus
        .iter()
        .map(|&nu| {
            let (radius, multipliers) =
                exact_multipliers(&Params { nu, ..params }, phi, s.method.accuracy())?;
            Ok(ExactMultipliers {
                nu,
                spectral_radius: radius,
                predicted: (max_re * 2.0 * PI / nu).exp(),
                multipliers: multipliers.iter().map(|(re, im)| [*re, *im]).collect(),
            })
        })
        .collect::<Result<_, OdeError>>()?;
    Ok(Friction {
        equilibrium: [phi.0, phi.1],
        mu: params.mu,
        a: params.a,
        nu: params.nu,
        averaged_eigenvalues: eigenvalues.iter().map(|(re, im)| [*re, *im]).collect(),
        max_real_part: max_re,
        exact,
        exact_decay: distance(&c.exact),
        limit_decay: distance(&c.averaged),
        offset: s.offset,
        t_end: s.t_end,
    })
}

impl Friction {
    /// The decay of a perturbation in both systems (log scale) beside
    /// exp(max Re λ t), and 1 − ρ of the exact system against ν beside the
    /// averaged eigenvalues' prediction.
    pub fn figure(&self) -> Figure {
        let floor = self
            .exact_decay
            .iter()
            .chain(&self.limit_decay)
            .map(|p| p.1)
            .filter(|d| *d > 0.0)
            .fold(f64::MAX, f64::min)
            .max(1e-12);
        let title = format!("decay, μ = {}, a = {}, ν = {}", self.mu, self.a, self.nu);
        let top = 2.0 * self.offset.abs().max(1e-9) * 1.5;
        let mut decay = PanelSpec::new(
            &title,
            "t",
            "distance to the equilibrium",
            (0.0, self.t_end),
            (floor / 2.0, top),
        );
        decay.log_y = true;
        let gaps: Vec<(f64, f64)> = self
            .exact
            .iter()
            .map(|r| (r.nu, 1.0 - r.spectral_radius))
            .collect();
        let gap_max = gaps.iter().fold(0.0f64, |m, g| m.max(g.1)).max(1e-12);
        let gap_min = gaps.iter().fold(f64::MAX, |m, g| m.min(g.1)).max(1e-12);
        let nu_min = gaps.iter().fold(f64::MAX, |m, g| m.min(g.0));
        let nu_max = gaps.iter().fold(0.0f64, |m, g| m.max(g.0));
        let multipliers = PanelSpec::new(
            "exact system: 1 − spectral radius ρ",
            "ν",
            "1 − ρ",
            (nu_min / 1.3, nu_max * 1.3),
            (gap_min / 2.0, gap_max * 2.0),
        )
        .log_log();
        let mut figure = Figure::grid(2, 1, 620, 460, &[decay, multipliers]);
        let predicted: Vec<(f64, f64)> = self
            .exact_decay
            .iter()
            .map(|(t, _)| {
                (
                    *t,
                    self.offset * std::f64::consts::SQRT_2 * (self.max_real_part * t).exp(),
                )
            })
            .collect();
        figure.line(0, &self.exact_decay, BLUE);
        figure.line(0, &self.limit_decay, BLACK);
        figure.line(0, &predicted, GREY);
        figure.legend(
            0,
            &[
                ("exact".into(), BLUE),
                ("limit".into(), BLACK),
                ("exp(max Re λ · t)".into(), GREY),
            ],
        );
        let predicted_gap: Vec<(f64, f64)> = self
            .exact
            .iter()
            .map(|r| (r.nu, 1.0 - r.predicted))
            .collect();
        figure.line(1, &gaps, BLUE);
        figure.points(1, gaps.iter().copied(), BLUE, 7);
        figure.line(1, &predicted_gap, GREY);
        figure.legend(
            1,
            &[
                ("exact (Floquet)".into(), BLUE),
                ("from the averaged eigenvalues".into(), GREY),
            ],
        );
        figure
    }
}
