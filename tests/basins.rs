//! Basins of attraction: the unforced damped double well against its
//! symmetry and its equilibria, the forced one's attractors checked as
//! cycles of the period map by an independent integration, early stops
//! against whole runs, and the boundary's dimension against synthetic
//! boundaries of known dimension and Melnikov's threshold.

use mechlab::analysis::attractor::{attractor, AttractorSettings};
use mechlab::analysis::basins::{basins, BasinSettings, Boundary, CHAOTIC, DIVERGED};
use mechlab::models::duffing;
use mechlab::ode::{Integrator, Method};

/// The largest Lyapunov exponent of the period map from an attractor's
/// representative and its error, by the attractor analysis (tolerance,
/// transient, periods of each Lyapunov run).
fn largest_exponent(
    model: &mechlab::registry::Model,
    params: &[f64],
    a: &mechlab::analysis::basins::Attractor,
    (tol, transient, periods): (f64, usize, usize),
) -> (f64, f64) {
    let measured = attractor(
        model,
        params,
        &AttractorSettings {
            method: Method::Taylor { tol },
            start: [a.representative[0], a.representative[1]],
            transient,
            points: 100,
            lyapunov_periods: periods,
            accuracy: None,
            pixels: 20,
        },
    )
    .unwrap();
    (measured.lyapunov[0], measured.lyapunov_error[0])
}

fn settings(pixels: usize) -> BasinSettings {
    BasinSettings {
        axes: [0, 1],
        ranges: [(-2.0, 2.0), (-2.0, 2.0)],
        through: None,
        pixels,
        transient: 60,
        record: 8,
        cell: 0.05,
        method: Method::Taylor { tol: 1e-12 },
        stop_early: true,
        check: 0,
        accuracy: None,
        tiles: None,
    }
}

/// x'' + 0.3x' − x + x³ = 0: two attractors found unaided, the wells'
/// bottoms (±1, 0) to 1e-9, each a fixed point; the basins exchange under
/// (x, p) → (−x, −p) pixel for pixel (the grid is symmetric), so each holds
/// half of the starts.
#[test]
fn the_unforced_double_well_has_two_symmetric_basins() {
    let model = mechlab::models::by_name("duffing").unwrap();
    let result = basins(model, &[0.3, 0.0, 1.2], &settings(24), &|_| ()).unwrap();
    assert_eq!(result.attractors.len(), 2, "{:?}", result.attractors);
    assert_eq!(result.diverged, 0);
    for a in &result.attractors {
        assert_eq!(a.kind, "period 1");
        assert!(
            (a.representative[0].abs() - 1.0).abs() < 1e-9 && a.representative[1].abs() < 1e-9,
            "{a:?}"
        );
        assert_eq!(a.fraction, 0.5);
    }
    let n = result.labels.len();
    for k in 0..n {
        assert_ne!(
            result.labels[k],
            result.labels[n - 1 - k],
            "pixel {k} and its mirror image"
        );
    }
}

/// Driven (γ = 0.2, ω = 1.2): every attractor found is a cycle whose
/// representative the period map, integrated here by DOP853, returns to
/// after its period, to 1e-7; no start is left unassigned.
#[test]
fn the_forced_double_wells_attractors_are_cycles_of_its_period_map() {
    let model = mechlab::models::by_name("duffing").unwrap();
    let params = [0.3, 0.2, 1.2];
    let result = basins(model, &params, &settings(16), &|_| ()).unwrap();
    assert!(!result.attractors.is_empty());
    let starts: usize = result.attractors.iter().map(|a| a.starts).sum();
    assert_eq!(starts + result.diverged, 256);
    assert!(result
        .labels
        .iter()
        .all(|&l| l == DIVERGED || (l as usize) < result.attractors.len()));
    let exact = duffing::Exact {
        params: duffing::Params::from_values(&params),
    };
    let period = 2.0 * std::f64::consts::PI / 1.2;
    for a in &result.attractors {
        let k: usize = a
            .kind
            .strip_prefix("period ")
            .expect("a cycle")
            .parse()
            .unwrap();
        let mut integrator = Integrator::new(Method::Dop853 {
            rtol: 1e-13,
            atol: 1e-13,
        })
        .unwrap();
        let mut y = [a.representative[0], a.representative[1]];
        for _ in 0..k {
            y = integrator.advance(&exact, 0.0, &y, period).unwrap();
        }
        assert!(
            (y[0] - a.representative[0]).abs() < 1e-7 && (y[1] - a.representative[1]).abs() < 1e-7,
            "{a:?} → {y:?}"
        );
    }
}

