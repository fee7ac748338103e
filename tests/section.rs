//! Poincaré sections at a fixed energy (`analysis::section`), checked on
//! Hénon–Heiles: with the coupling off it is two equal oscillators, whose
//! section map is the identity (every crossing returns to the seed); with
//! it on, every crossing lies on the plane and at H = E.

use mechlab::analysis::section::{
    parse_plane, section, seeds_across, OrbitEnd, PlaneTextProblem, SectionError, SectionSettings,
};
use mechlab::analysis::Refusal;
use mechlab::models;

fn settings(energy: f64) -> SectionSettings {
    SectionSettings {
        plane: vec![1.0, 0.0],
        value: 0.0,
        rising: true,
        energy,
        crossings: 60,
        t_max: 2000.0,
        tol: 1e-12,
        phase: 0.0,
        slab: 0.05,
    }
}

#[test]
fn equal_oscillators_return_to_their_seed_at_every_crossing() {
    let model = models::by_name("henon_heiles").unwrap();
    let params = [0.0];
    let energy = 0.3;
    let seeds = [[0.2, 0.0], [-0.5, 0.3], [0.1, -0.6]];
    let result = section(model, &params, &seeds, &settings(energy)).unwrap();
    for (orbit, seed) in result.orbits.iter().zip(&seeds) {
        assert_eq!(orbit.points.len(), 60);
        // p_x from H = E on the rising branch: (p_x² + y² + p_y²)/2 = E.
        let p_x = (2.0 * energy - seed[0] * seed[0] - seed[1] * seed[1]).sqrt();
        assert!((orbit.start[2] - p_x).abs() < 1e-12, "{:?}", orbit.start);
        for p in &orbit.points {
            let off = (p[0] - seed[0]).hypot(p[1] - seed[1]);
            assert!(off < 1e-8, "seed {seed:?}: a crossing at {p:?}");
        }
    }
}

#[test]
fn henon_heiles_crossings_lie_on_the_plane_at_the_energy() {
    let model = models::by_name("henon_heiles").unwrap();
    let params = [1.0];
    let s = settings(0.125);
    let seeds = seeds_across(model, &params, &s, 2.0, 8);
    assert_eq!(seeds.len(), 8);
    // On x = 0 the accessible stretch of y is where y²/2 − y³/3 < 1/8: it
    // ends at the roots of that cubic, −0.4149… and 0.6536… (the branch
    // beyond the barrier at y = 1 is not seeded).
    assert!(
        seeds.iter().all(|s| s[0] > -0.42 && s[0] < 0.66),
        "{seeds:?}"
    );
    let result = section(model, &params, &seeds, &s).unwrap();
    assert!(
        result.largest_energy_drift < 1e-9,
        "{}",
        result.largest_energy_drift
    );
    assert!(
        result.largest_plane_distance < 1e-10,
        "{}",
        result.largest_plane_distance
    );
    for orbit in &result.orbits {
        assert_eq!(orbit.points.len(), 60);
        for p in &orbit.points {
            // Every crossing is inside the energy's region on the plane.
            let v = p[0] * p[0] / 2.0 - p[0].powi(3) / 3.0;
            assert!(p[1] * p[1] / 2.0 + v <= 0.125 + 1e-9, "{p:?}");
        }
    }
    let falling = SectionSettings {
        rising: false,
        ..s.clone()
    };
    let down = section(model, &params, &seeds[..1], &falling).unwrap();
    assert!(down.orbits[0].start[2] < 0.0);
}

#[test]
fn a_section_says_why_it_cannot_be_drawn() {
    let hh = models::by_name("henon_heiles").unwrap();
    // V(0, 0.6) = 0.18 − 0.072 = 0.108 > E.
    match section(hh, &[1.0], &[[0.6, 0.0]], &settings(0.01)) {
        Err(SectionError::Inaccessible { least, .. }) => assert!((least - 0.108).abs() < 1e-12),
        other => panic!("{other:?}"),
    }
    // No seeds (energy below the minimum, nothing accessible): named, not
    // an empty figure.
    assert!(matches!(
        section(hh, &[1.0], &[], &settings(-1.0)),
        Err(SectionError::NoSeeds { .. })
    ));
    assert!(seeds_across(hh, &[1.0], &settings(-1.0), 2.0, 8).is_empty());
    let kapitza = models::by_name("kapitza").unwrap();
    let defaults = kapitza.dynamic.defaults();
    assert!(matches!(
        section(kapitza, &defaults, &[[0.0, 0.0]], &settings(1.0)),
        Err(SectionError::Refused(Refusal::FastPhase { .. }))
    ));
    let zero_tolerance = SectionSettings {
        tol: 0.0,
        ..settings(0.1)
    };
    assert!(matches!(
        section(hh, &[1.0], &[[0.0, 0.0]], &zero_tolerance),
        Err(SectionError::Refused(Refusal::Setting { .. }))
    ));
}

