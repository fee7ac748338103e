//! Scene `painleve_phi` (deliverables 3.1, 3.2): the broken line
//! Φ(R) = 2R + σ(μ1*|R − Y1*| − μ2*|R + Y2*|) of the rigid Painlevé–Klein rod.
//!
//! Every qualitatively different graph (by the signs of its three slopes) is
//! drawn for an example, with the region of (μ1*, μ2*, Y1*, Y2*, σ) where
//! it occurs as inequalities (Δ = μ2* − μ1*, S = μ1* + μ2*, o = +1 if
//! Y1* < −Y2*) and as region plots in the (μ1*, μ2*) plane for σo = +1 and
//! σo = −1. For the given parameters, every root R* of X* = Φ(R) for σ = ±1
//! with its Painlevé case.

use mechlab::scene::{knob, run, Scene};
use mechlab::studies::painleve::graphs::phi_graphs;
use mechlab::studies::painleve::{parameter_knobs, params_from_scene};

fn main() {
    run(|| {
        let mut knobs = parameter_knobs();
        knobs.push(knob(
            "region_pixels",
            "120",
            "resolution of the region plots",
        ));
        let scene = Scene::from_args(
            "painleve_phi",
            "Φ(R): every graph class, its region, the roots for given parameters",
            &knobs,
        )?;
        let result = phi_graphs(&params_from_scene(&scene)?, scene.count("region_pixels")?);
        for ((_, roots), class) in result.examples.iter().zip(result.classes) {
            println!(
                "class {}: {}; {} (example: {} roots)",
                class.signs,
                class.region,
                class.roots,
                roots.len()
            );
        }
        for g in &result.given {
            println!(
                "given parameters, σ = {:+}: slopes {}, X* = {:.6}, roots {:?} (Φ' > 0: {:?}): {}",
                g.sigma, g.signs, result.reduced.x_star, g.roots, g.rising, g.case
            );
        }
        scene.save_figure(&result.figure(), "phi.png")?;
        let header = ["sigma_o", "mu1_star", "mu2_star", "signs"];
        scene.write_csv("regions.csv", &header, &result.regions)?;
        scene.write_summary(&result)?;
        Ok(())
    });
}
