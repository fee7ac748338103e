//! The derivation: model files → Symbolica → generated Rust modules.
//!
//! Used by the workspace's `build.rs` only (Symbolica's restricted mode
//! allows one thread of one process: never from a test, an example or the
//! runtime). Reading and validation of the files live in `mechlab-model`,
//! derivations in `derive.rs` (`contacts.rs` for rough guides), readable
//! forms in `mechlab-simplify` and `latex.rs`, common subexpression elimination
//! in `emit.rs`, Taylor recurrences in `taylor.rs`, the averaging series in
//! `lie.rs` (`deprit.rs` closed form, `numeric.rs` through run-time solves),
//! module assembly in `generate.rs`, layout in the workspace's `templates/`.
//!
//! Each model's generated module is cached under a hash of its file and of
//! the derivation code, so editing or adding one model file derives that
//! model only. Each model is derived in a process of its own (the build
//! script run again for that one file): Symbolica orders a product's
//! factors by when their symbols were first made, so in a shared process a
//! model's code would depend on which other models were derived before it.

use mechlab_model as model;

mod algebra;
mod constraints;
mod contacts;
mod deprit;
mod derive;
mod emit;
mod error;
mod functions;
mod generate;
mod latex;
mod lie;
mod numeric;
use mechlab_simplify as simplify;
mod taylor;

use std::hash::{Hash, Hasher};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

/// Stack of the derivation thread: the recursion of expression trees is as
/// deep as the longest sum, and a model near the size limit needs far more
/// than the main thread's 8 MiB. Only the pages used are ever committed.
const STACK_BYTES: usize = 1 << 30;

fn fail(message: String) -> ! {
    eprintln!("error: {message}");
    std::process::exit(1);
}

/// Derives every model file of `folder` (`models` or `test_models`, in
/// the workspace at `root`) into `OUT_DIR/generated` (one module per file
/// and `mod.rs` listing them) and prints cargo's rerun rules. Run from a
/// build script; any failure ends the build with a message that names the
/// model file and the reason. The derivation code is a dependency of the
/// build script, so cargo reruns it when that changes.
pub fn build_models(root: &str, folder: &str) {
    if let (Ok(file), Ok(out)) = (std::env::var(DERIVE_FILE), std::env::var(DERIVE_OUT)) {
        return on_derivation_thread(move || derive_one(&file, Path::new(&out)));
    }
    let root = std::fs::canonicalize(root)
        .unwrap_or_else(|e| fail(format!("cannot find the workspace at {root}: {e}")));
    for watched in [folder, "templates"] {
        println!("cargo:rerun-if-changed={}", root.join(watched).display());
    }
    println!("cargo:rerun-if-changed=build.rs");
    // Paths in messages and in the generated code are the workspace's.
    std::env::set_current_dir(&root)
        .unwrap_or_else(|e| fail(format!("cannot enter {}: {e}", root.display())));
    let _only_derivation = symbolica_lock();
    run(folder);
}

/// The variables that make the build script derive one model file into one
/// module (the file, then where to write the module): set for the
/// processes [`build_model`] starts.
const DERIVE_FILE: &str = "MECHLAB_DERIVE_FILE";
const DERIVE_OUT: &str = "MECHLAB_DERIVE_OUT";
const DERIVE_LIMIT: &str = "MECHLAB_DERIVE_SECONDS";

/// Runs `work` on a thread with the derivation's stack.
fn on_derivation_thread(work: impl FnOnce() + Send + 'static) {
    let worker = std::thread::Builder::new()
        .name("derivations".into())
        .stack_size(STACK_BYTES)
        .spawn(work)
        .unwrap_or_else(|e| fail(format!("cannot start the derivation thread: {e}")));
    if worker.join().is_err() {
        fail("the derivation thread panicked (see above)".into());
    }
}

/// In a process of its own: derives the model `file` and writes its
/// formatted module to `out`.
fn derive_one(file: &str, out: &Path) {
    let tera =
        tera::Tera::new("templates/*.tera").unwrap_or_else(|e| fail(format!("templates: {e:?}")));
    let text = std::fs::read_to_string(file).unwrap_or_else(|e| fail(format!("{file}: {e}")));
    let model = model::Model::parse(file, &text).unwrap_or_else(|e| fail(e.to_string()));
    let derivation = std::panic::AssertUnwindSafe(|| generate_model(&tera, &model, file));
    let code = std::panic::catch_unwind(derivation).unwrap_or_else(|_| {
        fail(format!(
            "{file}: the derivation stopped on an internal error (above); please report it with this model file"
        ))
    });
    write_formatted(out, &code);
}

