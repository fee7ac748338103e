//! The worked example as the rod stiffens (`painleve_stiff_limit`): both
//! cases start from the worked example's rod force (δ(0) ∝ ε²); R(t)
//! settles to the rigid rod's R* within O(ε) time, and the friction impact
//! sharpens.

use super::{phi_slope, reduced, rigid_rod_roots, rod, Params};
use crate::contact::{HybridRun, StickSlip};
use crate::models::painleve_klein::Contacts;
use crate::ode::Method;
use crate::plot::{palette, Figure, PanelSpec, GREY};
use crate::studies::StudyError;
use std::time::Instant;

pub struct StiffLimitSettings {
    pub eps_values: Vec<f64>,
    /// x2(0) of the regular and the impact case at ε = 0.1.
    pub x2_regular: f64,
    pub x2_impact: f64,
    pub t_end: f64,
    pub method: Method,
}

#[derive(serde::Serialize)]
pub struct Event {
    pub t: f64,
    pub point: usize,
    pub case: String,
}

/// One run: case, ε, how it ended, its cost and its events.
#[allow(non_snake_case)]
#[derive(serde::Serialize)]
pub struct Run {
    pub case: &'static str,
    pub eps: f64,
    pub outcome: String,
    pub t_end: f64,
    pub final_R: f64,
    pub steps: u64,
    pub f_evals: u64,
    pub seconds: f64,
    pub events: Vec<Event>,
    #[serde(skip)]
    pub run: HybridRun<2, 4>,
    #[serde(skip)]
    pub params: Params,
}

#[allow(non_snake_case)]
#[derive(serde::Serialize)]
pub struct StiffLimit {
    pub rigid_R_star: Option<f64>,
    pub runs: Vec<Run>,
    #[serde(skip)]
    pub eps_values: Vec<f64>,
}

/// The start with the worked example's rod length at ε = 0.1, the
/// deformation scaled by ε².
fn start(base: &Params, x2_ref: f64, eps: f64) -> [f64; 4] {
    let delta_ref = x2_ref.hypot(base.d) - base.l;
    let delta = delta_ref * (eps / 0.1).powi(2);
    let x2 = -((base.l + delta).powi(2) - base.d * base.d).sqrt();
    [0.0, x2, 10.0, 10.0]
}

pub fn stiff_limit(s: &StiffLimitSettings) -> Result<StiffLimit, StudyError> {
    let base = Params::default();
    let q = reduced(&base);
    let rigid_r_star = rigid_rod_roots(1.0, &q)
        .into_iter()
        .find(|r| phi_slope(*r, 1.0, &q) > 0.0);
    let times: Vec<f64> = (0..=3000).map(|i| s.t_end * i as f64 / 3000.0).collect();
    let mut runs = Vec::new();
    for (case, x2_ref) in [("regular", s.x2_regular), ("impact", s.x2_impact)] {
        for (index, &eps) in s.eps_values.iter().enumerate() {
            let params = Params { eps, ..base };
            let y0 = start(&base, x2_ref, eps);
            let clock = Instant::now();
            let run = StickSlip::new(s.method)
                .run(&Contacts { params }, 0.0, &y0, s.t_end, &times)
                .map_err(|source| StudyError::Case {
                    index,
                    value: eps,
                    source,
                })?;
            runs.push(Run {
                case,
                eps,
                outcome: format!("{:?}", run.outcome),
                t_end: run.t,
                final_R: rod(&run.y, &params).reaction,
                steps: run.phases.iter().map(|p| p.stats.steps).sum(),
                f_evals: run.phases.iter().map(|p| p.stats.f_evals).sum(),
                seconds: clock.elapsed().as_secs_f64(),
                events: run
                    .switches
                    .iter()
                    .map(|sw| Event {
                        t: sw.t,
                        point: sw.contact + 1,
                        case: sw.case.clone(),
                    })
                    .collect(),
                run,
                params,
            });
        }
    }
    Ok(StiffLimit {
        rigid_R_star: rigid_r_star,
        runs,
        eps_values: s.eps_values.clone(),
    })
}

