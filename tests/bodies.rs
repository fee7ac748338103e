//! Rigid bodies declared in model files, against closed forms: the heavy
//! symmetric top of `models/heavy_top.toml` (one `[[bodies]]` table, its
//! energy derived by mechlab) precesses steadily at the rates of the
//! quadratic A Ω² cos θ − C ω₃ Ω + m g l = 0 and, released, nods between the
//! angles and with the period of Lagrange's cubic; its hand-written
//! Hamiltonian is conserved.

use mechlab::analysis::states::{states_at, StatesError};
use mechlab::ode::Method;

/// m, l, A, C, g in the file's order.
const PARAMS: [f64; 5] = [1.0, 1.0, 2.0, 1.0, 1.0];
const TIGHT: f64 = 1e-13;

fn top() -> &'static mechlab::registry::Model {
    mechlab::models::by_name("heavy_top").unwrap()
}

/// The state [φ, θ, ψ, p_φ, p_θ, p_ψ] at tilt θ with rates φ', θ' and
/// the spin ω₃ = ψ' + φ' cos θ: p_θ = A θ', p_ψ = C ω₃,
/// p_φ = A φ' sin²θ + C ω₃ cos θ.
fn state(theta: f64, phi_rate: f64, theta_rate: f64, spin: f64) -> [f64; 6] {
    let [_, _, a, c, _] = PARAMS;
    let p_phi = a * phi_rate * theta.sin().powi(2) + c * spin * theta.cos();
    [0.0, theta, 0.0, p_phi, a * theta_rate, c * spin]
}

/// H = p_θ²/2A + (p_φ − p_ψ cos θ)²/(2A sin²θ) + p_ψ²/2C + m g l cos θ,
/// written by hand.
fn hamiltonian(y: &[f64]) -> f64 {
    let [m, l, a, c, g] = PARAMS;
    let (theta, p_phi, p_theta, p_psi) = (y[1], y[3], y[4], y[5]);
    p_theta.powi(2) / (2.0 * a)
        + (p_phi - p_psi * theta.cos()).powi(2) / (2.0 * a * theta.sin().powi(2))
        + p_psi.powi(2) / (2.0 * c)
        + m * g * l * theta.cos()
}

fn run(y0: &[f64; 6], times: &[f64]) -> Vec<Vec<f64>> {
    let method = Method::parse("dop853", TIGHT).unwrap();
    states_at(top(), &PARAMS, method, y0, times).unwrap()
}

/// The file's start (tilt 0.5, spin rate ψ' = 10, the axis still) has
/// the momenta of its rates: p_φ = C ψ' cos θ, p_θ = 0, p_ψ = C ψ'.
#[test]
fn the_file_starts_the_top_spinning_with_the_momenta_of_its_rates() {
    let start = top()
        .dynamic
        .start(&PARAMS)
        .expect("the file gives a start");
    let expected = state(0.5, 0.0, 0.0, 10.0);
    for (got, want) in start.iter().zip(expected) {
        assert!(
            (got - want).abs() < 1e-14,
            "start {start:?}, by hand {expected:?}"
        );
    }
}

/// Both steady precessions: θ stays put to 1e-10 and φ turns at Ω.
#[test]
fn the_heavy_top_precesses_steadily_at_both_roots_of_the_quadratic() {
    let [m, l, a, c, g] = PARAMS;
    let (theta, spin) = (0.5_f64, 3.0);
    let (qa, qb, qc) = (a * theta.cos(), -c * spin, m * g * l);
    let root = (qb * qb - 4.0 * qa * qc).sqrt();
    let times: Vec<f64> = (0..=40).map(|k| 0.5 * k as f64).collect();
    for omega in [(-qb - root) / (2.0 * qa), (-qb + root) / (2.0 * qa)] {
        let states = run(&state(theta, omega, 0.0, spin), &times);
        for (t, y) in times.iter().zip(&states) {
            assert!(
                (y[1] - theta).abs() < 1e-10,
                "Ω = {omega}: θ({t}) = {}",
                y[1]
            );
            assert!(
                (y[0] - omega * t).abs() < 1e-9 * (1.0 + t),
                "Ω = {omega}: φ({t}) = {}",
                y[0]
            );
        }
    }
}

