//! A Lagrangian with exp() in it (`test_models/morse_pendulum.toml`, a
//! pendulum whose rod is a Morse spring): Symbolica prints exp(x) as 𝑒^x,
//! which the derivation reads back. Its derived field is checked against
//! the one written out here.

use mechlab_test_models::morse_pendulum::{exact_rhs, Params};

/// [r', φ', p_r', p_φ'] by hand: T = ½ m (r'² + r² φ'²),
/// V = −m g r cos φ + D (1 − E)², E = exp(−a (r − r₀)).
fn field_by_hand(y: [f64; 4], p: &Params) -> [f64; 4] {
    let [r, phi, p_r, p_phi] = y;
    let (rd, phid) = (p_r / p.m, p_phi / (p.m * r * r));
    let bond = (-p.a * (r - p.r0)).exp();
    let (s, c) = phi.sin_cos();
    [
        rd,
        phid,
        p.m * r * phid * phid + p.m * p.g * c - 2.0 * p.D * (1.0 - bond) * p.a * bond,
        -p.m * p.g * r * s,
    ]
}

#[test]
fn a_lagrangian_with_exp_gives_the_hand_written_field() {
    let params = Params::default();
    let worst = crate::common::worst_field_difference(
        |s| [1.0 + s(1), 6.0 * s(2), 4.0 * s(3), 2.0 * s(4)],
        |y| exact_rhs(0.0, y, &params),
        |y| field_by_hand(*y, &params),
    );
    assert!(
        worst < 1e-12,
        "derived field off the hand-written one by {worst:e}"
    );
}
