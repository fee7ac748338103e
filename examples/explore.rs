//! Scene `explore`: any model of `models/`, by name. It integrates the exact
//! system (and the averaged one if the model has a fast phase; the
//! stick–slip integrator for a contact model) with the chosen method and
//! tolerance, and draws the time series and phase portraits per degree of
//! freedom, the period map, exact against averaged, and the energy change;
//! the equilibria of the effective potential with their stability go to the
//! summary. Every parameter of the chosen model is a knob.
//!
//! `cargo run --release --example explore -- --set model=elastic_pendulum --set k=20`

use mechlab::explore::{explore, Settings};
use mechlab::registry::Kind;
use mechlab::scene::{knob, parameter_knobs, run, Scene};
use mechlab::scenes::{method_from, method_knobs};

fn main() {
    run(|| {
        let name = Scene::peek("model").unwrap_or_else(|| "kapitza".into());
        let handle = mechlab::models::by_name(&name)?;
        let model = handle.dynamic;
        let info = model.info();
        let [method, tol] = method_knobs("dop853", "1e-10");
        let mut knobs = vec![
            knob("model", "kapitza", "the model (a file models/<name>.toml)"),
            knob("y0", "auto", "initial state, comma-separated: [q; p] or [s; s'] (auto: q = 0.3, 0.5, …, p = 0; contacts: s = 0, −0.3, …, s' = 1)"),
            knob("t_end", "20", "length of the run"),
            method,
            tol,
            knob("samples", "2000", "samples of the time series"),
            knob("periods", "300", "periods of the period map (models with a fast phase)"),
        ];
        knobs.extend(parameter_knobs(info, &[]));
        let scene = Scene::from_args(
            "explore",
            "any model by name: runs, portraits, period map, equilibria, energy",
            &knobs,
        )?;
        let params = scene.parameter_values(info)?;
        let (n, contacts) = match model.kind() {
            Kind::Hamiltonian { dof, .. } => (dof, false),
            Kind::Contacts { count } => (count, true),
        };
        let y0: Vec<f64> = match scene.text("y0") {
            "auto" if contacts => (0..n)
                .map(|i| -0.3 * i as f64)
                .chain((0..n).map(|_| 1.0))
                .collect(),
            "auto" => (0..n)
                .map(|i| 0.3 + 0.2 * i as f64)
                .chain((0..n).map(|_| 0.0))
                .collect(),
            _ => scene.numbers("y0")?,
        };
        let settings = Settings {
            method: method_from(&scene)?,
            t_end: scene.positive("t_end")?,
            samples: scene.count("samples")?,
            periods: scene.count("periods")?,
        };
        let result = explore(handle, &params, &y0, &settings)?;

        let figure = mechlab::explore::figure(&result, model, settings.t_end);
        scene.save_figure(&figure, "explore.png")?;
        let header: Vec<String> = std::iter::once("t".to_string())
            .chain((0..2 * n).map(|k| format!("exact_{k}")))
            .chain(
                (0..if result.averaged.is_some() { 2 * n } else { 0 })
                    .map(|k| format!("averaged_{k}")),
            )
            .collect();
        scene.write_csv(
            "series.csv",
            &header.iter().map(String::as_str).collect::<Vec<_>>(),
            result.times.iter().enumerate().map(|(k, t)| {
                std::iter::once(*t)
                    .chain(result.exact[k].iter().copied())
                    .chain(result.averaged.iter().flat_map(|a| a[k].iter().copied()))
                    .collect::<Vec<f64>>()
            }),
        )?;
        let names = info.coordinates;
        const PRINTED: usize = 32;
        for e in result.equilibria.iter().take(PRINTED) {
            let family: Vec<&str> = e.family_along.iter().map(|&i| names[i]).collect();
            let family = match family.is_empty() {
                true => String::new(),
                false => format!(" (a family along {}, judged reduced)", family.join(", ")),
            };
            let pole = match e.pole {
                true => " (a pole of the chart: singular only along the family)",
                false => "",
            };
            println!(
                "equilibrium q = {:?}{family}{pole}: Hessian eigenvalues {:?}: {}",
                e.q, e.hessian_eigenvalues, e.verdict
            );
        }
        if result.equilibria.len() > PRINTED {
            let more = result.equilibria.len() - PRINTED;
            println!("… and {more} more equilibria in summary.json");
        }
        if let Some(reason) = &result.equilibria_not_searched {
            println!("equilibria not searched: {reason}");
        }
        if let Some(search) = &result.equilibria_search_sampled {
            println!("equilibria searched from {search}");
        }
        for s in &result.switches {
            println!("{s}");
        }
        let max_energy = result
            .energy_change
            .iter()
            .fold(0.0f64, |m, e| m.max(e.abs()));
        println!("{}: max |change| {max_energy:.3e}", result.energy_label);
        #[derive(serde::Serialize)]
        struct Energy {
            label: &'static str,
            max_abs_change: f64,
        }
        #[derive(serde::Serialize)]
        struct Summary<'a> {
            model: &'static str,
            params: std::collections::BTreeMap<&'static str, f64>,
            y0: &'a [f64],
            final_state: Option<&'a Vec<f64>>,
            equilibria: &'a [mechlab::explore::Equilibrium],
            equilibria_not_searched: &'a Option<mechlab::explore::NotSearched>,
            #[serde(skip_serializing_if = "Option::is_none")]
            equilibria_search_sampled: Option<mechlab::analysis::equilibria::Search>,
            energy: Energy,
            switches: &'a [String],
        }
        scene.write_summary(&Summary {
            model: info.name,
            params: info
                .parameter_names
                .iter()
                .copied()
                .zip(params.iter().copied())
                .collect(),
            y0: &y0,
            final_state: result.exact.last(),
            equilibria: &result.equilibria,
            equilibria_not_searched: &result.equilibria_not_searched,
            equilibria_search_sampled: result.equilibria_search_sampled,
            energy: Energy {
                label: result.energy_label,
                max_abs_change: max_energy,
            },
            switches: &result.switches,
        })?;
        Ok(())
    });
}
