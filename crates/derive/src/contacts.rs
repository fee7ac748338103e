//! Derivations for models with Coulomb contacts (build time, Symbolica).
//!
//! Each contact is a point sliding along a rough guide: one coordinate s_i
//! slides, another h_i is held at a fixed value by the guide. With the
//! Lagrangian L and the Rayleigh function D over all coordinates, Lagrange's
//! equations with the multipliers of h_i = const give, on the guides
//! (h = const, h' = 0):
//!
//! - the free force along each guide, everything but friction:
//!   G_i = ∂L/∂s_i − ∂D/∂s_i' − Σ_k ∂²L/∂s_i'∂q_k q_k';
//! - the normal reaction, the multiplier of h_i = const:
//!   N_i = −(∂L/∂h_i − ∂D/∂h_i' − Σ_k ∂²L/∂h_i'∂q_k q_k');
//! - the mass m_i = ∂²L/∂s_i'², so that m_i s_i'' = G_i + F_i.
//!
//! The runtime (`mechlab::contact`) adds the friction F_i: −μ_i |N_i| σ_i
//! while sliding with σ_i = sign s_i', or −G_i while stuck, which static
//! friction can supply as long as |G_i| ≤ μ_i |N_i|. These formulas need a
//! mass matrix that couples no coordinate of a contact to any other (point
//! masses on guides, as in the Painlevé–Klein example); the build checks it.
//! Also derived: the energy function E = Σ q'∂L/∂q' − L, which changes only
//! by the friction work and the dissipation P_D = Σ q' ∂D/∂q'.

use crate::algebra::{is_zero, num, subst, var, DeriveError, Derived, Recorder};
use crate::derive::kinematic;
use crate::model::Model;
use symbolica::prelude::*;

/// Everything the contact template needs, as readable text over the sliding
/// coordinates and their velocities.
pub struct ContactDerivation {
    pub derived: Vec<Derived>,
    /// Sliding coordinates and their velocities, in contact order.
    pub slides: Vec<String>,
    pub velocities: Vec<String>,
    pub free_forces: Vec<String>,
    pub normal_forces: Vec<String>,
    pub masses: Vec<String>,
    pub friction: Vec<String>,
    pub energy: String,
    pub dissipation_power: String,
}

fn error(reason: String) -> DeriveError {
    DeriveError::Model {
        key: "contacts".into(),
        reason,
    }
}

/// The mass matrix must not couple a contact's coordinates to any other,
/// nor depend on the configuration: point masses on guides.
fn check_point_masses(lagrangian: &Atom, coordinates: &[(&str, &str)]) -> Result<(), DeriveError> {
    for (a, va) in coordinates {
        for (b, vb) in coordinates {
            let entry = lagrangian
                .derivative(symbol!(*va))
                .derivative(symbol!(*vb))
                .expand();
            if a != b && !is_zero(&entry) {
                return Err(error(format!(
                    "the mass matrix couples '{a}' and '{b}'; contacts need point masses on guides (a diagonal mass matrix)"
                )));
            }
            let moving = coordinates
                .iter()
                .any(|(c, _)| !is_zero(&entry.derivative(symbol!(*c))));
            if a == b && moving {
                return Err(error(format!(
                    "the mass of '{a}' depends on the configuration; contacts need constant masses"
                )));
            }
        }
    }
    Ok(())
}

