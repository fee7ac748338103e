//! Scene `kapitza_attractor` (deliverable 1.7): a strange attractor of the
//! dissipative period map of the pendulum with a vibrating pivot. With
//! friction μ > 0 the map contracts areas by exp(−μT) per period, so orbits
//! settle on an attractor; at the default parameters (found by a scan of
//! (ε, A, μ) for a positive largest Lyapunov exponent, see the README) it is
//! a folded, layered set like the Hénon attractor. Draws the attractor after
//! transients, a zoom on its layers, the box-counting plot, and reports the
//! Lyapunov exponents (their sum is −μT) and the box-counting dimension.

use mechlab::models::kapitza::{Params, INFO};
use mechlab::scene::{knob, parameter_knobs, run, Scene};
use mechlab::scenes::{method_from, method_knobs};
use mechlab::studies::kapitza::{attractor, AttractorSettings};

fn main() {
    run(|| {
        let mut knobs = vec![
            knob("points", "100000", "points of the attractor"),
            knob("transient", "1000", "periods dropped first"),
            knob(
                "lyapunov_periods",
                "20000",
                "periods for the Lyapunov exponents",
            ),
            knob(
                "zoom",
                "8",
                "the zoom shows 1/zoom of the attractor's extent",
            ),
        ];
        knobs.extend(method_knobs("dop853", "1e-9"));
        knobs.extend(parameter_knobs(
            &INFO,
            &[("A", "1.5"), ("eps", "0.7"), ("mu", "0.4")],
        ));
        let scene = Scene::from_args(
            "kapitza_attractor",
            "strange attractor of the dissipative Kapitza period map",
            &knobs,
        )?;
        let result = attractor(&AttractorSettings {
            params: Params::from_values(&scene.parameter_values(&INFO)?),
            points: scene.count("points")?,
            transient: scene.count("transient")?,
            lyapunov_periods: scene.count("lyapunov_periods")?,
            zoom: scene.positive("zoom")?,
            method: method_from(&scene)?,
        })?;
        println!(
            "Lyapunov exponents per period {:.4?}, sum {:.4} (−μT = {:.4}), box-counting dimension {:.3}, Kaplan–Yorke {:.3}",
            result.lyapunov, result.lyapunov_sum, result.lyapunov_sum_expected,
            result.dimension, result.kaplan_yorke_dimension
        );
        if result.lyapunov[0] <= 0.0 {
            eprintln!("note: the largest exponent is not positive: at these parameters the attractor is not chaotic");
        }
        scene.save_figure(&result.figure(), "attractor.png")?;
        scene.save_figure(&result.box_counting_figure(), "box_counting.png")?;
        let points = result.orbit.iter().map(|p| (p[0], p[1]));
        scene.write_csv("attractor.csv", &["q", "p"], points)?;
        let boxes = result.box_sides.iter().zip(&result.boxes);
        scene.write_csv("box_counting.csv", &["box_side", "boxes"], boxes)?;
        scene.write_summary(&result)?;
        Ok(())
    });
}
