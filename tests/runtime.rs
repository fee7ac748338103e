//! Unit-level checks of runtime pieces that need no model: dual and
//! hyper-dual derivatives, bialternate products, formulas as MathML, the studio's
//! level sets, the memory budget. (The runtime crate has no test target of
//! its own: its tests live in this package, which `cargo test` runs.)

use mechlab::linalg::{bialternate, bialternate_sum};
use mechlab::ode::dual::{jacobian, lane_by_lane};
use mechlab::ode::hyperdual::{gradient, hessian};
use mechlab::ode::Scalar;
use mechlab::ode::{Dual, Lanes, LANES};
use mechlab_studio::calls::contour::Field;

/// f(x, y) = sin(x)·y³/(1 + x²) + √(exp(x y)) against its hand-derived
/// gradient and Hessian.
#[test]
fn gradient_and_hessian_match_closed_forms() {
    fn f<T: Scalar>(v: &[T; 2]) -> T {
        let (x, y) = (v[0], v[1]);
        x.sin() * y * y * y / (x * x + 1.0) + (x * y).exp().sqrt()
    }
    let (x, y) = (0.7, -1.3);
    let d = 1.0 + x * x;
    let e = (x * y / 2.0).exp();
    let s = x.sin() / d;
    let s_x = x.cos() / d - 2.0 * x * x.sin() / (d * d);
    let s_xx = -x.sin() / d - 4.0 * x * x.cos() / (d * d)
        + x.sin() * (8.0 * x * x / (d * d * d) - 2.0 / (d * d));
    let grad = gradient(f, &[x, y]);
    let expected = [s_x * y.powi(3) + y / 2.0 * e, 3.0 * s * y * y + x / 2.0 * e];
    let hess = hessian(f, &[x, y]);
    let expected_h = [
        [
            s_xx * y.powi(3) + y * y / 4.0 * e,
            3.0 * s_x * y * y + (0.5 + x * y / 4.0) * e,
        ],
        [
            3.0 * s_x * y * y + (0.5 + x * y / 4.0) * e,
            6.0 * s * y + x * x / 4.0 * e,
        ],
    ];
    for i in 0..2 {
        assert!(
            (grad[i] - expected[i]).abs() < 1e-13,
            "{grad:?} {expected:?}"
        );
        for j in 0..2 {
            assert!(
                (hess[i][j] - expected_h[i][j]).abs() < 1e-12,
                "{hess:?} {expected_h:?}"
            );
        }
    }
}

/// A fraction, powers (of a function name too) and a Greek letter become
/// MathML elements; a relation is escaped.
#[test]
fn formulas_become_mathml() {
    let html = mechlab::mathml::mathml(r"\frac{p^2}{2} + A^2 \sin^2\theta < 1", true);
    assert!(
        html.starts_with("<math") && html.contains("display=\"block\""),
        "{html}"
    );
    assert!(
        html.contains("<mfrac>") && html.contains("<msup>") && html.contains("θ"),
        "{html}"
    );
    assert!(
        html.contains("<msup><mrow><mi>sin</mi></mrow><mn>2</mn></msup>"),
        "{html}"
    );
    assert!(
        html.contains("<mo>&lt;</mo>") && !html.contains("<mo><"),
        "{html}"
    );
}

/// Every segment end of the level set x² + y² = r² lies on the circle
/// to the grid's interpolation error, and the segments add up to its
/// length.
#[test]
fn circle() {
    let field = Field::sample([(-2.0, 2.0), (-2.0, 2.0)], 101, |x, y| x * x + y * y);
    let r: f64 = 1.3;
    let segments = field.segments(r * r);
    let h = 4.0 / 100.0;
    let mut length = 0.0;
    for s in &segments {
        for (x, y) in [(s[0], s[1]), (s[2], s[3])] {
            assert!(((x * x + y * y).sqrt() - r).abs() < h * h, "({x}, {y})");
        }
        length += ((s[2] - s[0]).powi(2) + (s[3] - s[1]).powi(2)).sqrt();
    }
    assert!(
        (length - 2.0 * std::f64::consts::PI * r).abs() < 1e-3 * r,
        "{length}"
    );
}

/// A saddle x·y = 0 gives the two axes, and levels at quantiles are sorted.
#[test]
fn saddle_and_quantiles() {
    let field = Field::sample([(-1.0, 1.0), (-1.0, 1.0)], 20, |x, y| x * y);
    for s in field.segments(1e-3) {
        assert!(
            s[0] * s[1] > 0.0 && s[2] * s[3] > 0.0,
            "{s:?} crosses into the wrong quadrant"
        );
    }
    let levels = field.quantiles(9);
    assert!(levels.windows(2).all(|w| w[0] < w[1]));
    assert!(levels[0] < 0.0 && levels[8] > 0.0);
}

