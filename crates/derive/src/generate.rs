//! Assembles the generated module of one model from its derivation and renders
//! it through the tera templates in `templates/`.

use crate::algebra::Derived;
use crate::constraints::ConstrainedDerivation;
use crate::contacts::ContactDerivation;
use crate::derive::Derivation;
use crate::emit::Step;
use crate::error::DeriveError;
use crate::functions::{matrix, named, symbolic_functions, vector, Context, Inputs};
use crate::model::Model;
use serde::Serialize;

#[derive(Serialize)]
struct Param {
    name: String,
    default: String,
    description: String,
    /// The parameter's range as a Rust expression of `crate::registry::Range`.
    range: String,
}

/// A range as Rust source.
fn range_literal(range: &crate::model::Range) -> String {
    let end = |x: f64| {
        if x == f64::INFINITY {
            "f64::INFINITY".to_string()
        } else if x == f64::NEG_INFINITY {
            "f64::NEG_INFINITY".to_string()
        } else {
            format!("{x:?}")
        }
    };
    format!(
        "crate::registry::Range {{ min: {}, max: {}, min_open: {}, max_open: {} }}",
        end(range.min),
        end(range.max),
        range.min_open,
        range.max_open
    )
}

#[derive(Serialize)]
/// Rust string literals of one derived expression.
struct DerivedEntry {
    key: String,
    description: String,
    text: String,
    latex: String,
}

/// Renders the generated module of one model.
pub fn render(
    tera: &tera::Tera,
    model: &Model,
    derivation: &Derivation,
    source_file: &str,
) -> Result<String, DeriveError> {
    let cx = Context {
        model,
        n: derivation.dof,
        contact_state: Vec::new(),
        model_phase_rate: derivation.phase_rate.clone(),
    };
    let n = cx.n();
    let m = 2 * n;
    let (mut functions, taylor_functions) = match &derivation.numeric {
        Some(form) => crate::numeric::functions(&cx, derivation, form)?,
        None => symbolic_functions(&cx, derivation)?,
    };
    functions.extend(crate::functions::drawing_function(&cx)?);
    let starts = crate::functions::starts_functions(&cx)?;
    let has_starts = !starts.is_empty();
    let has_start_rates = starts.len() == 2;
    functions.extend(starts);

    // Functions of q alone must not depend on anything else.
    let forbidden: Vec<String> = cx
        .velocities()
        .into_iter()
        .chain(cx.momenta())
        .chain(model.fast_phase.iter().map(|f| f.name.clone()))
        .chain([model.time.clone()])
        .collect();
    for f in &functions {
        if f.args.starts_with("q: ") {
            for line in f.body.iter().skip(2) {
                if let Some(bad) = forbidden.iter().find(|s| {
                    line.split(|c: char| !c.is_alphanumeric() && c != '_')
                        .any(|w| w == s.as_str())
                }) {
                    return Err(DeriveError::Dependency {
                        function: f.name.clone(),
                        symbol: bad.clone(),
                    });
                }
            }
        }
    }

    let mut context = base_context(model, source_file, &derivation.derived);
    context.insert("has_starts", &has_starts);
    context.insert("has_start_rates", &has_start_rates);
    context.insert("dof", &n);
    context.insert("state_dim", &m);
    context.insert("coordinates", &cx.coordinates());
    context.insert(
        "periodic",
        &model
            .coordinates
            .iter()
            .map(|c| c.periodic)
            .collect::<Vec<_>>(),
    );
    context.insert("momenta", &cx.momenta());
    context.insert("has_phase", &model.fast_phase.is_some());
    // Without written-out tangent recurrences (`Tangents::DualNumbers`),
    // the template runs the exact ones over dual numbers.
    context.insert(
        "tangents_by_dual_numbers",
        &!taylor_functions.iter().any(|f| f.is_variational()),
    );
    // Every model with a fast phase: in closed form, or (numeric solves,
    // up to `numeric::SECOND_ORDER_MAX_DOF`) with the series in the DAG.
    context.insert(
        "has_second_order",
        &(derivation.second_order.is_some() || crate::numeric::has_second_order(derivation, model)),
    );
    context.insert(
        "phase",
        &model
            .fast_phase
            .as_ref()
            .map(|f| f.name.clone())
            .unwrap_or_default(),
    );
    context.insert("functions", &functions);
    context.insert("taylor_functions", &taylor_functions);
    context.insert("dyn_systems", &dyn_systems(model, derivation));
    context.insert(
        "operation_counts",
        &derivation
            .operation_counts
            .iter()
            .map(|(f, before, after, used)| format!("(\"{f}\", {before}, {after}, {used})"))
            .collect::<Vec<_>>(),
    );
    tera.render("model.rs.tera", &context)
        .map_err(|source| DeriveError::Template {
            template: "model.rs.tera",
            source,
        })
}

