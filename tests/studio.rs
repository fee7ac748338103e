//! The studio: its HTTP API answers what the library computes for the same
//! settings, and bad requests get errors that name the problem. The test
//! in a real browser is a package of its own (`tests/browser/`), so that
//! no other test binary links a WebDriver client; it runs only when asked.

mod common;
use axum::body::Body;
use axum::http::{Request, StatusCode};
use common::model_of;
use http_body_util::BodyExt;
use mechlab::analysis::chaos_map::{chaos_map, ChaosMapSettings};
use mechlab::analysis::period_map::{orbit, period_map, wrap_angle};
use mechlab::models::kapitza;
use mechlab::ode::{Integrator, Method};
use mechlab_studio::router;
use serde_json::{json, Value};
use tower::ServiceExt;

/// Sends one request to the router; the status and the body's text.
async fn call(method: &str, uri: &str, body: Option<Value>) -> (StatusCode, String, String) {
    let request = Request::builder()
        .method(method)
        .uri(uri)
        .header("content-type", "application/json")
        .body(body.map_or_else(Body::empty, |b| Body::from(b.to_string())))
        .unwrap();
    let response = router(mechlab::models::MODELS)
        .oneshot(request)
        .await
        .unwrap();
    let status = response.status();
    let content_type = response
        .headers()
        .get("content-type")
        .map(|v| v.to_str().unwrap().to_string())
        .unwrap_or_default();
    let bytes = response.into_body().collect().await.unwrap().to_bytes();
    (
        status,
        content_type,
        String::from_utf8(bytes.to_vec()).unwrap(),
    )
}

fn lines(text: &str) -> Vec<Value> {
    text.lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

/// The points of a streamed orbit's chunks, in order.
fn orbit_points(lines: &[Value]) -> Vec<[f64; 2]> {
    lines
        .iter()
        .filter_map(|l| l.get("points"))
        .flat_map(|p| serde_json::from_value::<Vec<[f64; 2]>>(p.clone()).unwrap())
        .collect()
}

/// Kapitza's period map from the library: its exact system at `params`
/// (A, ε, μ) and the forcing period.
fn kapitza_map(params: [f64; 3]) -> (kapitza::Exact, f64) {
    let exact = kapitza::Exact {
        params: kapitza::Params::from_values(&params),
    };
    (exact, 2.0 * std::f64::consts::PI * params[1])
}

#[tokio::test]
async fn models_and_page_are_served() {
    // The settings the page fills its inputs from are the declarations,
    // with the studio's interactive values named as such.
    let (status, _, body) = call("GET", "/api/schema", None).await;
    assert_eq!(status, StatusCode::OK);
    let schema: Value = serde_json::from_str(&body).unwrap();
    assert_eq!(
        schema,
        serde_json::to_value(mechlab_studio::calls::schemas()).unwrap()
    );
    let chaos = schema
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["analysis"] == "chaos_map")
        .unwrap();
    assert_eq!(chaos["interactive"], json!({"periods": 100, "check": 64}));
    let (status, kind, body) = call("GET", "/api/models", None).await;
    assert_eq!(status, StatusCode::OK);
    assert!(kind.starts_with("application/json"));
    let models: Value = serde_json::from_str(&body).unwrap();
    let names: Vec<&str> = models
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["name"].as_str().unwrap())
        .collect();
    let expected: Vec<&str> = mechlab::models::ALL.iter().map(|m| m.name).collect();
    assert_eq!(names, expected);
    let k = &models[names.iter().position(|n| *n == "kapitza").unwrap()];
    let defaults: Vec<(String, f64)> = k["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            (
                p["name"].as_str().unwrap().to_string(),
                p["default"].as_f64().unwrap(),
            )
        })
        .collect();
    assert_eq!(
        defaults,
        [
            ("A".to_string(), 1.5),
            ("eps".into(), 0.1),
            ("mu".into(), 0.0)
        ]
    );
    assert_eq!(k["periodic"], json!([true, false]));
    assert_eq!(k["through"], json!([0.0, 0.0]), "no start in its file");
    // The heavy top's plane passes through its file's start, θ = 0.5
    // (off the upright θ = 0 where its Euler angles are singular), spun
    // at ψ' = 10 (C = 1): p_φ = C ψ' cos θ, p_ψ = C ψ'.
    let top = &models[names.iter().position(|n| *n == "heavy_top").unwrap()];
    let by_hand = [0.0, 0.5, 0.0, 10.0 * 0.5f64.cos(), 0.0, 10.0];
    let through: Vec<f64> = serde_json::from_value(top["through"].clone()).unwrap();
    assert!(
        through
            .iter()
            .zip(by_hand)
            .all(|(a, b)| (a - b).abs() < 1e-14),
        "through {through:?}, by hand {by_hand:?}"
    );

    let (status, kind, page) = call("GET", "/", None).await;
    assert_eq!(status, StatusCode::OK);
    assert!(kind.starts_with("text/html"));
    assert!(page.contains("<canvas id=\"plane\"") && page.contains("/studio.js"));
    // No network: nothing is loaded from another host.
    assert!(!page.contains("http://") && !page.contains("https://"));
    let (_, kind, script) = call("GET", "/studio.js", None).await;
    assert!(kind.starts_with("text/javascript") && script.contains("/api/orbit"));

    let (status, _, body) = call("GET", "/api/models/kapitza/derivations", None).await;
    assert_eq!(status, StatusCode::OK);
    let derivations: Value = serde_json::from_str(&body).unwrap();
    let hamiltonian = derivations
        .as_array()
        .unwrap()
        .iter()
        .find(|d| d["key"] == "hamiltonian")
        .unwrap();
    assert!(hamiltonian["mathml"].as_str().unwrap().starts_with("<math"));
}

