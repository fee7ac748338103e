//! Exploring any model by name: one run of the exact system (and of the
//! averaged one when the model has a fast phase, or the stick–slip
//! integrator for a contact model), the period map, the equilibria of the
//! effective potential with their stability, and the energy change.
//!
//! A Hamiltonian model runs through its [`Systems`] (states as slices, any
//! size; each run at the model's own size). A contact model's stick–slip
//! integrator is fixed-size, so its state length is dispatched once to a
//! const-generic instance (2, 4 or 6: up to three contacts).

use crate::analysis::equilibria::{effective_equilibria, Search};
pub use crate::analysis::equilibria::{Equilibrium, NotSearched, Verdict};
use crate::analysis::on_constraints::{self, ConstrainedError};
use crate::contact::{ContactError, ContactModel, StickSlip};
use crate::ode::{Method, OdeError};
use crate::plot::{palette, Figure, PanelSpec, BLACK, GREY, RED};
use crate::registry::{
    display_name, ConstrainedSystems, DynamicModel, Kind, Model, ModelInfo, Systems,
};
use crate::settings::{method, Declared, Range, SettingError, METHODS};

crate::declare_settings! {
    /// Any model by name: its run (and the averaged run and the period map
    /// with a fast phase; stick–slip for a contact model), portraits, the
    /// energy's change, the equilibria and a constrained model's reactions.
    pub struct ExploreOptions for "explore" {
        /// The initial state, [q; p] or [s; s'] (auto: the model file's
        /// start where it gives one, its momenta those of its starting
        /// rates; else q = 0.3, 0.5, …, p = 0; contacts: s = 0, −0.3, …,
        /// s' = 1).
        y0: Option<Vec<f64>> = None, Range::Any;
        /// The length of the run.
        t_end: f64 = 20.0, Range::Positive;
        /// Samples of the time series.
        samples: usize = 2000, Range::Count { min: 2, max: 100_000_000 };
        /// Periods of the period map (models with a fast phase).
        periods: usize = 300, Range::Count { min: 1, max: 100_000_000 };
        /// The integration method.
        method: String = "dop853".into(), Range::OneOf(METHODS);
        /// Its tolerance (taylor, dop853, radau5) or step size (rk4, gauss4,
        /// gauss6).
        tol: f64 = 1e-10, Range::Positive;
    }
}

impl ExploreOptions {
    /// The settings of [`explore`] and its start for `model`, `auto`
    /// resolved.
    pub fn resolve(&self, model: &Model) -> Result<(Settings, Vec<f64>), SettingError> {
        let settings = Settings {
            method: method(Self::ANALYSIS, &self.method, self.tol)?,
            t_end: self.t_end,
            samples: self.samples,
            periods: self.periods,
        };
        let y0 = self
            .y0
            .clone()
            .unwrap_or_else(|| default_start(model.dynamic));
        Ok((settings, y0))
    }
}

/// What to run, resolved from [`ExploreOptions`].
#[derive(Clone, Debug)]
pub struct Settings {
    pub method: Method,
    pub t_end: f64,
    /// Samples of the time series.
    pub samples: usize,
    /// Periods of the period map (models with a fast phase).
    pub periods: usize,
}

/// Everything the explorer computed.
#[derive(Clone, Debug, Default)]
pub struct Exploration {
    pub times: Vec<f64>,
    pub exact: Vec<Vec<f64>>,
    /// The averaged system from the same state (fast phase only).
    pub averaged: Option<Vec<Vec<f64>>>,
    /// Exact states at multiples of the phase period (fast phase only).
    pub period_map: Option<Vec<Vec<f64>>>,
    /// H(t) − H(0) along the exact run for an autonomous model, H̄ along the
    /// averaged run for a model with a fast phase, E for contacts.
    pub energy_change: Vec<f64>,
    pub energy_label: &'static str,
    pub equilibria: Vec<Equilibrium>,
    /// Why `equilibria` is empty without a search, if it is.
    pub equilibria_not_searched: Option<NotSearched>,
    /// The search, where it sampled its grid of starts (more than 8
    /// degrees of freedom): equilibria may be missing.
    pub equilibria_search_sampled: Option<Search>,
    /// Switches of a contact model, as text.
    pub switches: Vec<String>,
    /// A constrained model's reactions along the run.
    pub reactions: Option<Reactions>,
}

