//! The deformation equation (25) (`painleve_delta`): its equilibria and
//! phase portraits without and with damping, for an example of each graph
//! class and for the given parameters.

use super::{
    class_example, reduced, DeformationEquation, DeformationEquilibrium, Params, GRAPH_CLASSES,
};
use crate::ode::{states_at, Method, OdeError};
use crate::plot::{palette, Figure, PanelSpec, BLACK, RED};

/// One portrait's equation and its equilibria.
#[derive(serde::Serialize)]
pub struct Case {
    pub case: String,
    pub x_star: f64,
    pub sigma: f64,
    pub equilibria: Vec<DeformationEquilibrium>,
}

/// One panel: its title, window in δ, rate bound, trajectories, and the
/// equilibria with Φ' > 0 (black) or not (red).
pub struct Portrait {
    pub title: String,
    pub window: (f64, f64),
    pub rate: f64,
    pub curves: Vec<Vec<(f64, f64)>>,
    pub equilibria: Vec<(f64, bool)>,
}

#[derive(serde::Serialize)]
pub struct Deformation {
    pub cases: Vec<Case>,
    #[serde(skip)]
    pub portraits: Vec<Portrait>,
}

/// Trajectories from a grid of `starts`² points over the window, cut where
/// they leave it.
fn trajectories(
    eq: &DeformationEquation,
    window: ((f64, f64), (f64, f64)),
    starts: usize,
    t_end: f64,
) -> Result<Vec<Vec<(f64, f64)>>, OdeError> {
    let ((x0, x1), (y0, y1)) = window;
    let times: Vec<f64> = (1..=400).map(|i| t_end * i as f64 / 400.0).collect();
    let mut curves = Vec::new();
    for i in 0..starts {
        for j in 0..starts {
            let start = [
                x0 + (x1 - x0) * (i as f64 + 0.5) / starts as f64,
                y0 + (y1 - y0) * (j as f64 + 0.5) / starts as f64,
            ];
            let states = states_at(Method::parse("dop853", 1e-9)?, eq, 0.0, &start, &times)?;
            let inside = |y: &[f64; 2]| {
                y[0] >= x0 - (x1 - x0)
                    && y[0] <= x1 + (x1 - x0)
                    && y[1].abs() <= 3.0 * (y1 - y0).abs()
            };
            let mut curve = vec![(start[0], start[1])];
            curve.extend(
                states
                    .iter()
                    .take_while(|y| inside(y))
                    .map(|y| (y[0], y[1])),
            );
            curves.push(curve);
        }
    }
    Ok(curves)
}

/// An example of each class (σ = 1), then the given parameters with `sigma`;
/// each drawn without damping and with the rod's ν, trajectories of
/// `t_end` (in units of ε) from `starts`² points.
pub fn deformation(
    params: &Params,
    sigma: f64,
    starts: usize,
    t_end: f64,
) -> Result<Deformation, OdeError> {
    let equation = |reduced, sigma| DeformationEquation {
        reduced,
        sigma,
        k: params.k,
        nu: params.nu,
        eps: params.eps,
    };
    let mut equations: Vec<(String, DeformationEquation)> = GRAPH_CLASSES
        .iter()
        .enumerate()
        .map(|(k, c)| {
            (
                format!("class {}", c.signs),
                equation(class_example(k), 1.0),
            )
        })
        .collect();
    equations.push((
        format!("given parameters, σ = {sigma:+}"),
        equation(reduced(params), sigma),
    ));
    let mut cases = Vec::new();
    let mut portraits = Vec::new();
    for (name, eq) in equations {
        let equilibria = eq.equilibria();
        // The window: the equilibria (or the kinks) with a margin, in δ = ε² R/k.
        let scale = eq.eps * eq.eps / eq.k;
        let kinks = [eq.reduced.y1, -eq.reduced.y2];
        let (lo, hi) = equilibria
            .iter()
            .map(|e| e.root)
            .chain(kinks)
            .fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(v), h.max(v)));
        let margin = 0.5 * (hi - lo).max(1.0);
        let window = ((lo - margin) * scale, (hi + margin) * scale);
        let rate = (window.1 - window.0) / eq.eps;
        for nu in [0.0, params.nu] {
            let system = DeformationEquation { nu, ..eq };
            portraits.push(Portrait {
                title: format!("{name}, ν = {nu}"),
                window,
                rate,
                curves: trajectories(&system, (window, (-rate, rate)), starts, t_end * params.eps)?,
                equilibria: system
                    .equilibria()
                    .iter()
                    .map(|e| (e.delta, e.slope > 0.0))
                    .collect(),
            });
        }
        cases.push(Case {
            case: name,
            x_star: eq.reduced.x_star,
            sigma: eq.sigma,
            equilibria,
        });
    }
    Ok(Deformation { cases, portraits })
}

impl Deformation {
    pub fn figure(&self) -> Figure {
        let specs: Vec<PanelSpec> = self
            .portraits
            .iter()
            .map(|p| PanelSpec::new(&p.title, "δ", "δ′", p.window, (-p.rate, p.rate)))
            .collect();
        let mut figure = Figure::grid(4, specs.len().div_ceil(4), 400, 330, &specs);
        for (k, p) in self.portraits.iter().enumerate() {
            for (c, curve) in p.curves.iter().enumerate() {
                figure.line(k, curve, palette(c % 7 + 1));
            }
            for (delta, rising) in &p.equilibria {
                figure.points(k, [(*delta, 0.0)], if *rising { BLACK } else { RED }, 9);
            }
        }
        figure
    }
}
