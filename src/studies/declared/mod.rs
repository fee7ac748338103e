//! The study scenes' declarations: each scene's settings written once
//! (name, default, range, help), how the scene runs on them, and what its
//! result writes (figures, tables, the headline lines). The scenes in
//! `examples/` are then one line each ([`crate::scenes::study_scene`]).
//! A module per study, each its own codegen unit, calling the studies
//! through functions that are not inlined: editing one study's model
//! recompiles that study's declarations only, and little of them.

mod double_pendulum;
mod kapitza;
mod painleve;

pub use double_pendulum::*;
pub use kapitza::*;
pub use painleve::*;

use crate::plot::Figure;

/// A figure with its file name.
fn named(file: &str, figure: Figure) -> (String, Figure) {
    (file.to_string(), figure)
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
