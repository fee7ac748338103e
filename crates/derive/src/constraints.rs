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
//! state and keeps the state on the constraints by projection. h is not
//! derived here: the generated code differentiates c's code by forward
//! mode (`generate::bias_steps`), since h written out is the longest
//! expression of a model (a rolling wheel's contact under a square root,
//! differentiated: 8 × 10⁵ characters for the bicycle's front wheel).
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
    /// The coordinates' starting rates, expressions in the parameters
    /// ("0" where the file gives none), and which the file gives.
    pub start_rates: Vec<String>,
    pub rates_given: Vec<bool>,
    /// Whether M is singular at the starts (massless parts): the field
    /// then solves with M + α GᵀG and F − α Gᵀh, α = tr M / tr GᵀG.
    pub massless: bool,
}

/// The model's coordinates and velocities, and the time derivatives the
/// constrained forms need.
struct Calculus<'m> {
    model: &'m Model,
    q: Vec<&'m str>,
    qd: Vec<&'m str>,
    rate: Option<Atom>,
}

impl<'m> Calculus<'m> {
    fn new(model: &'m Model) -> Result<Self, DeriveError> {
        Ok(Calculus {
            model,
            q: model.coordinates.iter().map(|c| c.name.as_str()).collect(),
            qd: model
                .coordinates
                .iter()
                .map(|c| c.velocity.as_str())
                .collect(),
            rate: match &model.fast_phase {
                Some(f) => Some(atom(&f.rate.to_string())?),
                None => None,
            },
        })
    }

    /// ∂/∂t at fixed q and q': through the fast phase, or time itself.
    fn partial_t(&self, e: &Atom) -> Atom {
        match (&self.model.fast_phase, &self.rate) {
            (Some(f), Some(rate)) => rate * e.derivative(symbol!(f.name.as_str())),
            _ => e.derivative(symbol!(self.model.time.as_str())),
        }
    }

    /// Σ ∂e/∂q_j q'_j + ∂e/∂t, for e free of q''.
    fn total(&self, e: &Atom) -> Atom {
        let mut d = self.partial_t(e);
        for (qj, vj) in self.q.iter().zip(&self.qd) {
            d += e.derivative(symbol!(*qj)) * var(vj);
        }
        d
    }

    /// Whether `e` depends on time (or the phase).
    fn moves(&self, e: &Atom) -> bool {
        !crate::algebra::is_zero(&self.partial_t(e).expand())
    }

