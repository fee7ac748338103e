//! The brute-force orbit diagram (the attractor of the period map against
//! the parameter, each value from the same start, on all cores and in the
//! batch lanes) and the figure of a continuation.

use super::{BifurcationKind, Continuation, DiagramSettings, FamilyMap};
use crate::analysis::period_map::stream_orbit;
use crate::ode::{AnySystem, Integrator, Method, OdeError};
use crate::plot::{palette, Figure, PanelSpec, Rgb};
use rayon::prelude::*;

/// The orbit diagram: for each parameter value, the iterates of the map
/// after a transient.
#[derive(Clone, Debug, serde::Serialize)]
pub struct OrbitDiagram {
    pub values: usize,
    pub transient: usize,
    pub iterates: usize,
    /// Parameter values whose orbit failed (diverged): left blank.
    pub failed: usize,
    pub seconds: f64,
    /// (parameter, state) of every drawn iterate.
    #[serde(skip)]
    pub points: Vec<(f64, Vec<f64>)>,
}

/// Parameter values evenly over `bounds`, each orbit from `start`.
pub(super) fn orbit_diagram(
    map: &dyn FamilyMap,
    bounds: (f64, f64),
    start: &[f64],
    settings: &DiagramSettings,
) -> OrbitDiagram {
    let clock = std::time::Instant::now();
    let n = settings.values.max(2);
    let values: Vec<f64> = (0..n)
        .map(|i| bounds.0 + (bounds.1 - bounds.0) * i as f64 / (n - 1) as f64)
        .collect();
    let orbits = map.diagram(&values, start, settings.transient, settings.iterates);
    let mut points = Vec::with_capacity(n * settings.iterates);
    let mut failed = 0;
    for (p, orbit) in values.iter().zip(orbits) {
        match orbit {
            Ok(states) => points.extend(states.into_iter().map(|y| (*p, y))),
            Err(_) => failed += 1,
        }
    }
    OrbitDiagram {
        values: n,
        transient: settings.transient,
        iterates: settings.iterates,
        failed,
        seconds: clock.elapsed().as_secs_f64(),
        points,
    }
}

/// Orbits of the period map of each (system, period), from `start`: the
/// `iterates` states after `transient` periods, angles wrapped, on all
/// cores. (The batch lanes would be 2–3× faster, but their instances for
/// the plain field at every size cost the runtime's compile more than the
/// diagram's seconds are worth.)
pub(super) fn iterates(
    method: Method,
    problems: &[(Box<dyn AnySystem>, Result<f64, OdeError>)],
    start: &[f64],
    wrap: &[bool],
    transient: usize,
    iterates: usize,
) -> Vec<Result<Vec<Vec<f64>>, OdeError>> {
    problems
        .par_iter()
        .map(|(system, period)| {
            let period = period.clone()?;
            let mut integrator = Integrator::new(method)?;
            // The start, then one point a period (angles in [−π, π)).
            let (mut seen, mut states) = (0, Vec::with_capacity(iterates));
            let mut keep = |y: &[f64]| {
                if seen > transient {
                    states.push(y.to_vec());
                }
                seen += 1;
                true
            };
            let periods = transient + iterates;
            stream_orbit(
                &mut integrator,
                &**system,
                period,
                start,
                periods,
                wrap,
                &mut keep,
            )?;
            Ok(states)
        })
        .collect()
}

impl Continuation {
    /// Three panels: the branches (a coordinate of every point of the
    /// cycle against the parameter; stable solid, unstable dashed;
    /// bifurcations marked), the orbit diagram on the same axes, and the
    /// multipliers of every branch point with the unit circle.
    pub fn figure(&self, coordinate: usize) -> Figure {
        let name = |i: usize| {
            crate::registry::display_name(self.state_names.get(i).copied().unwrap_or("y"))
        };
        let parameter = crate::registry::display_name(&self.parameter);
        let coordinate_name = name(coordinate);
        let x_range = (self.from.min(self.to), self.from.max(self.to));
        let y_range = self.coordinate_range(coordinate);
        let branches_title = format!("{} branches of periodic orbits", self.branches.len());
        let diagram_title = match self.flow {
            true => "no period map: no orbit diagram".to_string(),
            false => "orbit diagram (attractor of P)".to_string(),
        };
        let mut figure = Figure::grid(
            3,
            1,
            560,
            460,
            &[
                PanelSpec::new(
                    &branches_title,
                    &parameter,
                    &coordinate_name,
                    x_range,
                    y_range,
                ),
                PanelSpec::new(
                    &diagram_title,
                    &parameter,
                    &coordinate_name,
                    x_range,
                    y_range,
                ),
                PanelSpec::new(
                    if self.flow {
                        "eigenvalues of the Jacobian along the branches"
                    } else {
                        "Floquet multipliers of P^k along the branches"
                    },
                    "Re λ",
                    "Im λ",
                    (-2.5, 2.5),
                    (-2.0, 2.0),
                ),
            ],
        );
        self.draw_branches(&mut figure, coordinate);
        // Where stability is lost: the unit circle for multipliers, the
        // imaginary axis for eigenvalues.
        let edge: Vec<(f64, f64)> = match self.flow {
            true => vec![(0.0, -2.0), (0.0, 2.0)],
            false => (0..=200)
                .map(|i| {
                    let a = std::f64::consts::TAU * i as f64 / 200.0;
                    (a.cos(), a.sin())
                })
                .collect(),
        };
        figure.line(2, &edge, Rgb(120, 120, 120));
        self.mark_bifurcations(&mut figure, coordinate);
        if let Some(d) = &self.diagram {
            figure.points(
                1,
                d.points.iter().map(|(p, y)| (*p, y[coordinate])),
                Rgb(20, 20, 60),
                1,
            );
        }
        figure
    }

