//! The generated functions of one model, before rendering: each with its
//! inputs, its arguments and its body (straight-line code from the
//! emitter's DAG), the Taylor-coefficient functions, and the second order's
//! steps. `generate.rs` renders them through the templates; the
//! numeric-solve form (`numeric.rs`) builds its own over the same types.

use crate::algebra::momentum_name;
use crate::derive::Derivation;
use crate::emit::{params_line, Emitter, Step};
use crate::error::DeriveError;
use crate::model::Model;
use crate::taylor::{recurrences, Signature};
use serde::Serialize;

/// A generated Taylor-coefficient function (layout in `templates/taylor.rs.tera`).
#[derive(Serialize)]
pub struct TaylorFunction {
    name: String,
    doc: String,
    /// State length (of the solution, without tangents).
    dim: usize,
    /// Whether it takes tangent columns (`z: &[f64]`, flat `out`).
    variational: bool,
    /// The time argument's name (the model's).
    time: String,
    /// `let &Params { .. } = params;`
    params: String,
    body: Vec<String>,
    /// Runs of its order-n loop in functions of their own (`taylor::Part`).
    parts: Vec<TaylorPart>,
}

impl TaylorFunction {
    /// Whether these are tangent recurrences (written out, see [`Tangents`]).
    pub(crate) fn is_variational(&self) -> bool {
        self.variational
    }
    /// The length of its written recurrences in bytes (what the compiler
    /// is given, once per number type).
    pub(crate) fn source_bytes(&self) -> usize {
        let lines = self.parts.iter().flat_map(|p| &p.body);
        let body: usize = self
            .body
            .iter()
            .chain(lines)
            .map(|line| line.len() + 5)
            .sum();
        let parts: usize = self
            .parts
            .iter()
            .map(|p| p.args.len() + self.params.len())
            .sum();
        body + parts
    }
}

#[derive(Serialize)]
pub struct TaylorPart {
    name: String,
    /// Its arguments after `n` and `params`.
    args: String,
    body: Vec<String>,
}

#[derive(Serialize)]
pub struct Function {
    pub(crate) name: String,
    pub(crate) doc: String,
    pub(crate) args: String,
    pub(crate) ret: String,
    pub(crate) body: Vec<String>,
    pub(crate) result: String,
}

/// What a function reads from its arguments.
#[derive(Clone, Copy)]
pub enum Inputs {
    /// Parameters only.
    Params,
    /// Coordinates only (`q: &[f64; N]`).
    Coordinates,
    /// Coordinates as dual numbers, for first derivatives at run time.
    DualCoordinates,
    /// Coordinates and velocities, at time t.
    CoordinatesVelocities,
    /// Coordinates at time t.
    TimeCoordinates,
    /// Those as dual numbers (time stays f64), for Jacobians at run time.
    DualTimeCoordinates,
    /// Coordinates and velocities as dual numbers, at time t.
    DualCoordinatesVelocities,
    /// The Hamiltonian state `y = [q, p]` at time t.
    State,
    /// The state of the autonomous averaged system.
    AveragedState,
    /// That state as hyper-dual numbers (`crate::ode::HyperDual`), for
    /// derivatives at run time.
    HyperDualAveragedState,
    /// The Hamiltonian state as dual numbers (`crate::ode::Dual`), for the
    /// Jacobian at run time.
    DualState,
    /// The averaged system's state as dual numbers.
    DualAveragedState,
    /// `y = [s, s']` of a contact model (sliding coordinates, velocities).
    ContactState,
}

pub struct Context<'a> {
    pub model: &'a Model,
    /// Degrees of freedom (contacts, for a contact model).
    pub(crate) n: usize,
    /// For a contact model: the sliding coordinates and their velocities.
    pub(crate) contact_state: Vec<String>,
    /// dθ/dt of the fast phase, if there is one.
    pub(crate) model_phase_rate: String,
}

