//! Malformed model files give errors naming the file, the key and the reason.
//! The library compiles the same reader as `build.rs`.

use mechlab_model::{Model, ModelError};

const GOOD: &str = r#"
name = "toy"
description = "a pendulum"
lagrangian = "qd^2/2 + k*cos(q)"

[[coordinates]]
name = "q"
velocity = "qd"
periodic = true

[[parameters]]
name = "k"
default = 1.0
description = "stiffness"
"#;

fn error(text: &str) -> ModelError {
    Model::parse("models/toy.toml", text).expect_err("the model should be rejected")
}

fn assert_error(text: &str, key: &str, reason_part: &str) {
    let e = error(text);
    assert_eq!(e.file, "models/toy.toml");
    assert_eq!(e.key, key, "wrong key in: {e}");
    assert!(
        e.reason.contains(reason_part),
        "reason '{}' lacks '{reason_part}'",
        e.reason
    );
    let shown = e.to_string();
    assert!(shown.starts_with("models/toy.toml: key `"), "{shown}");
}

#[test]
fn the_reference_model_is_accepted() {
    let model = Model::parse("models/toy.toml", GOOD).unwrap();
    assert_eq!(model.dof(), 1);
    assert_eq!(model.parameters[0].default, 1.0);
}

#[test]
fn the_shipped_models_are_accepted() {
    for info in mechlab::models::ALL {
        Model::parse(info.source_file, info.source).unwrap_or_else(|e| panic!("{e}"));
    }
    // The opt-in models of models/extra/ (not built by default).
    let file = "models/extra/six_link_pendulum.toml";
    let text = include_str!("../models/extra/six_link_pendulum.toml");
    let model = Model::parse(file, text).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        (model.dof(), model.inverse),
        (6, mechlab_model::Inverse::Numeric)
    );
}

#[test]
fn unknown_key() {
    assert_error(
        &GOOD.replace("[[parameters]]", "colour = \"red\"\n[[parameters]]"),
        "coordinates.colour",
        "unknown field `colour`",
    );
}

#[test]
fn non_numeric_default() {
    assert_error(
        &GOOD.replace("default = 1.0", "default = \"one\""),
        "parameters.default",
        "invalid type",
    );
}

#[test]
fn unknown_symbol() {
    assert_error(
        &GOOD.replace("k*cos(q)", "k*cos(q) + g*q"),
        "lagrangian",
        "unknown symbol 'g'",
    );
}

#[test]
fn unknown_function() {
    assert_error(
        &GOOD.replace("k*cos(q)", "k*cosh(q)"),
        "lagrangian",
        "unknown function 'cosh'",
    );
}

#[test]
fn malformed_expression() {
    assert_error(
        &GOOD.replace("k*cos(q)", "k*cos(q"),
        "lagrangian",
        "cannot parse",
    );
}

#[test]
fn not_quadratic_in_velocities() {
    assert_error(
        &GOOD.replace("qd^2/2", "qd^4/4"),
        "lagrangian",
        "not quadratic in the velocities",
    );
}

#[test]
fn singular_mass_matrix() {
    let two = GOOD
        .replace("qd^2/2 + k*cos(q)", "(qd + sd)^2/2 + k*cos(q)")
        .replace(
            "[[parameters]]",
            "[[coordinates]]\nname = \"s\"\nvelocity = \"sd\"\n\n[[parameters]]",
        );
    assert_error(&two, "lagrangian", "singular or not positive definite");
}

#[test]
fn negative_kinetic_energy() {
    assert_error(
        &GOOD.replace("qd^2/2", "-qd^2/2"),
        "lagrangian",
        "not positive definite",
    );
}

#[test]
fn duplicate_name() {
    assert_error(
        &GOOD.replace("name = \"k\"", "name = \"q\""),
        "parameters[0].name",
        "declared twice",
    );
}

#[test]
fn reserved_name() {
    assert_error(
        &GOOD.replace("name = \"k\"", "name = \"pi\""),
        "parameters[0].name",
        "reserved",
    );
}

