//! The `standard_map` scene: the declaration and the run are the
//! library's; this says what its result writes.

use crate::scene::SceneError;
use crate::study::{Outputs, Study, Table};
use mechlab_runtime::analysis::standard_map::{standard_map_study, StandardMapOptions, StandardMapStudy};
use mechlab_runtime::plot::{ColorMap, Figure};
use mechlab_runtime::registry::ModelInfo;

impl Study for StandardMapOptions {
    type Outcome = StandardMapStudy;
    fn model() -> Option<&'static ModelInfo> {
        None
    }
    fn run(&self, _: &[f64]) -> Result<StandardMapStudy, SceneError> {
        Ok(standard_map_study(self))
    }
}

impl Outputs for StandardMapStudy {
    fn figures(&self) -> Vec<(String, Figure)> {
        vec![
            ("orbits.png".into(), self.orbits_figure()),
            ("chaos_map.png".into(), self.chaos_map_figure(ColorMap::Grey)),
            ("chaos_map_viridis.png".into(), self.chaos_map_figure(ColorMap::Viridis)),
        ]
    }
    fn tables(&self) -> Vec<Table> {
        vec![
            Table::new("orbits.csv", &["orbit", "iterate", "q", "p"], self.orbit_rows()),
            Table::new("chaos_map.csv", &["q", "p", "fli"], self.map_rows()),
        ]
    }
}