impl Context<'_> {
    pub fn n(&self) -> usize {
        self.n
    }
    pub fn coordinates(&self) -> Vec<String> {
        self.model
            .coordinates
            .iter()
            .map(|c| c.name.clone())
            .collect()
    }
    pub fn velocities(&self) -> Vec<String> {
        self.model
            .coordinates
            .iter()
            .map(|c| c.velocity.clone())
            .collect()
    }
    pub fn momenta(&self) -> Vec<String> {
        self.coordinates()
            .iter()
            .map(|c| momentum_name(c))
            .collect()
    }

    /// The arguments and first lines of a generated function. The inputs
    /// are unpacked into the model's own names, state first (an argument is
    /// read once, before any name of the model can shadow it), then the
    /// parameters (`params` is a reserved name); the time argument has the
    /// model's name for time, so no parameter can shadow it.
    fn signature_and_prelude(&self, inputs: Inputs) -> (String, Vec<String>) {
        let n = self.n();
        let time = &self.model.time;
        let params: Vec<String> = self
            .model
            .parameters
            .iter()
            .map(|p| p.name.clone())
            .collect();
        let params_line = params_line(&params);
        let phase_line = self
            .model
            .fast_phase
            .as_ref()
            .map(|f| format!("let {} = {time} * phase_rate(params);", f.name));
        let mut prelude = Vec::new();
        let args = match inputs {
            Inputs::Params => "params: &Params".to_string(),
            Inputs::Coordinates | Inputs::DualCoordinates => {
                prelude.push(format!("let [{}] = *q;", self.coordinates().join(", ")));
                match inputs {
                    Inputs::DualCoordinates => {
                        format!("q: &[crate::ode::Dual; {n}], params: &Params")
                    }
                    _ => format!("q: &[f64; {n}], params: &Params"),
                }
            }
            Inputs::CoordinatesVelocities => {
                prelude.push(format!(
                    "let ([{}], [{}]) = (*q, *qd);",
                    self.coordinates().join(", "),
                    self.velocities().join(", ")
                ));
                format!("{time}: f64, q: &[f64; {n}], qd: &[f64; {n}], params: &Params")
            }
            Inputs::TimeCoordinates => {
                prelude.push(format!("let [{}] = *q;", self.coordinates().join(", ")));
                format!("{time}: f64, q: &[f64; {n}], params: &Params")
            }
            Inputs::DualTimeCoordinates => {
                prelude.push(format!("let [{}] = *q;", self.coordinates().join(", ")));
                format!("{time}: f64, q: &[crate::ode::Dual; {n}], params: &Params")
            }
            Inputs::DualCoordinatesVelocities => {
                prelude.push(format!(
                    "let ([{}], [{}]) = (*q, *qd);",
                    self.coordinates().join(", "),
                    self.velocities().join(", ")
                ));
                format!("{time}: f64, q: &[crate::ode::Dual; {n}], qd: &[crate::ode::Dual; {n}], params: &Params")
            }
            Inputs::ContactState => {
                prelude.push(format!("let [{}] = *y;", self.contact_state.join(", ")));
                format!("y: &[f64; {}], params: &Params", 2 * n)
            }
            Inputs::State
            | Inputs::AveragedState
            | Inputs::HyperDualAveragedState
            | Inputs::DualState
            | Inputs::DualAveragedState => {
                let mut names = self.coordinates();
                names.extend(self.momenta());
                prelude.push(format!("let [{}] = *y;", names.join(", ")));
                let m = 2 * n;
                match inputs {
                    Inputs::State => format!("{time}: f64, y: &[f64; {m}], params: &Params"),
                    Inputs::DualState => {
                        format!("{time}: f64, y: &[crate::ode::Dual; {m}], params: &Params")
                    }
                    Inputs::HyperDualAveragedState => {
                        format!("y: &[crate::ode::HyperDual; {m}], params: &Params")
                    }
                    Inputs::DualAveragedState => {
                        format!("y: &[crate::ode::Dual; {m}], params: &Params")
                    }
                    _ => format!("y: &[f64; {m}], params: &Params"),
                }
            }
        };
        prelude.push(params_line);
        if matches!(
            inputs,
            Inputs::State
                | Inputs::DualState
                | Inputs::CoordinatesVelocities
                | Inputs::TimeCoordinates
                | Inputs::DualTimeCoordinates
                | Inputs::DualCoordinatesVelocities
        ) {
            prelude.extend(phase_line);
        }
        (args, prelude)
    }

    /// A function evaluating `stages` of named outputs, returning `result`.
    pub(crate) fn function(
        &self,
        name: &str,
        doc: &str,
        inputs: Inputs,
        ret: String,
        stages: &[Vec<(String, String)>],
        result: String,
    ) -> Result<Function, DeriveError> {
        let steps: Vec<Step> = stages.iter().cloned().map(Step::Values).collect();
        self.function_steps(name, doc, inputs, ret, &steps, result)
    }

    /// A function evaluating `steps`, returning `result`.
    pub fn function_steps(
        &self,
        name: &str,
        doc: &str,
        inputs: Inputs,
        ret: String,
        steps: &[Step],
        result: String,
    ) -> Result<Function, DeriveError> {
        let (args, mut body) = self.signature_and_prelude(inputs);
        let mut emitter = Emitter::default();
        emitter.lift = match inputs {
            Inputs::HyperDualAveragedState => Some("crate::ode::HyperDual::from"),
            Inputs::DualState
            | Inputs::DualAveragedState
            | Inputs::DualCoordinates
            | Inputs::DualTimeCoordinates
            | Inputs::DualCoordinatesVelocities => {
                emitter.factorisation = Some("crate::ode::dual::Cholesky");
                Some("crate::ode::Dual::from")
            }
            _ => None,
        };
        // A vector's or a matrix's entries are lifted one by one (an entry
        // may be a constant f64).
        let result = lift_entries(&emitter, &result);
        for step in steps {
            emitter.apply(step).map_err(|e| e.in_function(name))?;
        }
        body.extend(emitter.finish());
        Ok(Function {
            name: name.into(),
            doc: doc.into(),
            args,
            ret,
            body,
            result,
        })
    }
}

