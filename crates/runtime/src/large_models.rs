//! Models of 4 to 24 degrees of freedom: their analyses are compiled in the
//! models package, at the sizes its model files have, instead of here for
//! every size (at sizes 5 to 8 they were half the runtime's compile time,
//! at size 4 about an eighth of what remained),
//! for sizes no model in `models/` needs.
//!
//! This module sits above the analyses and the registry: it names every
//! analysis's work once ([`LargeModel`] gets a method per work) and gives
//! the registry a type-erased [`LargeHandle`], so the registry imports no
//! analysis and the analyses import only the registry.

use crate::registry::{Erased, LargeHandleRef, LargeWork, WithFixed};

/// Declares the works that run on a model at its own size (each is a
/// [`WithFixed`] with one lifetime), once: [`LargeModel`] gets a method per
/// work, [`AtSize`] implements it, and each work [`LargeWork`] calling it.
macro_rules! large_works {
    ($($method:ident: $work:path => $output:ty;)*) => {
        /// The analyses of one model of 4 to 24 degrees of freedom, compiled
        /// in the models package for the sizes its model files have.
        pub trait LargeModel: Sync {
            $(fn $method(&self, work: $work) -> $output;)*
        }

        impl<const D: usize, const S: usize, const T: usize, const V: usize> LargeModel
            for AtSize<D, S, T, V>
        {
            $(fn $method(&self, work: $work) -> $output {
                work.run(self.0)
            })*
        }

        $(impl LargeWork for $work {
            fn on_large(self, model: LargeHandleRef) -> $output {
                LargeHandle::of(model).0.$method(self)
            }
        })*
    };
}

large_works! {
    explore: crate::explore::HamiltonianRuns<'_> => Result<crate::explore::Exploration, crate::explore::ExploreError>;
    stability: crate::analysis::stability::Analysis<'_> => Result<crate::analysis::stability::Stability, crate::analysis::stability::StabilityError>;
    at_equilibrium: crate::analysis::stability::AtEquilibrium<'_> => Result<crate::analysis::stability::EquilibriumStability, crate::analysis::stability::StabilityError>;
    stability_chart: crate::analysis::stability::Chart<'_> => Result<crate::analysis::stability::StabilityChart, crate::analysis::stability::StabilityError>;
}

/// A model of 4 to 24 degrees of freedom as a [`LargeModel`]: the models
/// package makes one per such model, which compiles the analyses there at
/// that size.
pub struct AtSize<const D: usize, const S: usize, const T: usize, const V: usize>(
    pub &'static Erased<D, S, T, V>,
);

/// What [`crate::registry::FixedSize::Large`] holds (as a
/// [`LargeHandleRef`]): the model's analyses at its size.
pub struct LargeHandle(pub &'static dyn LargeModel);

impl LargeHandle {
    /// The handle behind a registry's type-erased reference (the generated
    /// models make each one from a `LargeHandle`; anything else is a bug in
    /// the generated code).
    fn of(model: LargeHandleRef) -> &'static LargeHandle {
        model
            .downcast_ref::<LargeHandle>()
            .expect("FixedSize::Large holds a large_models::LargeHandle")
    }
}
