//! The study scenes' declarations: each scene's settings written once
//! (name, default, range, help), how the scene runs on them, and what its
//! result writes (figures, tables, the headline lines). The scenes in
//! `examples/` are then one line each ([`crate::scenes::study_scene`]).

use super::double_pendulum::{self as dp, EQUILIBRIA};
use super::kapitza::{self, Portrait, SingleOrbit, UpperPosition};
use super::painleve::{self, deformation, graphs, impact, stiff_limit};
use crate::plot::Figure;
use crate::registry::ModelInfo;
use crate::scene::{Progress, SceneError};
use crate::scenes::{Outputs, Study, Table};
use crate::settings::{method, Declared, Range, METHODS};
use mechlab_runtime::declare_settings;

/// A figure with its file name.
fn named(file: &str, figure: Figure) -> (String, Figure) {
    (file.to_string(), figure)
}

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

/// The portraits of several amplitudes, or one orbit.
#[derive(serde::Serialize)]
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

impl Study for KapitzaPeriodMap {
    type Outcome = KapitzaOrbits;
    fn model() -> Option<&'static ModelInfo> {
        Some(&crate::models::kapitza::INFO)
    }
    const PARAMETERS: &'static [(&'static str, &'static str)] = &[("A", "1")];
    fn run(&self, values: &[f64]) -> Result<KapitzaOrbits, SceneError> {
        let params = crate::models::kapitza::Params::from_values(values);
        let method = method(Self::ANALYSIS, &self.method, self.tol)?;
        if let Some(start) = self.start {
            let orbit = kapitza::single_orbit(params, start, self.periods, method, self.repeat)?;
            return Ok(KapitzaOrbits::One(orbit));
        }
        let portraits = self
            .presets
            .iter()
            .map(|&a| {
                let params = crate::models::kapitza::Params { A: a, ..params };
                kapitza::portrait(params, self.orbits, self.periods, method)
            })
            .collect::<Result<_, _>>()?;
        Ok(KapitzaOrbits::Portraits {
            eps: params.eps,
            mu: params.mu,
            method: method.name(),
            portraits,
        })
    }
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
        Some(&crate::models::kapitza::INFO)
    }
    const PARAMETERS: &'static [(&'static str, &'static str)] = &[("A", "1.6")];
    fn run(&self, values: &[f64]) -> Result<UpperPosition, SceneError> {
        Ok(kapitza::upper_position(&kapitza::UpperPositionSettings {
            params: crate::models::kapitza::Params::from_values(values),
            periods: self.periods,
            chart_eps: self.chart_eps,
            chart_a: self.chart_a,
            chart_a_max: self.chart_a_max,
            method: method(Self::ANALYSIS, "dop853", self.tol)?,
        })?)
    }
}

impl Outputs for UpperPosition {
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
        Some(&crate::models::kapitza::INFO)
    }
    const PARAMETERS: &'static [(&'static str, &'static str)] =
        &[("A", "1.5"), ("eps", "0.7"), ("mu", "0.4")];
    fn run(&self, values: &[f64]) -> Result<kapitza::Attractor, SceneError> {
        Ok(kapitza::attractor(&kapitza::AttractorSettings {
            params: crate::models::kapitza::Params::from_values(values),
            points: self.points,
            transient: self.transient,
            lyapunov_periods: self.lyapunov_periods,
            zoom: self.zoom,
            method: method(Self::ANALYSIS, &self.method, self.tol)?,
        })?)
    }
}

impl Outputs for kapitza::Attractor {
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

declare_settings! {
    /// Theorem 2 on the double pendulum with a vibrating base: the exact
    /// system at large ν and the limiting system from the same (q, p), for
    /// each amplitude and start: coordinates, deviations (of order 1/ν) and
    /// velocities (which converge only weakly).
    pub struct DoublePendulumAveraging for "double_pendulum_averaging" {
        /// Values of a, one row of cases each.
        amplitudes: Vec<f64> = vec![2.5, 5.0], Range::NonNegative;
        /// (φ1(0), φ2(0)) of each initial state, p(0) = 0.
        starts: Vec<[f64; 2]> = vec![[0.2, -0.1], [0.5, 0.3]], Range::Any;
        /// Observation time.
        t_end: f64 = 10.0, Range::Positive;
        /// The integration method.
        method: String = "dop853".into(), Range::OneOf(METHODS);
        /// Its tolerance (taylor, dop853, radau5) or step size.
        tol: f64 = 1e-10, Range::Positive;
    }
}

impl Study for DoublePendulumAveraging {
    type Outcome = dp::AveragingCases;
    fn model() -> Option<&'static ModelInfo> {
        Some(&crate::models::double_pendulum::INFO)
    }
    const PARAMETERS: &'static [(&'static str, &'static str)] = &[("nu", "1000")];
    fn run(&self, values: &[f64]) -> Result<dp::AveragingCases, SceneError> {
        Ok(dp::averaging_cases(&dp::AveragingSettings {
            params: dp::study_params(values)?,
            amplitudes: self.amplitudes.clone(),
            starts: self.starts.clone(),
            t_end: self.t_end,
            method: method(Self::ANALYSIS, &self.method, self.tol)?,
        })?)
    }
}