/// `result` with each entry of its (nested) array literal lifted.
fn lift_entries(emitter: &Emitter, result: &str) -> String {
    let Some(inner) = result.strip_prefix('[').and_then(|r| r.strip_suffix(']')) else {
        return emitter.lifted(result.to_string());
    };
    let mut entries = Vec::new();
    let (mut depth, mut begin) = (0usize, 0usize);
    for (i, c) in inner.char_indices() {
        match c {
            '[' | '(' => depth += 1,
            ']' | ')' => depth -= 1,
            ',' if depth == 0 => {
                entries.push(inner[begin..i].trim());
                begin = i + 1;
            }
            _ => {}
        }
    }
    entries.push(inner[begin..].trim());
    let lifted: Vec<String> = entries
        .into_iter()
        .map(|e| lift_entries(emitter, e))
        .collect();
    format!("[{}]", lifted.join(", "))
}

impl Context<'_> {
    /// Taylor-coefficient recurrences of x' = f, f given as steps.
    pub fn taylor_steps(
        &self,
        name: &str,
        doc: &str,
        steps: &[Step],
        outputs: &[String],
        state: Vec<String>,
    ) -> Result<TaylorFunction, DeriveError> {
        let mut emitter = Emitter::default();
        emitter.whole_angles = true;
        let phase = match &self.model.fast_phase {
            Some(phase) => {
                let rate = vec![("rate__".to_string(), self.model_phase_rate.clone())];
                emitter.stage(&rate).map_err(|e| e.in_function(name))?;
                Some((phase.name.clone(), "rate__".to_string()))
            }
            None => None,
        };
        for step in steps {
            emitter.apply(step).map_err(|e| e.in_function(name))?;
        }
        let signature = Signature {
            state,
            time: self.model.time.clone(),
            phase,
            parameters: self
                .model
                .parameters
                .iter()
                .map(|p| p.name.clone())
                .collect(),
        };
        let body = recurrences(name, &emitter.into_dag(), &signature, outputs)
            .map_err(|e| e.in_function(name))?;
        Ok(TaylorFunction {
            name: name.into(),
            doc: doc.into(),
            dim: outputs.len(),
            variational: signature.state.len() > outputs.len(),
            time: self.model.time.clone(),
            params: body.params_line,
            body: body.lines,
            parts: body
                .parts
                .into_iter()
                .map(|p| TaylorPart {
                    name: p.name,
                    args: p.args,
                    body: p.lines,
                })
                .collect(),
        })
    }
}

/// Outputs `{prefix}__{i}`: generated names contain `__`, which no name of a
/// model file may, so they never shadow a parameter or coordinate.
pub fn named(prefix: &str, values: &[String]) -> Vec<(String, String)> {
    values
        .iter()
        .enumerate()
        .map(|(i, v)| (format!("{prefix}__{i}"), v.clone()))
        .collect()
}

pub fn matrix(prefix: &str, m: &[Vec<String>]) -> (Vec<(String, String)>, String) {
    let mut outputs = Vec::new();
    let mut rows = Vec::new();
    for (i, row) in m.iter().enumerate() {
        let mut cells = Vec::new();
        for (j, v) in row.iter().enumerate() {
            let name = format!("{prefix}__{i}_{j}");
            outputs.push((name.clone(), v.clone()));
            cells.push(name);
        }
        rows.push(format!("[{}]", cells.join(", ")));
    }
    (outputs, format!("[{}]", rows.join(", ")))
}

pub fn vector(prefix: &str, values: &[String]) -> (Vec<(String, String)>, String) {
    let outputs = named(prefix, values);
    let names: Vec<String> = outputs.iter().map(|(n, _)| n.clone()).collect();
    (outputs, format!("[{}]", names.join(", ")))
}