/// MEGNO maps of the section (`analysis::section_map`): the uncoupled
/// oscillators are isochronous, so no tangent vector grows and ⟨Y⟩ stays
/// near 0 on every pixel; Hénon–Heiles is nearly all regular at E = 1/12
/// and mostly chaotic at E = 1/6, as Hénon and Heiles found.
#[test]
fn megno_maps_find_no_chaos_in_oscillators_and_chaos_growing_with_energy() {
    use mechlab::analysis::section_map::{section_map, SectionMapSettings};
    let model = models::by_name("henon_heiles").unwrap();
    let map = |coupling: f64, energy: f64| {
        let settings = SectionMapSettings {
            section: settings(energy),
            pixels: 24,
            t_max: 400.0,
            extent: 1.0,
            check: 0,
        };
        section_map(model, &[coupling], &settings).unwrap()
    };
    let free = map(0.0, 0.125);
    assert!(free.accessible > 300, "{}", free.accessible);
    let largest = free
        .megno
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .fold(0.0, f64::max);
    assert!(largest < 0.5, "⟨Y⟩ up to {largest}");
    let (low, high) = (map(1.0, 1.0 / 12.0), map(1.0, 1.0 / 6.0));
    assert!(
        low.chaotic_fraction < 0.1,
        "E = 1/12: {}",
        low.chaotic_fraction
    );
    assert!(
        high.chaotic_fraction > 0.5,
        "E = 1/6: {}",
        high.chaotic_fraction
    );
    assert_eq!(low.failed + high.failed, 0);
}

/// The free double pendulum (`models/free_double_pendulum.toml`): near
/// the bottom of its well (E = −2.9, the least H being −3) it is nearly
/// linear, two normal modes, and its MEGNO map finds no chaos; at
/// E = −1 most of the section is chaotic. Its second angle is drawn on
/// its circle, [−π, π), however often the rod turns.
#[test]
fn the_free_double_pendulum_goes_from_regular_to_chaotic_with_energy() {
    use mechlab::analysis::section_map::{section_map, SectionMapSettings};
    let model = models::by_name("free_double_pendulum").unwrap();
    let params = model.dynamic.defaults();
    let map = |energy: f64| {
        let settings = SectionMapSettings {
            section: settings(energy),
            pixels: 24,
            t_max: 300.0,
            extent: 3.2,
            check: 0,
        };
        section_map(model, &params, &settings).unwrap()
    };
    let (low, high) = (map(-2.9), map(-1.0));
    assert_eq!(low.chaotic_fraction, 0.0, "E = −2.9");
    assert!(
        high.chaotic_fraction > 0.6,
        "E = −1: {}",
        high.chaotic_fraction
    );
    let turning = section(model, &params, &[[0.0, 0.0]], &settings(0.0)).unwrap();
    let angles = turning.orbits[0].points.iter().map(|p| p[0]);
    assert!(angles
        .clone()
        .all(|a| (-std::f64::consts::PI..std::f64::consts::PI).contains(&a)));
}

/// Planes given as linear functions of the coordinates.
#[test]
fn planes_are_read_as_linear_functions_of_the_coordinates() {
    let names = ["x", "y"];
    let read = |text: &str| parse_plane(text, &names);
    assert_eq!(read("x").unwrap(), [1.0, 0.0]);
    assert_eq!(read("x - y").unwrap(), [1.0, -1.0]);
    assert_eq!(read("x + 0.5*y").unwrap(), [1.0, 0.5]);
    assert_eq!(read("-2*y").unwrap(), [0.0, -2.0]);
    assert_eq!(read("1e-3*x − y").unwrap(), [1e-3, -1.0]);
    use PlaneTextProblem::{Coefficient, Term, Zero};
    for (bad, problem) in [
        ("z", Term),
        ("x*", Coefficient),
        ("0*x", Zero),
        ("", Zero),
        ("2*x*y", Term),
        ("inf*x", Zero),
    ] {
        match read(bad) {
            Err(e) => assert_eq!(e.problem, problem, "{bad:?}: {e}"),
            Ok(a) => panic!("{bad:?} was read as {a:?}"),
        }
    }
}

