//! Study 3: the generated contact model against the hand-written equations,
//! and the stick–slip integrator on the worked example.

use mechlab::contact::{Mode, Outcome, StickSlip};
use mechlab::models::painleve_klein::{self as model, Contacts, Params};
use mechlab::ode::Method;
use mechlab::studies::painleve::{rod, worked_example_start};

fn random(state: &mut u64) -> f64 {
    *state ^= *state << 13;
    *state ^= *state >> 7;
    *state ^= *state << 17;
    (*state >> 11) as f64 / (1u64 << 53) as f64
}

/// G and N from the model file equal x1'' = X1 − R cos φ − …, x2'' = X2 +
/// R cos φ − …, N1 = R sin φ − Y1, N2 = −Y2 − R sin φ (docs/studies.md,
/// sliding equations) at random states and parameters.
#[test]
fn generated_forces_match_the_hand_written_equations() {
    let mut s = 0x1234_5678_9abc_def1u64;
    for _ in 0..500 {
        let p = Params {
            d: 0.3 + 0.5 * random(&mut s),
            l: 1.0 + 0.5 * random(&mut s),
            X1: 4.0 * random(&mut s) - 2.0,
            Y1: 4.0 * random(&mut s) - 2.0,
            X2: 4.0 * random(&mut s) - 2.0,
            Y2: 4.0 * random(&mut s) - 2.0,
            k: 0.5 + random(&mut s),
            nu: 0.5 + random(&mut s),
            eps: 0.05 + 0.2 * random(&mut s),
            ..Params::default()
        };
        let y = [
            2.0 * random(&mut s),
            2.0 * random(&mut s) - 2.0,
            4.0 * random(&mut s) - 2.0,
            4.0 * random(&mut s) - 2.0,
        ];
        let r = rod(&y, &p);
        let g = model::free_forces(&y, &p);
        let n = model::normal_forces(&y, &p);
        let expected_g = [p.X1 - r.reaction * r.cos_phi, p.X2 + r.reaction * r.cos_phi];
        let expected_n = [
            r.reaction * r.sin_phi - p.Y1,
            -p.Y2 - r.reaction * r.sin_phi,
        ];
        for i in 0..2 {
            let scale = 1.0 + r.reaction.abs() + p.X1.abs() + p.Y1.abs() + p.Y2.abs();
            assert!(
                (g[i] - expected_g[i]).abs() < 1e-10 * scale,
                "G{i}: {} vs {}",
                g[i],
                expected_g[i]
            );
            assert!(
                (n[i] - expected_n[i]).abs() < 1e-10 * scale,
                "N{i}: {} vs {}",
                n[i],
                expected_n[i]
            );
        }
        assert_eq!(model::masses(&p), [1.0, 1.0]);
    }
}

#[test]
fn worked_example_debug() {
    let model = Contacts {
        params: Params::default(),
    };
    for x2 in [-0.65, -0.78] {
        let run = StickSlip::new(Method::parse("dop853", 1e-10).unwrap())
            .run(&model, 0.0, &worked_example_start(x2), 6.0, &[])
            .unwrap();
        eprintln!(
            "x2(0) = {x2}: {:?} at t = {}, y = {:?}",
            run.outcome, run.t, run.y
        );
        for s in &run.switches {
            eprintln!(
                "  t = {:.6} contact {} {} -> {} case {} v = {:?}",
                s.t,
                s.contact,
                s.from,
                s.to,
                s.case,
                &s.y[2..]
            );
        }
        let _ = (Mode::Stick, Outcome::Rest);
    }
}