/// The multipliers of a constrained model's constraints, by name: at each
/// time of the run, one value per constraint (the reaction in the units of
/// its row: for a rod written as |x − x₀|² − l² = 0, λ times 2(x − x₀) is
/// the force on the point).
#[derive(Clone, Debug, Default)]
pub struct Reactions {
    pub names: Vec<&'static str>,
    pub values: Vec<Vec<f64>>,
}

/// The start a scene uses when none is given: the model file's start
/// where it gives one (its coordinates' starts, the momenta of its
/// starting rates); else q = 0.3, 0.5, …, p = 0; for a contact model
/// s = 0, −0.3, …, s' = 1; for a constrained model its file's start
/// (which the run makes consistent).
pub fn default_start(model: &dyn DynamicModel) -> Vec<f64> {
    match model.kind() {
        Kind::Hamiltonian { dof, .. } => model.start(&model.defaults()).unwrap_or_else(|| {
            (0..dof)
                .map(|i| 0.3 + 0.2 * i as f64)
                .chain((0..dof).map(|_| 0.0))
                .collect()
        }),
        Kind::Contacts { count } => (0..count)
            .map(|i| -0.3 * i as f64)
            .chain((0..count).map(|_| 1.0))
            .collect(),
        Kind::Constrained { coordinates, .. } => model
            .start(&model.defaults())
            .unwrap_or_else(|| vec![0.0; 2 * coordinates]),
    }
}

/// What a run of `explore` reports in its `summary.json`.
#[derive(Debug, serde::Serialize)]
pub struct Summary<'a> {
    pub model: &'static str,
    pub params: std::collections::BTreeMap<&'static str, f64>,
    pub y0: &'a [f64],
    pub final_state: Option<&'a Vec<f64>>,
    pub equilibria: &'a [Equilibrium],
    pub equilibria_not_searched: &'a Option<NotSearched>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub equilibria_search_sampled: Option<Search>,
    pub energy: EnergyChange,
    pub switches: &'a [String],
}

/// The largest change of the conserved (or averaged) energy along a run.
#[derive(Debug, serde::Serialize)]
pub struct EnergyChange {
    pub label: &'static str,
    pub max_abs_change: f64,
}

impl Exploration {
    /// The summary of this run of `info`'s model from `y0`.
    pub fn summary<'a>(&'a self, info: &ModelInfo, params: &[f64], y0: &'a [f64]) -> Summary<'a> {
        Summary {
            model: info.name,
            params: info
                .parameter_names
                .iter()
                .copied()
                .zip(params.iter().copied())
                .collect(),
            y0,
            final_state: self.exact.last(),
            equilibria: &self.equilibria,
            equilibria_not_searched: &self.equilibria_not_searched,
            equilibria_search_sampled: self.equilibria_search_sampled,
            energy: EnergyChange {
                label: self.energy_label,
                max_abs_change: self.max_energy_change(),
            },
            switches: &self.switches,
        }
    }

    /// The largest |change| of the energy along the run.
    pub fn max_energy_change(&self) -> f64 {
        self.energy_change
            .iter()
            .fold(0.0f64, |m, e| m.max(e.abs()))
    }

    /// The columns of the time series: t, the exact state, the averaged
    /// one, a constrained model's reactions.
    pub fn series_header(&self) -> Vec<String> {
        let size = self.exact.first().map_or(0, Vec::len);
        let averaged = if self.averaged.is_some() { size } else { 0 };
        let reactions = self.reactions.iter().flat_map(|r| &r.names);
        std::iter::once("t".to_string())
            .chain((0..size).map(|k| format!("exact_{k}")))
            .chain((0..averaged).map(|k| format!("averaged_{k}")))
            .chain(reactions.map(|name| format!("reaction_{name}")))
            .collect()
    }

