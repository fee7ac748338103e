//! The derivations, with Symbolica (build time only, one thread).
//!
//! From a validated [`Model`] this derives, symbolically and without any
//! special case per model:
//! - the Lagrangian with positions substituted and velocities taken as total
//!   time derivatives; terms depending on time only are dropped (they are total
//!   time derivatives and change no equation of motion);
//! - the mass matrix A(q) = ∂²L/∂q'², the linear term b(q, θ) = ∂L/∂q'|_{q'=0},
//!   the potential V(q, θ) = −L|_{q'=0}, the momenta p = A q' + b;
//! - the velocities q' = A⁻¹(p − b) (A⁻¹ by cofactors) and the Hamiltonian
//!   H = ½ (p − b)ᵀ A⁻¹ (p − b) + V;
//! - Hamilton's equations with generalised forces: q' as above,
//!   p' = ∂L/∂q + Q evaluated at that q' (equal to −∂H/∂q + Q);
//! - with a fast phase θ: the means over θ of H (H̄), V, the vibrational
//!   potential V_vibr = ½ mean(bᵀ A⁻¹ b), the forces P̄ = mean Q(q, q'(q, p, θ)),
//!   the averaged equations q' = ∂H̄/∂p, p' = −∂H̄/∂q + P̄;
//! - the Jacobians of both vector fields, ∂V/∂q, C = ∂²V/∂q² and the Hessian
//!   of the effective potential V + V_vibr.
//!
//! Every recorded result goes through `crates/simplify` (readable forms,
//! checked against Symbolica's result at random points) and is kept as text
//! (for snapshots and code generation) and as LaTeX (`crates/derive/src/latex.rs`).

use crate::algebra::{
    atom, cheaper, drop_terms_without, inverse, is_zero, matrix_text, momentum_name, monomial_mean,
    num, phase_mean, phase_modes, reduce_pythagorean, subst, var, DeriveError, Derived, Recorder,
};
use crate::model::{Expr, Model};
use symbolica::prelude::*;

/// The part of the derivation the code generator needs, as printed text.
#[derive(Default)]
pub struct Derivation {
    pub dof: usize,
    /// Everything derived, in reading order, for snapshots and reports.
    pub derived: Vec<Derived>,
    /// Velocities q'(q, p, θ).
    pub velocities: Vec<String>,
    /// ∂L/∂q + Q, in terms of q, q', θ (evaluated after the velocities).
    pub momentum_rates: Vec<String>,
    /// p = A q' + b in terms of q, q', θ.
    pub momenta: Vec<String>,
    pub hamiltonian: String,
    /// Jacobian of the exact field; entries may use the velocity symbols.
    pub exact_jacobian: Vec<Vec<String>>,
    pub mass_matrix: Vec<Vec<String>>,
    /// Phase averaged quantities (empty without a fast phase).
    pub averaged_rhs: Vec<String>,
    pub averaged_jacobian: Vec<Vec<String>>,
    pub averaged_hamiltonian: String,
    /// Potential (its mean over the phase, if any).
    pub potential: String,
    pub vibrational_potential: String,
    pub potential_gradient: Vec<String>,
    pub potential_hessian: Vec<Vec<String>>,
    pub effective_potential_hessian: Vec<Vec<String>>,
    /// dθ/dt in terms of the parameters.
    pub phase_rate: String,
    /// Arithmetic operations of the right-hand sides after CSE, as derived
    /// and in the readable form: (function, derived, readable, chosen).
    pub operation_counts: Vec<(String, usize, usize, usize)>,
    /// The pieces of the numeric-solve form, for models whose velocities
    /// are solved at run time (then `velocities`, `hamiltonian`, the
    /// Jacobians, `averaged_*` and `vibrational_potential` are empty: the
    /// generator builds them from these through the solve).
    pub numeric: Option<NumericForm>,
    /// The second-order averaged system (symbolic form with a fast phase).
    pub second_order: Option<crate::deprit::SecondOrderForm>,
}

