//! Every scene command shown in the README and the book (`cargo run
//! --release --example NAME -- ARGS`, in code blocks or inline) names an
//! example that exists and arguments it accepts: each is run with
//! `MECHLAB_CHECK_ARGUMENTS` set, which checks the model and every knob's
//! name and exits before computing. Commands with a placeholder (`<name>`)
//! are skipped. The examples are built by `cargo test --release`.

use mechlab::scene::CHECK_ARGUMENTS;
use std::path::{Path, PathBuf};
use std::process::Command;

/// (document, example, arguments) of every scene command in `text`.
fn commands(document: &str, text: &str) -> Vec<(String, String, Vec<String>)> {
    let joined = text.replace("\\\n", " ");
    let marker = "cargo run --release --example ";
    let mut found = Vec::new();
    for (at, _) in joined.match_indices(marker) {
        let rest = &joined[at + marker.len()..];
        let end = rest.find(['`', '#', '\n']).unwrap_or(rest.len());
        let words: Vec<&str> = rest[..end].split_whitespace().collect();
        if words.is_empty() || rest[..end].contains('<') {
            continue;
        }
        let args = match words.get(1) {
            Some(&"--") => words[2..].iter().map(|w| w.to_string()).collect(),
            _ => Vec::new(),
        };
        found.push((document.to_string(), words[0].to_string(), args));
    }
    found
}

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

#[test]
fn every_scene_command_in_the_docs_is_accepted() {
    let mut documents = vec![workspace().join("README.md")];
    let mut book: Vec<PathBuf> = std::fs::read_dir(workspace().join("docs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "md"))
        .collect();
    book.sort();
    documents.extend(book);
    let examples = std::env::current_exe()
        .unwrap()
        .parent()
        .unwrap()
        .join("../examples");
    let mut checked = 0;
    for path in &documents {
        let text = std::fs::read_to_string(path).unwrap();
        let name = path.file_name().unwrap().to_string_lossy();
        for (document, example, args) in commands(&name, &text) {
            // The first chapter's model is the file the reader creates
            // (docs/first_model/): its commands are checked when it is in
            // models/, as `benches/added_models/run.sh` puts it.
            let written_by_reader = args.iter().any(|a| {
                a.strip_prefix("model=").is_some_and(|m| {
                    workspace()
                        .join(format!("docs/first_model/{m}.toml"))
                        .exists()
                        && !workspace().join(format!("models/{m}.toml")).exists()
                })
            });
            if written_by_reader {
                continue;
            }
            let binary = examples.join(&example);
            assert!(
                binary.is_file(),
                "{document}: `{example}` is not an example (no {}; build the examples with `cargo test --release`)",
                binary.display()
            );
            let output = Command::new(&binary)
                .args(&args)
                .env(CHECK_ARGUMENTS, "1")
                .output()
                .unwrap();
            assert!(
                output.status.success(),
                "{document}: `{example} {}` is refused: {}",
                args.join(" "),
                String::from_utf8_lossy(&output.stderr)
            );
            checked += 1;
        }
    }
    // The README's scene lines alone are more than ten.
    assert!(checked >= 15, "only {checked} commands found");
}

#[test]
fn the_parser_finds_commands_and_their_arguments() {
    let text = "run `cargo run --release --example explore -- --set model=kapitza` or\n\
                ```sh\ncargo run --release --example chaos_map -- --set model=kapitza \\\n  --set pixels=40   # a comment\n```\n\
                and `cargo run --release --example explore -- --set model=<name>`";
    let found = commands("t.md", text);
    assert_eq!(found.len(), 2);
    assert_eq!(found[0].1, "explore");
    assert_eq!(found[0].2, ["--set", "model=kapitza"]);
    assert_eq!(found[1].2, ["--set", "model=kapitza", "--set", "pixels=40"]);
}

/// Every path the README and the book name (`crates/…`, `src/…`,
/// `tests/…`, …, in backticks) exists; `{a,b}` names each of a and b,
/// and a path with a placeholder (`<name>`, `*`) is skipped.
#[test]
fn every_path_in_the_docs_exists() {
    let roots = [
        "crates/",
        "src/",
        "tests/",
        "models/",
        "benches/",
        "examples/",
        "templates/",
        "docs/",
        "test_models/",
        ".ci/",
    ];
    let mut documents = vec![workspace().join("README.md")];
    for entry in std::fs::read_dir(workspace().join("docs")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|x| x == "md") {
            documents.push(path);
        }
    }
    let mut missing = Vec::new();
    for document in &documents {
        let text = std::fs::read_to_string(document).unwrap();
        for quoted in text.split('`').skip(1).step_by(2) {
            let quoted = quoted.trim();
            if !roots.iter().any(|r| quoted.starts_with(r)) || quoted.contains(['<', '*', ' ', '$'])
            {
                continue;
            }
            let paths: Vec<String> = match (quoted.find('{'), quoted.find('}')) {
                (Some(a), Some(b)) if a < b => quoted[a + 1..b]
                    .split(',')
                    .map(|part| format!("{}{}{}", &quoted[..a], part, &quoted[b + 1..]))
                    .collect(),
                _ => vec![quoted.to_string()],
            };
            for path in paths {
                let path = path.trim_end_matches([':', '.', ',']);
                let path = path.split([':', '#']).next().unwrap();
                if !workspace().join(path).exists() {
                    missing.push(format!(
                        "{}: {path}",
                        document.file_name().unwrap().to_string_lossy()
                    ));
                }
            }
        }
    }
    assert!(
        missing.is_empty(),
        "paths that do not exist:\n{}",
        missing.join("\n")
    );
}

/// The first chapter's model file is the one beside it, and it reads and
/// checks as `build.rs` reads it (without deriving it).
#[test]
fn the_first_chapters_model_file_is_valid() {
    let chapter = std::fs::read_to_string(workspace().join("docs/first_model.md")).unwrap();
    let file =
        std::fs::read_to_string(workspace().join("docs/first_model/my_pendulum.toml")).unwrap();
    let block = chapter
        .split("```toml\n")
        .nth(1)
        .and_then(|rest| rest.split("```").next())
        .unwrap();
    assert_eq!(block, file);
    let model = mechlab_model::Model::parse("models/my_pendulum.toml", &file).unwrap();
    assert_eq!(model.name, "my_pendulum");
    assert_eq!(model.coordinates.len(), 1);
}
