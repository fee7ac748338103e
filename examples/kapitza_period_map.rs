//! Scene `kapitza_period_map` (deliverables 1.2–1.4): orbits of the period map
//! of the pendulum with a vibrating pivot on the unrolled cylinder
//! (q mod 2π, p). Without q0/p0 it draws the portraits of three presets
//! (A = 0: the ordinary pendulum; small A: chaos near the separatrices;
//! larger A: a wide chaotic sea) or of the given A; with q0 and p0 it
//! computes one orbit and reports its final state and cost.

use mechlab::models::kapitza::{Params, INFO};
use mechlab::scene::{knob, parameter_knobs, run, Scene};
use mechlab::scenes::{method_from, method_knobs};
use mechlab::studies::kapitza::{portrait, single_orbit};

fn main() {
    run(|| {
        let mut knobs = vec![
            knob(
                "orbits",
                "24",
                "number of initial conditions (portrait mode)",
            ),
            knob("periods", "3000", "periods per orbit"),
            knob(
                "presets",
                "0,0.2,1",
                "the amplitudes A drawn (portrait mode)",
            ),
            knob("q0", "", "single-orbit mode: initial q"),
            knob("p0", "", "single-orbit mode: initial p"),
            knob(
                "repeat",
                "1",
                "single-orbit mode: timed runs (the fastest is reported)",
            ),
        ];
        knobs.extend(method_knobs("dop853", "1e-10"));
        knobs.extend(parameter_knobs(&INFO, &[("A", "1")]));
        let scene = Scene::from_args(
            "kapitza_period_map",
            "orbits of the period map of the Kapitza pendulum",
            &knobs,
        )?;
        let params = Params::from_values(&scene.parameter_values(&INFO)?);
        let (periods, method) = (scene.count("periods")?, method_from(&scene)?);

        if !scene.text("q0").is_empty() || !scene.text("p0").is_empty() {
            let y0 = [scene.number("q0")?, scene.number("p0")?];
            let result = single_orbit(params, y0, periods, method, scene.count("repeat")?)?;
            let rows = result
                .points
                .iter()
                .enumerate()
                .map(|(k, y)| (k, y[0], y[1]));
            scene.write_csv("orbit.csv", &["period", "q", "p"], rows)?;
            scene.save_figure(&result.figure(), "orbit.png")?;
            scene.write_summary(&result)?;
            return Ok(());
        }

        let mut portraits = Vec::new();
        for a in scene.numbers("presets")? {
            let params = Params { A: a, ..params };
            let result = portrait(params, scene.count("orbits")?, periods, method)?;
            eprintln!(
                "A = {a}: {} orbits in {:.1} s",
                result.orbits, result.seconds
            );
            scene.save_figure(&result.figure(), &format!("portrait_A{a}.png"))?;
            let header = ["orbit", "period", "q", "p"];
            scene.write_csv(&format!("orbits_A{a}.csv"), &header, result.rows())?;
            portraits.push(result);
        }
        scene.write_summary(&serde_json::json!({
            "eps": params.eps,
            "mu": params.mu,
            "method": method.name(),
            "portraits": portraits,
        }))?;
        Ok(())
    });
}
