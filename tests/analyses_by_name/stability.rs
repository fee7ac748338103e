//! The `stability` analysis on any model by name, against the closed forms
//! and the study-specific computations it generalises.

use super::model_of;
use mechlab::analysis::floquet::{first_stability_onset, jury_margin, monodromy};
use mechlab::analysis::stability::{stability, EquilibriumStability, Settings, StabilityError};
use mechlab::models::{self, kapitza};
use mechlab::ode::{Integrator, Method, OdeError};
use mechlab::studies::double_pendulum::{self as study, threshold_closed_form};
use std::f64::consts::PI;

fn settings(amplitude: &str) -> Settings {
    Settings {
        amplitude: amplitude.into(),
        a_max: None,
        samples: 60,
        edge_tolerance: 1e-11,
        method: Method::parse("dop853", 1e-12).unwrap(),
        max_windows: mechlab::analysis::stability::MAX_WINDOWS,
        accuracy: None,
        first: Default::default(),
    }
}

fn defaults(name: &str) -> Vec<f64> {
    model_of(name).dynamic.defaults()
}

fn at<'a>(result: &'a [EquilibriumStability], q: &[f64]) -> &'a EquilibriumStability {
    result
        .iter()
        .find(|e| {
            e.q.iter()
                .zip(q)
                .all(|(a, b)| mechlab::analysis::period_map::wrap_angle(a - b).abs() < 1e-8)
        })
        .unwrap_or_else(|| panic!("no equilibrium at {q:?} in {result:#?}"))
}

/// Kapitza's exact A*(ε) as `kapitza_stability` found it before the generic
/// analysis: the first A in (0, a_max] where the Jury criterion
/// |tr M| − 1 − det M of the 2×2 monodromy matrix becomes ≤ 0 (100 samples
/// per unit of A, bisected to 1e-11).
fn jury_threshold(eps: f64, a_max: f64) -> f64 {
    let jury = |a: f64| -> Result<f64, OdeError> {
        let params = kapitza::Params { A: a, eps, mu: 0.0 };
        let mut integrator = Integrator::new(Method::parse("dop853", 1e-12)?)?;
        let system = kapitza::Exact { params };
        let (_, m) = monodromy::<_, 2, 6>(&mut integrator, &system, 2.0 * PI * eps, &[0.0, 0.0])?;
        Ok(jury_margin(&m))
    };
    let samples = (100.0 * a_max) as usize;
    first_stability_onset(&jury, 0.0, a_max, samples, 1e-11)
        .unwrap()
        .expect("the upper position becomes stable below a_max")
}

/// Kapitza: a* = √2 from the averaged system, and the exact lower edge equals
/// the one found with the Jury criterion |tr M| − 1 − det M on the 2×2
/// monodromy matrix (as `kapitza_stability` finds A*), to 1e-9.
#[test]
fn kapitza_threshold_and_exact_edge() {
    let result = stability(model_of("kapitza"), &defaults("kapitza"), &settings("A")).unwrap();
    assert_eq!(result.equilibria.len(), 2, "{result:#?}");
    let upright = at(&result.equilibria, &[0.0]);
    assert!(!upright.stable_without_vibration);
    assert!((upright.lambdas[0] + 1.0).abs() < 1e-12);
    assert!((upright.a_star.unwrap() - 2f64.sqrt()).abs() < 1e-12);
    let hanging = at(&result.equilibria, &[PI]);
    assert!(hanging.stable_without_vibration && hanging.a_star.is_none());
    let eps = 0.1;
    let reference = jury_threshold(eps, 4.0);
    let [low, _] = upright.exact_window.unwrap();
    assert!(
        (low.unwrap() - reference).abs() < 1e-9,
        "{low:?} vs {reference}"
    );
    // The exact threshold lies above √2 by about 0.62 ε².
    assert!((reference - 2f64.sqrt() - 0.62 * eps * eps).abs() < 0.01 * eps * eps);
    // The spectral radius is 1 inside the window and larger outside.
    let inside = upright
        .spectral_radius
        .iter()
        .filter(|p| p[0] > reference + 0.1 && p[0] < 3.0);
    assert!(inside.clone().count() > 3 && inside.clone().all(|p| (p[1] - 1.0).abs() < 1e-6));
}