/// What the generated code of the numeric-solve form evaluates: A(q) (in
/// `Derivation::mass_matrix`), b(q, θ), V(q, θ), the momentum rates
/// ∂L/∂q + Q at (q, q', θ) (in `Derivation::momentum_rates`), and for the
/// averaged system b̄ = mean b, the modes of b over the phase and the rates
/// of L̄₀ = ½ q'ᵀAq' + b̄ᵀq' − V̄ with the mean forces.
pub struct NumericForm {
    pub linear_term: Vec<String>,
    /// V(q, θ) (with the phase, unlike `Derivation::potential`).
    pub potential: String,
    pub mean_linear_term: Vec<String>,
    /// The modes of b over the phase: b = Σ_s h_s(θ) g_s(q) with h_s a
    /// monomial sin(θ)^a cos(θ)^b (one mode, sin θ, for a vertical
    /// vibration): the vectors g_s.
    pub modes: Vec<Vec<String>>,
    /// mean(h_s h_t), so that mean(b bᵀ) = Σ M_st g_s g_tᵀ and
    /// V_vibr = ½ Σ M_st g_sᵀA⁻¹g_t: one solve per mode, not A⁻¹.
    pub mode_products: Vec<Vec<f64>>,
    /// mean(h_s), so that b̄ = Σ m_s g_s.
    pub mode_means: Vec<f64>,
    pub averaged_momentum_rates: Vec<String>,
    /// (a, b) of each mode's h_s = sin(θ)^a cos(θ)^b.
    pub mode_exponents: Vec<(i64, i64)>,
    /// The Fourier series of V(q, θ) in the phase, harmonic by harmonic.
    pub potential_series: Vec<(crate::lie::Harmonic, String)>,
    /// P̄ = mean of the forces over the phase, in q and the velocities.
    pub mean_forces: Vec<String>,
    /// The nonzero ∂A_ij/∂q_k, i ≤ j, as (k, i, j, text): ∂W/∂q by the
    /// adjoint of the solves (see `numeric.rs`).
    pub mass_slopes: Vec<(usize, usize, usize, String)>,
    /// The nonzero ∂(g_s)_i/∂q_k as (k, s, i, text).
    pub mode_slopes: Vec<(usize, usize, usize, String)>,
}

/// An expression of the model (the Lagrangian, a dissipation function) with
/// the definitions substituted and `dot(x)` replaced by the total time
/// derivative of x (through the coordinates, and the fast phase or time).
pub fn kinematic(model: &Model, e: &Expr) -> Result<Atom, DeriveError> {
    let q: Vec<&str> = model.coordinates.iter().map(|c| c.name.as_str()).collect();
    let qd: Vec<&str> = model
        .coordinates
        .iter()
        .map(|c| c.velocity.as_str())
        .collect();
    let phase = model.fast_phase.as_ref().map(|f| f.name.clone());
    let rate = match &model.fast_phase {
        Some(f) => atom(&f.rate.to_string())?,
        None => num(1),
    };
    let mut positions: Vec<(String, Atom)> = Vec::new();
    for (name, e) in &model.definitions {
        let mut a = atom(&e.to_string())?;
        for (prev, value) in &positions {
            a = subst(&a, prev, value);
        }
        positions.push((name.clone(), a));
    }
    let total_derivative = |x: &Atom| -> Atom {
        let mut d = num(0);
        for (qi, qdi) in q.iter().zip(&qd) {
            d += x.derivative(symbol!(qi)) * var(qdi);
        }
        match &phase {
            Some(th) => d + &rate * x.derivative(symbol!(th.as_str())),
            None => d + x.derivative(symbol!(model.time.as_str())),
        }
    };
    // `dot(x)` becomes the symbol x__dot, replaced by its value.
    let with_placeholders = e.rewrite_calls(&mut |name, args| match (name, &args[0]) {
        ("dot", Expr::Sym(s)) => Some(Expr::Sym(format!("{s}__dot"))),
        _ => None,
    });
    let mut result = atom(&with_placeholders.to_string())?;
    for (name, value) in &positions {
        result = subst(&result, &format!("{name}__dot"), &total_derivative(value));
    }
    for qi in &q {
        result = subst(&result, &format!("{qi}__dot"), &total_derivative(&var(qi)));
    }
    for (name, value) in &positions {
        result = subst(&result, name, value);
    }
    Ok(result)
}

/// The model's generalised forces Q: its `[forces]`, less the Rayleigh
/// dissipation's ∂D/∂q' (D with its `dot()`s of definitions carried
/// through the chain rule), in the coordinates and velocities; D reduced
/// by sin² + cos² = 1 of each turning angle, as L is.
fn generalised_forces(model: &Model) -> Result<Vec<Atom>, DeriveError> {
    let mut rayleigh = kinematic(model, &model.rayleigh)?;
    for c in model.coordinates.iter().filter(|c| c.periodic) {
        rayleigh = reduce_pythagorean(&rayleigh, &c.name)?;
    }
    model
        .forces
        .iter()
        .zip(&model.coordinates)
        .map(|(f, c)| Ok(atom(&f.to_string())? - rayleigh.derivative(symbol!(c.velocity.as_str()))))
        .collect()
}

/// The names of the model's coordinates and of their velocities.
fn coordinates_and_velocities(model: &Model) -> (Vec<String>, Vec<String>) {
    model
        .coordinates
        .iter()
        .map(|c| (c.name.clone(), c.velocity.clone()))
        .unzip()
}

