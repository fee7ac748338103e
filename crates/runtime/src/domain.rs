//! A run that stopped where its model is not defined: which of the model
//! file's expressions stopped being real, and where. A model written in a
//! chart that covers only part of its motion (a bead on a circle in its
//! horizontal coordinate, a road point at √(L² − y²)) is valid; a run
//! that leaves the chart stops with this instead of a bare non-finite
//! state.

use crate::ode::OdeError;
use crate::registry::Model;

/// Where a run left its model's domain.
#[derive(Clone, Debug, thiserror::Error)]
#[error("model '{model}' ({file}) is not defined where the run went: {undefined} (t = {t}, {})", state_text(.state))]
pub struct OutsideDomain {
    pub model: &'static str,
    pub file: &'static str,
    /// The expression that is not finite.
    pub undefined: mechlab_model::Undefined,
    pub t: f64,
    /// The coordinates (and velocities, where the state holds them) at
    /// which it is not: the run's last state, or a point just past it
    /// along the run's direction.
    pub state: Vec<(String, f64)>,
}

fn state_text(state: &[(String, f64)]) -> String {
    let parts: Vec<String> = state.iter().map(|(n, v)| format!("{n} = {v}")).collect();
    parts.join(", ")
}

/// The expression of `model`'s file that stopped the run `stop` (a
/// non-finite step or a collapsed one), at `values`: at the run's last
/// state, or on the line from it along the flow (ever further, up to the
/// coordinates' own size). None when the stop is of another kind or every
/// expression is finite along the probe.
pub fn explain(model: &Model, values: &[f64], stop: &OdeError) -> Option<OutsideDomain> {
    let (t, y) = match stop {
        OdeError::NonFinite { t, y } => (*t, &y[..]),
        OdeError::StepSizeUnderflow { t, y, .. } => (*t, &y[..]),
        _ => return None,
    };
    let info = model.info;
    let file = mechlab_model::Model::parse(info.source_file, info.source).ok()?;
    let n = file.coordinates.len();
    if y.len() < n {
        return None;
    }
    let parameter = |s: &str| {
        info.parameter_names
            .iter()
            .position(|p| *p == s)
            .and_then(|k| values.get(k).copied())
    };
    let phase = file
        .fast_phase
        .as_ref()
        .and_then(|p| p.rate.eval(&parameter).ok())
        .map(|rate| rate * t);
    // The state's second half are velocities for a constrained model,
    // momenta (not symbols of the file) otherwise.
    let velocities = info.velocities && y.len() >= 2 * n;
    let named = |z: &[f64]| -> Vec<(String, f64)> {
        let mut state: Vec<(String, f64)> = file
            .coordinates
            .iter()
            .zip(z)
            .map(|(c, v)| (c.name.clone(), *v))
            .collect();
        if velocities {
            state.extend(
                file.coordinates
                    .iter()
                    .zip(&z[n..])
                    .map(|(c, v)| (c.velocity.clone(), *v)),
            );
        }
        state
    };
    let at = |z: &[f64]| {
        let state = named(z);
        let value = |s: &str| {
            state
                .iter()
                .find(|(name, _)| name == s)
                .map(|(_, v)| *v)
                .or_else(|| (s == file.time).then_some(t))
                .or_else(|| phase.filter(|_| file.fast_phase.as_ref().is_some_and(|p| p.name == s)))
                .or_else(|| parameter(s))
        };
        file.undefined_at(&value).map(|undefined| OutsideDomain {
            model: info.name,
            file: info.source_file,
            undefined,
            t,
            state,
        })
    };
    if let Some(found) = at(y) {
        return Some(found);
    }
    let rate = model.flows()?.exact(values).rhs(t, y).ok()?;
    let speed = rate[..n].iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let size = y[..n].iter().fold(1.0_f64, |m, v| m.max(v.abs()));
    if !(speed > 0.0 && speed.is_finite()) {
        return None;
    }
    (0..=12).find_map(|k| {
        let reach = size * 1e-6 * 4f64.powi(k) / speed;
        let probe: Vec<f64> = y
            .iter()
            .enumerate()
            .map(|(i, v)| if i < n { v + reach * rate[i] } else { *v })
            .collect();
        at(&probe)
    })
}