#[test]
fn a_basin_map_that_cannot_be_made_says_why() {
    let duffing = mechlab::models::by_name("duffing").unwrap();
    let mut bad = settings(8);
    bad.cell = 0.0;
    let error = basins(duffing, &[0.3, 0.0, 1.2], &bad, &|_| ()).unwrap_err();
    assert!(error.to_string().contains("positive cell"), "{error}");
    let henon = mechlab::models::by_name("henon_heiles").unwrap();
    let error = basins(henon, &[1.0], &settings(8), &|_| ()).unwrap_err();
    assert!(error.to_string().contains("no fast phase"), "{error}");
}

/// Orbits stopped once settled on a cycle, or once on an attractor the
/// scouts found, get the labels the whole runs give: the driven well's
/// two cycles, and Ueda's chaotic attractor, its record joined from
/// pieces.
#[test]
fn stopping_early_gives_the_labels_of_the_whole_runs() {
    let duffing = mechlab::models::by_name("duffing").unwrap();
    let mut whole = settings(48);
    whole.stop_early = false;
    let params = [0.3, 0.2, 1.2];
    let early = basins(duffing, &params, &settings(48), &|_| ()).unwrap();
    let full = basins(duffing, &params, &whole, &|_| ()).unwrap();
    assert_eq!(early.attractors.len(), 2, "{:?}", early.attractors);
    assert_eq!(early.labels, full.labels);

    let ueda = mechlab::models::by_name("ueda").unwrap();
    let mut chaotic = settings(32);
    chaotic.ranges = [(-4.0, 4.0), (-8.0, 8.0)];
    chaotic.record = 16;
    chaotic.method = Method::Taylor { tol: 1e-10 };
    let early = basins(ueda, &[0.05, 7.5, 1.0], &chaotic, &|_| ()).unwrap();
    chaotic.stop_early = false;
    let full = basins(ueda, &[0.05, 7.5, 1.0], &chaotic, &|_| ()).unwrap();
    for result in [&early, &full] {
        assert_eq!(result.attractors.len(), 1, "{:?}", result.attractors);
        assert_eq!(result.attractors[0].kind, CHAOTIC);
        assert_eq!(result.attractors[0].fraction, 1.0);
    }
}

/// Records of 4 iterates in cells of 0.02 leave Ueda's chaotic attractor
/// in pieces no two records share; the representatives' longer runs join
/// them into the one attractor.
#[test]
fn the_pieces_of_a_chaotic_attractor_are_joined() {
    let ueda = mechlab::models::by_name("ueda").unwrap();
    let mut pieces = settings(24);
    pieces.ranges = [(-4.0, 4.0), (-8.0, 8.0)];
    pieces.record = 4;
    pieces.cell = 0.02;
    pieces.stop_early = false;
    pieces.method = Method::Taylor { tol: 1e-10 };
    let result = basins(ueda, &[0.05, 7.5, 1.0], &pieces, &|_| ()).unwrap();
    assert_eq!(result.attractors.len(), 1, "{:?}", result.attractors);
}

/// Labels of a 1024² grid split by the curve y = f(x): a straight line
/// has uncertainty exponent 1 (dimension 1); the graph of Weierstrass'
/// function Σ 2^(−Hk) cos(2π 2^k x) has box dimension 2 − H, so the
/// exponent is H.
#[test]
fn the_boundary_dimension_of_known_curves() {
    let n = 1024;
    let split = |f: &dyn Fn(f64) -> f64| -> Vec<i32> {
        (0..n * n)
            .map(|k| {
                let (x, y) = (
                    ((k % n) as f64 + 0.5) / n as f64,
                    ((k / n) as f64 + 0.5) / n as f64,
                );
                i32::from(y > f(x))
            })
            .collect()
    };
    let line = Boundary::of_labels(&split(&|x| 0.3 + 0.4 * x), n);
    let alpha = line.exponent.unwrap();
    assert!((alpha - 1.0).abs() < 0.02, "{line:?}");
    assert!((line.dimension.unwrap() - 1.0).abs() < 0.02);
    let h = 0.5;
    let weierstrass = |x: f64| {
        0.5 + 0.12
            * (0..20)
                .map(|k| {
                    2f64.powf(-h * k as f64) * (2.0 * std::f64::consts::PI * 2f64.powi(k) * x).cos()
                })
                .sum::<f64>()
    };
    let rough = Boundary::of_labels(&split(&weierstrass), n);
    assert!((rough.exponent.unwrap() - h).abs() < 0.1, "{rough:?}");
    let one = Boundary::of_labels(&vec![0; 256 * 256], 256);
    assert!(one.exponent.is_none() && one.why_not.unwrap().contains("no boundary"));
    let small = Boundary::of_labels(
        &split(&|x| x)
            .iter()
            .take(64 * 64)
            .copied()
            .collect::<Vec<_>>(),
        64,
    );
    assert!(small.why_not.unwrap().contains("128 pixels"));
}

