//! The FLI chaos map of any model by name against the direct computation
//! of `kapitza_chaos_map` and of a plane of the double pendulum.

use super::model_of;
use mechlab::analysis::chaos_map::{chaos_map, ChaosMapError, ChaosMapSettings, TileError, Tiles};
use mechlab::analysis::lyapunov::fast_lyapunov_indicator;
use mechlab::analysis::row_blocks;
use mechlab::models::{double_pendulum, kapitza};
use mechlab::ode::{Integrator, Method};
use std::f64::consts::{FRAC_1_SQRT_2, PI};

fn settings(axes: [usize; 2], pixels: usize, periods: usize) -> ChaosMapSettings {
    ChaosMapSettings {
        check: 0,
        accuracy: None,
        axes,
        ranges: [None, None],
        p_max: 3.0,
        through: None,
        pixels,
        periods,
        method: Method::parse("taylor", 1e-6).unwrap(),
        tiles: None,
    }
}

/// Same FLI per pixel as the Kapitza scene's own loop (cell centres on
/// [−π, π] × [−p_max, p_max], tangent (1, 1)/√2), to 1e-9.
#[test]
fn kapitza_map_is_the_scene_s_map() {
    let params = kapitza::Params {
        A: 1.0,
        eps: 0.1,
        mu: 0.0,
    };
    let map = chaos_map(
        model_of("kapitza"),
        &params.values(),
        &settings([0, 1], 12, 40),
        &|| true,
    )
    .unwrap();
    assert_eq!((map.axes[0].as_str(), map.axes[1].as_str()), ("q", "p_q"));
    let system = kapitza::Exact { params };
    let mut integrator = Integrator::new(Method::parse("taylor", 1e-6).unwrap()).unwrap();
    for k in 0..144 {
        let (i, j) = (k % 12, k / 12);
        let q = -PI + 2.0 * PI * (i as f64 + 0.5) / 12.0;
        let p = -3.0 + 6.0 * (j as f64 + 0.5) / 12.0;
        let direct = fast_lyapunov_indicator::<_, 2, 4>(
            &mut integrator,
            &system,
            2.0 * PI * 0.1,
            &[q, p],
            &[FRAC_1_SQRT_2; 2],
            40,
        )
        .unwrap();
        assert!(
            (map.fli[k] - direct).abs() < 1e-9,
            "pixel {k}: {} vs {direct}",
            map.fli[k]
        );
        assert_eq!(map.pixel(k), (q, p));
    }
    assert!(map.fli.iter().all(|f| f.is_finite()) && map.chaotic_fraction < 0.5);
}

/// The rows are streamed in blocks, about four a thread: on one thread
/// (blocks of 3 of the 12 rows) and on three (blocks of 1) the map is the
/// same bit for bit, with the same f-evaluations, and every row is
/// reported once.
#[test]
fn the_map_does_not_depend_on_how_rows_are_grouped() {
    let params = kapitza::Params {
        A: 1.0,
        eps: 0.1,
        mu: 0.0,
    };
    let on = |threads: usize| {
        let rows = std::sync::atomic::AtomicUsize::new(0);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let map = pool.install(|| {
            chaos_map(
                model_of("kapitza"),
                &params.values(),
                &settings([0, 1], 12, 20),
                &|| {
                    rows.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    true
                },
            )
            .unwrap()
        });
        assert_eq!(rows.into_inner(), 12);
        map
    };
    let (one, three) = (on(1), on(3));
    let bits = |m: &[f64]| m.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&one.fli), bits(&three.fli));
    assert_eq!(one.f_evals, three.f_evals);
}

/// A plane (φ₁, p_φ₁) of the double pendulum through a given state.
#[test]
fn a_plane_of_a_larger_model() {
    let params = double_pendulum::Params::default();
    let mut s = settings([0, 2], 3, 10);
    s.through = Some(vec![0.0, 0.1, 0.0, 0.05]);
    s.ranges = [None, Some((-1.0, 1.0))];
    let map = chaos_map(model_of("double_pendulum"), &params.values(), &s, &|| true).unwrap();
    assert_eq!(map.axes, ["phi1".to_string(), "p_phi1".to_string()]);
    let system = double_pendulum::Exact { params };
    let mut integrator = Integrator::new(Method::parse("taylor", 1e-6).unwrap()).unwrap();
    for k in [0, 4, 8] {
        let (x, y) = map.pixel(k);
        let direct = fast_lyapunov_indicator::<_, 4, 8>(
            &mut integrator,
            &system,
            2.0 * PI / params.nu,
            &[x, 0.1, y, 0.05],
            &[0.5; 4],
            10,
        )
        .unwrap();
        assert!((map.fli[k] - direct).abs() < 1e-9);
    }
}

