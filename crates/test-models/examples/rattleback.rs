//! The rattleback of `test_models/rattleback.toml` (Kane and Levinson's
//! 1982 parameters) spun at 3 rad/s each way from a small pitch: spun the
//! way its pitch mode grows, it rocks, stops and spins the other way;
//! rolling does no work, so its energy stays put. Writes
//! `out/rattleback/spin.png` (yaw rate, pitch and roll against time) and
//! `spin.csv`, and prints the linear growth rates each way and the energy's
//! largest change.
//!
//! `cargo run --release -p mechlab-test-models --example rattleback`

use mechlab_runtime::analysis::declared::{no_progress, Analysis};
use mechlab_runtime::analysis::on_constraints::run;
use mechlab_runtime::analysis::on_constraints::steady::study::SteadyMotionOptions;
use mechlab_runtime::ode::Method;
use mechlab_runtime::outputs::Table;
use mechlab_runtime::plot::{Figure, PanelSpec, BLUE, RED};
use mechlab_test_models::rattleback;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let model = rattleback::MODEL.constrained.expect("a constrained model");
    let params = rattleback::Params::default().values();
    let times: Vec<f64> = (0..=2000).map(|k| 0.01 * k as f64).collect();
    let mut figure = Figure::grid(
        1,
        3,
        900,
        220,
        &[
            PanelSpec::new(
                "rattleback spun at ±3 rad/s from a pitch of 0.005",
                "t (s)",
                "yaw rate ψ' (rad/s)",
                (0.0, 20.0),
                (-3.5, 3.5),
            ),
            PanelSpec::new("", "t (s)", "pitch θ (rad)", (0.0, 20.0), (-0.05, 0.05)),
            PanelSpec::new("", "t (s)", "roll φ (rad)", (0.0, 20.0), (-0.06, 0.06)),
        ],
    );
    let mut rows = Vec::new();
    for (spin, color) in [(-3.0, RED), (3.0, BLUE)] {
        let options = SteadyMotionOptions {
            speed: Some("psi".into()),
            at: Some(spin),
            sweep: 0,
            ..Default::default()
        };
        let linear = options.run(&rattleback::MODEL, &params, &no_progress)?;
        println!("spun at {spin:+}: {}", linear.motion.verdict);
        for ((re, im), e) in linear.motion.eigenvalues.iter().zip(&linear.motion.errors) {
            println!("  eigenvalue {re:.9} {im:+.9}i ± {e:.1e}");
        }
        let mut y0 = vec![0.0; 10];
        (y0[3], y0[7]) = (0.005, spin);
        let result = run(
            model,
            &params,
            Some(&y0),
            Method::Dop853 {
                rtol: 1e-12,
                atol: 1e-12,
            },
            &times,
        )?;
        let e0 = result.energy[0];
        let drift = result
            .energy
            .iter()
            .fold(0.0_f64, |m, e| m.max((e - e0).abs()));
        println!(
            "  energy {e0:.12} J, largest change {drift:.1e} J; yaw rate at 20 s {:.4}",
            result.states.last().map_or(f64::NAN, |s| s[7])
        );
        for (k, index) in [7, 3, 4].into_iter().enumerate() {
            let series: Vec<(f64, f64)> = result
                .times
                .iter()
                .zip(&result.states)
                .map(|(&t, s)| (t, s[index]))
                .collect();
            figure.line(k, &series, color);
        }
        rows.extend(
            result
                .times
                .iter()
                .zip(&result.states)
                .map(|(&t, s)| (spin, t, s[7], s[3], s[4])),
        );
    }
    figure.legend(
        0,
        &[
            ("spun at −3 rad/s".into(), RED),
            ("spun at +3 rad/s".into(), BLUE),
        ],
    );
    let out = std::path::Path::new("out/rattleback");
    std::fs::create_dir_all(out)?;
    std::fs::write(
        out.join("spin.csv"),
        Table::new(
            "spin.csv",
            &["spin", "t", "yaw_rate", "pitch", "roll"],
            rows,
        )
        .csv,
    )?;
    figure.save(&out.join("spin.png"))?;
    println!("wrote {}/spin.png and spin.csv", out.display());
    Ok(())
}