    /// The range of state component `coordinate` over the branches and
    /// the orbit diagram, padded by 5 %.
    fn coordinate_range(&self, coordinate: usize) -> (f64, f64) {
        let mut values: Vec<f64> = self
            .branches
            .iter()
            .flat_map(|b| {
                b.points
                    .iter()
                    .flat_map(|p| p.cycle.iter().map(|y| y[coordinate]))
            })
            .collect();
        if let Some(d) = &self.diagram {
            values.extend(d.points.iter().map(|(_, y)| y[coordinate]));
        }
        let (lo, hi) = values
            .iter()
            .filter(|v| v.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            });
        let pad = 0.05 * (hi - lo).max(1e-3);
        (lo - pad, hi + pad)
    }

    /// Each branch in its colour: every point of its cycle against the
    /// parameter (stable runs solid, unstable dashed) in panel 0, its
    /// multipliers in panel 2.
    fn draw_branches(&self, figure: &mut Figure, coordinate: usize) {
        for (b, branch) in self.branches.iter().enumerate() {
            let color = palette(b);
            // Each point of the cycle is a curve; stable runs solid,
            // unstable dashed.
            for j in 0..branch.period {
                let mut run: Vec<(f64, f64)> = Vec::new();
                let mut stable = None;
                for point in &branch.points {
                    let xy = (
                        point.parameter,
                        point.cycle.get(j).map_or(f64::NAN, |y| y[coordinate]),
                    );
                    if stable.is_some_and(|s| s != point.stable) {
                        run.push(xy);
                        draw_run(figure, &run, stable == Some(true), color);
                        run.clear();
                    }
                    stable = Some(point.stable);
                    run.push(xy);
                }
                draw_run(figure, &run, stable == Some(true), color);
            }
            figure.points(
                2,
                branch
                    .points
                    .iter()
                    .flat_map(|p| p.multipliers.iter().copied()),
                color,
                2,
            );
        }
    }

    /// The bifurcations of each kind marked on panel 0, with the legend.
    fn mark_bifurcations(&self, figure: &mut Figure, coordinate: usize) {
        let mut legend = Vec::new();
        for (kind, label, color) in KINDS {
            let marks: Vec<(f64, f64)> = self
                .bifurcations
                .iter()
                .filter(|b| b.kind == kind)
                .map(|b| (b.parameter, b.state[coordinate]))
                .collect();
            if !marks.is_empty() {
                figure.points(0, marks, color, 7);
                legend.push((
                    format!(
                        "{label} ({})",
                        self.bifurcations.iter().filter(|b| b.kind == kind).count()
                    ),
                    color,
                ));
            }
        }
        legend.push(("stable solid, unstable dashed".into(), Rgb(90, 90, 90)));
        figure.legend(0, &legend);
    }
}

const KINDS: [(BifurcationKind, &str, Rgb); 5] = [
    (BifurcationKind::Fold, "fold", Rgb(214, 39, 40)),
    (
        BifurcationKind::BranchPoint,
        "branch point",
        Rgb(44, 160, 44),
    ),
    (
        BifurcationKind::PeriodDoubling,
        "period doubling",
        Rgb(0, 0, 0),
    ),
    (
        BifurcationKind::NeimarkSacker,
        "Neimark–Sacker",
        Rgb(148, 103, 189),
    ),
    (BifurcationKind::Hopf, "Hopf", Rgb(148, 103, 189)),
];

fn draw_run(figure: &mut Figure, run: &[(f64, f64)], stable: bool, color: Rgb) {
    if run.len() < 2 {
        return;
    }
    if stable {
        figure.line(0, run, color);
    } else {
        figure.dashed_line(0, run, color);
    }
}
