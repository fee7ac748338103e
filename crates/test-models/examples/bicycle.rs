//! The bicycle benchmark: the Whipple–Carvallo bicycle of
//! `test_models/whipple_bicycle.toml` (four rigid bodies, derived by
//! mechlab) linearised by name (`steady_motion`, which finds its speed,
//! lean and steer itself) about its upright straight-ahead motion at
//! 5 m/s and at speeds 0 to 10 m/s: its eigenvalues against the speed and
//! the weave and capsize speeds, each with its error, beside the published
//! benchmark of Meijaard et al. (2007). Writes `out/bicycle/`
//! (`eigenvalues.png`, `eigenvalues.csv`, `linearisation.csv`,
//! `summary.json`).
//!
//! `cargo run --release -p mechlab-test-models --example bicycle`

use mechlab_runtime::analysis::declared::{no_progress, Analysis};
use mechlab_runtime::analysis::on_constraints::steady::study::SteadyMotionOptions;
use mechlab_runtime::outputs::Outputs;
use mechlab_test_models::whipple_bicycle as bicycle;

/// Meijaard et al. (2007), §5: the weave and capsize speeds.
const PUBLISHED: [(&str, f64); 2] = [("weave", 4.29238253634111), ("capsize", 6.02426201538837)];

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let options = SteadyMotionOptions {
        at: Some(5.0),
        sweep: 201,
        sweep_range: Some([0.0, 10.0]),
        ..Default::default()
    };
    let values = bicycle::Params::default().values();
    let study = options.run(&bicycle::MODEL, &values, &no_progress)?;
    for line in study.lines() {
        println!("{line}");
    }
    let boundaries = study.sweep.as_ref().map_or(&[][..], |s| &s.boundaries[..]);
    println!("boundary   mechlab (m/s)       published (m/s)     difference  stated error");
    for (boundary, (name, published)) in boundaries.iter().zip(PUBLISHED) {
        let v = boundary.speed;
        let (missed, error) = (v - published, boundary.error);
        println!("{name:<10} {v:<19.14} {published:<19.14} {missed:<11.1e} {error:.1e}");
    }
    let out = std::path::Path::new("out/bicycle");
    std::fs::create_dir_all(out)?;
    for table in study.tables() {
        std::fs::write(out.join(&table.file), table.csv)?;
    }
    for (file, figure) in study.figures() {
        figure.save(&out.join(file))?;
    }
    std::fs::write(
        out.join("summary.json"),
        serde_json::to_string_pretty(&study)?,
    )?;
    println!("wrote {}/", out.display());
    Ok(())
}
