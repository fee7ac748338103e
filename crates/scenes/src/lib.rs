//! mechlab's application layer, above the runtime: [`scene`] is the scene
//! framework (knobs from the command line, progress, figures with their
//! CSV and `summary.json` written together, the one root error
//! `SceneError`), and [`scenes`] the scene bodies that more than one
//! example runs (a chaos map, averaging, a period map, separatrix
//! splitting, an attractor, continuation, a section), each a few knobs,
//! one library call and its figures. The runtime below holds the
//! numerics and depends on no scene.

pub mod scene;
pub mod scenes;
pub mod study;
