//! A model of 4 degrees of freedom reaches the analyses through the models
//! package's own instantiation at its size (`registry::FixedSize::Large`), and
//! they give its closed-form normal modes.

use mechlab::explore::{explore, Settings};
use mechlab::ode::Method;
use mechlab::registry::FixedSize;
use mechlab_test_models::spring_chain4;
use std::f64::consts::PI;

/// Masses on a line held at one end: mode j has the shape
/// sin((2j − 1) i π / 9) along the chain and ω_j = 2√k sin((2j − 1) π / 18).
#[test]
fn a_four_degree_chain_oscillates_in_its_closed_form_normal_modes() {
    let handle = &spring_chain4::MODEL;
    assert!(matches!(handle.sized, Some(FixedSize::Large(..))));
    let k = 2.0;
    let settings = Settings {
        method: Method::parse("dop853", 1e-11).unwrap(),
        t_end: 10.0,
        samples: 101,
        periods: 0,
    };
    for j in [1, 2, 4] {
        let phase = (2 * j - 1) as f64 * PI / 9.0;
        let shape: Vec<f64> = (1..=4).map(|i| (phase * i as f64).sin()).collect();
        let omega = 2.0 * f64::sqrt(k) * (phase / 2.0).sin();
        let y0: Vec<f64> = shape.iter().copied().chain([0.0; 4]).collect();
        let run = explore(handle, &[k], &y0, &settings).unwrap();
        for (t, y) in run.times.iter().zip(&run.exact) {
            for i in 0..4 {
                let q = shape[i] * (omega * t).cos();
                let p = -shape[i] * omega * (omega * t).sin();
                assert!(
                    (y[i] - q).abs() < 1e-8,
                    "mode {j}, t = {t}: q{i} {} against {q}",
                    y[i]
                );
                assert!(
                    (y[4 + i] - p).abs() < 1e-8,
                    "mode {j}, t = {t}: p{i} {} against {p}",
                    y[4 + i]
                );
            }
        }
        let drift = run.energy_change.iter().fold(0.0f64, |m, e| m.max(e.abs()));
        assert!(drift < 1e-9, "mode {j}: energy drifted by {drift}");
    }
}