impl Outputs for dp::AveragingCases {
    fn figures(&self) -> Vec<(String, Figure)> {
        vec![named("averaging.png", self.figure())]
    }
    fn tables(&self) -> Vec<Table> {
        let header = [
            "case",
            "t",
            "phi1_exact",
            "phi2_exact",
            "phi1_limit",
            "phi2_limit",
            "v1_exact",
            "v2_exact",
            "v1_limit",
            "v2_limit",
        ];
        vec![Table::new("series.csv", &header, self.rows())]
    }
    fn lines(&self) -> Vec<String> {
        self.cases.iter().map(|c| format!("{c:?}")).collect()
    }
}

declare_settings! {
    /// The equilibria of the double pendulum with a vibrating base,
    /// criterion (11) and the thresholds a*, long runs of the limiting
    /// system either side of a*, and the exact stability window.
    pub struct DoublePendulumStabilization for "double_pendulum_stabilization" {
        /// Initial distance of the long runs from the equilibrium (both angles).
        offset: f64 = 0.05, Range::Any;
        /// Length of the long runs of the limiting system.
        t_long: f64 = 300.0, Range::Positive;
        /// The long runs use a = (1 ± margin) a*.
        margin: f64 = 0.1, Range::Positive;
        /// The exact window is searched for a up to this × a*.
        a_max_factor: f64 = 30.0, Range::Positive;
        /// Amplitudes sampled for the exact spectral-radius chart.
        chart_points: usize = 150, Range::Count { min: 2, max: 1_000_000 };
        /// The integration method.
        method: String = "dop853".into(), Range::OneOf(METHODS);
        /// Its tolerance (taylor, dop853, radau5) or step size.
        tol: f64 = 1e-10, Range::Positive;
    }
}

impl Study for DoublePendulumStabilization {
    type Outcome = dp::EquilibriaStabilization;
    fn model() -> Option<&'static ModelInfo> {
        Some(&crate::models::double_pendulum::INFO)
    }
    fn run(&self, values: &[f64]) -> Result<dp::EquilibriaStabilization, SceneError> {
        let progress = Progress::new("equilibria", EQUILIBRIA.len());
        let settings = dp::StabilizationSettings {
            params: dp::study_params(values)?,
            offset: self.offset,
            t_long: self.t_long,
            margin: self.margin,
            a_max_factor: self.a_max_factor,
            chart_points: self.chart_points,
            method: method(Self::ANALYSIS, &self.method, self.tol)?,
        };
        Ok(dp::stabilization_study(&settings, &|done| {
            progress.update(done)
        })?)
    }
}

impl Outputs for dp::EquilibriaStabilization {
    fn figures(&self) -> Vec<(String, Figure)> {
        vec![named("stabilization.png", self.figure())]
    }
    fn tables(&self) -> Vec<Table> {
        let header = ["panel", "a", "spectral_radius"];
        vec![Table::new(
            "exact_spectral_radius.csv",
            &header,
            self.chart_rows(),
        )]
    }
    fn lines(&self) -> Vec<String> {
        self.equilibria
            .iter()
            .map(|e| {
                format!(
                    "({}, {}): λ = {:?}, stable without vibration: {}, a* = {:?} {}, exact window at ν = {}: {:?}",
                    e.phi1, e.phi2, e.lambdas, e.stable_without_vibration, e.a_star,
                    e.a_star_formula.as_deref().unwrap_or(""), self.nu, e.exact_window
                )
            })
            .collect()
    }
}

