//! Rigid bodies in model files (`[[bodies]]`): each body's kinetic energy,
//! ½ m v·v + ½ ωᵀ I ω, and gravity's potential, written out as text and
//! added to the Lagrangian, so that the derivation sees one Lagrangian as
//! for any model. The centre's coordinates become definitions (`<body>_x`,
//! `<body>_y`, `<body>_z`) whose `dot()` gives its velocity; the body's
//! angular velocity comes from its rotation sequence. Points fixed in a
//! body become definitions too (`<body>_<point>_x`, …), so that a chain of
//! bodies hangs each one from the one before. A point of a body has the
//! velocity v_c + ω × (p − c): the rolling constraints.

use crate::file::{ConstraintSpec, ModelFile, NumberSpec};
use serde::Deserialize;
use std::collections::BTreeMap;

/// A rigid body: its mass, its inertia about its centre in its own axes,
/// the centre's position and the body's orientation as a sequence of
/// rotations about its own axes.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    pub name: String,
    pub mass: NumberSpec,
    /// Principal moments [I_x, I_y, I_z], or the tensor
    /// [[I_xx, I_xy, I_xz], [I_xy, I_yy, I_yz], [I_xz, I_yz, I_zz]], both
    /// about the centre in the body's axes (read by [`inertia`]).
    pub inertia: toml::Value,
    /// The body's origin (x, y, z) in the fixed frame: its centre of mass
    /// unless `centre` puts that elsewhere.
    pub position: [NumberSpec; 3],
    /// The centre of mass in the body's axes, from its origin (a rod hung
    /// from its end: half its length along it). Default: at the origin.
    pub centre: Option<[NumberSpec; 3]>,
    /// Points fixed in the body, in its axes from its origin: each becomes
    /// the definitions `<body>_<point>_x`, `_y`, `_z`, its place in the
    /// fixed frame (where the next body of a chain hangs, or a joint's
    /// axis for a closure).
    #[serde(default)]
    pub points: BTreeMap<String, [NumberSpec; 3]>,
    /// Rotations about the body's own axes, each applied to the frame the
    /// ones before left: "Z(phi) X(theta) Y(psi)" (empty: the body does
    /// not turn). An angle is a coordinate or definition (it turns) or an
    /// expression of the parameters (a fixed tilt, as a steering head's).
    #[serde(default)]
    pub rotation: String,
    /// Instead of `rotation`: four coordinates (e0, e1, e2, e3), the Euler
    /// parameters (unit quaternion) of the body's orientation, a chart with
    /// no singular point; the unit norm is added as a constraint.
    pub quaternion: Option<[String; 4]>,
    #[serde(default)]
    pub description: String,
    /// The rotation's turns, read by [`name_turns`] before validation.
    #[serde(skip)]
    pub turns: Vec<Turn>,
}

/// The text of a number or expression.
pub fn text(value: &NumberSpec) -> String {
    match value {
        NumberSpec::Value(v) => format!("{v:?}"),
        NumberSpec::Expression(e) => e.clone(),
    }
}

