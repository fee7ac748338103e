//! Generated functions of the numeric-solve form (models of 3 or more
//! degrees of freedom by default, see `SYMBOLIC_INVERSE_MAX_DOF`).
//!
//! The derivation gives closed forms of A(q), b(q, θ), V, the momentum
//! rates ∂L/∂q + Q at (q, q', θ), and for the averaged system b̄, the modes
//! of b over the phase and the rates of L̄₀ = ½ q'ᵀAq' + b̄ᵀq' − V̄.
//! Everything that needs A⁻¹ is computed here as steps of the emitter's DAG:
//! - exact field: A q' = p − b (one Cholesky factorisation), then p';
//! - H = ½ (p − b)ᵀq' + V;
//! - V_vibr = ½ mean(bᵀA⁻¹b): with b = Σ_s h_s(θ) g_s(q) over its modes in
//!   the phase (one, sin θ, for a vertical vibration) and the numbers
//!   M_st = mean(h_s h_t), V_vibr = ½ Σ M_st g_sᵀx_t with A x_t = g_t: one
//!   solve per mode, with the same factorisation, never A⁻¹ itself;
//! - averaged field: q' = A⁻¹(p − b̄), p' = ∂L̄₀/∂q + P̄ − ∂W/∂q with
//!   W = V_vibr − ½ b̄ᵀA⁻¹b̄ (so that H̄ = ½(p − b̄)ᵀA⁻¹(p − b̄) + V̄ + W,
//!   the mean of H over the phase);
//! - ∂W/∂q and ∂V_vibr/∂q by the adjoint of the solves
//!   (Σ w_st (∂g_s)·x_t − ½ Σ w_st x_sᵀ(∂A)x_t, with the nonzero slopes of
//!   A and g from the derivation), so no quantity is approximated by
//!   finite differences and no solve is repeated per direction;
//! - the Jacobians, the variational recurrences and the Hessian of
//!   V + V_vibr at run time, by dual numbers through the generated fields,
//!   recurrences and gradient: written out by forward mode through the
//!   solves, they and ∂W/∂q grew like N³ (a 12-link chain's module was
//!   3.9 MB, now 1.3).

use crate::derive::{Derivation, NumericForm};
use crate::emit::Step;
use crate::error::DeriveError;
use crate::functions::{
    common_functions, taylor_set, Context, Function, Inputs, Tangents, TaylorFunction,
};

/// The name of entry (i, j) of a symmetric matrix `prefix` (upper triangle).
fn entry(prefix: &str, i: usize, j: usize) -> String {
    format!("{prefix}__{}_{}", i.min(j), i.max(j))
}

/// The upper triangle of a symmetric matrix as named outputs.
pub(crate) fn upper(prefix: &str, m: &[Vec<String>]) -> Vec<(String, String)> {
    let n = m.len();
    (0..n)
        .flat_map(|i| (i..n).map(move |j| (i, j)))
        .map(|(i, j)| (entry(prefix, i, j), m[i][j].clone()))
        .collect()
}

/// The full matrix of names of a symmetric matrix.
pub(crate) fn names(prefix: &str, n: usize) -> Vec<Vec<String>> {
    (0..n)
        .map(|i| (0..n).map(|j| entry(prefix, i, j)).collect())
        .collect()
}

/// Σ_i x_i·y_i as text.
pub(crate) fn dot(x: &[String], y: &[String]) -> String {
    let terms: Vec<String> = x.iter().zip(y).map(|(a, b)| format!("{a}*{b}")).collect();
    format!("({})", terms.join("+"))
}

/// A's upper triangle (`mass__i_j`) and the modes g_s of b (`mode{s}__{i}`).
fn mass_and_modes(derivation: &Derivation, form: &NumericForm) -> Vec<(String, String)> {
    let mut values = upper("mass", &derivation.mass_matrix);
    for (s, mode) in form.modes.iter().enumerate() {
        values.extend(
            mode.iter()
                .enumerate()
                .map(|(i, g)| (format!("mode{s}__{i}"), g.clone())),
        );
    }
    values
}