/// The functions both forms have as closed forms: the phase rate, momenta,
/// mass matrix, potential and its derivatives.
pub fn common_functions(
    cx: &Context,
    derivation: &Derivation,
) -> Result<Vec<Function>, DeriveError> {
    let n = cx.n();
    let mut functions = Vec::new();
    if cx.model.fast_phase.is_some() {
        functions.push(cx.function(
            "phase_rate",
            "dθ/dt of the fast phase θ.",
            Inputs::Params,
            "f64".into(),
            &[vec![("rate__".into(), derivation.phase_rate.clone())]],
            "rate__".into(),
        )?);
    }
    let (outs, result) = vector("p", &derivation.momenta);
    functions.push(cx.function(
        "momenta",
        "Momenta p = A q' + b from coordinates and velocities.",
        Inputs::CoordinatesVelocities,
        format!("[f64; {n}]"),
        &[outs],
        result,
    )?);
    let (outs, result) = matrix("a", &derivation.mass_matrix);
    functions.push(cx.function(
        "mass_matrix",
        "Mass matrix A(q) = ∂²L/∂q'².",
        Inputs::Coordinates,
        format!("[[f64; {n}]; {n}]"),
        &[outs],
        result,
    )?);
    functions.push(cx.function(
        "potential",
        "Potential energy V(q) (averaged over the phase).",
        Inputs::Coordinates,
        "f64".into(),
        &[vec![("v__".into(), derivation.potential.clone())]],
        "v__".into(),
    )?);
    let (outs, result) = vector("g", &derivation.potential_gradient);
    functions.push(cx.function(
        "potential_gradient",
        "∂V/∂q.",
        Inputs::Coordinates,
        format!("[f64; {n}]"),
        &[outs],
        result,
    )?);
    let (outs, result) = matrix("c", &derivation.potential_hessian);
    functions.push(cx.function(
        "potential_hessian",
        "C = ∂²V/∂q².",
        Inputs::Coordinates,
        format!("[[f64; {n}]; {n}]"),
        &[outs],
        result,
    )?);
    Ok(functions)
}

/// The functions of the symbolic-inverse form: every quantity a closed form.
pub(crate) fn symbolic_functions(
    cx: &Context,
    derivation: &Derivation,
) -> Result<(Vec<Function>, Vec<TaylorFunction>), DeriveError> {
    let n = cx.n();
    let m = 2 * n;
    let velocity_stage: Vec<(String, String)> = cx
        .velocities()
        .into_iter()
        .zip(derivation.velocities.iter().cloned())
        .collect();
    let mut functions = common_functions(cx, derivation)?;
    let (outs, result) = vector("v", &derivation.velocities);
    functions.push(cx.function(
        "velocities",
        "Velocities q' = A⁻¹(p − b) at state y = [q, p].",
        Inputs::State,
        format!("[f64; {n}]"),
        &[outs],
        result,
    )?);
    let (exact_stages, rhs_names) = exact_field(cx, derivation, &velocity_stage);
    functions.push(cx.function(
        "exact_rhs",
        "Hamilton's equations with forces: [q', p'] with q' = A⁻¹(p − b), p' = ∂L/∂q + Q.",
        Inputs::State,
        format!("[f64; {m}]"),
        &exact_stages,
        format!("[{}]", rhs_names.join(", ")),
    )?);
    let (outs, result) = matrix("j", &derivation.exact_jacobian);
    functions.push(cx.function(
        "exact_jacobian",
        "Jacobian ∂(q', p')/∂(q, p) of the exact field.",
        Inputs::State,
        format!("[[f64; {m}]; {m}]"),
        &[velocity_stage.clone(), outs],
        result,
    )?);
    functions.push(cx.function(
        "hamiltonian",
        "Hamiltonian H(q, p, t).",
        Inputs::State,
        "f64".into(),
        &[vec![("h__".into(), derivation.hamiltonian.clone())]],
        "h__".into(),
    )?);

    if cx.model.fast_phase.is_some() {
        functions.extend(symbolic_averaged_functions(cx, derivation)?);
    }

    if let Some(second) = &derivation.second_order {
        functions.extend(second_order_functions(
            cx,
            second,
            &SecondOrderSteps::default(),
        )?);
    }
    let taylor_functions = taylor_functions(cx, derivation, &velocity_stage)?;
    Ok((functions, taylor_functions))
}