impl StiffLimit {
    /// R against the fast time τ = t/ε (regular case), εR against τ (the
    /// impact force grows like 1/ε), and the impact's switch times against ε.
    pub fn figure(&self) -> Figure {
        let tau_regular = 30.0;
        let impact = || self.runs.iter().filter(|r| r.case == "impact");
        let tau_impact = impact().fold(1.0f64, |m, r| m.max(r.run.t / r.eps));
        let scaled_force = |case: &str| {
            self.runs
                .iter()
                .filter(|r| r.case == case)
                .flat_map(|r| {
                    let factor = if case == "impact" { r.eps } else { 1.0 };
                    r.run
                        .samples
                        .iter()
                        .map(move |(_, y)| factor * rod(y, &r.params).reaction)
                })
                .fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(v), h.max(v)))
        };
        let (lo_r, hi_r) = scaled_force("regular");
        let (lo_i, hi_i) = scaled_force("impact");
        let all_times: Vec<f64> = self
            .runs
            .iter()
            .flat_map(|r| r.events.iter().map(|e| e.t))
            .collect();
        let t_lo = all_times.iter().fold(f64::MAX, |m, t| m.min(*t)).max(1e-9);
        let t_hi = all_times
            .iter()
            .fold(0.0f64, |m, t| m.max(*t))
            .max(2.0 * t_lo);
        let eps_lo = self.eps_values.iter().fold(f64::MAX, |m, e| m.min(*e));
        let eps_hi = self.eps_values.iter().fold(0.0f64, |m, e| m.max(*e));
        let specs = [
            PanelSpec::new(
                "regular: R against t/ε",
                "t/ε",
                "R",
                (0.0, tau_regular),
                (lo_r.min(hi_r - 0.1), hi_r),
            ),
            PanelSpec::new(
                "impact: εR against t/ε",
                "t/ε",
                "εR",
                (0.0, tau_impact),
                (lo_i, hi_i * 1.05),
            ),
            PanelSpec::new(
                "impact: switch times against ε",
                "ε",
                "t",
                (eps_lo / 1.5, eps_hi * 1.5),
                (t_lo / 1.5, t_hi * 1.5),
            )
            .log_log(),
        ];
        let mut figure = Figure::grid(3, 1, 560, 440, &specs);
        let mut legend = Vec::new();
        for r in &self.runs {
            let is_impact = r.case == "impact";
            let k = usize::from(is_impact);
            let factor = if is_impact { r.eps } else { 1.0 };
            let color = palette(
                self.eps_values
                    .iter()
                    .position(|e| *e == r.eps)
                    .unwrap_or(0),
            );
            let force = |t: f64, y: &[f64; 4]| (t / r.eps, factor * rod(y, &r.params).reaction);
            let curve: Vec<(f64, f64)> = r.run.samples.iter().map(|(t, y)| force(*t, y)).collect();
            figure.line(k, &curve, color);
            for sw in &r.run.switches {
                figure.points(k, [force(sw.t, &sw.y)], color, 7);
                if is_impact {
                    figure.points(2, [(r.eps, sw.t)], color, 7);
                }
            }
            if !is_impact {
                legend.push((format!("ε = {}", r.eps), color));
            }
        }
        if let Some(r) = self.rigid_R_star {
            figure.line(0, &[(0.0, r), (tau_regular, r)], GREY);
            legend.push(("rigid rod R*".into(), GREY));
        }
        figure.legend(0, &legend);
        figure.legend(1, &legend[..self.eps_values.len().min(legend.len())]);
        figure
    }

    /// Rows (case, ε, outcome, t_end, final R, steps, f-evaluations, seconds).
    pub fn rows(&self) -> impl Iterator<Item = (&str, f64, &str, f64, f64, u64, u64, f64)> + '_ {
        self.runs.iter().map(|r| {
            (
                r.case,
                r.eps,
                r.outcome.as_str(),
                r.t_end,
                r.final_R,
                r.steps,
                r.f_evals,
                r.seconds,
            )
        })
    }
}