    /// The rows of the time series, as [`Exploration::series_header`] names them.
    pub fn series_rows(&self) -> impl Iterator<Item = Vec<f64>> + '_ {
        self.times.iter().enumerate().map(|(k, t)| {
            std::iter::once(*t)
                .chain(self.exact[k].iter().copied())
                .chain(self.averaged.iter().flat_map(|a| a[k].iter().copied()))
                .chain(
                    self.reactions
                        .iter()
                        .flat_map(|r| r.values[k].iter().copied()),
                )
                .collect()
        })
    }

    /// What a scene prints: the first `limit` equilibria with their
    /// verdicts (and how many more there are), why none were searched or
    /// how the search sampled, the switches, the energy's change.
    pub fn report(&self, coordinates: &[&str], limit: usize) -> Vec<String> {
        let mut lines: Vec<String> = self
            .equilibria
            .iter()
            .take(limit)
            .map(|e| {
                let family: Vec<&str> = e.family_along.iter().map(|&i| coordinates[i]).collect();
                let family = match family.is_empty() {
                    true => String::new(),
                    false => format!(" (a family along {}, judged reduced)", family.join(", ")),
                };
                let pole = match e.pole {
                    true => " (a pole of the chart: singular only along the family)",
                    false => "",
                };
                format!(
                    "equilibrium q = {:?}{family}{pole}: Hessian eigenvalues {:?}: {}",
                    e.q, e.hessian_eigenvalues, e.verdict
                )
            })
            .collect();
        if self.equilibria.len() > limit {
            let more = self.equilibria.len() - limit;
            lines.push(format!("… and {more} more equilibria in summary.json"));
        }
        if let Some(reason) = &self.equilibria_not_searched {
            lines.push(format!("equilibria not searched: {reason}"));
        }
        if let Some(search) = &self.equilibria_search_sampled {
            lines.push(format!("equilibria searched from {search}"));
        }
        lines.extend(self.switches.iter().cloned());
        let change = self.max_energy_change();
        lines.push(format!("{}: max |change| {change:.3e}", self.energy_label));
        lines
    }
}