/// The streamed orbit is the library's orbit of the period map, number for
/// number, angles wrapped into [−π, π).
#[tokio::test]
async fn orbit_equals_the_library_period_map() {
    let request = json!({"model": "kapitza", "params": {"A": 1.2}, "method": "taylor", "tol": 1e-10,
        "seed": [2.5, 0.4], "periods": 300});
    let (status, kind, body) = call("POST", "/api/orbit", Some(request)).await;
    assert_eq!(status, StatusCode::OK);
    assert_eq!(kind, "application/x-ndjson");
    let lines = lines(&body);
    let points = orbit_points(&lines);
    let end = &lines.last().unwrap()["end"];
    assert_eq!(end["periods"], 300);
    assert_eq!(end["cancelled"], false);

    let (system, period) = kapitza_map([1.2, 0.1, 0.0]);
    let mut integrator = Integrator::new(Method::Taylor { tol: 1e-10 }).unwrap();
    let expected = orbit(
        &mut integrator,
        &system,
        period,
        &[2.5, 0.4],
        300,
        &[true, false],
    )
    .unwrap();
    assert_eq!(points.len(), 301);
    for (k, (got, want)) in points.iter().zip(&expected).enumerate() {
        assert_eq!(got, want, "point {k}");
    }
    assert_eq!(end["f_evals"], integrator.stats.f_evals);
}

/// A constrained model's orbit: the seed is put on the constraints with
/// the axes' components held, and the points are the library's portrait
/// of the same seed, point for point.
#[tokio::test]
async fn a_constrained_models_orbit_is_its_portrait_on_the_constraints() {
    use mechlab::analysis::period_map::{portrait, PortraitSettings};
    // Off the constraints: the coupler's angle and the rocker's rate are wrong.
    let seed = vec![0.35, 0.05, -0.3, 0.4, 0.0, 0.7];
    let request = json!({"model": "four_bar", "params": {}, "method": "dop853", "tol": 1e-10,
        "axes": [0, 3], "seed": seed, "periods": 40});
    let (status, _, body) = call("POST", "/api/orbit", Some(request)).await;
    assert_eq!(status, StatusCode::OK);
    let lines = lines(&body);
    let points = orbit_points(&lines);
    assert_eq!(points.len(), 41);
    assert_eq!(points[0], [0.35, 0.4], "the axes' components are held");
    let model = mechlab::models::by_name("four_bar").unwrap();
    let settings = PortraitSettings {
        axes: [0, 3],
        seeds: Some(vec![seed]),
        count: 1,
        p_max: 1.0,
        periods: 40,
        method: Method::Dop853 {
            rtol: 1e-10,
            atol: 1e-10,
        },
        check: 0,
        accuracy: None,
    };
    let expected = portrait(
        model,
        &mechlab::models::four_bar::Params::default().values(),
        &settings,
    )
    .unwrap();
    for (k, (got, want)) in points.iter().zip(&expected.orbits[0]).enumerate() {
        assert_eq!(got[0], want.0, "point {k}");
        assert_eq!(got[1], want.1, "point {k}");
    }
}

/// A clicked orbit's tune: near Kapitza's stable upright (A = 1.5,
/// ε = 0.1) a small orbit of the period map turns by the angle of the
/// upright's Floquet multipliers e^{±2πiν} each period: NAFF of its
/// iterates gives ν to 1e-5 (the orbit's amplitude detunes it by less).
#[tokio::test]
async fn a_clicked_orbits_tune_is_its_floquet_angle() {
    let request = json!({"model": "kapitza", "params": {"A": 1.5, "eps": 0.1, "mu": 0.0},
        "method": "taylor", "tol": 1e-13, "seed": [0.01, 0.0], "periods": 2000});
    let (status, _, body) = call("POST", "/api/orbit", Some(request)).await;
    assert_eq!(status, StatusCode::OK);
    let end = lines(&body).last().unwrap()["end"].clone();
    let tune = end["tunes"][0].as_f64().unwrap_or_else(|| panic!("{end}"));
    let model = mechlab::models::by_name("kapitza").unwrap();
    let params = [1.5, 0.1, 0.0];
    let mut integrator = Integrator::new(Method::Taylor { tol: 1e-13 }).unwrap();
    let period = 2.0 * std::f64::consts::PI * 0.1;
    let (_, monodromy) = model
        .systems()
        .unwrap()
        .monodromy(&params, &mut integrator, period, &[0.0, 0.0])
        .unwrap();
    let floquet = (0.5 * monodromy.trace()).acos() / (2.0 * std::f64::consts::PI);
    assert!(
        (tune - floquet).abs() < 1e-5,
        "NAFF {tune}, Floquet {floquet}"
    );
    // Too short an orbit has no tunes.
    let request = json!({"model": "kapitza", "seed": [0.01, 0.0], "periods": 10});
    let (_, _, body) = call("POST", "/api/orbit", Some(request)).await;
    assert!(
        lines(&body).last().unwrap()["end"]["tunes"].is_null(),
        "{body}"
    );
}

