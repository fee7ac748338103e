//! Scene `painleve_phi` (deliverables 3.1, 3.2): the broken line
//! Φ(R) = 2R + σ(μ1*|R − Y1*| − μ2*|R + Y2*|) of the rigid Painlevé–Klein rod.
//!
//! Every qualitatively different graph (by the signs of its three slopes) is
//! drawn for an example, with the region of (μ1*, μ2*, Y1*, Y2*, σ) where
//! it occurs as inequalities (Δ = μ2* − μ1*, S = μ1* + μ2*, o = +1 if
//! Y1* < −Y2*) and as region plots in the (μ1*, μ2*) plane for σo = +1 and
//! σo = −1. For the given parameters, every root R* of X* = Φ(R) for σ = ±1
//! with its Painlevé case.

use mechlab::plot::{palette, Figure, PanelSpec, BLACK, GREY, RED};
use mechlab::scene::{knob, run, Knob, Scene};
use mechlab::studies::painleve::{
    class_example, painleve_case, parameter_knobs, params_from_scene, phi, phi_slope, reduced,
    rigid_rod_roots, slope_signs, Reduced, GRAPH_CLASSES,
};

/// The roots for the given parameters and one σ.
#[derive(serde::Serialize)]
struct Given {
    sigma: f64,
    signs: String,
    roots: Vec<f64>,
    /// Φ'(R) > 0 at each root.
    rising: Vec<bool>,
    case: &'static str,
}

fn graph(q: &Reduced, sigma: f64, lo: f64, hi: f64) -> Vec<(f64, f64)> {
    (0..=400)
        .map(|i| lo + (hi - lo) * i as f64 / 400.0)
        .map(|r| (r, phi(r, sigma, q)))
        .collect()
}

fn knobs() -> Vec<Knob> {
    let mut knobs = parameter_knobs();
    knobs.push(knob(
        "region_pixels",
        "120",
        "resolution of the region plots",
    ));
    knobs
}