/// Steps of x_t = A⁻¹g_t for every mode g_t of b over the phase (as
/// `solved{t}__{i}`) and V_vibr = ½ Σ M_st g_s·x_t (as `v_vibr__`), from
/// the coordinates alone. (Generated names contain `__`, which no name of a
/// model file may: they never shadow a parameter.)
fn vibrational_steps(derivation: &Derivation, form: &NumericForm) -> Vec<Step> {
    let n = derivation.dof;
    let values = mass_and_modes(derivation, form);
    let mut steps = vec![Step::Values(values)];
    if !form.modes.is_empty() {
        steps.push(Step::Solve {
            matrix: names("mass", n),
            columns: (0..form.modes.len())
                .map(|s| (0..n).map(|i| format!("mode{s}__{i}")).collect())
                .collect(),
            names: (0..form.modes.len())
                .map(|s| (0..n).map(|i| format!("solved{s}__{i}")).collect())
                .collect(),
            semidefinite: false,
        });
    }
    let w_vibr = mode_quadratic_form(n, &form.mode_products);
    steps.push(Step::Values(vec![("v_vibr__".into(), w_vibr)]));
    steps
}

/// ½ Σ_st weights_st g_s·x_t as text ("0" without modes).
fn mode_quadratic_form(n: usize, weights: &[Vec<f64>]) -> String {
    let mut terms = Vec::new();
    for (s, row) in weights.iter().enumerate() {
        for (t, &weight) in row.iter().enumerate() {
            if weight != 0.0 {
                let g: Vec<String> = (0..n).map(|i| format!("mode{s}__{i}")).collect();
                let x: Vec<String> = (0..n).map(|i| format!("solved{t}__{i}")).collect();
                terms.push(format!("{weight:?}*{}", dot(&g, &x)));
            }
        }
    }
    if terms.is_empty() {
        "0".into()
    } else {
        format!("({})/2", terms.join("+"))
    }
}

/// The exact field: A, p − b, the solve for q', then p'.
fn exact_steps(
    cx: &Context,
    derivation: &Derivation,
    form: &NumericForm,
) -> (Vec<Step>, Vec<String>) {
    let n = cx.n();
    let momenta = cx.momenta();
    let mut values = upper("mass", &derivation.mass_matrix);
    values.extend((0..n).map(|i| {
        (
            format!("residual__{i}"),
            format!("{}-({})", momenta[i], form.linear_term[i]),
        )
    }));
    let rates: Vec<(String, String)> = (0..n)
        .map(|i| (format!("dp__{i}"), derivation.momentum_rates[i].clone()))
        .collect();
    let mut outputs = cx.velocities();
    outputs.extend(rates.iter().map(|(name, _)| name.clone()));
    let steps = vec![
        Step::Values(values),
        Step::Solve {
            matrix: names("mass", n),
            columns: vec![(0..n).map(|i| format!("residual__{i}")).collect()],
            names: vec![cx.velocities()],
            semidefinite: false,
        },
        Step::Values(rates),
    ];
    (steps, outputs)
}

/// The averaged field: q' = A⁻¹(p − b̄) (named like the velocities, which
/// the averaged rates use), W and its gradient, then [q', p'] as `f0..`.
fn averaged_steps(
    cx: &Context,
    derivation: &Derivation,
    form: &NumericForm,
) -> (Vec<Step>, Vec<String>) {
    let n = cx.n();
    let momenta = cx.momenta();
    let mut steps = vibrational_steps(derivation, form);
    let shifted: Vec<(String, String)> = (0..n)
        .map(|i| {
            (
                format!("residual_mean__{i}"),
                format!("{}-({})", momenta[i], form.mean_linear_term[i]),
            )
        })
        .collect();
    steps.push(Step::Values(shifted));
    steps.push(Step::Solve {
        matrix: names("mass", n),
        columns: vec![(0..n).map(|i| format!("residual_mean__{i}")).collect()],
        names: vec![cx.velocities()],
        semidefinite: false,
    });
    steps.push(Step::Values(vec![(
        "w__".into(),
        dynamic_potential(n, form),
    )]));
    let weights = dynamic_weights(form);
    steps.push(Step::Values(quadratic_form_gradient(
        n, form, &weights, "dw",
    )));
    let mut field: Vec<(String, String)> = cx
        .velocities()
        .into_iter()
        .enumerate()
        .map(|(i, v)| (format!("f__{i}"), v))
        .collect();
    field.extend((0..n).map(|k| {
        (
            format!("f__{}", n + k),
            format!("({})-dw__{k}", form.averaged_momentum_rates[k]),
        )
    }));
    let outputs = field.iter().map(|(name, _)| name.clone()).collect();
    steps.push(Step::Values(field));
    (steps, outputs)
}

