//! Benchmark `bicycle_field` (`cargo bench -p mechlab-test-models --bench
//! bicycle_field`): the cost of one evaluation of the Whipple–Carvallo
//! bicycle's generated field [q'; q''] (`whipple_bicycle::exact_rhs`: the
//! mass matrix, forces and constraints of four rigid bodies and the
//! Schur-complement solve), as `benches/bicycle/sympy_peer.py` compares
//! it with PyDy's code generated from SymPy's bicycle. Prints one line of
//! JSON: nanoseconds per call, the best of five passes over 10,000 states
//! near the upright motion at 5 m/s.

use mechlab_test_models::whipple_bicycle as bicycle;
use std::hint::black_box;
use std::time::Instant;

const STATES: usize = 10_000;

/// A state near the upright motion at `speed`: small leans, steers and
/// their rates, varied from state to state by a fixed sequence.
fn state(i: usize, speed: f64, params: &bicycle::Params) -> ([f64; 8], [f64; 8]) {
    let s = |k: usize| ((i * 7919 + k * 104_729) % 1000) as f64 / 1000.0 - 0.5;
    let mut q = bicycle::start(params);
    let mut qd = [0.0; 8];
    q[3] = 0.1 * s(1); // lean
    q[5] = 0.1 * s(2); // steer
    qd[0] = speed;
    qd[3] = s(3);
    qd[5] = s(4);
    qd[6] = speed / params.rR;
    qd[7] = speed / params.rF;
    (q, qd)
}

fn main() {
    let params = bicycle::Params::default();
    let states: Vec<_> = (0..STATES).map(|i| state(i, 5.0, &params)).collect();
    let mut best = f64::INFINITY;
    let mut checksum = 0.0;
    for _ in 0..5 {
        let started = Instant::now();
        for (q, qd) in &states {
            let field = bicycle::exact_rhs(0.0, black_box(q), black_box(qd), &params);
            checksum += black_box(field)[11];
        }
        best = best.min(started.elapsed().as_secs_f64());
    }
    assert!(
        checksum.is_finite(),
        "the bicycle's field is not finite on its states"
    );
    let nanoseconds = best / STATES as f64 * 1e9;
    println!("{{\"field_ns_per_call\": {nanoseconds:.1}, \"states\": {STATES}}}");
}