/// Why part of a body cannot be read: the key's last part and the reason.
pub type BodyError = (&'static str, String);

/// One elementary rotation of a sequence: the body axis (0, 1, 2 for
/// x, y, z), the angle as written and the name its rate is `dot()` of:
/// the angle itself where it is a name, else a definition made for it
/// (`<body>_turn<k>`).
#[derive(Clone, Debug)]
pub struct Turn {
    pub axis: usize,
    pub angle: String,
    pub name: String,
}

/// What the bodies add to a model file before it is validated: their
/// centres, and their angles written as expressions, as definitions; the
/// unit norm of Euler parameters as a constraint. Or the key and reason
/// of a clash.
pub fn declare(spec: &mut ModelFile) -> Result<(), (String, String)> {
    let clash = |name: &String, what: &str| {
        (
            format!("definitions.{name}"),
            format!("'{name}' is {what} and a definition too"),
        )
    };
    let turns = name_turns(&mut spec.bodies)
        .map_err(|(k, (part, reason))| (format!("bodies[{k}].{part}"), reason))?;
    for (name, angle) in turns {
        if spec.definitions.insert(name.clone(), angle).is_some() {
            return Err(clash(&name, "an angle of a body"));
        }
    }
    for body in &spec.bodies {
        let centre_in_space = match &body.centre {
            Some(offset) => in_space(body, offset),
            None => body.position.clone().map(|at| text(&at)),
        };
        for (name, at) in centre(&body.name).into_iter().zip(centre_in_space) {
            if spec.definitions.insert(name.clone(), at).is_some() {
                return Err(clash(&name, "the centre of a body"));
            }
        }
        for (point, offset) in &body.points {
            let names = ["x", "y", "z"].map(|axis| format!("{}_{point}_{axis}", body.name));
            for (name, at) in names.into_iter().zip(in_space(body, offset)) {
                if spec.definitions.insert(name.clone(), at).is_some() {
                    return Err(clash(&name, "a point of a body"));
                }
            }
        }
        if let Some([e0, e1, e2, e3]) = &body.quaternion {
            spec.constraints.push(ConstraintSpec {
                name: format!("{}_unit", body.name),
                position: Some(format!("{e0}^2 + {e1}^2 + {e2}^2 + {e3}^2 - 1")),
                velocity: None,
                rolling: None,
                contact: None,
                description: format!("the Euler parameters of '{}' have unit norm", body.name),
            });
        }
    }
    Ok(())
}

/// Reads each body's rotation into its turns and returns the definitions
/// the angles that are not plain names need, or the failing body's index
/// and reason.
fn name_turns(bodies: &mut [BodySpec]) -> Result<Vec<(String, String)>, (usize, BodyError)> {
    let mut definitions = Vec::new();
    for (k, body) in bodies.iter_mut().enumerate() {
        body.turns = rotation(&body.rotation).map_err(|e| (k, e))?;
        for (i, turn) in body.turns.iter_mut().enumerate() {
            if !crate::file::is_identifier(&turn.angle) {
                turn.name = format!("{}_turn{}", body.name, i + 1);
                definitions.push((turn.name.clone(), turn.angle.clone()));
            }
        }
    }
    Ok(definitions)
}

/// Reads "A1(q1) A2(q2) …" into its turns.
pub fn rotation(sequence: &str) -> Result<Vec<Turn>, BodyError> {
    let bad = |why: &str| Err(("rotation", format!("'{sequence}': {why}")));
    let mut turns = Vec::new();
    let mut rest = sequence.trim();
    while !rest.is_empty() {
        let axis =
            match rest.as_bytes()[0] {
                b'X' => 0,
                b'Y' => 1,
                b'Z' => 2,
                _ => return bad(
                    "each rotation is X(angle), Y(angle) or Z(angle), about the body's own axis",
                ),
            };
        let inner = rest[1..].trim_start();
        if !inner.starts_with('(') {
            return bad("a rotation's angle goes in parentheses, as Z(phi)");
        }
        // The angle may itself hold parentheses: find the matching one.
        let mut depth = 0;
        let close = inner.char_indices().find_map(|(i, ch)| {
            match ch {
                '(' => depth += 1,
                ')' => depth -= 1,
                _ => {}
            }
            (depth == 0).then_some(i)
        });
        let Some(close) = close else {
            return bad("a rotation's parentheses do not close");
        };
        let angle = inner[1..close].trim();
        if angle.is_empty() {
            return bad("each rotation is an axis and an angle, as Z(phi)");
        }
        turns.push(Turn {
            axis,
            angle: angle.to_string(),
            name: angle.to_string(),
        });
        rest = inner[close + 1..].trim_start();
    }
    Ok(turns)
}

/// The inertia tensor's entries (None: zero), symmetric; principal
/// moments give a diagonal one.
pub fn inertia(value: &toml::Value) -> Result<[[Option<String>; 3]; 3], BodyError> {
    let usage = "give three principal moments [I_x, I_y, I_z] or the symmetric tensor [[I_xx, I_xy, I_xz], [I_xy, I_yy, I_yz], [I_xz, I_yz, I_zz]] about the centre, in the body's axes";
    let entry = |v: &toml::Value| -> Result<Option<String>, BodyError> {
        match v {
            toml::Value::String(s) => Ok(Some(s.clone())),
            toml::Value::Integer(0) => Ok(None),
            toml::Value::Integer(i) => Ok(Some(i.to_string())),
            toml::Value::Float(f) if *f == 0.0 => Ok(None),
            toml::Value::Float(f) => Ok(Some(format!("{f:?}"))),
            _ => Err(("inertia", usage.to_string())),
        }
    };
    let rows = match value {
        toml::Value::Array(rows) if rows.len() == 3 => rows,
        _ => return Err(("inertia", usage.to_string())),
    };
    let mut tensor: [[Option<String>; 3]; 3] = Default::default();
    if rows.iter().all(|r| !r.is_array()) {
        for (i, moment) in rows.iter().enumerate() {
            tensor[i][i] = entry(moment)?;
        }
        return Ok(tensor);
    }
    for (i, row) in rows.iter().enumerate() {
        match row {
            toml::Value::Array(row) if row.len() == 3 => {
                for (j, v) in row.iter().enumerate() {
                    tensor[i][j] = entry(v)?;
                }
            }
            _ => return Err(("inertia", usage.to_string())),
        }
    }
    for i in 0..3 {
        for j in i + 1..3 {
            let same = match (&tensor[i][j], &tensor[j][i]) {
                (Some(a), Some(b)) => a.replace(' ', "") == b.replace(' ', ""),
                (a, b) => a == b,
            };
            if !same {
                let axes = ["x", "y", "z"];
                return Err((
                    "inertia",
                    format!(
                        "the tensor is not symmetric: I_{}{} and I_{}{} differ",
                        axes[i], axes[j], axes[j], axes[i]
                    ),
                ));
            }
        }
    }
    Ok(tensor)
}

/// Where a point fixed in the body, `offset` in its axes from its origin,
/// is in the fixed frame: the origin plus R·offset, R's columns the body's
/// axes (its rotation's turns are read by then).
fn in_space(body: &BodySpec, offset: &[NumberSpec; 3]) -> [String; 3] {
    let axes = axes(body);
    std::array::from_fn(|k| {
        let mut at = Some(text(&body.position[k]));
        for (axis, along) in axes.iter().zip(offset) {
            if !matches!(along, NumberSpec::Value(v) if *v == 0.0) {
                at = sum(at, times(&text(along), &axis[k]));
            }
        }
        at.expect("the origin's component")
    })
}

/// The names of a body's centre coordinates, which are definitions.
pub fn centre(body: &str) -> [String; 3] {
    ["x", "y", "z"].map(|axis| format!("{body}_{axis}"))
}

/// A component of a vector written out: None is 0.
type Component = Option<String>;

fn sum(a: Component, b: Component) -> Component {
    match (a, b) {
        (None, b) => b,
        (a, None) => a,
        (Some(a), Some(b)) => Some(format!("{a} + {b}")),
    }
}

fn times(factor: &str, a: &Component) -> Component {
    a.as_ref().map(|a| format!("({factor})*({a})"))
}

fn product(a: &Component, b: &Component) -> Component {
    match (a, b) {
        (Some(a), Some(b)) => Some(format!("({a})*({b})")),
        _ => None,
    }
}

fn minus(a: Component) -> Component {
    a.map(|a| format!("-({a})"))
}

/// The rate of a turn's angle: `dot(name)` where the angle may move (a
/// coordinate or definition), none where it is a parameter.
fn rate(turn: &Turn, moves: &dyn Fn(&str) -> bool) -> Component {
    moves(&turn.name).then(|| format!("dot({})", turn.name))
}

/// The body's angular velocity in its own axes for the turns
/// A1(q1) A2(q2) …: ω = R_nᵀ(… R_2ᵀ(R_1ᵀ e_1 q1' + e_2 q2') …), each
/// elementary rotation leaving its own axis unchanged.
fn body_rates(turns: &[Turn], moves: &dyn Fn(&str) -> bool) -> [Component; 3] {
    let mut w: [Component; 3] = [None, None, None];
    for turn in turns {
        let axis = turn.axis;
        w[axis] = sum(w[axis].take(), rate(turn, moves));
        // Rᵀ about `axis` applied to w: the other two components turn by −q.
        let (c, s) = (
            format!("cos({})", turn.angle),
            format!("sin({})", turn.angle),
        );
        let (i, j) = ((axis + 1) % 3, (axis + 2) % 3);
        let (wi, wj) = (w[i].take(), w[j].take());
        w[i] = sum(times(&c, &wi), times(&s, &wj));
        w[j] = sum(minus(times(&s, &wi)), times(&c, &wj));
    }
    w
}

/// The fixed frame's axes as columns of the identity.
fn identity() -> [[Component; 3]; 3] {
    let one = || Some("1".to_string());
    [
        [one(), None, None],
        [None, one(), None],
        [None, None, one()],
    ]
}

/// Carries the body's axes (columns of R_1…R_{k−1}, in the fixed frame)
/// through one more turn: R·R_a(q) maps e_i → c e_i + s e_j and
/// e_j → −s e_i + c e_j.
fn turn_axes(axes: &mut [[Component; 3]; 3], turn: &Turn) {
    let (c, s) = (
        format!("cos({})", turn.angle),
        format!("sin({})", turn.angle),
    );
    let (i, j) = ((turn.axis + 1) % 3, (turn.axis + 2) % 3);
    let (ei, ej) = (axes[i].clone(), axes[j].clone());
    for k in 0..3 {
        axes[i][k] = sum(times(&c, &ei[k]), times(&s, &ej[k]));
        axes[j][k] = sum(minus(times(&s, &ei[k])), times(&c, &ej[k]));
    }
}

/// The body's angular velocity in the fixed frame: ω = Σ_k R_1…R_{k−1}
/// e_k q_k', each turn's axis carried by the turns before it.
fn world_rates(turns: &[Turn], moves: &dyn Fn(&str) -> bool) -> [Component; 3] {
    let mut axes = identity();
    let mut w: [Component; 3] = [None, None, None];
    for turn in turns {
        if let Some(r) = rate(turn, moves) {
            for (wi, ai) in w.iter_mut().zip(&axes[turn.axis]) {
                *wi = sum(wi.take(), product(ai, &Some(r.clone())));
            }
        }
        turn_axes(&mut axes, turn);
    }
    w
}

/// The body's axes in the fixed frame, the columns of its rotation R:
/// the turns' product, or R(e) = (2e0² − 1) I + 2(e eᵀ + e0 ẽ) from Euler
/// parameters (the rotation whose rates [`quaternion_rates`] gives).
fn axes(body: &BodySpec) -> [[Component; 3]; 3] {
    let Some([w, x, y, z]) = &body.quaternion else {
        let mut axes = identity();
        for turn in &body.turns {
            turn_axes(&mut axes, turn);
        }
        return axes;
    };
    let e = [x, y, z];
    let entry = |row: usize, column: usize| -> Component {
        let product = format!("2*{}*{}", e[row], e[column]);
        Some(match (row + 3 - column) % 3 {
            0 => format!("2*{w}^2 - 1 + {product}"),
            // ẽ[row][column] = −e_k for column = row + 1, +e_k for row = column + 1.
            2 => format!("{product} - 2*{w}*{}", e[3 - row - column]),
            _ => format!("{product} + 2*{w}*{}", e[3 - row - column]),
        })
    };
    // Column i holds body axis i.
    std::array::from_fn(|column| std::array::from_fn(|row| entry(row, column)))
}

/// How a body is drawn: its centre and the tips of its three axes, each
/// of the length sqrt(tr I / 2m), the root-mean-square distance of its
/// mass from its centre (tr I = 2 ∫ r² dm; a diagonal that cannot cancel,
/// so the length is real for every inertia). Positions (x, y, z) as text.
pub fn frame(body: &BodySpec, tensor: &[[Option<String>; 3]; 3]) -> [[String; 3]; 4] {
    let centre = centre(&body.name);
    let trace: Vec<String> = (0..3).filter_map(|i| tensor[i][i].clone()).collect();
    let length = match trace.is_empty() {
        true => "0".to_string(),
        false => format!("sqrt(({})/(2*({})))", trace.join(" + "), text(&body.mass)),
    };
    let axes = axes(body);
    let tip = |axis: usize| -> [String; 3] {
        std::array::from_fn(|k| match &axes[axis][k] {
            Some(a) => format!("{} + ({length})*({a})", centre[k]),
            None => centre[k].clone(),
        })
    };
    [centre.clone(), tip(0), tip(1), tip(2)]
}

/// The angular velocity from Euler parameters e = (e0, e1, e2, e3):
/// ω = 2 G(e) e' in the body's axes, 2 E(e) e' in the fixed frame.
fn quaternion_rates(e: &[String; 4], in_body: bool) -> [Component; 3] {
    let [w, x, y, z] = e;
    let n = |s: &String| format!("-{s}");
    let rows: [[String; 4]; 3] = match in_body {
        true => [
            [n(x), w.clone(), z.clone(), n(y)],
            [n(y), n(z), w.clone(), x.clone()],
            [n(z), y.clone(), n(x), w.clone()],
        ],
        false => [
            [n(x), w.clone(), n(z), y.clone()],
            [n(y), z.clone(), w.clone(), n(x)],
            [n(z), n(y), x.clone(), w.clone()],
        ],
    };
    rows.map(|row| {
        let terms: Vec<String> = row
            .iter()
            .zip(e)
            .map(|(a, c)| format!("({a})*dot({c})"))
            .collect();
        Some(format!("2*({})", terms.join(" + ")))
    })
}

/// The body's angular velocity in its own axes or the fixed frame.
fn rates(body: &BodySpec, in_body: bool, moves: &dyn Fn(&str) -> bool) -> [Component; 3] {
    match (&body.quaternion, in_body) {
        (Some(e), _) => quaternion_rates(e, in_body),
        (None, true) => body_rates(&body.turns, moves),
        (None, false) => world_rates(&body.turns, moves),
    }
}

/// The kinetic energy ½ m v·v + ½ ωᵀ I ω of a body (ω in its own axes),
/// plus m g·c where the model gives gravity. With Euler parameters, also
/// ½ tr(I) (e·e')², which vanishes on their unit sphere (e·e' = 0) and
/// adds nothing to the motion there, but gives the mass matrix the
/// direction across it, along which ω does not move.
pub fn energy(
    body: &BodySpec,
    tensor: &[[Option<String>; 3]; 3],
    gravity: Option<&[NumberSpec; 3]>,
    moves: &dyn Fn(&str) -> bool,
) -> String {
    let mass = text(&body.mass);
    let centre = centre(&body.name);
    let speed = centre
        .iter()
        .map(|c| format!("dot({c})^2"))
        .collect::<Vec<_>>()
        .join(" + ");
    let mut energy = format!("({mass})*({speed})/2");
    let w = rates(body, true, moves);
    for i in 0..3 {
        for j in 0..3 {
            if let (Some(moment), Some(wi), Some(wj)) = (&tensor[i][j], &w[i], &w[j]) {
                energy += &format!(" + ({moment})*({wi})*({wj})/2");
            }
        }
    }
    if let Some(e) = &body.quaternion {
        let trace: Vec<String> = (0..3).filter_map(|i| tensor[i][i].clone()).collect();
        let along: Vec<String> = e.iter().map(|c| format!("{c}*dot({c})")).collect();
        energy += &format!(" + ({})*({})^2/2", trace.join(" + "), along.join(" + "));
    }
    if let Some(g) = gravity {
        for (gi, c) in g.iter().zip(&centre) {
            energy += &format!(" + ({mass})*({})*{c}", text(gi));
        }
    }
    energy
}

/// The velocity (x, y, z) of the body's material point at `point`: v_c +
/// ω × (p − c), ω in the fixed frame.
pub fn point_velocity(
    body: &BodySpec,
    point: &[String; 3],
    moves: &dyn Fn(&str) -> bool,
) -> [String; 3] {
    let centre = centre(&body.name);
    let w = rates(body, false, moves);
    let arm: Vec<Component> = point
        .iter()
        .zip(&centre)
        .map(|(p, c)| Some(format!("({p}) - {c}")))
        .collect();
    std::array::from_fn(|i| {
        let (j, k) = ((i + 1) % 3, (i + 2) % 3);
        let turning = sum(product(&w[j], &arm[k]), minus(product(&w[k], &arm[j])));
        match turning {
            Some(t) => format!("dot({}) + {t}", centre[i]),
            None => format!("dot({})", centre[i]),
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// About one axis the rate is the angle's; a parameter has none.
    #[test]
    fn one_rotation_turns_about_its_own_axis() {
        let moves = |s: &str| s == "phi";
        let turns = rotation("Z(phi)").unwrap();
        assert_eq!(
            body_rates(&turns, &moves),
            [None, None, Some("dot(phi)".into())]
        );
        assert_eq!(
            body_rates(&rotation("X(lambda)").unwrap(), &moves),
            [None, None, None]
        );
        assert!(rotation("W(phi)").is_err());
        assert!(rotation("Z phi").is_err());
        assert!(rotation("Z(phi").is_err());
        assert_eq!(rotation("Y(pi/2 - (a))").unwrap()[0].angle, "pi/2 - (a)");
    }

    /// A point fixed in a body turned by Z(q) about its origin (1, 2, 3):
    /// the origin plus the point's offset turned, and a zero offset's
    /// components left out.
    #[test]
    fn a_point_of_a_body_is_its_offset_turned_from_the_origin() {
        let body: BodySpec = toml::from_str(
            "name = 'arm'\nmass = 1\ninertia = [1, 1, 1]\nposition = [1, 2, 3]\nrotation = 'Z(q)'\ncentre = ['l', 0, 0]",
        )
        .unwrap();
        let body = BodySpec {
            turns: rotation(&body.rotation).unwrap(),
            ..body
        };
        let offset = body.centre.clone().unwrap();
        assert_eq!(
            in_space(&body, &offset),
            [
                "1.0 + (l)*((cos(q))*(1))",
                "2.0 + (l)*((sin(q))*(1))",
                "3.0"
            ]
        );
    }

    #[test]
    fn inertia_is_principal_or_a_symmetric_tensor() {
        let read = |s: &str| inertia(&toml::from_str::<toml::Table>(s).unwrap()["i"]);
        let diagonal = read("i = ['a', 2, 0.0]").unwrap();
        assert_eq!(diagonal[0][0].as_deref(), Some("a"));
        assert_eq!(diagonal[2][2], None);
        assert_eq!(diagonal[0][1], None);
        let full = read("i = [['a', 'c', 0], ['c', 'b', 0], [0, 0, 'a+b']]").unwrap();
        assert_eq!(full[1][0].as_deref(), Some("c"));
        assert!(read("i = [['a', 'c', 0], ['d', 'b', 0], [0, 0, 1]]").is_err());
        assert!(read("i = ['a', 'b']").is_err());
    }
}