/// The weights w_st = M_st − m_s m_t of W = V_vibr − ½ b̄ᵀA⁻¹b̄ =
/// ½ Σ w_st g_s·x_t, the part of H̄ besides V̄ that depends on q alone.
fn dynamic_weights(form: &NumericForm) -> Vec<Vec<f64>> {
    form.mode_products
        .iter()
        .zip(&form.mode_means)
        .map(|(row, ms)| {
            row.iter()
                .zip(&form.mode_means)
                .map(|(mst, mt)| mst - ms * mt)
                .collect()
        })
        .collect()
}

/// W as text (V_vibr itself where b̄ = 0).
fn dynamic_potential(n: usize, form: &NumericForm) -> String {
    if form.mode_means.iter().all(|m| *m == 0.0) {
        return "v_vibr__".into();
    }
    mode_quadratic_form(n, &dynamic_weights(form))
}

/// The gradient of ½ Σ_st w_st g_s·x_t (W, or V_vibr with w = M) as
/// `{prefix}__k`, by the adjoint of the solves x_t = A⁻¹g_t (A and w
/// symmetric): ∂_k = Σ_st w_st (∂_k g_s)·x_t − ½ Σ_st w_st x_sᵀ(∂_k A)x_t.
/// No solve per direction, and only the nonzero slopes of A and g appear.
fn quadratic_form_gradient(
    n: usize,
    form: &NumericForm,
    weights: &[Vec<f64>],
    prefix: &str,
) -> Vec<(String, String)> {
    let mut terms: Vec<Vec<String>> = vec![Vec::new(); n];
    let x = |t: usize, i: usize| format!("solved{t}__{i}");
    for (k, s, i, slope) in &form.mode_slopes {
        for (t, &w) in weights[*s].iter().enumerate() {
            if w != 0.0 {
                terms[*k].push(format!("({w:?})*({slope})*{}", x(t, *i)));
            }
        }
    }
    for (k, i, j, slope) in &form.mass_slopes {
        for (s, row) in weights.iter().enumerate() {
            for (t, &w) in row.iter().enumerate() {
                if w == 0.0 {
                    continue;
                }
                let pair = if i == j {
                    format!("{}*{}", x(s, *i), x(t, *i))
                } else if s == t {
                    format!("2*{}*{}", x(s, *i), x(s, *j))
                } else {
                    format!("({}*{}+{}*{})", x(s, *i), x(t, *j), x(s, *j), x(t, *i))
                };
                terms[*k].push(format!("({:?})*({slope})*{pair}", -w / 2.0));
            }
        }
    }
    terms
        .into_iter()
        .enumerate()
        .map(|(k, t)| {
            let text = if t.is_empty() {
                "0".into()
            } else {
                t.join("+")
            };
            (format!("{prefix}__{k}"), text)
        })
        .collect()
}

/// A vector field of the numeric form: its steps and outputs, and what its
/// Hamiltonian needs (the first `hamiltonian_steps` steps, then the
/// expression `hamiltonian`).
struct Field<'a> {
    /// `exact` or `averaged`: the functions are `<prefix>_rhs`,
    /// `<prefix>_jacobian` and the Hamiltonian.
    prefix: &'a str,
    inputs: Inputs,
    /// Documentation of the field, its Jacobian and its Hamiltonian.
    docs: [&'a str; 3],
    steps: &'a [Step],
    outputs: &'a [String],
    hamiltonian_steps: usize,
    hamiltonian: String,
}

