//! The runs of the three studies' scenes, each returning a typed result
//! (the scene's summary, with the data its figures are drawn from), and the
//! closed forms derived by hand that the generated code is tested against.

pub mod double_pendulum;
pub mod kapitza;
pub mod painleve;

pub use mechlab_runtime::study::StudyError;
