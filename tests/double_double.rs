//! Double-double numbers: the arithmetic against exact integer computations
//! (error-free sums and products), the functions against 32-digit reference
//! values (computed with mpmath at 300 bits), and the Taylor method in
//! double-double on generated models: energy kept to 10⁻²⁸ where double
//! precision keeps 10⁻¹⁶, the same period map as double precision, and the
//! f64 coefficients (fused sums) equal to the double-double ones to rounding.

use mechlab::models::{self, kapitza};
use mechlab::ode::{DoubleDouble, DoubleDoubleTaylor, Integrator, Method, Scalar};
use mechlab::registry::{Fixed, FixedSize};
use proptest::prelude::*;

fn dd(hi: f64, lo: f64) -> DoubleDouble {
    DoubleDouble { hi, lo }
}

/// hi + lo as an exact integer (both integral).
fn exact(x: DoubleDouble) -> i128 {
    assert_eq!(x.hi.fract(), 0.0);
    assert_eq!(x.lo.fract(), 0.0);
    x.hi as i128 + x.lo as i128
}

/// A double-double integer below 2⁶¹: hi a multiple of 2⁸ with 53 bits, lo
/// below half its ulp.
fn integer(hi: i64, lo: i64) -> (DoubleDouble, i128) {
    let hi = ((hi.rem_euclid(1 << 52)) + (1 << 52)) << 8;
    let lo = lo.rem_euclid(256) - 128;
    let x = DoubleDouble::sum(hi as f64, lo as f64);
    (x, hi as i128 + lo as i128)
}

proptest! {
    #[test]
    fn sums_and_products_of_two_doubles_are_exact(a in -(1i64 << 52)..(1i64 << 52), b in -(1i64 << 52)..(1i64 << 52)) {
        let (a, b) = (a as f64 * 1024.0, b as f64);
        prop_assert_eq!(exact(DoubleDouble::sum(a, b)), a as i128 + b as i128);
        prop_assert_eq!(exact(DoubleDouble::product(a, b)), a as i128 * b as i128);
    }

    /// Sums exact where the result fits; products within 2⁻¹⁰³ relative
    /// (Joldeș et al. bound 5u², u = 2⁻⁵³); quotients and square roots by
    /// their inverse operations.
    #[test]
    fn double_double_operations_are_within_their_bounds(
        ah in any::<i64>(), al in any::<i64>(), bh in any::<i64>(), bl in any::<i64>(), negative in any::<bool>()
    ) {
        let (a, ea) = integer(ah, al);
        let (b, eb) = integer(bh, bl);
        let b = if negative { -b } else { b };
        let eb = if negative { -eb } else { eb };
        prop_assert_eq!(exact(a + b), ea + eb);
        prop_assert_eq!(exact(a - b), ea - eb);
        let p = a * b;
        let error = (exact(p) - ea * eb).unsigned_abs() as f64;
        prop_assert!(error <= 2f64.powi(-103) * (ea * eb).unsigned_abs() as f64, "product error {error}");
        let q = a / b;
        let back = q * b - a;
        prop_assert!(back.abs().hi <= 1e-31 * a.hi.abs(), "quotient: q b − a = {back:?}");
        let r = a.sqrt();
        let back = r * r - a;
        prop_assert!(back.abs().hi <= 1e-31 * a.hi, "root: r² − a = {back:?}");
    }
}

/// (x, sin x, cos x, e^x, ln |x|, √|x|) as (hi, lo) pairs from mpmath
/// (ln 0.1 = −ln 10 among them, to its last bit).
#[allow(clippy::type_complexity, clippy::approx_constant)]
const REFERENCE: [(
    (f64, f64),
    (f64, f64),
    (f64, f64),
    (f64, f64),
    (f64, f64),
    (f64, f64),
); 6] = [
    (
        (0.1, -5.551115123125783e-18),
        (0.09983341664682815, -2.4433675401530753e-18),
        (0.9950041652780258, -5.4466828902896175e-17),
        (1.1051709180756477, -8.763017013024472e-17),
        (-2.302585092994046, 2.1707562233822494e-16),
        (0.31622776601683794, -7.976586724465037e-18),
    ),
    (
        (0.3333333333333333, 1.850371707708594e-17),
        (0.32719469679615226, -1.814582427259489e-17),
        (0.9449569463147377, -3.581052075189009e-17),
        (1.3956124250860895, 1.4446871884803438e-17),
        (-1.0986122886681098, 9.07129723500153e-17),
        (0.5773502691896257, 3.345028073935634e-17),
    ),
    (
        (2.5, 0.0),
        (0.5984721441039565, -5.521403334082375e-17),
        (-0.8011436155469337, -1.8674742705085553e-17),
        (12.182493960703473, 2.0334002173348147e-16),
        (0.9162907318741551, -4.141195369011963e-17),
        (1.5811388300841898, -9.539408485358302e-17),
    ),
    (
        (-7.25, 0.0),
        (-0.8230808790115055, 4.782695371371335e-17),
        (0.5679241732886948, 4.202033681904503e-17),
        (0.000710174388842549, 3.546078199295509e-20),
        (1.9810014688665833, 6.013262624124967e-17),
        (2.692582403567252, 1.4592269629506974e-16),
    ),
    (
        (100.75, 0.0),
        (0.2172878636707302, -7.707407610179142e-18),
        (0.9761075679972009, 1.0933022008863626e-17),
        (5.690744033881574e+43, 4.39938648547122e+27),
        (4.612642200826793, -2.9684740240597587e-16),
        (10.037429949942366, -4.3618291587058787e-16),
    ),
    (
        (1e-05, -8.180305391403131e-22),
        (9.999999999833334e-06, -1.9979693281312927e-22),
        (0.99999999995, 4.137435216621184e-18),
        (1.00001000005, 9.701802454713091e-17),
        (-11.512925464970229, 1.971996919909995e-16),
        (0.0031622776601683794, -6.241863248488229e-20),
    ),
];

