//! The bicycle benchmark: the Whipple–Carvallo bicycle of
//! `test_models/whipple_bicycle.toml` (four rigid bodies, derived by
//! mechlab) linearised about its upright straight-ahead motion at speeds
//! 0 to 10 m/s: its eigenvalues against the speed and the weave and
//! capsize speeds, beside the published benchmark of Meijaard et al.
//! (2007). Writes `out/bicycle/eigenvalues.png`, `eigenvalues.csv`.
//!
//! `cargo run --release -p mechlab-test-models --example bicycle`

use mechlab_runtime::analysis::on_constraints::steady::{speed_sweep, SteadySettings};
use mechlab_runtime::outputs::Table;
use mechlab_test_models::whipple_bicycle as bicycle;

/// Meijaard et al. (2007), §5: the weave and capsize speeds.
const PUBLISHED: [(&str, f64); 2] = [("weave", 4.29238253634111), ("capsize", 6.02426201538837)];

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let model = bicycle::MODEL.constrained.expect("a constrained model");
    let defaults = bicycle::Params::default();
    let names = model.info().coordinates;
    let index = |name: &str| names.iter().position(|c| *c == name).expect("a coordinate");
    let q = vec![0.0; names.len()];
    let shape = [index("phi"), index("delta")];
    // Forward speed v: the rear wheel turns at v / rR.
    let held = [(index("thetaR"), 1.0 / defaults.get("rR").expect("rR"))];
    let speeds: Vec<f64> = (0..=200).map(|k| 0.05 * k as f64).collect();
    let settings = SteadySettings {
        q: &q,
        shape: &shape,
        held: &held,
    };
    let sweep = speed_sweep(model, &defaults.values(), &settings, &speeds)?;

    println!("boundary   mechlab (m/s)       published (m/s)     difference");
    for (boundary, (name, published)) in sweep.boundaries.iter().zip(PUBLISHED) {
        let v = boundary.speed;
        println!(
            "{name:<10} {v:<19.14} {published:<19.14} {:.1e}",
            v - published
        );
    }
    let out = std::path::Path::new("out/bicycle");
    std::fs::create_dir_all(out)?;
    let rows = sweep
        .speeds
        .iter()
        .zip(&sweep.eigenvalues)
        .flat_map(|(&v, values)| values.iter().map(move |&(re, im)| (v, re, im)));
    std::fs::write(
        out.join("eigenvalues.csv"),
        Table::new("eigenvalues.csv", &["speed", "re", "im"], rows).csv,
    )?;
    sweep
        .figure(
            "Whipple bicycle (benchmark parameters): linearised eigenvalues",
            "forward speed v (m/s)",
        )
        .save(&out.join("eigenvalues.png"))?;
    println!(
        "wrote {}/eigenvalues.png and eigenvalues.csv",
        out.display()
    );
    Ok(())
}