/// Runs every derivation for one model.
pub fn derive(model: &Model) -> Result<Derivation, DeriveError> {
    let (q, qd) = coordinates_and_velocities(model);
    let p: Vec<String> = q.iter().map(|c| momentum_name(c)).collect();
    for name in &p {
        let clash = model.parameters.iter().any(|x| &x.name == name)
            || model.definitions.iter().any(|(d, _)| d == name);
        if clash || q.contains(name) || qd.contains(name) {
            return Err(DeriveError::Model {
                key: "coordinates".into(),
                reason: format!("the momentum name '{name}' is already used"),
            });
        }
    }
    let rate = match &model.fast_phase {
        Some(f) => atom(&f.rate.to_string())?,
        None => num(1),
    };
    let mut rec = Recorder::for_model(model, p.iter().chain(&qd).cloned().collect());
    let pieces = mechanical_pieces(model, &qd, &p, rate, &mut rec)?;
    if model.inverse == crate::model::Inverse::Numeric {
        return numeric_form(model, pieces, rec);
    }
    let (mut derivation, exact) = symbolic_exact(model, &p, &pieces, &mut rec)?;
    let (mean_potential, vibrational) = match &model.fast_phase {
        Some(phase) => symbolic_averaged(
            model,
            &p,
            &pieces,
            &exact,
            &phase.name,
            &mut derivation,
            &mut rec,
        )?,
        None => (pieces.potential.clone(), num(0)),
    };
    potentials(
        model,
        &pieces,
        mean_potential,
        vibrational,
        &mut derivation,
        &mut rec,
    )?;
    derivation.derived = rec.finish();
    Ok(derivation)
}

/// L with the terms of time alone dropped, A = ∂²L/∂q'², b = ∂L/∂q' and
/// V = −L at q' = 0, and the momenta, recorded.
fn mechanical_pieces(
    model: &Model,
    qd: &[String],
    p: &[String],
    rate: Atom,
    rec: &mut Recorder,
) -> Result<Pieces, DeriveError> {
    let n = model.dof();
    let q: Vec<String> = model.coordinates.iter().map(|c| c.name.clone()).collect();
    let lagrangian = kinematic(model, &model.lagrangian)?;
    let mut dynamic: Vec<String> = q.clone();
    dynamic.extend(qd.iter().cloned());
    let mut lagrangian = drop_terms_without(&lagrangian, &dynamic)?;
    for (coordinate, c) in q.iter().zip(&model.coordinates) {
        if c.periodic {
            lagrangian = reduce_pythagorean(&lagrangian, coordinate)?;
        }
    }
    rec.record(
        "lagrangian",
        "L(q, q', θ), terms depending on time only dropped",
        &lagrangian,
    )?;

    // Mass matrix, linear term, potential.
    let at_rest = |e: &Atom| qd.iter().fold(e.clone(), |acc, v| subst(&acc, v, &num(0)));
    let mass: Vec<Vec<Atom>> = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| {
                    lagrangian
                        .derivative(symbol!(qd[i].as_str()))
                        .derivative(symbol!(qd[j].as_str()))
                        .expand()
                })
                .collect()
        })
        .collect();
    for i in 0..n {
        for k in 0..n {
            let third = mass[i][k].derivative(symbol!(qd[0].as_str()));
            let mut nonzero = !is_zero(&third);
            for v in &qd[1..] {
                nonzero |= !is_zero(&mass[i][k].derivative(symbol!(v.as_str())));
            }
            if nonzero {
                return Err(DeriveError::Model {
                    key: "lagrangian".into(),
                    reason: "is not quadratic in the velocities".into(),
                });
            }
        }
    }
    let mut readable_mass = vec![Vec::new(); n];
    for i in 0..n {
        for j in 0..n {
            readable_mass[i].push(rec.record(
                format!("mass_matrix[{i}][{j}]"),
                "A = ∂²L/∂q'²",
                &mass[i][j],
            )?);
        }
    }
    let linear: Vec<Atom> = (0..n)
        .map(|i| at_rest(&lagrangian.derivative(symbol!(qd[i].as_str()))).expand())
        .collect();
    let mut readable_linear = Vec::new();
    for (i, b) in linear.iter().enumerate() {
        readable_linear.push(rec.record(format!("linear_term[{i}]"), "b = ∂L/∂q' at q' = 0", b)?);
    }
    let potential = (-at_rest(&lagrangian)).expand();
    rec.record("potential", "V = −L at q' = 0", &potential)?;

    let momenta: Vec<Atom> = (0..n)
        .map(|i| {
            let mut m = linear[i].clone();
            for j in 0..n {
                m += &mass[i][j] * var(&qd[j]);
            }
            m.expand()
        })
        .collect();
    for (i, m) in momenta.iter().enumerate() {
        rec.record(
            format!("momenta[{i}]"),
            format!("{} = ∂L/∂{}", p[i], qd[i]),
            m,
        )?;
    }

    Ok(Pieces {
        lagrangian,
        mass,
        linear,
        readable_mass,
        readable_linear,
        potential,
        momenta,
        rate,
    })
}

