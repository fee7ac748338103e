//! Scene `painleve_delta` (deliverables 3.3, 3.4): the deformation equation
//! (25) of the sliding rod, δ'' = cos²φ0 (X* − Φ(R)), R = k ε⁻² δ + ν ε⁻¹ δ'.
//!
//! Its equilibria are δ* = ε² R*/k for every root R* of X* = Φ(R); the
//! eigenvalues of the linearisation solve λ² + c Φ' ν/ε λ + c Φ' k/ε² = 0
//! (c = cos²φ0): a saddle where Φ' < 0, a centre (ν = 0) or a stable focus
//! or node (ν > 0) where Φ' > 0. Phase portraits on (δ, δ') for an example
//! of each graph class of `painleve_phi`, first ν = 0 then ν ≠ 0, and for the
//! given parameters; equilibria marked (black: stable, red: unstable).

use mechlab::ode::{Integrator, Method};
use mechlab::plot::{palette, Figure, PanelSpec, BLACK, RED};
use mechlab::scene::{knob, run, Knob, Scene};
use mechlab::studies::painleve::{
    class_example, parameter_knobs, params_from_scene, reduced, DeformationEquation,
    DeformationEquilibrium, GRAPH_CLASSES,
};

fn knobs() -> Vec<Knob> {
    let mut knobs = parameter_knobs();
    knobs.extend([
        knob(
            "sigma",
            "1",
            "sliding direction σ = ±1 for the given parameters",
        ),
        knob(
            "starts",
            "7",
            "initial points per side of the portrait grid",
        ),
        knob("t_end", "3", "length of each trajectory, in units of ε"),
    ]);
    knobs
}

/// Trajectories of (25) from a grid of starts over the window, cut where they leave it.
fn portrait(
    eq: &DeformationEquation,
    window: ((f64, f64), (f64, f64)),
    starts: usize,
    t_end: f64,
) -> Result<Vec<Vec<(f64, f64)>>, mechlab::ode::OdeError> {
    let ((x0, x1), (y0, y1)) = window;
    let times: Vec<f64> = (1..=400).map(|i| t_end * i as f64 / 400.0).collect();
    let mut curves = Vec::new();
    for i in 0..starts {
        for j in 0..starts {
            let start = [
                x0 + (x1 - x0) * (i as f64 + 0.5) / starts as f64,
                y0 + (y1 - y0) * (j as f64 + 0.5) / starts as f64,
            ];
            let states = Integrator::new(Method::parse("dop853", 1e-9)?)?
                .advance_sampled(eq, 0.0, &start, &times)?;
            let mut curve = vec![(start[0], start[1])];
            for y in states {
                if y[0] < x0 - (x1 - x0)
                    || y[0] > x1 + (x1 - x0)
                    || y[1].abs() > 3.0 * (y1 - y0).abs()
                {
                    break;
                }
                curve.push((y[0], y[1]));
            }
            curves.push(curve);
        }
    }
    Ok(curves)
}

/// One portrait's equation and its equilibria.
#[derive(serde::Serialize)]
struct Case {
    case: String,
    x_star: f64,
    sigma: f64,
    equilibria: Vec<DeformationEquilibrium>,
}

fn main() {
    run(|| {
        let knobs = knobs();
        let scene = Scene::from_args(
            "painleve_delta",
            "equilibria of the deformation equation (25) and phase portraits",
            &knobs,
        )?;
        let params = params_from_scene(&scene)?;
        let sigma = if scene.number("sigma")? >= 0.0 {
            1.0
        } else {
            -1.0
        };
        let starts = scene.count("starts")?;
        let t_end = scene.positive("t_end")? * params.eps;

        // Cases: an example of each class, then the given parameters.
        let mut cases: Vec<(String, DeformationEquation)> = GRAPH_CLASSES
            .iter()
            .enumerate()
            .map(|(k, c)| {
                let eq = DeformationEquation {
                    reduced: class_example(k),
                    sigma: 1.0,
                    k: params.k,
                    nu: params.nu,
                    eps: params.eps,
                };
                (format!("class {}", c.signs), eq)
            })
            .collect();
        cases.push((
            format!("given parameters, σ = {sigma:+}"),
            DeformationEquation {
                reduced: reduced(&params),
                sigma,
                k: params.k,
                nu: params.nu,
                eps: params.eps,
            },
        ));

        let mut specs_titles = Vec::new();
        let mut panels = Vec::new();
        let mut summary = Vec::new();
        for (name, eq) in &cases {
            let equilibria = eq.equilibria();
            println!("{name}: X* = {:.4}", eq.reduced.x_star);
            for e in &equilibria {
                println!(
                    "  R* = {:.6}, δ* = {:.6}, Φ' = {:+.3}, eigenvalues {:?}: {}",
                    e.root,
                    e.delta,
                    e.slope,
                    e.eigenvalues,
                    if e.asymptotically_stable {
                        "asymptotically stable"
                    } else {
                        "not asymptotically stable"
                    }
                );
            }
            // The window: the equilibria (or the kinks) with a margin, in δ = ε² R/k.
            let scale = eq.eps * eq.eps / eq.k;
            let kinks = [eq.reduced.y1, -eq.reduced.y2];
            let points: Vec<f64> = equilibria.iter().map(|e| e.root).chain(kinks).collect();
            let (lo, hi) = points
                .iter()
                .fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(*v), h.max(*v)));
            let margin = 0.5 * (hi - lo).max(1.0);
            let window_x = ((lo - margin) * scale, (hi + margin) * scale);
            let rate = (window_x.1 - window_x.0) / eq.eps;
            for nu in [0.0, params.nu] {
                let system = DeformationEquation { nu, ..*eq };
                let stable: Vec<bool> = system.equilibria().iter().map(|e| e.slope > 0.0).collect();
                let curves = portrait(&system, (window_x, (-rate, rate)), starts, t_end)?;
                specs_titles.push(format!("{name}, ν = {nu}"));
                panels.push((window_x, rate, curves, system.equilibria(), stable));
            }
            summary.push(Case {
                case: name.clone(),
                x_star: eq.reduced.x_star,
                sigma: eq.sigma,
                equilibria,
            });
        }
        let specs: Vec<PanelSpec> = panels
            .iter()
            .zip(&specs_titles)
            .map(|((wx, rate, ..), title)| PanelSpec::new(title, "δ", "δ′", *wx, (-rate, *rate)))
            .collect();
        let mut figure = Figure::grid(4, panels.len().div_ceil(4), 400, 330, &specs);
        for (k, (_, _, curves, equilibria, stable)) in panels.iter().enumerate() {
            for (c, curve) in curves.iter().enumerate() {
                figure.line(k, curve, palette(c % 7 + 1));
            }
            for (e, s) in equilibria.iter().zip(stable) {
                figure.points(k, [(e.delta, 0.0)], if *s { BLACK } else { RED }, 9);
            }
        }
        scene.save_figure(&figure, "portraits.png")?;
        #[derive(serde::Serialize)]
        struct Summary {
            cases: Vec<Case>,
        }
        scene.write_summary(&Summary { cases: summary })?;
        Ok(())
    });
}
