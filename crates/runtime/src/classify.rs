//! One classification of the library's errors, which every front end maps
//! from: the scenes print the message, the studio answers with a status
//! (a bad value 400, a refusal or an integration failure 422), and Python
//! raises `ValueError`, `mechlab.Refused`, `mechlab.IntegrationError` or
//! `KeyboardInterrupt`.

use crate::analysis::attractor::AttractorError;
use crate::analysis::averaging::AveragingError;
use crate::analysis::basins::BasinsError;
use crate::analysis::continuation::ContinuationError;
use crate::analysis::mechanism::MechanismError;
use crate::analysis::on_constraints::steady::{study::SteadyError, SteadyMotionError};
use crate::analysis::on_constraints::vibration::VibrationError;
use crate::analysis::period_map::PeriodMapError;
use crate::analysis::section::SectionError;
use crate::analysis::separatrix::SplittingError;
use crate::analysis::stability::StabilityError;
use crate::analysis::states::StatesError;
use crate::analysis::Refusal;
use crate::explore::ExploreError;
use crate::ode::OdeError;
use crate::registry::{ParameterError, UnknownModel};
use crate::settings::SettingError;

/// What kind of failure an error is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ErrorClass {
    /// A value the user gave is wrong (a setting, a parameter, a state of
    /// the wrong length, a model name): the message names it.
    BadValue,
    /// The analysis does not apply to this model; the message says why and
    /// what does.
    Refused,
    /// The numerics could not follow the model (an orbit that leaves its
    /// domain, Newton that does not converge).
    Integration,
    /// Stopped on request (Ctrl-C, a page that no longer listens).
    Stopped,
}

/// An error of the library with its class.
pub trait Classify: std::error::Error {
    fn class(&self) -> ErrorClass;
    /// The integration's stop behind this error, if one is (a non-finite
    /// step, a collapsed one): where [`crate::domain::explain`] looks for
    /// the model's expression that stopped being real.
    fn integration_stop(&self) -> Option<&OdeError> {
        None
    }
}

use ErrorClass::{BadValue, Integration, Stopped};

impl Classify for Refusal {
    fn class(&self) -> ErrorClass {
        match self {
            Refusal::Parameter(_)
            | Refusal::ParameterCount { .. }
            | Refusal::StateLength { .. }
            | Refusal::Setting { .. }
            | Refusal::BelowPrecision { .. } => BadValue,
            _ => ErrorClass::Refused,
        }
    }
}

impl Classify for OdeError {
    fn class(&self) -> ErrorClass {
        match self {
            OdeError::UnknownMethod(_)
            | OdeError::InvalidSetting { .. }
            | OdeError::BelowPrecision { .. }
            | OdeError::NonFiniteInitialState { .. }
            | OdeError::StateLength { .. }
            | OdeError::TooLarge(_) => BadValue,
            OdeError::Stopped { .. } => Stopped,
            _ => Integration,
        }
    }
    fn integration_stop(&self) -> Option<&OdeError> {
        Some(self)
    }
}

/// Errors that are always a bad value.
macro_rules! bad_value {
    ($($error:ty),*) => {$(
        impl Classify for $error {
            fn class(&self) -> ErrorClass {
                BadValue
            }
        }
    )*};
}
bad_value!(ParameterError, SettingError, UnknownModel);

impl Classify for StatesError {
    fn class(&self) -> ErrorClass {
        match self {
            StatesError::Refused(r) => r.class(),
            StatesError::Ode(e) => e.class(),
            StatesError::Constrained(_) => Integration,
            _ => BadValue,
        }
    }
    fn integration_stop(&self) -> Option<&OdeError> {
        match self {
            StatesError::Ode(e) => Some(e),
            _ => None,
        }
    }
}

impl Classify for PeriodMapError {
    fn class(&self) -> ErrorClass {
        match self {
            PeriodMapError::Refused(r) => r.class(),
            PeriodMapError::Cancelled => Stopped,
            PeriodMapError::Ode(e) => e.class(),
            _ => BadValue,
        }
    }
    fn integration_stop(&self) -> Option<&OdeError> {
        match self {
            PeriodMapError::Ode(e) => Some(e),
            _ => None,
        }
    }
}

impl Classify for StabilityError {
    fn class(&self) -> ErrorClass {
        match self {
            StabilityError::Refused(r) => r.class(),
            StabilityError::Ode(e) => e.class(),
            _ => BadValue,
        }
    }
    fn integration_stop(&self) -> Option<&OdeError> {
        match self {
            StabilityError::Ode(e) => Some(e),
            _ => None,
        }
    }
}