/// On the tilted plane x + 0.5 y = 0 the seeds lie on the plane at H = E,
/// the uncoupled (isochronous) oscillators return to their seed, and the
/// coupled section map is area-preserving in the plane's canonical chart
/// (Q_o, P_o) = (y, p_y − 0.5 p_x): its Jacobian's determinant, by central
/// differences, is 1.
#[test]
fn a_tilted_plane_has_a_canonical_chart() {
    let model = models::by_name("henon_heiles").unwrap();
    let tilted = |energy: f64, crossings: usize| SectionSettings {
        plane: vec![1.0, 0.5],
        crossings,
        ..settings(energy)
    };
    let seeds = [[0.2, 0.1], [-0.3, -0.2]];
    let free = section(model, &[0.0], &seeds, &tilted(0.3, 20)).unwrap();
    assert_eq!(free.plane, "x + 0.5·y = 0 (increasing)");
    assert_eq!(free.axes, ["y".to_string(), "p_y − 0.5·p_x".to_string()]);
    for (orbit, seed) in free.orbits.iter().zip(&seeds) {
        let y = &orbit.start;
        assert!((y[0] + 0.5 * y[1]).abs() < 1e-15);
        let energy = (y[0] * y[0] + y[1] * y[1] + y[2] * y[2] + y[3] * y[3]) / 2.0;
        assert!((energy - 0.3).abs() < 1e-12);
        // Rising: (x + 0.5 y)' = px + 0.5 py > 0, and P_o is the seed's.
        assert!(y[2] + 0.5 * y[3] > 0.0);
        assert!((y[3] - 0.5 * y[2] - seed[1]).abs() < 1e-14);
        assert_eq!(orbit.points.len(), 20);
        for p in &orbit.points {
            assert!((p[0] - seed[0]).hypot(p[1] - seed[1]) < 1e-8, "{p:?}");
        }
    }
    // The same plane written as −x − 0.5 y, crossed falling: the same map.
    let turned = SectionSettings {
        plane: vec![-1.0, -0.5],
        rising: false,
        ..tilted(0.125, 2)
    };
    let first_return = |settings: &SectionSettings, seed: [f64; 2]| {
        section(model, &[1.0], &[seed], settings).unwrap().orbits[0].points[1]
    };
    let seed = [0.1, 0.05];
    let (a, b) = (
        first_return(&tilted(0.125, 2), seed),
        first_return(&turned, seed),
    );
    assert!((a[0] - b[0]).hypot(a[1] - b[1]) < 1e-12, "{a:?} {b:?}");
    // Area preservation of the coupled map at E = 1/8.
    let h = 1e-5;
    let column = |k: usize| {
        let (mut plus, mut minus) = (seed, seed);
        plus[k] += h;
        minus[k] -= h;
        let (p, m) = (
            first_return(&tilted(0.125, 2), plus),
            first_return(&tilted(0.125, 2), minus),
        );
        [(p[0] - m[0]) / (2.0 * h), (p[1] - m[1]) / (2.0 * h)]
    };
    let (c0, c1) = (column(0), column(1));
    let determinant = c0[0] * c1[1] - c0[1] * c1[0];
    assert!((determinant - 1.0).abs() < 1e-6, "det {determinant}");
    // The map is not trivial there: the return moved the seed.
    assert!((a[0] - seed[0]).hypot(a[1] - seed[1]) > 1e-3, "{a:?}");
}

/// The shaken double pendulum's defaults with the base's amplitude a and
/// frequency ν.
fn shaken_params(a: f64, nu: f64) -> Vec<f64> {
    let model = models::by_name("double_pendulum").unwrap();
    let mut params = model.dynamic.defaults();
    for (name, value) in [("a", a), ("nu", nu)] {
        let k = model.info.parameter_names.iter().position(|n| *n == name);
        params[k.unwrap()] = value;
    }
    params
}

/// The free double pendulum (m = l = g = 1) with its angles from the
/// upward vertical, written by hand: M φ'' = f with
/// M = [[2, c], [c, 1]], c = cos(φ₁ − φ₂), s = sin(φ₁ − φ₂),
/// f = (2 sin φ₁ − s φ₂'², sin φ₂ + s φ₁'²); state (φ₁, φ₂, φ₁', φ₂').
fn upright_double_pendulum(y: [f64; 4]) -> [f64; 4] {
    let (c, s) = ((y[0] - y[1]).cos(), (y[0] - y[1]).sin());
    let f = [
        2.0 * y[0].sin() - s * y[3] * y[3],
        y[1].sin() + s * y[2] * y[2],
    ];
    let det = 2.0 - c * c;
    [
        y[2],
        y[3],
        (f[0] - c * f[1]) / det,
        (2.0 * f[1] - c * f[0]) / det,
    ]
}