#[test]
fn bad_requests_are_typed_errors() {
    let kapitza = mechlab::models::by_name("kapitza")
        .unwrap()
        .dynamic
        .defaults();
    let e = chaos_map(
        model_of("kapitza"),
        &kapitza,
        &settings([0, 2], 2, 2),
        &|| true,
    )
    .unwrap_err();
    assert!(
        matches!(&e, ChaosMapError::Plane { model, source } if model == "kapitza" && source.names == ["q", "p_q"]),
        "{e}"
    );
    assert!(e.to_string().contains("q, p_q"), "{e}");
    let e = chaos_map(
        model_of("kapitza"),
        &kapitza,
        &settings([1, 1], 2, 2),
        &|| true,
    )
    .unwrap_err();
    assert!(matches!(e, ChaosMapError::Plane { .. }), "{e}");
    let mut s = settings([0, 1], 2, 2);
    s.through = Some(vec![0.0; 3]);
    assert!(chaos_map(model_of("kapitza"), &kapitza, &s, &|| true).is_err());
    let none = mechlab::models::by_name("painleve_klein")
        .unwrap()
        .dynamic
        .defaults();
    assert!(matches!(
        chaos_map(
            model_of("painleve_klein"),
            &none,
            &settings([0, 1], 2, 2),
            &|| true
        ),
        Err(ChaosMapError::Refused(
            mechlab::analysis::Refusal::ContactModel { .. }
        ))
    ));
}

/// Figure labels use the model's notation.
#[test]
fn names_are_drawn_in_the_notation_of_the_studies() {
    use mechlab::registry::display_name;
    for (name, shown) in [
        ("phi1", "φ₁"),
        ("p_phi1", "p_φ₁"),
        ("eps", "ε"),
        ("A", "A"),
        ("l12", "l₁₂"),
        ("p_q", "p_q"),
        ("nu", "ν"),
        ("tau", "τ"),
        ("mu1", "μ₁"),
        ("phid", "phid"),
    ] {
        assert_eq!(display_name(name), shown);
    }
}

/// The period-map portrait of any model: the orbit from a seed equals the
/// period map iterated directly (Kapitza), projected on the chosen axes.
#[test]
fn portraits_are_the_period_map_iterated() {
    use mechlab::analysis::period_map::{orbit, portrait, PortraitSettings};
    let params = kapitza::Params {
        A: 1.5,
        eps: 0.1,
        mu: 0.0,
    };
    let settings = PortraitSettings {
        axes: [1, 0],
        seeds: Some(vec![vec![0.3, 0.0], vec![2.0, 0.5]]),
        count: 0,
        p_max: 1.0,
        periods: 50,
        method: Method::parse("taylor", 1e-12).unwrap(),
        check: 0,
        accuracy: None,
    };
    let result = portrait(model_of("kapitza"), &params.values(), &settings).unwrap();
    let mut integrator = Integrator::new(settings.method).unwrap();
    for (k, seed) in [[0.3, 0.0], [2.0, 0.5]].iter().enumerate() {
        let direct = orbit(
            &mut integrator,
            &kapitza::Exact { params },
            2.0 * PI * 0.1,
            seed,
            50,
            &[true, false],
        )
        .unwrap();
        assert_eq!(result.orbits[k].len(), 51);
        for (p, y) in result.orbits[k].iter().zip(&direct) {
            assert!((p.0 - y[1]).abs() < 1e-12 && (p.1 - y[0]).abs() < 1e-12);
        }
    }
}

