//! Holonomic constraints on redundant coordinates (`ode::holonomic`),
//! against independent forms: a pendulum written with the Cartesian
//! point and its rod equals the angle pendulum, its multiplier is the
//! rod's tension m(l θ̇² + g cos θ), and projection lands on the manifold
//! by the nearest point in the metric of M.

use mechlab::ode::holonomic::{
    accelerations, project, restricted_monodromy, tangent_basis, tangent_inverse_mass,
    tangent_stability, vibrational_potential, ConstraintError, Holonomic,
};
use mechlab::ode::{states_at, Integrator, Method, System};
use nalgebra::{DMatrix, DVector};

/// A point of mass `m` on a rod of length `l` about the origin, gravity `g`
/// along −y: coordinates (x, y), constraint (x² + y² − l²)/2 = 0.
struct CartesianPendulum {
    m: f64,
    l: f64,
    g: f64,
}

impl Holonomic for CartesianPendulum {
    fn coordinates(&self) -> usize {
        2
    }
    fn residual(&self, _t: f64, q: &[f64]) -> DVector<f64> {
        DVector::from_element(1, 0.5 * (q[0] * q[0] + q[1] * q[1] - self.l * self.l))
    }
    fn jacobian(&self, _t: f64, q: &[f64]) -> (DMatrix<f64>, DVector<f64>) {
        (DMatrix::from_row_slice(1, 2, q), DVector::zeros(1))
    }
    fn mass(&self, _t: f64, _q: &[f64]) -> DMatrix<f64> {
        DMatrix::identity(2, 2) * self.m
    }
}

impl CartesianPendulum {
    /// q̈ and the multiplier λ at y = [x, y, ẋ, ẏ]: F = (0, −m g),
    /// h = ẋ² + ẏ² (the time derivative of G q̇ = x ẋ + y ẏ without q̈).
    fn motion(&self, y: &[f64; 4]) -> (DVector<f64>, f64) {
        let q = &y[..2];
        let (g, _) = Holonomic::jacobian(self, 0.0, q);
        let f = DVector::from_column_slice(&[0.0, -self.m * self.g]);
        let h = DVector::from_element(1, y[2] * y[2] + y[3] * y[3]);
        let (a, lambda) = accelerations(&self.mass(0.0, q), &f, &g, &h, q).unwrap();
        (a, lambda[0])
    }
}

impl System<4> for CartesianPendulum {
    fn rhs(&self, _t: f64, y: &[f64; 4]) -> [f64; 4] {
        let (a, _) = self.motion(y);
        [y[2], y[3], a[0], a[1]]
    }
}

/// θ'' = −(g/l) sin θ, θ from the downward vertical.
struct AnglePendulum {
    l: f64,
    g: f64,
}

impl System<2> for AnglePendulum {
    fn rhs(&self, _t: f64, y: &[f64; 2]) -> [f64; 2] {
        [y[1], -(self.g / self.l) * y[0].sin()]
    }
}

const PENDULUM: CartesianPendulum = CartesianPendulum {
    m: 0.7,
    l: 1.3,
    g: 9.81,
};

/// The Cartesian state of the angle state (θ, θ̇).
fn cartesian(theta: f64, rate: f64) -> [f64; 4] {
    let l = PENDULUM.l;
    [
        l * theta.sin(),
        -l * theta.cos(),
        l * theta.cos() * rate,
        l * theta.sin() * rate,
    ]
}

/// Over 200 time units (about 80 swings), the Cartesian run projected
/// back onto the manifold after every unit equals the angle pendulum to
/// 1e-10 in the angle and its rate, with the constraints' residuals at
/// round-off after each projection, and the multiplier is the rod's
/// tension at every sample.
#[test]
fn a_cartesian_pendulum_with_its_rod_equals_the_angle_pendulum() {
    let (theta0, rate0) = (1.0, 0.3);
    let method = Method::parse("dop853", 1e-14).unwrap();
    let angle = AnglePendulum {
        l: PENDULUM.l,
        g: PENDULUM.g,
    };
    let times: Vec<f64> = (1..=200).map(f64::from).collect();
    let expected = states_at(method, &angle, 0.0, &[theta0, rate0], &times).unwrap();
    let mut integrator = Integrator::new(method).unwrap();
    let mut k = 0;
    let mut worst: f64 = 0.0;
    integrator
        .stream(&PENDULUM, &cartesian(theta0, rate0), 1.0, 200, &mut |y| {
            let projection = project(&PENDULUM, 0.0, y, 1e-15).unwrap();
            assert!(projection.position_residual <= 1e-15, "{projection:?}");
            assert!(projection.velocity_residual <= 1e-13, "{projection:?}");
            let [theta, rate] = expected[k];
            let there = cartesian(theta, rate);
            for i in 0..4 {
                worst = worst.max((y[i] - there[i]).abs());
            }
            // The tension: −λ l = m (l θ̇² + g cos θ).
            let (_, lambda) = PENDULUM.motion(y);
            let tension = PENDULUM.m * (PENDULUM.l * rate * rate + PENDULUM.g * theta.cos());
            assert!(
                (-lambda * PENDULUM.l - tension).abs() < 1e-9 * tension.abs().max(1.0),
                "t = {}: λ = {lambda}, tension {tension}",
                times[k]
            );
            k += 1;
            true
        })
        .unwrap();
    assert_eq!(k, 200);
    assert!(worst < 1e-10, "largest difference {worst:e}");
}

