//! The readable-forms stage of the derivation (`crates/simplify`), tested
//! directly: it is plain Rust (no Symbolica, so a test may run it).

use mechlab_model as model;
use mechlab_simplify as simplify;

use model::Expr;

fn vocabulary(keys: &[&str], phase: Option<&str>) -> simplify::Vocabulary {
    simplify::Vocabulary {
        keys: keys.iter().map(|k| k.to_string()).collect(),
        phase: phase.map(str::to_string),
        coordinates: vec!["q".into(), "phi1".into(), "phi2".into()],
    }
}

/// The readable form, checked against the input at random points.
fn readable(text: &str, keys: &[&str], phase: Option<&str>) -> String {
    let e = simplify::simplify(text, &vocabulary(keys, phase)).unwrap();
    simplify::verify(text, &e, 7, &Default::default()).unwrap();
    e.to_string()
}

#[test]
fn pythagoras_and_addition_formulas_are_applied() {
    assert_eq!(readable("m*sin(x)^2 + m*cos(x)^2", &[], None), "m");
    assert_eq!(
        readable("sin(phi1)*cos(phi2) - cos(phi1)*sin(phi2)", &[], None),
        "sin(phi1-phi2)"
    );
    assert_eq!(
        readable("cos(phi1)*cos(phi2) + sin(phi1)*sin(phi2)", &[], None),
        "cos(phi1-phi2)"
    );
}

#[test]
fn inclined_line_and_elastic_pendulum_come_out_short() {
    // Pivot vibrating along a line at α: (A²/4) sin²(q − α).
    let inclined = readable("(A*sin(q)*cos(alpha) - A*cos(q)*sin(alpha))^2/4", &[], None);
    assert_eq!(inclined, "A^2*sin(q-alpha)^2/4");
    assert_eq!(
        readable("(a^2*m*sin(phi)^2 + a^2*m*cos(phi)^2)/4", &[], None),
        "a^2*m/4"
    );
}

#[test]
fn fractions_are_reduced_with_a_positive_denominator() {
    // −(m1 + m2 sin²Δ) written out in products of single angles.
    let den = "(-m2 + 2*m2*sin(phi1)*sin(phi2)*cos(phi1)*cos(phi2) + m2*sin(phi1)^2*sin(phi2)^2 + m2*cos(phi1)^2*cos(phi2)^2 - m1)";
    assert_eq!(
        readable(&format!("2*l1^2*a/{den}"), &[], None),
        "-2*a*l1^2/(m1+m2*sin(phi1-phi2)^2)"
    );
    assert_eq!(readable(&format!("{den}/(3*{den})"), &[], None), "1/3");
}

#[test]
fn the_fast_phase_stays_a_plain_factor_and_keys_group_the_terms() {
    let h = readable(
        "(p - A*sin(q)*sin(theta))^2/2 + cos(q)",
        &["p"],
        Some("theta"),
    );
    // One fraction per power of p; the derivation adds V as a separate part.
    assert_eq!(
        h,
        "p^2/2-A*p*sin(q)*sin(theta)+(2*cos(q)+A^2*sin(q)^2*sin(theta)^2)/2"
    );
}

/// A small deterministic generator of random trigonometric rational
/// expressions: products and sums of sines and cosines of angle
/// combinations, parameters, a fast phase and a key variable.
fn next(state: &mut u64, n: u64) -> u64 {
    *state ^= *state << 13;
    *state ^= *state >> 7;
    *state ^= *state << 17;
    *state % n
}

fn random_expression(state: &mut u64, depth: u32) -> String {
    if depth == 0 {
        let atoms = [
            "sin(x)",
            "cos(x)",
            "sin(y)",
            "cos(y)",
            "sin(x-y)",
            "cos(2*x+y)",
            "a",
            "b",
            "p",
            "sin(th)",
            "cos(th)",
            "2",
            "3",
        ];
        return atoms[next(state, atoms.len() as u64) as usize].to_string();
    }
    let (l, r) = (
        random_expression(state, depth - 1),
        random_expression(state, depth - 1),
    );
    match next(state, 5) {
        0 | 1 => format!("({l})*({r})"),
        2 => format!("({l})+({r})"),
        3 => format!("({l})-({r})"),
        _ => format!("({l})/(2+({r})^2)"),
    }
}

#[test]
fn random_expressions_keep_their_values() {
    let mut state = 0x9e3779b97f4a7c15u64;
    for _ in 0..300 {
        let text = random_expression(&mut state, 3);
        let e = simplify::simplify(&text, &vocabulary(&["p"], Some("th"))).unwrap();
        simplify::verify(&text, &e, 11, &Default::default())
            .unwrap_or_else(|err| panic!("{text}: {err}"));
    }
}

#[test]
fn verification_catches_a_wrong_form() {
    let wrong = Expr::parse("cos(q)^2").unwrap();
    assert!(simplify::verify("sin(q)^2", &wrong, 3, &Default::default()).is_err());
    let right = Expr::parse("1-cos(q)^2").unwrap();
    assert!(simplify::verify("sin(q)^2", &right, 3, &Default::default()).is_ok());
}

/// A form defined only near the model's start (a bead's height
/// −√(R² − x²)) is checked there: random points with x > R are skipped and
/// the points drawn near the start instead, where a wrong form is still
/// caught; a form undefined where the derived one is defined is wrong.
#[test]
fn verification_samples_where_the_model_is_defined() {
    let start: simplify::Start = [("x".to_string(), 0.2), ("R".to_string(), 0.4)].into();
    let derived = "-(R^2 - x^2)^(1/2)*x";
    let right = Expr::parse("-x*sqrt(R^2 - x^2)").unwrap();
    assert!(simplify::verify(derived, &right, 5, &start).is_ok());
    let wrong = Expr::parse("-x*sqrt(R^2 - x^2 + x^4)").unwrap();
    assert!(matches!(
        simplify::verify(derived, &wrong, 5, &start),
        Err(simplify::SimplifyError::Differs { .. })
    ));
    let narrower = Expr::parse("-x*sqrt(R - x)*sqrt(R + x)*sqrt(x - R/2)/sqrt(x - R/2)").unwrap();
    assert!(simplify::verify(derived, &narrower, 5, &start).is_err());
    // Undefined everywhere: named, not a NaN compared with a NaN.
    let nowhere = Expr::parse("sqrt(-1 - x^2)").unwrap();
    assert!(matches!(
        simplify::verify("(-1 - x^2)^(1/2)", &nowhere, 5, &start),
        Err(simplify::SimplifyError::Undefined { tried: 64 })
    ));
}

/// Symbolica prints exp(x) as 𝑒^x; its printed results are read back
/// with exp() in its place, equal in value.
#[test]
fn symbolicas_euler_powers_are_read_as_exp() {
    let printed = "1/2*𝑒^(x^2)-𝑒^cos(x)*𝑒+log(x)";
    let read = Expr::parse_printed(printed).unwrap();
    assert_eq!(read.to_string(), "1/2*exp(x^2)-exp(cos(x))*exp(1)+log(x)");
    let x = 0.7_f64;
    let by_hand = 0.5 * (x * x).exp() - x.cos().exp() * std::f64::consts::E + x.ln();
    let value = read.eval(&|s| (s == "x").then_some(x)).unwrap();
    assert!((value - by_hand).abs() < 1e-15 * by_hand.abs().max(1.0));
    assert!(Expr::parse("𝑒^x").is_err(), "a model file names exp()");
}