/// Tiles: an interrupted run (two tiles of seven), then a resumed one that
/// computes only the missing rows, merge into the single run's map bit for
/// bit; a damaged tile or a tile that does not exist is a typed error.
#[test]
fn tiles_resume_and_merge_bit_for_bit() {
    let params = kapitza::Params {
        A: 1.0,
        eps: 0.1,
        mu: 0.0,
    };
    let whole = chaos_map(
        model_of("kapitza"),
        &params.values(),
        &settings([0, 1], 20, 30),
        &|| true,
    )
    .unwrap();
    let folder = tempfile::tempdir().unwrap();
    let tiled = |only: Option<Vec<usize>>| ChaosMapSettings {
        tiles: Some(Tiles {
            folder: folder.path().to_path_buf(),
            rows: 3,
            only,
        }),
        ..settings([0, 1], 20, 30)
    };
    let rows = std::sync::atomic::AtomicUsize::new(0);
    let count = || rows.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let first = chaos_map(
        model_of("kapitza"),
        &params.values(),
        &tiled(Some(vec![1, 6])),
        &|| {
            count();
            true
        },
    );
    assert!(matches!(first, Err(ChaosMapError::Partial)));
    assert_eq!(rows.swap(0, std::sync::atomic::Ordering::Relaxed), 3 + 2);
    let resumed = chaos_map(model_of("kapitza"), &params.values(), &tiled(None), &|| {
        count();
        true
    })
    .unwrap();
    assert_eq!(rows.load(std::sync::atomic::Ordering::Relaxed), 20 - 5);
    let bits = |m: &[f64]| m.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&resumed.fli), bits(&whole.fli));
    assert_eq!(resumed.f_evals, whole.f_evals);

    let sweep = super::sweep_folder(folder.path());
    let tile = sweep.join("tile_2.bin");
    let bytes = std::fs::read(&tile).unwrap();
    std::fs::write(&tile, &bytes[..bytes.len() - 3]).unwrap();
    let damaged = chaos_map(model_of("kapitza"), &params.values(), &tiled(None), &|| {
        true
    });
    assert!(
        matches!(
            damaged,
            Err(ChaosMapError::Tile(TileError::Truncated { .. }))
        ),
        "{damaged:?}"
    );
    let missing = chaos_map(
        model_of("kapitza"),
        &params.values(),
        &tiled(Some(vec![7])),
        &|| true,
    );
    assert!(
        matches!(
            missing,
            Err(ChaosMapError::Tile(TileError::NoSuchTile {
                tile: 7,
                count: 7
            }))
        ),
        "{missing:?}"
    );
}

/// A map whose caller stops listening after a few rows ends with
/// `Cancelled`, without computing the rows not yet started.
#[test]
fn a_map_nobody_waits_for_stops() {
    let rows = std::sync::atomic::AtomicUsize::new(0);
    let params = kapitza::Params::default();
    let result = chaos_map(
        model_of("kapitza"),
        &params.values(),
        &settings([0, 1], 64, 30),
        &|| rows.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1 < 3,
    );
    assert!(
        matches!(result, Err(ChaosMapError::Cancelled)),
        "{result:?}"
    );
    let done = rows.load(std::sync::atomic::Ordering::Relaxed);
    // Blocks of rows already running on the workers finish; no new one
    // starts.
    let block = row_blocks(0..64, 64)[0].len();
    assert!(
        done <= block * (1 + rayon::current_num_threads()) && done < 64,
        "{done} of 64 rows in blocks of {block}"
    );
}

/// The map's class check counts, on its sample of pixels, exactly the
/// class changes between the map and the same map at a hundredth of the
/// tolerance (each pixel's orbit the same run bit for bit), and its
/// estimate covers the share that changes over the whole map; at a tight
/// tolerance none change and the error is the rule of three's bound; with
/// every pixel checked, the share is the whole map's and has no error.
#[test]
fn the_class_check_counts_the_pixels_a_tighter_run_reclassifies() {
    use mechlab::analysis::check::sample_pixels;
    use mechlab::analysis::lyapunov::fli_is_chaotic;
    let params = kapitza::Params {
        A: 1.0,
        eps: 0.1,
        mu: 0.0,
    }
    .values();
    let map = |tol: f64, check: usize| {
        let settings = ChaosMapSettings {
            check,
            method: Method::parse("taylor", tol).unwrap(),
            ..settings([0, 1], 40, 100)
        };
        chaos_map(model_of("kapitza"), &params, &settings, &|| true).unwrap()
    };
    let (crude, tighter) = (map(1e-3, 400), map(1e-5, 0));
    let check = crude.class_check.clone().unwrap();
    let changed = |ks: &mut dyn Iterator<Item = usize>| {
        ks.filter(|&k| fli_is_chaotic(crude.fli[k], 100) != fli_is_chaotic(tighter.fli[k], 100))
            .count()
    };
    assert_eq!(check.sampled, 400);
    assert_eq!(
        check.changed,
        changed(&mut sample_pixels(1600, 400).into_iter())
    );
    let whole = changed(&mut (0..1600)) as f64 / 1600.0;
    eprintln!("{check:?}, whole map {whole}");
    assert!(check.changed > 0, "{check:?}");
    assert!(
        (check.fraction - whole).abs() <= 3.0 * check.error,
        "{check:?} vs {whole}"
    );
    assert!(
        check.runs.contains("1e-3") && check.runs.contains("1e-5"),
        "{}",
        check.runs
    );
    let tight = map(1e-10, 400).class_check.unwrap();
    assert_eq!(tight.changed, 0, "{tight:?}");
    assert!((tight.error - 3.0 / 400.0).abs() < 1e-15);
    // Every pixel checked: the share is counted, not estimated.
    let census = map(1e-3, 1600).class_check.unwrap();
    assert_eq!(census.sampled, 1600);
    assert_eq!(census.fraction, whole);
    assert_eq!(census.error, 0.0);
}