declare_settings! {
    /// Theorem 3 with viscous friction Q1 = −μ φ1', Q2 = −μ(φ2' − φ1'):
    /// above a* the stabilised equilibrium of the limiting system is
    /// asymptotically stable; a perturbation decaying in both systems, and
    /// the exact Floquet multipliers against the averaged eigenvalues.
    pub struct DoublePendulumFriction for "double_pendulum_friction" {
        /// The equilibrium (φ1, φ2), each 0 or π.
        equilibrium: [f64; 2] = [0.0, 0.0], Range::Any;
        /// Initial perturbation of both angles.
        offset: f64 = 0.1, Range::Any;
        /// Length of the decay runs.
        t_end: f64 = 150.0, Range::Positive;
        /// Frequencies for the exact multipliers.
        nus: Vec<f64> = vec![50.0, 100.0, 200.0, 400.0, 800.0, 1600.0], Range::Positive;
        /// DOP853 tolerance.
        tol: f64 = 1e-11, Range::Positive;
    }
}

impl Study for DoublePendulumFriction {
    type Outcome = dp::Friction;
    fn model() -> Option<&'static ModelInfo> {
        Some(&crate::models::double_pendulum::INFO)
    }
    const PARAMETERS: &'static [(&'static str, &'static str)] = &[("mu", "0.3")];
    fn run(&self, values: &[f64]) -> Result<dp::Friction, SceneError> {
        Ok(dp::friction(&dp::FrictionSettings {
            params: dp::study_params(values)?,
            equilibrium: (self.equilibrium[0], self.equilibrium[1]),
            offset: self.offset,
            t_end: self.t_end,
            nus: self.nus.clone(),
            method: method(Self::ANALYSIS, "dop853", self.tol)?,
        })?)
    }
}

impl Outputs for dp::Friction {
    fn figures(&self) -> Vec<(String, Figure)> {
        vec![named("friction.png", self.figure())]
    }
    fn tables(&self) -> Vec<Table> {
        let rows = self
            .exact
            .iter()
            .map(|r| (r.nu, r.spectral_radius, r.predicted));
        let decay = self
            .exact_decay
            .iter()
            .zip(&self.limit_decay)
            .map(|(e, l)| (e.0, e.1, l.1));
        vec![
            Table::new(
                "multipliers.csv",
                &["nu", "spectral_radius", "predicted"],
                rows,
            ),
            Table::new(
                "decay.csv",
                &["t", "distance_exact", "distance_limit"],
                decay,
            ),
        ]
    }
    fn lines(&self) -> Vec<String> {
        let mut lines = vec![format!(
            "averaged eigenvalues {:?}, max Re λ = {:.6}",
            self.averaged_eigenvalues, self.max_real_part
        )];
        if self.max_real_part >= 0.0 {
            lines.push(format!(
                "note: max Re λ ≥ 0: not asymptotically stable at a = {} (raise a or μ)",
                self.a
            ));
        }
        lines.extend(self.exact.iter().map(|r| {
            format!(
                "ν = {}: exact spectral radius {:.9}, averaged prediction {:.9}",
                r.nu, r.spectral_radius, r.predicted
            )
        }));
        lines
    }
}

declare_settings! {
    /// Φ(R) of the sliding rod: every graph class, its region in the
    /// friction coefficients, and the roots for the given parameters.
    pub struct PainlevePhi for "painleve_phi" {
        /// Resolution of the region plots.
        region_pixels: usize = 120, Range::Count { min: 2, max: 4000 };
    }
}

impl Study for PainlevePhi {
    type Outcome = graphs::PhiGraphs;
    fn model() -> Option<&'static ModelInfo> {
        Some(&crate::models::painleve_klein::INFO)
    }
    fn run(&self, values: &[f64]) -> Result<graphs::PhiGraphs, SceneError> {
        Ok(graphs::phi_graphs(
            &painleve::study_params(values)?,
            self.region_pixels,
        ))
    }
}

impl Outputs for graphs::PhiGraphs {
    fn figures(&self) -> Vec<(String, Figure)> {
        vec![named("phi.png", self.figure())]
    }
    fn tables(&self) -> Vec<Table> {
        let header = ["sigma_o", "mu1_star", "mu2_star", "signs"];
        vec![Table::new("regions.csv", &header, &self.regions)]
    }
    fn lines(&self) -> Vec<String> {
        let classes = self
            .examples
            .iter()
            .zip(self.classes)
            .map(|((_, roots), class)| {
                format!(
                    "class {}: {}; {} (example: {} roots)",
                    class.signs,
                    class.region,
                    class.roots,
                    roots.len()
                )
            });
        let given = self.given.iter().map(|g| {
            format!(
                "given parameters, σ = {:+}: slopes {}, X* = {:.6}, roots {:?} (Φ' > 0: {:?}): {}",
                g.sigma, g.signs, self.reduced.x_star, g.roots, g.rising, g.case
            )
        });
        classes.chain(given).collect()
    }
}

