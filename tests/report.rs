//! The report builds from whatever outputs exist, and every link in it
//! points to a file that exists (missing scenes are named, not linked).

use mechlab::report::{index_html, links, SECTIONS};

#[test]
fn every_link_of_the_report_exists() {
    let root = tempfile::tempdir().unwrap();
    // Outputs for every other section; the rest are missing.
    for (k, s) in SECTIONS.iter().enumerate() {
        if k % 2 == 0 {
            let dir = root.path().join(s.scene);
            std::fs::create_dir_all(&dir).unwrap();
            std::fs::write(dir.join(s.figure), b"png").unwrap();
            std::fs::write(
                dir.join("summary.json"),
                br#"{"eps": 0.1, "slope": [-1.0, -0.98]}"#,
            )
            .unwrap();
        }
    }
    let html = index_html(mechlab::models::MODELS, root.path());
    let targets = links(&html);
    assert!(
        targets.iter().any(|l| l.ends_with(".png")),
        "figures are linked"
    );
    for link in targets {
        if let Some(anchor) = link.strip_prefix('#') {
            assert!(
                html.contains(&format!("id=\"{anchor}\"")),
                "anchor {anchor}"
            );
        } else {
            assert!(root.path().join(&link).exists(), "{link} does not exist");
        }
    }
    assert!(html.contains("Not run yet"), "missing scenes are named");
    // Formulas are MathML beside the figures (Kapitza's H̄ in the first
    // section, which has its outputs), not LaTeX source in <pre> blocks.
    let first = &html[html.find("id=\"1.2-1.4\"").unwrap()..html.find("id=\"1.5-1.6\"").unwrap()];
    assert!(first.contains("<img") && first.contains("<math"), "{first}");
    assert!(!html.contains("<pre>"));
    let hamiltonian = mechlab::models::by_name("kapitza")
        .ok()
        .map(|m| m.info)
        .unwrap()
        .derivations
        .iter()
        .find(|d| d.key == "hamiltonian")
        .unwrap();
    assert!(html.contains(&mechlab::mathml::mathml(hamiltonian.latex, true)));
}

/// The report runs each missing scene through cargo: the examples in
/// release mode, the work–precision benchmark through `cargo bench`,
/// which refuses `--release` (a fresh clone has no `out/work_precision`,
/// so the report ran `cargo bench --release` and failed).
#[test]
fn the_report_runs_scenes_with_arguments_cargo_accepts() {
    use mechlab::report::scene_command;
    let bench = scene_command("work_precision");
    assert_eq!(&bench[..3], &["bench", "--quiet", "--bench"]);
    assert!(!bench.contains(&"--release"));
    assert_eq!(bench.last(), Some(&"--out"));
    let example = scene_command("kapitza_period_map");
    assert_eq!(
        example,
        [
            "run",
            "--release",
            "--quiet",
            "--example",
            "kapitza_period_map",
            "--",
            "--out"
        ]
    );
    for section in SECTIONS {
        let args = scene_command(section.scene);
        assert!(args.contains(&section.scene), "{}", section.scene);
        assert!(!(args[0] == "bench" && args.contains(&"--release")));
    }
}