/// A model with a fast phase gets a slice of its period map: its orbit
/// sampled at the forcing's phase, the points within a slab of the plane
/// moving across it the way asked, its seeds at the averaged energy
/// H̄ = E. With the base at rest (a = 0) the vibrating double pendulum is
/// the free one, and H̄ = H: its slice equals the hand-written equations'
/// orbit (RK4) sampled every period T = 2π/ν and filtered alike. Vibrated
/// (a = 5), every kept point is in the slab, and H̄ stays near E.
#[test]
fn a_model_with_a_fast_phase_gets_a_slice_of_its_period_map() {
    use std::f64::consts::{PI, TAU};
    let shaken = models::by_name("double_pendulum").unwrap();
    let params = shaken_params(0.0, 100.0);
    let period = TAU / 100.0;
    let slice = SectionSettings {
        value: PI,
        crossings: 25,
        slab: 0.05,
        t_max: 2000.0,
        ..settings(-2.5)
    };
    let seed = [PI + 0.3, 0.0];
    let at_rest = section(shaken, &params, &[seed], &slice).unwrap();
    let orbit = &at_rest.orbits[0];
    assert_eq!(orbit.crossings, 25);
    // The reference: (φ, p) → (φ, φ') by M⁻¹, RK4 at T/16.
    let y = &orbit.start;
    let c = (y[0] - y[1]).cos();
    let det = 2.0 - c * c;
    let mut z = [
        y[0],
        y[1],
        (y[2] - c * y[3]) / det,
        (2.0 * y[3] - c * y[2]) / det,
    ];
    let wrap = |x: f64| (x + PI).rem_euclid(TAU) - PI;
    let mut expected = Vec::new();
    let h = period / 16.0;
    while expected.len() < 24 {
        for _ in 0..16 {
            let k1 = upright_double_pendulum(z);
            let at = |k: &[f64; 4], f: f64| std::array::from_fn(|i| z[i] + f * h * k[i]);
            let k2 = upright_double_pendulum(at(&k1, 0.5));
            let k3 = upright_double_pendulum(at(&k2, 0.5));
            let k4 = upright_double_pendulum(at(&k3, 1.0));
            z = std::array::from_fn(|i| z[i] + h / 6.0 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]));
        }
        let offset = wrap(z[0] - PI);
        assert!(
            (offset.abs() - 0.05).abs() > 1e-6,
            "a sample on the slab's edge"
        );
        if offset.abs() < 0.05 && z[2] > 0.0 {
            let p2 = (z[0] - z[1]).cos() * z[2] + z[3];
            expected.push([wrap(z[1]), p2]);
        }
    }
    for (p, e) in orbit.points[1..].iter().zip(&expected) {
        assert!(
            wrap(p[0] - e[0]).abs() < 1e-7 && (p[1] - e[1]).abs() < 1e-7,
            "{p:?} against {e:?}"
        );
    }
    // Vibrated (a = 5): every kept point in the slab, and H̄ conserved as
    // ε = 1/ν → 0, at first order or better: its largest drift falls at
    // least three-fold when ν quadruples (0.81 at ν = 100, 0.15 at 400).
    let drift = |nu: f64| {
        let vibrated = shaken_params(5.0, nu);
        let raised = SectionSettings {
            energy: -1.5,
            ..slice.clone()
        };
        let orbit = section(shaken, &vibrated, &[seed], &raised).unwrap().orbits[0].clone();
        assert_eq!(orbit.crossings, 25);
        let averaged = shaken
            .dynamic
            .averaged_energy(&vibrated, &orbit.start)
            .unwrap();
        assert!((averaged - -1.5).abs() < 1e-12);
        assert!(orbit.plane_distance < 0.05);
        orbit.energy_drift
    };
    let (coarse, fine) = (drift(100.0), drift(400.0));
    assert!(coarse / fine > 3.0, "H̄ drifted by {coarse}, then by {fine}");
}

/// Every model in models/ gets a section or a named reason, never a panic:
/// its seeds are searched, and its section drawn from them (or from one
/// seed at the origin where none was found).
#[test]
fn every_model_gets_a_section_or_a_named_reason() {
    for info in models::ALL {
        let model = models::by_name(info.name).unwrap();
        let params = model.dynamic.defaults();
        let s = SectionSettings {
            crossings: 5,
            t_max: 50.0,
            ..settings(0.5)
        };
        let mut seeds = seeds_across(model, &params, &s, 2.0, 3);
        if seeds.is_empty() {
            seeds.push([0.0, 0.0]);
        }
        match section(model, &params, &seeds, &s) {
            Ok(result) => {
                assert_eq!(result.orbits.len(), seeds.len(), "{}", info.name);
                // Every orbit has its crossings, or says why not.
                for o in &result.orbits {
                    assert_eq!(o.points.len(), o.crossings, "{}", info.name);
                    assert_eq!(
                        o.end == OrbitEnd::Complete,
                        o.crossings == s.crossings,
                        "{}: {} crossings, {}",
                        info.name,
                        o.crossings,
                        o.end
                    );
                }
            }
            Err(e) => assert!(!e.to_string().is_empty(), "{}", info.name),
        }
    }
}