#[test]
fn functions_are_accurate_to_1e_30_relative() {
    let check = |what: &str, x: DoubleDouble, got: DoubleDouble, (hi, lo): (f64, f64)| {
        let want = dd(hi, lo);
        let error = (got - want).abs().to_f64() / hi.abs();
        assert!(
            error <= 1e-30,
            "{what}({x:?}) = {got:?}, want {want:?}: relative error {error:e}"
        );
    };
    for (x, sin, cos, exp, ln, sqrt) in REFERENCE {
        let x = dd(x.0, x.1);
        let (s, c) = x.sin_cos();
        check("sin", x, s, sin);
        check("cos", x, c, cos);
        check("exp", x, x.exp(), exp);
        check("ln", x, x.abs().ln(), ln);
        check("sqrt", x, x.abs().sqrt(), sqrt);
    }
}

/// The pendulum (Kapitza's model without vibration, A = 0): H = p²/2 + cos q
/// is conserved. Over 20 time units the double-double Taylor method keeps
/// it to 10⁻²⁸, far below what double precision can hold (10⁻¹⁶), and the
/// state agrees with double precision's to its accuracy.
#[test]
fn the_pendulum_keeps_its_energy_to_1e_28_in_double_double() {
    let params = kapitza::Params {
        A: 0.0,
        eps: 0.1,
        mu: 0.0,
    };
    let system = kapitza::Exact { params };
    let energy = |y: &[DoubleDouble; 2]| y[1] * y[1] * 0.5 + y[0].cos();
    let y0 = [DoubleDouble::from(0.3), DoubleDouble::from(1.2)];
    let mut taylor = DoubleDoubleTaylor::new();
    let y1 = taylor
        .advance(
            &system,
            DoubleDouble::ZERO,
            &y0,
            DoubleDouble::from(20.0),
            1e-32,
        )
        .unwrap();
    let drift = (energy(&y1) - energy(&y0)).abs().to_f64();
    assert!(drift < 1e-28, "energy drift {drift:e}");
    let mut double = Integrator::new(Method::Taylor { tol: 1e-16 }).unwrap();
    let z = double.advance(&system, 0.0, &[0.3, 1.2], 20.0).unwrap();
    for i in 0..2 {
        assert!(
            (y1[i].to_f64() - z[i]).abs() < 1e-12,
            "{i}: {:?} against {}",
            y1[i],
            z[i]
        );
    }
    // Backwards to the start.
    let back = taylor
        .advance(
            &system,
            DoubleDouble::from(20.0),
            &y1,
            DoubleDouble::ZERO,
            1e-32,
        )
        .unwrap();
    for i in 0..2 {
        let error = (back[i] - y0[i]).abs().to_f64();
        assert!(error < 1e-26, "return error {error:e}");
    }
}

/// Kapitza's period map through the model's erased system (as the
/// analyses by name reach it): double-double equals double precision to
/// 10⁻¹³, and halving the tolerance's digits moves it by less than 10⁻²⁰.
#[test]
fn the_period_map_in_double_double_equals_double_precision() {
    let model = models::by_name("kapitza").unwrap();
    let Some(FixedSize::Dof1(fixed)) = model.sized else {
        panic!("kapitza has one degree of freedom")
    };
    let params = kapitza::Params {
        A: 1.0,
        eps: 0.1,
        mu: 0.0,
    }
    .values();
    let period = fixed.phase_period(&params).unwrap();
    let system = fixed.exact(&params);
    let y0 = [0.2, -0.1];
    let mut double = Integrator::new(Method::Taylor { tol: 1e-16 }).unwrap();
    let z = double.advance(&system, 0.0, &y0, period).unwrap();
    let period_dd = DoubleDouble::TAU * 0.1;
    let mut taylor = DoubleDoubleTaylor::new();
    let start = y0.map(DoubleDouble::from);
    let fine = taylor
        .advance(&system, DoubleDouble::ZERO, &start, period_dd, 1e-32)
        .unwrap();
    let coarse = taylor
        .advance(&system, DoubleDouble::ZERO, &start, period_dd, 1e-22)
        .unwrap();
    for i in 0..2 {
        assert!(
            (fine[i].to_f64() - z[i]).abs() < 1e-13,
            "{i}: {:?} against {}",
            fine[i],
            z[i]
        );
        assert!((fine[i] - coarse[i]).abs().to_f64() < 1e-20);
    }
}