#[test]
fn a_model_named_by_a_rust_keyword_is_refused_before_code_is_generated() {
    // The model's module is named after it: `pub mod type` would not compile.
    for keyword in ["type", "box", "loop", "match", "fn", "self", "gen"] {
        assert_error(
            &GOOD.replace("name = \"toy\"", &format!("name = \"{keyword}\"")),
            "name",
            &format!("'{keyword}' is a Rust keyword"),
        );
    }
    // Names that merely contain one are fine.
    let text = GOOD.replace("name = \"toy\"", "name = \"type_model\"");
    Model::parse("models/toy.toml", &text).unwrap();
}

#[test]
fn force_on_unknown_coordinate() {
    assert_error(
        &format!("{GOOD}\n[forces]\nx = \"-qd\"\n"),
        "forces.x",
        "not a coordinate",
    );
}

#[test]
fn cyclic_definitions() {
    let text = GOOD.replace("k*cos(q)", "k*a") + "\n[definitions]\na = \"b + q\"\nb = \"a\"\n";
    assert_error(&text, "definitions", "cycle");
}

#[test]
fn dot_of_an_expression() {
    assert_error(
        &GOOD.replace("qd^2/2", "dot(sin(q))^2/2"),
        "lagrangian",
        "dot() takes the name",
    );
}

#[test]
fn velocities_in_a_definition() {
    let text = GOOD.replace("k*cos(q)", "k*x") + "\n[definitions]\nx = \"qd\"\n";
    assert_error(&text, "definitions.x", "unknown symbol 'qd'");
}

#[test]
fn explicit_time_with_a_fast_phase() {
    let text = GOOD.replace("k*cos(q)", "k*cos(q)*t")
        + "\n[fast_phase]\nname = \"theta\"\nrate = \"1/k\"\n";
    assert_error(
        &text,
        "lagrangian",
        "time enters only through the fast phase",
    );
}

#[test]
fn zero_phase_rate() {
    let text = GOOD.to_string() + "\n[fast_phase]\nname = \"theta\"\nrate = \"0*k\"\n";
    assert_error(&text, "fast_phase.rate", "non-zero");
}

#[test]
fn missing_lagrangian() {
    let e = error(&GOOD.replace("lagrangian = \"qd^2/2 + k*cos(q)\"", ""));
    assert_eq!(e.key, "lagrangian", "{e}");
    assert!(e.reason.contains("missing"), "{e}");
}

const CONTACTS: &str = r#"
name = "toy"
description = "a point on a rough guide"
lagrangian = "(xd^2 + yd^2)/2 + F*x - y"
rayleigh = "c*xd^2/2"

[[coordinates]]
name = "x"
velocity = "xd"

[[coordinates]]
name = "y"
velocity = "yd"

[[contacts]]
slides = "x"
held = "y"
at = "0"
friction = "mu"

[[parameters]]
name = "F"
default = 1.0
description = "pull"

[[parameters]]
name = "mu"
default = 0.5
description = "friction"

[[parameters]]
name = "c"
default = 0.1
description = "damping"
"#;

#[test]
fn a_contact_model_is_accepted() {
    let model = Model::parse("models/toy.toml", CONTACTS).unwrap();
    assert_eq!(model.contacts.len(), 1);
    assert_eq!(model.contacts[0].slides, "x");
}

#[test]
fn malformed_contacts_name_the_problem() {
    assert_error(
        &CONTACTS.replace("slides = \"x\"", "slides = \"z\""),
        "contacts[0].slides",
        "'z' is not a coordinate",
    );
    assert_error(
        &CONTACTS.replace("held = \"y\"", "held = \"x\""),
        "contacts[0].held",
        "already takes part in a contact",
    );
    assert_error(
        &CONTACTS.replace("friction = \"mu\"", "friction = \"mu*x\""),
        "contacts[0].friction",
        "unknown symbol 'x'",
    );
    assert_error(
        &CONTACTS.replace("at = \"0\"", "at = \"y0\""),
        "contacts[0].at",
        "unknown symbol 'y0'",
    );
    assert_error(
        &CONTACTS.replace("friction = \"mu\"", "friction = \"mu\"\nnormal = \"y\""),
        "contacts.normal",
        "unknown field",
    );
    let extra = CONTACTS.replace(
        "[[contacts]]",
        "[[coordinates]]\nname = \"z\"\nvelocity = \"zd\"\n\n[[contacts]]",
    );
    assert_error(&extra, "contacts", "'z' takes part in no contact");
    assert_error(
        &CONTACTS.replace("rayleigh = \"c*xd^2/2\"", "rayleigh = \"c*xd^2/2 + w\""),
        "rayleigh",
        "unknown symbol 'w'",
    );
}