/// The double pendulum: a* at all four equilibria equals the closed form of
/// Study 2 (or none where it is stable without vibration), and the exact
/// window's lower edge at ν = 100 equals the study's.
#[test]
fn double_pendulum_thresholds_are_the_closed_forms() {
    let params = defaults("double_pendulum");
    let result = stability(model_of("double_pendulum"), &params, &settings("a")).unwrap();
    assert_eq!(result.equilibria.len(), 4);
    let p = models::double_pendulum::Params::from_values(&params);
    for phi in study::EQUILIBRIA {
        let e = at(&result.equilibria, &[phi.0, phi.1]);
        match threshold_closed_form(&p, phi) {
            Some(a) => assert!(
                (e.a_star.unwrap() - a).abs() < 1e-9,
                "{phi:?}: {:?} vs {a}",
                e.a_star
            ),
            None => assert!(e.stable_without_vibration && e.a_star.is_none(), "{phi:?}"),
        }
    }
    let upright = at(&result.equilibria, &[0.0, 0.0]);
    let window =
        study::exact_stability_window(&p, (0.0, 0.0), 3.0 * upright.a_star.unwrap(), 60, 1e-12)
            .unwrap()
            .unwrap();
    let [low, high] = upright.exact_window.unwrap();
    // The study bisects to 1e-6·a_max; this analysis to 1e-11.
    assert!(
        (low.unwrap() - window.0).abs() < 1e-5,
        "{low:?} vs {window:?}"
    );
    assert_eq!(high.is_some(), window.1.is_some());
}

/// The N-link chains (numeric-solve form): a* of the upright from the
/// normal modes of the hanging chain, a*² = 2/λ_min(A₀⁻¹D).
#[test]
fn chain_thresholds_match_the_normal_modes() {
    for (name, expected) in [
        ("triple_pendulum", 2.19323942081245),
        ("quadruple_pendulum", 2.490107120232377),
    ] {
        let mut fast = settings("a");
        fast.samples = 8;
        fast.edge_tolerance = 1e-6;
        let result = stability(model_of(name), &defaults(name), &fast).unwrap();
        let upright = at(&result.equilibria, &vec![0.0; result.equilibria[0].q.len()]);
        assert!(
            (upright.a_star.unwrap() - expected).abs() < 1e-9,
            "{name}: {:?}",
            upright.a_star
        );
        // Every link hanging: stable without vibration.
        let hanging = at(&result.equilibria, &vec![PI; upright.q.len()]);
        assert!(hanging.stable_without_vibration);
        assert_eq!(result.equilibria.len(), 1 << upright.q.len());
    }
}

/// With more equilibria than exact sweeps allowed, the sweeps go to the
/// lowest thresholds a*, give the same windows as an unlimited run, and
/// every other equilibrium says why it has none.
#[test]
fn exact_windows_beyond_the_budget_are_named_not_computed() {
    let mut fast = settings("a");
    fast.samples = 8;
    fast.edge_tolerance = 1e-6;
    let model = model_of("triple_pendulum");
    let all = stability(model, &defaults("triple_pendulum"), &fast).unwrap();
    fast.max_windows = 2;
    let budget = stability(model, &defaults("triple_pendulum"), &fast).unwrap();
    let mut thresholds: Vec<f64> = all.equilibria.iter().filter_map(|e| e.a_star).collect();
    assert!(thresholds.len() > 2, "{thresholds:?}");
    thresholds.sort_by(f64::total_cmp);
    assert_eq!(budget.equilibria.len(), all.equilibria.len());
    for (limited, full) in budget.equilibria.iter().zip(&all.equilibria) {
        assert_eq!(limited.q, full.q);
        assert_eq!(limited.a_star, full.a_star);
        match limited.a_star {
            Some(a) if a <= thresholds[1] => assert_eq!(limited.exact_window, full.exact_window),
            Some(_) => {
                assert_eq!(limited.exact_window, None);
                let reason = limited.exact_reason.as_deref().unwrap();
                assert!(reason.starts_with("not computed"), "{reason}");
            }
            None => assert_eq!(limited.exact_reason, full.exact_reason),
        }
    }
}

