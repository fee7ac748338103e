//! The worked example (`painleve_klein_impact`): the rod with exact
//! stick–slip switching from several x2(0), with its event table.

use super::{rod, worked_example_start, Params};
use crate::contact::{HybridRun, Outcome, Smooth, StickSlip};
use crate::models::painleve_klein::Contacts;
use crate::ode::{Method, System};
use crate::plot::{Figure, PanelSpec, BLACK, BLUE, RED};
use crate::studies::StudyError;

/// What the scene computes.
pub struct ImpactSettings {
    pub params: Params,
    /// x2(0) of each case (x1 = 0, x1' = x2' = 10).
    pub x2_starts: Vec<f64>,
    pub t_end: f64,
    pub method: Method,
    /// Samples per case for the figures.
    pub samples: usize,
}

/// One switch of the event table.
#[allow(non_snake_case)]
#[derive(serde::Serialize)]
pub struct Event {
    pub t: f64,
    pub point: usize,
    pub case: String,
    pub from: String,
    pub to: String,
    pub v1: f64,
    pub v2: f64,
    pub R: f64,
}

/// One initial condition: its events and how it ends.
#[derive(serde::Serialize)]
pub struct Case {
    pub x2_0: f64,
    pub delta_0: f64,
    pub events: Vec<Event>,
    /// "rest" or "sliding".
    pub r#final: &'static str,
    pub t_end: f64,
    /// The constant accelerations when sliding at the end.
    pub acceleration: Option<[f64; 2]>,
    pub final_state: [f64; 4],
    pub steps: u64,
    pub phases: usize,
    #[serde(skip)]
    pub run: HybridRun<2, 4>,
}

#[derive(serde::Serialize)]
pub struct Impact {
    pub cases: Vec<Case>,
    #[serde(skip)]
    pub params: Params,
}

/// Runs every case to `t_end` (or rest).
pub fn impact(s: &ImpactSettings) -> Result<Impact, StudyError> {
    let times: Vec<f64> = (0..=s.samples)
        .map(|i| s.t_end * i as f64 / s.samples as f64)
        .collect();
    let model = Contacts { params: s.params };
    let integrator = StickSlip::new(s.method);
    let mut cases = Vec::new();
    for (index, &x2) in s.x2_starts.iter().enumerate() {
        let y0 = worked_example_start(x2);
        let run = integrator
            .run(&model, 0.0, &y0, s.t_end, &times)
            .map_err(|source| StudyError::Case {
                index,
                value: x2,
                source,
            })?;
        let events = run
            .switches
            .iter()
            .map(|sw| Event {
                t: sw.t,
                point: sw.contact + 1,
                case: sw.case.clone(),
                from: sw.from.to_string(),
                to: sw.to.to_string(),
                v1: sw.y[2],
                v2: sw.y[3],
                R: rod(&sw.y, &s.params).reaction,
            })
            .collect();
        let (r#final, acceleration) = match run.outcome {
            Outcome::Rest => ("rest", None),
            Outcome::Moving => {
                let f = Smooth {
                    model: &model,
                    modes: run.modes,
                }
                .rhs(run.t, &run.y);
                ("sliding", Some([f[2], f[3]]))
            }
        };
        cases.push(Case {
            x2_0: x2,
            delta_0: rod(&y0, &s.params).delta,
            events,
            r#final,
            t_end: run.t,
            acceleration,
            final_state: run.y,
            steps: run.phases.iter().map(|p| p.stats.steps).sum(),
            phases: run.phases.len(),
            run,
        });
    }
    Ok(Impact {
        cases,
        params: s.params,
    })
}

fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(v), h.max(v)));
    let pad = 0.05 * (hi - lo).max(1e-9);
    (lo - pad, hi + pad)
}

