//! Basins of attraction: the unforced damped double well against its
//! symmetry and its equilibria, and the forced one's attractors checked as
//! cycles of the period map by an independent integration.

use mechlab::analysis::basins::{basins, BasinSettings, DIVERGED};
use mechlab::models::duffing;
use mechlab::ode::{Integrator, Method};

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
    }
}

/// x'' + 0.3x' − x + x³ = 0: two attractors found unaided, the wells'
/// bottoms (±1, 0) to 1e-9, each a fixed point; the basins exchange under
/// (x, p) → (−x, −p) pixel for pixel (the grid is symmetric), so each holds
/// half of the starts.
#[test]
fn the_unforced_double_well_has_two_symmetric_basins() {
    let model = mechlab::models::by_name("duffing").unwrap();
    let result = basins(model, &[0.3, 0.0, 1.2], &settings(24)).unwrap();
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
    let result = basins(model, &params, &settings(16)).unwrap();
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
    let error = basins(duffing, &[0.3, 0.0, 1.2], &bad).unwrap_err();
    assert!(error.to_string().contains("positive cell"), "{error}");
    let henon = mechlab::models::by_name("henon_heiles").unwrap();
    let error = basins(henon, &[1.0], &settings(8)).unwrap_err();
    assert!(error.to_string().contains("no fast phase"), "{error}");
}
