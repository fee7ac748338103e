//! Scene `standard_map`: the Chirikov standard map
//! (q, p) ↦ (q + p + ε sin q, p + ε sin q) on the cylinder — orbits, and a
//! chaos map in which every pixel is shaded by the fast Lyapunov indicator of
//! its orbit (dark = chaotic): the stochastic web of Study 1 (docs/studies.md).

use mechlab::analysis::lyapunov::fli_shading;
use mechlab::analysis::standard_map::{standard_map, standard_map_fli};
use mechlab::plot::{palette, ColorMap, Figure, PanelSpec};
use mechlab::scene::{knob, run, Scene};
use rayon::prelude::*;
use std::f64::consts::PI;

fn main() {
    run(|| {
        let scene = Scene::from_args(
            "standard_map",
            "orbits and FLI chaos map of the Chirikov standard map",
            &[
                knob("eps", "0.16", "map parameter ε"),
                knob("pixels", "600", "chaos map resolution (pixels per side)"),
                knob("iterations", "500", "iterations per pixel for the FLI"),
                knob("orbits", "40", "orbits in the orbit picture"),
                knob("length", "3000", "iterates per orbit"),
            ],
        )?;
        let eps = scene.number("eps")?;
        let (pixels, iterations) = (scene.count("pixels")?, scene.count("iterations")?);

        // Orbits.
        let mut figure = Figure::single(
            800,
            800,
            PanelSpec::new(
                &format!("standard map orbits, ε = {eps}"),
                "q",
                "p",
                (-PI, PI),
                (-PI, PI),
            ),
        );
        let mut rows = Vec::new();
        let count = scene.count("orbits")?;
        for k in 0..count {
            let mut x = (
                0.3 * (k as f64 * 2.399).sin() * PI,
                -PI + 2.0 * PI * (k as f64 + 0.5) / count as f64,
            );
            let mut points = Vec::new();
            for n in 0..scene.count("length")? {
                points.push(x);
                rows.push((k, n, x.0, x.1));
                x = standard_map(eps, x);
                x.1 = (x.1 + PI).rem_euclid(2.0 * PI) - PI;
            }
            figure.points(0, points, palette(k), 1);
        }
        scene.save_figure(&figure, "orbits.png")?;
        scene.write_csv("orbits.csv", &["orbit", "iterate", "q", "p"], rows)?;

        // FLI chaos map, rows in parallel (deterministic order).
        let start = std::time::Instant::now();
        let fli: Vec<f64> = (0..pixels * pixels)
            .into_par_iter()
            .map(|k| {
                let (i, j) = (k % pixels, k / pixels);
                let q = -PI + 2.0 * PI * (i as f64 + 0.5) / pixels as f64;
                let p = -PI + 2.0 * PI * (j as f64 + 0.5) / pixels as f64;
                standard_map_fli(eps, (q, p), iterations)
            })
            .collect();
        let seconds = start.elapsed().as_secs_f64();
        let shading = fli_shading(&fli, iterations);
        let (shades, low, chaotic) = (
            &shading.shades,
            shading.regular_level,
            shading.chaotic_fraction,
        );
        let mut figure = Figure::single(
            pixels + 90,
            pixels + 75,
            PanelSpec::new(
                &format!("FLI chaos map, ε = {eps}, {iterations} iterations"),
                "q",
                "p",
                (-PI, PI),
                (-PI, PI),
            ),
        );
        let label = "FLI: regular level (0) to the 99th percentile (1)";
        let mut viridis = figure.clone();
        figure.shaded_map(0, pixels, pixels, shades, ColorMap::Grey, label);
        scene.save_figure(&figure, "chaos_map.png")?;
        viridis.shaded_map(0, pixels, pixels, shades, ColorMap::Viridis, label);
        scene.save_figure(&viridis, "chaos_map_viridis.png")?;
        scene.write_csv(
            "chaos_map.csv",
            &["q", "p", "fli"],
            (0..pixels * pixels).map(|k| {
                let (i, j) = (k % pixels, k / pixels);
                (
                    -PI + 2.0 * PI * (i as f64 + 0.5) / pixels as f64,
                    -PI + 2.0 * PI * (j as f64 + 0.5) / pixels as f64,
                    fli[k],
                )
            }),
        )?;
        #[derive(serde::Serialize)]
        struct Summary {
            eps: f64,
            pixels: usize,
            iterations: usize,
            chaotic_fraction: f64,
            fli_regular_level: f64,
            seconds: f64,
        }
        scene.write_summary(&Summary {
            eps,
            pixels,
            iterations,
            chaotic_fraction: chaotic,
            fli_regular_level: low,
            seconds,
        })?;
        Ok(())
    });
}