/// The mechanism drawn from a click on the four-bar: its bars keep their
/// lengths in every frame (the seed is put on the constraints as the
/// orbit's is), its base moves as the model file says; a model without
/// points gets a 422 naming `[[points]]`.
#[tokio::test]
async fn the_mechanism_moves_with_its_bars_rigid() {
    let seed = vec![0.35, 0.05, -0.3, 0.4, 0.0, 0.7];
    let request = json!({"model": "four_bar", "method": "dop853", "tol": 1e-11,
        "axes": [0, 3], "seed": seed, "duration": 2.0, "frames": 61});
    let (status, _, body) = call("POST", "/api/mechanism", Some(request)).await;
    assert_eq!(status, StatusCode::OK, "{body}");
    let view: Value = serde_json::from_str(&body).unwrap();
    assert_eq!(view["points"], json!(["O1", "O2", "B", "C"]));
    assert_eq!(view["bars"], json!([[0, 1], [0, 2], [2, 3], [1, 3]]));
    assert_eq!(
        (&view["in_space"], &view["up"], &view["body_frames"]),
        (&json!(false), &json!([0.0, 1.0, 0.0]), &json!([]))
    );
    let frames: Vec<Vec<[f64; 3]>> = serde_json::from_value(view["frames"].clone()).unwrap();
    let times: Vec<f64> = serde_json::from_value(view["times"].clone()).unwrap();
    assert_eq!((frames.len(), times[60]), (61, 2.0));
    let p = mechlab::models::four_bar::Params::default();
    let length = |a: [f64; 3], b: [f64; 3]| (a[0] - b[0]).hypot(a[1] - b[1]);
    for (f, points) in frames.iter().enumerate() {
        let [o1, o2, b, c] = [points[0], points[1], points[2], points[3]];
        assert!(points.iter().all(|p| p[2] == 0.0), "in the plane");
        assert!((length(o1, b) - p.l).abs() < 1e-12, "crank, frame {f}");
        assert!((length(o2, c) - p.l).abs() < 1e-12, "rocker, frame {f}");
        assert!(
            (length(b, c) - p.c).abs() < 1e-8,
            "coupler (the closure), frame {f}"
        );
        let w = p.a / p.nu * (p.nu * times[f]).cos();
        let base = [o1[0] + p.d / 2.0, o1[1] - w, o2[0] - p.d / 2.0, o2[1] - w];
        assert!(base.iter().all(|e| e.abs() < 1e-15), "the base, frame {f}");
    }
    assert_eq!(
        frames[0][2][0],
        -p.d / 2.0 + p.l * 0.35f64.sin(),
        "the crank angle is held"
    );
    // The heavy top moves in space, drawn as its frame (its centre named
    // as the body, then its axes' tips) with the tip joined to the centre,
    // up against gravity.
    let request = json!({"model": "heavy_top", "seed": [0.0, 0.5, 0.0, 1.0, 0.0, 4.0],
        "duration": 1.0, "frames": 11});
    let (status, _, body) = call("POST", "/api/mechanism", Some(request)).await;
    assert_eq!(status, StatusCode::OK, "{body}");
    let view: Value = serde_json::from_str(&body).unwrap();
    assert_eq!(
        (&view["points"], &view["bars"], &view["body_frames"]),
        (
            &json!(["top", "top_axis_x", "top_axis_y", "top_axis_z", "tip"]),
            &json!([[0, 4]]),
            &json!([[0, 1, 2, 3]])
        )
    );
    assert_eq!(
        (&view["in_space"], &view["up"]),
        (&json!(true), &json!([0.0, 0.0, 1.0]))
    );
    let request = json!({"model": "duffing", "seed": [0.1, 0.0], "duration": 1.0, "frames": 10});
    let (status, _, body) = call("POST", "/api/mechanism", Some(request)).await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY);
    assert!(
        body.contains("names no points") && body.contains("[[points]]"),
        "{body}"
    );
    let request = json!({"model": "kapitza", "seed": [0.1, 0.0], "duration": 1.0, "frames": 1});
    let (status, _, body) = call("POST", "/api/mechanism", Some(request)).await;
    assert_eq!(status, StatusCode::BAD_REQUEST);
    assert!(
        body.contains("frames = 1 is outside its range (2 to 3600)"),
        "{body}"
    );
}

/// The steady motion through the studio: Chaplygin's sleigh gliding
/// backwards at u = −1 is unstable with the eigenvalue −m b u/(I + m b²)
/// = 2/3 (the heading's rate); a coordinate the model lacks, or a model
/// with a fast phase, is a 400 naming it.
#[tokio::test]
async fn the_steady_motion_is_the_sleigh_s_closed_form() {
    let request = json!({"model": "chaplygin_sleigh", "speed": "auto", "at": -1.0, "sweep": 5});
    let (status, _, body) = call("POST", "/api/steady_motion", Some(request)).await;
    assert_eq!(status, StatusCode::OK, "{body}");
    let answer: Value = serde_json::from_str(&body).unwrap();
    let value = answer["motion"]["eigenvalues"][0][0].as_f64().unwrap();
    let error = answer["motion"]["errors"][0].as_f64().unwrap();
    assert!((value - 2.0 / 3.0).abs() <= error, "{body}");
    assert!(
        answer["motion"]["verdict"]["unstable"].is_object(),
        "{body}"
    );
    assert_eq!(answer["sweep"]["speeds"].as_array().unwrap().len(), 5);
    // The heavy top hanging and precessing at Ω = 2 without spin (the
    // studio's rates and start): cos θ₀ = −m g l/((A − C) Ω²) = −1/4, and
    // it nods at √(U''(θ₀)/A) of the Routhian written here.
    let request = json!({"model": "heavy_top", "speed": "phi", "at": 2.0,
        "rates": [2.0, 0.0, 0.0], "start": [0.0, 1.5, 0.0], "sweep": 0});
    let (status, _, body) = call("POST", "/api/steady_motion", Some(request)).await;
    assert_eq!(status, StatusCode::OK, "{body}");
    let answer: Value = serde_json::from_str(&body).unwrap();
    let theta = answer["motion"]["state"][1].as_f64().unwrap();
    assert!((theta.cos() + 0.25).abs() < 1e-9, "θ₀ = {theta}");
    let (a, c, omega) = (2.0, 1.0, 2.0);
    let spin = omega * theta.cos();
    let (p_phi, p_psi) = (
        a * omega * theta.sin().powi(2) + c * spin * theta.cos(),
        c * spin,
    );
    let u = |t: f64| (p_phi - p_psi * t.cos()).powi(2) / (2.0 * a * t.sin().powi(2)) + t.cos();
    let h = 1e-4;
    let nodding = ((u(theta + h) - 2.0 * u(theta) + u(theta - h)) / (h * h) / a).sqrt();
    let im = answer["motion"]["eigenvalues"][0][1]
        .as_f64()
        .unwrap()
        .abs();
    assert!(
        (im - nodding).abs() < 1e-6 * nodding,
        "{im} against {nodding}"
    );
    let request = json!({"model": "heavy_top", "rates": [1.0, "x", 0.0]});
    let (status, _, body) = call("POST", "/api/steady_motion", Some(request)).await;
    assert_eq!(status, StatusCode::BAD_REQUEST, "{body}");
    assert!(body.contains("rates"), "{body}");
    let request = json!({"model": "chaplygin_sleigh", "speed": "z"});
    let (status, _, body) = call("POST", "/api/steady_motion", Some(request)).await;
    assert_eq!(status, StatusCode::BAD_REQUEST, "{body}");
    assert!(
        body.contains("speed = z") && body.contains("no such coordinate"),
        "{body}"
    );
    let request = json!({"model": "kapitza"});
    let (status, _, body) = call("POST", "/api/steady_motion", Some(request)).await;
    assert_eq!(status, StatusCode::BAD_REQUEST, "{body}");
    assert!(body.contains("fast phase"), "{body}");
}