/// A start off the manifold goes to the nearest point on it (M = m I: the
/// point on the circle along the same ray), and the velocity loses its
/// radial part exactly.
#[test]
fn projection_lands_on_the_nearest_consistent_state() {
    let mut y = [0.9, -1.5, 0.4, 0.8];
    let projection = project(&PENDULUM, 0.0, &mut y, 1e-15).unwrap();
    let r = (0.9f64 * 0.9 + 1.5 * 1.5).sqrt();
    let on_ray = [0.9 * PENDULUM.l / r, -1.5 * PENDULUM.l / r];
    assert!(
        (y[0] - on_ray[0]).abs() < 1e-15 && (y[1] - on_ray[1]).abs() < 1e-15,
        "{y:?}"
    );
    let radial = (y[0] * y[2] + y[1] * y[3]) / PENDULUM.l;
    assert!(radial.abs() < 1e-15, "{y:?}");
    // The tangential part is kept: v·t̂ with t̂ ⟂ the ray.
    let tangent = [-on_ray[1] / PENDULUM.l, on_ray[0] / PENDULUM.l];
    let before = 0.4 * tangent[0] + 0.8 * tangent[1];
    let after = y[2] * tangent[0] + y[3] * tangent[1];
    assert!((before - after).abs() < 1e-15);
    assert!(projection.newton_steps >= 1 && projection.newton_steps <= 10);
}

/// Where the constraint degenerates (G = 0 at the origin) or the state
/// has another length, the error says so by name.
#[test]
fn degenerate_constraints_and_wrong_states_are_named_errors() {
    let mut at_origin = [0.0, 0.0, 1.0, 0.0];
    assert!(matches!(
        project(&PENDULUM, 0.0, &mut at_origin, 1e-15),
        Err(ConstraintError::Singular { .. })
    ));
    // No constraint: the whole space; as many as coordinates: none left.
    assert_eq!(
        tangent_basis(&DMatrix::zeros(0, 3)),
        Some(DMatrix::identity(3, 3))
    );
    assert_eq!(tangent_basis(&DMatrix::identity(2, 2)), None);
    // Redundant: two equal rows leave the kernel of one, orthogonal to it.
    let basis = tangent_basis(&DMatrix::from_row_slice(
        2,
        3,
        &[1.0, 2.0, 3.0, 1.0, 2.0, 3.0],
    ))
    .unwrap();
    assert_eq!(basis.ncols(), 2);
    let row = nalgebra::DVector::from_row_slice(&[1.0, 2.0, 3.0]);
    assert!((basis.transpose() * row).norm() < 1e-14);
    let mut y = [0.9, -1.5, 0.4, 0.8];
    assert_eq!(
        project(&PENDULUM, 0.0, &mut y, 0.0),
        Err(ConstraintError::Tolerance { value: 0.0 })
    );
    let mut short = [1.0, 0.0, 0.0];
    assert_eq!(
        project(&PENDULUM, 0.0, &mut short, 1e-15),
        Err(ConstraintError::StateLength {
            given: 3,
            coordinates: 2
        })
    );
}