/// Why an exploration failed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ExploreError {
    #[error(transparent)]
    Ode(#[from] OdeError),
    #[error(transparent)]
    Contact(#[from] ContactError),
    #[error(transparent)]
    Constrained(#[from] ConstrainedError),
    #[error("the state of '{model}' has {expected} components, got {got}")]
    StateLength {
        model: &'static str,
        expected: usize,
        got: usize,
    },
    /// A contact model of more points than the explorer is compiled for.
    #[error("'{model}' has {points} contact points: the explorer runs contact models of 1 to 3")]
    TooManyContacts { model: &'static str, points: usize },
}

struct Contacts<'a> {
    model: &'a dyn DynamicModel,
    params: &'a [f64],
}

impl<const C: usize, const M: usize> ContactModel<C, M> for Contacts<'_> {
    fn free_forces(&self, y: &[f64; M]) -> [f64; C] {
        to_array(
            &self
                .model
                .contact_forces(self.params, y)
                .unwrap_or_default()
                .0,
        )
    }
    fn normal_forces(&self, y: &[f64; M]) -> [f64; C] {
        to_array(
            &self
                .model
                .contact_forces(self.params, y)
                .unwrap_or_default()
                .1,
        )
    }
    fn masses(&self) -> [f64; C] {
        to_array(
            &self
                .model
                .contact_constants(self.params)
                .unwrap_or_default()
                .0,
        )
    }
    fn friction(&self) -> [f64; C] {
        to_array(
            &self
                .model
                .contact_constants(self.params)
                .unwrap_or_default()
                .1,
        )
    }
}

fn to_array<const N: usize>(v: &[f64]) -> [f64; N] {
    std::array::from_fn(|i| v.get(i).copied().unwrap_or(f64::NAN))
}

/// Runs everything the explorer shows for `model` from `y0`.
pub fn explore(
    handle: &Model,
    params: &[f64],
    y0: &[f64],
    settings: &Settings,
) -> Result<Exploration, ExploreError> {
    let model = handle.dynamic;
    let expected = model.periodic_state().len();
    if y0.len() != expected {
        return Err(ExploreError::StateLength {
            model: model.info().name,
            expected,
            got: y0.len(),
        });
    }
    let name = model.info().name;
    // A Hamiltonian model; otherwise a contact model.
    if let Some(systems) = handle.systems() {
        return hamiltonian_runs(systems, model, params, y0, settings);
    }
    if let Some(constrained) = handle.constrained {
        return constrained_runs(constrained, params, y0, settings);
    }
    match expected {
        2 => contacts::<1, 2>(model, params, y0, settings),
        4 => contacts::<2, 4>(model, params, y0, settings),
        6 => contacts::<3, 6>(model, params, y0, settings),
        _ => Err(ExploreError::TooManyContacts {
            model: name,
            points: expected / 2,
        }),
    }
}

fn grid(t_end: f64, samples: usize) -> Vec<f64> {
    (0..=samples.max(1))
        .map(|i| t_end * i as f64 / samples.max(1) as f64)
        .collect()
}

/// The runs of a Hamiltonian model on its generated systems (so every
/// method, `taylor` included, is available).
fn hamiltonian_runs(
    systems: &dyn Systems,
    model: &dyn DynamicModel,
    params: &[f64],
    y0: &[f64],
    settings: &Settings,
) -> Result<Exploration, ExploreError> {
    let times = grid(settings.t_end, settings.samples);
    let exact_system = systems.exact(params);
    let exact = exact_system.states_at(settings.method, 0.0, y0, &times)?;
    let (found, search, not_searched) = match effective_equilibria(model, params) {
        Ok((found, search)) => (found, Some(search), None),
        Err(reason) => (Vec::new(), None, Some(reason)),
    };
    let mut out = Exploration {
        equilibria: found,
        equilibria_search_sampled: search.filter(Search::sampled),
        equilibria_not_searched: not_searched,
        ..Default::default()
    };
    match (systems.phase_period(params), systems.averaged(params)) {
        (Some(period), Some(averaged_system)) => {
            let averaged = averaged_system.states_at(settings.method, 0.0, y0, &times)?;
            let h0 = model.averaged_energy(params, y0).unwrap_or(0.0);
            out.energy_change = averaged
                .iter()
                .map(|y| model.averaged_energy(params, y).unwrap_or(0.0) - h0)
                .collect();
            out.energy_label = "averaged Hamiltonian: change along the averaged run";
            out.averaged = Some(averaged);
            let map_times: Vec<f64> = (0..=settings.periods).map(|k| k as f64 * period).collect();
            let map = exact_system.states_at(settings.method, 0.0, y0, &map_times)?;
            out.period_map = Some(map);
        }
        _ => {
            let h0 = model.energy(params, 0.0, y0);
            out.energy_change = times
                .iter()
                .zip(&exact)
                .map(|(t, y)| model.energy(params, *t, y) - h0)
                .collect();
            out.energy_label = "H(t) − H(0) along the exact run";
        }
    }
    out.exact = exact;
    out.times = times;
    Ok(out)
}

/// The value of the parameter the model file names as its vibration's
/// amplitude, if it names one.
fn vibration_amplitude(model: &dyn ConstrainedSystems, params: &[f64]) -> Option<f64> {
    let info = model.info();
    let name = info.amplitude?;
    let index = info.parameter_names.iter().position(|n| *n == name)?;
    params.get(index).copied()
}

/// The run of a constrained model on its constraints (projected at each
/// sample), and its period map if it has a fast phase.
fn constrained_runs(
    model: &dyn ConstrainedSystems,
    params: &[f64],
    y0: &[f64],
    settings: &Settings,
) -> Result<Exploration, ExploreError> {
    let times = grid(settings.t_end, settings.samples);
    let run = on_constraints::run(model, params, Some(y0), settings.method, &times)?;
    let e0 = run.energy.first().copied().unwrap_or(0.0);
    let period_map = match model.phase_period(params) {
        Some(period) if settings.periods > 0 => {
            let map_times: Vec<f64> = (0..=settings.periods).map(|k| k as f64 * period).collect();
            let map = on_constraints::run(model, params, Some(y0), settings.method, &map_times)?;
            Some(map.states)
        }
        _ => None,
    };
    Ok(Exploration {
        energy_change: run.energy.iter().map(|e| e - e0).collect(),
        energy_label: match (&period_map, vibration_amplitude(model, params)) {
            // A vibration set to amplitude 0 does no work: E is conserved.
            (Some(_), amplitude) if amplitude != Some(0.0) => {
                "E(t) − E(0) on the constraints (the vibration does work)"
            }
            _ => "E(t) − E(0) on the constraints",
        },
        period_map,
        equilibria_not_searched: Some(NotSearched::OnConstraints),
        switches: std::iter::once(format!(
            "constraints ({}): largest residual |g| {:.1e}, |G q' + c_t| {:.1e} after projection; {:.1e}, {:.1e} before",
            run.constraint_names.join(", "),
            run.largest_residual.0,
            run.largest_residual.1,
            run.largest_drift.0,
            run.largest_drift.1
        ))
        .chain(run.near_singular.first().map(|[from, _]| {
            format!(
                "near a singular position {} time(s), the first from t = {from:.4}: passed by the equations made for them (DOP853)",
                run.near_singular.len()
            )
        }))
        .collect(),
        reactions: Some(Reactions {
            names: run.constraint_names,
            values: run.reactions,
        }),
        exact: run.states,
        times: run.times,
        ..Default::default()
    })
}

fn contacts<const C: usize, const M: usize>(
    model: &dyn DynamicModel,
    params: &[f64],
    y0: &[f64],
    settings: &Settings,
) -> Result<Exploration, ExploreError> {
    let y0: [f64; M] = to_array(y0);
    let times = grid(settings.t_end, settings.samples);
    let system = Contacts { model, params };
    let run = StickSlip::new(settings.method).run::<_, C, M>(
        &system,
        0.0,
        &y0,
        settings.t_end,
        &times,
    )?;
    let e0 = model.energy(params, 0.0, &y0);
    Ok(Exploration {
        times: run.samples.iter().map(|(t, _)| *t).collect(),
        exact: run.samples.iter().map(|(_, y)| y.to_vec()).collect(),
        energy_change: run
            .samples
            .iter()
            .map(|(t, y)| model.energy(params, *t, y) - e0)
            .collect(),
        energy_label: "E(t) − E(0): friction and dissipation work",
        equilibria_not_searched: Some(NotSearched::NoPotential),
        switches: run
            .switches
            .iter()
            .map(|s| {
                format!(
                    "t = {:.6}: contact {} {} → {} (case {})",
                    s.t,
                    s.contact + 1,
                    s.from,
                    s.to,
                    s.case
                )
            })
            .collect(),
        ..Default::default()
    })
}

/// Limits of the finite values, widened a little ((−1, 1) if none).
fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(v), h.max(v)));
    if lo > hi {
        return (-1.0, 1.0);
    }
    let pad = 0.05 * (hi - lo).max(1e-9);
    (lo - pad, hi + pad)
}