/// The symbolic-inverse form's averaged functions: V_vibr, V + V_vibr and
/// its Hessian, the averaged field, its Jacobian and H̄.
fn symbolic_averaged_functions(
    cx: &Context,
    derivation: &Derivation,
) -> Result<Vec<Function>, DeriveError> {
    let (n, m) = (cx.n(), 2 * cx.n());
    let mut functions = Vec::new();
    functions.push(cx.function(
        "vibrational_potential",
        "Vibrational potential V_vibr(q) = ½ mean(bᵀA⁻¹b).",
        Inputs::Coordinates,
        "f64".into(),
        &[vec![(
            "w__".into(),
            derivation.vibrational_potential.clone(),
        )]],
        "w__".into(),
    )?);
    let effective = format!(
        "({}) + ({})",
        derivation.potential, derivation.vibrational_potential
    );
    functions.push(cx.function(
        "effective_potential",
        "Effective potential V + V_vibr of the averaged system.",
        Inputs::Coordinates,
        "f64".into(),
        &[vec![("v__".into(), effective)]],
        "v__".into(),
    )?);
    let (outs, result) = matrix("b", &derivation.effective_potential_hessian);
    functions.push(cx.function(
        "effective_potential_hessian",
        "∂²(V + V_vibr)/∂q².",
        Inputs::Coordinates,
        format!("[[f64; {n}]; {n}]"),
        &[outs],
        result,
    )?);
    let (outs, result) = vector("f", &derivation.averaged_rhs);
    functions.push(cx.function(
        "averaged_rhs",
        "Averaged equations: q' = ∂H̄/∂p, p' = −∂H̄/∂q + P̄.",
        Inputs::AveragedState,
        format!("[f64; {m}]"),
        &[outs],
        result,
    )?);
    let (outs, result) = matrix("j", &derivation.averaged_jacobian);
    functions.push(cx.function(
        "averaged_jacobian",
        "Jacobian of the averaged field.",
        Inputs::AveragedState,
        format!("[[f64; {m}]; {m}]"),
        &[outs],
        result,
    )?);
    functions.push(cx.function(
        "averaged_hamiltonian",
        "Averaged Hamiltonian H̄(q, p).",
        Inputs::AveragedState,
        "f64".into(),
        &[vec![(
            "h__".into(),
            derivation.averaged_hamiltonian.clone(),
        )]],
        "h__".into(),
    )?);
    Ok(functions)
}

/// The exact field as stages (velocities, then momentum rates) and the names
/// of its outputs [q', p'].
pub(crate) fn exact_field(
    cx: &Context,
    derivation: &Derivation,
    velocity_stage: &[(String, String)],
) -> (Vec<Vec<(String, String)>>, Vec<String>) {
    let (rates, _) = vector("dp", &derivation.momentum_rates);
    let mut names = cx.velocities();
    names.extend(rates.iter().map(|(name, _)| name.clone()));
    (vec![velocity_stage.to_vec(), rates], names)
}

/// The Taylor-coefficient functions of a model: the exact field, the
/// averaged one, and the exact field with tangent vectors (FLI, monodromy,
/// Lyapunov spectrum), the tangent rates as forward-mode derivatives of the
/// field's nodes.
pub(crate) fn taylor_functions(
    cx: &Context,
    derivation: &Derivation,
    velocity_stage: &[(String, String)],
) -> Result<Vec<TaylorFunction>, DeriveError> {
    let (exact_stages, rhs_names) = exact_field(cx, derivation, velocity_stage);
    let exact: Vec<Step> = exact_stages.into_iter().map(Step::Values).collect();
    let averaged = cx.model.fast_phase.as_ref().map(|_| {
        let (outs, _) = vector("f", &derivation.averaged_rhs);
        let names: Vec<String> = outs.iter().map(|(n, _)| n.clone()).collect();
        (vec![Step::Values(outs)], names)
    });
    let mut functions = taylor_set(
        cx,
        (&exact, &rhs_names),
        averaged.as_ref().map(|(s, n)| (&s[..], &n[..])),
        Tangents::WrittenOut,
    )?;
    if cx.model.coordinates.len() == 1 && cx.model.fast_phase.is_some() {
        functions.push(action_taylor(cx, derivation, &exact, &rhs_names)?);
    }
    Ok(functions)
}

/// The exact field with the action S = ∫ (p·q' − H) dt and the fast phase θ
/// (θ' = its rate) as two more state components, for models of one degree
/// of freedom with a fast phase: the lobe areas of their separatrix
/// splitting are differences of such actions (`analysis::separatrix`),
/// which double-double precision follows below 10⁻¹⁶ of their size, and
/// the phase gives the period in the same precision as the recurrences
/// (the rate computed in f64 would make a period map of another system).
pub(crate) fn action_taylor(
    cx: &Context,
    derivation: &Derivation,
    exact: &[Step],
    rhs_names: &[String],
) -> Result<TaylorFunction, DeriveError> {
    let products: Vec<String> = cx
        .momenta()
        .iter()
        .zip(cx.velocities())
        .map(|(p, v)| format!("{p}*{v}"))
        .collect();
    let rate = format!("{} - ({})", products.join(" + "), derivation.hamiltonian);
    let mut steps = exact.to_vec();
    steps.push(Step::Values(vec![("action_rate__".into(), rate)]));
    let mut outputs = rhs_names.to_vec();
    outputs.extend(["action_rate__".into(), "rate__".into()]);
    let mut state = cx.coordinates();
    state.extend(cx.momenta());
    state.extend(["action__".into(), "phase__".into()]);
    cx.taylor_steps(
        "exact_action_taylor",
        "Normalised Taylor coefficients of the exact solution with its action S = ∫ (p·q' − H) dt and the fast phase θ: z = [q, p, S, θ].",
        &steps,
        &outputs,
        state,
    )
}

