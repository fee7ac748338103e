//! The `continuation` scene.

use super::declared_scene;
use crate::scene::{knob, Scene, SceneError};
use mechlab_runtime::registry::Catalog;
use mechlab_runtime::settings::Range;

/// Scene `continuation`: the periodic orbits of a model's period map
/// followed in one parameter, their bifurcations, and the orbit diagram.
pub fn continuation_scene(catalog: Catalog) -> Result<(), SceneError> {
    use mechlab_runtime::analysis::continuation::{continuation, ContinuationOptions};
    let drawn = knob(
        "coordinate",
        "0",
        "the state component drawn (0 = first coordinate; for a constrained model, of its chart)",
    );
    let (model, scene, options) = declared_scene::<ContinuationOptions>(
        catalog,
        "continuation",
        ("duffing", None),
        (ContinuationOptions::default(), &[]),
        &[drawn],
    )?;
    let params = scene.parameter_values(model.info)?;
    let settings = options.resolve(model, &params)?;
    eprintln!("continuing in {} …", settings.parameter);
    let result = continuation(model, &params, &settings)?;
    // (A constrained model's states are its chart's coordinates.)
    let last = result.state_names.len() - 1;
    let coordinate = scene.get("coordinate", Range::Count { min: 0, max: last })?;
    write_continuation(&scene, &result, coordinate)?;
    scene.write_summary(&result)?;
    Ok(())
}

/// The `continuation` scene's figure and tables (branches, bifurcations,
/// the orbit diagram), drawn in state component `coordinate`.
fn write_continuation(
    scene: &Scene,
    result: &mechlab_runtime::analysis::continuation::Continuation,
    coordinate: usize,
) -> Result<(), SceneError> {
    scene.save_figure(&result.figure(coordinate), "continuation.png")?;
    let rows = result.branches.iter().enumerate().flat_map(|(b, branch)| {
        branch.points.iter().map(move |p| {
            let radius = mechlab_runtime::analysis::floquet::spectral_radius(&p.multipliers);
            (
                b,
                branch.period,
                p.parameter,
                p.state[coordinate],
                radius,
                p.stable,
            )
        })
    });
    scene.write_csv(
        "branches.csv",
        &[
            "branch",
            "period",
            "parameter",
            "coordinate",
            "spectral_radius",
            "stable",
        ],
        rows,
    )?;
    scene.write_csv(
        "bifurcations.csv",
        &[
            "kind",
            "branch",
            "period",
            "parameter",
            "parameter_error",
            "coordinate",
            "residual",
            "criticality",
        ],
        result.bifurcations.iter().map(|b| {
            (
                format!("{:?}", b.kind),
                b.branch,
                b.period,
                b.parameter,
                b.parameter_error.unwrap_or(f64::NAN),
                b.state[coordinate],
                b.residual,
                b.criticality.map_or(String::new(), |c| format!("{c:?}")),
            )
        }),
    )?;
    if let Some(d) = &result.diagram {
        scene.write_csv(
            "orbit_diagram.csv",
            &["parameter", "coordinate"],
            d.points.iter().map(|(p, y)| (*p, y[coordinate])),
        )?;
    }
    Ok(())
}
