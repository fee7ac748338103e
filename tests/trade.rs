//! The trade of an analysis between cost and stated error: each run of the
//! ladder states an error that bounds its distance to the most accurate
//! run (within that run's own error), and a run asked for an accuracy is
//! compared with the cheapest run of the ladder that states as much.

use crate::common::model_of;
use mechlab::analysis::stability::StabilityOptions;
use mechlab::analysis::trade::{cheapest_reaching, trade, Stated, TradeRun};
use mechlab::settings::Declared;

/// Kapitza's exact window over DOP853 and Taylor from 1e-6 to 1e-12: the
/// stated errors fall with the tolerance, and each bounds the run's
/// distance to the reference run's edges, give or take that run's error.
#[test]
fn each_runs_stated_error_bounds_its_distance_to_the_most_accurate_run() {
    let model = model_of("kapitza");
    let mut values = model.dynamic.defaults();
    values[model
        .info
        .parameter_names
        .iter()
        .position(|n| *n == "eps")
        .unwrap()] = 0.01;
    let base = StabilityOptions::default()
        .with_texts([("edge_tolerance", "1e-13")])
        .unwrap();
    let ladder: Vec<(String, f64)> = ["dop853", "taylor"]
        .iter()
        .flat_map(|m| [1e-6, 1e-8, 1e-10, 1e-12].map(|t| (m.to_string(), t)))
        .collect();
    let asked = base.clone().with_texts([("accuracy", "1e-9")]).unwrap();
    let result = trade(model, &values, &base, &ladder, Some(&asked), &|_| ()).unwrap();
    assert!(result.failed.is_empty());
    let reference = &result.runs[result.reference.unwrap()];
    for run in &result.runs {
        let Some(distance) = run.largest_distance else {
            continue;
        };
        assert!(
            distance <= run.largest_error + reference.largest_error,
            "{} at {:e}: distance {distance:e}, stated {:e}",
            run.method,
            run.tol,
            run.largest_error
        );
    }
    let dop853: Vec<f64> = result.runs[..4].iter().map(|r| r.largest_error).collect();
    assert!(dop853.windows(2).all(|w| w[1] < w[0]), "{dop853:?}");
    let requested = &result.runs[result.requested.unwrap()];
    assert!(
        requested.largest_error <= 1e-9,
        "{}",
        requested.largest_error
    );
    assert!(result.cost_ratio.is_some());
    // Every stated number is a row of the table beside the figure.
    let table = &mechlab::outputs::Outputs::tables(&result)[0];
    let rows: usize = result.runs.iter().map(|r| r.stated.len()).sum();
    let text = String::from_utf8(table.csv.clone()).unwrap();
    assert_eq!(text.lines().count(), 1 + rows, "{text}");
}

/// The cheapest run within an error is the one of least time among those
/// that state at most that error, and none where none does.
#[test]
fn the_cheapest_run_within_an_error_is_found() {
    let run = |seconds: f64, error: f64| TradeRun {
        method: "dop853".into(),
        tol: 1e-8,
        seconds,
        stated: vec![Stated {
            what: "x".into(),
            kind: "x",
            value: 1.0,
            error,
        }],
        largest_error: error,
        largest_distance: None,
    };
    let runs = [
        run(1.0, 1e-6),
        run(3.0, 1e-9),
        run(2.0, 1e-8),
        run(5.0, 1e-10),
    ];
    assert_eq!(cheapest_reaching(&runs, 1e-8), Some(2));
    assert_eq!(cheapest_reaching(&runs, 1e-5), Some(0));
    assert_eq!(cheapest_reaching(&runs, 1e-11), None);
}

/// A ladder none of whose runs can give a result (stability on a model
/// that names no amplitude) is the analysis's error, not an empty figure.
#[test]
fn a_trade_of_runs_that_all_fail_is_their_error() {
    let model = model_of("ueda");
    let ladder = [("dop853".to_string(), 1e-8), ("dop853".to_string(), 1e-10)];
    let e = trade(
        model,
        &model.dynamic.defaults(),
        &StabilityOptions::default(),
        &ladder,
        None,
        &|_| (),
    )
    .unwrap_err();
    assert!(
        e.to_string().contains("names no [fast_phase] amplitude"),
        "{e}"
    );
}