/// What every model template shows: names, parameters, derived expressions.
fn base_context(model: &Model, source_file: &str, derived: &[Derived]) -> tera::Context {
    let params: Vec<Param> = model
        .parameters
        .iter()
        .map(|p| Param {
            name: p.name.clone(),
            default: format!("{:?}", p.default),
            description: format!("{:?}", p.description),
            range: range_literal(&p.range),
        })
        .collect();
    let derived: Vec<DerivedEntry> = derived
        .iter()
        .map(|d| DerivedEntry {
            key: format!("{:?}", d.key),
            description: format!("{:?}", d.description),
            text: format!("{:?}", d.text),
            latex: format!("{:?}", d.latex),
        })
        .collect();
    let mut context = tera::Context::new();
    context.insert("name", &model.name);
    context.insert("description", &model.description);
    context.insert("source_file", source_file);
    context.insert("tangents_by_dual_numbers", &false);
    // The file's text as a raw string literal, with enough `#` to hold it.
    let text = std::fs::read_to_string(source_file).unwrap_or_default();
    let hashes = "#".repeat(
        (1..)
            .find(|n| !text.contains(&format!("\"{}", "#".repeat(*n))))
            .unwrap_or(1),
    );
    context.insert("source_text", &format!("r{hashes}\"{text}\"{hashes}"));
    context.insert("params", &params);
    context.insert("derived", &derived);
    context.insert(
        "amplitude",
        &model
            .fast_phase
            .as_ref()
            .and_then(|f| f.amplitude.clone())
            .unwrap_or_default(),
    );
    // The parameter the phase's rate depends on, if exactly one: the one
    // the averaging analysis sweeps unless told otherwise.
    let rate_symbols = model
        .fast_phase
        .as_ref()
        .map(|f| f.rate.symbols())
        .unwrap_or_default();
    let rate_parameter = match rate_symbols.len() {
        1 => rate_symbols.into_iter().next().unwrap_or_default(),
        _ => String::new(),
    };
    context.insert("rate_parameter", &rate_parameter);
    let point_names: Vec<&str> = model.points.iter().map(|p| p.name.as_str()).collect();
    let bars: Vec<[usize; 2]> = model
        .points
        .iter()
        .enumerate()
        .flat_map(|(i, p)| p.joined_to.iter().map(move |&j| [j, i]))
        .collect();
    context.insert("point_names", &point_names);
    context.insert("bars", &bars);
    context.insert("body_frames", &model.body_frames);
    context.insert("drawn_in_space", &model.points.iter().any(|p| p.in_space));
    context.insert("has_gravity", &model.gravity.is_some());
    context
}

