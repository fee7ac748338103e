//! Scene `double_pendulum_convergence` (deliverable 2.3): the deviation of
//! the exact from the limiting system is of order 1/ν.
//!
//! For a fixed observation time and ν over two decades, both systems start
//! from the same (q, p); the maximal deviation of each coordinate over the
//! time, and ν times it, are plotted against ν (log-log) with the fitted
//! exponent (−1 where Theorem 2 holds: ν × deviation levels off).

use mechlab::analysis::averaging::deviation_against_frequency;
use mechlab::models::double_pendulum::{Averaged, Exact, Params};
use mechlab::ode::Method;
use mechlab::plot::{Figure, PanelSpec, BLUE, GREY, RED};
use mechlab::scene::{knob, run, Scene};
use mechlab::studies::double_pendulum::{parameter_knobs, params_from_scene};

fn log_range(values: &[f64]) -> (f64, f64) {
    let (lo, hi) = values
        .iter()
        .fold((f64::MAX, 0.0f64), |(l, h), v| (l.min(*v), h.max(*v)));
    (lo / 1.5, hi * 1.5)
}

fn main() {
    run(|| {
        let mut knobs = parameter_knobs(&[]);
        knobs.extend([
            knob("t_obs", "5", "observation time"),
            knob("nu_min", "100", "smallest ν"),
            knob("nu_max", "10000", "largest ν"),
            knob("count", "8", "number of ν values (geometric)"),
            knob("phi1_0", "0.2", "φ1(0)"),
            knob("phi2_0", "-0.1", "φ2(0)"),
            knob("p1_0", "0", "p_φ1(0)"),
            knob("p2_0", "0", "p_φ2(0)"),
            knob("method", "dop853", "integration method"),
            knob("tol", "1e-11", "tolerance (or step for fixed-step methods)"),
        ]);
        let scene = Scene::from_args(
            "double_pendulum_convergence",
            "max |exact − limit| over a fixed time against ν: slope −1",
            &knobs,
        )?;
        let base = params_from_scene(&scene)?;
        let t_obs = scene.positive("t_obs")?;
        let (nu_min, nu_max) = (scene.positive("nu_min")?, scene.positive("nu_max")?);
        let count = scene.count("count")?.max(2);
        let y0 = [
            scene.number("phi1_0")?,
            scene.number("phi2_0")?,
            scene.number("p1_0")?,
            scene.number("p2_0")?,
        ];
        let method = Method::parse(scene.text("method"), scene.positive("tol")?)?;
        let frequencies: Vec<f64> = (0..count)
            .map(|k| nu_min * (nu_max / nu_min).powf(k as f64 / (count - 1) as f64))
            .collect();
        let systems = |nu: f64| {
            let params = Params { nu, ..base };
            (Exact { params }, Averaged { params })
        };
        eprintln!("{count} runs of both systems, ν = {nu_min} … {nu_max}");
        let result = deviation_against_frequency(method, &systems, &y0, t_obs, &frequencies, 2)?;
        let scaled: Vec<Vec<f64>> = result
            .max_deviation
            .iter()
            .map(|d| d.iter().zip(&frequencies).map(|(d, nu)| d * nu).collect())
            .collect();
        let slopes: Vec<f64> = result.fits.iter().map(|f| f.slope).collect();

        let nu_range = (nu_min / 1.3, nu_max * 1.3);
        let all_dev: Vec<f64> = result.max_deviation.concat();
        let all_scaled: Vec<f64> = scaled.concat();
        let title = format!(
            "max deviation over t ≤ {t_obs}: slopes {:.3}, {:.3}",
            slopes[0], slopes[1]
        );
        let specs = [
            PanelSpec::new(
                &title,
                "ν",
                "max |exact − limit|",
                nu_range,
                log_range(&all_dev),
            )
            .log_log(),
            PanelSpec::new(
                "ν × max deviation",
                "ν",
                "ν × deviation",
                nu_range,
                (0.0, 1.1 * all_scaled.iter().fold(0.0f64, |m, v| m.max(*v))),
            )
            .log_x(),
        ];
        let mut figure = Figure::grid(2, 1, 620, 460, &specs);
        for (i, color) in [(0, BLUE), (1, RED)] {
            let points: Vec<(f64, f64)> = frequencies
                .iter()
                .copied()
                .zip(result.max_deviation[i].iter().copied())
                .collect();
            figure.line(0, &points, color);
            figure.points(0, points.iter().copied(), color, 7);
            let fit = result.fits[i];
            let line: Vec<(f64, f64)> = [nu_min, nu_max]
                .iter()
                .map(|nu| (*nu, (fit.intercept + fit.slope * nu.ln()).exp()))
                .collect();
            figure.line(0, &line, GREY);
            let points: Vec<(f64, f64)> = frequencies
                .iter()
                .copied()
                .zip(scaled[i].iter().copied())
                .collect();
            figure.line(1, &points, color);
            figure.points(1, points.iter().copied(), color, 7);
        }
        let legend = [
            ("φ₁".to_string(), BLUE),
            ("φ₂".to_string(), RED),
            ("fitted power law".to_string(), GREY),
        ];
        figure.legend(0, &legend);
        figure.legend(1, &legend[..2]);
        scene.save_figure(&figure, "convergence.png")?;
        scene.write_csv(
            "convergence.csv",
            &[
                "nu",
                "max_dev_phi1",
                "max_dev_phi2",
                "nu_times_max_dev_phi1",
                "nu_times_max_dev_phi2",
            ],
            (0..count).map(|k| {
                (
                    frequencies[k],
                    result.max_deviation[0][k],
                    result.max_deviation[1][k],
                    scaled[0][k],
                    scaled[1][k],
                )
            }),
        )?;
        println!(
            "slopes of max deviation against ν: φ1 {:.4}, φ2 {:.4}",
            slopes[0], slopes[1]
        );
        #[derive(serde::Serialize)]
        struct Summary {
            t_obs: f64,
            nu: Vec<f64>,
            /// [coordinate][frequency]
            max_dev: Vec<Vec<f64>>,
            nu_times_max_dev: Vec<Vec<f64>>,
            slope: Vec<f64>,
        }
        scene.write_summary(&Summary {
            t_obs,
            nu: frequencies,
            max_dev: result.max_deviation,
            nu_times_max_dev: scaled,
            slope: slopes,
        })?;
        Ok(())
    });
}
