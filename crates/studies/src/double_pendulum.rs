//! Study 2's scenes: Theorem 2's cases, the equilibria's stabilisation,
//! Theorem 3 with friction.

use super::{named, Written};
use mechlab::plot::Figure;
use mechlab::registry::ModelInfo;
use mechlab::scene::{Progress, SceneError};
use mechlab::scenes::{Outputs, Study, Table};
use mechlab::settings::{method, Declared, Range, METHODS};
use mechlab::studies::double_pendulum::{self as dp, EQUILIBRIA};
use mechlab_runtime::declare_settings;

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
    type Outcome = Written<dp::AveragingCases>;
    fn model() -> Option<&'static ModelInfo> {
        Some(dp::info())
    }
    const PARAMETERS: &'static [(&'static str, &'static str)] = &[("nu", "1000")];
    fn run(&self, values: &[f64]) -> Result<Self::Outcome, SceneError> {
        Ok(Written(dp::averaging_cases(&dp::AveragingSettings {
            params: dp::study_params(values)?,
            amplitudes: self.amplitudes.clone(),
            starts: self.starts.clone(),
            t_end: self.t_end,
            method: method(Self::ANALYSIS, &self.method, self.tol)?,
        })?))
    }
}

impl Outputs for Written<dp::AveragingCases> {
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
    type Outcome = Written<dp::EquilibriaStabilization>;
    fn model() -> Option<&'static ModelInfo> {
        Some(dp::info())
    }
    fn run(&self, values: &[f64]) -> Result<Self::Outcome, SceneError> {
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
        Ok(Written(dp::stabilization_study(&settings, &|done| {
            progress.update(done)
        })?))
    }
}

impl Outputs for Written<dp::EquilibriaStabilization> {
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
    type Outcome = Written<dp::Friction>;
    fn model() -> Option<&'static ModelInfo> {
        Some(dp::info())
    }
    const PARAMETERS: &'static [(&'static str, &'static str)] = &[("mu", "0.3")];
    fn run(&self, values: &[f64]) -> Result<Self::Outcome, SceneError> {
        Ok(Written(dp::friction(&dp::FrictionSettings {
            params: dp::study_params(values)?,
            equilibrium: (self.equilibrium[0], self.equilibrium[1]),
            offset: self.offset,
            t_end: self.t_end,
            nus: self.nus.clone(),
            method: method(Self::ANALYSIS, "dop853", self.tol)?,
        })?))
    }
}

impl Outputs for Written<dp::Friction> {
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