/// Sizes are bounded before any recursion over an expression: a file too
/// large, an expression too long or nested too deep is an error naming the
/// key, never a stack overflow (these would overflow the parser otherwise).
#[test]
fn oversized_and_deeply_nested_models_are_errors() {
    let lagrangian = |l: &str| GOOD.replace("lagrangian = \"", &format!("lagrangian = \"{l} + "));
    let nested = format!("{}q{}", "(".repeat(5000), ")".repeat(5000));
    assert_error(
        &lagrangian(&nested),
        "lagrangian",
        "characters: an expression may have at most 10000",
    );
    let nested = format!("{}q{}", "(".repeat(150), ")".repeat(150));
    assert_error(
        &lagrangian(&nested),
        "lagrangian",
        "nested more than 100 levels deep",
    );
    let e = error(&lagrangian(&nested));
    assert!(
        e.reason.len() < 200,
        "the message quotes the expression's start only: {e}"
    );
    assert_error(
        &lagrangian(&"-".repeat(3000)),
        "lagrangian",
        "nested more than 100 levels deep",
    );
    let padding = format!("\n# {}\n", "x".repeat(300 * 1024));
    assert_error(
        &format!("{GOOD}{padding}"),
        "(file)",
        "a model file may have at most 262144",
    );
    // Long but legal: a sum of 900 terms is read (its tree is 900 deep).
    let sum: Vec<String> = (0..900).map(|i| format!("{i}*q")).collect();
    Model::parse(
        "models/toy.toml",
        &lagrangian(&format!("({})", sum.join("+"))),
    )
    .expect("a long sum within the limits is a valid expression");
}

/// A parameter's `range`: an interval read from the file, its default
/// inside it, and values outside it refused with both named.
#[test]
fn parameter_ranges() {
    use mechlab_model::Range;
    let with = |range: &str, default: &str| {
        GOOD.replace(
            "default = 1.0",
            &format!("default = {default}\nrange = \"{range}\""),
        )
    };
    let model = Model::parse("models/toy.toml", &with("(0, inf)", "1.0")).unwrap();
    let range = model.parameters[0].range;
    assert_eq!(
        (range.min, range.max, range.min_open, range.max_open),
        (0.0, f64::INFINITY, true, true)
    );
    assert!(range.contains(1e-300) && !range.contains(0.0) && !range.contains(-1.0));
    let closed = Range::parse("[-1, 2]").unwrap();
    assert!(closed.contains(-1.0) && closed.contains(2.0) && !closed.contains(2.0 + 1e-15));
    assert_eq!(closed.to_string(), "[-1, 2]");
    assert_eq!(Range::ALL.to_string(), "(-inf, inf)");
    assert_error(
        &with("(0, inf)", "-0.5"),
        "parameters[0].default",
        "outside its range (0, inf)",
    );
    assert_error(
        &with("[0, 1)", "1.0"),
        "parameters[0].default",
        "outside its range [0, 1)",
    );
    assert_error(
        &with("0, 1", "1.0"),
        "parameters[0].range",
        "is not an interval",
    );
    assert_error(&with("(2, 1)", "1.0"), "parameters[0].range", "is empty");
    assert_error(
        &with("(0, nan)", "1.0"),
        "parameters[0].range",
        "is not an interval",
    );
}

/// A negative ε gave the generic scenes a negative period: the shipped
/// models declare their ranges, and a scene refuses a value outside one.
#[test]
fn a_scene_refuses_a_parameter_outside_its_range() {
    use mechlab::scene::{parameter_knobs, Scene};
    let info = mechlab::models::by_name("kapitza").unwrap().info;
    let knobs = parameter_knobs(info, &[]);
    let args = |eps: &str| vec!["--set".to_string(), format!("eps={eps}")];
    let scene = Scene::parse("stability", &knobs, &args("-0.1")).unwrap();
    let e = scene.parameter_values(info).unwrap_err().to_string();
    assert!(
        e.contains("'eps'") && e.contains("(0, inf)") && e.contains("-0.1"),
        "{e}"
    );
    let scene = Scene::parse("stability", &knobs, &args("0.05")).unwrap();
    assert_eq!(scene.parameter_values(info).unwrap()[1], 0.05);
    // Params::set keeps the same rule.
    let mut params = mechlab::models::kapitza::Params::default();
    assert!(params.set("eps", 0.0).is_err() && params.set("mu", -1.0).is_err());
    params.set("eps", 0.2).unwrap();
    assert_eq!(params.eps, 0.2);
}

