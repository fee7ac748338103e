//! Scene `report`: runs every study's scenes at their defaults (only those
//! whose outputs are missing, unless `--set run=all`) and writes
//! `out/index.html`: a section per deliverable with its figure, its key
//! numbers and a line on what it shows, and the LaTeX of the derivations.
//! Static, no network: open it from the disk.

use mechlab::report::{index_html, links, scene_command, SECTIONS};
use mechlab::scene::{knob, run, write_atomic, Scene, SceneError, ValueProblem};
use std::path::PathBuf;
use std::process::Command;

fn main() {
    run(|| {
        let scene = Scene::from_args(
            "report",
            "runs the study scenes and writes out/index.html",
            &[
                knob(
                    "run",
                    "missing",
                    "which scenes to run first: missing, all or none",
                ),
                knob(
                    "root",
                    "out",
                    "the folder holding the scenes' outputs; index.html goes there",
                ),
            ],
        )?;
        let root = PathBuf::from(scene.text("root"));
        let mode = scene.text("run").to_string();
        if !["missing", "all", "none"].contains(&mode.as_str()) {
            return Err(SceneError::BadValue {
                name: "run".into(),
                value: mode,
                reason: ValueProblem::Requirement("use missing, all or none"),
            });
        }
        let mut scenes: Vec<&str> = SECTIONS.iter().map(|s| s.scene).collect();
        scenes.dedup();
        for name in scenes {
            let present = root.join(name).join("summary.json").exists();
            if mode == "all" || (mode == "missing" && !present) {
                eprintln!("running {name} …");
                let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
                let status = Command::new(cargo)
                    .args(scene_command(name))
                    .arg(root.join(name))
                    .status()
                    .map_err(|source| SceneError::Spawn {
                        scene: name.into(),
                        source,
                    })?;
                if !status.success() {
                    return Err(SceneError::SceneFailed {
                        scene: name.into(),
                        status,
                    });
                }
            }
        }
        let html = index_html(mechlab::models::MODELS, &root);
        let missing: Vec<String> = links(&html)
            .into_iter()
            .filter(|l| !l.starts_with('#') && !root.join(l).exists())
            .collect();
        if !missing.is_empty() {
            return Err(SceneError::BrokenLinks(missing));
        }
        let path = root.join("index.html");
        std::fs::create_dir_all(&root).map_err(|source| SceneError::Io {
            path: root.clone(),
            source,
        })?;
        write_atomic(&path, html.as_bytes()).map_err(|source| SceneError::Io {
            path: path.clone(),
            source,
        })?;
        println!("wrote {} ({} sections)", path.display(), SECTIONS.len());
        Ok(())
    });
}