/// The driven double well's basin boundary is a smooth curve below
/// Melnikov's threshold γ_c = 4δ cosh(πω/2)/(3√2 πω), where the saddle's
/// manifolds do not cross, and fractal above it (Moon and Li): box
/// dimension within 0.1 of 1 at 0.8 γ_c, above 1.5 at 1.15 γ_c (two
/// cycles of period 4 there).
#[test]
fn the_double_well_boundary_turns_fractal_at_melnikovs_threshold() {
    let model = mechlab::models::by_name("duffing").unwrap();
    let (delta, omega) = (0.3, 1.2);
    let pi = std::f64::consts::PI;
    let threshold = 4.0 * delta * (pi * omega / 2.0).cosh() / (3.0 * 2f64.sqrt() * pi * omega);
    let mut grid = settings(256);
    grid.transient = 100;
    grid.record = 16;
    grid.method = Method::Taylor { tol: 1e-10 };
    let dimension = |gamma: f64| {
        let result = basins(model, &[delta, gamma, omega], &grid, &|_| ()).unwrap();
        assert!(result.attractors.len() >= 2, "{:?}", result.attractors);
        result.boundary.dimension.unwrap()
    };
    let below = dimension(0.8 * threshold);
    assert!((below - 1.0).abs() < 0.1, "{below}");
    let above = dimension(1.15 * threshold);
    assert!(above > 1.5, "{above}");
}

/// Basins in tiles of rows: a job given some tiles writes them and has no
/// map; the run that merges them gives the single run's labels.
#[test]
fn tiled_basins_equal_the_single_run() {
    use mechlab::analysis::basins::BasinsError;
    use mechlab::analysis::tiles::Tiles;
    let model = mechlab::models::by_name("duffing").unwrap();
    let params = [0.3, 0.2, 1.2];
    let single = basins(model, &params, &settings(32), &|_| ()).unwrap();
    let folder = tempfile::tempdir().unwrap();
    let mut tiled = settings(32);
    tiled.tiles = Some(Tiles {
        folder: folder.path().to_path_buf(),
        rows: 5,
        only: Some(vec![0, 3, 6]),
    });
    let partial = basins(model, &params, &tiled, &|_| ());
    assert!(matches!(partial, Err(BasinsError::Partial)), "{partial:?}");
    tiled.tiles.as_mut().unwrap().only = None;
    let merged = basins(model, &params, &tiled, &|_| ()).unwrap();
    assert_eq!(merged.labels, single.labels);
}

/// What an attractor is, told by its longer run: at γ = 0.29 the driven
/// well's two attractors are cycles of period 4, which a record of 4
/// iterates cannot show (its cycles are looked for up to period 2); at
/// γ = 0.27 the attractors called chaotic have a positive largest
/// Lyapunov exponent by the attractor analysis (their iterates hop between
/// bands in a fixed order, so a single frequency would look regular).
#[test]
fn attractors_are_told_apart_by_their_longer_runs() {
    let model = mechlab::models::by_name("duffing").unwrap();
    let mut short = settings(32);
    short.record = 4;
    short.method = Method::Taylor { tol: 1e-10 };
    let result = basins(model, &[0.3, 0.29, 1.2], &short, &|_| ()).unwrap();
    let kinds: Vec<&str> = result.attractors.iter().map(|a| a.kind.as_str()).collect();
    assert_eq!(kinds, ["period 4", "period 4"], "{:?}", result.attractors);

    let mut grid = settings(64);
    grid.transient = 100;
    grid.record = 16;
    grid.method = Method::Taylor { tol: 1e-10 };
    let params = [0.3, 0.27, 1.2];
    let result = basins(model, &params, &grid, &|_| ()).unwrap();
    let chaotic: Vec<_> = result
        .attractors
        .iter()
        .filter(|a| a.kind == CHAOTIC)
        .collect();
    assert!(!chaotic.is_empty(), "{:?}", result.attractors);
    for a in chaotic {
        let (lambda, error) = largest_exponent(model, &params, a, (1e-10, 100, 4000));
        assert!(lambda > 10.0 * error, "{a:?}: {lambda} ± {error}");
    }
}