/// Each refinement of the streamed chaos map is the library's map of the
/// same view, pixel for pixel.
#[tokio::test]
async fn chaos_levels_equal_the_library_map() {
    let ranges = [[-3.0, 3.0], [-2.0, 2.5]];
    let request = json!({"model": "kapitza", "params": {"A": 1.0}, "tol": 1e-8, "ranges": ranges,
        "levels": [4, 9], "periods": 40});
    let (status, _, body) = call("POST", "/api/chaos", Some(request)).await;
    assert_eq!(status, StatusCode::OK);
    let levels = lines(&body);
    assert_eq!(levels.len(), 2);
    for level in &levels {
        let pixels = level["pixels"].as_u64().unwrap() as usize;
        let settings = ChaosMapSettings {
            check: 0,
            accuracy: None,
            axes: [0, 1],
            ranges: ranges.map(|r| Some((r[0], r[1]))),
            p_max: 1.0,
            through: Some(vec![0.0, 0.0]),
            pixels,
            periods: 40,
            method: Method::Taylor { tol: 1e-8 },
            tiles: None,
        };
        let map = chaos_map(model_of("kapitza"), &[1.0, 0.1, 0.0], &settings, &|| true).unwrap();
        let fli: Vec<Option<f64>> = serde_json::from_value(level["fli"].clone()).unwrap();
        let expected: Vec<Option<f64>> = map
            .fli
            .iter()
            .map(|v| v.is_finite().then_some(*v))
            .collect();
        assert_eq!(fli, expected, "{pixels}² pixels");
        assert_eq!(level["regular_level"].as_f64().unwrap(), 40f64.ln());
    }
}

/// The basins streamed for a view equal the library's basins of that view
/// at each resolution; the unforced double well's two attractors are the
/// wells' bottoms; a bad cell is a named error.
#[tokio::test]
async fn basins_levels_equal_the_library_basins() {
    use mechlab::analysis::basins::{basins, BasinSettings};
    let ranges = [[-2.0, 2.0], [-2.0, 2.0]];
    let request = json!({"model": "duffing", "params": {"gamma": 0.0}, "tol": 1e-10,
        "ranges": ranges, "levels": [16, 32], "transient": 60});
    let (status, _, body) = call("POST", "/api/basins", Some(request.clone())).await;
    assert_eq!(status, StatusCode::OK);
    let levels = lines(&body);
    assert_eq!(levels.len(), 2);
    for level in &levels {
        let pixels = level["pixels"].as_u64().unwrap() as usize;
        let settings = BasinSettings {
            axes: [0, 1],
            ranges: ranges.map(|r| (r[0], r[1])),
            through: Some(vec![0.0, 0.0]),
            pixels,
            transient: 60,
            record: 16,
            cell: 0.05,
            method: Method::Taylor { tol: 1e-10 },
            stop_early: true,
            check: 0,
            accuracy: None,
            tiles: None,
        };
        let library = basins(model_of("duffing"), &[0.3, 0.0, 1.2], &settings, &|_| ()).unwrap();
        let labels: Vec<i32> = serde_json::from_value(level["labels"].clone()).unwrap();
        assert_eq!(labels, library.labels, "{pixels}² pixels");
        let attractors = level["attractors"].as_array().unwrap();
        assert_eq!(attractors.len(), 2);
        for a in attractors {
            let at: Vec<f64> = serde_json::from_value(a["representative"].clone()).unwrap();
            assert!(
                (at[0].abs() - 1.0).abs() < 1e-8 && at[1].abs() < 1e-8,
                "{at:?}"
            );
        }
    }
    let mut bad = request;
    bad["cell"] = json!(0.0);
    let (status, _, body) = call("POST", "/api/basins", Some(bad)).await;
    assert_eq!(status, StatusCode::BAD_REQUEST);
    assert!(
        body.contains("basins: cell = 0 is outside its range (> 0)"),
        "{body}"
    );
    let (status, _, body) = call(
        "POST",
        "/api/basins",
        Some(json!({"model": "henon_heiles", "ranges": ranges, "levels": [8], "transient": 10})),
    )
    .await;
    assert!(status.is_client_error(), "{status}: {body}");
}

