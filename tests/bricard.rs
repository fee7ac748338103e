//! Bricard's overconstrained mechanism, the IFToMM benchmark A04
//! (`test_models/iftomm_bricard.toml`), against its kinematics and
//! energy written out here by hand with rotation matrices, and against
//! its period from a quadrature along the closed loop's one-parameter
//! motion.

use mechlab::analysis::on_constraints::{run, ConstrainedError};
use mechlab::ode::{Method, OdeError};
use mechlab_test_models::iftomm_bricard;
use nalgebra::{Matrix3, Matrix5, Vector3, Vector5};
use std::f64::consts::{FRAC_PI_2, PI};

const MASS: f64 = 1.0;
const LENGTH: f64 = 1.0;
const GRAVITY: f64 = 9.81;

/// Each joint's axis in the frame of the rod before it (the ground's for
/// the first): y, z, x, y, z; each rod's direction in its own frame.
const JOINT_AXES: [usize; 5] = [1, 2, 0, 1, 2];
const ROD_DIRECTIONS: [[f64; 3]; 5] = [
    [1.0, 0.0, 0.0],
    [0.0, -1.0, 0.0],
    [0.0, 0.0, 1.0],
    [-1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
];

fn turn(axis: usize, angle: f64) -> Matrix3<f64> {
    let (s, c) = angle.sin_cos();
    match axis {
        0 => Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c),
        1 => Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c),
        _ => Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0),
    }
}

/// The chain at joint angles θ: each rod's hinge (where it starts), the
/// hinge's axis and the rod's direction in the fixed frame, the last
/// rod's tip and its frame.
struct Chain {
    hinges: [Vector3<f64>; 5],
    axes: [Vector3<f64>; 5],
    directions: [Vector3<f64>; 5],
    tip: Vector3<f64>,
    last: Matrix3<f64>,
}

fn chain(theta: &[f64]) -> Chain {
    let mut frame = Matrix3::identity();
    let mut at = Vector3::zeros();
    let mut chain = Chain {
        hinges: [Vector3::zeros(); 5],
        axes: [Vector3::zeros(); 5],
        directions: [Vector3::zeros(); 5],
        tip: Vector3::zeros(),
        last: Matrix3::identity(),
    };
    for k in 0..5 {
        chain.hinges[k] = at;
        chain.axes[k] = frame.column(JOINT_AXES[k]).into_owned();
        frame *= turn(JOINT_AXES[k], theta[k]);
        chain.directions[k] = frame * Vector3::from(ROD_DIRECTIONS[k]);
        at += LENGTH * chain.directions[k];
    }
    chain.tip = at;
    chain.last = frame;
    chain
}

/// The loop's closure at the last ground hinge, (0, 0, l) with its axis
/// along x: the last rod's tip there, its x axis with no y or z part.
fn closure(theta: &[f64]) -> Vector5<f64> {
    let c = chain(theta);
    let axis = c.last.column(0);
    Vector5::new(c.tip.x, c.tip.y, c.tip.z - LENGTH, axis.y, axis.z)
}

/// T and V of the five slender rods: each centre's velocity from the
/// joint rates about the hinges before it, each rod's spin ω = Σ a_j θ_j'
/// with m l²/12 across the rod and nothing along it.
fn energy(theta: &[f64], rates: &[f64]) -> (f64, f64) {
    let c = chain(theta);
    let (mut kinetic, mut potential) = (0.0, 0.0);
    let mut spin = Vector3::zeros();
    for k in 0..5 {
        spin += c.axes[k] * rates[k];
        let centre = c.hinges[k] + 0.5 * LENGTH * c.directions[k];
        let velocity: Vector3<f64> = (0..=k)
            .map(|j| rates[j] * c.axes[j].cross(&(centre - c.hinges[j])))
            .sum();
        let across = spin.norm_squared() - spin.dot(&c.directions[k]).powi(2);
        kinetic +=
            0.5 * MASS * velocity.norm_squared() + 0.5 * MASS * LENGTH * LENGTH / 12.0 * across;
        potential += MASS * GRAVITY * centre.y;
    }
    (kinetic, potential)
}

/// The closure's Jacobian by central differences (5 × 5, rank 4).
fn jacobian(theta: &[f64; 5]) -> Matrix5<f64> {
    let h = 1e-6;
    let mut j = Matrix5::zeros();
    for i in 0..5 {
        let (mut up, mut down) = (*theta, *theta);
        up[i] += h;
        down[i] -= h;
        j.set_column(i, &((closure(&up) - closure(&down)) / (2.0 * h)));
    }
    j
}

/// The configuration with θ₁ = a, the other four angles solved from the
/// closure by Gauss–Newton from `guess`, and the motion's tangent dθ/da:
/// the closure Jacobian's null vector.
fn on_the_loop(a: f64, guess: [f64; 5]) -> ([f64; 5], [f64; 5]) {
    let mut theta = guess;
    theta[0] = a;
    for _ in 0..20 {
        let j = jacobian(&theta).remove_column(0);
        let step = j.svd(true, true).solve(&-closure(&theta), 1e-12).unwrap();
        for i in 0..4 {
            theta[i + 1] += step[i];
        }
    }
    let svd = jacobian(&theta).svd(false, true);
    let smallest = svd.singular_values.imin();
    let null = svd.v_t.unwrap().row(smallest).transpose();
    let tangent = std::array::from_fn(|i| null[i] / null[0]);
    (theta, tangent)
}