/// Kapitza's pendulum with friction (μ = 0.1) shaken above the averaged
/// threshold A² > 2: two attractors, each a fixed point of the period map,
/// the hanging state (q = ±π: one attractor across the cut of the angle,
/// its cells neighbours around the circle) and the upright one (q = 0) it
/// stabilises, whose basin is the smaller.
#[test]
fn the_shaken_pendulum_with_friction_hangs_or_stands_upright() {
    let model = mechlab::models::by_name("kapitza").unwrap();
    let mut grid = settings(48);
    grid.ranges = [(-std::f64::consts::PI, std::f64::consts::PI), (-3.0, 3.0)];
    grid.transient = 300;
    grid.method = Method::Taylor { tol: 1e-10 };
    let result = basins(model, &[1.5, 0.1, 0.1], &grid, &|_| ()).unwrap();
    assert_eq!(result.attractors.len(), 2, "{:?}", result.attractors);
    let angle_to = |a: &[f64], q: f64| mechlab::analysis::period_map::wrap_angle(a[0] - q).abs();
    let hanging = result
        .attractors
        .iter()
        .find(|a| angle_to(&a.representative, std::f64::consts::PI) < 1e-2);
    let upright = result
        .attractors
        .iter()
        .find(|a| angle_to(&a.representative, 0.0) < 1e-2);
    let (Some(hanging), Some(upright)) = (hanging, upright) else {
        panic!("{:?}", result.attractors);
    };
    assert_eq!(
        (hanging.kind.as_str(), upright.kind.as_str()),
        ("period 1", "period 1")
    );
    assert!(
        upright.fraction < hanging.fraction && upright.starts >= 2,
        "{:?}",
        result.attractors
    );
    assert_eq!(result.diverged, 0);
}

/// Kapitza's pendulum with weak friction (μ = 0.01) after a short
/// transient: its orbits are still closing in on cycles (rotations among
/// them). None is called quasi-periodic, and each called "not settled" is
/// a cycle still being approached: its largest Lyapunov exponent, by the
/// attractor analysis, is negative beyond its stated error (three standard
/// errors).
#[test]
fn a_cycle_still_being_approached_is_not_called_quasi_periodic() {
    use mechlab::analysis::basins::{NOT_SETTLED, QUASI_PERIODIC};
    let model = mechlab::models::by_name("kapitza").unwrap();
    let mut grid = settings(32);
    grid.ranges = [(-std::f64::consts::PI, std::f64::consts::PI), (-3.0, 3.0)];
    grid.transient = 100;
    grid.method = Method::Taylor { tol: 1e-8 };
    let params = [1.5, 0.1, 0.01];
    let result = basins(model, &params, &grid, &|_| ()).unwrap();
    assert!(
        result.attractors.iter().all(|a| a.kind != QUASI_PERIODIC),
        "{:?}",
        result.attractors
    );
    let unsettled: Vec<_> = result
        .attractors
        .iter()
        .filter(|a| a.kind == NOT_SETTLED)
        .collect();
    assert!(!unsettled.is_empty(), "{:?}", result.attractors);
    for a in unsettled {
        let (lambda, error) = largest_exponent(model, &params, a, (1e-8, 0, 20_000));
        assert!(lambda + error < 0.0, "{a:?}: {lambda} ± {error}");
    }
}

/// Which well the unforced damped double well x'' + δx' − x + x³ = 0
/// from (x, p) settles in, by a hand-written RK4 (step 0.01): once its
/// energy p²/2 − x²/2 + x⁴/4 is negative the damping keeps it in the well
/// of x's sign (an orbit that creeps to the saddle for 400 time units is
/// called by its last x).
fn settles_right(delta: f64, (mut x, mut p): (f64, f64)) -> bool {
    let f = |x: f64, p: f64| (p, -delta * p + x - x * x * x);
    let h = 0.01;
    for _ in 0..40_000 {
        if p * p / 2.0 - x * x / 2.0 + x.powi(4) / 4.0 < 0.0 {
            break;
        }
        let (k1x, k1p) = f(x, p);
        let (k2x, k2p) = f(x + h / 2.0 * k1x, p + h / 2.0 * k1p);
        let (k3x, k3p) = f(x + h / 2.0 * k2x, p + h / 2.0 * k2p);
        let (k4x, k4p) = f(x + h * k3x, p + h * k3p);
        x += h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
        p += h / 6.0 * (k1p + 2.0 * k2p + 2.0 * k3p + k4p);
    }
    x > 0.0
}