/// The swinging Atwood machine on the plane θ = 0: r = 0 is a singular
/// point of its chart and r < 0 an open branch of the energy surface. The
/// seeds are placed on the closed stretch 0 < r < E/(g(M − m)), where
/// orbits recur; an orbit started on the open branch ends early and says
/// why instead of showing one point and nothing else.
#[test]
fn orbits_that_end_early_say_why_and_seeds_go_where_orbits_recur() {
    let model = &mechlab_test_models::swinging_atwood::MODEL;
    let params = model.dynamic.defaults(); // M = 3, m = 1, g = 1
    let s = SectionSettings {
        plane: vec![0.0, 1.0],
        energy: 1.0,
        crossings: 20,
        t_max: 400.0,
        ..settings(1.0)
    };
    let seeds = seeds_across(model, &params, &s, 2.0, 12);
    assert_eq!(seeds.len(), 12);
    let barrier = 1.0 / (1.0 * (3.0 - 1.0));
    assert!(
        seeds.iter().all(|&[r, _]| r > 0.0 && r < barrier),
        "{seeds:?}"
    );
    let result = section(model, &params, &seeds, &s).unwrap();
    // At M = 3m the orbits from these seeds reach the pulley (r = 0) in
    // finite time, where the polar chart is singular: they say so (or,
    // stepped across it, that they left along r < 0).
    let mut singular = 0;
    for (k, end) in result.ended_early() {
        match end {
            OrbitEnd::Singular { at, .. } => {
                assert_eq!(at[0].0, "r");
                assert!(at[0].1.abs() < 1e-4, "orbit {k}: {end}");
                singular += 1;
            }
            // Stepped across r = 0 onto the open branch r < 0.
            OrbitEnd::Escaped { coordinate, .. } => assert_eq!(coordinate, "r"),
            OrbitEnd::TimeLimit { .. } => {}
            other => panic!("orbit {k} ended as {other}"),
        }
    }
    assert!(singular > 0);
    // On the open branch: the rope's swinging side runs off to r → −∞.
    let open = section(model, &params, &[[-1.0, 0.0]], &s).unwrap();
    let orbit = &open.orbits[0];
    assert!(orbit.crossings < s.crossings);
    match &orbit.end {
        OrbitEnd::Escaped {
            coordinate, value, ..
        } => {
            assert_eq!(coordinate, "r");
            assert!(*value < -1e3, "{value}");
        }
        OrbitEnd::Failed { .. } => {}
        other => panic!("the open branch's orbit ended as {other:?}"),
    }
    assert!(!orbit.end.to_string().is_empty());
}

/// The MEGNO map of a model with a fast phase: every pixel's orbit from
/// the plane at the averaged energy, its tangent vector sampled every
/// whole number of periods. Low in the double pendulum's well (H̄ = −2.5,
/// near its two normal modes) no pixel is chaotic with the base at rest
/// (a = 0) or shaken gently (a = 0.3, ν = 20); shaken hard (a = 2, a
/// pivot acceleration of 40 g) most of the section is chaotic.
#[test]
fn a_model_with_a_fast_phase_gets_a_megno_map_of_its_slice() {
    use mechlab::analysis::section_map::{section_map, SectionMapSettings};
    use std::f64::consts::PI;
    let shaken = models::by_name("double_pendulum").unwrap();
    let map = |a: f64| {
        let params = shaken_params(a, 20.0);
        let settings = SectionMapSettings {
            section: SectionSettings {
                value: PI,
                ..settings(-2.5)
            },
            pixels: 12,
            t_max: 100.0,
            extent: 3.2,
            check: 0,
        };
        section_map(shaken, &params, &settings).unwrap()
    };
    let (rest, gentle, hard) = (map(0.0), map(0.3), map(2.0));
    assert_eq!(hard.energy_of, "H̄");
    for m in [&rest, &gentle, &hard] {
        assert!(
            m.accessible > 50 && m.failed == 0,
            "{} accessible",
            m.accessible
        );
    }
    assert_eq!(rest.chaotic, 0);
    assert_eq!(gentle.chaotic, 0);
    assert!(hard.chaotic_fraction > 0.5, "{}", hard.chaotic_fraction);
}