/// The Taylor functions from the steps and outputs of the exact and (with a
/// fast phase) averaged fields: the solutions and the exact variational
/// equations.
pub fn taylor_set(
    cx: &Context,
    exact: (&[Step], &[String]),
    averaged: Option<(&[Step], &[String])>,
    tangents: Tangents,
) -> Result<Vec<TaylorFunction>, DeriveError> {
    let mut state = cx.coordinates();
    state.extend(cx.momenta());
    let mut functions = vec![cx.taylor_steps(
        "exact_taylor",
        "Normalised Taylor coefficients out[k] = y^(k)(t)/k!, k = 0..=order, of the exact solution through (t, y).",
        exact.0,
        exact.1,
        state.clone(),
    )?];
    if let Some((steps, names)) = averaged {
        functions.push(cx.taylor_steps(
            "averaged_taylor",
            "Normalised Taylor coefficients of the averaged solution through y.",
            steps,
            names,
            state.clone(),
        )?);
    }
    if tangents == Tangents::DualNumbers {
        return Ok(functions);
    }
    let mut with_tangent = state.clone();
    with_tangent.extend(state.iter().map(|s| format!("tangent_{s}")));
    functions.push(cx.taylor_steps(
        "exact_variational_taylor",
        "Taylor coefficients of the exact solution and its tangent vectors V' = J V: z = [y; V] with any number of columns (one for the FLI, a full set for the monodromy matrix), out flat with rows of z.len(). The tangent recurrences run once per column, in forward mode (the derivatives of the field's nodes) or in Jacobian form (δf_i = Σ_j c_ij·δx_j with coefficients computed once per step), whichever the derivation counted cheaper.",
        exact.0,
        exact.1,
        with_tangent,
    )?);
    Ok(functions)
}

/// How a model's derivatives are computed: its Jacobians, its variational
/// recurrences and the Hessian of its effective potential.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tangents {
    /// Written out by forward mode through the derivation's DAG at build
    /// time (closed forms: the code stays small).
    WrittenOut,
    /// At run time, by dual numbers through the generated recurrences
    /// (`crate::ode::dual` in the runtime): for models whose mass matrix is
    /// solved at run time, whose written-out derivatives grow like N³.
    DualNumbers,
}

/// The steps that define the names the texts of a
/// [`crate::deprit::SecondOrderForm`] use (none in closed form; the solves
/// and brackets of the numeric-solve form), and how K̄ is differentiated.
#[derive(Default)]
pub struct SecondOrderSteps {
    /// Before K̄.
    pub hamiltonian: Vec<Step>,
    /// After K̄ and before the forces P̄.
    pub forces: Vec<Step>,
    /// Before εχ₁.
    pub generator: Vec<Step>,
    /// K̄'s gradient and Hessian at run time, by hyper-dual numbers through
    /// `averaged2_hamiltonian_dual`, instead of forward mode through the
    /// DAG at build time: where K̄ already holds second derivatives of
    /// solves, the DAG's third and fourth would multiply the code's size.
    pub run_time_derivatives: bool,
}

/// `f` with `line` first, before the prelude (whose coordinates may shadow
/// the argument `y` the line reads).
pub(crate) fn first_line(mut f: Function, line: String) -> Function {
    f.body.insert(0, line);
    f
}

const DOC_K2: &str = "Averaged Hamiltonian to second order, K̄ = H̄ + εK̄₁ + ε²K̄₂ with ε = 1/rate.";
const DOC_RHS2: &str = "Second-order averaged equations: q' = ∂K̄/∂p, p' = −∂K̄/∂q + P̄.";
const DOC_HESSIAN2: &str =
    "Hessian ∂²K̄/∂y² of the second-order averaged Hamiltonian in the state y = [q; p].";