/// Renders the generated module of a model with Coulomb contacts.
pub fn render_contacts(
    tera: &tera::Tera,
    model: &Model,
    derivation: &ContactDerivation,
    source_file: &str,
) -> Result<String, DeriveError> {
    let n = derivation.slides.len();
    let cx = Context {
        model,
        n,
        contact_state: derivation
            .slides
            .iter()
            .chain(&derivation.velocities)
            .cloned()
            .collect(),
        model_phase_rate: String::new(),
    };
    let functions = vec![
        cx.function(
            "free_forces",
            "Force along each guide, all but friction: G = ∂L/∂s − ∂D/∂s' − (velocity terms).",
            Inputs::ContactState,
            format!("[f64; {n}]"),
            &[named("g", &derivation.free_forces)],
            vector("g", &derivation.free_forces).1,
        )?,
        cx.function(
            "normal_forces",
            "Normal reaction of each guide (the multiplier of its constraint).",
            Inputs::ContactState,
            format!("[f64; {n}]"),
            &[named("n", &derivation.normal_forces)],
            vector("n", &derivation.normal_forces).1,
        )?,
        cx.function(
            "masses",
            "Mass of each sliding point.",
            Inputs::Params,
            format!("[f64; {n}]"),
            &[named("m", &derivation.masses)],
            vector("m", &derivation.masses).1,
        )?,
        cx.function(
            "friction",
            "Friction coefficient of each contact.",
            Inputs::Params,
            format!("[f64; {n}]"),
            &[named("mu", &derivation.friction)],
            vector("mu", &derivation.friction).1,
        )?,
        cx.function(
            "energy",
            "Energy function E = Σ q'∂L/∂q' − L on the guides.",
            Inputs::ContactState,
            "f64".into(),
            &[vec![("e__".into(), derivation.energy.clone())]],
            "e__".into(),
        )?,
        cx.function(
            "dissipation_power",
            "P_D = Σ q'∂D/∂q': the rate at which the Rayleigh function dissipates energy.",
            Inputs::ContactState,
            "f64".into(),
            &[vec![("p__".into(), derivation.dissipation_power.clone())]],
            "p__".into(),
        )?,
    ];
    let mut context = base_context(model, source_file, &derivation.derived);
    context.insert("dof", &n);
    context.insert("state_dim", &(2 * n));
    context.insert("coordinates", &derivation.slides);
    context.insert("functions", &functions);
    tera.render("contact_model.rs.tera", &context)
        .map_err(|source| DeriveError::Template {
            template: "contact_model.rs.tera",
            source,
        })
}