impl Classify for SectionError {
    fn class(&self) -> ErrorClass {
        match self {
            SectionError::Refused(r) => r.class(),
            SectionError::Method(e) => e.class(),
            _ => BadValue,
        }
    }
    fn integration_stop(&self) -> Option<&OdeError> {
        match self {
            SectionError::Method(e) => Some(e),
            _ => None,
        }
    }
}

impl Classify for BasinsError {
    fn class(&self) -> ErrorClass {
        match self {
            BasinsError::Refused(r) => r.class(),
            BasinsError::Ode(e) => e.class(),
            _ => BadValue,
        }
    }
    fn integration_stop(&self) -> Option<&OdeError> {
        match self {
            BasinsError::Ode(e) => Some(e),
            _ => None,
        }
    }
}

impl Classify for VibrationError {
    fn class(&self) -> ErrorClass {
        match self {
            VibrationError::Setting(e) => e.class(),
            VibrationError::Refused(r) => r.class(),
            VibrationError::Ode(e) => e.class(),
            _ => Integration,
        }
    }
    fn integration_stop(&self) -> Option<&OdeError> {
        match self {
            VibrationError::Ode(e) => Some(e),
            _ => None,
        }
    }
}

impl Classify for SteadyError {
    fn class(&self) -> ErrorClass {
        match self {
            SteadyError::Setting(_) | SteadyError::Motion(SteadyMotionError::Setting { .. }) => {
                BadValue
            }
            SteadyError::Motion(SteadyMotionError::Ode(e)) => e.class(),
            SteadyError::Refused(r) => r.class(),
            SteadyError::Motion(_) | SteadyError::NoSpeed { .. } | SteadyError::NoCyclic { .. } => {
                ErrorClass::Refused
            }
        }
    }
    fn integration_stop(&self) -> Option<&OdeError> {
        match self {
            SteadyError::Motion(SteadyMotionError::Ode(e)) => Some(e),
            _ => None,
        }
    }
}

impl Classify for AttractorError {
    fn class(&self) -> ErrorClass {
        match self {
            AttractorError::Refused(r) => r.class(),
            AttractorError::Ode(e) => e.class(),
            AttractorError::Constrained(_) => Integration,
            AttractorError::Setting(_) => BadValue,
        }
    }
    fn integration_stop(&self) -> Option<&OdeError> {
        match self {
            AttractorError::Ode(e) => Some(e),
            _ => None,
        }
    }
}

impl Classify for ContinuationError {
    fn class(&self) -> ErrorClass {
        match self {
            ContinuationError::Refused(r) => r.class(),
            ContinuationError::Ode(e) => e.class(),
            ContinuationError::Setting(_) => BadValue,
            _ => Integration,
        }
    }
    fn integration_stop(&self) -> Option<&OdeError> {
        match self {
            ContinuationError::Ode(e) => Some(e),
            _ => None,
        }
    }
}

impl Classify for SplittingError {
    fn class(&self) -> ErrorClass {
        match self {
            SplittingError::Refused(r) => r.class(),
            _ => Integration,
        }
    }
    fn integration_stop(&self) -> Option<&OdeError> {
        match self {
            SplittingError::Ode(e) => Some(e),
            _ => None,
        }
    }
}

impl Classify for AveragingError {
    fn class(&self) -> ErrorClass {
        match self {
            AveragingError::Refused(r) => r.class(),
            AveragingError::Sweep { .. } | AveragingError::Order(..) => BadValue,
            AveragingError::Dissipative { .. } => ErrorClass::Refused,
            AveragingError::Ode(e) => e.class(),
            _ => Integration,
        }
    }
    fn integration_stop(&self) -> Option<&OdeError> {
        match self {
            AveragingError::Ode(e) => Some(e),
            _ => None,
        }
    }
}

impl Classify for ExploreError {
    fn class(&self) -> ErrorClass {
        match self {
            ExploreError::Ode(e) => e.class(),
            ExploreError::StateLength { .. } => BadValue,
            _ => Integration,
        }
    }
    fn integration_stop(&self) -> Option<&OdeError> {
        match self {
            ExploreError::Ode(e) => Some(e),
            _ => None,
        }
    }
}

impl Classify for MechanismError {
    fn class(&self) -> ErrorClass {
        match self {
            MechanismError::Refused(r) => r.class(),
            MechanismError::NotDrawn { .. } => ErrorClass::Refused,
            MechanismError::Ode(e) => e.class(),
            _ => BadValue,
        }
    }
    fn integration_stop(&self) -> Option<&OdeError> {
        match self {
            MechanismError::Ode(e) => Some(e),
            _ => None,
        }
    }
}
