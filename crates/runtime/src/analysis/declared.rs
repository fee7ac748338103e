//! Every declared analysis behind one call: [`Analysis::run`] takes the
//! declared settings, resolves what is `auto` from the model and runs the
//! analysis. The scenes, the studio and Python call it alike, so the same
//! settings give the same numbers whichever door they came through.

use crate::analysis::attractor::{attractor, AttractorError, AttractorOptions};
use crate::analysis::averaging::{convergence, AveragingError, AveragingOptions};
use crate::analysis::basins::{basins, BasinsError, BasinsOptions};
use crate::analysis::chaos_map::{chaos_map, ChaosMapOptions};
use crate::analysis::continuation::{continuation, ContinuationError, ContinuationOptions};
use crate::analysis::on_constraints::steady::study::{
    steady_study, SteadyError, SteadyMotionOptions,
};
use crate::analysis::on_constraints::vibration::{linkage, LinkageOptions, VibrationError};
use crate::analysis::period_map::{portrait, PeriodMapError, PeriodMapOptions};
use crate::analysis::section::{section_study, SectionError, SectionOptions};
use crate::analysis::separatrix::{separatrix_splitting, SplittingError, SplittingOptions};
use crate::analysis::stability::{stability, StabilityError, StabilityOptions};
use crate::analysis::Refusal;
use crate::classify::{Classify, ErrorClass};
use crate::domain::{explain, OutsideDomain};
use crate::explore::{explore, ExploreError, ExploreOptions};
use crate::registry::Model;
use crate::settings::{Declared, SettingError};

/// Progress of a run: `progress(k)` after `k` more units of its work (rows
/// of a map, starts of the basins); `false` asks it to stop between blocks.
pub type Progress<'a> = &'a (dyn Fn(usize) -> bool + Sync);

/// A progress that counts nothing and never stops.
pub fn no_progress(_: usize) -> bool {
    true
}

/// A declared analysis: its settings ([`Declared`]), what it returns, and
/// its run on a model.
pub trait Analysis: Declared + Send + Sync {
    type Output: Send;
    /// The units `progress` counts in a run of these settings (0: it
    /// reports none).
    fn work(&self) -> usize {
        0
    }
    /// Runs on `model` at the parameter `values`.
    fn run(
        &self,
        model: &'static Model,
        values: &[f64],
        progress: Progress,
    ) -> Result<Self::Output, AnalysisError>;
}