/// Half the period of the swing released at rest from θ = 0: the time to
/// the mirror position θ₁ = π, ∫ √(m(a) / 2(E − V(a))) da over the
/// loop's motion, m(a) = 2T along its tangent. With a = π/2 (1 − cos u)
/// the integrand is smooth, even and periodic in u, so the midpoint rule
/// converges faster than any power of the nodes.
fn half_period(nodes: usize) -> f64 {
    let e = energy(&[0.0; 5], &[0.0; 5]).1;
    let mut theta = [0.0; 5];
    let mut sum = 0.0;
    for k in 0..nodes {
        let u = (k as f64 + 0.5) * PI / nodes as f64;
        let a = FRAC_PI_2 * (1.0 - u.cos());
        let tangent;
        (theta, tangent) = on_the_loop(a, theta);
        let (kinetic, potential) = energy(&theta, &tangent);
        sum += (kinetic / (e - potential)).sqrt() * FRAC_PI_2 * u.sin();
    }
    sum * PI / nodes as f64
}

/// θ₁ crosses π/2, found between two outputs by the cubic through their
/// angles and rates (bisection on it).
fn crossing(t: [f64; 2], angle: [f64; 2], rate: [f64; 2]) -> f64 {
    let h = t[1] - t[0];
    let at = |s: f64| {
        let (s2, s3) = (s * s, s * s * s);
        (2.0 * s3 - 3.0 * s2 + 1.0) * angle[0]
            + (s3 - 2.0 * s2 + s) * h * rate[0]
            + (-2.0 * s3 + 3.0 * s2) * angle[1]
            + (s3 - s2) * h * rate[1]
            - FRAC_PI_2
    };
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if (at(mid) > 0.0) == (at(lo) > 0.0) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    t[0] + h * 0.5 * (lo + hi)
}

/// Released at rest in the benchmark's position, the mechanism swings to
/// its mirror image and back. Over the benchmark's 10 s, with DOP853 and
/// Gauss6: the loop stays closed to 1e-12 by the hand-written closure;
/// the energy, written out here by hand, holds to 1e-10 (J; the
/// benchmark's measure); the three odd joints turn alike and the two even
/// ones alike (the loop's symmetry); the swing crosses the bottom at the
/// times the quadrature of its period gives, to 1e-8 s; and the build
/// names the one repeated closure condition's reactions indeterminate.
#[test]
fn bricards_mechanism_swings_with_the_period_of_its_one_freedom() {
    let half = half_period(48);
    assert!(
        (half - half_period(32)).abs() < 1e-10,
        "quadrature not converged"
    );
    let params = [MASS, LENGTH, GRAVITY];
    let times: Vec<f64> = (0..=10_000).map(|k| 1e-3 * k as f64).collect();
    let e0 = energy(&[0.0; 5], &[0.0; 5]).1;
    for method in [
        Method::Dop853 {
            rtol: 1e-13,
            atol: 1e-13,
        },
        Method::Gauss {
            stages: 3,
            step: 5e-3,
        },
    ] {
        let started = std::time::Instant::now();
        let r = run(&iftomm_bricard::SYSTEMS, &params, None, method, &times).unwrap();
        let seconds = started.elapsed().as_secs_f64();
        let (mut closed, mut drift, mut asymmetry) = (0.0_f64, 0.0_f64, 0.0_f64);
        let mut crossings = Vec::new();
        for (k, state) in r.states.iter().enumerate() {
            let (theta, rates) = state.split_at(5);
            closed = closed.max(closure(theta).amax());
            let (kinetic, potential) = energy(theta, rates);
            drift = drift.max((kinetic + potential - e0).abs());
            asymmetry = asymmetry
                .max((theta[2] - theta[0]).abs())
                .max((theta[4] - theta[0]).abs())
                .max((theta[3] - theta[1]).abs());
            if k > 0 {
                let before = &r.states[k - 1];
                if (before[0] - FRAC_PI_2) * (theta[0] - FRAC_PI_2) < 0.0 {
                    crossings.push(crossing(
                        [times[k - 1], times[k]],
                        [before[0], theta[0]],
                        [before[5], rates[0]],
                    ));
                }
            }
        }
        eprintln!(
            "{method:?}: {} steps in {seconds:.3} s, energy {drift:.1e} J, loop {closed:.1e}",
            r.steps
        );
        assert!(closed < 1e-12, "{method:?}: loop open by {closed:e}");
        assert!(drift < 1e-10, "{method:?}: energy off by {drift:e} J");
        assert!(asymmetry < 1e-9, "{method:?}: {asymmetry:e}");
        // Released at rest at θ₁ = 0, at rest again at θ₁ = π after half a
        // period: the bottom is crossed at t₁, 2T − t₁, 2T + t₁, 4T − t₁.
        assert_eq!(crossings.len(), 4, "{method:?}: {crossings:?}");
        let t1 = crossings[0];
        for (found, expected) in
            crossings
                .iter()
                .zip([t1, 2.0 * half - t1, 2.0 * half + t1, 4.0 * half - t1])
        {
            assert!(
                (found - expected).abs() < 1e-8,
                "{method:?}: crossed at {found}, the quadrature says {expected}"
            );
        }
        assert!(!r.indeterminate.is_empty(), "{method:?}");
        assert!(
            r.near_singular.is_empty(),
            "{method:?}: {:?}",
            r.near_singular
        );
    }
}

/// Bricard's recurrences would be 1.3 MB of source, past the size rule
/// (`TAYLOR_SOURCE_BYTES`): the model has none, and the Taylor method is
/// refused by name rather than run.
#[test]
fn bricards_mechanism_refuses_the_taylor_method_by_name() {
    let refused = run(
        &iftomm_bricard::SYSTEMS,
        &[MASS, LENGTH, GRAVITY],
        None,
        Method::Taylor { tol: 1e-12 },
        &[0.0, 1.0],
    );
    assert!(
        matches!(
            refused,
            Err(ConstrainedError::Ode(OdeError::TaylorUnavailable))
        ),
        "{refused:?}"
    );
}