/// Asked for at most 0.2 % of pixels changing class, a map at 1e-3 (where
/// 0.5 % of the checked ones change) is run again at 1e-5, which the check
/// passes: the map returned is that run's, pixel for pixel.
#[test]
fn a_chaos_map_asked_for_an_accuracy_tightens_its_tolerance_until_its_check_passes() {
    let params = kapitza::Params {
        A: 1.0,
        eps: 0.1,
        mu: 0.0,
    }
    .values();
    let map = |tol: f64, accuracy: Option<f64>| {
        let settings = ChaosMapSettings {
            check: 400,
            accuracy,
            method: Method::parse("taylor", tol).unwrap(),
            ..settings([0, 1], 40, 100)
        };
        chaos_map(model_of("kapitza"), &params, &settings, &|| true).unwrap()
    };
    let asked = map(1e-3, Some(0.002));
    let said = asked.accuracy.clone().unwrap();
    assert!(
        said.contains("0.002 reached") && said.contains("tol 1e-5"),
        "{said}"
    );
    assert!(asked.class_check.as_ref().unwrap().fraction <= 0.002);
    assert_eq!(asked.fli, map(1e-5, None).fli);
}

/// x'' + x = F cos(ωt) from (x0, v0), at t = kT (T = 2π/ω): the particular
/// solution A cos ωt (A = F/(1 − ω²)) is A, 0 there; the free one turns by
/// ωT per period.
fn undamped_forced_period_map(f: f64, omega: f64, (x0, v0): (f64, f64), k: usize) -> (f64, f64) {
    let amplitude = f / (1.0 - omega * omega);
    let t = k as f64 * 2.0 * PI / omega;
    let (c1, c2) = (x0 - amplitude, v0);
    (
        amplitude + c1 * t.cos() + c2 * t.sin(),
        -c1 * t.sin() + c2 * t.cos(),
    )
}

/// The period map's drawn points against the undamped forced oscillator's
/// closed form, over 400 periods from five seeds at three tolerances of two
/// methods: each orbit's stated error bounds its largest distance to the
/// closed form, and is within 100 times it.
#[test]
fn the_period_maps_stated_errors_bound_the_distance_to_the_closed_form() {
    use mechlab::analysis::period_map::{portrait, PortraitSettings};
    let model = &mechlab_test_models::forced_oscillator::MODEL;
    let (f, omega) = (0.1, 1.3);
    let params = [0.0, 0.0, f, omega];
    let seeds: Vec<Vec<f64>> = [
        (0.5, 0.0),
        (-1.0, 0.3),
        (2.0, -1.0),
        (0.0, 1.5),
        (-0.3, -0.7),
    ]
    .iter()
    .map(|&(x, v)| vec![x, v])
    .collect();
    let mut cases = 0;
    for (name, tol) in [
        ("dop853", 1e-6),
        ("dop853", 1e-8),
        ("dop853", 1e-10),
        ("taylor", 1e-6),
        ("taylor", 1e-9),
    ] {
        let settings = PortraitSettings {
            axes: [0, 1],
            seeds: Some(seeds.clone()),
            count: seeds.len(),
            p_max: 1.0,
            periods: 400,
            method: Method::parse(name, tol).unwrap(),
            check: seeds.len(),
            accuracy: None,
        };
        let drawn = portrait(model, &params, &settings).unwrap();
        assert_eq!(drawn.checks.len(), seeds.len());
        for check in &drawn.checks {
            let seed = &seeds[check.orbit];
            let distance = drawn.orbits[check.orbit]
                .iter()
                .enumerate()
                .map(|(k, &(x, v))| {
                    let (cx, cv) = undamped_forced_period_map(f, omega, (seed[0], seed[1]), k);
                    (x - cx).hypot(v - cv)
                })
                .fold(0.0, f64::max);
            println!(
                "{name} {tol:e}, orbit {}: stated {:.2e}, off by {distance:.2e}",
                check.orbit, check.error
            );
            assert!(
                distance <= check.error,
                "{name} {tol:e}: {check:?} against {distance:e}"
            );
            assert!(
                check.error <= 100.0 * distance.max(1e-14),
                "{name} {tol:e}: {check:?} against {distance:e}"
            );
            cases += 1;
        }
    }
    assert_eq!(cases, 25);
}