/// Kapitza's averaged Hamiltonian H̄ = p²/2 + cos q + A² sin² q / 4 (q from
/// the upward vertical): its unstable equilibria sit at cos q = 2/A², the
/// separatrices are the level H̄(q*, 0), and every drawn segment end lies
/// on its level set.
#[tokio::test]
async fn overlay_matches_the_averaged_hamiltonian_by_hand() {
    let a: f64 = 1.8;
    let pi = std::f64::consts::PI;
    let request = json!({"model": "kapitza", "params": {"A": a}, "ranges": [[-pi, pi], [-3, 3]],
        "grid": 200, "levels": 10});
    let (status, _, body) = call("POST", "/api/overlay", Some(request)).await;
    assert_eq!(status, StatusCode::OK);
    let overlay: Value = serde_json::from_str(&body).unwrap();
    let h_bar = |q: f64, p: f64| p * p / 2.0 + q.cos() + a * a * q.sin().powi(2) / 4.0;
    let q_star = (2.0 / (a * a)).acos();
    let mut unstable: Vec<f64> = Vec::new();
    let mut stable: Vec<f64> = Vec::new();
    for e in overlay["equilibria"].as_array().unwrap() {
        let q = wrap_angle(e["q"][0].as_f64().unwrap());
        if e["stable"].as_bool().unwrap() {
            stable.push(q);
        } else {
            unstable.push(q);
        }
    }
    unstable.sort_by(f64::total_cmp);
    stable.sort_by(f64::total_cmp);
    assert_eq!(unstable.len(), 2, "{unstable:?}");
    assert!(
        (unstable[0] + q_star).abs() < 1e-8 && (unstable[1] - q_star).abs() < 1e-8,
        "{unstable:?} against ±{q_star}"
    );
    // Upright (A > √2) and hanging.
    assert!(
        stable.iter().any(|q| q.abs() < 1e-8)
            && stable
                .iter()
                .any(|q| (q.abs() - std::f64::consts::PI).abs() < 1e-8),
        "{stable:?}"
    );
    let separatrix_level = h_bar(q_star, 0.0);
    let mut separatrices = 0;
    for level in overlay["levels"].as_array().unwrap() {
        let value = level["value"].as_f64().unwrap();
        if level["separatrix"].as_bool().unwrap() {
            separatrices += 1;
            assert!((value - separatrix_level).abs() < 1e-12);
        }
        for s in level["segments"].as_array().unwrap() {
            let s: [f64; 4] = serde_json::from_value(s.clone()).unwrap();
            for (q, p) in [(s[0], s[1]), (s[2], s[3])] {
                // Linear interpolation on a grid of spacing h: error O(h²).
                assert!(
                    (h_bar(q, p) - value).abs() < 2e-3,
                    "H̄({q}, {p}) = {} on level {value}",
                    h_bar(q, p)
                );
            }
        }
    }
    assert_eq!(separatrices, 2);

    // To second order for every model with a fast phase, the numeric-solve
    // form included; an order that is not derived is refused by name.
    for model in ["kapitza", "triple_pendulum"] {
        let second = json!({"model": model, "ranges": [[-3.0, 3.0], [-3, 3]], "grid": 40, "levels": 5, "order": 2});
        let (status, _, body) = call("POST", "/api/overlay", Some(second)).await;
        assert_eq!(status, StatusCode::OK, "{body}");
        assert!(body.contains("second order"), "{body}");
    }
    let third = json!({"model": "triple_pendulum", "ranges": [[-3.0, 3.0], [-3, 3]], "grid": 40, "levels": 5, "order": 3});
    let (status, _, body) = call("POST", "/api/overlay", Some(third)).await;
    assert_eq!(status, StatusCode::BAD_REQUEST);
    assert!(
        body.contains("order = 3 is outside its range (1 to 2)"),
        "{body}"
    );
}

/// The manifolds overlay: Kapitza's W^u and W^s at A = 1 on the page's
/// cylinder, with a primary homoclinic point on the symmetry line q = ±π and
/// a lobe area near Melnikov's closed form; a 2-degree model is refused by
/// name (422), an unknown field by name (400).
#[tokio::test]
async fn manifolds_overlay_gives_the_tangle_or_a_named_error() {
    let request = json!({"model": "kapitza", "params": {"A": 1.0, "eps": 0.1}});
    let (status, _, body) = call("POST", "/api/manifolds", Some(request)).await;
    assert_eq!(status, StatusCode::OK, "{body}");
    let m: Value = serde_json::from_str(&body).unwrap();
    for curve in ["unstable", "stable"] {
        let segments = m[curve].as_array().unwrap();
        assert!(segments.len() > 100, "{curve}: {}", segments.len());
        for s in segments {
            let q = [s[0].as_f64().unwrap(), s[2].as_f64().unwrap()];
            assert!(
                q.iter()
                    .all(|q| (-std::f64::consts::PI..std::f64::consts::PI).contains(q)),
                "{s}"
            );
        }
    }
    let on_line = m["homoclinic"]
        .as_array()
        .unwrap()
        .iter()
        .any(|h| (h[0].as_f64().unwrap().abs() - std::f64::consts::PI).abs() < 1e-8);
    assert!(on_line, "{}", m["homoclinic"]);
    let area = m["lobe_area"].as_f64().unwrap();
    assert!(m["resolved"].as_bool().unwrap());
    // Melnikov's first-order lobe in closed form at A = 1,
    // 2√2π/(ε cosh(π/(2√2 ε))): the tangle at ε = 0.1 lies 1.4 % below it.
    let eps = 0.1;
    let melnikov = 2.0 * 2f64.sqrt() * std::f64::consts::PI
        / (eps * (std::f64::consts::PI / (2.0 * 2f64.sqrt() * eps)).cosh());
    assert!(
        (area / melnikov - 1.0).abs() < 0.03,
        "{area} vs Melnikov's {melnikov}"
    );
    let (status, _, body) = call(
        "POST",
        "/api/manifolds",
        Some(json!({"model": "double_pendulum"})),
    )
    .await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{body}");
    assert!(body.contains("degrees of freedom"), "{body}");
    let (status, _, body) = call(
        "POST",
        "/api/manifolds",
        Some(json!({"model": "kapitza", "colour": "red"})),
    )
    .await;
    assert_eq!(status, StatusCode::BAD_REQUEST, "{body}");
    assert!(body.contains("colour"), "{body}");
}

