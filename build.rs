//! Build script: model files → derivations (Symbolica) → generated Rust.
//!
//! Thin on purpose: reading and validation live in `src/model/` (shared with
//! the library), derivations in `build/derive.rs`, readable forms in
//! `build/simplify.rs` and `build/latex.rs`, common subexpression
//! elimination in `build/emit.rs`, module assembly in `build/generate.rs`,
//! layout in `templates/`. Symbolica runs here only, on this one thread.

#[allow(dead_code, unused_imports)]
#[path = "src/model/mod.rs"]
mod model;

#[path = "build/contacts.rs"]
mod contacts;
#[path = "build/derive.rs"]
mod derive;
#[path = "build/emit.rs"]
mod emit;
#[path = "build/generate.rs"]
mod generate;
#[path = "build/latex.rs"]
mod latex;
#[path = "build/simplify.rs"]
mod simplify;
#[path = "build/taylor.rs"]
mod taylor;

use std::path::{Path, PathBuf};
use std::process::Command;

fn fail(message: String) -> ! {
    eprintln!("error: {message}");
    std::process::exit(1);
}

fn main() {
    for watched in ["models", "templates", "build", "src/model", "build.rs"] {
        println!("cargo:rerun-if-changed={watched}");
    }
    let out_dir = PathBuf::from(std::env::var("OUT_DIR").expect("cargo sets OUT_DIR"));
    let generated = out_dir.join("generated");
    std::fs::create_dir_all(&generated)
        .unwrap_or_else(|e| fail(format!("cannot create {}: {e}", generated.display())));
    let tera =
        tera::Tera::new("templates/*.tera").unwrap_or_else(|e| fail(format!("templates: {e:?}")));

    let mut files: Vec<PathBuf> = std::fs::read_dir("models")
        .unwrap_or_else(|e| fail(format!("cannot read models/: {e}")))
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();

    let mut models = Vec::new();
    for path in &files {
        let file = path.to_string_lossy().replace('\\', "/");
        let text = std::fs::read_to_string(path).unwrap_or_else(|e| fail(format!("{file}: {e}")));
        let model = model::Model::parse(&file, &text).unwrap_or_else(|e| fail(e.to_string()));
        let expected = path
            .file_stem()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_default();
        if model.name != expected {
            fail(format!(
                "{file}: key `name`: '{}' must equal the file name '{expected}'",
                model.name
            ));
        }
        let derive_failure = |e: derive::DeriveError| -> ! {
            fail(format!("{file}: key `{}`: {}", e.key, e.reason))
        };
        let code = if model.contacts.is_empty() {
            let derivation = derive::derive(&model).unwrap_or_else(|e| derive_failure(e));
            generate::render(&tera, &model, &derivation, &file)
        } else {
            let derivation = contacts::derive(&model).unwrap_or_else(|e| derive_failure(e));
            generate::render_contacts(&tera, &model, &derivation, &file)
        }
        .unwrap_or_else(|e| fail(format!("{file}: {e}")));
        write_formatted(&generated.join(format!("{}.rs", model.name)), &code);
        models.push(model);
    }
    let registry = generate::render_registry(&tera, &models).unwrap_or_else(|e| fail(e));
    write_formatted(&generated.join("mod.rs"), &registry);
}

/// Writes Rust source and formats it with rustfmt when it is available.
fn write_formatted(path: &Path, code: &str) {
    std::fs::write(path, code)
        .unwrap_or_else(|e| fail(format!("cannot write {}: {e}", path.display())));
    let rustfmt = std::env::var("RUSTFMT").unwrap_or_else(|_| "rustfmt".into());
    // Formatting is for readers only; unformatted code compiles the same.
    let _ = Command::new(rustfmt)
        .args(["--edition", "2021"])
        .arg(path)
        .status();
}
