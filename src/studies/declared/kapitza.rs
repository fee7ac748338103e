//! Study 1's scenes: the period map's portraits, the upper position's
//! stability, the attractor (their results say what they write, in
//! `studies::kapitza`).

use crate::registry::ModelInfo;
use crate::scene::SceneError;
use crate::scenes::Study;
use crate::settings::{method, Declared, Range, METHODS};
use crate::studies::kapitza::{self, KapitzaOrbits, UpperPosition};
use mechlab_runtime::declare_settings;

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
    type Outcome = UpperPosition;
    fn model() -> Option<&'static ModelInfo> {
        Some(kapitza::info())
    }
    const PARAMETERS: &'static [(&'static str, &'static str)] = &[("A", "1.6")];
    fn run(&self, values: &[f64]) -> Result<UpperPosition, SceneError> {
        Ok(kapitza::upper_position(&kapitza::UpperPositionSettings {
            params: kapitza::study_params(values),
            periods: self.periods,
            chart_eps: self.chart_eps,
            chart_a: self.chart_a,
            chart_a_max: self.chart_a_max,
            method: method(Self::ANALYSIS, "dop853", self.tol)?,
        })?)
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
    type Outcome = kapitza::Attractor;
    fn model() -> Option<&'static ModelInfo> {
        Some(kapitza::info())
    }
    const PARAMETERS: &'static [(&'static str, &'static str)] =
        &[("A", "1.5"), ("eps", "0.7"), ("mu", "0.4")];
    fn run(&self, values: &[f64]) -> Result<kapitza::Attractor, SceneError> {
        Ok(kapitza::attractor(&kapitza::AttractorSettings {
            params: kapitza::study_params(values),
            points: self.points,
            transient: self.transient,
            lyapunov_periods: self.lyapunov_periods,
            zoom: self.zoom,
            method: method(Self::ANALYSIS, &self.method, self.tol)?,
        })?)
    }
}