/// The panel titles, in the model's notation (φ₁, p_φ₁, x₁′).
fn panel_titles(result: &Exploration, info: &ModelInfo, velocities: bool) -> Vec<String> {
    let names: Vec<String> = info.coordinates.iter().map(|c| display_name(c)).collect();
    let velocity = |i: usize| {
        if velocities {
            format!("{}′", names[i])
        } else {
            display_name(info.momenta[i])
        }
    };
    let mut titles = Vec::new();
    for (i, q) in names.iter().enumerate() {
        titles.push(format!("{q}(t)"));
        titles.push(format!("phase portrait ({q}, {})", velocity(i)));
        titles.push(if result.period_map.is_some() {
            format!("period map ({q}, {})", velocity(i))
        } else {
            format!("{}(t)", velocity(i))
        });
    }
    titles.push(result.energy_label.to_string());
    if result.averaged.is_some() {
        titles.push("|exact − averaged| of the coordinates".into());
    }
    titles
}

/// The panels of degree of freedom `i` of `n`: its time series, its phase
/// portrait, and its period map (or its velocity).
fn degree_panels<'a>(
    result: &Exploration,
    averaged: &[Vec<f64>],
    [i, n]: [usize; 2],
    titles: &'a [String],
    name: &'a str,
    t_range: (f64, f64),
) -> [PanelSpec<'a>; 3] {
    let column = |k: usize, rows: &[Vec<f64>]| rows.iter().map(move |y| y[k]).collect::<Vec<f64>>();
    let q: Vec<f64> = column(i, &result.exact)
        .into_iter()
        .chain(column(i, averaged))
        .collect();
    let p: Vec<f64> = column(n + i, &result.exact)
        .into_iter()
        .chain(column(n + i, averaged))
        .collect();
    let (q_range, p_range) = (range(q.iter().copied()), range(p.iter().copied()));
    let third = match &result.period_map {
        Some(map) => PanelSpec::new(
            &titles[3 * i + 2],
            name,
            "",
            range(column(i, map).into_iter()),
            range(column(n + i, map).into_iter()),
        ),
        None => PanelSpec::new(&titles[3 * i + 2], "t", "", t_range, p_range),
    };
    [
        PanelSpec::new(&titles[3 * i], "t", name, t_range, q_range),
        PanelSpec::new(&titles[3 * i + 1], name, "", q_range, p_range),
        third,
    ]
}