/// Why a declared analysis did not give its result.
#[derive(Debug, thiserror::Error)]
pub enum AnalysisError {
    #[error(transparent)]
    Setting(#[from] SettingError),
    #[error(transparent)]
    Refusal(#[from] Refusal),
    #[error(transparent)]
    Basins(#[from] BasinsError),
    #[error(transparent)]
    Continuation(#[from] ContinuationError),
    #[error(transparent)]
    Splitting(#[from] SplittingError),
    #[error(transparent)]
    Section(#[from] SectionError),
    #[error(transparent)]
    Stability(#[from] StabilityError),
    #[error(transparent)]
    Vibration(#[from] VibrationError),
    #[error(transparent)]
    Steady(#[from] SteadyError),
    #[error(transparent)]
    Attractor(#[from] AttractorError),
    #[error(transparent)]
    Averaging(#[from] AveragingError),
    #[error(transparent)]
    PeriodMap(#[from] PeriodMapError),
    #[error(transparent)]
    Explore(#[from] ExploreError),
    /// A run left the model's domain: the analysis's error, then the model
    /// file's expression that stopped being real and where.
    #[error("{source}\n{domain}")]
    OutsideDomain {
        source: Box<AnalysisError>,
        domain: Box<OutsideDomain>,
    },
}

impl AnalysisError {
    /// This error, with the model file's expression named where one of its
    /// runs left the model's domain (see [`crate::domain`]).
    pub fn located(self, model: &Model, values: &[f64]) -> AnalysisError {
        match self
            .integration_stop()
            .and_then(|stop| explain(model, values, stop))
        {
            Some(domain) => AnalysisError::OutsideDomain {
                source: Box::new(self),
                domain: Box::new(domain),
            },
            None => self,
        }
    }
}

impl Classify for AnalysisError {
    fn class(&self) -> ErrorClass {
        match self {
            AnalysisError::Setting(e) => e.class(),
            AnalysisError::Refusal(e) => e.class(),
            AnalysisError::Basins(e) => e.class(),
            AnalysisError::Continuation(e) => e.class(),
            AnalysisError::Splitting(e) => e.class(),
            AnalysisError::Section(e) => e.class(),
            AnalysisError::Stability(e) => e.class(),
            AnalysisError::Vibration(e) => e.class(),
            AnalysisError::Steady(e) => e.class(),
            AnalysisError::Attractor(e) => e.class(),
            AnalysisError::Averaging(e) => e.class(),
            AnalysisError::PeriodMap(e) => e.class(),
            AnalysisError::Explore(e) => e.class(),
            AnalysisError::OutsideDomain { .. } => ErrorClass::Integration,
        }
    }
    fn integration_stop(&self) -> Option<&crate::ode::OdeError> {
        match self {
            AnalysisError::Setting(_) | AnalysisError::Refusal(_) => None,
            AnalysisError::Basins(e) => e.integration_stop(),
            AnalysisError::Continuation(e) => e.integration_stop(),
            AnalysisError::Splitting(e) => e.integration_stop(),
            AnalysisError::Section(e) => e.integration_stop(),
            AnalysisError::Stability(e) => e.integration_stop(),
            AnalysisError::Vibration(e) => e.integration_stop(),
            AnalysisError::Steady(e) => e.integration_stop(),
            AnalysisError::Attractor(e) => e.integration_stop(),
            AnalysisError::Averaging(e) => e.integration_stop(),
            AnalysisError::PeriodMap(e) => e.integration_stop(),
            AnalysisError::Explore(e) => e.integration_stop(),
            AnalysisError::OutsideDomain { source, .. } => source.integration_stop(),
        }
    }
}

impl Analysis for ChaosMapOptions {
    type Output = crate::analysis::chaos_map::ChaosMap;
    fn work(&self) -> usize {
        self.pixels
    }
    fn run(
        &self,
        model: &'static Model,
        values: &[f64],
        progress: Progress,
    ) -> Result<Self::Output, AnalysisError> {
        Ok(chaos_map(model, values, &self.resolve(model)?, &|| {
            progress(1)
        })?)
    }
}

impl Analysis for BasinsOptions {
    type Output = crate::analysis::basins::Basins;
    fn work(&self) -> usize {
        self.pixels * self.pixels
    }
    fn run(
        &self,
        model: &'static Model,
        values: &[f64],
        progress: Progress,
    ) -> Result<Self::Output, AnalysisError> {
        Ok(basins(model, values, &self.resolve(model)?, &|k| {
            progress(k);
        })?)
    }
}

impl Analysis for LinkageOptions {
    type Output = crate::analysis::on_constraints::vibration::Linkage;
    fn run(
        &self,
        model: &'static Model,
        values: &[f64],
        _: Progress,
    ) -> Result<Self::Output, AnalysisError> {
        let Some(constrained) = model.constrained else {
            return Err(Refusal::Setting {
                model: model.info.name.into(),
                requirement: "linkage runs on a model with [[constraints]] in its file (`stability` on the others)",
            }
            .into());
        };
        Ok(linkage(constrained, values, self)?)
    }
}

impl Analysis for ExploreOptions {
    type Output = crate::explore::Exploration;
    fn run(
        &self,
        model: &'static Model,
        values: &[f64],
        _: Progress,
    ) -> Result<Self::Output, AnalysisError> {
        let (settings, y0) = self.resolve(model)?;
        Ok(explore(model, values, &y0, &settings)?)
    }
}

/// Analyses that report no progress: their output and the call that
/// runs them (`options`, `model` and `values` in scope).
macro_rules! without_progress {
    ($($options:ty => $output:ty: |$o:ident, $model:ident, $values:ident| $run:expr;)+) => {$(
        impl Analysis for $options {
            type Output = $output;
            fn run(
                &self,
                $model: &'static Model,
                $values: &[f64],
                _: Progress,
            ) -> Result<Self::Output, AnalysisError> {
                let $o = self;
                Ok($run?)
            }
        }
    )+};
}

without_progress! {
    ContinuationOptions => crate::analysis::continuation::Continuation: |o, model, values| continuation(model, values, &o.resolve(model, values)?);
    SplittingOptions => crate::analysis::separatrix::Splitting: |o, model, values| separatrix_splitting(model, values, &o.resolve()?);
    SectionOptions => crate::analysis::section::SectionStudy: |o, model, values| section_study(model, values, o, &|_| ());
    StabilityOptions => crate::analysis::stability::Stability: |o, model, values| stability(model, values, &o.resolve(model)?);
    AttractorOptions => crate::analysis::attractor::Attractor: |o, model, values| attractor(model, values, &o.resolve()?);
    AveragingOptions => crate::analysis::averaging::AveragingConvergence: |o, model, values| convergence(model, values, &o.resolve()?);
    PeriodMapOptions => crate::analysis::period_map::Portrait: |o, model, values| portrait(model, values, &o.resolve(model)?);
    SteadyMotionOptions => crate::analysis::on_constraints::steady::study::SteadyStudy: |o, model, values| steady_study(model, values, o);
}