/// `<prefix>_jacobian`: `<prefix>_rhs_dual`, the field over dual numbers,
/// one column a pass (`crate::ode::dual::jacobian`). Written out by forward
/// mode through the solves, the Jacobians grew like N³: 1 of a 12-link
/// chain's 3.9 MB of code.
fn jacobian_by_dual_numbers(prefix: &str, doc: &str, m: usize) -> Function {
    let (args, time) = match prefix {
        "exact" => ("time__: f64, ", "time__, "),
        _ => ("", ""),
    };
    Function {
        name: format!("{prefix}_jacobian"),
        doc: format!("{doc} By dual numbers through `{prefix}_rhs_dual`, one column a pass."),
        args: format!("{args}y: &[f64; {m}], params: &Params"),
        ret: format!("[[f64; {m}]; {m}]"),
        body: Vec::new(),
        result: format!("crate::ode::dual::jacobian(y, |y| {prefix}_rhs_dual({time}y, params))"),
    }
}

/// The field's function, its Jacobian and its Hamiltonian.
fn field_functions(
    cx: &Context,
    field: Field,
    functions: &mut Vec<Function>,
) -> Result<(), DeriveError> {
    let m = 2 * cx.n();
    functions.push(cx.function_steps(
        &format!("{}_rhs", field.prefix),
        field.docs[0],
        field.inputs,
        format!("[f64; {m}]"),
        field.steps,
        format!("[{}]", field.outputs.join(", ")),
    )?);
    let over_duals = match field.inputs {
        Inputs::State => Inputs::DualState,
        _ => Inputs::DualAveragedState,
    };
    functions.push(cx.function_steps(
        &format!("{}_rhs_dual", field.prefix),
        "The field over dual numbers, for its Jacobian.",
        over_duals,
        format!("[crate::ode::Dual; {m}]"),
        field.steps,
        format!("[{}]", field.outputs.join(", ")),
    )?);
    functions.push(jacobian_by_dual_numbers(field.prefix, field.docs[1], m));
    let mut steps = field.steps[..field.hamiltonian_steps].to_vec();
    steps.push(Step::Values(vec![("h__".into(), field.hamiltonian)]));
    let name = match field.prefix {
        "exact" => "hamiltonian".to_string(),
        other => format!("{other}_hamiltonian"),
    };
    functions.push(cx.function_steps(
        &name,
        field.docs[2],
        field.inputs,
        "f64".into(),
        &steps,
        "h__".into(),
    )?);
    Ok(())
}

/// Every generated function of a numeric-solve model.
pub fn functions(
    cx: &Context,
    derivation: &Derivation,
    form: &NumericForm,
) -> Result<(Vec<Function>, Vec<TaylorFunction>), DeriveError> {
    let n = cx.n();
    let mut functions = common_functions(cx, derivation)?;
    let (exact, exact_outputs) = exact_steps(cx, derivation, form);
    functions.push(cx.function_steps(
        "velocities",
        "Velocities q' solved from A(q) q' = p − b (Cholesky) at state y = [q, p].",
        Inputs::State,
        format!("[f64; {n}]"),
        &exact[..2],
        format!("[{}]", cx.velocities().join(", ")),
    )?);
    let residuals: Vec<String> = (0..n).map(|i| format!("residual__{i}")).collect();
    let hamiltonian = format!(
        "{}/2+({})",
        dot(&residuals, &cx.velocities()),
        form.potential
    );
    field_functions(
        cx,
        Field {
            prefix: "exact",
            inputs: Inputs::State,
            docs: [
                "Hamilton's equations with forces: [q', p'] with A q' = p − b solved numerically, p' = ∂L/∂q + Q.",
                "Jacobian ∂(q', p')/∂(q, p) of the exact field.",
                "Hamiltonian H(q, p, t) = ½ (p − b)ᵀq' + V.",
            ],
            steps: &exact,
            outputs: &exact_outputs,
            hamiltonian_steps: 2,
            hamiltonian,
        },
        &mut functions,
    )?;
    let averaged = match cx.model.fast_phase {
        Some(_) => {
            let field = averaged_functions(cx, derivation, form, &mut functions)?;
            if has_second_order(derivation, cx.model) {
                let (second, steps) = second_order(cx, derivation, form);
                functions.extend(crate::functions::second_order_functions(
                    cx, &second, &steps,
                )?);
            }
            Some(field)
        }
        None => None,
    };
    let taylor = taylor_set(
        cx,
        (&exact, &exact_outputs),
        averaged.as_ref().map(|(s, o)| (&s[..], &o[..])),
        Tangents::DualNumbers,
    )?;
    Ok((functions, taylor))
}