/// The arithmetic-geometric mean, for K(k) = π / (2 agm(1, √(1 − k²))).
fn agm(mut a: f64, mut b: f64) -> f64 {
    // Quadratic convergence: 8 steps reach rounding from any k² < 0.99.
    for _ in 0..8 {
        (a, b) = ((a + b) / 2.0, (a * b).sqrt());
    }
    a
}

/// Released at θ₀ with no precession or nodding, the top nods between θ₀
/// and arccos u₁ with the period 4K(k)/√(β(u₃ − u₁)), k² = (u₀ − u₁)/(u₃ −
/// u₁), where u = cos θ and u₁ < u₀ < 1 < u₃ are the roots of Lagrange's
/// cubic f(u) = (u₀ − u)(β(1 − u²) − a²(u₀ − u)), a = C ω₃/A, β = 2mgl/A.
/// At half the period θ is at its largest and p_θ vanishes; at the period
/// it is back at θ₀. The hand-written Hamiltonian holds to 1e-11.
#[test]
fn the_released_heavy_top_nods_with_lagrange_cubics_period_and_amplitude() {
    let [m, l, a_moment, c, g] = PARAMS;
    let (theta0, spin) = (0.5_f64, 3.0);
    let (a, beta, u0) = (
        c * spin / a_moment,
        2.0 * m * g * l / a_moment,
        theta0.cos(),
    );
    // β u² − a² u + (a² u₀ − β) = 0.
    let disc = (a.powi(4) - 4.0 * beta * (a * a * u0 - beta)).sqrt();
    let (u1, u3) = ((a * a - disc) / (2.0 * beta), (a * a + disc) / (2.0 * beta));
    assert!(-1.0 < u1 && u1 < u0 && u3 > 1.0, "{u1} {u0} {u3}");
    let k2 = (u0 - u1) / (u3 - u1);
    let big_k = std::f64::consts::PI / (2.0 * agm(1.0, (1.0 - k2).sqrt()));
    let period = 4.0 * big_k / (beta * (u3 - u1)).sqrt();
    let y0 = state(theta0, 0.0, 0.0, spin);
    let times: Vec<f64> = (0..=8).map(|k| period * k as f64 / 2.0).collect();
    let states = run(&y0, &times);
    let h0 = hamiltonian(&y0);
    for (k, y) in states.iter().enumerate() {
        let expected = if k % 2 == 0 { theta0 } else { u1.acos() };
        assert!(
            (y[1] - expected).abs() < 1e-8,
            "θ at {k} half periods: {} not {expected}",
            y[1]
        );
        assert!(y[4].abs() < 1e-8, "p_θ at {k} half periods: {}", y[4]);
        assert!(
            (hamiltonian(y) - h0).abs() < 1e-11 * h0.abs(),
            "H drifted to {}",
            hamiltonian(y)
        );
    }
    // Within the period θ moves: the check is not of a top at rest.
    let quarter = run(&y0, &[0.0, period / 4.0]);
    assert!((quarter[1][1] - theta0).abs() > 0.05);
}

/// A body's inertia given as a tensor with products of inertia, in axes
/// turned by a fixed angle α about the body's z axis, is the same body as
/// the principal moments in the principal axes: the tensor
/// R_z(α)ᵀ diag(I₁, I₂, I₃) R_z(α) with the rotation sequence continued by
/// Z(alpha) gives the same Lagrangian at random states (to rounding), and
/// the tensor with its products' sign flipped does not.
/// The top is drawn as its frame: its z axis from its centre points
/// along the centre's position l (sin θ sin φ, −sin θ cos φ, cos θ)
/// written in the model file (the rotation Z(φ) X(θ) Z(ψ) turns the axis
/// there), sqrt(tr I / 2m) = sqrt((2(A − m l²) + C)/2m) long, and the
/// tip stays at the origin, joined to the centre.
#[test]
fn the_top_is_drawn_along_its_axis() {
    use mechlab::analysis::mechanism::{animate, Frames};
    let [m, l, a, c, _] = PARAMS;
    let start = state(0.5, 0.3, 0.2, 4.0);
    let frames = Frames {
        duration: 5.0,
        count: 51,
    };
    let method = Method::parse("dop853", TIGHT).unwrap();
    let animation = animate(top(), &PARAMS, method, &start, &[], frames).unwrap();
    assert!(animation.in_space);
    assert_eq!(animation.up, [0.0, 0.0, 1.0], "against gravity (0, 0, −g)");
    let length = ((2.0 * (a - m * l * l) + c) / (2.0 * m)).sqrt();
    let [centre, _, _, z] = animation.body_frames[0];
    let tip = animation.points.iter().position(|&p| p == "tip").unwrap();
    assert_eq!(animation.bars, &[[centre, tip]]);
    for (t, points) in animation.times.iter().zip(&animation.frames) {
        assert_eq!(points[tip], [0.0; 3]);
        for k in 0..3 {
            let along = points[centre][k] / l * length;
            assert!(
                (points[z][k] - points[centre][k] - along).abs() < 1e-14,
                "t = {t}: the z axis {:?} from the centre {:?}",
                points[z],
                points[centre]
            );
        }
    }
}