/// The frequency map of Hénon–Heiles at E = 1/8 on the MEGNO map's grid:
/// on the pixels MEGNO finds regular (⟨Y⟩ < 2.2: KAM tori) the diffusion
/// index is small, in the chaotic sea (⟨Y⟩ > 6) large, by four orders
/// of magnitude (T = 1000); with no coupling (two uncoupled oscillators) every orbit's
/// frequencies are the oscillators', 1 and 1, to 1e-9.
#[test]
fn the_diffusion_index_is_small_on_tori_and_large_in_the_chaotic_sea() {
    use mechlab::analysis::frequency_map::{frequency_map, FrequencyMapSettings};
    use mechlab::analysis::section_map::{section_map, SectionMapSettings};
    let model = models::by_name("henon_heiles").unwrap();
    let (pixels, t_max, extent) = (24, 1000.0, 1.0);
    let megno = section_map(
        model,
        &[1.0],
        &SectionMapSettings {
            section: settings(0.125),
            pixels,
            t_max,
            extent,
            check: 0,
        },
    )
    .unwrap();
    let fma = |coupling: f64| {
        let settings = FrequencyMapSettings {
            section: settings(0.125),
            pixels,
            t_max,
            samples: 2048,
            extent,
            check: 0,
        };
        frequency_map(model, &[coupling], &settings).unwrap()
    };
    let map = fma(1.0);
    assert_eq!(map.accessible, megno.accessible);
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let index_where = |keep: &dyn Fn(f64) -> bool| {
        let values: Vec<f64> = megno
            .megno
            .iter()
            .zip(&map.diffusion)
            .filter(|(y, d)| y.is_finite() && d.is_finite() && keep(**y))
            .map(|(_, d)| *d)
            .collect();
        (values.len(), median(values))
    };
    let (tori, on_tori) = index_where(&|y| y < 2.2);
    let (sea, in_sea) = index_where(&|y| y > 6.0);
    assert!(tori > 50 && sea > 50, "{tori} tori, {sea} in the sea");
    // Measured: −5.96 on tori, −1.55 in the sea.
    assert!(
        on_tori < -5.0 && in_sea > -2.5,
        "median index {on_tori} on tori, {in_sea} in the sea"
    );
    let free = fma(0.0);
    let worst = free
        .frequencies
        .iter()
        .filter(|nu| nu[0].is_finite())
        .flat_map(|nu| nu.iter().map(|f| (f - 1.0).abs()))
        .fold(0.0, f64::max);
    assert!(worst < 1e-9, "uncoupled: {worst}");
}

/// The free double pendulum written with two Cartesian points on two rods
/// has the angle model's section: on x₁ = 0 (φ₁ = 0, rising), orbits from
/// the same states cross at the same points, x₂ = l₂ sin φ₂. The angle
/// model's seeds come from the Cartesian starts by a hand-written
/// Legendre map.
#[test]
fn two_points_on_two_rods_cross_their_plane_where_the_angle_model_does() {
    let points = &mechlab_test_models::cartesian_free_double_pendulum::MODEL;
    let angles = models::by_name("free_double_pendulum").unwrap();
    let params = [1.0, 1.0, 1.0, 1.0, 1.0]; // m1, m2, l1, l2, g
    let energy = -2.5; // the hanging rest is at −3
    let cartesian = SectionSettings {
        plane: parse_plane("x1", points.info.coordinates).unwrap(),
        crossings: 25,
        t_max: 500.0,
        ..settings(energy)
    };
    let seeds = seeds_across(points, &params, &cartesian, 2.0, 4);
    assert_eq!(seeds.len(), 4);
    // On x₁ = 0 at E = −2.5: −1 − cos φ₂ − … ≤ E needs |x₂| < sin(acos 0.5).
    assert!(seeds.iter().all(|s| s[0].abs() < 0.87), "{seeds:?}");
    let drawn = section(points, &params, &seeds, &cartesian).unwrap();
    assert_eq!(drawn.axes, ["x₂", "x₂′"]);
    assert!(
        drawn.largest_energy_drift < 1e-9,
        "{}",
        drawn.largest_energy_drift
    );
    // The event located to 1e-12 in time, then the projection.
    assert!(
        drawn.largest_plane_distance < 1e-10,
        "{}",
        drawn.largest_plane_distance
    );
    // Each Cartesian start as the angle model's seed (φ₂, p₂), φ₁ = 0.
    let (m1, m2, l1, l2) = (1.0, 1.0, 1.0, 1.0);
    let mut angle_seeds = Vec::new();
    let mut angle_p1 = Vec::new();
    for orbit in &drawn.orbits {
        let y = &orbit.start;
        assert_eq!(orbit.end, OrbitEnd::Complete);
        let (u, w) = (y[2] - y[0], y[1] - y[3]);
        let phi2 = u.atan2(w);
        let phi1_rate = (-y[1] * y[4] + y[0] * y[5]) / (l1 * l1);
        let phi2_rate = (w * (y[6] - y[4]) - u * (y[5] - y[7])) / (l2 * l2);
        let m12 = m2 * l1 * l2 * phi2.cos(); // cos(φ₁ − φ₂) at φ₁ = 0
        angle_p1.push((m1 + m2) * l1 * l1 * phi1_rate + m12 * phi2_rate);
        angle_seeds.push([phi2, m12 * phi1_rate + m2 * l2 * l2 * phi2_rate]);
    }
    let angle = SectionSettings {
        plane: vec![1.0, 0.0],
        crossings: 25,
        t_max: 500.0,
        ..settings(energy)
    };
    let reference = section(angles, &params, &angle_seeds, &angle).unwrap();
    let mut worst: f64 = 0.0;
    for ((a, b), p1) in reference.orbits.iter().zip(&drawn.orbits).zip(&angle_p1) {
        // The angle model solved p₁ from H = E as the constraints did.
        assert!(
            (a.start[2] - p1).abs() < 1e-10,
            "p1 {} against {p1}",
            a.start[2]
        );
        assert_eq!(a.points.len(), b.points.len());
        for (pa, pb) in a.points.iter().zip(&b.points) {
            worst = worst.max((l2 * pa[0].sin() - pb[0]).abs());
        }
    }
    assert!(worst < 1e-8, "x₂ differs by {worst:e}");
}