#[test]
fn bialternate_eigenvalues_are_pairwise_products() {
    let m = nalgebra::DMatrix::from_row_slice(
        3,
        3,
        &[2.0, 1.0, 0.0, 0.0, 3.0, 1.0, 0.0, 0.0, 5.0], // eigenvalues 2, 3, 5
    );
    let mut values: Vec<f64> = bialternate(&m)
        .eigenvalues()
        .unwrap()
        .iter()
        .copied()
        .collect();
    values.sort_by(f64::total_cmp);
    for (got, want) in values.iter().zip([6.0, 10.0, 15.0]) {
        assert!((got - want).abs() < 1e-12, "{values:?}");
    }
}

#[test]
fn bialternate_sum_eigenvalues_are_pairwise_sums() {
    // A full matrix with eigenvalues 1, 2, 4, 7 (a similarity transform
    // of the diagonal), so that every entry of the formula is exercised.
    let d =
        nalgebra::DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![1.0, 2.0, 4.0, 7.0]));
    let t = nalgebra::DMatrix::from_fn(4, 4, |i, j| {
        1.0 / (1.0 + i as f64 + 2.0 * j as f64) + f64::from(u8::from(i == j))
    });
    let a = &t * d * t.clone().try_inverse().unwrap();
    let mut values: Vec<f64> = bialternate_sum(&a)
        .complex_eigenvalues()
        .iter()
        .map(|z| z.re)
        .collect();
    values.sort_by(f64::total_cmp);
    for (got, want) in values.iter().zip([3.0, 5.0, 6.0, 8.0, 9.0, 11.0]) {
        assert!((got - want).abs() < 1e-9, "{values:?}");
    }
}

#[test]
fn a_request_over_the_memory_budget_is_named_and_one_within_passes() {
    use mechlab::budget::check;
    let points = |n: u128| check(|| format!("{n} points"), n, 16);
    assert!(points(1_000_000).is_ok());
    let e = points(2_000_000_001).unwrap_err();
    assert_eq!(e.count, 2_000_000_001);
    assert!(
        e.to_string()
            .starts_with("2000000001 points: 2000000001 × 16 bytes would keep 29.8 GiB"),
        "{e}"
    );
    // Products that overflow are refused, not wrapped.
    assert!(check(|| "huge".into(), u128::MAX, 2).is_err());
}

/// The equilibrium finder's starts: the whole grid up to 4⁸ points (an
/// 8-link chain), a sample of the same size at any larger number of
/// coordinates, always with every angle at 0 and every one at −π, every
/// point on the grid, the same on every run.
#[test]
fn equilibrium_starts_are_the_grid_or_a_bounded_sample_of_it() {
    use mechlab::analysis::equilibria::{starts, GRID_STARTS, SAMPLED_STARTS};
    use std::f64::consts::PI;
    let eight = starts(&[true; 8]);
    assert_eq!(eight.points.len(), GRID_STARTS);
    assert!(!eight.search.sampled());
    assert_eq!(starts(&[true, false, true]).points.len(), 12 * 12 * 12);
    for (periodic, grid) in [
        (vec![true; 12], 4f64.powi(12)),
        (vec![true; 40], 4f64.powi(40)),
        (
            [vec![true; 6], vec![false; 6]].concat(),
            4f64.powi(6) * 7f64.powi(6),
        ),
    ] {
        let sample = starts(&periodic);
        assert!(sample.search.sampled());
        assert_eq!(sample.search.starts, SAMPLED_STARTS);
        assert_eq!(sample.search.grid, grid);
        assert_eq!(sample.points.len(), SAMPLED_STARTS);
        let upright: Vec<f64> = vec![0.0; periodic.len()];
        let hanging: Vec<f64> = periodic
            .iter()
            .map(|&p| if p { -PI } else { 0.0 })
            .collect();
        assert!(sample.points.contains(&upright));
        assert!(sample.points.contains(&hanging));
        let angles = [-PI, -PI / 2.0, 0.0, PI / 2.0];
        let lengths = [-2.0, -1.0, -0.5, 0.0, 0.5, 1.0, 2.0];
        for point in &sample.points {
            for (x, &p) in point.iter().zip(&periodic) {
                let axis: &[f64] = if p { &angles } else { &lengths };
                assert!(
                    axis.iter().any(|a| (a - x).abs() < 1e-15),
                    "{x} not on the grid"
                );
            }
        }
        assert_eq!(starts(&periodic).points, sample.points);
    }
}

