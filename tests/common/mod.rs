//! Helpers shared by the integration tests.
#![allow(dead_code)]

use mechlab::ode::{Integrator, LaneIntegrator, Method, Orbit, System};
use mechlab::registry::Model;

/// The users' model `name`, which the test expects to exist.
pub fn model_of(name: &str) -> &'static Model {
    match name {
        // A test model (test_models/): the scenes' build does not compile it.
        "quadruple_pendulum" => &mechlab_test_models::quadruple_pendulum::MODEL,
        _ => mechlab::models::by_name(name).unwrap_or_else(|e| panic!("{e}")),
    }
}

/// Deterministic pseudo-random numbers (xorshift64), so that a failing
/// case can be rerun.
pub struct Rng(pub u64);

impl Rng {
    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [a, b).
    pub fn between(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.uniform()
    }
}

/// Whether a and b agree to `tol`, relative to their size (absolute near 0).
pub fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + a.abs().max(b.abs()))
}

/// Asserts [`close`], naming the quantity.
pub fn assert_close(what: &str, a: f64, b: f64, tol: f64) {
    assert!(close(a, b, tol), "{what}: {a} vs {b}");
}

/// Each orbit streamed for one segment (Taylor, 1e-10) against its scalar run
/// (its end sampled from the step across it).
pub fn assert_streams_equal_scalar<S: System<N>, const N: usize>(orbits: &[Orbit<'_, S, N>]) {
    let mut ends: Vec<[f64; N]> = orbits.iter().map(|o| o.start).collect();
    let mut batch = LaneIntegrator::new(Method::Taylor { tol: 1e-10 }).unwrap();
    let errors = batch.stream(orbits, |k, y| {
        ends[k] = *y;
        false
    });
    let mut scalar = Integrator::new(Method::Taylor { tol: 1e-10 }).unwrap();
    for (k, orbit) in orbits.iter().enumerate() {
        let mut end = None;
        let expected = scalar
            .advance_segments(orbit.system, &orbit.start, orbit.end, 1, &mut |y| {
                end = Some(*y);
                false
            })
            .map(|()| end.unwrap_or(orbit.start));
        let streamed = match &errors[k] {
            Some(e) => Err(e.clone()),
            None => Ok(ends[k]),
        };
        // Debug text: NaN ≠ NaN, but the errors must read the same.
        assert_eq!(
            format!("{streamed:?}"),
            format!("{expected:?}"),
            "orbit {k}"
        );
    }
    assert_eq!(batch.stats.steps, scalar.stats.steps);
    assert_eq!(batch.stats.f_evals, scalar.stats.f_evals);
}