fn main() {
    run(|| {
        let knobs = knobs();
        let scene = Scene::from_args(
            "painleve_phi",
            "Φ(R): every graph class, its region, the roots for given parameters",
            &knobs,
        )?;
        let params = params_from_scene(&scene)?;
        let pixels = scene.count("region_pixels")?;
        let q = reduced(&params);

        // The classes, each with an example graph and X* between its kinks.
        let mut titles: Vec<String> = Vec::new();
        let mut examples = Vec::new();
        for (k, class) in GRAPH_CLASSES.iter().enumerate() {
            let e = class_example(k);
            assert_eq!(
                slope_signs(1.0, &e),
                class.signs,
                "example of class {}",
                class.signs
            );
            let roots = rigid_rod_roots(1.0, &e);
            println!(
                "class {}: {}; {} (example: {} roots)",
                class.signs,
                class.region,
                class.roots,
                roots.len()
            );
            titles.push(format!(
                "slopes {}: {} roots of X* = Φ(R)",
                class.signs,
                roots.len()
            ));
            examples.push((e, roots));
        }
        // The given parameters.
        let mut given = Vec::new();
        for sigma in [1.0, -1.0] {
            let roots = rigid_rod_roots(sigma, &q);
            let stable: Vec<bool> = roots
                .iter()
                .map(|r| phi_slope(*r, sigma, &q) > 0.0)
                .collect();
            println!(
                "given parameters, σ = {sigma:+}: slopes {}, X* = {:.6}, roots {roots:?} (Φ' > 0: {stable:?}): {}",
                slope_signs(sigma, &q), q.x_star, painleve_case(roots.len())
            );
            given.push(Given {
                sigma,
                signs: slope_signs(sigma, &q),
                case: painleve_case(roots.len()),
                roots,
                rising: stable,
            });
        }
        titles.push("regions, σo = +1".into());
        titles.push("regions, σo = −1".into());
        titles.push(format!(
            "given: X* = {:.3}, σ = +1 (blue), −1 (red)",
            q.x_star
        ));

        let mut specs = Vec::new();
        let mut ranges = Vec::new();
        for (e, _) in &examples {
            let (lo, hi) = (e.y1.min(-e.y2) - 2.0, e.y1.max(-e.y2) + 2.0);
            let values: Vec<f64> = graph(e, 1.0, lo, hi).iter().map(|p| p.1).collect();
            let (a, b) = values
                .iter()
                .fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(*v), h.max(*v)));
            ranges.push((lo, hi));
            specs.push(PanelSpec::new(
                &titles[specs.len()],
                "R",
                "Φ",
                (lo, hi),
                (a - 0.5, b + 0.5),
            ));
        }
        specs.push(PanelSpec::new(
            &titles[6],
            "μ₁*",
            "μ₂*",
            (0.0, 5.0),
            (0.0, 5.0),
        ));
        specs.push(PanelSpec::new(
            &titles[7],
            "μ₁*",
            "μ₂*",
            (0.0, 5.0),
            (0.0, 5.0),
        ));
        let (glo, ghi) = (q.y1.min(-q.y2) - 3.0, q.y1.max(-q.y2) + 3.0);
        let given_values: Vec<f64> = [1.0, -1.0]
            .iter()
            .flat_map(|s| graph(&q, *s, glo, ghi))
            .map(|p| p.1)
            .chain([q.x_star])
            .collect();
        let (ga, gb) = given_values
            .iter()
            .fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(*v), h.max(*v)));
        specs.push(PanelSpec::new(
            &titles[8],
            "R",
            "Φ",
            (glo, ghi),
            (ga - 0.5, gb + 0.5),
        ));
        let mut figure = Figure::grid(3, 3, 480, 360, &specs);
        for (k, ((e, roots), (lo, hi))) in examples.iter().zip(&ranges).enumerate() {
            figure.line(k, &graph(e, 1.0, *lo, *hi), palette(k));
            figure.line(k, &[(*lo, e.x_star), (*hi, e.x_star)], GREY);
            figure.points(k, roots.iter().map(|r| (*r, e.x_star)), BLACK, 7);
        }
        // Region plots: the class of each (μ1*, μ2*) for σ = +1 and o = ±1.
        let mut region_rows = Vec::new();
        for (panel, y2) in [(6, -3.0), (7, 0.0)] {
            for i in 0..pixels {
                for j in 0..pixels {
                    let (mu1, mu2) = (
                        5.0 * (i as f64 + 0.5) / pixels as f64,
                        5.0 * (j as f64 + 0.5) / pixels as f64,
                    );
                    let e = Reduced::sample(mu1, mu2, y2);
                    let signs = slope_signs(1.0, &e);
                    if let Some(k) = GRAPH_CLASSES.iter().position(|c| c.signs == signs) {
                        figure.points(
                            panel,
                            [(mu1, mu2)],
                            palette(k),
                            (480 / pixels as i64).max(1) + 1,
                        );
                        region_rows.push((if panel == 6 { 1 } else { -1 }, mu1, mu2, signs));
                    }
                }
            }
        }
        let legend: Vec<(String, _)> = GRAPH_CLASSES
            .iter()
            .enumerate()
            .map(|(k, c)| (c.signs.to_string(), palette(k)))
            .collect();
        figure.legend(6, &legend[..3]);
        figure.legend(
            7,
            &[
                legend[0].clone(),
                legend[3].clone(),
                legend[4].clone(),
                legend[5].clone(),
            ],
        );
        for (sigma, color) in [(1.0, palette(0)), (-1.0, RED)] {
            figure.line(8, &graph(&q, sigma, glo, ghi), color);
            figure.points(
                8,
                rigid_rod_roots(sigma, &q).iter().map(|r| (*r, q.x_star)),
                color,
                7,
            );
        }
        figure.line(8, &[(glo, q.x_star), (ghi, q.x_star)], GREY);
        scene.save_figure(&figure, "phi.png")?;
        scene.write_csv(
            "regions.csv",
            &["sigma_o", "mu1_star", "mu2_star", "signs"],
            region_rows,
        )?;
        #[derive(serde::Serialize)]
        struct Summary {
            classes: &'static [mechlab::studies::painleve::GraphClass],
            /// X*, μ1*, μ2*, Y1*, Y2*, cos φ0 of the given parameters.
            reduced: Reduced,
            given: Vec<Given>,
        }
        scene.write_summary(&Summary {
            classes: &GRAPH_CLASSES,
            reduced: q,
            given,
        })?;
        Ok(())
    });
}
