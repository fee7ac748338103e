//! Scene `painleve_delta` (deliverables 3.3, 3.4): the deformation equation
//! (25) of the sliding rod, δ'' = cos²φ0 (X* − Φ(R)), R = k ε⁻² δ + ν ε⁻¹ δ'.
//!
//! Its equilibria are δ* = ε² R*/k for every root R* of X* = Φ(R); the
//! eigenvalues of the linearisation solve λ² + c Φ' ν/ε λ + c Φ' k/ε² = 0
//! (c = cos²φ0): a saddle where Φ' < 0, a centre (ν = 0) or a stable focus
//! or node (ν > 0) where Φ' > 0. Phase portraits on (δ, δ') for an example
//! of each graph class of `painleve_phi`, first ν = 0 then ν ≠ 0, and for the
//! given parameters; equilibria marked (black: stable, red: unstable).

use mechlab::scene::{knob, run, Scene};
use mechlab::studies::painleve::deformation::deformation;
use mechlab::studies::painleve::{parameter_knobs, params_from_scene};

fn main() {
    run(|| {
        let mut knobs = parameter_knobs();
        knobs.extend([
            knob(
                "sigma",
                "1",
                "sliding direction σ = ±1 for the given parameters",
            ),
            knob(
                "starts",
                "7",
                "initial points per side of the portrait grid",
            ),
            knob("t_end", "3", "length of each trajectory, in units of ε"),
        ]);
        let scene = Scene::from_args(
            "painleve_delta",
            "equilibria of the deformation equation (25) and phase portraits",
            &knobs,
        )?;
        let sigma = if scene.number("sigma")? >= 0.0 {
            1.0
        } else {
            -1.0
        };
        let params = params_from_scene(&scene)?;
        let result = deformation(
            &params,
            sigma,
            scene.count("starts")?,
            scene.positive("t_end")?,
        )?;
        for case in &result.cases {
            println!("{}: X* = {:.4}", case.case, case.x_star);
            for e in &case.equilibria {
                println!(
                    "  R* = {:.6}, δ* = {:.6}, Φ' = {:+.3}, eigenvalues {:?}, asymptotically stable: {}",
                    e.root, e.delta, e.slope, e.eigenvalues, e.asymptotically_stable
                );
            }
        }
        scene.save_figure(&result.figure(), "portraits.png")?;
        scene.write_summary(&result)?;
        Ok(())
    });
}
