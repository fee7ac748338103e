//! Sections of autonomous constrained models with two degrees of freedom
//! on holonomic constraints (n coordinates, n − 2 constraints). The plane
//! is one coordinate, q_c = value; the chart is (q_o, q_o′), q_o the first
//! coordinate that, held with q_c, fixes the others through the
//! constraints at the model's start (for two points on rods, x₁ = 0 is
//! drawn in (x₂, x₂′), not in z₁, which the plane already fixes).
//!
//! A seed (q_o, q_o′) is completed by projection holding q_c, q_o and their
//! rates: the positions by Newton's method from the model's start, the
//! other velocities from the constraints, and q_c′ from E = H (the energy
//! is quadratic in q_c′ along that family, read exactly from three values)
//! on the branch crossing the plane in the direction asked. Crossings are
//! located on DOP853's dense output and put back on the constraints.
//!
//! The chart's second axis is a velocity, not the conjugate momentum: the
//! section map preserves the area ∫ p_o dq_o, not the area drawn.

use rayon::prelude::*;

use super::{
    quadratic_through, seeds_on_line, short, OrbitEnd, Section, SectionError, SectionOrbit,
};
use super::{SectionSettings, PLANE_COEFFICIENTS};
use crate::analysis::Refusal;
use crate::ode::holonomic::ConstraintError;
use crate::registry::{ConstrainedSystems, Model, PlaneCrossing};

/// The section of the constrained `model` through `seeds` (q_o, q_o′).
pub(super) fn section(
    model: &Model,
    systems: &'static dyn ConstrainedSystems,
    params: &[f64],
    seeds: &[[f64; 2]],
    settings: &SectionSettings,
) -> Result<Section, SectionError> {
    let chart = Chart::new(model, systems, params, settings)?;
    let s = settings;
    let name = model.info.name.to_string();
    if !(s.tol > 0.0 && s.t_max > 0.0 && s.energy.is_finite()) {
        return Err(Refusal::setting(
            name,
            "the tolerance and t_max must be positive, the energy and value finite",
        )
        .into());
    }
    if seeds.is_empty() {
        return Err(SectionError::NoSeeds { model: name });
    }
    crate::budget::check(
        || format!("{} orbits of {} crossings", seeds.len(), s.crossings),
        seeds.len() as u128 * s.crossings as u128,
        2 * std::mem::size_of::<f64>(),
    )
    .map_err(crate::ode::OdeError::from)?;
    let orbits = seeds
        .par_iter()
        .map(|seed| chart.follow(seed, s))
        .collect::<Result<Vec<_>, SectionError>>()?;
    let largest = |f: fn(&SectionOrbit) -> f64| orbits.iter().map(f).fold(0.0, f64::max);
    let info = model.info;
    Ok(Section {
        largest_energy_drift: largest(|o| o.energy_drift),
        largest_plane_distance: largest(|o| o.plane_distance),
        crossing_errors: Vec::new(),
        crossing_check: None,
        accuracy: None,
        model: name,
        energy: s.energy,
        energy_of: "H",
        plane: format!(
            "{} = {} ({}; on the constraints)",
            info.label(chart.c),
            short(chart.value),
            if chart.rising {
                "increasing"
            } else {
                "decreasing"
            },
        ),
        axes: [info.label(chart.o), info.label(chart.n + chart.o)],
        orbits,
    })
}

/// `count` seeds on the line q_o′ = 0 of the plane where the energy is
/// accessible, about the model's start (see [`super::seeds_across`]).
pub(super) fn seeds_across(
    model: &Model,
    systems: &'static dyn ConstrainedSystems,
    params: &[f64],
    settings: &SectionSettings,
    extent: f64,
    count: usize,
) -> Vec<[f64; 2]> {
    let Ok(chart) = Chart::new(model, systems, params, settings) else {
        return Vec::new();
    };
    let least = |q: f64| chart.least_energy(&[q, 0.0]);
    seeds_on_line(least, chart.centre, extent, settings.energy, count)
}

/// The plane q_c = value and the chart (q_o, q_o′) on it.
struct Chart<'a> {
    systems: &'static dyn ConstrainedSystems,
    params: &'a [f64],
    n: usize,
    c: usize,
    o: usize,
    value: f64,
    rising: bool,
    /// The model's start on the constraints, where Newton's method starts.
    reference: Vec<f64>,
    periodic: Vec<bool>,
    /// q_o at the start: seeds are scanned and an angle drawn about it.
    centre: f64,
}

