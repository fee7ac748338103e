//! The scene of a declared study: its declaration's settings and its
//! model's parameters as knobs → one run → its figures, tables and
//! summary. A study (in `mechlab::studies`) is a declaration
//! ([`Declared`]) that says which model's parameters it takes and how it
//! runs ([`Study`]), and a result that says what it writes ([`Outputs`]);
//! its scene is then one line.

use crate::scene::{parameter_knobs, Knob, Scene, SceneError};
pub use mechlab_runtime::outputs::{Outputs, Table};
use mechlab_runtime::registry::ModelInfo;
use mechlab_runtime::settings::Declared;

/// A study: its declared settings, the model whose parameters it takes (with
/// the study's own defaults for some), and its run.
pub trait Study: Declared {
    type Outcome: Outputs;
    /// The model whose parameters are knobs of the scene, if any.
    fn model() -> Option<&'static ModelInfo>;
    /// The study's defaults for some of them (the model file's otherwise).
    const PARAMETERS: &'static [(&'static str, &'static str)] = &[];
    /// Runs on the model's parameter `values` (in its declaration order).
    fn run(&self, values: &[f64]) -> Result<Self::Outcome, SceneError>;
}

/// The scene of study `T`, named by its declaration: knobs from the
/// declaration and the model's parameters, one run, its files.
pub fn study_scene<T: Study>() -> Result<(), SceneError> {
    let mut knobs: Vec<Knob> = T::default()
        .declarations()
        .into_iter()
        .map(Knob::from_declaration)
        .collect();
    if let Some(model) = T::model() {
        knobs.extend(parameter_knobs(model, T::PARAMETERS));
    }
    let scene = Scene::from_args(T::ANALYSIS, &T::about(), &knobs)?;
    let options = T::default().with_texts(T::names().iter().map(|&n| (n, scene.text(n))))?;
    let values = match T::model() {
        Some(model) => scene.parameter_values(model)?,
        None => Vec::new(),
    };
    let outcome = options.run(&values)?;
    write_outputs(&scene, &outcome)
}

/// Prints a result's lines and writes its figures, texts and tables.
pub fn write_files<O: Outputs>(scene: &Scene, outcome: &O) -> Result<(), SceneError> {
    for line in outcome.lines() {
        println!("{line}");
    }
    for (file, figure) in outcome.figures() {
        scene.save_figure(&figure, &file)?;
    }
    for (file, text) in outcome.texts() {
        scene.write_text(&file, &text)?;
    }
    for table in outcome.tables() {
        scene.write_bytes(&table.file, &table.csv)?;
    }
    Ok(())
}

/// [`write_files`], then the result as `summary.json` (the scene's last
/// step: its files are published together).
pub fn write_outputs<O: Outputs>(scene: &Scene, outcome: &O) -> Result<(), SceneError> {
    write_files(scene, outcome)?;
    scene.write_summary(outcome)?;
    Ok(())
}

/// The standard map's study (declared and run in the library).
impl Study for mechlab_runtime::analysis::standard_map::StandardMapOptions {
    type Outcome = mechlab_runtime::analysis::standard_map::StandardMapStudy;
    fn model() -> Option<&'static ModelInfo> {
        None
    }
    fn run(&self, _: &[f64]) -> Result<Self::Outcome, SceneError> {
        Ok(mechlab_runtime::analysis::standard_map::standard_map_study(
            self,
        ))
    }
}