/// Symbolica's restricted mode aborts when two processes of one user use
/// it at once, and cargo runs the build scripts of two packages (the
/// users' models and the test models) in parallel: a lock file per user
/// makes them take turns. Held until the returned file is dropped.
fn symbolica_lock() -> std::fs::File {
    let user = std::env::var("USER").unwrap_or_else(|_| "user".into());
    let path = std::env::temp_dir().join(format!("mechlab-symbolica-{user}.lock"));
    let file = std::fs::OpenOptions::new()
        .create(true)
        .truncate(false)
        .write(true)
        .open(&path)
        .unwrap_or_else(|e| fail(format!("cannot open {}: {e}", path.display())));
    file.lock()
        .unwrap_or_else(|e| fail(format!("cannot lock {}: {e}", path.display())));
    file
}

fn run(folder: &str) {
    let out_dir = PathBuf::from(std::env::var("OUT_DIR").expect("cargo sets OUT_DIR"));
    let generated = out_dir.join("generated");
    let cache = out_dir.join("cache");
    for dir in [&generated, &cache] {
        std::fs::create_dir_all(dir)
            .unwrap_or_else(|e| fail(format!("cannot create {}: {e}", dir.display())));
    }
    let tera =
        tera::Tera::new("templates/*.tera").unwrap_or_else(|e| fail(format!("templates: {e:?}")));
    let code_version = code_version();

    let mut timings = String::from("model\tseconds\tcached\n");
    let mut names = std::collections::BTreeSet::new();
    let mut models = Vec::new();
    for path in model_files(folder) {
        let started = Instant::now();
        let (model, hit) = build_model(&path, &cache, &generated, code_version);
        if !names.insert(model.name.clone()) {
            fail(format!(
                "{}: key `name`: '{}' is also the name of another model",
                path.display(),
                model.name
            ));
        }
        timings.push_str(&format!(
            "{}\t{:.2}\t{hit}\n",
            model.name,
            started.elapsed().as_secs_f64()
        ));
        models.push(model);
    }
    let registry = generate::render_registry(&tera, &models, folder == "models")
        .unwrap_or_else(|e| fail(e.to_string()));
    write_formatted(&generated.join("mod.rs"), &registry);
    let _ = std::fs::write(out_dir.join("derivation_times.tsv"), timings);
}

/// The model files of a folder, sorted (none if the folder is absent).
fn model_files(dir: &str) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = match std::fs::read_dir(dir) {
        Ok(entries) => entries
            .filter_map(|entry| entry.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "toml"))
            .collect(),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Vec::new(),
        Err(e) => fail(format!("cannot read {dir}/: {e}")),
    };
    files.sort();
    files
}

/// Reads one model file and puts its generated module in `generated`,
/// from the cache when the file and the derivation code are unchanged.
/// Returns the model and whether the cache had it.
fn build_model(
    path: &Path,
    cache: &Path,
    generated: &Path,
    code_version: u64,
) -> (model::Model, bool) {
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
    let cached = cache.join(format!(
        "{}-{:016x}.rs",
        model.name,
        key(&text, code_version)
    ));
    let hit = cached.is_file();
    if !hit {
        // Written beside and renamed: an interrupted build never leaves a
        // half-written module under a valid key.
        let partial = cached.with_extension("partial");
        derive_in_own_process(&file, &partial);
        std::fs::rename(&partial, &cached)
            .unwrap_or_else(|e| fail(format!("cannot write {}: {e}", cached.display())));
        prune_cache(cache, &model.name, &cached);
    }
    std::fs::copy(&cached, generated.join(format!("{}.rs", model.name)))
        .unwrap_or_else(|e| fail(format!("cannot copy {}: {e}", cached.display())));
    (model, hit)
}