/// What the symbolic form's averaging needs of its exact system.
struct SymbolicExact {
    inverse: Vec<Vec<Atom>>,
    velocities: Vec<Atom>,
    kinetic: Atom,
    hamiltonian: Atom,
    forces: Vec<Atom>,
}

/// The symbolic form's exact system: A⁻¹, q' = A⁻¹(p − b), H, the momentum
/// rates and the Jacobian, each in the cheaper of its forms.
fn symbolic_exact(
    model: &Model,
    p: &[String],
    pieces: &Pieces,
    rec: &mut Recorder,
) -> Result<(Derivation, SymbolicExact), DeriveError> {
    let n = model.dof();
    let (q, qd) = coordinates_and_velocities(model);
    let Pieces {
        lagrangian,
        mass,
        linear,
        potential,
        momenta,
        rate,
        ..
    } = pieces;
    let (det, inv) = inverse(mass);
    if is_zero(&det) {
        return Err(DeriveError::Model {
            key: "lagrangian".into(),
            reason: "the mass matrix is singular".into(),
        });
    }
    rec.record("mass_matrix_determinant", "det A", &det)?;
    let shifted: Vec<Atom> = (0..n).map(|i| var(&p[i]) - &linear[i]).collect();
    let velocities: Vec<Atom> = (0..n)
        .map(|i| (0..n).fold(num(0), |acc, j| acc + &inv[i][j] * &shifted[j]))
        .collect();
    let mut readable_velocities = Vec::new();
    for (i, v) in velocities.iter().enumerate() {
        readable_velocities.push(rec.record(
            format!("velocities[{i}]"),
            format!("{} = A⁻¹(p − b)", qd[i]),
            v,
        )?);
    }
    let mut kinetic = num(0);
    for i in 0..n {
        for j in 0..n {
            kinetic += &shifted[i] * &inv[i][j] * &shifted[j];
        }
    }
    let kinetic = kinetic / num(2);
    let hamiltonian = &kinetic + potential;
    let hamiltonian_text = rec.record_sum(
        "hamiltonian",
        "H = ½(p − b)ᵀA⁻¹(p − b) + V, by powers of the momenta",
        &[kinetic.clone(), potential.clone()],
    )?;

    // Exact equations: q' = A⁻¹(p − b), p' = ∂L/∂q + Q at that q'.
    let forces = generalised_forces(model)?;
    let rates: Vec<Atom> = (0..n)
        .map(|i| (lagrangian.derivative(symbol!(q[i].as_str())) + &forces[i]).expand())
        .collect();
    let mut readable_rates = Vec::new();
    for i in 0..n {
        readable_rates.push(rec.record(
            format!("momentum_rates[{i}]"),
            format!("d{}/dt = ∂L/∂{} + Q, at the velocities above", p[i], q[i]),
            &rates[i],
        )?);
    }
    let (use_readable, exact_counts) = readable_is_cheaper(
        &qd,
        &velocities,
        &rates,
        &readable_velocities,
        &readable_rates,
    )?;
    let exact_jacobian = chain_rule_jacobian(&q, &qd, p, &velocities, &rates);

    let derivation = Derivation {
        dof: n,
        velocities: if use_readable {
            readable_velocities
        } else {
            velocities.iter().map(|v| v.to_string()).collect()
        },
        momentum_rates: if use_readable {
            readable_rates
        } else {
            rates.iter().map(|r| r.to_string()).collect()
        },
        momenta: momenta.iter().map(|m| m.to_string()).collect(),
        hamiltonian: hamiltonian_text,
        exact_jacobian,
        mass_matrix: matrix_text(mass),
        phase_rate: rate.to_string(),
        operation_counts: vec![exact_counts],
        ..Default::default()
    };

    Ok((
        derivation,
        SymbolicExact {
            inverse: inv,
            velocities,
            kinetic,
            hamiltonian,
            forces,
        },
    ))
}

/// Whether the readable forms of q' and p' are the cheaper after CSE (by
/// 10 %), with the operation counts (function, derived, readable, used).
fn readable_is_cheaper(
    qd: &[String],
    velocities: &[Atom],
    rates: &[Atom],
    readable_velocities: &[String],
    readable_rates: &[String],
) -> Result<(bool, (String, usize, usize, usize)), DeriveError> {
    let velocity_names: Vec<(String, String)> =
        qd.iter().map(|v| (v.clone(), String::new())).collect();
    let staged = |velocities: Vec<String>, rates: Vec<String>| {
        let with = |values: Vec<String>, prefix: &str| -> Vec<(String, String)> {
            values
                .into_iter()
                .enumerate()
                .map(|(i, t)| (format!("{prefix}{i}"), t))
                .collect()
        };
        let first: Vec<(String, String)> = velocity_names
            .iter()
            .zip(velocities)
            .map(|((n, _), t)| (n.clone(), t))
            .collect();
        vec![first, with(rates, "dp")]
    };
    let (_, before, after, used) = cheaper(
        staged(
            velocities.iter().map(|v| v.to_string()).collect(),
            rates.iter().map(|r| r.to_string()).collect(),
        ),
        staged(readable_velocities.to_vec(), readable_rates.to_vec()),
    )?;
    Ok((
        used == after,
        ("exact_rhs".to_string(), before, after, used),
    ))
}