/// The functions of the averaged system and the vibrational potential;
/// returns the averaged field's steps and outputs (for its recurrences).
fn averaged_functions(
    cx: &Context,
    derivation: &Derivation,
    form: &NumericForm,
    functions: &mut Vec<Function>,
) -> Result<(Vec<Step>, Vec<String>), DeriveError> {
    let n = cx.n();
    let vibrational = vibrational_steps(derivation, form);
    functions.push(cx.function_steps(
        "vibrational_potential",
        "Vibrational potential V_vibr(q) = ½ mean(bᵀA⁻¹b) = ½ Σ M_st g_sᵀA⁻¹g_t over the modes g_s of b.",
        Inputs::Coordinates,
        "f64".into(),
        &vibrational,
        "v_vibr__".into(),
    )?);
    let mut effective = vibrational.clone();
    effective.push(Step::Values(vec![(
        "v__".into(),
        format!("({})+v_vibr__", derivation.potential),
    )]));
    functions.push(cx.function_steps(
        "effective_potential",
        "Effective potential V + V_vibr of the averaged system.",
        Inputs::Coordinates,
        "f64".into(),
        &effective,
        "v__".into(),
    )?);
    let mut gradient = vibrational_steps(derivation, form);
    gradient.push(Step::Values(quadratic_form_gradient(
        n,
        form,
        &form.mode_products,
        "dv_vibr",
    )));
    gradient.push(Step::Values(
        (0..n)
            .map(|k| {
                (
                    format!("g__{k}"),
                    format!("({})+dv_vibr__{k}", derivation.potential_gradient[k]),
                )
            })
            .collect(),
    ));
    let names: Vec<String> = (0..n).map(|k| format!("g__{k}")).collect();
    functions.push(cx.function_steps(
        "effective_potential_gradient_dual",
        "∇(V + V_vibr) over dual numbers (∇V_vibr by the adjoint of the solves), for the Hessian.",
        Inputs::DualCoordinates,
        format!("[crate::ode::Dual; {n}]"),
        &gradient,
        format!("[{}]", names.join(", ")),
    )?);
    functions.push(Function {
        name: "effective_potential_hessian".into(),
        doc: "∂²(V + V_vibr)/∂q²: the Jacobian of `effective_potential_gradient_dual` by dual numbers, one column a pass.".into(),
        args: format!("q: &[f64; {n}], params: &Params"),
        ret: format!("[[f64; {n}]; {n}]"),
        body: Vec::new(),
        result: "crate::ode::dual::jacobian(q, |q| effective_potential_gradient_dual(q, params))".into(),
    });
    let (averaged, outputs) = averaged_steps(cx, derivation, form);
    let shifted: Vec<String> = (0..n).map(|i| format!("residual_mean__{i}")).collect();
    let hamiltonian = format!(
        "{}/2+w__+({})",
        dot(&shifted, &cx.velocities()),
        derivation.potential
    );
    field_functions(
        cx,
        Field {
            prefix: "averaged",
            inputs: Inputs::AveragedState,
            docs: [
                "Averaged equations: q' = A⁻¹(p − b̄), p' = ∂L̄₀/∂q + P̄ − ∂W/∂q.",
                "Jacobian of the averaged field.",
                "Averaged Hamiltonian H̄(q, p) = ½ (p − b̄)ᵀA⁻¹(p − b̄) + V̄ + W.",
            ],
            steps: &averaged,
            outputs: &outputs,
            hamiltonian_steps: averaged.len() - 2,
            hamiltonian,
        },
        functions,
    )?;
    Ok((averaged, outputs))
}

/// The largest numeric-solve model averaged to second order. K̄₂ holds
/// second derivatives of the solves in every pair of coordinates, so its
/// code grows like n⁴: 1 200 lines for 4 degrees of freedom, 8 300 for 6,
/// which made the library's build 8 minutes longer.
pub const SECOND_ORDER_MAX_DOF: usize = 4;

