//! Derivations for models with ideal constraints (build time, Symbolica).
//!
//! The coordinates q (n of them, possibly redundant: Cartesian points, or
//! angles with loop closures) move under k constraints, each holonomic,
//! g(q, t) = 0, or nonholonomic, c(q, q', t) = a(q, t)·q' + b(q, t) = 0.
//! Both are used at the velocity level, c = G q' + c_t with
//! c = Σ ∂g/∂q_j q'_j + ∂g/∂t for a holonomic one, so that
//! d/dt c = G q'' + h with h = Σ ∂c/∂q_j q'_j + ∂c/∂t. Lagrange's equations
//! with multipliers are then
//!
//!   M q'' = F + Gᵀ λ,   G q'' + h = 0,
//!
//! with M = ∂²L/∂q'² and the free generalised force
//! F = ∂L/∂q − (∂²L/∂q'∂q) q' − ∂/∂t (∂L/∂q') + Q − ∂D/∂q'; Gᵀλ is the
//! constraints' reaction in the coordinates. With a fast phase θ, ∂/∂t is
//! rate · ∂/∂θ. The runtime (`mechlab::constrained`) solves them at each
//! state and keeps the state on the constraints by projection.
//! Also derived: the energy function E = Σ q'∂L/∂q' − L, constant when
//! neither L nor the constraints depend on time and nothing dissipates.

use crate::algebra::{atom, num, subst, var, DeriveError, Derived, Recorder};
use crate::derive::kinematic;
use crate::model::{ConstraintKind, Model};
use symbolica::prelude::*;

/// Everything the constrained template needs, as readable text over the
/// coordinates and velocities.
pub struct ConstrainedDerivation {
    pub derived: Vec<Derived>,
    /// dθ/dt of the fast phase, if there is one.
    pub phase_rate: Option<String>,
    pub mass_matrix: Vec<Vec<String>>,
    pub free_forces: Vec<String>,
    /// g of each holonomic constraint (0 for a nonholonomic one).
    pub residuals: Vec<String>,
    /// G = ∂c/∂q' (k × n).
    pub jacobian: Vec<Vec<String>>,
    /// c_t = c at q' = 0: the velocity constraints read G q' + c_t = 0.
    pub rates: Vec<String>,
    /// h = Σ ∂c/∂q_j q'_j + ∂c/∂t.
    pub bias: Vec<String>,
    pub energy: String,
    /// V = −L at q' = 0 and b = ∂L/∂q' at q' = 0, for the averaging.
    pub potential: String,
    pub linear_term: Vec<String>,
    /// Whether every constraint is holonomic and fixed (independent of
    /// time and the fast phase) and M does not depend on them: the
    /// averaging's conditions.
    pub stationary: bool,
    /// The coordinates' starts, expressions in the parameters.
    pub starts: Vec<String>,
}

