//! The `trade` scene: the cost of an analysis against the error it states,
//! on the user's own model, over a ladder of methods and tolerances (and
//! what `accuracy`, where set, cost against the cheapest run as accurate).

use super::{declared_scene, geometric_progression};
use crate::scene::{knob, Scene, SceneError, ValueProblem};
use mechlab_runtime::analysis::declared::Analysis;
use mechlab_runtime::analysis::trade::{trade, StatedErrors};
use mechlab_runtime::registry::Catalog;
use mechlab_runtime::settings::Range;

/// The analyses whose stated errors are integration errors (or, for the
/// attractor, statistical ones), each with the model the scene defaults
/// to. The separatrix splitting's lobe area is not among them: it is
/// integrated in double-double at 10⁻³² whatever `tol`.
const ANALYSES: &[(&str, &str)] = &[
    ("stability", "triple_pendulum"),
    ("chaos_map", "kapitza"),
    ("attractor", "ueda"),
    ("continuation", "duffing"),
    ("section", "henon_heiles"),
    ("basins", "duffing"),
    ("period_map", "duffing"),
    ("averaging", "double_pendulum"),
    ("linkage", "four_bar"),
];

/// Scene `trade`: `--set analysis=…` (one of [`ANALYSES`]), its settings
/// and the model's parameters as knobs, and the ladder (`methods`,
/// `tols`).
pub fn trade_scene(catalog: Catalog) -> Result<(), SceneError> {
    use mechlab_runtime::analysis::{
        attractor::AttractorOptions, averaging::AveragingOptions, basins::BasinsOptions,
        chaos_map::ChaosMapOptions, continuation::ContinuationOptions,
        on_constraints::vibration::LinkageOptions, period_map::PeriodMapOptions,
        section::SectionOptions, stability::StabilityOptions,
    };
    let analysis = Scene::peek("analysis").unwrap_or_else(|| "stability".into());
    let Some(&(_, model)) = ANALYSES.iter().find(|(name, _)| *name == analysis) else {
        let names: Vec<&str> = ANALYSES.iter().map(|(name, _)| *name).collect();
        return Err(SceneError::BadValue {
            name: "analysis".into(),
            value: analysis,
            reason: ValueProblem::Kind {
                kind: "the name of an analysis that states its errors",
                range: format!("one of {}", names.join(", ")),
            },
        });
    };
    match analysis.as_str() {
        "stability" => trade_of::<StabilityOptions>(catalog, model),
        "chaos_map" => trade_of::<ChaosMapOptions>(catalog, model),
        "attractor" => trade_of::<AttractorOptions>(catalog, model),
        "continuation" => trade_of::<ContinuationOptions>(catalog, model),
        "basins" => trade_of::<BasinsOptions>(catalog, model),
        "period_map" => trade_of::<PeriodMapOptions>(catalog, model),
        "averaging" => trade_of::<AveragingOptions>(catalog, model),
        "linkage" => trade_of::<LinkageOptions>(catalog, model),
        _ => trade_of::<SectionOptions>(catalog, model),
    }
}

fn trade_of<T: Analysis>(catalog: Catalog, default_model: &'static str) -> Result<(), SceneError>
where
    T::Output: StatedErrors,
{
    let about = format!(
        "The trade between cost and stated error of an analysis ({}) on a model, over a ladder of methods and tolerances",
        ANALYSES.iter().map(|(name, _)| *name).collect::<Vec<_>>().join(", ")
    );
    let extra = [
        knob("analysis", "stability", "the analysis whose trade is measured"),
        knob("methods", "dop853,taylor", "the methods of the ladder (comma-separated)"),
        knob("tols", "1e-6,1e-12,4", "the ladder's tolerances (step sizes for rk4, gauss4, gauss6): first,last,count in geometric progression"),
    ];
    let (model, scene, options) = declared_scene::<T>(
        catalog,
        "trade",
        (default_model, Some(&about)),
        (T::default(), &[]),
        &extra,
    )?;
    // The section has one method of its own (DOP853 for its orbits, Taylor
    // for its maps), at one tolerance.
    let methods: Vec<String> = if !T::names().contains(&"method") {
        vec![format!("{}'s own", T::ANALYSIS)]
    } else {
        scene
            .text("methods")
            .split(',')
            .map(|m| m.trim().to_string())
            .collect()
    };
    let parts: Vec<f64> = scene.get("tols", Range::Any)?;
    let tols = geometric_progression(&parts).map_err(|requirement| SceneError::BadValue {
        name: "tols".into(),
        value: scene.text("tols").into(),
        reason: ValueProblem::Requirement(requirement),
    })?;
    let ladder: Vec<(String, f64)> = methods
        .iter()
        .flat_map(|m| tols.iter().map(move |&t| (m.clone(), three_digits(t))))
        .collect();
    let asked = T::names().contains(&"accuracy") && scene.text("accuracy") != "auto";
    let base = if asked {
        options.clone().with_texts([("accuracy", "auto")])?
    } else {
        options.clone()
    };
    let values = scene.parameter_values(model.info)?;
    eprintln!(
        "the trade of {} on {}: {} runs …",
        T::ANALYSIS,
        model.info.name,
        ladder.len() + usize::from(asked)
    );
    let result = trade(
        model,
        &values,
        &base,
        &ladder,
        asked.then_some(&options),
        &|line| eprintln!("{line}"),
    )?;
    for run in &result.runs {
        println!(
            "{:>8} tol {:<8.1e} {:>8.3} s  stated error {:.2e}  distance to the most accurate run {}",
            run.method,
            run.tol,
            run.seconds,
            run.largest_error,
            run.largest_distance.map_or("–".into(), |d| format!("{d:.2e}"))
        );
    }
    for run in &result.failed {
        println!(
            "{:>8} tol {:<8.1e} failed: {}",
            run.method, run.tol, run.error
        );
    }
    if let Some(ratio) = result.cost_ratio {
        println!("the accuracy asked cost {ratio:.2}× the cheapest run of the ladder that stated an error within it");
    }
    crate::study::write_outputs(&scene, &result)
}

/// `x` to three significant digits (a ladder's 1.0000000000000002e-8 as 1e-8).
fn three_digits(x: f64) -> f64 {
    format!("{x:.2e}").parse().unwrap_or(x)
}