/// K̄, the second-order field and its Hessian with K̄'s derivatives taken
/// at run time over hyper-dual numbers: K̄ is generated once (`k_steps`),
/// the field adds the forces (`rhs_steps`) to J∇K̄.
fn by_hyper_duals(
    cx: &Context,
    k_steps: &[Step],
    rhs_steps: &[Step],
    rhs_result: String,
) -> Result<Vec<Function>, DeriveError> {
    let m = 2 * cx.n();
    // K̄ itself as the value part of the hyper-dual one: one copy of
    // the code, the largest function of these models.
    let k = cx.function_steps(
        "averaged2_hamiltonian",
        DOC_K2,
        Inputs::AveragedState,
        "f64".into(),
        &[],
        "k__".into(),
    )?;
    let mut functions = vec![first_line(
        k,
        "let k__ = averaged2_hamiltonian_dual(&y.map(crate::ode::HyperDual::from), params).re;"
            .into(),
    )];
    functions.push(cx.function_steps(
        "averaged2_hamiltonian_dual",
        "K̄ over hyper-dual numbers: its gradient and Hessian at run time (`crate::ode::hyperdual`).",
        Inputs::HyperDualAveragedState,
        "crate::ode::HyperDual".into(),
        k_steps,
        "k__".into(),
    )?);
    let dual_k = "|y| averaged2_hamiltonian_dual(y, params)";
    let rhs = cx.function_steps(
        "averaged2_rhs",
        DOC_RHS2,
        Inputs::AveragedState,
        format!("[f64; {m}]"),
        rhs_steps,
        rhs_result,
    )?;
    let names: Vec<String> = (0..m).map(|i| format!("dk__{i}")).collect();
    functions.push(first_line(
        rhs,
        format!(
            "let [{}] = crate::ode::hyperdual::gradient({dual_k}, y);",
            names.join(", ")
        ),
    ));
    let hessian = cx.function_steps(
        "averaged2_hessian",
        DOC_HESSIAN2,
        Inputs::AveragedState,
        format!("[[f64; {m}]; {m}]"),
        &[],
        "hessian__".into(),
    )?;
    functions.push(first_line(
        hessian,
        format!("let hessian__ = crate::ode::hyperdual::hessian({dual_k}, y);"),
    ));
    Ok(functions)
}

/// The second-order averaged system: K̄ = H̄ + εK̄₁ + ε²K̄₂ (ε = 1/rate), its
/// field, its Hessian in the state and the first-order map's shift.
pub fn second_order_functions(
    cx: &Context,
    second: &crate::deprit::SecondOrderForm,
    before: &SecondOrderSteps,
) -> Result<Vec<Function>, DeriveError> {
    let q = cx.coordinates();
    let p: Vec<String> = q.iter().map(|c| momentum_name(c)).collect();
    let n = q.len();
    let m = 2 * n;
    let state: Vec<String> = q.iter().chain(&p).cloned().collect();
    let k_bar = Step::Values(vec![("k__".into(), second.hamiltonian.clone())]);
    let gradient = |value: &str, prefix: &str| {
        Step::Derivatives(
            state
                .iter()
                .enumerate()
                .map(|(i, v)| (format!("{prefix}__{i}"), value.to_string(), vec![v.clone()]))
                .collect(),
        )
    };
    // J∇: [∂/∂p; −∂/∂q] of the gradient named `prefix`.
    let symplectic = |prefix: &str, extra: &dyn Fn(usize) -> String| {
        let mut parts: Vec<String> = (0..n).map(|i| format!("{prefix}__{}", n + i)).collect();
        parts.extend((0..n).map(|i| format!("-{prefix}__{i}{}", extra(i))));
        format!("[{}]", parts.join(", "))
    };
    let forces = Step::Values(
        second
            .forces
            .iter()
            .enumerate()
            .map(|(i, f)| (format!("force__{i}"), f.clone()))
            .collect(),
    );
    let generator = Step::Values(vec![("chi__".into(), second.generator.clone())]);
    let with = |prelude: &[Step], steps: &[Step]| -> Vec<Step> {
        prelude.iter().chain(steps).cloned().collect()
    };
    let k_steps = with(&before.hamiltonian, std::slice::from_ref(&k_bar));
    let mut functions = Vec::new();
    if before.run_time_derivatives {
        let rhs_steps = with(&before.forces, &[forces]);
        let rhs_result = symplectic("dk", &|i| format!(" + force__{i}"));
        functions.extend(by_hyper_duals(cx, &k_steps, &rhs_steps, rhs_result)?);
    } else {
        functions.push(cx.function_steps(
            "averaged2_hamiltonian",
            DOC_K2,
            Inputs::AveragedState,
            "f64".into(),
            &k_steps,
            "k__".into(),
        )?);
        let mut field = k_steps.clone();
        field.extend(before.forces.iter().cloned());
        field.extend([forces, gradient("k__", "dk")]);
        functions.push(cx.function_steps(
            "averaged2_rhs",
            DOC_RHS2,
            Inputs::AveragedState,
            format!("[f64; {m}]"),
            &field,
            symplectic("dk", &|i| format!(" + force__{i}")),
        )?);
        let hessian = Step::Derivatives(
            (0..m)
                .flat_map(|i| (0..m).map(move |j| (i, j)))
                .map(|(i, j)| {
                    (
                        format!("k__{i}_{j}"),
                        "k__".to_string(),
                        vec![state[i].clone(), state[j].clone()],
                    )
                })
                .collect(),
        );
        let (_, hessian_result) = matrix("k", &vec![vec![String::new(); m]; m]);
        functions.push(cx.function_steps(
            "averaged2_hessian",
            DOC_HESSIAN2,
            Inputs::AveragedState,
            format!("[[f64; {m}]; {m}]"),
            &with(&before.hamiltonian, &[k_bar, hessian]),
            hessian_result,
        )?);
    }
    functions.push(cx.function_steps(
        "averaged2_shift",
        "J∇(εχ₁) at (y′, θ(t)): the exact state is y = y′ + shift to first order in ε.",
        Inputs::State,
        format!("[f64; {m}]"),
        &with(&before.generator, &[generator, gradient("chi__", "dchi")]),
        symplectic("dchi", &|_| String::new()),
    )?);
    Ok(functions)
}