/// A pivot on a circle vibrates isotropically, and its horizontal
/// component moves the upright and the hanging position: (q, p) = (0, 0)
/// is no solution of the exact system, so neither has a Floquet window to
/// give. The analysis says so (an exact window there, from the monodromy of
/// an orbit that is not periodic, would be wrong); so does Ueda's driven
/// oscillator, whose drive moves x = 0.
#[test]
fn equilibria_the_vibration_moves_are_named_not_judged() {
    use mechlab::analysis::stability::NoEquilibria;
    let result = stability(
        model_of("circle_pendulum"),
        &defaults("circle_pendulum"),
        &settings("A"),
    )
    .unwrap();
    assert!(result.equilibria.is_empty());
    assert_eq!(result.moved_by_vibration.len(), 2, "{result:#?}");
    assert_eq!(result.none_because, Some(NoEquilibria::AllMoved));
    let ueda = stability(model_of("ueda"), &defaults("ueda"), &settings("B")).unwrap();
    let moved: Vec<_> = ueda
        .moved_by_vibration
        .iter()
        .map(|m| m.q.clone())
        .collect();
    assert_eq!(moved, vec![vec![0.0]]);
    assert_eq!(ueda.none_because, Some(NoEquilibria::AllMoved));
}

#[test]
fn bad_requests_are_typed_errors() {
    let e = stability(
        model_of("painleve_klein"),
        &defaults("painleve_klein"),
        &settings("mu1"),
    )
    .unwrap_err();
    assert!(
        matches!(
            e,
            StabilityError::Refused(mechlab::analysis::Refusal::ContactModel { .. })
        ),
        "{e}"
    );
    let e = stability(model_of("kapitza"), &defaults("kapitza"), &settings("B")).unwrap_err();
    assert!(
        e.to_string().contains("no parameter 'B'") && e.to_string().contains("A, eps, mu"),
        "{e}"
    );
    let e = models::by_name("no_such_model").unwrap_err();
    assert!(
        e.to_string().contains("no model named 'no_such_model'")
            && e.to_string().contains("kapitza"),
        "{e}"
    );
    let e = stability(model_of("kapitza"), &[1.0], &settings("A")).unwrap_err();
    assert!(matches!(e, StabilityError::ParameterCount(1, _)));
}

/// The chart's first boundary at each ε is Kapitza's exact A*(ε) (Jury
/// criterion on the 2×2 monodromy matrix), to 1e-8; above it a second
/// boundary closes the window (parametric resonance) for the larger ε.
#[test]
fn kapitza_chart_boundaries_are_the_exact_thresholds() {
    use mechlab::analysis::stability::{stability_chart, ChartSettings};
    let settings = ChartSettings {
        q: vec![0.0],
        x: "eps".into(),
        x_values: vec![0.1, 0.3],
        y: "A".into(),
        y_max: 6.0,
        y_samples: 60,
        edge_tolerance: 1e-11,
        method: Method::parse("dop853", 1e-12).unwrap(),
        tiles: None,
    };
    let chart = stability_chart(model_of("kapitza"), &defaults("kapitza"), &settings).unwrap();
    for (k, &eps) in settings.x_values.iter().enumerate() {
        let reference = jury_threshold(eps, 6.0);
        let first = chart.boundaries[k][0];
        assert!(
            (first - reference).abs() < 1e-8,
            "ε = {eps}: {first} vs {reference}"
        );
        assert!(!chart.stable[k][0] && chart.stable[k].iter().any(|s| *s));
    }
    assert!(chart.boundaries[1].len() >= 2, "{:?}", chart.boundaries);
}

/// A chart of a point the vibration moves (the elastic pendulum upright:
/// its vertical shaking stretches the spring) has no monodromy matrix to
/// chart: a typed error naming the model and the point, where it was a
/// divergence at the spring's singular length r = 0.
#[test]
fn a_chart_of_a_point_the_vibration_moves_is_refused() {
    use mechlab::analysis::stability::{stability_chart, ChartSettings};
    let settings = ChartSettings {
        q: vec![0.9, 0.0],
        x: "nu".into(),
        x_values: vec![5.0, 40.0],
        y: "a".into(),
        y_max: 4.0,
        y_samples: 8,
        edge_tolerance: 1e-6,
        method: Method::parse("taylor", 1e-10).unwrap(),
        tiles: None,
    };
    let e = stability_chart(
        model_of("elastic_pendulum"),
        &defaults("elastic_pendulum"),
        &settings,
    )
    .unwrap_err();
    assert!(
        matches!(&e, StabilityError::MovedByVibration { model, q } if model == "elastic_pendulum" && *q == [0.9, 0.0]),
        "{e}"
    );
    assert!(e.to_string().contains("the vibration moves it"), "{e}");
}