/// A system whose recurrences are not compiled for double-double says so.
#[test]
fn a_larger_model_has_no_double_double_recurrences() {
    let model = models::by_name("double_pendulum").unwrap();
    let Some(FixedSize::Dof2(fixed)) = model.sized else {
        panic!("two degrees of freedom")
    };
    let system = fixed.exact(&model.dynamic.defaults());
    let start = [DoubleDouble::from(0.1); 4];
    let error = DoubleDoubleTaylor::new()
        .advance(
            &system,
            DoubleDouble::ZERO,
            &start,
            DoubleDouble::ONE,
            1e-30,
        )
        .unwrap_err();
    assert_eq!(error, mechlab::ode::OdeError::TaylorUnavailable);
}

/// The generated action system: its Taylor recurrences against its
/// right-hand side (the generated H) by DOP853 over one period, and the
/// same in double-double; the fourth component is the phase θ = t/ε.
#[test]
fn the_action_system_integrates_p_dq_minus_h_dt() {
    let model = models::by_name("kapitza").unwrap();
    let params = kapitza::Params {
        A: 1.0,
        eps: 0.1,
        mu: 0.0,
    }
    .values();
    let system = mechlab::ode::ErasedSystem {
        system: model.dynamic.action_system().unwrap(),
        params,
    };
    let period = std::f64::consts::TAU * 0.1;
    let start = [0.4, 0.9, 0.0, 0.0];
    let mut taylor = Integrator::new(Method::Taylor { tol: 1e-16 }).unwrap();
    let by_taylor = taylor.advance(&system, 0.0, &start, period).unwrap();
    let mut dop = Integrator::new(Method::Dop853 {
        rtol: 1e-13,
        atol: 1e-13,
    })
    .unwrap();
    let by_rhs = dop.advance(&system, 0.0, &start, period).unwrap();
    for i in 0..4 {
        assert!(
            (by_taylor[i] - by_rhs[i]).abs() < 1e-11,
            "{i}: {by_taylor:?} {by_rhs:?}"
        );
    }
    assert!((by_taylor[3] - 2.0 * std::f64::consts::PI).abs() < 1e-12);
    let precise = DoubleDoubleTaylor::new()
        .advance(
            &system,
            DoubleDouble::ZERO,
            &start.map(DoubleDouble::from),
            DoubleDouble::TAU * 0.1,
            1e-32,
        )
        .unwrap();
    for i in 0..4 {
        assert!((precise[i].to_f64() - by_taylor[i]).abs() < 1e-13);
    }
}

/// The f64 Taylor coefficients (Cauchy sums with fused multiply–adds where
/// the processor has them, `series::fused`) against the same recurrences in
/// double-double: every coefficient of Kapitza's solution to order 24 within
/// 256 rounding units of its row's largest coefficient (61 measured: the
/// high orders cancel). A wrong or lost term would be off by far more.
#[test]
fn fused_f64_coefficients_equal_double_double_to_rounding() {
    use mechlab::ode::TaylorWork;
    const ORDER: usize = 24;
    let params = kapitza::Params {
        A: 1.5,
        eps: 0.1,
        mu: 0.02,
    };
    let (t, y) = (0.37, [2.5, -0.4]);
    let mut single = [[0.0; 2]; ORDER + 1];
    kapitza::exact_taylor(
        t,
        &y,
        &params,
        ORDER,
        &mut TaylorWork::default(),
        &mut single,
    );
    let mut double = [[DoubleDouble::ZERO; 2]; ORDER + 1];
    let y_dd = y.map(DoubleDouble::from);
    kapitza::exact_taylor(
        DoubleDouble::from(t),
        &y_dd,
        &params.splat(),
        ORDER,
        &mut TaylorWork::default(),
        &mut double,
    );
    for k in 1..=ORDER {
        let scale = double[k]
            .iter()
            .map(|c| c.to_f64().abs())
            .fold(0.0, f64::max);
        for i in 0..2 {
            let error = (single[k][i] - double[k][i].to_f64()).abs();
            assert!(
                error <= 256.0 * f64::EPSILON * scale,
                "order {k}, component {i}: {} against {:?} ({error:e})",
                single[k][i],
                double[k][i]
            );
        }
    }
}