/// The values of one generated function of a constrained model.
enum Values<'a> {
    Scalar(&'a str),
    Vector(&'a [String]),
    Matrix(&'a [Vec<String>]),
}

/// One generated function of a constrained model: its name, doc, inputs
/// and values, and the inputs of its twin over dual numbers, if it has one.
struct Form<'a> {
    name: &'static str,
    /// Its values' names in the code: `{prefix}__{i}`.
    prefix: &'static str,
    doc: &'static str,
    inputs: Inputs,
    values: Values<'a>,
    dual: Option<Inputs>,
}

/// The functions of a constrained model's module, in order.
fn constrained_forms(derivation: &ConstrainedDerivation) -> Vec<Form<'_>> {
    use Inputs::*;
    let rate = derivation.phase_rate.as_deref();
    [
        rate.map(|rate| Form {
            name: "phase_rate",
            prefix: "rate",
            doc: "dθ/dt of the fast phase θ.",
            inputs: Params,
            values: Values::Scalar(rate),
            dual: None,
        }),
        Some(Form {
            name: "start",
            prefix: "q",
            doc: "The coordinates' starts of the model file (consistent at t = 0 with the default parameters).",
            inputs: Params,
            values: Values::Vector(&derivation.starts),
            dual: None,
        }),
        Some(Form {
            name: "start_rates",
            prefix: "qd",
            doc: "The coordinates' starting rates of the model file (0 where it gives none; those it gives are held while the others are made consistent).",
            inputs: Params,
            values: Values::Vector(&derivation.start_rates),
            dual: None,
        }),
        Some(Form {
            name: "mass_matrix",
            prefix: "m",
            doc: "Mass matrix M = ∂²L/∂q'².",
            inputs: TimeCoordinates,
            values: Values::Matrix(&derivation.mass_matrix),
            dual: None,
        }),
        Some(Form {
            name: "free_forces",
            prefix: "f",
            doc: "Free generalised force F: M q'' = F + Gᵀλ.",
            inputs: CoordinatesVelocities,
            values: Values::Vector(&derivation.free_forces),
            dual: None,
        }),
        Some(Form {
            name: "position_residuals",
            prefix: "g",
            doc: "g of each position constraint (0 for a velocity constraint).",
            inputs: TimeCoordinates,
            values: Values::Vector(&derivation.residuals),
            dual: None,
        }),
        Some(Form {
            name: "constraint_jacobian",
            prefix: "jac",
            doc: "G = ∂c/∂q' of each constraint's velocity form c = G q' + c_t.",
            inputs: TimeCoordinates,
            values: Values::Matrix(&derivation.jacobian),
            dual: Some(DualTimeCoordinates),
        }),
        Some(Form {
            name: "constraint_rates",
            prefix: "ct",
            doc: "c_t of each constraint's velocity form c = G q' + c_t.",
            inputs: TimeCoordinates,
            values: Values::Vector(&derivation.rates),
            dual: Some(DualTimeCoordinates),
        }),
        Some(Form {
            name: "potential",
            prefix: "v",
            doc: "V = −L at q' = 0 (with the fast phase, for the averaging).",
            inputs: TimeCoordinates,
            values: Values::Scalar(&derivation.potential),
            dual: None,
        }),
        Some(Form {
            name: "linear_term",
            prefix: "b",
            doc: "b = ∂L/∂q' at q' = 0 (the vibration's coupling, for the averaging).",
            inputs: TimeCoordinates,
            values: Values::Vector(&derivation.linear_term),
            dual: None,
        }),
        Some(Form {
            name: "energy",
            prefix: "e",
            doc: "Energy function E = Σ q'∂L/∂q' − L.",
            inputs: CoordinatesVelocities,
            values: Values::Scalar(&derivation.energy),
            dual: None,
        }),
    ]
    .into_iter()
    .flatten()
    .collect()
}

/// The functions of a constrained model's module ([`constrained_forms`]),
/// each with its twin over dual numbers where the Jacobians need it.
fn constrained_functions(
    cx: &Context,
    derivation: &ConstrainedDerivation,
) -> Result<Vec<crate::functions::Function>, DeriveError> {
    let mut functions = Vec::new();
    for form in constrained_forms(derivation) {
        let (outs, result, shape) = match form.values {
            Values::Scalar(text) => (
                vec![(format!("{}__", form.prefix), text.to_string())],
                format!("{}__", form.prefix),
                None,
            ),
            Values::Vector(values) => {
                let (outs, result) = vector(form.prefix, values);
                (outs, result, Some((values.len(), None)))
            }
            Values::Matrix(rows) => {
                let (outs, result) = matrix(form.prefix, rows);
                let columns = rows.first().map_or(0, Vec::len);
                (outs, result, Some((rows.len(), Some(columns))))
            }
        };
        let ret = |number: &str| match shape {
            None => number.to_string(),
            Some((len, None)) => format!("[{number}; {len}]"),
            Some((rows, Some(columns))) => format!("[[{number}; {columns}]; {rows}]"),
        };
        let outs = [outs];
        functions.push(cx.function(
            form.name,
            form.doc,
            form.inputs,
            ret("f64"),
            &outs,
            result.clone(),
        )?);
        if let Some(inputs) = form.dual {
            functions.push(cx.function(
                &format!("{}_dual", form.name),
                &format!(
                    "`{}` over dual numbers (derivatives at run time).",
                    form.name
                ),
                inputs,
                ret("crate::ode::Dual"),
                &outs,
                result,
            )?);
        }
    }
    let k = derivation.jacobian.len();
    let bias: Vec<String> = (0..k).map(|r| format!("bias__{r}")).collect();
    functions.push(cx.function_steps(
        "constraint_bias",
        "h: d/dt c = G q'' + h, by forward-mode derivatives of each velocity form c = G q' + c_t.",
        Inputs::CoordinatesVelocities,
        format!("[f64; {k}]"),
        &bias_steps(cx, derivation),
        format!("[{}]", bias.join(", ")),
    )?);
    Ok(functions)
}