pub fn derive(model: &Model) -> Result<ConstrainedDerivation, DeriveError> {
    let q: Vec<&str> = model.coordinates.iter().map(|c| c.name.as_str()).collect();
    let qd: Vec<&str> = model
        .coordinates
        .iter()
        .map(|c| c.velocity.as_str())
        .collect();
    let rate = match &model.fast_phase {
        Some(f) => Some(atom(&f.rate.to_string())?),
        None => None,
    };
    // ∂/∂t at fixed q and q': through the fast phase, or time itself.
    let partial_t = |e: &Atom| -> Atom {
        match (&model.fast_phase, &rate) {
            (Some(f), Some(rate)) => rate * e.derivative(symbol!(f.name.as_str())),
            _ => e.derivative(symbol!(model.time.as_str())),
        }
    };
    // Σ ∂e/∂q_j q'_j + ∂e/∂t, for e free of q''.
    let total = |e: &Atom| -> Atom {
        let mut d = partial_t(e);
        for (qj, vj) in q.iter().zip(&qd) {
            d += e.derivative(symbol!(*qj)) * var(vj);
        }
        d
    };
    let lagrangian = kinematic(model, &model.lagrangian)?;
    let rayleigh = kinematic(model, &model.rayleigh)?;
    let mut rec = Recorder::for_model(model, qd.iter().map(|v| v.to_string()).collect());
    rec.record(
        "lagrangian",
        "L(q, q', t) over all coordinates",
        &lagrangian,
    )?;
    let phase_rate = match &rate {
        Some(rate) => Some(rec.record("phase_rate", "dθ/dt of the fast phase", rate)?),
        None => None,
    };

    let n = q.len();
    let moves = |e: &Atom| !crate::algebra::is_zero(&partial_t(e).expand());
    let mut stationary = true;
    let mut mass_matrix = vec![Vec::new(); n];
    let mut free_forces = Vec::new();
    for i in 0..n {
        let momentum = lagrangian.derivative(symbol!(qd[i]));
        for j in 0..n {
            let entry = momentum.derivative(symbol!(qd[j])).expand();
            stationary &= !moves(&entry);
            mass_matrix[i].push(rec.record(
                format!("mass_matrix[{i}][{j}]"),
                "M = ∂²L/∂q'²",
                &entry,
            )?);
        }
        // d/dt ∂L/∂q' without its q'' terms.
        let mut velocity_terms = partial_t(&momentum);
        for (qk, vk) in q.iter().zip(&qd) {
            velocity_terms += momentum.derivative(symbol!(*qk)) * var(vk);
        }
        let force = kinematic(model, &model.forces[i])?;
        let free = lagrangian.derivative(symbol!(q[i])) - velocity_terms + force
            - rayleigh.derivative(symbol!(qd[i]));
        free_forces.push(rec.record(
            format!("free_force[{i}]"),
            format!(
                "F = ∂L/∂{0} − d/dt ∂L/∂{1} (without q'') + Q − ∂D/∂{1}",
                q[i], qd[i]
            ),
            &free.expand(),
        )?);
    }

    let mut residuals = Vec::new();
    let mut jacobian = Vec::new();
    let mut rates = Vec::new();
    let mut bias = Vec::new();
    for (r, constraint) in model.constraints.iter().enumerate() {
        let name = &constraint.name;
        let velocity_level = match &constraint.kind {
            ConstraintKind::Position(e) => {
                let g = kinematic(model, e)?;
                stationary &= !moves(&g);
                rec.record(
                    format!("constraint[{r}]"),
                    format!("g = 0: the position constraint '{name}'"),
                    &g,
                )?;
                // The code keeps the file's form: the readable one expands
                // squares of differences, which cancel near the constraint.
                residuals.push(g.to_string());
                total(&g)
            }
            ConstraintKind::Velocity(e) => {
                stationary = false;
                residuals.push("0".into());
                let c = kinematic(model, e)?;
                rec.record(
                    format!("constraint[{r}]"),
                    format!("c = 0: the velocity constraint '{name}'"),
                    &c,
                )?;
                c
            }
        };
        let mut row = Vec::new();
        let mut rate_part = velocity_level.clone();
        for (j, vj) in qd.iter().enumerate() {
            let entry = velocity_level.derivative(symbol!(*vj)).expand();
            rate_part = subst(&rate_part, vj, &num(0));
            row.push(rec.record(
                format!("constraint_jacobian[{r}][{j}]"),
                format!("G = ∂c/∂q' of '{name}'"),
                &entry,
            )?);
        }
        jacobian.push(row);
        rates.push(rec.record(
            format!("constraint_rate[{r}]"),
            format!("c_t: the part of '{name}''s velocity form free of q'"),
            &rate_part.expand(),
        )?);
        bias.push(rec.record(
            format!("constraint_bias[{r}]"),
            format!("h = d/dt c − G q'' of '{name}'"),
            &total(&velocity_level).expand(),
        )?);
    }

    let mut energy = -lagrangian.clone();
    for vk in &qd {
        energy += lagrangian.derivative(symbol!(*vk)) * var(vk);
    }
    let energy = rec.record("energy", "E = Σ q'∂L/∂q' − L", &energy.expand())?;
    let at_rest = |e: &Atom| qd.iter().fold(e.clone(), |acc, v| subst(&acc, v, &num(0)));
    let potential = rec.record(
        "potential",
        "V = −L at q' = 0",
        &(-at_rest(&lagrangian)).expand(),
    )?;
    let mut linear_term = Vec::new();
    for (i, v) in qd.iter().enumerate() {
        let b = at_rest(&lagrangian.derivative(symbol!(*v))).expand();
        linear_term.push(rec.record(format!("linear_term[{i}]"), "b = ∂L/∂q' at q' = 0", &b)?);
    }
    let starts = model
        .coordinates
        .iter()
        .map(|c| {
            c.start
                .as_ref()
                .map(|e| e.to_string())
                .unwrap_or_else(|| "0".into())
        })
        .collect();
    Ok(ConstrainedDerivation {
        derived: rec.finish(),
        phase_rate,
        mass_matrix,
        free_forces,
        residuals,
        jacobian,
        rates,
        bias,
        energy,
        potential,
        linear_term,
        stationary,
        starts,
    })
}