pub fn derive(model: &Model) -> Result<ContactDerivation, DeriveError> {
    let coordinates: Vec<(&str, &str)> = model
        .coordinates
        .iter()
        .map(|c| (c.name.as_str(), c.velocity.as_str()))
        .collect();
    let velocity_of = |name: &str| -> &str {
        coordinates
            .iter()
            .find(|(c, _)| *c == name)
            .map(|(_, v)| *v)
            .expect("validated: contacts name coordinates")
    };
    let lagrangian = kinematic(model, &model.lagrangian)?;
    let rayleigh = kinematic(model, &model.rayleigh)?;
    if !is_zero(&lagrangian.derivative(symbol!(model.time.as_str())))
        || !is_zero(&rayleigh.derivative(symbol!(model.time.as_str())))
    {
        return Err(error(
            "a model with contacts must not depend on time".into(),
        ));
    }

    check_point_masses(&lagrangian, &coordinates)?;

    // Lagrange's expression without the acceleration term, for coordinate c.
    let lagrange = |c: &str| -> Atom {
        let vc = velocity_of(c);
        let mut e = lagrangian.derivative(symbol!(c)) - rayleigh.derivative(symbol!(vc));
        for (k, vk) in &coordinates {
            e -= lagrangian.derivative(symbol!(vc)).derivative(symbol!(*k)) * var(vk);
        }
        e
    };
    // On the guides: held coordinates at their values, not moving.
    let on_guides = |e: &Atom| -> Result<Atom, DeriveError> {
        let mut r = e.clone();
        for contact in &model.contacts {
            r = subst(&r, velocity_of(&contact.held), &num(0));
            r = subst(
                &r,
                &contact.held,
                &crate::algebra::atom(&contact.at.to_string())?,
            );
        }
        Ok(r)
    };

    let slides: Vec<String> = model.contacts.iter().map(|c| c.slides.clone()).collect();
    let velocities: Vec<String> = slides.iter().map(|s| velocity_of(s).to_string()).collect();
    let mut rec = Recorder::for_model(model, velocities.clone());
    rec.record("lagrangian", "L over all coordinates", &lagrangian)?;
    rec.record("rayleigh", "Rayleigh dissipation function D", &rayleigh)?;
    let mut free_forces = Vec::new();
    let mut normal_forces = Vec::new();
    let mut masses = Vec::new();
    let mut friction = Vec::new();
    for (i, contact) in model.contacts.iter().enumerate() {
        let v = velocity_of(&contact.slides);
        let mass = lagrangian.derivative(symbol!(v)).derivative(symbol!(v));
        masses.push(rec.record(format!("mass[{i}]"), format!("m = ∂²L/∂{v}²"), &mass)?);
        // The code keeps Symbolica's form: it is written in the differences
        // of positions (x1 − x2), while the readable form expands them and
        // would cancel catastrophically far from the origin.
        let free = on_guides(&lagrange(&contact.slides))?;
        rec.record(
            format!("free_force[{i}]"),
            format!("G along {}: all forces but friction", contact.slides),
            &free,
        )?;
        free_forces.push(free.to_string());
        let normal = on_guides(&(-lagrange(&contact.held)))?;
        rec.record(
            format!("normal_force[{i}]"),
            format!("N: the guide's reaction holding {}", contact.held),
            &normal,
        )?;
        normal_forces.push(normal.to_string());
        friction.push(rec.record(
            format!("friction[{i}]"),
            "μ, the friction coefficient",
            &crate::algebra::atom(&contact.friction.to_string())?,
        )?);
    }
    let mut energy = -lagrangian.clone();
    let mut power = num(0);
    for (_, vk) in &coordinates {
        energy += lagrangian.derivative(symbol!(*vk)) * var(vk);
        power += rayleigh.derivative(symbol!(*vk)) * var(vk);
    }
    let energy = on_guides(&energy)?;
    rec.record("energy", "E = Σ q'∂L/∂q' − L on the guides", &energy)?;
    let power = on_guides(&power)?;
    rec.record(
        "dissipation_power",
        "P_D = Σ q'∂D/∂q' on the guides (dE/dt = Σ F_i s_i' − P_D)",
        &power,
    )?;
    let (energy, dissipation_power) = (energy.to_string(), power.to_string());
    Ok(ContactDerivation {
        derived: rec.finish(),
        slides,
        velocities,
        free_forces,
        normal_forces,
        masses,
        friction,
        energy,
        dissipation_power,
    })
}