/// A section on constraints is refused, with the reason, where it does not
/// apply: a fast phase, one degree of freedom, a nonholonomic constraint,
/// a plane of two coordinates.
#[test]
fn sections_on_constraints_are_refused_where_they_do_not_apply() {
    let refused = |name: &str, plane: Vec<f64>| {
        let model = models::by_name(name).unwrap();
        let params = model.dynamic.defaults();
        let s = SectionSettings {
            plane,
            ..settings(0.0)
        };
        match section(model, &params, &[[0.0, 0.0]], &s) {
            Err(SectionError::Refused(refusal)) => refusal,
            other => panic!("{name}: {other:?}"),
        }
    };
    assert!(matches!(
        refused("four_bar", vec![1.0, 0.0, 0.0]),
        Refusal::FastPhase { .. }
    ));
    assert!(matches!(
        refused("slider_crank", vec![1.0, 0.0, 0.0]),
        Refusal::Dimension { dof: 1, .. }
    ));
    let nonholonomic = refused("chaplygin_sleigh", vec![1.0, 0.0, 0.0]);
    assert!(
        nonholonomic.to_string().contains("holonomic"),
        "{nonholonomic}"
    );
    let points = &mechlab_test_models::cartesian_free_double_pendulum::MODEL;
    let s = SectionSettings {
        plane: vec![1.0, 0.0, 1.0, 0.0],
        ..settings(-2.5)
    };
    match section(points, &[1.0; 5], &[[0.0, 0.0]], &s) {
        Err(SectionError::Refused(r)) => assert!(r.to_string().contains("one coordinate"), "{r}"),
        other => panic!("{other:?}"),
    }
}

/// The section's frequency map states its tunes' integration error: on
/// the uncoupled Hénon–Heiles oscillators every tune is exactly 1, so a
/// loose tolerance's error in the tunes is their distance from 1, and the
/// check (orbits rerun at a hundredth of the tolerance) states it within
/// a factor 2, median and largest alike.
#[test]
fn the_section_frequency_maps_tune_check_states_its_error() {
    use mechlab::analysis::frequency_map::{frequency_map, FrequencyMapSettings};
    let model = models::by_name("henon_heiles").unwrap();
    let pixels = 12;
    let settings = FrequencyMapSettings {
        section: SectionSettings {
            tol: 1e-5,
            ..settings(0.125)
        },
        pixels,
        t_max: 1000.0,
        samples: 2048,
        extent: 1.0,
        check: pixels * pixels,
    };
    let map = frequency_map(model, &[0.0], &settings).unwrap();
    let errors: Vec<f64> = (map.frequencies.iter())
        .zip(&map.diffusion)
        .filter(|(nu, d)| nu[0].is_finite() && **d < -4.0)
        .flat_map(|(nu, _)| nu.iter().map(|f| (f - 1.0).abs()))
        .collect();
    crate::common::assert_tune_check_states(&map.tune_check.unwrap(), errors);
}

/// The MEGNO map's class check is the map's own reclassification: with
/// every pixel sampled, its count of class changes is that between the
/// map and the same map at a hundredth of the tolerance, pixel for pixel.
#[test]
fn the_megno_maps_class_check_counts_the_tighter_maps_changes() {
    use mechlab::analysis::section_map::{section_map, SectionMapSettings, CHAOS_THRESHOLD};
    let model = models::by_name("henon_heiles").unwrap();
    let pixels = 16;
    let map = |tol: f64, check: usize| {
        let settings = SectionMapSettings {
            section: SectionSettings {
                tol,
                ..settings(0.125)
            },
            pixels,
            t_max: 400.0,
            extent: 1.0,
            check,
        };
        section_map(model, &[1.0], &settings).unwrap()
    };
    let (loose, tight) = (map(1e-3, pixels * pixels), map(1e-5, 0));
    let class = |y: f64| y.is_finite().then_some(y > CHAOS_THRESHOLD);
    let pairs: Vec<_> = (loose.megno.iter().zip(&tight.megno))
        .filter_map(|(a, b)| Some((class(*a)?, class(*b)?)))
        .collect();
    let changed = pairs.iter().filter(|(a, b)| a != b).count();
    let check = loose.class_check.unwrap();
    eprintln!("{check:?}; {changed} of {} change", pairs.len());
    assert_eq!((check.sampled, check.changed), (pairs.len(), changed));
    assert!(check.sampled > 100 && check.changed > 0, "{check:?}");
}