#[test]
fn an_inertia_tensor_with_products_is_the_principal_body_turned() {
    use mechlab_model::Model;
    let body = |inertia: &str, rotation: &str| {
        format!(
            r#"
name = "body"
description = "a free rigid body about a fixed point"
gravity = [0, 0, "-1"]

[[coordinates]]
name = "phi"
velocity = "phid"

[[coordinates]]
name = "theta"
velocity = "thetad"
start = 0.7

[[coordinates]]
name = "psi"
velocity = "psid"

[[parameters]]
name = "alpha"
default = 0.4
description = "the turn of the tensor's axes from the principal ones"

[[bodies]]
name = "b"
mass = 1.3
inertia = {inertia}
position = ["0.2*sin(theta)*sin(phi)", "-0.2*sin(theta)*cos(phi)", "0.2*cos(theta)"]
rotation = "{rotation}"
"#
        )
    };
    let (i1, i2, i3, alpha) = (1.0_f64, 2.5, 3.2, 0.4_f64);
    let (c, s) = (alpha.cos(), alpha.sin());
    // R_z(α)ᵀ diag(I₁, I₂, I₃) R_z(α).
    let (ixx, iyy, ixy) = (
        i1 * c * c + i2 * s * s,
        i1 * s * s + i2 * c * c,
        (i2 - i1) * s * c,
    );
    let tensor = |sign: f64| {
        format!(
            "[[{ixx:?}, {:?}, 0], [{:?}, {iyy:?}, 0], [0, 0, {i3:?}]]",
            sign * ixy,
            sign * ixy
        )
    };
    let principal = Model::parse(
        "body.toml",
        &body("[1.0, 2.5, 3.2]", "Z(phi) X(theta) Z(psi)"),
    )
    .unwrap();
    let turned = Model::parse(
        "body.toml",
        &body(&tensor(1.0), "Z(phi) X(theta) Z(psi) Z(alpha)"),
    )
    .unwrap();
    let flipped = Model::parse(
        "body.toml",
        &body(&tensor(-1.0), "Z(phi) X(theta) Z(psi) Z(alpha)"),
    )
    .unwrap();
    let (a, b, f) = (
        principal.expanded_lagrangian(),
        turned.expanded_lagrangian(),
        flipped.expanded_lagrangian(),
    );
    let mut seed = 0.61_f64;
    let mut next = || {
        seed = (seed * 997.0 + 0.123).fract();
        2.0 * seed - 1.0
    };
    let mut largest_flipped: f64 = 0.0;
    for _ in 0..20 {
        let values: Vec<(&str, f64)> = ["phi", "theta", "psi", "phid", "thetad", "psid"]
            .into_iter()
            .map(|name| (name, 2.0 * next()))
            .chain([("alpha", alpha)])
            .collect();
        let env = |s: &str| values.iter().find(|(n, _)| *n == s).map(|(_, v)| *v);
        let (la, lb, lf) = (
            a.eval(&env).unwrap(),
            b.eval(&env).unwrap(),
            f.eval(&env).unwrap(),
        );
        assert!(
            (la - lb).abs() < 1e-13 * (1.0 + la.abs()),
            "{la} against {lb}"
        );
        largest_flipped = largest_flipped.max((la - lf).abs());
    }
    assert!(
        largest_flipped > 0.01,
        "the products' sign should matter: {largest_flipped}"
    );
}