/// A point on a rod of length l about the origin, in Cartesian coordinates.
const ROD: &str = r#"
name = "toy"
description = "a point on a rod"
lagrangian = "(dot(x)^2 + dot(y)^2)/2 - g*y"

[[coordinates]]
name = "x"
velocity = "xd"
start = 0.6

[[coordinates]]
name = "y"
velocity = "yd"
start = "-0.8*l"

[[constraints]]
name = "rod"
position = "x^2 + y^2 - l^2"

[[parameters]]
name = "g"
default = 1.0
description = "gravity"

[[parameters]]
name = "l"
default = 1.0
description = "rod length"
"#;

#[test]
fn a_constrained_model_is_accepted() {
    let model = Model::parse("models/toy.toml", ROD).unwrap();
    assert_eq!((model.dof(), model.constraints.len()), (2, 1));
}

#[test]
fn starts_that_violate_a_constraint_are_named_with_the_residual() {
    let text = ROD.replace("start = 0.6", "start = 0.5");
    // 0.25 + 0.64 − 1 = −0.11.
    assert_error(&text, "constraints[0].position", "its value there is -1.1");
}

#[test]
fn a_constrained_model_needs_a_start_for_every_coordinate() {
    let text = ROD.replace("start = 0.6\n", "");
    assert_error(&text, "coordinates[0].start", "needs a start for 'x'");
}

/// A constraint that repeats others is kept (its reaction is
/// indeterminate, the motion the same); one that contradicts them is named.
#[test]
fn redundant_constraints_are_kept_and_inconsistent_ones_named() {
    let with = |extra: &str| {
        ROD.replace("- g*y", "+ dot(z)^2/2 - g*y").replace(
            "[[parameters]]\nname = \"g\"",
            &format!("{extra}[[coordinates]]\nname = \"z\"\nvelocity = \"zd\"\nstart = 0\n\n[[parameters]]\nname = \"g\""),
        )
    };
    let again = "[[constraints]]\nname = \"again\"\nposition = \"2*(x^2 + y^2 - l^2)\"\n\n";
    let model = Model::parse("models/toy.toml", &with(again)).expect("a redundant constraint");
    assert_eq!(model.constraints.len(), 2);
    let moving = "[[constraints]]\nname = \"slide\"\nposition = \"z - t\"\n\n[[constraints]]\nname = \"stop\"\nposition = \"2*z\"\n\n";
    assert_error(&with(moving), "constraints", "inconsistent");
}

#[test]
fn as_many_constraints_as_coordinates_leave_no_motion() {
    let text = ROD.replace(
        "[[parameters]]\nname = \"g\"",
        "[[constraints]]\nname = \"level\"\nposition = \"y + 0.8*l\"\n\n[[parameters]]\nname = \"g\"",
    );
    assert_error(&text, "constraints", "leave no motion");
}

#[test]
fn a_constraint_gives_exactly_one_form() {
    let text = ROD.replace(
        "position = \"x^2 + y^2 - l^2\"",
        "position = \"x^2 + y^2 - l^2\"\nvelocity = \"x*xd + y*yd\"",
    );
    assert_error(&text, "constraints[0]", "exactly one of `position`");
}

