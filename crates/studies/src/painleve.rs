//! Study 3's scenes: the graphs of Φ, the deformation equation, the
//! worked example's impact, its stiff limit.

use super::{named, Written};
use mechlab::plot::Figure;
use mechlab::registry::ModelInfo;
use mechlab::scene::SceneError;
use mechlab::scenes::{Outputs, Study, Table};
use mechlab::settings::{method, Declared, Range, METHODS};
use mechlab::studies::painleve::{self, deformation, graphs, impact, stiff_limit};
use mechlab_runtime::declare_settings;

declare_settings! {
    /// Φ(R) of the sliding rod: every graph class, its region in the
    /// friction coefficients, and the roots for the given parameters.
    pub struct PainlevePhi for "painleve_phi" {
        /// Resolution of the region plots.
        region_pixels: usize = 120, Range::Count { min: 2, max: 4000 };
    }
}

impl Study for PainlevePhi {
    type Outcome = Written<graphs::PhiGraphs>;
    fn model() -> Option<&'static ModelInfo> {
        Some(painleve::info())
    }
    fn run(&self, values: &[f64]) -> Result<Self::Outcome, SceneError> {
        Ok(Written(graphs::phi_graphs(
            &painleve::study_params(values)?,
            self.region_pixels,
        )))
    }
}

impl Outputs for Written<graphs::PhiGraphs> {
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
    type Outcome = Written<deformation::Deformation>;
    fn model() -> Option<&'static ModelInfo> {
        Some(painleve::info())
    }
    fn run(&self, values: &[f64]) -> Result<Self::Outcome, SceneError> {
        let sigma = if self.sigma >= 0.0 { 1.0 } else { -1.0 };
        let params = painleve::study_params(values)?;
        Ok(Written(deformation::deformation(
            &params,
            sigma,
            self.starts,
            self.t_end,
        )?))
    }
}

impl Outputs for Written<deformation::Deformation> {
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
    type Outcome = Written<impact::Impact>;
    fn model() -> Option<&'static ModelInfo> {
        Some(painleve::info())
    }
    fn run(&self, values: &[f64]) -> Result<Self::Outcome, SceneError> {
        Ok(Written(impact::impact(&impact::ImpactSettings {
            params: painleve::study_params(values)?,
            x2_starts: self.x2_starts.clone(),
            t_end: self.t_end,
            method: method(Self::ANALYSIS, &self.method, self.tol)?,
            samples: self.samples,
        })?))
    }
}

impl Outputs for Written<impact::Impact> {
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
    type Outcome = Written<stiff_limit::StiffLimit>;
    fn model() -> Option<&'static ModelInfo> {
        None
    }
    fn run(&self, _: &[f64]) -> Result<Self::Outcome, SceneError> {
        Ok(Written(stiff_limit::stiff_limit(
            &stiff_limit::StiffLimitSettings {
                eps_values: self.eps_values.clone(),
                x2_regular: self.x2_regular,
                x2_impact: self.x2_impact,
                t_end: self.t_end,
                method: method(Self::ANALYSIS, &self.method, self.tol)?,
            },
        )?))
    }
}

impl Outputs for Written<stiff_limit::StiffLimit> {
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
