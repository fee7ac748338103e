//! The study scenes' declarations: each scene's settings written once
//! (name, default, range, help), how the scene runs on them, and what its
//! result writes (figures, tables, the headline lines). The scenes in
//! `examples/` are then one line each ([`mechlab::scenes::study_scene`]).
//! A package of its own above the generated models: editing a model
//! recompiles the `mechlab` package, and none of this.

mod double_pendulum;
mod kapitza;
mod painleve;

pub use double_pendulum::*;
pub use kapitza::*;
pub use painleve::*;

use mechlab::plot::Figure;

/// A study's result as its scene writes it (the results are the studies'
/// types, in the `mechlab` package; what they write is said here, so that
/// a model edit, which recompiles that package, does not compile it).
#[derive(serde::Serialize)]
#[serde(transparent)]
pub struct Written<T>(pub T);

impl<T> std::ops::Deref for Written<T> {
    type Target = T;
    fn deref(&self) -> &T {
        &self.0
    }
}

/// A figure with its file name.
fn named(file: &str, figure: Figure) -> (String, Figure) {
    (file.to_string(), figure)
}

/// The study scenes' declarations (the book's reference lists them after
/// the analyses').
pub fn schemas() -> Vec<mechlab::settings::Schema> {
    use mechlab::analysis::standard_map::StandardMapOptions;
    use mechlab::settings::Schema;
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