/// "Continue this orbit": the periodic orbit nearest a seed followed in a
/// parameter, projected on the plane, with its bifurcations: Duffing's
/// right-well orbit doubles its period where a hand-written RK4, Newton
/// and Jury bisection put it (γ ≈ 0.26558) and the branch of period 2 is followed from
/// there. Errors are named: a parameter the model lacks (listing
/// them: a bad value, 400, as everywhere), a contact model (422), a start
/// longer than the state.
#[tokio::test]
async fn continuation_follows_a_clicked_orbit_or_names_the_error() {
    let request = json!({"model": "duffing", "start": [1.0, 0.0], "parameter": "gamma", "to": 0.28, "tol": 1e-12});
    let (status, _, body) = call("POST", "/api/continuation", Some(request)).await;
    assert_eq!(status, StatusCode::OK, "{body}");
    let answer: Value = serde_json::from_str(&body).unwrap();
    let branches = answer["branches"].as_array().unwrap();
    assert_eq!(branches.len(), 2, "{body}");
    assert_eq!(branches[1]["period"], 2);
    let doubling = answer["bifurcations"]
        .as_array()
        .unwrap()
        .iter()
        .find(|b| b["kind"] == "period_doubling")
        .expect("a period doubling");
    let gamma = doubling["parameter"].as_f64().unwrap();
    let reference = common::duffing_period_doubling(0.3, 1.2, (0.2, 0.28), 4000);
    assert!((gamma - reference).abs() < 1e-9, "{gamma} vs {reference}");
    let first = &branches[0]["points"][0];
    assert!(
        (first[2].as_f64().unwrap() - 0.2).abs() < 1e-12,
        "starts at γ = 0.2: {first}"
    );

    let bad = |request: Value| async move {
        let (status, _, body) = call("POST", "/api/continuation", Some(request)).await;
        (status, body)
    };
    let (status, body) =
        bad(json!({"model": "duffing", "start": [1.0, 0.0], "parameter": "kappa", "to": 1.0}))
            .await;
    assert_eq!(status, StatusCode::BAD_REQUEST, "{body}");
    assert!(body.contains("kappa") && body.contains("gamma"), "{body}");
    let (status, body) =
        bad(json!({"model": "painleve_klein", "start": [0.0, 0.0], "parameter": "mu", "to": 1.0}))
            .await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{body}");
    assert!(body.contains("contact"), "{body}");
    let (status, body) =
        bad(json!({"model": "duffing", "start": [1.0, 0.0, 0.5], "parameter": "gamma", "to": 1.0}))
            .await;
    assert!(status.is_client_error(), "{status}: {body}");
    assert!(body.contains("start"), "{body}");

    // A constrained model, in the chart of the plane's axes: the four-bar's
    // upright tips over at a branch point where its exact window opens
    // (a = 1.18609, as the `linkage` scene finds); a model whose
    // constraints leave more than the plane's two dimensions says so.
    let upright = [
        0.304_692_654_015_397_5,
        0.0,
        -0.304_692_654_015_397_5,
        0.0,
        0.0,
        0.0,
    ];
    let request = json!({"model": "four_bar", "method": "dop853", "tol": 1e-10, "axes": [0, 3],
        "start": upright, "parameter": "a", "to": 1.0});
    let (status, _, body) = call("POST", "/api/continuation", Some(request)).await;
    assert_eq!(status, StatusCode::OK, "{body}");
    let answer: Value = serde_json::from_str(&body).unwrap();
    let first = &answer["branches"][0]["points"][0];
    assert!(
        (first[0].as_f64().unwrap() - upright[0]).abs() < 1e-10,
        "{first}"
    );
    let tipping = answer["bifurcations"][0]["parameter"].as_f64().unwrap();
    assert!((tipping - 1.18609).abs() < 1e-5, "{body}");
    let request = json!({"model": "rolling_disk", "method": "dop853", "start": vec![0.0; 8],
        "parameter": "R", "to": 2.0});
    let (status, body) = bad(request).await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{body}");
    assert!(body.contains("dimension 6"), "{body}");
}

