//! The tippe top of `test_models/tippe_top.toml` spun at 150 rad/s from a
//! tilt of 0.1 rad, for three ratios of its moments of inertia I1/I3: below
//! Hugenholtz's range (1 − a/R, 1 + a/R) it stays up; inside it, it turns
//! over onto its stem; above it, it ends tilted. Writes
//! `out/tippe_top/turning.png` (the axis's height k_z and the spin about
//! the vertical ω_z against time) and `turning.csv`, and prints each run's
//! end state and the energy the friction took.
//!
//! `cargo run --release -p mechlab-test-models --example tippe_top`

use mechlab_runtime::analysis::on_constraints::run;
use mechlab_runtime::ode::Method;
use mechlab_runtime::outputs::Table;
use mechlab_runtime::plot::{Figure, PanelSpec, BLACK, BLUE, RED};
use mechlab_test_models::tippe_top;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let times: Vec<f64> = (0..=4000).map(|k| 0.005 * k as f64).collect();
    let mut figure = Figure::grid(
        1,
        2,
        900,
        260,
        &[
            PanelSpec::new(
                "tippe top spun at 150 rad/s: the symmetry axis's height",
                "t (s)",
                "k_z = cos θ",
                (0.0, 20.0),
                (-1.05, 1.05),
            ),
            PanelSpec::new(
                "",
                "t (s)",
                "spin about the vertical ω_z (rad/s)",
                (0.0, 20.0),
                (50.0, 160.0),
            ),
        ],
    );
    let (mut legend, mut rows) = (Vec::new(), Vec::new());
    for (ratio, color) in [(0.5, BLACK), (0.889, BLUE), (1.35, RED)] {
        let mut params = tippe_top::Params::default();
        params.set("I1", ratio * params.get("I3").unwrap())?;
        let method = Method::Dop853 {
            rtol: 1e-12,
            atol: 1e-12,
        };
        let model = tippe_top::MODEL.constrained.expect("a constrained model");
        let result = run(model, &params.values(), None, method, &times)?;
        // The symmetry axis's height and ω_z = 2 (e0 e3' − e3 e0' + e1 e2' − e2 e1').
        let axis = |s: &[f64]| s[2] * s[2] - s[3] * s[3] - s[4] * s[4] + s[5] * s[5];
        let spin = |s: &[f64]| 2.0 * (s[2] * s[11] - s[5] * s[8] + s[3] * s[10] - s[4] * s[9]);
        let t = &result.times;
        figure.line(
            0,
            &t.iter()
                .zip(&result.states)
                .map(|(&t, s)| (t, axis(s)))
                .collect::<Vec<_>>(),
            color,
        );
        figure.line(
            1,
            &t.iter()
                .zip(&result.states)
                .map(|(&t, s)| (t, spin(s)))
                .collect::<Vec<_>>(),
            color,
        );
        let end = result.states.last().expect("a run");
        println!(
            "I1/I3 = {ratio}: ends at k_z {:.9}, ω_z {:.9} rad/s; energy {:.6e} → {:.6e} J; {} steps",
            axis(end), spin(end), result.energy[0], result.energy.last().unwrap(), result.steps
        );
        legend.push((format!("I1/I3 = {ratio}"), color));
        rows.extend(
            t.iter()
                .zip(&result.states)
                .map(|(&t, s)| (ratio, t, axis(s), spin(s))),
        );
    }
    figure.legend(0, &legend);
    let out = std::path::Path::new("out/tippe_top");
    std::fs::create_dir_all(out)?;
    let table = Table::new("turning.csv", &["I1_over_I3", "t", "k_z", "omega_z"], rows);
    std::fs::write(out.join("turning.csv"), table.csv)?;
    figure.save(&out.join("turning.png"))?;
    println!("wrote {}/turning.png and turning.csv", out.display());
    Ok(())
}