/// The Taylor recurrences of the equations on the constraints, y = [q; q']:
/// the same Schur complement as the runtime's, as two solves of the DAG,
/// M [x_F, x_G] = [F, Gᵀ] and (G x_G) λ = −h − G x_F, then
/// q'' = x_F + x_G λ; G x_G is singular where constraints are redundant,
/// and solved with their rows skipped. Their recurrences solve with the factors of order 0
/// at every order (`crates/derive/src/taylor.rs`), so a step costs what
/// the model's size asks and no inverse is formed.
fn constrained_steps(cx: &Context, derivation: &ConstrainedDerivation) -> (Vec<Step>, Vec<String>) {
    use crate::numeric::{dot, names, upper};
    let n = cx.n();
    let k = derivation.jacobian.len();
    let free: Vec<String> = (0..n).map(|i| format!("free__{i}")).collect();
    let rows: Vec<Vec<String>> = (0..k)
        .map(|r| (0..n).map(|i| format!("jac__{r}_{i}")).collect())
        .collect();
    let solved_free: Vec<String> = (0..n).map(|i| format!("solved_free__{i}")).collect();
    let solved_rows: Vec<Vec<String>> = (0..k)
        .map(|r| (0..n).map(|i| format!("solved_row{r}__{i}")).collect())
        .collect();
    let forms = match derivation.massless {
        false => {
            let mut forms = upper("mass", &derivation.mass_matrix);
            forms.extend(named("free", &derivation.free_forces));
            vec![Step::Values(forms)]
        }
        true => massless_forms(derivation, &rows),
    };
    let mut columns = vec![free];
    columns.extend(rows.iter().cloned());
    let mut solutions = vec![solved_free.clone()];
    solutions.extend(solved_rows.iter().cloned());
    let schur: Vec<Vec<String>> = (0..k)
        .map(|r| (0..k).map(|c| dot(&rows[r], &solved_rows[c])).collect())
        .collect();
    let mut reduced = upper("schur", &schur);
    reduced.extend((0..k).map(|r| {
        (
            format!("reduced__{r}"),
            format!("-bias__{r}-{}", dot(&rows[r], &solved_free)),
        )
    }));
    let lambda: Vec<String> = (0..k).map(|r| format!("lambda__{r}")).collect();
    let accelerations: Vec<(String, String)> = (0..n)
        .map(|i| {
            let column: Vec<String> = (0..k).map(|r| solved_rows[r][i].clone()).collect();
            let reaction = if k == 0 {
                "0".to_string()
            } else {
                dot(&column, &lambda)
            };
            (
                format!("acceleration__{i}"),
                format!("{}+{reaction}", solved_free[i]),
            )
        })
        .collect();
    // q' = the velocities, as outputs of their own (the recurrences read
    // outputs, and a state variable is not one).
    let mut rates: Vec<(String, String)> = cx
        .velocities()
        .into_iter()
        .enumerate()
        .map(|(i, v)| (format!("coordinate_rate__{i}"), v))
        .collect();
    rates.extend(accelerations);
    let outputs: Vec<String> = rates.iter().map(|(name, _)| name.clone()).collect();
    let mut steps = bias_steps(cx, derivation);
    steps.extend(forms);
    steps.extend([
        Step::Solve {
            matrix: names("mass", n),
            columns,
            names: solutions,
            semidefinite: false,
        },
        Step::Values(reduced),
        Step::Solve {
            matrix: names("schur", k),
            columns: vec![(0..k).map(|r| format!("reduced__{r}")).collect()],
            names: vec![lambda],
            // Redundant constraints make it singular: their reactions are
            // left at 0, the motion is the same.
            semidefinite: true,
        },
        Step::Values(rates),
    ]);
    (steps, outputs)
}