    /// M and F, recorded, and whether M stays still.
    fn dynamics(
        &self,
        lagrangian: &Atom,
        rayleigh: &Atom,
        rec: &mut Recorder,
    ) -> Result<(Vec<Vec<String>>, Vec<String>, bool), DeriveError> {
        let (q, qd) = (&self.q, &self.qd);
        let n = q.len();
        let mut still = true;
        let mut mass_matrix = vec![Vec::new(); n];
        let mut free_forces = Vec::new();
        for i in 0..n {
            let momentum = lagrangian.derivative(symbol!(qd[i]));
            for j in 0..n {
                let entry = momentum.derivative(symbol!(qd[j])).expand();
                still &= !self.moves(&entry);
                mass_matrix[i].push(rec.record(
                    format!("mass_matrix[{i}][{j}]"),
                    "M = ∂²L/∂q'²",
                    &entry,
                )?);
            }
            // d/dt ∂L/∂q' without its q'' terms.
            let mut velocity_terms = self.partial_t(&momentum);
            for (qk, vk) in q.iter().zip(qd) {
                velocity_terms += momentum.derivative(symbol!(*qk)) * var(vk);
            }
            let force = kinematic(self.model, &self.model.forces[i])?;
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
        Ok((mass_matrix, free_forces, still))
    }

    /// Each constraint's g (0 for a velocity one), G, c_t and h, recorded,
    /// and whether all are holonomic and still.
    fn constraint_rows(&self, rec: &mut Recorder) -> Result<(Rows, bool), DeriveError> {
        let mut rows = Rows::default();
        let mut still = true;
        for (r, constraint) in self.model.constraints.iter().enumerate() {
            let name = &constraint.name;
            let velocity_level = match &constraint.kind {
                ConstraintKind::Position(e) => {
                    let g = kinematic(self.model, e)?;
                    still &= !self.moves(&g);
                    rec.record(
                        format!("constraint[{r}]"),
                        format!("g = 0: the position constraint '{name}'"),
                        &g,
                    )?;
                    // The code keeps the file's form: the readable one
                    // expands squares of differences, which cancel near the
                    // constraint.
                    rows.residuals.push(g.to_string());
                    self.total(&g)
                }
                ConstraintKind::Velocity(e) => {
                    still = false;
                    rows.residuals.push("0".into());
                    let c = kinematic(self.model, e)?;
                    // Differentiated in its readable form (as L is).
                    atom(&rec.record(
                        format!("constraint[{r}]"),
                        format!("c = 0: the velocity constraint '{name}'"),
                        &c,
                    )?)?
                }
            };
            let mut row = Vec::new();
            let mut rate_part = velocity_level.clone();
            for (j, vj) in self.qd.iter().enumerate() {
                let entry = velocity_level.derivative(symbol!(*vj)).expand();
                rate_part = subst(&rate_part, vj, &num(0));
                row.push(rec.record(
                    format!("constraint_jacobian[{r}][{j}]"),
                    format!("G = ∂c/∂q' of '{name}'"),
                    &entry,
                )?);
            }
            rows.jacobian.push(row);
            rows.rates.push(rec.record(
                format!("constraint_rate[{r}]"),
                format!("c_t: the part of '{name}''s velocity form free of q'"),
                &rate_part.expand(),
            )?);
        }
        Ok((rows, still))
    }

    /// E, V and b, recorded.
    fn energies(
        &self,
        lagrangian: &Atom,
        rec: &mut Recorder,
    ) -> Result<(String, String, Vec<String>), DeriveError> {
        let mut energy = -lagrangian.clone();
        for vk in &self.qd {
            energy += lagrangian.derivative(symbol!(*vk)) * var(vk);
        }
        let energy = rec.record("energy", "E = Σ q'∂L/∂q' − L", &energy.expand())?;
        let at_rest = |e: &Atom| {
            self.qd
                .iter()
                .fold(e.clone(), |acc, v| subst(&acc, v, &num(0)))
        };
        let potential = rec.record(
            "potential",
            "V = −L at q' = 0",
            &(-at_rest(lagrangian)).expand(),
        )?;
        let mut linear_term = Vec::new();
        for (i, v) in self.qd.iter().enumerate() {
            let b = at_rest(&lagrangian.derivative(symbol!(*v))).expand();
            linear_term.push(rec.record(
                format!("linear_term[{i}]"),
                "b = ∂L/∂q' at q' = 0",
                &b,
            )?);
        }
        Ok((energy, potential, linear_term))
    }
}

/// The constraints' rows, as text.
#[derive(Default)]
struct Rows {
    residuals: Vec<String>,
    jacobian: Vec<Vec<String>>,
    rates: Vec<String>,
}

pub fn derive(model: &Model) -> Result<ConstrainedDerivation, DeriveError> {
    let calculus = Calculus::new(model)?;
    let lagrangian = kinematic(model, &model.lagrangian)?;
    let rayleigh = kinematic(model, &model.rayleigh)?;
    let mut rec = Recorder::for_model(model, calculus.qd.iter().map(|v| v.to_string()).collect());
    // Derived from its readable form: canonical in the angles' Fourier
    // basis, where a rigid body's L written in the world's axes loses the
    // terms that cancel by sin² + cos² = 1 (the bicycle's L falls from
    // about 10⁶ characters to a few thousand), so that its derivatives
    // are as short as the mechanics.
    let lagrangian = atom(&rec.record(
        "lagrangian",
        "L(q, q', t) over all coordinates",
        &lagrangian,
    )?)?;
    let phase_rate = match &calculus.rate {
        Some(rate) => Some(rec.record("phase_rate", "dθ/dt of the fast phase", rate)?),
        None => None,
    };
    let (mass_matrix, free_forces, mass_still) =
        calculus.dynamics(&lagrangian, &rayleigh, &mut rec)?;
    let (rows, constraints_still) = calculus.constraint_rows(&mut rec)?;
    let (energy, potential, linear_term) = calculus.energies(&lagrangian, &mut rec)?;
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
        residuals: rows.residuals,
        jacobian: rows.jacobian,
        rates: rows.rates,
        energy,
        potential,
        linear_term,
        stationary: mass_still && constraints_still,
        starts,
        start_rates: model
            .coordinates
            .iter()
            .map(|c| {
                c.start_rate
                    .as_ref()
                    .map_or_else(|| "0".into(), |e| e.to_string())
            })
            .collect(),
        rates_given: model
            .coordinates
            .iter()
            .map(|c| c.start_rate.is_some())
            .collect(),
        massless: model.has_massless_parts(),
    })
}