/// A chart in the lanes of the batch Taylor method (each (ε, A) point with
/// its own parameters and period, every boundary bisected in lockstep)
/// equals, bit for bit, the chart of one scalar monodromy matrix at a time
/// with one bisection per boundary, written out here.
#[test]
fn chart_in_lanes_equals_the_scalar_chart_bit_for_bit() {
    use mechlab::analysis::floquet::{floquet_multipliers, spectral_radius};
    use mechlab::analysis::stability::{stability_chart, ChartSettings};
    let method = Method::parse("taylor", 1e-10).unwrap();
    let settings = ChartSettings {
        q: vec![0.0],
        x: "eps".into(),
        x_values: vec![0.05, 0.15, 0.3],
        y: "A".into(),
        y_max: 6.0,
        y_samples: 15,
        edge_tolerance: 1e-9,
        method,
        tiles: None,
    };
    let chart = stability_chart(model_of("kapitza"), &defaults("kapitza"), &settings).unwrap();
    let margin = |eps: f64, a: f64| {
        let system = kapitza::Exact {
            params: kapitza::Params { A: a, eps, mu: 0.0 },
        };
        let mut integrator = Integrator::new(method).unwrap();
        let (_, m) =
            monodromy::<_, 2, 6>(&mut integrator, &system, 2.0 * PI * eps, &[0.0, 0.0]).unwrap();
        spectral_radius(&floquet_multipliers(&m)) - 1.0 - 1e-6
    };
    for (k, &eps) in settings.x_values.iter().enumerate() {
        let margins: Vec<f64> = chart.y_values.iter().map(|&a| margin(eps, a)).collect();
        let stable: Vec<bool> = margins.iter().map(|m| *m <= 0.0).collect();
        assert_eq!(chart.stable[k], stable, "ε = {eps}");
        let mut edges = Vec::new();
        for j in 1..margins.len() {
            if (margins[j - 1] > 0.0) == (margins[j] > 0.0) {
                continue;
            }
            let (mut low, mut high) = (chart.y_values[j - 1], chart.y_values[j]);
            while high - low > settings.edge_tolerance {
                let mid = 0.5 * (low + high);
                if (margin(eps, mid) <= 0.0) == stable[j - 1] {
                    low = mid;
                } else {
                    high = mid;
                }
            }
            edges.push((0.5 * (low + high)).to_bits());
        }
        let found: Vec<u64> = chart.boundaries[k].iter().map(|b| b.to_bits()).collect();
        assert_eq!(found, edges, "ε = {eps}");
        assert!(!edges.is_empty());
    }
}

/// The window search in batches of 8 (the Taylor lanes: 9 parts a step)
/// finds Kapitza's exact lower edge within its tolerance of the Jury
/// criterion's (bisected with DOP853); width 1 is the bisection itself.
#[test]
fn window_in_lanes_finds_the_exact_edge() {
    let mut taylor = settings("A");
    taylor.method = Method::parse("taylor", 1e-12).unwrap();
    let result = stability(model_of("kapitza"), &defaults("kapitza"), &taylor).unwrap();
    let [low, _] = at(&result.equilibria, &[0.0]).exact_window.unwrap();
    let reference = jury_threshold(0.1, 4.0);
    assert!(
        (low.unwrap() - reference).abs() < 1e-9,
        "{low:?} vs {reference}"
    );
    // A closed form: cos a first becomes ≤ 0 at π/2.
    use mechlab::analysis::floquet::first_onset_in_batches;
    let cosines = |a: &[f64]| -> Result<Vec<f64>, ()> { Ok(a.iter().map(|a| a.cos()).collect()) };
    let onset = |width| first_onset_in_batches(&cosines, width, 0.0, 4.0, 10, 1e-12);
    for width in [1, 3, 8] {
        let found = onset(width).unwrap().unwrap();
        assert!((found - PI / 2.0).abs() < 1e-12, "width {width}: {found}");
    }
    let bisected = first_stability_onset(&|a: f64| Ok::<_, ()>(a.cos()), 0.0, 4.0, 10, 1e-12);
    assert_eq!(onset(1), bisected);
}