/// M + α GᵀG (`mass__i_j`) and F − α Gᵀh (`free__i`) with α = tr M /
/// tr GᵀG, for a model with massless parts: regular where M is on the
/// constraints' motions, and the same accelerations and reactions (G q''
/// = −h makes the added terms cancel). After the bias steps (G and h).
fn massless_forms(derivation: &ConstrainedDerivation, rows: &[Vec<String>]) -> Vec<Step> {
    use crate::numeric::{dot, upper};
    let n = derivation.mass_matrix.len();
    let mut forms = upper("inertia", &derivation.mass_matrix);
    forms.extend(named("applied", &derivation.free_forces));
    let trace: Vec<String> = (0..n).map(|i| format!("inertia__{i}_{i}")).collect();
    let squares: Vec<String> = rows.iter().map(|row| dot(row, row)).collect();
    let weight = (
        "augmentation".to_string(),
        format!("({})/({})", trace.join("+"), squares.join("+")),
    );
    let column = |i: usize| -> Vec<String> { rows.iter().map(|row| row[i].clone()).collect() };
    let bias: Vec<String> = (0..rows.len()).map(|r| format!("bias__{r}")).collect();
    let augmented: Vec<Vec<String>> = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| {
                    format!(
                        "inertia__{}_{}+augmentation*{}",
                        i.min(j),
                        i.max(j),
                        dot(&column(i), &column(j))
                    )
                })
                .collect()
        })
        .collect();
    let mut values = upper("mass", &augmented);
    values.extend((0..n).map(|i| {
        (
            format!("free__{i}"),
            format!("applied__{i}-augmentation*{}", dot(&column(i), &bias)),
        )
    }));
    vec![
        Step::Values(forms),
        Step::Values(vec![weight]),
        Step::Values(values),
    ]
}

/// The steps that give each constraint's row of G (`jac__{r}_{j}`) and
/// h = d/dt c − G q'' = Σ_j ∂c/∂q_j q'_j + ∂c/∂t (`bias__{r}`), c = G q' +
/// c_t, h by forward-mode derivatives of c's code (through the fast phase
/// at its rate): the same number as the symbolic derivative, without
/// writing that derivative out.
fn bias_steps(cx: &Context, derivation: &ConstrainedDerivation) -> Vec<Step> {
    let k = derivation.jacobian.len();
    let coordinates = cx.coordinates();
    let velocities = cx.velocities();
    let time = cx.model.time.clone();
    let phase = cx.model.fast_phase.as_ref().map(|f| f.name.clone());
    let mut values = matrix("jac", &derivation.jacobian).0;
    values.extend(named("ct", &derivation.rates));
    values.extend((0..k).map(|r| {
        let row: Vec<String> = (0..coordinates.len())
            .map(|j| format!("jac__{r}_{j}"))
            .collect();
        (
            format!("velocity_form__{r}"),
            format!("ct__{r}+{}", crate::numeric::dot(&row, &velocities)),
        )
    }));
    let mut derivatives = Vec::new();
    let mut bias = Vec::new();
    for r in 0..k {
        let form = format!("velocity_form__{r}");
        let mut terms = Vec::new();
        for (j, (q, v)) in coordinates.iter().zip(&velocities).enumerate() {
            derivatives.push((format!("dc__{r}_{j}"), form.clone(), vec![q.clone()]));
            terms.push(format!("dc__{r}_{j}*{v}"));
        }
        derivatives.push((format!("dc__{r}_t"), form.clone(), vec![time.clone()]));
        terms.push(format!("dc__{r}_t"));
        if let (Some(phase), Some(rate)) = (&phase, &derivation.phase_rate) {
            derivatives.push((format!("dc__{r}_phase"), form.clone(), vec![phase.clone()]));
            terms.push(format!("({rate})*dc__{r}_phase"));
        }
        bias.push((format!("bias__{r}"), terms.join("+")));
    }
    vec![
        Step::Values(values),
        Step::Derivatives(derivatives),
        Step::Values(bias),
    ]
}