#[test]
fn a_velocity_constraint_must_be_linear_and_not_integrable() {
    // Three coordinates, so that a non-integrable row exists at all.
    let knife = |row: &str| {
        ROD.replace("lagrangian = \"(dot(x)^2 + dot(y)^2)/2 - g*y\"", "lagrangian = \"(dot(x)^2 + dot(y)^2 + dot(phi)^2)/2 - g*y\"")
            .replace(
                "[[constraints]]\nname = \"rod\"\nposition = \"x^2 + y^2 - l^2\"",
                &format!("[[coordinates]]\nname = \"phi\"\nvelocity = \"phid\"\nstart = 0\n\n[[constraints]]\nname = \"blade\"\nvelocity = \"{row}\""),
            )
    };
    // The knife edge (Chaplygin's sleigh) is accepted.
    Model::parse("models/toy.toml", &knife("-sin(phi)*xd + cos(phi)*yd")).unwrap();
    assert_error(
        &knife("xd^2 + yd"),
        "constraints[0].velocity",
        "not linear in the velocities",
    );
    // x' x + y' y = 0 holds x² + y² constant: a position constraint.
    assert_error(
        &knife("x*xd + y*dot(y)"),
        "constraints[0].velocity",
        "is integrable",
    );
    // dot() is for velocity constraints, not position ones.
    let text = ROD.replace("x^2 + y^2 - l^2", "dot(x)");
    assert_error(&text, "constraints[0].position", "dot() is only allowed");
    // Constraints and contacts do not mix.
    let contact = ROD.replace(
        "[[parameters]]\nname = \"g\"",
        "[[contacts]]\nslides = \"x\"\nheld = \"y\"\nat = \"0\"\nfriction = \"0.5\"\n\n[[parameters]]\nname = \"g\"",
    );
    assert_error(&contact, "constraints", "cannot be combined");
}

/// `GOOD` drawn: a pivot and a bob on a rod.
fn drawn(points: &str) -> String {
    format!("{GOOD}\n[definitions]\nbob_x = \"sin(q)\"\n{points}")
}

const PIVOT: &str = "[[points]]\nname = \"pivot\"\nat = [\"0\", \"0\"]\n";

#[test]
fn points_are_read_with_their_bars() {
    let text = drawn(&format!(
        "{PIVOT}\n[[points]]\nname = \"bob\"\nat = [\"bob_x\", \"cos(q)\"]\njoined_to = [\"pivot\"]\n"
    ));
    let model = Model::parse("models/toy.toml", &text).unwrap();
    let names: Vec<&str> = model.points.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["pivot", "bob"]);
    assert_eq!(model.points[1].joined_to, [0]);
}