/// The Jacobian of the exact field by the chain rule through q'(q, p):
/// rows q' = `velocities`, then p' = `rates`(q, q').
fn chain_rule_jacobian(
    q: &[String],
    qd: &[String],
    p: &[String],
    velocities: &[Atom],
    rates: &[Atom],
) -> Vec<Vec<String>> {
    let n = q.len();
    let state: Vec<String> = q.iter().chain(p).cloned().collect();
    let mut exact_jacobian = vec![vec![String::new(); 2 * n]; 2 * n];
    for (k, s) in state.iter().enumerate() {
        let dv: Vec<Atom> = velocities
            .iter()
            .map(|v| v.derivative(symbol!(s.as_str())))
            .collect();
        for i in 0..n {
            exact_jacobian[i][k] = dv[i].to_string();
            let mut d = if k < n {
                rates[i].derivative(symbol!(s.as_str()))
            } else {
                num(0)
            };
            for m in 0..n {
                d += rates[i].derivative(symbol!(qd[m].as_str())) * &dv[m];
            }
            exact_jacobian[n + i][k] = d.to_string();
        }
    }
    exact_jacobian
}

/// The symbolic form averaged over the phase `th`: H̄, the averaged field
/// and its Jacobian, the second order; V̄ and V_vibr returned.
fn symbolic_averaged(
    model: &Model,
    p: &[String],
    pieces: &Pieces,
    exact: &SymbolicExact,
    th: &str,
    derivation: &mut Derivation,
    rec: &mut Recorder,
) -> Result<(Atom, Atom), DeriveError> {
    let n = model.dof();
    let (q, qd) = coordinates_and_velocities(model);
    let state: Vec<String> = q.iter().chain(p).cloned().collect();
    let Pieces {
        linear,
        potential,
        rate,
        ..
    } = pieces;
    let SymbolicExact {
        inverse: inv,
        velocities,
        kinetic,
        hamiltonian,
        forces,
    } = exact;
    let substitute_velocities = |e: &Atom| -> Atom {
        qd.iter()
            .zip(velocities)
            .fold(e.clone(), |acc, (name, value)| subst(&acc, name, value))
    };
    let averaged_hamiltonian = phase_mean(hamiltonian, th)?.together();
    let mean_potential = phase_mean(potential, th)?.expand();
    derivation.averaged_hamiltonian = rec.record_sum(
        "averaged_hamiltonian",
        "H̄ = mean over the phase of H, by powers of the momenta",
        &[phase_mean(kinetic, th)?, mean_potential.clone()],
    )?;
    let mut quadratic = num(0);
    for i in 0..n {
        for j in 0..n {
            quadratic += &linear[i] * &inv[i][j] * &linear[j];
        }
    }
    let vibrational = phase_mean(&(quadratic / num(2)), th)?;
    let vibrational = vibrational.together();
    let averaged_forces: Vec<Atom> = forces
        .iter()
        .map(|f| phase_mean(&substitute_velocities(f), th).map(|a| a.together()))
        .collect::<Result<_, _>>()?;
    for (i, f) in averaged_forces.iter().enumerate() {
        rec.record(
            format!("averaged_forces[{i}]"),
            "P̄ = mean Q(q, q'(q, p, θ))",
            f,
        )?;
    }
    let mut rhs: Vec<Atom> = (0..n)
        .map(|i| averaged_hamiltonian.derivative(symbol!(p[i].as_str())))
        .collect();
    for i in 0..n {
        rhs.push(-averaged_hamiltonian.derivative(symbol!(q[i].as_str())) + &averaged_forces[i]);
    }
    let mut readable_rhs = Vec::new();
    for (i, r) in rhs.iter().enumerate() {
        readable_rhs.push(rec.record(
            format!("averaged_rhs[{i}]"),
            format!("d{}/dt of the averaged system", state[i]),
            r,
        )?);
    }
    let outputs = |texts: Vec<String>| -> Vec<Vec<(String, String)>> {
        vec![texts
            .into_iter()
            .enumerate()
            .map(|(i, t)| (format!("f{i}"), t))
            .collect()]
    };
    let (chosen, before, after, used) = cheaper(
        outputs(rhs.iter().map(|r| r.to_string()).collect()),
        outputs(readable_rhs),
    )?;
    derivation
        .operation_counts
        .push(("averaged_rhs".into(), before, after, used));
    derivation.averaged_rhs = chosen;
    derivation.averaged_jacobian = rhs
        .iter()
        .map(|r| {
            state
                .iter()
                .map(|s| r.derivative(symbol!(s.as_str())).to_string())
                .collect()
        })
        .collect();
    derivation.second_order = Some(crate::deprit::second_order_form(
        hamiltonian,
        &averaged_hamiltonian,
        &averaged_forces,
        (th, rate),
        &q,
        p,
        rec,
    )?);
    Ok((mean_potential, vibrational))
}