declare_settings! {
    /// The deformation equation (25) of the sliding rod,
    /// δ'' = cos²φ0 (X* − Φ(R)), R = k ε⁻² δ + ν ε⁻¹ δ': its equilibria and
    /// their eigenvalues, and phase portraits on (δ, δ') for an example of
    /// each graph class and for the given parameters.
    pub struct PainleveDelta for "painleve_delta" {
        /// Sliding direction σ = ±1 for the given parameters.
        sigma: f64 = 1.0, Range::Any;
        /// Initial points per side of the portrait grid.
        starts: usize = 7, Range::Count { min: 1, max: 1000 };
        /// Length of each trajectory, in units of ε.
        t_end: f64 = 3.0, Range::Positive;
    }
}

impl Study for PainleveDelta {
    type Outcome = deformation::Deformation;
    fn model() -> Option<&'static ModelInfo> {
        Some(&crate::models::painleve_klein::INFO)
    }
    fn run(&self, values: &[f64]) -> Result<deformation::Deformation, SceneError> {
        let sigma = if self.sigma >= 0.0 { 1.0 } else { -1.0 };
        let params = painleve::study_params(values)?;
        Ok(deformation::deformation(
            &params,
            sigma,
            self.starts,
            self.t_end,
        )?)
    }
}

impl Outputs for deformation::Deformation {
    fn figures(&self) -> Vec<(String, Figure)> {
        vec![named("portraits.png", self.figure())]
    }
    fn lines(&self) -> Vec<String> {
        let mut lines = Vec::new();
        for case in &self.cases {
            lines.push(format!("{}: X* = {:.4}", case.case, case.x_star));
            lines.extend(case.equilibria.iter().map(|e| {
                format!(
                    "  R* = {:.6}, δ* = {:.6}, Φ' = {:+.3}, eigenvalues {:?}, asymptotically stable: {}",
                    e.root, e.delta, e.slope, e.eigenvalues, e.asymptotically_stable
                )
            }));
        }
        lines
    }
}

declare_settings! {
    /// The sliding rod's worked example: stick–slip switching, friction
    /// impact, and the event table.
    pub struct PainleveKleinImpact for "painleve_klein_impact" {
        /// x2(0) of each case (x1 = 0, x1' = x2' = 10).
        x2_starts: Vec<f64> = vec![-0.65, -0.78], Range::Any;
        /// End time (a case at rest ends earlier).
        t_end: f64 = 4.0, Range::Positive;
        /// Samples per case for the figures.
        samples: usize = 4000, Range::Count { min: 2, max: 10_000_000 };
        /// The integration method.
        method: String = "dop853".into(), Range::OneOf(METHODS);
        /// Its tolerance (taylor, dop853, radau5) or step size.
        tol: f64 = 1e-10, Range::Positive;
    }
}

impl Study for PainleveKleinImpact {
    type Outcome = impact::Impact;
    fn model() -> Option<&'static ModelInfo> {
        Some(&crate::models::painleve_klein::INFO)
    }
    fn run(&self, values: &[f64]) -> Result<impact::Impact, SceneError> {
        Ok(impact::impact(&impact::ImpactSettings {
            params: painleve::study_params(values)?,
            x2_starts: self.x2_starts.clone(),
            t_end: self.t_end,
            method: method(Self::ANALYSIS, &self.method, self.tol)?,
            samples: self.samples,
        })?)
    }
}