/// At θ = 0 the Euler angles are a singular chart (φ and ψ turn about one
/// axis, the mass matrix is singular): a run started there is refused
/// with an error naming the state, not a NaN.
#[test]
fn the_top_started_in_its_singular_chart_is_refused_by_name() {
    let method = Method::parse("dop853", 1e-10).unwrap();
    let upright = [0.0, 0.0, 0.0, 0.0, 0.0, 1.0];
    match states_at(top(), &PARAMS, method, &upright, &[0.0, 1.0]) {
        Err(StatesError::SingularChart { t, momenta, .. }) => {
            // p_φ and p_ψ turn the top about the same axis there.
            assert!(
                t == 0.0 && momenta.contains(&0) && momenta.contains(&2),
                "{momenta:?}"
            );
        }
        other => panic!("a singular chart should be named: {other:?}"),
    }
}

/// Euler parameters (a unit quaternion) as a body's orientation: a free
/// asymmetric body spun near its intermediate axis flips over (the
/// Dzhanibekov effect), and its body-frame angular velocity ω = 2 G(e) e'
/// follows Euler's equations I₁ω₁' = (I₂ − I₃)ω₂ω₃, … (integrated here by
/// hand with RK4) to 1e-9 over 20 time units, through orientations where
/// any Euler-angle chart is singular; the unit norm holds to 1e-12.
#[test]
fn a_free_body_in_euler_parameters_follows_eulers_equations_through_its_flips() {
    use mechlab::analysis::on_constraints::run;
    use mechlab_test_models::free_body_quaternion;
    let moments = [1.0, 2.0, 3.0];
    let w0 = [0.02, 1.0, 0.01];
    let times: Vec<f64> = (0..=40).map(|k| 0.5 * k as f64).collect();
    let euler = |w: [f64; 3]| {
        let [i1, i2, i3] = moments;
        [
            (i2 - i3) * w[1] * w[2] / i1,
            (i3 - i1) * w[2] * w[0] / i2,
            (i1 - i2) * w[0] * w[1] / i3,
        ]
    };
    let mut reference = vec![w0];
    let mut w = w0;
    let h = 1e-4;
    for _ in 1..times.len() {
        for _ in 0..5000 {
            w = crate::common::rk4_step(euler, w, h);
        }
        reference.push(w);
    }
    // It flips: ω₂ changes sign.
    assert!(reference.iter().any(|w| w[1] < -0.9), "no flip");
    // e = (1, 0, 0, 0), e' = ½ e ⊗ (0, ω₀).
    let y0 = [
        1.0,
        0.0,
        0.0,
        0.0,
        0.0,
        w0[0] / 2.0,
        w0[1] / 2.0,
        w0[2] / 2.0,
    ];
    let method = Method::parse("dop853", 1e-13).unwrap();
    let r = run(
        &free_body_quaternion::SYSTEMS,
        &moments,
        Some(&y0),
        method,
        &times,
    )
    .unwrap();
    for (k, (y, expected)) in r.states.iter().zip(&reference).enumerate() {
        let (e, d) = (&y[..4], &y[4..]);
        let body = [
            2.0 * (-e[1] * d[0] + e[0] * d[1] + e[3] * d[2] - e[2] * d[3]),
            2.0 * (-e[2] * d[0] - e[3] * d[1] + e[0] * d[2] + e[1] * d[3]),
            2.0 * (-e[3] * d[0] + e[2] * d[1] - e[1] * d[2] + e[0] * d[3]),
        ];
        for i in 0..3 {
            assert!(
                (body[i] - expected[i]).abs() < 1e-9,
                "t = {}: ω = {body:?}, Euler's equations {expected:?}",
                times[k]
            );
        }
    }
    assert!(r.largest_residual.0 < 1e-12, "{:?}", r.largest_residual);
    // The drawing's frame is the body's orientation R(e): the angular
    // momentum R I ω in the fixed frame is conserved with it (a frame
    // turned the other way, Rᵀ, would not conserve it). The axes are
    // drawn sqrt(tr I / 2m) = √3 long.
    let drawing = free_body_quaternion::INFO.drawing.unwrap();
    let momentum = |y: &[f64]| -> [f64; 3] {
        let (e, d) = (&y[..4], &y[4..]);
        let body = [
            2.0 * (-e[1] * d[0] + e[0] * d[1] + e[3] * d[2] - e[2] * d[3]),
            2.0 * (-e[2] * d[0] - e[3] * d[1] + e[0] * d[2] + e[1] * d[3]),
            2.0 * (-e[3] * d[0] + e[2] * d[1] - e[1] * d[2] + e[0] * d[3]),
        ];
        let points = (drawing.at)(0.0, &y[..4], &moments);
        let [centre, ax, ay, az] = drawing.body_frames[0];
        std::array::from_fn(|k| {
            [ax, ay, az]
                .iter()
                .enumerate()
                .map(|(i, &tip)| {
                    (points[tip][k] - points[centre][k]) / 3f64.sqrt() * moments[i] * body[i]
                })
                .sum()
        })
    };
    let first = momentum(&r.states[0]);
    for (t, y) in times.iter().zip(&r.states) {
        let now = momentum(y);
        assert!(
            (0..3).all(|k| (now[k] - first[k]).abs() < 1e-8),
            "t = {t}: R I ω = {now:?}, at the start {first:?}"
        );
    }
}