/// Each constraint's reaction against time in panel `k`, with a legend.
fn draw_reactions(figure: &mut Figure, k: usize, times: &[f64], reactions: &Reactions) {
    let mut legend = Vec::new();
    for (r, name) in reactions.names.iter().enumerate() {
        let curve: Vec<(f64, f64)> = times
            .iter()
            .zip(&reactions.values)
            .map(|(t, values)| (*t, values[r]))
            .collect();
        figure.line(k, &curve, palette(r));
        legend.push((display_name(name), palette(r)));
    }
    figure.legend(k, &legend);
}

/// The figure: per degree of freedom the time series, the phase portrait
/// and the period map (or the velocity), then the energy change and the
/// exact−averaged deviation.
pub fn figure(result: &Exploration, model: &dyn DynamicModel, t_end: f64) -> Figure {
    let info = model.info();
    // The state's second half: momenta, or velocities.
    let (n, velocities) = match model.kind() {
        Kind::Hamiltonian { dof, .. } => (dof, false),
        Kind::Contacts { count } => (count, true),
        Kind::Constrained { coordinates, .. } => (coordinates, true),
    };
    let names: Vec<String> = info.coordinates.iter().map(|c| display_name(c)).collect();
    let coordinate_names: Vec<&str> = names.iter().map(String::as_str).collect();
    let titles = panel_titles(result, info, velocities);
    let t_range = (0.0, t_end);
    let averaged = result.averaged.clone().unwrap_or_default();
    let mut specs: Vec<PanelSpec> = (0..n)
        .flat_map(|i| {
            degree_panels(
                result,
                &averaged,
                [i, n],
                &titles,
                coordinate_names[i],
                t_range,
            )
        })
        .collect();
    specs.push(PanelSpec::new(
        &titles[3 * n],
        "t",
        "",
        t_range,
        range(result.energy_change.iter().copied().chain([0.0])),
    ));
    let deviation: Vec<Vec<(f64, f64)>> = (0..n)
        .map(|i| {
            result
                .times
                .iter()
                .zip(result.exact.iter().zip(&averaged))
                .map(|(t, (e, a))| (*t, (e[i] - a[i]).abs()))
                .collect()
        })
        .collect();
    if result.averaged.is_some() {
        specs.push(PanelSpec::new(
            &titles[3 * n + 1],
            "t",
            "",
            t_range,
            range(deviation.iter().flatten().map(|p| p.1).chain([0.0])),
        ));
    }
    let reaction_panel = result.reactions.as_ref().map(|reactions| {
        specs.push(PanelSpec::new(
            "reactions λ(t) of the constraints",
            "t",
            "",
            t_range,
            range(reactions.values.iter().flatten().copied()),
        ));
        specs.len() - 1
    });
    let mut figure = Figure::grid(3, specs.len().div_ceil(3), 460, 340, &specs);
    if let (Some(k), Some(reactions)) = (reaction_panel, &result.reactions) {
        draw_reactions(&mut figure, k, &result.times, reactions);
    }
    let series = |k: usize, rows: &[Vec<f64>]| {
        result
            .times
            .iter()
            .zip(rows)
            .map(|(t, y)| (*t, y[k]))
            .collect::<Vec<_>>()
    };
    let pairs = |a: usize, b: usize, rows: &[Vec<f64>]| {
        rows.iter().map(|y| (y[a], y[b])).collect::<Vec<_>>()
    };
    for i in 0..n {
        figure.line(3 * i, &series(i, &result.exact), palette(0));
        figure.line(3 * i + 1, &pairs(i, n + i, &result.exact), palette(0));
        if result.averaged.is_some() {
            figure.line(3 * i, &series(i, &averaged), BLACK);
            figure.line(3 * i + 1, &pairs(i, n + i, &averaged), BLACK);
            figure.legend(
                3 * i,
                &[("exact".into(), palette(0)), ("averaged".into(), BLACK)],
            );
        }
        match &result.period_map {
            Some(map) => figure.points(3 * i + 2, pairs(i, n + i, map), RED, 3),
            None => figure.line(3 * i + 2, &series(n + i, &result.exact), palette(1)),
        }
    }
    let energy: Vec<(f64, f64)> = result
        .times
        .iter()
        .copied()
        .zip(result.energy_change.iter().copied())
        .collect();
    figure.line(3 * n, &energy, GREY);
    for (i, d) in deviation.iter().enumerate() {
        if result.averaged.is_some() {
            figure.line(3 * n + 1, d, palette(i));
        }
    }
    figure
}
