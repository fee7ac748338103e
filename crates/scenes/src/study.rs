//! The scene of a declared study: its declaration's settings and its
//! model's parameters as knobs → one run → its figures, tables and
//! summary. A study (in `mechlab::studies`) is a declaration
//! ([`Declared`]) that says which model's parameters it takes and how it
//! runs ([`Study`]), and a result that says what it writes ([`Outputs`]);
//! its scene is then one line.

use crate::scene::{parameter_knobs, Knob, Scene, SceneError};
use mechlab_runtime::plot::Figure;
use mechlab_runtime::registry::ModelInfo;
use mechlab_runtime::settings::Declared;

/// A table of a result, already in CSV (through the csv crate, floats in
/// the shortest form that reads back exactly).
pub struct Table {
    pub file: String,
    pub csv: Vec<u8>,
}

impl Table {
    /// The CSV of `header` and one record per row (tuples or structs of
    /// numbers and text).
    pub fn new<R: serde::Serialize>(
        file: impl Into<String>,
        header: &[&str],
        rows: impl IntoIterator<Item = R>,
    ) -> Table {
        let mut writer = csv::WriterBuilder::new()
            .has_headers(false)
            .from_writer(Vec::new());
        writer.write_record(header).expect("CSV into memory");
        for row in rows {
            writer.serialize(row).expect("rows of numbers and text");
        }
        Table {
            file: file.into(),
            csv: writer.into_inner().expect("CSV into memory"),
        }
    }
}

/// What a result writes beside its `summary.json` (itself, serialised).
pub trait Outputs: serde::Serialize {
    /// Its figures, each with its file name (`.png`).
    fn figures(&self) -> Vec<(String, Figure)>;
    /// Its tables.
    fn tables(&self) -> Vec<Table> {
        Vec::new()
    }
    /// Its headline numbers, printed on the console.
    fn lines(&self) -> Vec<String> {
        Vec::new()
    }
}

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

/// Prints a result's lines and writes its figures, tables and summary.
pub fn write_outputs<O: Outputs>(scene: &Scene, outcome: &O) -> Result<(), SceneError> {
    for line in outcome.lines() {
        println!("{line}");
    }
    for (file, figure) in outcome.figures() {
        scene.save_figure(&figure, &file)?;
    }
    for table in outcome.tables() {
        scene.write_bytes(&table.file, &table.csv)?;
    }
    scene.write_summary(outcome)?;
    Ok(())
}
