//! The generic analyses by model name (`stability`, `averaging`,
//! `chaos_map`, the period-map portrait), run on the models of `models/`.

use crate::common::model_of;

#[path = "analyses_by_name/averaging.rs"]
mod averaging;
#[path = "analyses_by_name/chaos_map.rs"]
mod chaos_map;
#[path = "analyses_by_name/every_model.rs"]
mod every_model;
#[path = "analyses_by_name/stability.rs"]
mod stability;

/// The one sweep folder (named by its fingerprint) that a tiled run wrote
/// under `root`.
fn sweep_folder(root: &std::path::Path) -> std::path::PathBuf {
    let mut folders = std::fs::read_dir(root).unwrap();
    let sweep = folders.next().unwrap().unwrap().path();
    assert!(
        folders.next().is_none(),
        "one sweep under {}",
        root.display()
    );
    sweep
}