/// The Poincaré section of a model without a fast phase: an orbit of
/// Hénon–Heiles at E = 1/8 from a seed on the plane x = 0 is the library's
/// section orbit point for point, on H = E to 1e-9; the MEGNO map has
/// accessible and inaccessible pixels and a chaotic fraction; the shaken
/// double pendulum gets the slice of its period map the library draws; a
/// model of 1 degree of freedom with a fast phase and a seed where the
/// energy is not accessible are named errors (422 and 400).
#[tokio::test]
async fn section_orbits_and_their_megno_map() {
    use mechlab::analysis::section::{section, SectionSettings};
    let request = json!({"model": "henon_heiles", "energy": 0.125, "seeds": [[0.1, 0.0]], "crossings": 50, "tol": 1e-12});
    let (status, _, body) = call("POST", "/api/section", Some(request)).await;
    assert_eq!(status, StatusCode::OK, "{body}");
    let answer: Value = serde_json::from_str(&body).unwrap();
    let points: Vec<[f64; 2]> = serde_json::from_value(answer["points"].clone()).unwrap();
    assert_eq!(points.len(), 50);
    assert!(answer["energy_drift"].as_f64().unwrap() < 1e-9, "{body}");
    let model = mechlab::models::by_name("henon_heiles").unwrap();
    let settings = SectionSettings {
        plane: vec![1.0, 0.0],
        value: 0.0,
        rising: true,
        energy: 0.125,
        crossings: 50,
        t_max: 50.0 * 50.0,
        tol: 1e-12,
        phase: 0.0,
        slab: 0.05,
    };
    let library = section(model, &model.dynamic.defaults(), &[[0.1, 0.0]], &settings).unwrap();
    assert_eq!(points, library.orbits[0].points);

    let map = json!({"model": "henon_heiles", "energy": 0.125, "map": 16, "map_time": 200.0});
    let (status, _, body) = call("POST", "/api/section_map", Some(map)).await;
    assert_eq!(status, StatusCode::OK, "{body}");
    let answer: Value = serde_json::from_str(&body).unwrap();
    let megno = answer["megno"].as_array().unwrap();
    assert_eq!(megno.len(), 256);
    assert!(megno.iter().any(Value::is_null) && megno.iter().any(Value::is_f64));
    let fraction = answer["chaotic_fraction"].as_f64().unwrap();
    assert!((0.0..=1.0).contains(&fraction), "{fraction}");

    // A plane given as a linear function of the coordinates: the library's
    // section on it, in the plane's chart, named; a bad plane is refused.
    let tilted = json!({"model": "henon_heiles", "energy": 0.125, "plane": "x + 0.5*y", "seeds": [[0.1, 0.05]], "crossings": 30, "tol": 1e-12});
    let (status, _, body) = call("POST", "/api/section", Some(tilted)).await;
    assert_eq!(status, StatusCode::OK, "{body}");
    let answer: Value = serde_json::from_str(&body).unwrap();
    assert_eq!(answer["axes"], json!(["y", "p_y − 0.5·p_x"]));
    let points: Vec<[f64; 2]> = serde_json::from_value(answer["points"].clone()).unwrap();
    let on_tilted = SectionSettings {
        plane: vec![1.0, 0.5],
        crossings: 30,
        t_max: 50.0 * 30.0,
        ..settings.clone()
    };
    let library = section(model, &model.dynamic.defaults(), &[[0.1, 0.05]], &on_tilted).unwrap();
    assert_eq!(points, library.orbits[0].points);
    let (status, _, body) = call(
        "POST",
        "/api/section",
        Some(json!({"model": "henon_heiles", "energy": 0.125, "plane": "z", "seeds": [[0.1, 0.0]], "crossings": 5})),
    )
    .await;
    assert_eq!(status, StatusCode::BAD_REQUEST, "{body}");
    assert!(
        body.contains("plane") && body.contains("not a coordinate"),
        "{body}"
    );

    // A model with a fast phase and 2 degrees of freedom: the slice of its
    // period map, as the library draws it.
    let pi = std::f64::consts::PI;
    let slice = json!({"model": "double_pendulum", "energy": -1.5, "value": pi, "seeds": [[pi + 0.3, 0.0]], "crossings": 20, "tol": 1e-12});
    let (status, _, body) = call("POST", "/api/section", Some(slice)).await;
    assert_eq!(status, StatusCode::OK, "{body}");
    let answer: Value = serde_json::from_str(&body).unwrap();
    let points: Vec<[f64; 2]> = serde_json::from_value(answer["points"].clone()).unwrap();
    let shaken = mechlab::models::by_name("double_pendulum").unwrap();
    let settings = SectionSettings {
        value: pi,
        energy: -1.5,
        crossings: 20,
        t_max: 50.0 * 20.0,
        ..settings
    };
    let params = shaken.dynamic.defaults();
    let library = section(shaken, &params, &[[pi + 0.3, 0.0]], &settings).unwrap();
    assert_eq!(points, library.orbits[0].points);
    assert_eq!(points.len(), 20);

    let (status, _, body) = call(
        "POST",
        "/api/section",
        Some(json!({"model": "kapitza", "energy": 0.1, "seeds": [[0.1, 0.0]], "crossings": 5})),
    )
    .await;
    assert_eq!(status, StatusCode::UNPROCESSABLE_ENTITY, "{body}");
    assert!(body.contains("fast phase"), "{body}");
    let (status, _, body) = call(
        "POST",
        "/api/section",
        Some(json!({"model": "henon_heiles", "energy": 0.125, "seeds": [[0.9, 0.0]], "crossings": 5})),
    )
    .await;
    assert_eq!(status, StatusCode::BAD_REQUEST, "{body}");
    assert!(body.contains("not accessible"), "{body}");
}