/// Whether a numeric-solve model gets the second-order averaged system.
pub fn has_second_order(derivation: &Derivation, model: &crate::model::Model) -> bool {
    derivation.numeric.is_some()
        && model.fast_phase.is_some()
        && derivation.dof <= SECOND_ORDER_MAX_DOF
}

/// Coefficients of the Lie series as expressions over named outputs of the
/// emitter's DAG. A bracket names its operands and their first derivatives
/// in every state variable (forward mode through the solves, see
/// [`crate::emit::Emitter::derivative`]): nothing is expanded, and nested
/// brackets differentiate the earlier derivatives through their
/// definitions.
struct DagCoefficients {
    /// [q, p]: the first half coordinates, the second momenta.
    state: Vec<String>,
    steps: Vec<Step>,
    /// Expression text → the name it was given.
    named: std::collections::HashMap<String, String>,
}

impl DagCoefficients {
    /// The name of `text` (a new output with its derivatives on first use).
    fn name(&mut self, text: &str) -> String {
        if let Some(name) = self.named.get(text) {
            return name.clone();
        }
        let name = format!("lie{}__", self.named.len());
        self.steps
            .push(Step::Values(vec![(name.clone(), text.to_string())]));
        self.steps.push(Step::Derivatives(
            self.state
                .iter()
                .enumerate()
                .map(|(k, v)| (format!("{name}d{k}"), name.clone(), vec![v.clone()]))
                .collect(),
        ));
        self.named.insert(text.to_string(), name.clone());
        name
    }
}

impl crate::lie::Coefficients for DagCoefficients {
    type C = String;
    fn zero(&mut self) -> String {
        "0".into()
    }
    fn add(&mut self, a: &String, b: &String) -> String {
        match (a.as_str(), b.as_str()) {
            ("0", _) => b.clone(),
            (_, "0") => a.clone(),
            _ => format!("{a}+{b}"),
        }
    }
    fn scale(&mut self, c: &String, numerator: i64, denominator: i64) -> String {
        if c == "0" || numerator == 0 {
            return "0".into();
        }
        format!("({numerator}/{denominator})*({c})")
    }
    fn bracket(&mut self, f: &String, g: &String) -> String {
        if f == "0" || g == "0" {
            return "0".into();
        }
        let (f, g) = (self.name(f), self.name(g));
        let n = self.state.len() / 2;
        let terms: Vec<String> = (0..n)
            .map(|i| format!("{f}d{i}*{g}d{}-{f}d{}*{g}d{i}", n + i, n + i))
            .collect();
        format!("({})", terms.join("+"))
    }
}