/// V̄, its derivatives, V_vibr, the limiting Lagrangian and the Hessian of
/// V + V_vibr, recorded into `derivation`.
fn potentials(
    model: &Model,
    pieces: &Pieces,
    mean_potential: Atom,
    vibrational: Atom,
    derivation: &mut Derivation,
    rec: &mut Recorder,
) -> Result<(), DeriveError> {
    let n = model.dof();
    let (q, qd) = coordinates_and_velocities(model);
    let mass = &pieces.mass;
    (
        derivation.potential,
        derivation.potential_gradient,
        derivation.potential_hessian,
    ) = potential_derivatives(model, rec, &mean_potential)?;
    derivation.vibrational_potential = rec.record(
        "vibrational_potential",
        "V_vibr = ½ mean(bᵀ A⁻¹ b)",
        &vibrational,
    )?;
    if model.fast_phase.is_some() {
        let mut relative_kinetic = num(0);
        for i in 0..n {
            for j in 0..n {
                relative_kinetic += &mass[i][j] * var(&qd[i]) * var(&qd[j]);
            }
        }
        rec.record_sum(
            "limiting_lagrangian",
            "L̄ = ½ q'ᵀA q' − (V + V_vibr): the Lagrangian of the averaged system",
            &[
                relative_kinetic / num(2),
                -mean_potential.clone(),
                -vibrational.clone(),
            ],
        )?;
    }
    let effective = &mean_potential + &vibrational;
    rec.record_sum(
        "effective_potential",
        "V + V_vibr",
        &[mean_potential.clone(), vibrational.clone()],
    )?;
    derivation.effective_potential_hessian = hessian_of(
        &effective,
        &q,
        "effective_potential_hessian",
        "∂²(V + V_vibr)/∂q²",
        rec,
    )?;
    Ok(())
}

/// The potential V̄ (averaged over the phase, if any), ∂V̄/∂q and
/// C = ∂²V̄/∂q², recorded; V̄ must not depend on time.
fn potential_derivatives(
    model: &Model,
    rec: &mut Recorder,
    mean_potential: &Atom,
) -> Result<(String, Vec<String>, Vec<Vec<String>>), DeriveError> {
    if !is_zero(&mean_potential.derivative(symbol!(model.time.as_str()))) {
        return Err(DeriveError::Model {
            key: "lagrangian".into(),
            reason: "the potential depends on time other than through a fast phase".into(),
        });
    }
    let q: Vec<String> = model.coordinates.iter().map(|c| c.name.clone()).collect();
    let text = rec.record(
        "mean_potential",
        "V averaged over the phase",
        mean_potential,
    )?;
    let gradient = q
        .iter()
        .enumerate()
        .map(|(i, qi)| {
            rec.record(
                format!("potential_gradient[{i}]"),
                "∂V/∂q",
                &mean_potential.derivative(symbol!(qi.as_str())),
            )
        })
        .collect::<Result<_, _>>()?;
    let hessian = hessian_of(mean_potential, &q, "potential_hessian", "C = ∂²V/∂q²", rec)?;
    Ok((text, gradient, hessian))
}

/// The recorded Hessian of `e` in the coordinates `q`.
fn hessian_of(
    e: &Atom,
    q: &[String],
    key: &str,
    description: &str,
    rec: &mut Recorder,
) -> Result<Vec<Vec<String>>, DeriveError> {
    q.iter()
        .enumerate()
        .map(|(i, qi)| {
            q.iter()
                .enumerate()
                .map(|(j, qj)| {
                    let d = e
                        .derivative(symbol!(qi.as_str()))
                        .derivative(symbol!(qj.as_str()));
                    rec.record(format!("{key}[{i}][{j}]"), description, &d)
                })
                .collect()
        })
        .collect()
}

/// What both forms derive first.
struct Pieces {
    lagrangian: Atom,
    mass: Vec<Vec<Atom>>,
    linear: Vec<Atom>,
    /// The same in their readable forms (checked against the above).
    readable_mass: Vec<Vec<String>>,
    readable_linear: Vec<String>,
    potential: Atom,
    momenta: Vec<Atom>,
    rate: Atom,
}