/// Chart tiles (one column each): an interrupted run writes two of four,
/// the resumed run computes the other two and leaves those files alone,
/// and the merged chart equals the single run's bit for bit; a tile that
/// does not exist is a typed error.
#[test]
fn chart_tiles_resume_and_merge_bit_for_bit() {
    use mechlab::analysis::stability::{stability_chart, ChartSettings};
    use mechlab::analysis::tiles::{TileError, Tiles};
    let base = ChartSettings {
        q: vec![0.0],
        x: "eps".into(),
        x_values: vec![0.05, 0.1, 0.2, 0.3],
        y: "A".into(),
        y_max: 4.0,
        y_samples: 12,
        edge_tolerance: 1e-6,
        method: Method::parse("taylor", 1e-10).unwrap(),
        tiles: None,
    };
    let params = defaults("kapitza");
    let whole = stability_chart(model_of("kapitza"), &params, &base).unwrap();
    assert!(whole.boundaries.iter().all(|b| !b.is_empty()));
    let folder = tempfile::tempdir().unwrap();
    let tiled = |only: Option<Vec<usize>>| ChartSettings {
        tiles: Some(Tiles {
            folder: folder.path().to_path_buf(),
            rows: 1,
            only,
        }),
        ..base.clone()
    };
    let first = stability_chart(model_of("kapitza"), &params, &tiled(Some(vec![1, 3])));
    assert!(matches!(first, Err(StabilityError::Partial)), "{first:?}");
    let sweep = super::sweep_folder(folder.path());
    let files = || {
        let mut names: Vec<String> = std::fs::read_dir(&sweep)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        names.sort();
        names
    };
    assert_eq!(files(), ["tile_1.bin", "tile_3.bin"]);
    let stamp = |name: &str| {
        std::fs::metadata(sweep.join(name))
            .unwrap()
            .modified()
            .unwrap()
    };
    let before = [stamp("tile_1.bin"), stamp("tile_3.bin")];
    let resumed = stability_chart(model_of("kapitza"), &params, &tiled(None)).unwrap();
    assert_eq!(files().len(), 4);
    assert_eq!([stamp("tile_1.bin"), stamp("tile_3.bin")], before);
    assert_eq!(resumed.stable, whole.stable);
    let bits = |b: &[Vec<f64>]| -> Vec<Vec<u64>> {
        b.iter()
            .map(|c| c.iter().map(|v| v.to_bits()).collect())
            .collect()
    };
    assert_eq!(bits(&resumed.boundaries), bits(&whole.boundaries));
    let missing = stability_chart(model_of("kapitza"), &params, &tiled(Some(vec![4])));
    assert!(
        matches!(
            missing,
            Err(StabilityError::Tile(TileError::NoSuchTile {
                tile: 4,
                count: 4
            }))
        ),
        "{missing:?}"
    );
}

/// The horizontally shaken pivot moves its upright: the periodic orbit
/// near it, found by Newton on the period map, is the hyperbolic fixed
/// point that the separatrix analysis finds by its own Newton (from the
/// averaged saddle, with the Taylor method): the same point and
/// multipliers. The hanging position's orbit is stable (|λ| = 1).
#[test]
fn a_moved_equilibrium_is_replaced_by_its_periodic_orbit() {
    use mechlab::analysis::separatrix::{hyperbolic_fixed_point, SplittingSettings};
    let model = model_of("horizontal_pendulum");
    let params = defaults("horizontal_pendulum");
    let result = stability(model, &params, &settings("A")).unwrap();
    let upright = result
        .moved_by_vibration
        .iter()
        .find(|m| m.q[0].abs() < 1e-9)
        .expect("the upright, moved");
    assert_eq!(upright.verdict, Some("unstable"));
    let fixed = hyperbolic_fixed_point(model, &params, &SplittingSettings::default()).unwrap();
    let orbit = upright.periodic_orbit.as_ref().unwrap();
    assert!((orbit[0] - fixed.point[0]).abs() < 1e-9 && (orbit[1] - fixed.point[1]).abs() < 1e-9);
    assert!((upright.multipliers[0].0 / fixed.multipliers[0] - 1.0).abs() < 1e-8);
    let hanging = result
        .moved_by_vibration
        .iter()
        .find(|m| (m.q[0].abs() - PI).abs() < 1e-9)
        .expect("the hanging position, moved");
    assert_eq!(hanging.verdict, Some("stable"));
}