/// The coordinates' starts the model file gives (0 where it gives none),
/// in the parameters, and their starting rates where it gives any; none
/// when it gives neither: a model without constraints starts there, at
/// rest unless rates are given (where a file says its origin is a
/// singular chart, as the heavy top's upright θ = 0).
pub fn starts_functions(cx: &Context) -> Result<Vec<Function>, DeriveError> {
    let coordinates = &cx.model.coordinates;
    let given = |value: fn(&mechlab_model::file::Coordinate) -> &Option<crate::model::Expr>| {
        coordinates.iter().any(|c| value(c).is_some()).then(|| {
            coordinates
                .iter()
                .map(|c| value(c).as_ref().map_or("0".into(), |s| s.to_string()))
                .collect::<Vec<String>>()
        })
    };
    let rates = given(|c| &c.start_rate);
    let starts = given(|c| &c.start).or_else(|| rates.as_ref().map(|r| vec!["0".into(); r.len()]));
    [
        ("coordinate_starts", "start", "The coordinates' starts of the model file (0 where it gives none).", starts),
        ("coordinate_start_rates", "rate", "The coordinates' starting rates of the model file (0 where it gives none); the start's momenta are theirs.", rates),
    ]
    .into_iter()
    .filter_map(|(name, prefix, doc, values)| Some((name, prefix, doc, values?)))
    .map(|(name, prefix, doc, values)| {
        let (outputs, result) = vector(prefix, &values);
        let output = format!("[f64; {}]", coordinates.len());
        cx.function(name, doc, Inputs::Params, output, &[outputs], result)
    })
    .collect()
}

/// The drawing's points at (t, q) as `[[x, y, z]; P]` (the model file's
/// `[[points]]` and its bodies' frames, definitions substituted) and
/// gravity's acceleration where the file gives it, or none when nothing
/// is drawn. Both the Hamiltonian and the constrained templates have q first
/// in their state, so one form serves both.
pub fn drawing_function(cx: &Context) -> Result<Vec<Function>, DeriveError> {
    let points = &cx.model.points;
    if points.is_empty() {
        return Ok(Vec::new());
    }
    let rows = points
        .iter()
        .map(|p| {
            p.at.iter()
                .map(|e| Ok(crate::derive::kinematic(cx.model, e)?.to_string()))
                .collect::<Result<Vec<String>, DeriveError>>()
        })
        .collect::<Result<Vec<_>, _>>()?;
    let (outputs, result) = matrix("point", &rows);
    let names: Vec<&str> = points.iter().map(|p| p.name.as_str()).collect();
    let mut functions = vec![cx.function(
        "mechanism_points",
        &format!(
            "The mechanism's points ({}) in space (x, y, z).",
            names.join(", ")
        ),
        Inputs::TimeCoordinates,
        format!("[[f64; 3]; {}]", points.len()),
        &[outputs],
        result,
    )?];
    if let Some(gravity) = &cx.model.gravity {
        let values = gravity
            .iter()
            .map(|g| Ok(crate::derive::kinematic(cx.model, g)?.to_string()))
            .collect::<Result<Vec<String>, DeriveError>>()?;
        let (outputs, result) = vector("gravity", &values);
        functions.push(cx.function(
            "gravity",
            "Gravity's acceleration (x, y, z): the drawing's way down.",
            Inputs::Params,
            "[f64; 3]".into(),
            &[outputs],
            result,
        )?);
    }
    Ok(functions)
}
