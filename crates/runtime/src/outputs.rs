//! What a result writes beside its summary: its figures (drawn beside
//! the analysis that made them), its tables as CSV, and the headline lines
//! a scene prints. The scenes write them; the summary is the result itself.

use crate::plot::Figure;

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
    /// Its text files (a document, code).
    fn texts(&self) -> Vec<(String, String)> {
        Vec::new()
    }
    /// Its headline numbers, printed on the console.
    fn lines(&self) -> Vec<String> {
        Vec::new()
    }
}