/// The steady precessions by name (`steady_motion`, a model without
/// constraints): given Ω and the spin's rate ψ', the analysis finds the
/// tilt θ₀ = 0.5 of the quadratic by Newton's method (the shape θ, the
/// cyclic φ and ψ found by itself), and its linearisation nods at the
/// frequency of the Routhian written here, U(θ) = (p_φ − p_ψ cos θ)²/
/// (2A sin²θ) + m g l cos θ at the motion's p_φ, p_ψ: ω² = U''(θ₀)/A. The
/// motion is conservative, so the verdict is that the first order cannot
/// decide, with both roots on the imaginary axis.
#[test]
fn the_steady_precessions_nod_at_the_routhians_frequency() {
    use mechlab::analysis::declared::{no_progress, Analysis};
    use mechlab::analysis::on_constraints::steady::{study::SteadyMotionOptions, Verdict};
    let [m, l, a, c, g] = PARAMS;
    let (theta, spin) = (0.5_f64, 3.0);
    let (qa, qb, qc) = (a * theta.cos(), -c * spin, m * g * l);
    let root = (qb * qb - 4.0 * qa * qc).sqrt();
    for omega in [(-qb - root) / (2.0 * qa), (-qb + root) / (2.0 * qa)] {
        let psi_rate = spin - omega * theta.cos();
        let options = SteadyMotionOptions {
            at: Some(omega),
            rates: Some(vec![omega, 0.0, psi_rate]),
            start: Some(vec![0.0, 0.45, 0.0]),
            sweep: 0,
            ..Default::default()
        };
        let study = options.run(top(), &PARAMS, &no_progress).unwrap();
        assert_eq!(
            (study.speed.as_str(), &study.shape[..]),
            ("phi", &["theta".to_string()][..])
        );
        let found = study.motion.state[1];
        assert!((found - theta).abs() < 1e-9, "Ω = {omega}: θ₀ = {found}");
        let (p_phi, p_psi) = (
            a * omega * theta.sin().powi(2) + c * spin * theta.cos(),
            c * spin,
        );
        let u = |t: f64| {
            (p_phi - p_psi * t.cos()).powi(2) / (2.0 * a * t.sin().powi(2)) + m * g * l * t.cos()
        };
        let h = 1e-4;
        let u2 = (u(theta + h) - 2.0 * u(theta) + u(theta - h)) / (h * h);
        let nodding = (u2 / a).sqrt();
        let motion = &study.motion;
        println!(
            "Ω = {omega}: {:?} ± {:?} against ±{nodding}i",
            motion.eigenvalues, motion.errors
        );
        for ((re, im), e) in motion.eigenvalues.iter().zip(&motion.errors) {
            assert!(re.abs() <= *e, "Ω = {omega}: {re} ± {e}");
            assert!(
                (im.abs() - nodding).abs() < 1e-6 * nodding,
                "Ω = {omega}: {im} against {nodding}"
            );
        }
        assert_eq!(
            motion.verdict,
            Verdict::InconclusiveAtFirstOrder { on_axis: 2 }
        );
    }
}
