//! A scene's files replace the previous results together, when its summary
//! is written; a scene that fails before that leaves the old results as
//! they were and no staging folder behind.

use mechlab::scene::{knob, Scene};

fn scene(out: &std::path::Path) -> Scene {
    let args = vec!["--out".to_string(), out.display().to_string()];
    Scene::parse("test_scene", &[knob("x", "1", "a knob")], &args).unwrap()
}

#[test]
fn results_are_replaced_together_or_not_at_all() {
    let root = tempfile::tempdir().unwrap();
    let out = root.path().join("test_scene");
    {
        let s = scene(&out);
        s.write_text("a.txt", "old a").unwrap();
        s.write_text("b.txt", "old b").unwrap();
        s.write_summary(&serde_json::json!({"run": 1})).unwrap();
    }
    assert_eq!(std::fs::read_to_string(out.join("a.txt")).unwrap(), "old a");
    {
        // A run that fails before its summary: nothing of it is published.
        let s = scene(&out);
        s.write_text("a.txt", "new a").unwrap();
        s.write_csv("c.csv", &["x", "y"], [(1.0, 2.5)]).unwrap();
    }
    assert_eq!(std::fs::read_to_string(out.join("a.txt")).unwrap(), "old a");
    assert!(!out.join("c.csv").exists());
    {
        // A complete run replaces the folder: no file of the old run stays.
        let s = scene(&out);
        s.write_csv("c.csv", &["x", "y"], [(1.0, 2.5), (0.1, 1e-300)])
            .unwrap();
        s.write_summary(&serde_json::json!({"run": 3})).unwrap();
    }
    assert!(!out.join("a.txt").exists() && !out.join("b.txt").exists());
    assert_eq!(
        std::fs::read_to_string(out.join("c.csv")).unwrap(),
        "x,y\n1.0,2.5\n0.1,1e-300\n"
    );
    let leftovers: Vec<_> = std::fs::read_dir(root.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .filter(|n| n.starts_with('.'))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}
