//! Scene `stability`: stabilisation by vibration for any model with a fast
//! phase, by name. For every equilibrium of the system without vibration
//! that stays one of the averaged system: the roots λ of det(C − λA) = 0,
//! the threshold a* of the amplitude from V + V_vibr = C + a²K (or why there
//! is none), and the exact system's stability window from its Floquet
//! multipliers, drawn as the spectral radius against the amplitude.
//!
//! `cargo run --release --example stability -- --set model=triple_pendulum`

use mechlab::analysis::stability::{stability, EquilibriumStability, Settings, Stability};
use mechlab::models;
use mechlab::ode::Method;
use mechlab::plot::{Figure, PanelSpec, BLACK, BLUE, GREY, RED};
use mechlab::registry::display_name;
use mechlab::scene::{knob, parameter_knobs, run, Scene, SceneError};

fn main() {
    run(|| {
        let name = Scene::peek("model").unwrap_or_else(|| "kapitza".into());
        let info = mechlab::registry::find(&name).ok_or_else(|| SceneError::BadValue {
            name: "model".into(),
            value: name.clone(),
            reason: format!(
                "no such model (known: {})",
                models::ALL
                    .iter()
                    .map(|m| m.name)
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        })?;
        let mut knobs = vec![
            knob("model", "kapitza", "the model (a file models/<name>.toml) with a fast phase"),
            knob("amplitude", info.amplitude.unwrap_or("(none)"), "the parameter that scales the vibration (default: the model file's [fast_phase] amplitude)"),
            knob("method", "dop853", "integration method of the monodromy matrices (dop853, taylor, ...)"),
            knob("tol", "1e-10", "its tolerance"),
            knob("samples", "40", "amplitudes sampled on (0, a_max] to bracket the exact window's edges"),
            knob("a_max", "auto", "largest amplitude of the exact window (auto: 3 a*)"),
            knob("edge_tolerance", "1e-9", "the window's edges are bisected to this"),
        ];
        knobs.extend(parameter_knobs(info, &[]));
        let scene = Scene::from_args(
            "stability",
            "stabilisation by vibration of any model's equilibria",
            &knobs,
        )?;
        let settings = Settings {
            amplitude: scene.text("amplitude").to_string(),
            a_max: match scene.text("a_max") {
                "auto" => None,
                _ => Some(scene.positive("a_max")?),
            },
            samples: scene.count("samples")?,
            edge_tolerance: scene.positive("edge_tolerance")?,
            method: Method::parse(scene.text("method"), scene.positive("tol")?)?,
        };
        let result = stability(&name, &scene.parameter_values(info)?, &settings)?;
        for q in &result.moved_by_vibration {
            eprintln!("q = {q:?}: an equilibrium without vibration that the vibration moves");
        }
        for e in &result.equilibria {
            eprintln!(
                "q = {:?}: λ = {:?}, a* = {:?} {}, exact window {:?}",
                e.q,
                e.lambdas,
                e.a_star,
                e.reason.as_deref().unwrap_or(""),
                e.exact_window
            );
        }
        let rows: Vec<(usize, f64, f64)> = result
            .equilibria
            .iter()
            .enumerate()
            .flat_map(|(k, e)| e.spectral_radius.iter().map(move |p| (k, p[0], p[1])))
            .collect();
        scene.write_csv(
            "spectral_radius.csv",
            &["equilibrium", "amplitude", "spectral_radius"],
            &rows,
        )?;
        let drawn: Vec<&EquilibriumStability> = result
            .equilibria
            .iter()
            .filter(|e| !e.spectral_radius.is_empty())
            .collect();
        if !drawn.is_empty() {
            scene.save_figure(&figure(&drawn, &result), "spectral_radius.png")?;
        }
        scene.write_summary(&result)?;
        Ok(())
    });
}

/// One panel per equilibrium with an exact window: the spectral radius of
/// the monodromy matrix against the amplitude, a* of the averaged system
/// and the window's edges.
fn figure(equilibria: &[&EquilibriumStability], result: &Stability) -> Figure {
    let info = mechlab::registry::find(&result.model).expect("the analysed model exists");
    let amplitude = display_name(&result.amplitude);
    let amplitude = amplitude.as_str();
    let titles: Vec<String> = equilibria
        .iter()
        .map(|e| {
            let at: Vec<String> = info
                .coordinates
                .iter()
                .zip(&e.q)
                .map(|(c, x)| format!("{} = {x:.3}", display_name(c)))
                .collect();
            at.join(", ")
        })
        .collect();
    // The radius is drawn up to 3 (it is ≈ 1 + growth per period).
    let top = |e: &EquilibriumStability| {
        let highest = e.spectral_radius.iter().map(|p| p[1]).fold(1.0, f64::max);
        highest.min(3.0) + 0.05
    };
    let specs: Vec<PanelSpec> = equilibria
        .iter()
        .zip(&titles)
        .map(|(e, title)| {
            let a_max = e.spectral_radius.last().map_or(1.0, |p| p[0]);
            PanelSpec::new(
                title,
                amplitude,
                "spectral radius",
                (0.0, a_max),
                (0.9, top(e)),
            )
        })
        .collect();
    let mut figure = Figure::grid(
        specs.len().min(3),
        specs.len().div_ceil(3),
        520,
        380,
        &specs,
    );
    for (k, e) in equilibria.iter().enumerate() {
        let curve: Vec<(f64, f64)> = e.spectral_radius.iter().map(|p| (p[0], p[1])).collect();
        figure.line(
            k,
            &[(0.0, 1.0), (curve.last().map_or(1.0, |p| p.0), 1.0)],
            GREY,
        );
        figure.line(k, &curve, BLUE);
        let vertical = |x: f64| [(x, 0.901), (x, top(e) - 0.001)];
        if let Some(a) = e.a_star {
            figure.line(k, &vertical(a), BLACK);
        }
        for edge in e.exact_window.iter().flatten().flatten() {
            figure.line(k, &vertical(*edge), RED);
        }
        figure.legend(
            k,
            &[
                ("exact: spectral radius".into(), BLUE),
                ("averaged: a*".into(), BLACK),
                ("exact window edges".into(), RED),
            ],
        );
    }
    figure
}