/// The Taylor recurrences of the motion on the constraints ([`constrained_steps`]).
fn constrained_taylor(
    cx: &Context,
    derivation: &ConstrainedDerivation,
) -> Result<crate::functions::TaylorFunction, DeriveError> {
    let (steps, outputs) = constrained_steps(cx, derivation);
    let mut state = cx.coordinates();
    state.extend(cx.velocities());
    cx.taylor_steps(
        "exact_taylor",
        "Normalised Taylor coefficients out[k] = y^(k)(t)/k!, k = 0..=order, of the motion on the constraints through (t, y), y = [q; q']: M q'' = F + Gᵀλ with G q'' + h = 0, by the Schur complement.",
        &steps,
        &outputs,
        state,
    )
}

/// The field [q'; q''] of the motion on the constraints as one function
/// ([`constrained_steps`]): the forms share their subexpressions.
/// With `dual`, its twin over dual numbers (the Jacobian of a model
/// without Taylor recurrences).
fn constrained_rhs(
    cx: &Context,
    derivation: &ConstrainedDerivation,
    dual: bool,
) -> Result<crate::functions::Function, DeriveError> {
    let (steps, outputs) = constrained_steps(cx, derivation);
    let (name, inputs, number) = match dual {
        false => ("exact_rhs", Inputs::CoordinatesVelocities, "f64"),
        true => (
            "exact_rhs_dual",
            Inputs::DualCoordinatesVelocities,
            "crate::ode::Dual",
        ),
    };
    cx.function_steps(
        name,
        "The field [q'; q''] of the motion on the constraints at (t, q, q'): M q'' = F + Gᵀλ with G q'' + h = 0, by the Schur complement. NaN where M or G M⁻¹Gᵀ is not positive definite.",
        inputs,
        format!("[{number}; {}]", outputs.len()),
        &steps,
        format!("[{}]", outputs.join(", ")),
    )
}

/// The most coordinates a constrained model has Taylor recurrences for.
/// The recurrences solve with M at every order, and they are compiled in
/// three number types (f64, the batch lanes, dual numbers): for a closed
/// chain of ten rods they were two thirds of its module and a tenth of
/// the test command's build. A larger model runs the other methods.
pub const TAYLOR_COORDINATES: usize = 6;

/// The longest Taylor recurrences of a constrained model kept, in bytes
/// of source. Past it a model's forms are long (Bricard's five rods in
/// space: 1.3 MB of recurrences, three quarters of its module), each
/// order costs what many steps of an explicit method cost (there Taylor
/// ran 16 times slower than DOP853), and compiling them held the build.
/// Such a model runs the other methods, as a larger one does.
pub const TAYLOR_SOURCE_BYTES: usize = 300_000;