/// `accuracy` on the period map: reached on the oscillator from DOP853 1e-5
/// (its points then within it of the closed form); on Kapitza's chaotic
/// sea it cannot be, and the result says for how many periods each orbit
/// is within it.
#[test]
fn a_period_map_asked_for_an_accuracy_reaches_it_or_says_for_how_long() {
    use mechlab::analysis::period_map::{portrait, PortraitSettings};
    let model = &mechlab_test_models::forced_oscillator::MODEL;
    let (f, omega) = (0.1, 1.3);
    let settings = PortraitSettings {
        axes: [0, 1],
        seeds: Some(vec![vec![0.5, 0.0], vec![-1.0, 0.3]]),
        count: 2,
        p_max: 1.0,
        periods: 300,
        method: Method::parse("dop853", 1e-5).unwrap(),
        check: 2,
        accuracy: Some(1e-9),
    };
    let drawn = portrait(model, &[0.0, 0.0, f, omega], &settings).unwrap();
    let verdict = drawn.accuracy.clone().unwrap();
    println!("{verdict}");
    assert!(verdict.contains(" reached"), "{verdict}");
    for (orbit, seed) in drawn.orbits.iter().zip([(0.5, 0.0), (-1.0, 0.3)]) {
        for (k, &(x, v)) in orbit.iter().enumerate() {
            let (cx, cv) = undamped_forced_period_map(f, omega, seed, k);
            assert!((x - cx).hypot(v - cv) <= 1e-9, "period {k}");
        }
    }
    // Kapitza's chaotic layer about the unstable upright at A = 1.
    let kapitza = model_of("kapitza");
    let values = [1.0, 0.1, 0.0]; // A, eps, mu: the upright unstable
    let chaotic = PortraitSettings {
        axes: [0, 1],
        seeds: Some(vec![vec![0.05, 0.0]]),
        count: 1,
        p_max: 1.0,
        periods: 2000,
        method: Method::parse("taylor", 1e-8).unwrap(),
        check: 1,
        accuracy: Some(1e-6),
    };
    let drawn = portrait(kapitza, &values, &chaotic).unwrap();
    let verdict = drawn.accuracy.clone().unwrap();
    println!("{verdict}");
    assert!(verdict.contains("NOT reached"), "{verdict}");
    let within = drawn.checks[0].periods_within.unwrap();
    assert!(within > 0 && within < 2000, "{verdict}");
}

/// A run at the precision floor has no tighter run to check it: its
/// points' error is not stated (a check against itself would give 0).
#[test]
fn a_period_map_at_the_precision_floor_states_no_error() {
    use mechlab::analysis::period_map::{portrait, PortraitSettings};
    use mechlab::ode::PRECISION_FLOOR;
    let settings = PortraitSettings {
        axes: [0, 1],
        seeds: Some(vec![vec![0.5, 0.0]]),
        count: 1,
        p_max: 1.0,
        periods: 10,
        method: Method::Taylor {
            tol: PRECISION_FLOOR,
        },
        check: 1,
        accuracy: None,
    };
    let model = &mechlab_test_models::forced_oscillator::MODEL;
    let drawn = portrait(model, &[0.0, 0.0, 0.1, 1.3], &settings).unwrap();
    assert!(drawn.checks.is_empty(), "{:?}", drawn.checks);
    assert!(
        drawn.check_runs.contains("precision floor"),
        "{}",
        drawn.check_runs
    );
    assert!(Method::Taylor {
        tol: PRECISION_FLOOR
    }
    .check_run()
    .is_none());
}
