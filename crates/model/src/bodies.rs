//! Rigid bodies in model files (`[[bodies]]`): each body's kinetic energy,
//! ½ m v·v + ½ ωᵀ I ω, written out as text and added to the Lagrangian
//! before the file is validated, so that the derivation sees one
//! Lagrangian as for any model. The centre's coordinates become
//! definitions (`<body>_x`, `<body>_y`, `<body>_z`) whose `dot()` gives
//! its velocity; the body's angular velocity in its own axes comes from
//! its rotation sequence.

use serde::Deserialize;

/// A rigid body: its mass, its principal moments of inertia about its
/// centre along its own axes x, y, z, the centre's position and the
/// body's orientation as a sequence of rotations about its own axes.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    pub name: String,
    pub mass: String,
    /// I_x, I_y, I_z: principal moments about the centre, in the body's axes.
    pub inertia: [String; 3],
    /// The centre of mass (x, y, z) in the fixed frame (z up, as gravity
    /// in the Lagrangian is written by the model).
    pub position: [String; 3],
    /// Rotations about the body's own axes, each applied to the frame the
    /// ones before left: "Z(phi) X(theta) Y(psi)" (empty: the body does
    /// not turn).
    #[serde(default)]
    pub rotation: String,
    #[serde(default)]
    pub description: String,
}

/// Why a body cannot be read: the key and the reason.
pub type BodyError = (String, String);

/// The definitions each body adds (its centre's coordinates) and the
/// kinetic energies to add to the Lagrangian.
pub fn expand(bodies: &[BodySpec]) -> Result<(Vec<(String, String)>, String), BodyError> {
    let mut definitions = Vec::new();
    let mut energy = String::new();
    for (k, body) in bodies.iter().enumerate() {
        let centre: Vec<String> = ["x", "y", "z"]
            .iter()
            .map(|axis| format!("{}_{axis}", body.name))
            .collect();
        for (name, at) in centre.iter().zip(&body.position) {
            definitions.push((name.clone(), at.clone()));
        }
        let speed = centre
            .iter()
            .map(|c| format!("dot({c})^2"))
            .collect::<Vec<_>>()
            .join(" + ");
        energy += &format!(" + ({})*({speed})/2", body.mass);
        let omega = angular_velocity(&body.rotation)
            .map_err(|reason| (format!("bodies[{k}].rotation"), reason))?;
        for (moment, w) in body.inertia.iter().zip(omega) {
            if let Some(w) = w {
                energy += &format!(" + ({moment})*({w})^2/2");
            }
        }
    }
    Ok((definitions, energy))
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
    a.as_ref().map(|a| format!("{factor}*({a})"))
}

fn minus(a: Component) -> Component {
    a.map(|a| format!("-({a})"))
}

/// The body's angular velocity in its own axes for the rotation sequence
/// "A1(q1) A2(q2) …": ω = R_nᵀ(… R_2ᵀ(R_1ᵀ e_1 q1' + e_2 q2') …), each
/// elementary rotation leaving its own axis unchanged.
fn angular_velocity(sequence: &str) -> Result<[Component; 3], String> {
    let mut w: [Component; 3] = [None, None, None];
    let text = sequence.replace(' ', "");
    let mut rest = text.as_str();
    while !rest.is_empty() {
        let axis = match rest.as_bytes()[0] {
            b'X' => 0,
            b'Y' => 1,
            b'Z' => 2,
            _ => {
                return Err(format!(
                    "'{sequence}': each rotation is X(angle), Y(angle) or Z(angle), about the body's own axis"
                ))
            }
        };
        let (Some(open), Some(close)) = (rest.find('('), rest.find(')')) else {
            return Err(format!(
                "'{sequence}': a rotation's angle goes in parentheses, as Z(phi)"
            ));
        };
        let angle = &rest[open + 1..close];
        if open != 1 || angle.is_empty() {
            return Err(format!(
                "'{sequence}': each rotation is an axis and a coordinate, as Z(phi)"
            ));
        }
        rest = &rest[close + 1..];
        // w + e_axis q'
        w[axis] = sum(w[axis].take(), Some(format!("dot({angle})")));
        // Rᵀ about `axis` applied to w: the other two components turn by −q.
        let (c, s) = (format!("cos({angle})"), format!("sin({angle})"));
        let (i, j) = ((axis + 1) % 3, (axis + 2) % 3);
        let (wi, wj) = (w[i].take(), w[j].take());
        w[i] = sum(times(&c, &wi), times(&s, &wj));
        w[j] = sum(minus(times(&s, &wi)), times(&c, &wj));
    }
    Ok(w)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// About one axis the rate is the angle's.
    #[test]
    fn one_rotation_turns_about_its_own_axis() {
        let w = angular_velocity("Z(phi)").unwrap();
        assert_eq!(w, [None, None, Some("dot(phi)".into())]);
        assert!(angular_velocity("W(phi)").is_err());
        assert!(angular_velocity("Z phi").is_err());
    }
}