/// At the hanging equilibrium, the monodromy of the Cartesian ODE over a
/// time T (by central differences of its flow) has four multipliers: the
/// pendulum's e^{±iωT}, ω = √(g/l), and two at 1 from the directions
/// across the manifold (the constraint's drift). Restricted to the
/// constrained phase space it has exactly the physical two.
#[test]
fn floquet_multipliers_on_the_manifold_are_the_physical_ones() {
    let l = PENDULUM.l;
    let period = 1.3;
    let at_rest = [0.0, -l, 0.0, 0.0];
    let method = Method::parse("dop853", 1e-14).unwrap();
    let flow = |y: [f64; 4]| {
        Integrator::new(method)
            .unwrap()
            .advance(&PENDULUM, 0.0, &y, period)
            .unwrap()
    };
    let h = 1e-5;
    let full = DMatrix::from_fn(4, 4, |i, j| {
        let (mut up, mut down) = (at_rest, at_rest);
        up[j] += h;
        down[j] -= h;
        (flow(up)[i] - flow(down)[i]) / (2.0 * h)
    });
    // ∂[g; G q̇]/∂y at rest: [[x, y, 0, 0], [ẋ, ẏ, x, y]].
    let c = DMatrix::from_row_slice(2, 4, &[0.0, -l, 0.0, 0.0, 0.0, 0.0, 0.0, -l]);
    let basis = tangent_basis(&c).expect("the rod's constraint has full rank");
    assert_eq!(basis.shape(), (4, 2));
    assert!((&c * &basis).amax() < 1e-15);
    let restricted = restricted_monodromy(&full, &basis);
    let omega_t = (PENDULUM.g / l).sqrt() * period;
    let mut physical = mechlab::analysis::floquet::multipliers_of(&restricted);
    physical.sort_by(|a, b| a.1.total_cmp(&b.1));
    let s = omega_t.sin().abs();
    let expected = [(omega_t.cos(), -s), (omega_t.cos(), s)];
    for (got, want) in physical.iter().zip(expected) {
        assert!(
            (got.0 - want.0).abs() < 1e-7 && (got.1 - want.1).abs() < 1e-7,
            "{physical:?} against {expected:?}"
        );
    }
    let at_one = full
        .complex_eigenvalues()
        .iter()
        .filter(|z| (z.re - 1.0).abs() < 1e-4 && z.im.abs() < 1e-4)
        .count();
    assert_eq!(
        at_one,
        2,
        "the full matrix's multipliers: {:?}",
        full.complex_eigenvalues()
    );
}

/// Averaging with a constraint, in redundant coordinates: a point of mass
/// m on a rod of length l held upright (y up, V = m g y) on a pivot
/// vibrating vertically with velocity amplitude a. V_vibr = ½ mean⟨P β, β⟩
/// with β = m ẇ e_y, and the tangent-space test with the manifold's
/// curvature (μ ∇²g), give C_T / A_T = −g/l + a²/(2l²): the angle
/// model's (V + V_vibr)''/A, so the threshold a*² = 2 g l (Kapitza's).
/// Without the curvature term C_T would be a²m/(2l²) ≥ 0: never unstable.
#[test]
fn averaging_with_a_constraint_gives_kapitzas_threshold() {
    let (m, l, g) = (PENDULUM.m, PENDULUM.l, PENDULUM.g);
    let upright = [0.0, l];
    let jacobian = |q: &[f64]| DMatrix::from_row_slice(1, 2, q);
    let mass = DMatrix::identity(2, 2) * m;
    for a in [0.0, 3.0, 7.0] {
        let phases = 8;
        let betas: Vec<DVector<f64>> = (0..phases)
            .map(|k| {
                let w_dot = a * (std::f64::consts::TAU * k as f64 / phases as f64).cos();
                DVector::from_column_slice(&[0.0, m * w_dot])
            })
            .collect();
        let v_vibr = |q: &[f64]| {
            let p = tangent_inverse_mass(&mass, &jacobian(q), q).unwrap();
            vibrational_potential(&p, &betas)
        };
        // Its closed form off the equilibrium too: m a² x² / (4 |q|²).
        let q = [0.4, 1.1];
        let closed = m * a * a * q[0] * q[0] / (4.0 * (q[0] * q[0] + q[1] * q[1]));
        assert!((v_vibr(&q) - closed).abs() < 1e-14 * (1.0 + closed));
        // U = m g y + V_vibr: its gradient and Hessian at the upright point
        // (V_vibr's by central differences).
        let h = 1e-4;
        let hessian = DMatrix::from_fn(2, 2, |i, j| {
            let at = |di: f64, dj: f64| {
                let mut q = upright;
                q[i] += di;
                q[j] += dj;
                v_vibr(&q)
            };
            (at(h, h) - at(h, -h) - at(-h, h) + at(-h, -h)) / (4.0 * h * h)
        });
        let gradient = DVector::from_column_slice(&[0.0, m * g]);
        let test = tangent_stability(
            &mass,
            &jacobian(&upright),
            &gradient,
            &hessian,
            &[DMatrix::identity(2, 2)],
        )
        .unwrap();
        assert!((test.multipliers[0] - m * g / l).abs() < 1e-12);
        let ratio = test.stiffness[(0, 0)] / test.mass[(0, 0)];
        let angle_model = -g / l + a * a / (2.0 * l * l);
        assert!(
            (ratio - angle_model).abs() < 1e-6 * (1.0 + angle_model.abs()),
            "a = {a}: C_T/A_T = {ratio}, the angle model's {angle_model}"
        );
    }
    // a* = √(2 g l) = 5.05 for these numbers: 3 is below it, 7 above.
    assert!((2.0 * g * l).sqrt() > 3.0 && (2.0 * g * l).sqrt() < 7.0);
}