impl Outputs for impact::Impact {
    fn figures(&self) -> Vec<(String, Figure)> {
        vec![named("impact.png", self.figure())]
    }
    fn tables(&self) -> Vec<Table> {
        let events = ["x2_0", "t", "point", "case", "from", "to", "v1", "v2", "R"];
        let series = [
            "x2_0",
            "t",
            "x1",
            "x2",
            "v1",
            "v2",
            "delta",
            "delta_rate",
            "R",
        ];
        vec![
            Table::new("events.csv", &events, self.event_rows()),
            Table::new("series.csv", &series, self.series_rows()),
        ]
    }
    fn lines(&self) -> Vec<String> {
        let mut lines = Vec::new();
        for c in &self.cases {
            lines.push(format!(
                "x2(0) = {}: δ(0) = {:.4}; {} switches, {} phases, {} steps; {} at t = {:.6}, accelerations {:?}",
                c.x2_0, c.delta_0, c.events.len(), c.phases, c.steps, c.r#final, c.t_end, c.acceleration
            ));
            lines.extend(c.events.iter().map(|e| {
                format!(
                    "  t = {:.6}  point {}  case {:>2}  {} -> {}  v1 = {:+.6}  v2 = {:+.6}  R = {:.6}",
                    e.t, e.point, e.case, e.from, e.to, e.v1, e.v2, e.R
                )
            }));
        }
        lines
    }
}

declare_settings! {
    /// The sliding rod's worked example as ε → 0: R(t) → R*, the friction
    /// impact sharpening, event times and cost.
    pub struct PainleveStiffLimit for "painleve_stiff_limit" {
        /// Values of ε.
        eps_values: Vec<f64> = vec![0.1, 0.03, 0.01, 0.001], Range::Positive;
        /// x2(0) of the regular case at ε = 0.1.
        x2_regular: f64 = -0.65, Range::Any;
        /// x2(0) of the impact case at ε = 0.1.
        x2_impact: f64 = -0.78, Range::Any;
        /// End time.
        t_end: f64 = 2.0, Range::Positive;
        /// The integration method.
        method: String = "radau5".into(), Range::OneOf(METHODS);
        /// Its tolerance (taylor, dop853, radau5) or step size.
        tol: f64 = 1e-8, Range::Positive;
    }
}

impl Study for PainleveStiffLimit {
    type Outcome = stiff_limit::StiffLimit;
    fn model() -> Option<&'static ModelInfo> {
        None
    }
    fn run(&self, _: &[f64]) -> Result<stiff_limit::StiffLimit, SceneError> {
        Ok(stiff_limit::stiff_limit(
            &stiff_limit::StiffLimitSettings {
                eps_values: self.eps_values.clone(),
                x2_regular: self.x2_regular,
                x2_impact: self.x2_impact,
                t_end: self.t_end,
                method: method(Self::ANALYSIS, &self.method, self.tol)?,
            },
        )?)
    }
}

impl Outputs for stiff_limit::StiffLimit {
    fn figures(&self) -> Vec<(String, Figure)> {
        vec![named("stiff_limit.png", self.figure())]
    }
    fn tables(&self) -> Vec<Table> {
        let header = [
            "case", "eps", "outcome", "t_end", "final_R", "steps", "f_evals", "seconds",
        ];
        vec![Table::new("runs.csv", &header, self.rows())]
    }
    fn lines(&self) -> Vec<String> {
        let mut lines = vec![format!(
            "rigid rod: stable root R* = {:?}",
            self.rigid_R_star
        )];
        lines.extend(self.runs.iter().map(|r| {
            let events: Vec<(f64, usize, &str)> =
                r.events.iter().map(|e| (e.t, e.point, e.case.as_str())).collect();
            format!(
                "{:8} ε = {:<6} {} at t = {:.6}, R = {:.6}, {} steps, {} f, {:.4} s, events {events:?}",
                r.case, r.eps, r.outcome, r.t_end, r.final_R, r.steps, r.f_evals, r.seconds
            )
        }));
        lines
    }
}

/// The study scenes' declarations (the book's reference lists them after
/// the analyses').
pub fn schemas() -> Vec<crate::settings::Schema> {
    use crate::analysis::standard_map::StandardMapOptions;
    use crate::settings::Schema;
    vec![
        Schema::of::<KapitzaPeriodMap>(),
        Schema::of::<KapitzaStability>(),
        Schema::of::<KapitzaAttractor>(),
        Schema::of::<StandardMapOptions>(),
        Schema::of::<DoublePendulumAveraging>(),
        Schema::of::<DoublePendulumStabilization>(),
        Schema::of::<DoublePendulumFriction>(),
        Schema::of::<PainlevePhi>(),
        Schema::of::<PainleveDelta>(),
        Schema::of::<PainleveKleinImpact>(),
        Schema::of::<PainleveStiffLimit>(),
    ]
}