/// Asked for an accuracy, the section's maps are run again a hundredfold
/// tighter until their checks are within it: the uncoupled oscillators'
/// frequency map from tol 1e-5, asked for 1e-9, has every regular tune
/// within twice that of its exact value 1; the coupled model's MEGNO map,
/// asked for a share of 2 %, checks enough pixels to state it.
#[test]
fn the_sections_maps_asked_for_an_accuracy_reach_it() {
    use mechlab::analysis::section::{section_study, SectionOptions};
    use mechlab::settings::Declared;
    let model = models::by_name("henon_heiles").unwrap();
    let options = SectionOptions::default()
        .with_texts([
            ("orbits", "0"),
            ("frequencies", "12"),
            ("extent", "1"),
            ("map_time", "1000"),
            ("samples", "2048"),
            ("check", "144"),
            ("tol", "1e-5"),
            ("accuracy", "1e-9"),
        ])
        .unwrap();
    let study = section_study(model, &[0.0], &options, &|_| ()).unwrap();
    let map = study.frequency_map.unwrap();
    let said = map.accuracy.clone().unwrap();
    assert!(said.contains("1e-9 reached"), "{said}");
    assert!(map.tune_check.as_ref().unwrap().largest <= 1e-9);
    let worst = (map.frequencies.iter())
        .zip(&map.diffusion)
        .filter(|(nu, d)| nu[0].is_finite() && **d < -4.0)
        .flat_map(|(nu, _)| nu.iter().map(|f| (f - 1.0).abs()))
        .fold(0.0, f64::max);
    assert!(worst <= 2e-9, "{worst:e} ({said})");
    let megno = SectionOptions::default()
        .with_texts([
            ("orbits", "0"),
            ("map", "16"),
            ("extent", "1"),
            ("map_time", "400"),
            ("tol", "1e-3"),
            ("accuracy", "0.02"),
        ])
        .unwrap();
    let map = section_study(model, &[1.0], &megno, &|_| ())
        .unwrap()
        .megno_map
        .unwrap();
    let said = map.accuracy.clone().unwrap();
    let check = map.class_check.unwrap();
    assert!(
        said.contains("0.02 reached") || said.contains("2e-2 reached"),
        "{said}"
    );
    assert!(check.fraction.max(check.error) <= 0.02, "{check:?}");
}

/// The section's crossings' stated error against the closed form: for the
/// uncoupled oscillators (Hénon–Heiles at λ = 0) both motions have period
/// 2π, so every crossing of x = 0 is the seed itself. Over 200 crossings of
/// three orbits at three tolerances, each orbit's stated error bounds its
/// largest distance to the seed, within 100 times it; asked for 1e-9 from
/// 1e-5, the crossings are within it.
#[test]
fn the_sections_crossings_stated_errors_bound_their_distance_to_the_closed_form() {
    use mechlab::analysis::section::{section_study, SectionOptions};
    use mechlab::settings::Declared;
    let model = models::by_name("henon_heiles").unwrap();
    let seeds = [[0.1, 0.05], [0.3, -0.1], [-0.2, 0.2]];
    let settings = |tol: &str, accuracy: Option<&str>| {
        let mut texts = vec![
            ("seeds", "0.1,0.05;0.3,-0.1;-0.2,0.2"),
            ("crossings", "200"),
            ("tol", tol),
            ("check", "1"),
        ];
        texts.extend(accuracy.map(|a| ("accuracy", a)));
        SectionOptions::default().with_texts(texts).unwrap()
    };
    let distance = |orbit: &mechlab::analysis::section::SectionOrbit, seed: [f64; 2]| {
        (orbit.points.iter())
            .map(|p| (p[0] - seed[0]).hypot(p[1] - seed[1]))
            .fold(0.0, f64::max)
    };
    for tol in ["1e-6", "1e-8", "1e-10"] {
        let section = section_study(model, &[0.0], &settings(tol, None), &|_| ())
            .unwrap()
            .section
            .unwrap();
        assert_eq!(section.crossing_errors.len(), 3);
        for ((orbit, error), seed) in section
            .orbits
            .iter()
            .zip(&section.crossing_errors)
            .zip(seeds)
        {
            assert_eq!(orbit.points.len(), 200);
            let off = distance(orbit, seed);
            println!("tol {tol}: stated {error:.2e}, off by {off:.2e}");
            assert!(
                off <= *error && *error <= 100.0 * off.max(1e-15),
                "tol {tol}: {error:e} against {off:e}"
            );
        }
    }
    let asked = section_study(model, &[0.0], &settings("1e-5", Some("1e-9")), &|_| ())
        .unwrap()
        .section
        .unwrap();
    let said = asked.accuracy.clone().unwrap();
    println!("{said}");
    assert!(said.contains(" reached"), "{said}");
    for (orbit, seed) in asked.orbits.iter().zip(seeds) {
        assert!(distance(orbit, seed) <= 1e-9, "{said}");
    }
}
