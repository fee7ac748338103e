//! Models written for the tests (`test_models/`) whose recurrences compute
//! with literals only or take a parameter as an exponent, in the batch
//! Taylor method.

#[path = "../../../tests/common/mod.rs"]
mod common;

use common::assert_streams_equal_scalar;
use mechlab::ode::{Integrator, Method, Orbit};

const TAYLOR: Method = Method::Taylor { tol: 1e-10 };

/// Models whose recurrences compute with literals only (no parameters:
/// an empty `Params`, gravity √2 as a power of numbers) or take a
/// parameter as an exponent (through exp(α ln u), in a batch with each
/// lane's own α): the closed forms hold, and lanes equal scalar runs.
#[test]
fn models_without_parameters_or_with_a_parameter_exponent() {
    use mechlab_test_models::{bare_pendulum, power_law_oscillator};
    // H = p²/2 − √2 cos q is conserved.
    let bare = bare_pendulum::Exact {
        params: bare_pendulum::Params::default(),
    };
    let energy = |y: &[f64; 2]| y[1] * y[1] / 2.0 - 2f64.sqrt() * y[0].cos();
    let y0 = [1.0, 0.5];
    let y1 = Integrator::new(TAYLOR)
        .unwrap()
        .advance(&bare, 0.0, &y0, 10.0)
        .unwrap();
    assert!((energy(&y1) - energy(&y0)).abs() < 1e-11, "{y1:?}");
    // α = 1: V = 1 + x², x(t) = x₀ cos √2t + (p₀/√2) sin √2t.
    let oscillators: Vec<power_law_oscillator::Exact> =
        [0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 1.0, 0.75, 1.25]
            .map(|alpha| power_law_oscillator::Exact {
                params: power_law_oscillator::Params { alpha },
            })
            .to_vec();
    let orbits: Vec<Orbit<_, 2>> = oscillators
        .iter()
        .enumerate()
        .map(|(k, system)| Orbit {
            system,
            start: [0.3 + 0.1 * k as f64, -0.2],
            end: 3.0,
        })
        .collect();
    assert_streams_equal_scalar(&orbits);
    let [x0, p0] = orbits[1].start;
    let w = 2f64.sqrt();
    let y = Integrator::new(TAYLOR)
        .unwrap()
        .advance(&oscillators[1], 0.0, &orbits[1].start, 3.0)
        .unwrap();
    let exact = [
        x0 * (w * 3.0).cos() + p0 / w * (w * 3.0).sin(),
        -x0 * w * (w * 3.0).sin() + p0 * (w * 3.0).cos(),
    ];
    assert!(
        (y[0] - exact[0]).abs() < 1e-10 && (y[1] - exact[1]).abs() < 1e-10,
        "{y:?} vs {exact:?}"
    );
}