/// Derives the model `file` into `out` in a process of its own (this build
/// script again; see the crate's comment), which says what went wrong on
/// its standard error. A derivation that runs past the time limit is
/// stopped with an error naming the file, rather than holding the build.
fn derive_in_own_process(file: &str, out: &Path) {
    let script = std::env::current_exe()
        .unwrap_or_else(|e| fail(format!("cannot find the build script to run again: {e}")));
    let mut child = Command::new(script)
        .env(DERIVE_FILE, file)
        .env(DERIVE_OUT, out)
        .spawn()
        .unwrap_or_else(|e| fail(format!("{file}: cannot start its derivation: {e}")));
    let limit = derivation_limit();
    let started = Instant::now();
    let status = loop {
        match child.try_wait() {
            Ok(Some(status)) => break status,
            Ok(None) if started.elapsed().as_secs() >= limit => {
                let _ = child.kill();
                let _ = child.wait();
                fail(format!(
                    "{file}: its derivation did not finish in {limit} s and was stopped. Its time grows with the number of terms its expressions expand to (many bodies, high powers of long sums); the bicycle, four bodies, takes about 25 s. {DERIVE_LIMIT} sets the limit in seconds."
                ))
            }
            Ok(None) => std::thread::sleep(std::time::Duration::from_millis(50)),
            Err(e) => fail(format!("{file}: cannot follow its derivation: {e}")),
        }
    };
    if !status.success() {
        fail(format!("{file}: its derivation failed (above)"));
    }
}

/// How long one model's derivation may run, in seconds: the environment's
/// `MECHLAB_DERIVE_SECONDS`, else ten minutes (the largest model here, the
/// bicycle, takes about 25 s).
fn derivation_limit() -> u64 {
    std::env::var(DERIVE_LIMIT)
        .ok()
        .and_then(|s| s.trim().parse().ok())
        .unwrap_or(600)
}

/// Removes the model's other cached versions (earlier texts or code).
fn prune_cache(cache: &Path, name: &str, keep: &Path) {
    let prefix = format!("{name}-");
    let Ok(entries) = std::fs::read_dir(cache) else {
        return;
    };
    for entry in entries.filter_map(|e| e.ok()) {
        let path = entry.path();
        let stale = path != keep
            && entry
                .file_name()
                .to_string_lossy()
                .strip_prefix(&prefix)
                .is_some_and(|rest| {
                    rest.len() == "0123456789abcdef.rs".len() && rest.ends_with(".rs")
                });
        if stale {
            let _ = std::fs::remove_file(path);
        }
    }
}

/// Derives one model and renders its module; errors name the file.
fn generate_model(tera: &tera::Tera, model: &model::Model, file: &str) -> String {
    let generated = if !model.contacts.is_empty() {
        contacts::derive(model)
            .and_then(|derivation| generate::render_contacts(tera, model, &derivation, file))
    } else if !model.constraints.is_empty() {
        constraints::derive(model)
            .and_then(|derivation| generate::render_constrained(tera, model, &derivation, file))
    } else {
        derive::derive(model)
            .and_then(|derivation| generate::render(tera, model, &derivation, file))
    };
    generated.unwrap_or_else(|e| fail(format!("{file}: {e}")))
}

/// A hash of the derivation code and templates (not the model files):
/// part of every cache key, so a change to the pipeline derives every
/// model again.
fn code_version() -> u64 {
    let derivation_code = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut paths = Vec::new();
    let mut pending: Vec<PathBuf> = vec![
        PathBuf::from("templates"),
        derivation_code.join("src"),
        derivation_code.join("../model/src"),
        derivation_code.join("../simplify/src"),
    ];
    while let Some(path) = pending.pop() {
        if path.is_dir() {
            if let Ok(entries) = std::fs::read_dir(&path) {
                pending.extend(entries.filter_map(|e| e.ok().map(|e| e.path())));
            }
        } else {
            paths.push(path);
        }
    }
    paths.sort();
    let mut hasher = std::collections::hash_map::DefaultHasher::new();
    for path in paths {
        std::fs::read(&path).unwrap_or_default().hash(&mut hasher);
    }
    hasher.finish()
}

fn key(text: &str, code_version: u64) -> u64 {
    let mut hasher = std::collections::hash_map::DefaultHasher::new();
    text.hash(&mut hasher);
    code_version.hash(&mut hasher);
    hasher.finish()
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