/// f(x) = sin(x)·exp(x)/√x + ln(x)·x^1.5 + 1/x over dual numbers (through
/// the generic [`Scalar`] code the generated recurrences use) against its
/// derivative by hand, over f64 and over lanes.
#[test]
fn dual_numbers_differentiate_elementary_functions_exactly() {
    fn f<T: Scalar>(x: T) -> T {
        x.sin() * x.exp() / x.sqrt() + x.ln() * x.powf(1.5) + x.recip() + x.mul_add(x, x) * 0.5
    }
    let by_hand = |x: f64| {
        (x.cos() * x.exp() + x.sin() * x.exp()) / x.sqrt() - 0.5 * x.sin() * x.exp() / x.powf(1.5)
            + x.powf(0.5)
            + 1.5 * x.ln() * x.powf(0.5)
            - 1.0 / (x * x)
            + x
            + 0.5
    };
    for x in [0.3, 1.3, 4.0] {
        let d = f(Dual::seeded(x, 1.0));
        assert!((d.re - f(x)).abs() < 1e-15 * f(x).abs().max(1.0));
        assert!((d.du - by_hand(x)).abs() < 1e-14 * by_hand(x).abs(), "{x}");
    }
    let xs = Lanes(std::array::from_fn(|l| 0.5 + l as f64));
    let d = f(Dual::seeded(xs, Lanes::from(1.0)));
    for l in 0..LANES {
        assert_eq!(d.du.0[l], f(Dual::seeded(xs.0[l], 1.0)).du);
    }
}

/// The Jacobian of f(x, y) = (x² y, sin(x) + y/x) by dual numbers, column by
/// column, against its closed form; a batch run lane by lane lands in its
/// lanes.
#[test]
fn dual_jacobian_and_lane_by_lane() {
    let (x, y) = (0.8, -1.7);
    let j = jacobian(&[x, y], |v| [v[0] * v[0] * v[1], v[0].sin() + v[1] / v[0]]);
    let exact = [[2.0 * x * y, x * x], [x.cos() - y / (x * x), 1.0 / x]];
    for i in 0..2 {
        for k in 0..2 {
            assert!((j[i][k] - exact[i][k]).abs() < 1e-15, "{i} {k}");
        }
    }
    // A larger one: f_i = v_i·v_{i+1} (cyclic) over 11 variables.
    let y: [f64; 11] = std::array::from_fn(|i| 0.3 + i as f64);
    let j = jacobian(&y, |v| std::array::from_fn(|i| v[i] * v[(i + 1) % 11]));
    for i in 0..11 {
        for k in 0..11 {
            let exact = match k {
                k if k == i => y[(i + 1) % 11],
                k if k == (i + 1) % 11 => y[i],
                _ => 0.0,
            };
            assert_eq!(j[i][k], exact, "{i} {k}");
        }
    }
    let z: Vec<Lanes> = (0..3)
        .map(|i| Lanes(std::array::from_fn(|l| (i * 10 + l) as f64)))
        .collect();
    let mut out = vec![Lanes::from(0.0); 6];
    lane_by_lane(&z, &mut out, |l, z, out| {
        for (k, o) in out.iter_mut().enumerate() {
            *o = z[k % 3] * 2.0 + l as f64;
        }
    });
    for l in 0..LANES {
        for k in 0..6 {
            assert_eq!(out[k].0[l], z[k % 3].0[l] * 2.0 + l as f64);
        }
    }
}