impl Impact {
    /// Per case a row: the phase curve (δ, δ'), R(t), v1(t), v2(t), with
    /// the switches marked.
    pub fn figure(&self) -> Figure {
        let p = &self.params;
        let titles: Vec<String> = self
            .cases
            .iter()
            .flat_map(|c| {
                ["phase curve (δ, δ′)", "rod force R(t)", "v₁(t)", "v₂(t)"]
                    .map(|what| format!("x₂(0) = {}: {what}", c.x2_0))
            })
            .collect();
        let mut specs = Vec::new();
        for (k, c) in self.cases.iter().enumerate() {
            let samples = &c.run.samples;
            let rods: Vec<_> = samples.iter().map(|(_, y)| rod(y, p)).collect();
            let t_range = (0.0, c.run.t.max(1e-9));
            let speeds = |i: usize| range(samples.iter().map(|(_, y)| y[i]).chain([0.0]));
            let phase = (
                range(rods.iter().map(|r| r.delta)),
                range(rods.iter().map(|r| r.delta_rate)),
            );
            specs.push(PanelSpec::new(&titles[4 * k], "δ", "δ′", phase.0, phase.1));
            specs.push(PanelSpec::new(
                &titles[4 * k + 1],
                "t",
                "R",
                t_range,
                range(rods.iter().map(|r| r.reaction)),
            ));
            specs.push(PanelSpec::new(
                &titles[4 * k + 2],
                "t",
                "v₁",
                t_range,
                speeds(2),
            ));
            specs.push(PanelSpec::new(
                &titles[4 * k + 3],
                "t",
                "v₂",
                t_range,
                speeds(3),
            ));
        }
        let mut figure = Figure::grid(4, self.cases.len(), 400, 330, &specs);
        for (k, c) in self.cases.iter().enumerate() {
            let samples = &c.run.samples;
            let rods: Vec<_> = samples.iter().map(|(_, y)| rod(y, p)).collect();
            let phase: Vec<(f64, f64)> = rods.iter().map(|r| (r.delta, r.delta_rate)).collect();
            let force: Vec<(f64, f64)> = samples
                .iter()
                .zip(&rods)
                .map(|((t, _), r)| (*t, r.reaction))
                .collect();
            let speed = |i: usize| samples.iter().map(|(t, y)| (*t, y[i])).collect::<Vec<_>>();
            figure.line(4 * k, &phase, BLUE);
            figure.line(4 * k + 1, &force, BLACK);
            figure.line(4 * k + 2, &speed(2), BLUE);
            figure.line(4 * k + 3, &speed(3), RED);
            for sw in &c.run.switches {
                let r = rod(&sw.y, p);
                figure.points(4 * k, [(r.delta, r.delta_rate)], RED, 7);
                figure.points(4 * k + 1, [(sw.t, r.reaction)], RED, 7);
                figure.points(4 * k + 2, [(sw.t, sw.y[2])], RED, 7);
                figure.points(4 * k + 3, [(sw.t, sw.y[3])], RED, 7);
            }
        }
        figure
    }

    /// Rows (x2(0), t, point, case, from, to, [v1, v2, R]) of the events.
    pub fn event_rows(
        &self,
    ) -> impl Iterator<Item = (f64, f64, usize, &str, &str, &str, [f64; 3])> + '_ {
        self.cases.iter().flat_map(|c| {
            c.events.iter().map(move |e| {
                (
                    c.x2_0,
                    e.t,
                    e.point,
                    e.case.as_str(),
                    e.from.as_str(),
                    e.to.as_str(),
                    [e.v1, e.v2, e.R],
                )
            })
        })
    }

    /// Rows (x2(0), t, state, [δ, δ', R]) of the samples.
    pub fn series_rows(&self) -> impl Iterator<Item = (f64, f64, [f64; 4], [f64; 3])> + '_ {
        self.cases.iter().flat_map(move |c| {
            c.run.samples.iter().map(move |(t, y)| {
                let r = rod(y, &self.params);
                (c.x2_0, *t, *y, [r.delta, r.delta_rate, r.reaction])
            })
        })
    }
}
