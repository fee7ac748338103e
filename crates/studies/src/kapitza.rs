//! Study 1's scenes: the period map's portraits, the upper position's
//! stability, the attractor (their results say what they write, in
//! `studies::kapitza`).

use super::{named, Written};
use mechlab::plot::Figure;
use mechlab::registry::ModelInfo;
use mechlab::scene::SceneError;
use mechlab::scenes::Study;
use mechlab::scenes::{Outputs, Table};
use mechlab::settings::{method, Declared, Range, METHODS};
use mechlab::studies::kapitza::{self, Attractor, Portrait, SingleOrbit, UpperPosition};
use mechlab_runtime::declare_settings;
use serde::Serialize;

declare_settings! {
    /// Orbits of the period map of the Kapitza pendulum on the unrolled
    /// cylinder (q mod 2π, p): the portraits of the given amplitudes, or one
    /// orbit from `start` with its final state and cost.
    pub struct KapitzaPeriodMap for "kapitza_period_map" {
        /// Initial conditions of each portrait.
        orbits: usize = 24, Range::Count { min: 1, max: 100_000 };
        /// Periods per orbit.
        periods: usize = 3000, Range::Count { min: 1, max: 100_000_000 };
        /// The amplitudes A drawn (portraits; A = 0 is the ordinary pendulum).
        presets: Vec<f64> = vec![0.0, 0.2, 1.0], Range::NonNegative;
        /// auto: the portraits; q,p: one orbit from there.
        start: Option<[f64; 2]> = None, Range::Any;
        /// One orbit: timed runs (the fastest is reported).
        repeat: usize = 1, Range::Count { min: 1, max: 1000 };
        /// The integration method.
        method: String = "dop853".into(), Range::OneOf(METHODS);
        /// Its tolerance (taylor, dop853, radau5) or step size.
        tol: f64 = 1e-10, Range::Positive;
    }
}

impl Study for KapitzaPeriodMap {
    type Outcome = KapitzaOrbits;
    fn model() -> Option<&'static ModelInfo> {
        Some(kapitza::info())
    }
    const PARAMETERS: &'static [(&'static str, &'static str)] = &[("A", "1")];
    fn run(&self, values: &[f64]) -> Result<KapitzaOrbits, SceneError> {
        let params = kapitza::study_params(values);
        let method = method(Self::ANALYSIS, &self.method, self.tol)?;
        if let Some(start) = self.start {
            let orbit = kapitza::single_orbit(params, start, self.periods, method, self.repeat)?;
            return Ok(KapitzaOrbits::One(orbit));
        }
        let portraits =
            kapitza::portraits(params, &self.presets, self.orbits, self.periods, method)?;
        Ok(KapitzaOrbits::Portraits {
            eps: params.eps,
            mu: params.mu,
            method: method.name(),
            portraits,
        })
    }
}

declare_settings! {
    /// Is the upper position q = 0 of the pendulum with a vibrating pivot
    /// stable? Its Floquet multipliers, the critical amplitude A* against
    /// the averaged √2, orbits either side of A*, and the (ε, A) chart.
    pub struct KapitzaStability for "kapitza_stability" {
        /// DOP853 tolerance of every run (monodromy matrices, orbits, chart).
        tol: f64 = 1e-12, Range::Positive;
        /// Periods per orbit near q = 0.
        periods: usize = 2000, Range::Count { min: 1, max: 100_000_000 };
        /// Chart resolution in ε (0.02..0.5).
        chart_eps: usize = 40, Range::Count { min: 2, max: 10_000 };
        /// Chart resolution in A (0..chart_a_max).
        chart_a: usize = 120, Range::Count { min: 2, max: 100_000 };
        /// Largest A of the chart.
        chart_a_max: f64 = 12.0, Range::Positive;
    }
}

impl Study for KapitzaStability {
    type Outcome = Written<UpperPosition>;
    fn model() -> Option<&'static ModelInfo> {
        Some(kapitza::info())
    }
    const PARAMETERS: &'static [(&'static str, &'static str)] = &[("A", "1.6")];
    fn run(&self, values: &[f64]) -> Result<Self::Outcome, SceneError> {
        Ok(Written(kapitza::upper_position(
            &kapitza::UpperPositionSettings {
                params: kapitza::study_params(values),
                periods: self.periods,
                chart_eps: self.chart_eps,
                chart_a: self.chart_a,
                chart_a_max: self.chart_a_max,
                method: method(Self::ANALYSIS, "dop853", self.tol)?,
            },
        )?))
    }
}

declare_settings! {
    /// The strange attractor of the dissipative Kapitza period map: its
    /// points, Lyapunov exponents (their sum against −μT) and its
    /// box-counting and Kaplan–Yorke dimensions.
    pub struct KapitzaAttractor for "kapitza_attractor" {
        /// Points of the attractor.
        points: usize = 100_000, Range::Count { min: 1, max: 100_000_000 };
        /// Periods dropped first.
        transient: usize = 1000, Range::Count { min: 0, max: 100_000_000 };
        /// Periods for the Lyapunov exponents.
        lyapunov_periods: usize = 20_000, Range::Count { min: 2, max: 100_000_000 };
        /// The zoom shows 1/zoom of the attractor's extent.
        zoom: f64 = 8.0, Range::Positive;
        /// The integration method.
        method: String = "dop853".into(), Range::OneOf(METHODS);
        /// Its tolerance (taylor, dop853, radau5) or step size.
        tol: f64 = 1e-9, Range::Positive;
    }
}