/// The numeric-solve form: no inverse of A is formed symbolically, so the
/// computer algebra stays polynomial in the size of the model.
/// The nonzero slopes ∂A_ij/∂q_k (i ≤ j) and ∂(g_s)_i/∂q_k, for ∂W/∂q by
/// the adjoint of the solves: a chain's A_ij depends on q_i and q_j alone,
/// so their number, and the gradient's code, grows like N², where forward
/// mode through a solve per direction grows like N³.
#[allow(clippy::type_complexity)]
fn slopes(
    q: &[String],
    mass: &[Vec<Atom>],
    modes: &[((i64, i64), Vec<Atom>)],
) -> (
    Vec<(usize, usize, usize, String)>,
    Vec<(usize, usize, usize, String)>,
) {
    let mut mass_slopes = Vec::new();
    let mut mode_slopes = Vec::new();
    for (k, qk) in q.iter().enumerate() {
        let qk = symbol!(qk.as_str());
        for (i, row) in mass.iter().enumerate() {
            for (j, entry) in row.iter().enumerate().skip(i) {
                let slope = entry.derivative(qk).expand();
                if !is_zero(&slope) {
                    mass_slopes.push((k, i, j, slope.to_string()));
                }
            }
        }
        for (s, (_, g)) in modes.iter().enumerate() {
            for (i, component) in g.iter().enumerate() {
                let slope = component.derivative(qk).expand();
                if !is_zero(&slope) {
                    mode_slopes.push((k, s, i, slope.to_string()));
                }
            }
        }
    }
    (mass_slopes, mode_slopes)
}

fn numeric_form(
    model: &Model,
    pieces: Pieces,
    mut rec: Recorder,
) -> Result<Derivation, DeriveError> {
    let Pieces {
        lagrangian,
        mass,
        linear,
        readable_mass,
        readable_linear,
        potential,
        momenta,
        rate,
    } = pieces;
    let n = model.dof();
    let (q, qd) = coordinates_and_velocities(model);
    let p: Vec<String> = q.iter().map(|c| momentum_name(c)).collect();
    let phase = model.fast_phase.as_ref().map(|f| f.name.clone());
    let forces = generalised_forces(model)?;
    let mut momentum_rates = Vec::new();
    for i in 0..n {
        let rate_i = (lagrangian.derivative(symbol!(q[i].as_str())) + &forces[i]).expand();
        momentum_rates.push(rec.record(
            format!("momentum_rates[{i}]"),
            format!(
                "d{}/dt = ∂L/∂{} + Q, at the velocities solved from A q' = p − b",
                p[i], q[i]
            ),
            &rate_i,
        )?);
    }
    let mut derivation = Derivation {
        dof: n,
        momentum_rates,
        momenta: momenta.iter().map(|m| m.to_string()).collect(),
        mass_matrix: readable_mass,
        phase_rate: rate.to_string(),
        ..Default::default()
    };
    let mut form = NumericForm {
        linear_term: readable_linear,
        potential: potential.to_string(),
        mean_linear_term: Vec::new(),
        modes: Vec::new(),
        mode_products: Vec::new(),
        mode_means: Vec::new(),
        averaged_momentum_rates: Vec::new(),
        mode_exponents: Vec::new(),
        potential_series: Vec::new(),
        mean_forces: Vec::new(),
        mass_slopes: Vec::new(),
        mode_slopes: Vec::new(),
    };
    let mean_potential = match &phase {
        Some(th) => {
            check_numeric_averaging(&q, &qd, &mass, &forces, th)?;
            let averaging = Averaging {
                q: &q,
                qd: &qd,
                p: &p,
                mass: &mass,
                linear: &linear,
                potential: &potential,
                forces: &forces,
                th,
            };
            averaging.record(&mut rec, &mut form)?
        }
        None => potential.clone(),
    };
    (
        derivation.potential,
        derivation.potential_gradient,
        derivation.potential_hessian,
    ) = potential_derivatives(model, &mut rec, &mean_potential)?;
    derivation.numeric = Some(form);
    derivation.derived = rec.finish();
    Ok(derivation)
}

/// Averaging with a numeric solve of A needs A(q) free of the phase and
/// forces linear in the velocities with phase-free coefficients.
fn check_numeric_averaging(
    q: &[String],
    qd: &[String],
    mass: &[Vec<Atom>],
    forces: &[Atom],
    th: &str,
) -> Result<(), DeriveError> {
    let depends_on_phase = |e: &Atom| !is_zero(&e.derivative(symbol!(th)));
    if mass.iter().flatten().any(depends_on_phase) {
        return Err(DeriveError::Model {
            key: "lagrangian".into(),
            reason: format!("the mass matrix depends on the fast phase '{th}': averaging with a numeric solve of A needs A(q) alone"),
        });
    }
    for (i, f) in forces.iter().enumerate() {
        for v in qd {
            let slope = f.derivative(symbol!(v.as_str()));
            let nonlinear = qd
                .iter()
                .any(|w| !is_zero(&slope.derivative(symbol!(w.as_str()))));
            if nonlinear || depends_on_phase(&slope) {
                return Err(DeriveError::Model {
                    key: format!("forces.{}", q[i]),
                    reason: format!("averaging with a numeric solve of A needs forces linear in the velocities with coefficients free of the phase '{th}'"),
                });
            }
        }
    }
    Ok(())
}