/// Renders the generated module of a model with ideal constraints.
pub fn render_constrained(
    tera: &tera::Tera,
    model: &Model,
    derivation: &ConstrainedDerivation,
    source_file: &str,
) -> Result<String, DeriveError> {
    let n = model.dof();
    let k = model.constraints.len();
    let cx = Context {
        model,
        n,
        contact_state: Vec::new(),
        model_phase_rate: derivation.phase_rate.clone().unwrap_or_default(),
    };
    let mut functions = constrained_functions(&cx, derivation)?;
    functions.extend(crate::functions::drawing_function(&cx)?);
    functions.push(constrained_rhs(&cx, derivation, false)?);
    let taylor = match n <= TAYLOR_COORDINATES {
        true => Some(constrained_taylor(&cx, derivation)?),
        false => None,
    };
    let taylor_functions: Vec<_> = taylor
        .filter(|f| f.source_bytes() <= TAYLOR_SOURCE_BYTES)
        .into_iter()
        .collect();
    let has_taylor = !taylor_functions.is_empty();
    if !has_taylor {
        functions.push(constrained_rhs(&cx, derivation, true)?);
    }
    let mut context = base_context(model, source_file, &derivation.derived);
    context.insert("dof", &n);
    context.insert("constraints", &k);
    context.insert("state_dim", &(2 * n));
    let coordinates = &model.coordinates;
    let names: Vec<&str> = coordinates.iter().map(|c| c.name.as_str()).collect();
    let velocities: Vec<&str> = coordinates.iter().map(|c| c.velocity.as_str()).collect();
    let periodic: Vec<bool> = coordinates.iter().map(|c| c.periodic).collect();
    context.insert("coordinates", &names);
    context.insert("velocities", &velocities);
    context.insert("periodic", &periodic);
    let constraints = &model.constraints;
    let names: Vec<&str> = constraints.iter().map(|c| c.name.as_str()).collect();
    let holonomic: Vec<bool> = constraints
        .iter()
        .map(|c| matches!(c.kind, crate::model::ConstraintKind::Position(_)))
        .collect();
    context.insert("constraint_names", &names);
    context.insert("holonomic", &holonomic);
    context.insert("has_phase", &derivation.phase_rate.is_some());
    context.insert("stationary", &derivation.stationary);
    context.insert("massless", &derivation.massless);
    context.insert("rates_given", &derivation.rates_given);
    context.insert("functions", &functions);
    context.insert("taylor_functions", &taylor_functions);
    context.insert("tangents_by_dual_numbers", &true);
    context.insert("has_taylor", &has_taylor);
    context.insert("state_velocities", &true);
    context.insert("taylor_coordinates", &TAYLOR_COORDINATES);
    context.insert("taylor_source_bytes", &TAYLOR_SOURCE_BYTES);
    tera.render("constrained_model.rs.tera", &context)
        .map_err(|source| DeriveError::Template {
            template: "constrained_model.rs.tera",
            source,
        })
}

/// Renders the registry module listing every model.
pub fn render_registry(
    tera: &tera::Tera,
    models: &[Model],
    users_models: bool,
) -> Result<String, DeriveError> {
    #[derive(Serialize)]
    struct Entry {
        name: String,
        doc: String,
        /// Degrees of freedom of a Hamiltonian model, 0 for a contact model.
        dof: usize,
    }
    let entries: Vec<Entry> = models
        .iter()
        .map(|m| Entry {
            name: m.name.clone(),
            doc: format!("{:?}", m.description),
            dof: if m.contacts.is_empty() && m.constraints.is_empty() {
                m.dof()
            } else {
                0
            },
        })
        .collect();
    let mut context = tera::Context::new();
    context.insert("models", &entries);
    context.insert("users_models", &users_models);
    tera.render("registry.rs.tera", &context)
        .map_err(|source| DeriveError::Template {
            template: "registry.rs.tera",
            source,
        })
}

/// The systems a Hamiltonian model puts behind trait objects for the
/// analyses by name: (marker type, system type) pairs.
fn dyn_systems(
    model: &Model,
    derivation: &Derivation,
) -> Vec<std::collections::BTreeMap<&'static str, &'static str>> {
    let mut kinds = vec![("ExactDyn", "Exact")];
    if model.fast_phase.is_some() {
        kinds.push(("AveragedDyn", "Averaged"));
    }
    if derivation.second_order.is_some() || crate::numeric::has_second_order(derivation, model) {
        kinds.push(("Averaged2Dyn", "Averaged2"));
    }
    kinds
        .into_iter()
        .map(|(kind, system)| [("type", kind), ("system", system)].into_iter().collect())
        .collect()
}
