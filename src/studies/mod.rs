//! What the scenes of one study share: closed forms derived by hand (to test
//! the generated code against, and to print in reports) and the runs that
//! more than one scene makes.

pub mod double_pendulum;
pub mod painleve;
