//! A spring's length written between two turning points in the fixed frame
//! (`test_models/turning_arm_spring.toml`): its turn cancels only through
//! cos² + sin² = 1 under the root and in the Rayleigh function. The
//! derived equations are checked against the field written out here, and
//! the turn is checked gone from the derived Lagrangian.

use mechlab_test_models::turning_arm_spring::{exact_rhs, Params, INFO};

/// [φ', r', p_φ', p_r'] by hand: with ℓ² = (r − a)² + b² + h² (the hook
/// turns with the arm), L = ½(J + m r²)φ'² + ½ m r'² − ½ K (ℓ − L₀)² and
/// D = ½ c ℓ'² with ℓ' = (r − a) r'/ℓ.
fn field_by_hand(y: [f64; 4], p: &Params) -> [f64; 4] {
    let [_, r, p_phi, p_r] = y;
    let spin_inertia = p.J + p.m * r * r;
    let (phid, rd) = (p_phi / spin_inertia, p_r / p.m);
    let along = r - p.a;
    let length = (along * along + p.b * p.b + p.h * p.h).sqrt();
    let spring = -p.K * (length - p.L0) * along / length;
    let damper = -p.c * along * along * rd / (length * length);
    [phid, rd, 0.0, p.m * r * phid * phid + spring + damper]
}

#[test]
fn a_spring_written_in_the_fixed_frame_gives_the_hand_written_field() {
    let params = Params::default();
    let worst = crate::common::worst_field_difference(
        |s| [6.0 * s(1), 0.6 + 0.8 * s(2), 2.0 * s(3), 3.0 * s(4)],
        |y| exact_rhs(0.0, y, &params),
        |y| field_by_hand(*y, &params),
    );
    assert!(
        worst < 1e-12,
        "derived field off the hand-written one by {worst:e}"
    );
}

#[test]
fn the_turn_is_gone_from_the_derived_lagrangian() {
    let lagrangian = INFO
        .derivations
        .iter()
        .find(|d| d.key == "lagrangian")
        .expect("a derived Lagrangian");
    assert!(
        !lagrangian.text.contains("phi)"),
        "sin or cos of the turn left in L: {}",
        lagrangian.text
    );
}