/// Every bad request gets a status and a message naming the problem; the
/// router keeps answering.
#[tokio::test]
async fn bad_requests_are_named_errors() {
    let orbit = |extra: Value| {
        let mut request = json!({"model": "kapitza", "seed": [0.1, 0.0], "periods": 10});
        for (k, v) in extra.as_object().unwrap() {
            request[k] = v.clone();
        }
        request
    };
    let cases = [
        (
            orbit(json!({"model": "no_such_model"})),
            StatusCode::NOT_FOUND,
            "no model named 'no_such_model'",
        ),
        (
            orbit(json!({"params": {"B": 1.0}})),
            StatusCode::BAD_REQUEST,
            "no parameter 'B'",
        ),
        (
            orbit(json!({"tol": 0.0})),
            StatusCode::BAD_REQUEST,
            "tol = 0 is outside its range (> 0)",
        ),
        (
            orbit(json!({"method": "euler"})),
            StatusCode::BAD_REQUEST,
            "euler",
        ),
        (
            orbit(json!({"seed": [0.1]})),
            StatusCode::BAD_REQUEST,
            "the seed has 1 components",
        ),
        (
            orbit(json!({"periods": 0})),
            StatusCode::BAD_REQUEST,
            "periods = 0 is outside its range (1 to 100000)",
        ),
        (
            orbit(json!({"periods": 10_000_000})),
            StatusCode::BAD_REQUEST,
            "periods = 10000000 is outside its range (1 to 100000)",
        ),
        (
            orbit(json!({"axes": [1, 1]})),
            StatusCode::BAD_REQUEST,
            "axes",
        ),
        (
            orbit(json!({"model": "painleve_klein"})),
            StatusCode::UNPROCESSABLE_ENTITY,
            "contact model",
        ),
        (
            orbit(json!({"surprise": 1})),
            StatusCode::BAD_REQUEST,
            "surprise",
        ),
    ];
    for (request, status, message) in cases {
        let (got, kind, body) = call("POST", "/api/orbit", Some(request.clone())).await;
        assert_eq!(got, status, "{request}: {body}");
        assert!(kind.starts_with("application/json"));
        let error: Value = serde_json::from_str(&body).unwrap();
        assert!(
            error["error"].as_str().unwrap().contains(message),
            "{request}: {body}"
        );
    }
    let raw = Request::builder()
        .method("POST")
        .uri("/api/orbit")
        .body(Body::from("{\"model\":"))
        .unwrap();
    let response = router(mechlab::models::MODELS).oneshot(raw).await.unwrap();
    assert_eq!(response.status(), StatusCode::BAD_REQUEST);
    let chaos = json!({"model": "kapitza", "ranges": [[1.0, -1.0], [0.0, 1.0]], "levels": [8], "periods": 10});
    let (status, _, body) = call("POST", "/api/chaos", Some(chaos)).await;
    assert_eq!(status, StatusCode::BAD_REQUEST);
    assert!(
        body.contains("chaos_map: ranges = [[1.0,-1.0],[0.0,1.0]] is not a pair of intervals"),
        "{body}"
    );
    // A setting the chaos map does not declare is refused by name, with
    // the ones it does.
    let chaos = json!({"model": "kapitza", "levels": [8], "period": 10});
    let (status, _, body) = call("POST", "/api/chaos", Some(chaos)).await;
    assert_eq!(status, StatusCode::BAD_REQUEST);
    assert!(
        body.contains("chaos_map: no setting 'period' (settings: axes, through, ranges"),
        "{body}"
    );
    let (status, _, body) = call("GET", "/api/nothing", None).await;
    assert_eq!(status, StatusCode::NOT_FOUND);
    assert!(body.contains("/api/nothing"));
}

/// An orbit whose listener goes away stops at once and says so; the points
/// it handed over are the library's.
#[test]
fn a_dropped_orbit_stops() {
    let request: mechlab_studio::calls::AnalysisRequest =
        serde_json::from_value(json!({"model": "kapitza", "seed": [1.0, 0.5], "periods": 100_000}))
            .unwrap();
    let mut received = Vec::new();
    let end = mechlab_studio::calls::orbit(mechlab::models::MODELS, &request, &mut |chunk| {
        received.extend(chunk.points);
        false
    })
    .unwrap();
    assert!(end.cancelled);
    assert!(
        end.periods < 100_000 && end.periods + 1 == received.len(),
        "{end:?}, {} points",
        received.len()
    );
    let (system, period) = kapitza_map([1.5, 0.1, 0.0]);
    let mut integrator = Integrator::new(Method::Taylor { tol: 1e-10 }).unwrap();
    let second = period_map(&mut integrator, &system, period, &[1.0, 0.5]).unwrap();
    assert_eq!(received[1], [wrap_angle(second[0]), second[1]]);
}

/// The page offers a section where the library draws one: a Hamiltonian
/// model of 2 degrees of freedom (with a fast phase, a slice of its period
/// map), or an autonomous one of 2 on holonomic constraints; its orbit on
/// a constrained model is the library's, in the chart the library picks.
#[test]
fn sections_are_offered_where_they_apply_on_constraints_too() {
    use mechlab::analysis::section::{section as library_section, SectionSettings};
    use mechlab_studio::calls::{models, section, SectionRequest};
    let offered = |catalog: mechlab::registry::Catalog, name: &str| {
        models(catalog)
            .into_iter()
            .find(|m| m.name == name)
            .unwrap()
            .section
    };
    let main = mechlab::models::MODELS;
    assert!(offered(main, "henon_heiles") && offered(main, "double_pendulum"));
    for name in [
        "kapitza",
        "four_bar",
        "chaplygin_sleigh",
        "slider_crank",
        "painleve_klein",
    ] {
        assert!(!offered(main, name), "{name}");
    }
    let tests = mechlab_test_models::MODELS;
    assert!(offered(tests, "cartesian_free_double_pendulum"));
    let request: SectionRequest = serde_json::from_value(json!({
        "model": "cartesian_free_double_pendulum", "energy": -2.5, "seeds": [[0.3, 0.0]],
        "crossings": 20, "tol": 1e-12
    }))
    .unwrap();
    let answer = section(tests, &request).unwrap();
    assert_eq!(answer.axes, ["x₂", "x₂′"]);
    let model = mechlab::registry::lookup(tests, "cartesian_free_double_pendulum").unwrap();
    let settings = SectionSettings {
        plane: vec![1.0, 0.0, 0.0, 0.0],
        value: 0.0,
        rising: true,
        energy: -2.5,
        crossings: 20,
        t_max: 50.0 * 20.0,
        tol: 1e-12,
        phase: 0.0,
        slab: 0.05,
    };
    let library =
        library_section(model, &model.dynamic.defaults(), &[[0.3, 0.0]], &settings).unwrap();
    assert_eq!(answer.points, library.orbits[0].points);
}
