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