impl Study for KapitzaAttractor {
    type Outcome = Written<Attractor>;
    fn model() -> Option<&'static ModelInfo> {
        Some(kapitza::info())
    }
    const PARAMETERS: &'static [(&'static str, &'static str)] =
        &[("A", "1.5"), ("eps", "0.7"), ("mu", "0.4")];
    fn run(&self, values: &[f64]) -> Result<Self::Outcome, SceneError> {
        Ok(Written(kapitza::attractor(&kapitza::AttractorSettings {
            params: kapitza::study_params(values),
            points: self.points,
            transient: self.transient,
            lyapunov_periods: self.lyapunov_periods,
            zoom: self.zoom,
            method: method(Self::ANALYSIS, &self.method, self.tol)?,
        })?))
    }
}

impl Outputs for Written<UpperPosition> {
    fn figures(&self) -> Vec<(String, Figure)> {
        vec![
            named("orbits_near_upper_position.png", self.orbits_figure()),
            named("averaged_portraits.png", self.averaged_figure()),
            named("stability_chart.png", self.chart_figure()),
        ]
    }
    fn tables(&self) -> Vec<Table> {
        let header = ["A", "mu", "orbit", "period", "q", "p"];
        vec![
            Table::new("orbits_near_upper_position.csv", &header, self.orbit_rows()),
            Table::new(
                "stability_chart.csv",
                &["eps", "A_boundary"],
                self.chart_rows(),
            ),
        ]
    }
    fn lines(&self) -> Vec<String> {
        let mut lines = vec![format!(
            "ε = {}, μ = {}: A* = {:?} (averaged: √2, to second order: {:?}); at A = {}: multipliers {:?}, det M = {} (exp(−μT) = {}): {}",
            self.eps, self.mu, self.a_star, self.a_star_second_order, self.A, self.multipliers,
            self.determinant, self.determinant_expected, self.verdict
        )];
        lines.extend(self.a_star_by_eps.iter().map(|s| {
            format!(
                "ε = {}: A* = {:?}, second order {:?}",
                s.eps, s.a_star, s.a_star_second_order
            )
        }));
        lines
    }
}

impl Outputs for Written<Attractor> {
    fn figures(&self) -> Vec<(String, Figure)> {
        vec![
            named("attractor.png", self.figure()),
            named("box_counting.png", self.box_counting_figure()),
        ]
    }
    fn tables(&self) -> Vec<Table> {
        let points = self.orbit.iter().map(|p| (p[0], p[1]));
        let boxes = self.box_sides.iter().zip(&self.boxes);
        vec![
            Table::new("attractor.csv", &["q", "p"], points),
            Table::new("box_counting.csv", &["box_side", "boxes"], boxes),
        ]
    }
    fn lines(&self) -> Vec<String> {
        let mut lines = vec![format!(
            "Lyapunov exponents per period {:.4?}, sum {:.4} (−μT = {:.4}), box-counting dimension {:.3}, Kaplan–Yorke {:.3}",
            self.lyapunov, self.lyapunov_sum, self.lyapunov_sum_expected,
            self.dimension, self.kaplan_yorke_dimension
        )];
        if self.lyapunov[0] <= 0.0 {
            lines.push("note: the largest exponent is not positive: at these parameters the attractor is not chaotic".into());
        }
        lines
    }
}

/// The portraits of several amplitudes, or one orbit.
#[derive(Serialize)]
#[serde(untagged)]
pub enum KapitzaOrbits {
    Portraits {
        eps: f64,
        mu: f64,
        method: &'static str,
        portraits: Vec<Portrait>,
    },
    One(SingleOrbit),
}

impl Outputs for KapitzaOrbits {
    fn figures(&self) -> Vec<(String, Figure)> {
        match self {
            KapitzaOrbits::One(orbit) => vec![named("orbit.png", orbit.figure())],
            KapitzaOrbits::Portraits { portraits, .. } => portraits
                .iter()
                .map(|p| (format!("portrait_A{}.png", p.A), p.figure()))
                .collect(),
        }
    }
    fn tables(&self) -> Vec<Table> {
        match self {
            KapitzaOrbits::One(orbit) => {
                let rows = orbit
                    .points
                    .iter()
                    .enumerate()
                    .map(|(k, y)| (k, y[0], y[1]));
                vec![Table::new("orbit.csv", &["period", "q", "p"], rows)]
            }
            KapitzaOrbits::Portraits { portraits, .. } => portraits
                .iter()
                .map(|p| {
                    let header = ["orbit", "period", "q", "p"];
                    Table::new(format!("orbits_A{}.csv", p.A), &header, p.rows())
                })
                .collect(),
        }
    }
    fn lines(&self) -> Vec<String> {
        match self {
            KapitzaOrbits::One(o) => vec![format!(
                "after {} periods: {:?} ({} f evaluations, {:.3} s)",
                o.periods, o.final_state, o.f_evals, o.seconds
            )],
            KapitzaOrbits::Portraits { portraits, .. } => portraits
                .iter()
                .map(|p| format!("A = {}: {} orbits in {:.1} s", p.A, p.orbits, p.seconds))
                .collect(),
        }
    }
}