/// The right well's share of the window's area by [`settles_right`] on a
/// grid of `n`² pixel centres.
fn right_share(delta: f64, [(x0, x1), (p0, p1)]: [(f64, f64); 2], n: usize) -> f64 {
    let centre = |lo: f64, hi: f64, i: usize| lo + (hi - lo) * (i as f64 + 0.5) / n as f64;
    let right = (0..n * n)
        .filter(|k| settles_right(delta, (centre(x0, x1, k % n), centre(p0, p1, k / n))))
        .count();
    right as f64 / (n * n) as f64
}

/// The basins' fractions on windows where no symmetry fixes them, against
/// the areas by a hand-written integration on a grid six times finer: the
/// grid's stated error bounds the distance in every case, and is within
/// 100 times it (where the distance is above the reference's own pixel).
#[test]
fn the_basins_fractions_errors_bound_their_distance_to_the_areas() {
    let model = mechlab::models::by_name("duffing").unwrap();
    let windows = [
        [(-1.3, 2.1), (-1.7, 2.4)],
        [(-0.8, 1.9), (-2.2, 0.9)],
        [(-2.5, 1.2), (-1.0, 2.6)],
        [(-1.1, 1.6), (-1.6, 1.3)],
        [(-0.4, 2.3), (-2.7, 2.0)],
        [(-1.9, 0.7), (-0.9, 1.9)],
    ];
    let mut ratios = Vec::new();
    for ranges in windows {
        for pixels in [24, 40] {
            let settings = BasinSettings {
                ranges,
                through: Some(vec![0.0, 0.0]),
                ..settings(pixels)
            };
            let map = basins(model, &[0.3, 0.0, 1.2], &settings, &|_| ()).unwrap();
            let reference = right_share(0.3, ranges, 6 * pixels);
            let right = map
                .attractors
                .iter()
                .find(|a| a.representative[0] > 0.0)
                .map_or((0.0, 0.0), |a| (a.fraction, a.grid_error));
            let distance = (right.0 - reference).abs();
            println!(
                "{ranges:?} at {pixels}²: right well {:.5} ± {:.1e} against {reference:.5} (off by {distance:.1e})",
                right.0, right.1
            );
            assert!(distance <= right.1, "{ranges:?} at {pixels}²");
            if distance > 1.0 / (6.0 * pixels as f64).powi(2) {
                ratios.push(right.1 / distance);
            }
        }
    }
    println!("stated over distance: {ratios:.1?}");
    assert!(ratios.iter().all(|&r| r <= 100.0), "{ratios:?}");
}

/// `accuracy` on the fractions: from RK4 at a coarse step and 16 pixels
/// per side, the map is refined until every fraction's stated error is
/// within 0.01, and then is within it of the hand-written areas.
#[test]
fn basins_asked_for_an_accuracy_reach_it() {
    let model = mechlab::models::by_name("duffing").unwrap();
    let ranges = [(-1.3, 2.1), (-1.7, 2.4)];
    let settings = BasinSettings {
        ranges,
        through: Some(vec![0.0, 0.0]),
        method: Method::Rk4 { step: 0.8 },
        accuracy: Some(0.01),
        ..settings(16)
    };
    let map = basins(model, &[0.3, 0.0, 1.2], &settings, &|_| ()).unwrap();
    let verdict = map.accuracy.clone().unwrap();
    println!("{verdict}; {} pixels per side", map.pixels);
    assert!(verdict.contains(" reached"), "{verdict}");
    assert!(map.pixels > 16);
    let check = map.class_check.as_ref().unwrap();
    assert!(check.sampled >= 300, "{check:?}");
    let reference = right_share(0.3, ranges, 240);
    for a in &map.attractors {
        assert!(a.fraction_error <= 0.01, "{a:?}");
        let truth = if a.representative[0] > 0.0 {
            reference
        } else {
            1.0 - reference
        };
        assert!((a.fraction - truth).abs() <= 0.01, "{a:?} against {truth}");
    }
}