/// The second-order averaged system of a numeric-solve model: the Lie
/// series of `crates/derive/src/lie.rs` with coefficients in the DAG. With y = A⁻¹p,
/// x_s = A⁻¹g_s (one factorisation) and b = Σ h_s(θ) g_s,
/// H = ½ pᵀy − Σ h_s g_s·y + ½ Σ h_s h_t g_s·x_t + V(q, θ), whose Fourier
/// series in θ follows from the products h_s h_t (monomials in sin θ,
/// cos θ).
pub fn second_order(
    cx: &Context,
    derivation: &Derivation,
    form: &NumericForm,
) -> (
    crate::deprit::SecondOrderForm,
    crate::functions::SecondOrderSteps,
) {
    use crate::lie::{add_to, monomial, Harmonic, Series};
    let n = cx.n();
    let momenta = cx.momenta();
    let modes = form.modes.len();
    let values = mass_and_modes(derivation, form);
    let mut columns = vec![momenta.clone()];
    let mut solved: Vec<Vec<String>> = vec![(0..n).map(|i| format!("inverse_p__{i}")).collect()];
    for s in 0..modes {
        columns.push((0..n).map(|i| format!("mode{s}__{i}")).collect());
        solved.push((0..n).map(|i| format!("solved{s}__{i}")).collect());
    }
    let mode = |s: usize| -> Vec<String> { (0..n).map(|i| format!("mode{s}__{i}")).collect() };
    let mut scalars = vec![("kinetic__".to_string(), dot(&momenta, &solved[0]))];
    for s in 0..modes {
        scalars.push((format!("coupling{s}__"), dot(&mode(s), &solved[0])));
        for t in s..modes {
            scalars.push((format!("vibration{s}_{t}__"), dot(&mode(s), &solved[1 + t])));
        }
    }
    let base = vec![
        Step::Values(values),
        Step::Solve {
            matrix: names("mass", n),
            columns,
            names: solved,
            semidefinite: false,
        },
        Step::Values(scalars),
    ];
    let mut state = cx.coordinates();
    state.extend(momenta.iter().cloned());
    let mut alg = DagCoefficients {
        state,
        steps: Vec::new(),
        named: Default::default(),
    };
    let mut series: Series<String> = Series::new();
    add_to(
        &mut alg,
        &mut series,
        Harmonic::Cos(0),
        "kinetic__/2".into(),
    );
    for (s, &(a, b)) in form.mode_exponents.iter().enumerate() {
        for (h, numerator, denominator) in monomial(a, b) {
            let term = format!("({}/{denominator})*coupling{s}__", -numerator);
            add_to(&mut alg, &mut series, h, term);
        }
        for (t, &(c, d)) in form.mode_exponents.iter().enumerate() {
            let (low, high) = (s.min(t), s.max(t));
            for (h, numerator, denominator) in monomial(a + c, b + d) {
                let term = format!("({numerator}/{})*vibration{low}_{high}__", 2 * denominator);
                add_to(&mut alg, &mut series, h, term);
            }
        }
    }
    for (h, coefficient) in &form.potential_series {
        add_to(&mut alg, &mut series, *h, format!("({coefficient})"));
    }
    let terms = crate::lie::second_order(&mut alg, &series);
    let mean = crate::lie::mean(&mut alg, &series);
    let phase = cx.model.fast_phase.as_ref().map_or("", |f| f.name.as_str());
    let generator: Vec<String> = terms
        .generator
        .iter()
        .map(|(h, c)| match h {
            Harmonic::Cos(0) => format!("({c})"),
            Harmonic::Cos(k) => format!("({c})*cos({k}*{phase})"),
            Harmonic::Sin(k) => format!("({c})*sin({k}*{phase})"),
        })
        .collect();
    let eps = format!("(1/({}))", derivation.phase_rate);
    let velocities = averaged_velocity_steps(cx, derivation, form);
    let mut hamiltonian = base.clone();
    hamiltonian.extend(alg.steps);
    (
        crate::deprit::SecondOrderForm {
            hamiltonian: format!(
                "({mean}) + {eps}*({}) + {eps}^2*({})",
                terms.first, terms.second
            ),
            forces: form.mean_forces.clone(),
            generator: match generator.is_empty() {
                true => "0".into(),
                false => format!("{eps}*({})", generator.join("+")),
            },
        },
        crate::functions::SecondOrderSteps {
            hamiltonian,
            forces: velocities,
            generator: base,
            run_time_derivatives: true,
        },
    )
}

/// The steps that solve the velocities q' = A⁻¹(p − b̄) for the forces P̄
/// of the averaged system (none when the model has no forces).
fn averaged_velocity_steps(cx: &Context, derivation: &Derivation, form: &NumericForm) -> Vec<Step> {
    let (n, momenta) = (cx.n(), cx.momenta());
    let residuals: Vec<(String, String)> = (0..n)
        .map(|i| {
            (
                format!("residual_mean__{i}"),
                format!("{}-({})", momenta[i], form.mean_linear_term[i]),
            )
        })
        .collect();
    // The forces P̄ read the velocities q' = A⁻¹(p − b̄), if there are any.
    let frictionless = form.mean_forces.iter().all(|f| f == "0");
    if frictionless {
        return Vec::new();
    }
    vec![
        Step::Values(upper("mass", &derivation.mass_matrix)),
        Step::Values(residuals),
        Step::Solve {
            matrix: names("mass", n),
            columns: vec![(0..n).map(|i| format!("residual_mean__{i}")).collect()],
            names: vec![cx.velocities()],
            semidefinite: false,
        },
    ]
}