/// What the averaged numeric form is built from.
struct Averaging<'a> {
    q: &'a [String],
    qd: &'a [String],
    p: &'a [String],
    mass: &'a [Vec<Atom>],
    linear: &'a [Atom],
    potential: &'a Atom,
    forces: &'a [Atom],
    /// The fast phase.
    th: &'a str,
}

impl Averaging<'_> {
    /// Records the phase means, the modes of b and their products and
    /// slopes, V's harmonics and the averaged momentum rates in `form`;
    /// returns the mean potential V̄.
    fn record(&self, rec: &mut Recorder, form: &mut NumericForm) -> Result<Atom, DeriveError> {
        let Averaging {
            q,
            qd,
            p,
            mass,
            linear,
            potential,
            forces,
            th,
        } = *self;
        let n = q.len();
        let mean_linear: Vec<Atom> = linear
            .iter()
            .map(|b| phase_mean(b, th).map(|m| m.expand()))
            .collect::<Result<_, _>>()?;
        for (i, b) in mean_linear.iter().enumerate() {
            form.mean_linear_term.push(rec.record(
                format!("mean_linear_term[{i}]"),
                "b̄ = mean of b over the phase",
                b,
            )?);
        }
        let modes = phase_modes(linear, th)?;
        for (s_index, ((a, b), g)) in modes.iter().enumerate() {
            let mut texts = Vec::new();
            for (i, component) in g.iter().enumerate() {
                texts.push(rec.record(
                    format!("linear_term_modes[{s_index}][{i}]"),
                    format!("b = Σ_s h_s(θ) g_s(q): g_{s_index}, the coefficient of sin(θ)^{a} cos(θ)^{b}"),
                    component,
                )?);
            }
            form.modes.push(texts);
        }
        let mean = |a: i64, b: i64| {
            let (numerator, denominator) = monomial_mean(a, b);
            numerator as f64 / denominator as f64
        };
        (form.mass_slopes, form.mode_slopes) = slopes(q, mass, &modes);
        form.mode_exponents = modes.iter().map(|(k, _)| *k).collect();
        form.mode_means = modes.iter().map(|((a, b), _)| mean(*a, *b)).collect();
        form.mode_products = modes
            .iter()
            .map(|((a, b), _)| modes.iter().map(|((c, d), _)| mean(a + c, b + d)).collect())
            .collect();
        let mean_potential = phase_mean(potential, th)?.expand();
        let mut reduced = -mean_potential.clone();
        for i in 0..n {
            reduced += &mean_linear[i] * var(&qd[i]);
            for j in 0..n {
                reduced += &mass[i][j] * var(&qd[i]) * var(&qd[j]) / num(2);
            }
        }
        form.potential_series = potential_series(rec, potential, th)?;
        for i in 0..n {
            let force = phase_mean(&forces[i], th)?;
            form.mean_forces.push(force.to_string());
            let rate_i = (reduced.derivative(symbol!(q[i].as_str())) + force).expand();
            form.averaged_momentum_rates.push(rec.record(
                format!("averaged_momentum_rates[{i}]"),
                format!(
                    "d{}/dt of the averaged system without −∂V_vibr/∂{}: ∂L̄₀/∂{} + P̄, L̄₀ = ½ q'ᵀAq' + b̄ᵀq' − V̄, at q' = A⁻¹(p − b̄)",
                    p[i], q[i], q[i]
                ),
                &rate_i,
            )?);
        }
        Ok(mean_potential)
    }
}

/// V(q, θ)'s Fourier coefficients in θ, recorded for second-order averaging.
fn potential_series(
    rec: &mut Recorder,
    potential: &Atom,
    th: &str,
) -> Result<Vec<(crate::lie::Harmonic, String)>, DeriveError> {
    let mut series = Vec::new();
    for (h, coefficient) in crate::deprit::fourier(potential, th)? {
        let (label, what) = match h {
            crate::lie::Harmonic::Cos(0) => (
                "cos0".to_string(),
                format!("the mean of V(q, {th}) over {th}"),
            ),
            crate::lie::Harmonic::Cos(k) => (
                format!("cos{k}"),
                format!("the coefficient of cos({k}{th}) in V(q, {th})"),
            ),
            crate::lie::Harmonic::Sin(k) => (
                format!("sin{k}"),
                format!("the coefficient of sin({k}{th}) in V(q, {th})"),
            ),
        };
        let text = rec.record(
            format!("potential_harmonics[{label}]"),
            format!("{what}, for second-order averaging"),
            &coefficient.expand(),
        )?;
        series.push((h, text));
    }
    Ok(series)
}