/// `first` names the equilibria that get an exact window before the
/// others: the triple pendulum's inverted chain (φ = 0 is the upright
/// link, the greatest V) as `highest`, or by its coordinates (angles
/// modulo 2π); coordinates where no equilibrium is are refused by name.
#[test]
fn first_names_the_equilibria_that_get_a_window() {
    use mechlab::analysis::stability::FirstWindows;
    let name = "triple_pendulum";
    let windowed = |first: FirstWindows| -> Vec<Vec<f64>> {
        let one = Settings {
            max_windows: 1,
            accuracy: None,
            samples: 20,
            edge_tolerance: 1e-6,
            first,
            ..settings("a")
        };
        let result = stability(model_of(name), &defaults(name), &one).unwrap();
        result
            .equilibria
            .iter()
            .filter(|e| e.a_star.is_some() && e.exact_reason.is_none())
            .map(|e| e.q.clone())
            .collect()
    };
    let upright = |q: &[f64]| {
        q.iter()
            .all(|x| mechlab::analysis::period_map::wrap_angle(*x).abs() < 1e-8)
    };
    // By default the lowest threshold comes first, and it is not the
    // inverted chain's.
    let lowest = windowed(FirstWindows::Lowest);
    assert!(lowest.len() == 1 && !upright(&lowest[0]), "{lowest:?}");
    let highest = windowed(FirstWindows::Highest);
    assert_eq!(highest.len(), 1, "{highest:?}");
    assert!(upright(&highest[0]), "{highest:?}");
    let named = windowed(FirstWindows::At(vec![vec![2.0 * PI, 0.0, -2.0 * PI]]));
    assert_eq!(named.len(), 1, "{named:?}");
    assert!(upright(&named[0]), "{named:?}");
    let nowhere = Settings {
        first: FirstWindows::At(vec![vec![0.3, 0.0, 0.0]]),
        ..settings("a")
    };
    match stability(model_of(name), &defaults(name), &nowhere) {
        Err(StabilityError::NoEquilibriumNear { q, .. }) => assert_eq!(q, vec![0.3, 0.0, 0.0]),
        other => panic!("{other:?}"),
    }
}

/// The multipliers of an orbit the forcing moves an equilibrium to come
/// with their error, which holds: the linear oscillator
/// x'' + c x' + x = F cos ωt has the multipliers exp(σ T), σ = −c/2 ±
/// i √(1 − c²/4), T = 2π/ω, whatever its forced orbit; at DOP853 1e-5 and
/// 1e-7 each is within its stated error of them.
#[test]
fn a_moved_orbits_multipliers_are_within_their_stated_error_of_the_closed_form() {
    let model = &mechlab_test_models::forced_oscillator::MODEL;
    let (c, omega) = (0.1, 1.3);
    let params = [c, 0.0, 0.1, omega];
    let period = 2.0 * std::f64::consts::PI / omega;
    let (decay, frequency) = (-c / 2.0, (1.0 - c * c / 4.0).sqrt());
    let exact = [1.0, -1.0].map(|sign| {
        let modulus = (decay * period).exp();
        (
            modulus * (sign * frequency * period).cos(),
            modulus * (sign * frequency * period).sin(),
        )
    });
    for tol in [1e-5, 1e-7] {
        let result = stability(
            model,
            &params,
            &Settings {
                method: Method::parse("dop853", tol).unwrap(),
                ..settings("F")
            },
        )
        .unwrap();
        let moved = &result.moved_by_vibration[0];
        let error = moved.multipliers_error.expect("an error");
        for (re, im) in &moved.multipliers {
            let off = exact
                .iter()
                .map(|(er, ei)| (re - er).hypot(im - ei))
                .fold(f64::INFINITY, f64::min);
            eprintln!("tol {tol:e}: multiplier ({re}, {im}) off by {off:.1e}, stated {error:.1e}");
            assert!(
                off <= error,
                "tol {tol:e}: off by {off:e}, stated {error:e}"
            );
            assert!(
                error <= 100.0 * off.max(1e-14),
                "tol {tol:e}: off by {off:e}, stated {error:e}"
            );
        }
    }
}