impl<'a> Chart<'a> {
    fn new(
        model: &Model,
        systems: &'static dyn ConstrainedSystems,
        params: &'a [f64],
        s: &SectionSettings,
    ) -> Result<Chart<'a>, SectionError> {
        let name = model.info.name;
        let refuse =
            |requirement: &'static str| SectionError::from(Refusal::setting(name, requirement));
        if systems.has_fast_phase() {
            return Err(Refusal::FastPhase {
                model: name.into(),
                instead: "a constrained model's section is drawn without a fast phase; its period map (scenes period_map, chaos_map) is its section",
            }
            .into());
        }
        if systems.holonomic().iter().any(|h| !h) {
            return Err(Refusal::Nonholonomic {
                model: name.into(),
                reason: "a section needs holonomic constraints (with a nonholonomic one, a coordinate and its rate do not chart the energy surface on the plane)",
            }
            .into());
        }
        let n = model.info.coordinates.len();
        let k = systems.constraint_names().len();
        if n != k + 2 {
            return Err(Refusal::Dimension {
                model: name.into(),
                dof: n.saturating_sub(k),
                analysis: "a section",
                supported: "2 (on the constraints)",
            }
            .into());
        }
        let a = &s.plane;
        let planes: Vec<usize> = (0..a.len()).filter(|&i| a[i] != 0.0).collect();
        if a.len() != n || !a.iter().all(|x| x.is_finite()) || planes.is_empty() {
            return Err(refuse(PLANE_COEFFICIENTS));
        }
        let [c] = planes[..] else {
            return Err(refuse("a constrained model's plane is one coordinate (\"x1\", \"-2*x1\"): its other coordinates follow from the constraints"));
        };
        if !s.value.is_finite() {
            return Err(refuse("the plane's value must be finite"));
        }
        let mut reference = systems.start(params);
        systems
            .project(params, 0.0, &mut reference)
            .map_err(|source| SectionError::Start {
                model: name.into(),
                source,
            })?;
        let mut chart = Chart {
            systems,
            params,
            n,
            c,
            o: c,
            value: s.value / a[c],
            rising: s.rising == (a[c] > 0.0),
            periodic: systems.periodic_state(),
            reference,
            centre: 0.0,
        };
        // The first coordinate that, held with q_c, charts the constraints.
        chart.o = (0..n)
            .filter(|&i| i != c)
            .find(|&i| chart.state(&[chart.reference[i], 0.0], 0.0).is_ok())
            .ok_or_else(|| refuse("no coordinate, held with the plane's, fixes the others through the constraints at the model's start (a singular chart there)"))?;
        chart.centre = chart.reference[chart.o];
        Ok(chart)
    }

    /// The consistent state at `seed` = (q_o, q_o′) on the plane with
    /// q_c′ = `rate`.
    fn state(&self, seed: &[f64; 2], rate: f64) -> Result<Vec<f64>, ConstraintError> {
        let n = self.n;
        let mut y = self.reference.clone();
        y[n..].fill(0.0);
        y[self.c] = self.value;
        y[self.o] = seed[0];
        y[n + self.c] = rate;
        y[n + self.o] = seed[1];
        let held = [self.c, self.o, n + self.c, n + self.o];
        self.systems.consistent(self.params, &mut y, &held)?;
        Ok(y)
    }

    fn energy(&self, y: &[f64]) -> f64 {
        self.systems.energy(self.params, 0.0, y).unwrap_or(f64::NAN)
    }

    /// [α, β, γ] of the energy along q_c′ at `seed`.
    fn quadratic(&self, seed: &[f64; 2]) -> Result<[f64; 3], ConstraintError> {
        let mut values = [0.0; 3];
        for (value, rate) in values.iter_mut().zip([-1.0, 0.0, 1.0]) {
            *value = self.energy(&self.state(seed, rate)?);
        }
        Ok(quadratic_through(values))
    }

    /// The least energy over q_c′ at `seed` (NaN where the plane has no
    /// consistent positions there).
    fn least_energy(&self, seed: &[f64; 2]) -> f64 {
        match self.quadratic(seed) {
            Ok([alpha, beta, zero]) => zero - beta * beta / (4.0 * alpha),
            Err(_) => f64::NAN,
        }
    }

    /// The state at `seed` with q_c′ solved from H = E on the branch
    /// crossing the plane the way asked.
    fn on_plane(&self, seed: &[f64; 2], energy: f64) -> Result<Vec<f64>, SectionError> {
        let [alpha, beta, zero] =
            self.quadratic(seed)
                .map_err(|source| SectionError::Constraint {
                    seed: *seed,
                    source,
                })?;
        if !(alpha > 0.0) || !beta.is_finite() || !zero.is_finite() {
            return Err(SectionError::Singular { seed: *seed });
        }
        let discriminant = beta * beta - 4.0 * alpha * (zero - energy);
        if !(discriminant >= 0.0) {
            return Err(SectionError::Inaccessible {
                seed: *seed,
                energy,
                least: zero - beta * beta / (4.0 * alpha),
            });
        }
        let root = discriminant.sqrt();
        let rate = match self.rising {
            true => (-beta + root) / (2.0 * alpha),
            false => (-beta - root) / (2.0 * alpha),
        };
        self.state(seed, rate)
            .map_err(|source| SectionError::Constraint {
                seed: *seed,
                source,
            })
    }

    /// (q_o, q_o′) of a state, an angle on its circle about the centre.
    fn point(&self, y: &[f64]) -> [f64; 2] {
        let q = y[self.o];
        let q = match self.periodic[self.o] {
            true => self.centre + crate::ode::wrap_angle(q - self.centre),
            false => q,
        };
        [q, y[self.n + self.o]]
    }

    /// The crossings of the orbit through `seed`.
    fn follow(&self, seed: &[f64; 2], s: &SectionSettings) -> Result<SectionOrbit, SectionError> {
        let start = self.on_plane(seed, s.energy)?;
        let mut orbit = SectionOrbit::from_seed(seed, &start);
        if orbit.crossings >= s.crossings {
            return Ok(orbit);
        }
        let plane = PlaneCrossing {
            coordinate: self.c,
            value: self.value,
            rising: self.rising,
            tol: s.tol,
            t_max: s.t_max,
        };
        let periodic = self.periodic[self.c];
        let run = self
            .systems
            .crossings(self.params, &start, &plane, &mut |y| {
                orbit.points.push(self.point(y));
                orbit.crossings += 1;
                orbit.energy_drift = orbit.energy_drift.max((self.energy(y) - s.energy).abs());
                orbit.plane_distance = orbit.plane_distance.max(plane.offset(y, periodic).abs());
                orbit.crossings < s.crossings
            });
        match run {
            Ok(_) if orbit.crossings < s.crossings => {
                orbit.end = OrbitEnd::TimeLimit { t_max: s.t_max }
            }
            Ok(_) => {}
            Err(error) => orbit.end = OrbitEnd::Failed { error },
        }
        Ok(orbit)
    }
}