/// The dual-number solve that factorises the values alone gives the
/// derivative of the solve, x' = A⁻¹(b' − A'x): against the factorisation
/// differentiated entry by entry, and against differences.
#[test]
fn dual_solve_differentiates_the_solve() {
    let matrix = |s: f64| {
        [
            [4.0 + s, 1.0 - s * s, 0.5],
            [1.0 - s * s, 3.0 + s.sin(), 0.2 * s],
            [0.5, 0.2 * s, 2.0 + s * s],
        ]
    };
    let rhs = |s: f64| [1.0 + s, s.cos(), -0.3 * s];
    let s = 0.4;
    let a: [[Dual; 3]; 3] = {
        let h = 1e-7;
        let (m, mp, mm) = (matrix(s), matrix(s + h), matrix(s - h));
        std::array::from_fn(|i| {
            std::array::from_fn(|j| Dual::seeded(m[i][j], (mp[i][j] - mm[i][j]) / (2.0 * h)))
        })
    };
    let b: [Dual; 3] = {
        let h = 1e-7;
        let (r, rp, rm) = (rhs(s), rhs(s + h), rhs(s - h));
        std::array::from_fn(|i| Dual::seeded(r[i], (rp[i] - rm[i]) / (2.0 * h)))
    };
    let fast = mechlab::ode::dual::Cholesky::new(a).solve(b);
    let entrywise = mechlab::linalg::Cholesky::new(a).solve(b);
    let solve = |s: f64| mechlab::linalg::Cholesky::new(matrix(s)).solve(rhs(s));
    let h = 1e-6;
    let (xp, xm) = (solve(s + h), solve(s - h));
    for i in 0..3 {
        assert!((fast[i].re - entrywise[i].re).abs() < 1e-14);
        assert!((fast[i].du - entrywise[i].du).abs() < 1e-13, "{i}");
        assert!(
            (fast[i].du - (xp[i] - xm[i]) / (2.0 * h)).abs() < 1e-7,
            "{i}"
        );
    }
}

/// A model's `Systems` (states as slices, through trait objects) runs the
/// same steps as its typed system: Kapitza's period map streamed over 200
/// periods by name equals the typed stream bit for bit, with Taylor and
/// with DOP853, and a state of another length is refused by name.
#[test]
fn a_models_systems_run_its_typed_system_bit_for_bit() {
    use mechlab::models::kapitza;
    use mechlab::ode::{Integrator, Method, OdeError};
    let params = [1.5, 0.1, 0.0];
    let systems = mechlab::models::by_name("kapitza")
        .unwrap()
        .systems()
        .unwrap();
    let period = systems.phase_period(&params).unwrap();
    let by_name = systems.exact(&params);
    let typed = kapitza::Exact {
        params: kapitza::Params::from_values(&params),
    };
    for method in [
        Method::Taylor { tol: 1e-12 },
        Method::parse("dop853", 1e-10).unwrap(),
    ] {
        let y0 = [2.6, 0.3];
        let mut typed_points = Vec::new();
        Integrator::new(method)
            .unwrap()
            .stream(&typed, &y0, period, 200, &mut |y| {
                typed_points.push(*y);
                true
            })
            .unwrap();
        let mut points = Vec::new();
        by_name
            .stream(
                &mut Integrator::new(method).unwrap(),
                &y0,
                period,
                200,
                &mut |y| {
                    points.push([y[0], y[1]]);
                    true
                },
            )
            .unwrap();
        assert_eq!(points, typed_points, "{method:?}");
    }
    let mut integrator = Integrator::new(Method::Rk4 { step: 0.01 }).unwrap();
    assert_eq!(
        by_name.stream(&mut integrator, &[1.0, 0.0, 0.0], period, 1, &mut |_| true),
        Err(OdeError::StateLength {
            given: 3,
            expected: 2
        })
    );
}

/// The windowed factor of a semidefinite matrix: a row within the window
/// of the earlier rows' span is skipped (its unknown 0; here x = (2, 0)
/// solves [[1, 1], [1, 1 + ε]] x = (2, 2) with ε = 1e-8 inside a window of
/// 1e-6, while 1e-10 keeps the row: x = (2, 0) too, the exact solution),
/// and a NaN entry stays NaN rather than be skipped as a vanished row.
#[test]
fn the_windowed_factor_skips_dependent_rows_and_keeps_nan() {
    use mechlab::linalg::Cholesky;
    let a = [[1.0, 1.0], [1.0, 1.0 + 1e-8]];
    for window in [1e-6, 1e-10] {
        let factor = Cholesky::semidefinite_within(a, window);
        assert_eq!(factor.rank(), if window > 1e-8 { 1 } else { 2 });
        let x = factor.solve([2.0, 2.0]);
        assert!((x[0] - 2.0).abs() < 1e-7 && x[1].abs() < 1e-7, "{x:?}");
    }
    let b = [[1.0, 0.0], [0.0, 1.0 + 1e-8]];
    let x = Cholesky::semidefinite_within(b, 1e-6).solve([1.0, 1.0]);
    assert!((x[1] - 1.0).abs() < 1e-7, "an independent row kept: {x:?}");
    let nan = [[f64::NAN, 0.0], [0.0, 1.0]];
    let x = Cholesky::semidefinite_within(nan, 1e-6).solve([1.0, 1.0]);
    assert!(x[0].is_nan(), "{x:?}");
}