#[test]
fn malformed_points_name_the_problem() {
    let bob = |at: &str, joined: &str| {
        drawn(&format!(
            "{PIVOT}\n[[points]]\nname = \"bob\"\nat = {at}\njoined_to = {joined}\n"
        ))
    };
    assert_error(
        &bob(r#"["bob_x", "cos(q)"]"#, r#"["hinge"]"#),
        "points[1].joined_to",
        "'hinge' is not a point declared before 'bob'",
    );
    assert_error(
        &bob(r#"["bob_x", "cos(q)", "0", "1"]"#, "[]"),
        "points[1].at",
        "as [x, y] or [x, y, z]: 4 expressions given",
    );
    assert_error(
        &bob(r#"["dot(bob_x)", "cos(q)"]"#, "[]"),
        "points[1].at",
        "dot() is only allowed",
    );
    assert_error(
        &bob(r#"["qd", "cos(q)"]"#, "[]"),
        "points[1].at",
        "unknown symbol 'qd'",
    );
    assert_error(
        &drawn(&format!("{PIVOT}\n{PIVOT}")),
        "points[1].name",
        "'pivot' names two points",
    );
    let too_many: String = (0..=mechlab_model::MAX_POINTS)
        .map(|i| PIVOT.replace("\"pivot\"", &format!("\"p{i}\"")) + "\n")
        .collect();
    assert_error(&drawn(&too_many), "points", "a drawing has at most 64");
    assert_error(
        &format!("{CONTACTS}\n{PIVOT}"),
        "points",
        "a model with contacts cannot be drawn yet",
    );
}

/// A body's rotation that is not a sequence of X(angle), Y(angle), Z(angle)
/// is refused with the body's key; a body whose centre's or point's name
/// is taken by a definition is refused with the definition's; a
/// well-formed body is accepted.
#[test]
fn a_malformed_body_is_named() {
    let body = |rotation: &str| {
        format!(
            "{GOOD}\n[[bodies]]\nname = \"bob\"\nmass = \"1\"\ninertia = [\"1\", \"1\", \"1\"]\nposition = [\"sin(q)\", \"0\", \"-cos(q)\"]\nrotation = \"{rotation}\"\n"
        )
    };
    assert_error(
        &body("W(q)"),
        "bodies[0].rotation",
        "X(angle), Y(angle) or Z(angle)",
    );
    assert_error(&body("Y q"), "bodies[0].rotation", "parentheses");
    let clash = body("Y(q)").replace("[[bodies]]", "[definitions]\nbob_x = \"q\"\n\n[[bodies]]");
    assert_error(&clash, "definitions.bob_x", "the centre of a body");
    assert_error(&body("Y(w)"), "bodies[0].rotation", "unknown symbol 'w'");
    let tensor = |inertia: &str| body("Y(q)").replace("[\"1\", \"1\", \"1\"]", inertia);
    assert_error(
        &tensor("[[1, 2, 0], [3, 1, 0], [0, 0, 1]]"),
        "bodies[0].inertia",
        "not symmetric",
    );
    assert_error(
        &tensor("[1, 2]"),
        "bodies[0].inertia",
        "three principal moments",
    );
    assert_error(
        &tensor("[\"1\", \"q\", \"1\"]"),
        "bodies[0].inertia",
        "unknown symbol 'q'",
    );
    let gravity = body("Y(q)").replace(
        "[[coordinates]]",
        "gravity = [0, 0, \"-g\"]\n\n[[coordinates]]",
    );
    assert_error(&gravity, "gravity", "unknown symbol 'g'");
    Model::parse("models/toy.toml", &body("Y(q)")).expect("a body about its y axis");
    Model::parse("models/toy.toml", &body("Y(-q) X(k/2)")).expect("angles as expressions");
    let both = body("Y(q)").replace(
        "rotation =",
        "quaternion = [\"q\", \"q\", \"q\", \"q\"]\nrotation =",
    );
    assert_error(&both, "bodies[0].quaternion", "give the orientation once");
    let unknown = body("").replace(
        "rotation =",
        "quaternion = [\"q\", \"a\", \"b\", \"c\"]\nrotation =",
    );
    assert_error(&unknown, "bodies[0].quaternion", "'a' is not a coordinate");
    // Points fixed in the body and its centre: names, offsets in the
    // parameters, and their definitions' names free.
    let fixed = |extra: &str| body("Y(q)") + extra;
    assert_error(
        &fixed("points = { 2tip = [0, 0, 1] }\n"),
        "bodies[0].points.2tip",
        "not an identifier",
    );
    assert_error(
        &fixed("points = { tip = [0, 0, \"q\"] }\n"),
        "bodies[0].points.tip",
        "unknown symbol 'q'",
    );
    assert_error(
        &fixed("centre = [0, 0, \"w\"]\n"),
        "bodies[0].centre",
        "unknown symbol 'w'",
    );
    let taken = fixed("points = { tip = [0, 0, 1] }\n").replace(
        "[[bodies]]",
        "[definitions]\nbob_tip_z = \"q\"\n\n[[bodies]]",
    );
    assert_error(&taken, "definitions.bob_tip_z", "a point of a body");
    Model::parse(
        "models/toy.toml",
        &fixed("centre = [0, 0, 0.5]\npoints = { tip = [0, 0, 1] }\n"),
    )
    .expect("a centre and a point fixed in the body");
    // The body is drawn as its frame, points named as the body and its
    // axes' tips: the file's points may join them but not take their names.
    let drawn = |point: &str, joined: &str| {
        body("Y(q)")
            + &format!("\n[[points]]\nname = \"{point}\"\nat = [\"0\", \"0\", \"0\"]\njoined_to = [\"{joined}\"]\n")
    };
    assert_error(
        &drawn("bob_axis_y", "bob"),
        "points[0].name",
        "'bob_axis_y' names two points (each body is drawn as its frame",
    );
    let pivot =
        Model::parse("models/toy.toml", &drawn("pivot", "bob")).expect("joined to the body");
    assert_eq!(pivot.body_frames, [[0, 1, 2, 3]]);
    assert_eq!(pivot.points[4].joined_to, [0]);
}

/// A file of `test_models/` and its text.
fn test_model(name: &str) -> (String, String) {
    let path = format!("{}/../test_models/{name}.toml", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(path).unwrap();
    (format!("test_models/{name}.toml"), text)
}

/// `text` with `from` replaced by `to` is refused at `key`, for a reason
/// that contains `reason`.
fn assert_edit_named(file: &str, text: &str, (from, to): (&str, &str), key: &str, reason: &str) {
    let edited = text.replace(from, to);
    assert_ne!(edited, text, "'{from}' is not in {file}");
    let e = Model::parse(file, &edited).unwrap_err();
    assert_eq!(e.key, key, "{e}");
    assert!(e.reason.contains(reason), "{e}");
}

/// A rolling body's constraint names its body, and its contact must be
/// where the body touches the plane.
#[test]
fn a_rolling_constraint_is_checked_against_its_body() {
    let (file, text) = test_model("tipping_disk_body");
    Model::parse(&file, &text).expect("the disk rolls at its lowest point");
    let edit = |from: &str, to: &str, key: &str, reason: &str| {
        assert_edit_named(&file, &text, (from, to), key, reason)
    };
    edit(
        "contact = [\"x\", \"y\", 0]",
        "contact = [\"disk_x\", \"disk_y\", 0]",
        "constraints[0].contact",
        "moves off the plane",
    );
    edit(
        "rolling = \"disk\"",
        "rolling = \"wheel\"",
        "constraints[0].rolling",
        "not one of the model's [[bodies]]",
    );
}

/// A massless part (a coordinate without kinetic energy) is accepted when
/// the constraints hold it; one they leave free, a model without any mass
/// on its motion, and a kinetic energy negative along some velocity are
/// named.
#[test]
fn massless_parts_are_accepted_where_the_constraints_hold_them() {
    let with_z = |constraint: &str| {
        ROD.replace(
            "[[parameters]]\nname = \"g\"",
            &format!("[[coordinates]]\nname = \"z\"\nvelocity = \"zd\"\nstart = 0.6\n\n{constraint}[[parameters]]\nname = \"g\""),
        )
    };
    let held = "[[constraints]]\nname = \"follower\"\nposition = \"z - x\"\n\n";
    let model = Model::parse("models/toy.toml", &with_z(held)).expect("a held massless part");
    assert!(model.has_massless_parts());
    assert!(!Model::parse("models/toy.toml", ROD)
        .unwrap()
        .has_massless_parts());
    assert_error(
        &with_z(""),
        "lagrangian",
        "singular along a motion the constraints allow",
    );
    let massless_point = ROD.replace("(dot(x)^2 + dot(y)^2)/2 - g*y", "-g*y");
    assert_error(
        &massless_point,
        "lagrangian",
        "singular along a motion the constraints allow",
    );
    let negative = ROD.replace("(dot(x)^2 + dot(y)^2)/2", "(dot(x)^2 - dot(y)^2)/2");
    assert_error(&negative, "lagrangian", "not positive semidefinite");
}

/// A starting rate is held at the start of a constrained model and read
/// by one without constraints; rates the constraints cannot complete, and
/// one in a model with contacts, are named.
#[test]
fn starting_rates_must_be_ones_the_constraints_allow() {
    let rated = |x: &str, y: &str| {
        ROD.replace("start = 0.6\n", &format!("start = 0.6\n{x}"))
            .replace("start = \"-0.8*l\"\n", &format!("start = \"-0.8*l\"\n{y}"))
    };
    // 2x x' + 2y y' = 0 at (0.6, −0.8): y' = 0.75 x'.
    let model = Model::parse("models/toy.toml", &rated("start_rate = 1.0\n", ""))
        .expect("a rate the rod allows");
    assert!(model.coordinates[0].start_rate.is_some());
    assert_error(
        &rated("start_rate = 1.0\n", "start_rate = 1.0\n"),
        "coordinates[0].start_rate",
        "leave no velocity of the other coordinates",
    );
    let free = GOOD.replace("periodic = true\n", "periodic = true\nstart_rate = 1.0\n");
    let model = Model::parse("models/toy.toml", &free).expect("a rate of a free model");
    assert!(model.coordinates[0].start_rate.is_some());
    let in_contact = CONTACTS.replace(
        "velocity = \"xd\"\n",
        "velocity = \"xd\"\nstart_rate = 1.0\n",
    );
    assert_error(
        &in_contact,
        "coordinates[0].start_rate",
        "not read by a model with contacts",
    );
}

/// The tippe top in Euler angles (a model without constraints): its ball
/// slides on the floor at the lowest point, k = (sin θ sin φ, −sin θ cos φ,
/// cos θ) the symmetry axis.
const SLIDING_BALL: &str = r#"
name = "toy"
description = "a ball with a low centre of mass sliding on the floor"
gravity = [0, 0, "-g"]

[[coordinates]]
name = "x"
velocity = "xd"

[[coordinates]]
name = "y"
velocity = "yd"

[[coordinates]]
name = "phi"
velocity = "phid"

[[coordinates]]
name = "theta"
velocity = "thetad"
start = 0.5

[[coordinates]]
name = "psi"
velocity = "psid"

[[sliding]]
name = "floor"
body = "ball"
contact = ["x + a*sin(theta)*sin(phi)", "y - a*sin(theta)*cos(phi)", 0]
damping = "mu"

[[bodies]]
name = "ball"
mass = 1
inertia = [0.9, 0.9, 1]
position = ["x", "y", "1 - a*cos(theta)"]
rotation = "Z(phi) X(theta) Z(psi)"

[[parameters]]
name = "a"
default = 0.3
description = "a"

[[parameters]]
name = "mu"
default = 0.1
description = "mu"

[[parameters]]
name = "g"
default = 9.81
description = "g"
"#;

/// A sliding contact adds its friction to the Rayleigh function, names its
/// body, and must be where the body touches the plane, with or without
/// constraints (the tippe top in Euler parameters and in Euler angles).
#[test]
fn a_sliding_contact_is_checked_against_its_body() {
    let (file, text) = test_model("tippe_top");
    let model = Model::parse(&file, &text).expect("the ball slides at its lowest point");
    assert!(model.rayleigh.symbols().contains("mu"));
    let edit = |from: &str, to: &str, key: &str, reason: &str| {
        assert_edit_named(&file, &text, (from, to), key, reason)
    };
    edit(
        "contact = [\"x + a*kx\", \"y + a*ky\", 0]",
        "contact = [\"x\", \"y\", 0]",
        "sliding[0].contact",
        "moves off the plane",
    );
    edit(
        "body = \"top\"",
        "body = \"ball\"",
        "sliding[0].body",
        "not one of the model's [[bodies]]",
    );
    edit(
        "damping = \"mu\"",
        "damping = \"mu*x\"",
        "sliding[0].damping",
        "",
    );

    let ball = Model::parse("models/toy.toml", SLIDING_BALL).expect("the ball in Euler angles");
    assert!(ball.constraints.is_empty() && ball.sliding.len() == 1);
    let block = "[[sliding]]\nname = \"floor\"\n";
    let twice = SLIDING_BALL.replacen(
        block,
        &format!(
            "{block}body = \"ball\"\ncontact = [\"x\", \"y\", 0]\ndamping = \"mu\"\n\n{block}"
        ),
        1,
    );
    assert_error(&twice, "sliding[1].name", "names two sliding contacts");
    let off = SLIDING_BALL.replace("y - a*sin(theta)*cos(phi)", "y + a*sin(theta)*cos(phi)");
    assert_error(&off, "sliding[0].contact", "moves off the plane");
}

/// tan(u) reaches the derivation as sin(u)/cos(u), whose derivatives stay
/// in sines and cosines (the computer algebra's own tan differentiates to
/// sec, which the readable forms cannot evaluate); `pi` is not built in
/// and its error says what to write.
#[test]
fn tan_is_read_as_a_quotient_and_pi_is_named_with_its_remedy() {
    let with_tan = GOOD.replace("k*cos(q)", "k*tan(q/2)^2");
    let model = Model::parse("models/toy.toml", &with_tan).unwrap();
    let lagrangian = model.lagrangian.to_string();
    assert!(
        lagrangian.contains("sin(q/2)/cos(q/2)") && !lagrangian.contains("tan"),
        "{lagrangian}"
    );
    let x = 0.4_f64;
    let value = model
        .lagrangian
        .eval(&|s| match s {
            "q" => Some(x),
            "qd" => Some(0.0),
            "k" => Some(1.0),
            _ => None,
        })
        .unwrap();
    assert!((value - (x / 2.0).tan().powi(2)).abs() < 1e-15);
    assert_error(
        &GOOD.replace("k*cos(q)", "k*cos(2*pi*q)"),
        "lagrangian",
        "declare a parameter such as `Pi`",
    );
}
