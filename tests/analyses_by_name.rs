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

/// One orbit, or many, of a model by name at given times
/// (`analysis::states`, what a notebook integrates): Hénon–Heiles without
/// its coupling is two harmonic oscillators, each orbit of a batch equals
/// its run alone, and bad times or starts are refused by name.
#[test]
fn orbits_by_name_at_given_times() {
    use mechlab::analysis::states::{states_at, states_of_starts, StatesError};
    let model = mechlab::models::by_name("henon_heiles").unwrap();
    let method = mechlab::ode::Method::parse("dop853", 1e-12).unwrap();
    let times: Vec<f64> = (0..=40).map(|k| 0.5 * k as f64).collect();
    let y0 = [0.3, -0.2, 0.1, 0.4];
    let states = states_at(model, &[0.0], method, &y0, &times).unwrap();
    assert_eq!(states[0], y0);
    for (t, y) in times.iter().zip(&states) {
        let x = y0[0] * t.cos() + y0[2] * t.sin();
        let p_y = -y0[1] * t.sin() + y0[3] * t.cos();
        assert!(
            (y[0] - x).abs() < 1e-9 && (y[3] - p_y).abs() < 1e-9,
            "t = {t}: {y:?}"
        );
    }
    let starts = vec![y0.to_vec(), vec![0.0, 0.5, -0.3, 0.0]];
    let many = states_of_starts(model, &[1.0], method, &starts, &times).unwrap();
    for (run, y0) in many.iter().zip(&starts) {
        let alone = states_at(model, &[1.0], method, y0, &times).unwrap();
        assert_eq!(run.as_ref().unwrap(), &alone);
    }
    // The Taylor method runs a batch in the lanes, eight orbits at a time:
    // eleven starts (a second, partial block) on the harmonic closed form,
    // each lane as its scalar run.
    let taylor = mechlab::ode::Method::Taylor { tol: 1e-14 };
    let starts: Vec<Vec<f64>> = (0..11)
        .map(|k| vec![0.05 * k as f64, -0.2, 0.1, 0.02 * k as f64])
        .collect();
    let lanes = states_of_starts(model, &[0.0], taylor, &starts, &times).unwrap();
    for (run, y0) in lanes.iter().zip(&starts) {
        let run = run.as_ref().unwrap();
        assert_eq!(run.len(), times.len());
        let alone = states_at(model, &[0.0], taylor, y0, &times).unwrap();
        for ((t, y), z) in times.iter().zip(run).zip(&alone) {
            let x = y0[0] * t.cos() + y0[2] * t.sin();
            assert!((y[0] - x).abs() < 1e-12, "t = {t}: {y:?}");
            assert!(y.iter().zip(z).all(|(a, b)| (a - b).abs() < 1e-12));
        }
    }
    let backwards = states_at(model, &[1.0], method, &y0, &[1.0, 0.5]);
    assert!(matches!(backwards, Err(StatesError::Times)));
    let short = states_at(model, &[1.0], method, &y0[..3], &times);
    assert!(matches!(short, Err(StatesError::Refused(_))));
    // A constrained model's start is on its constraints: projecting it
    // again leaves it where it is.
    let four_bar = mechlab::models::by_name("four_bar").unwrap();
    let params = four_bar.dynamic.defaults();
    let constrained = four_bar.constrained.unwrap();
    let mut y = constrained.start(&params);
    constrained.project(&params, 0.0, &mut y).unwrap();
    let again = states_at(four_bar, &params, method, &y, &[0.0]).unwrap();
    for (a, b) in y.iter().zip(&again[0]) {
        assert!((a - b).abs() < 1e-12);
    }
}
