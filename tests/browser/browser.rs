//! The studio end to end in Debian's Chromium over WebDriver
//! (chromedriver, through `fantoccini`): clicks seed orbits that equal the
//! library's, a slider recomputes them, and every layer of the page is
//! painted where its numbers say. Ignored unless asked for (it needs
//! Chromium); a package of its own, so that no other test binary links a
//! WebDriver client:
//!
//! `apt-get install chromium chromium-driver`
//! `cargo test --release --test browser -- --ignored`

use fantoccini::actions::{InputSource, MouseActions, PointerAction, MOUSE_BUTTON_LEFT};
use fantoccini::{Client, ClientBuilder, Locator};
use mechlab::analysis::period_map::{period_map, wrap_angle};
use mechlab::models::kapitza;
use mechlab::ode::{Integrator, Method};
use mechlab_studio::router;
use serde_json::{json, Value};
use std::process::{Child, Command};
use std::time::{Duration, Instant};

/// chromedriver in a process group of its own, with the Chromium it
/// starts: the whole group is killed when the test ends, even by a
/// failed assertion (killing chromedriver alone left its browser
/// running).
struct Driver(Child);
impl Driver {
    fn start(program: &str, port: u16) -> Driver {
        use std::os::unix::process::CommandExt;
        let child = Command::new(program)
            .arg(format!("--port={port}"))
            .process_group(0)
            .spawn()
            .unwrap_or_else(|e| panic!("{program}: {e}"));
        Driver(child)
    }
}
impl Drop for Driver {
    fn drop(&mut self) {
        let group = format!("-{}", self.0.id());
        let _ = Command::new("kill").args(["-KILL", "--", &group]).status();
        let _ = self.0.wait();
    }
}

fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port()
}

async fn connect(port: u16) -> Client {
    let mut capabilities = serde_json::Map::new();
    capabilities.insert(
        "goog:chromeOptions".into(),
        json!({"binary": std::env::var("CHROMIUM").unwrap_or_else(|_| "/usr/bin/chromium".into()),
               "args": ["--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--window-size=1400,1000"]}),
    );
    let started = Instant::now();
    loop {
        let attempt = ClientBuilder::new(hyper_util::client::legacy::connect::HttpConnector::new())
            .capabilities(capabilities.clone())
            .connect(&format!("http://127.0.0.1:{port}"))
            .await;
        match attempt {
            Ok(client) => return client,
            Err(e) if started.elapsed() > Duration::from_secs(30) => {
                panic!("chromedriver: {e}")
            }
            Err(_) => tokio::time::sleep(Duration::from_millis(200)).await,
        }
    }
}

/// The page holds one orbit, done, with more than 100 points.
const ONE_LONG_ORBIT: &str =
    "studio.orbits.length === 1 && studio.orbits[0].done && studio.orbits[0].points.length > 100";

/// Evaluates `expression` in the page until it is true (or fails after
/// `seconds`).
/// Picks `name` in the model list and waits until the page has it.
async fn select_model(client: &Client, name: &str) {
    client
        .find(Locator::Id("model"))
        .await
        .unwrap()
        .select_by_value(name)
        .await
        .unwrap();
    let ready = format!("studio.ready && studio.model.name === '{name}'");
    wait_for(client, &ready, 30).await;
}

async fn wait_for(client: &Client, expression: &str, seconds: u64) {
    read_when(client, expression, "return true;", seconds).await;
}

/// Runs the script `read` in the same turn of the page's event loop as
/// the check that `condition` holds, once it does (or fails after
/// `seconds`): what it reads is one snapshot of the state the
/// condition saw. A separate read could find the page's orbits
/// already replaced by a later answer.
async fn read_when(client: &Client, condition: &str, read: &str, seconds: u64) -> Value {
    let started = Instant::now();
    let script = format!("if (!({condition})) return {{waiting: true}}; {read}");
    loop {
        let value = client.execute(&script, vec![]).await.unwrap();
        if value.get("waiting") != Some(&Value::Bool(true)) {
            return value;
        }
        assert!(
            started.elapsed() < Duration::from_secs(seconds),
            "timed out waiting for {condition}"
        );
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
}

/// A page expression: whether state point (x, y) is painted (not white)
/// on the canvas.
fn painted(x: &str, y: &str) -> String {
    format!("(studio.colorAt(...studio.pixelOf({x}, {y})).slice(0, 3).join() !== '255,255,255')")
}

async fn click_at(client: &Client, element: &fantoccini::elements::Element, x: f64, y: f64) {
    let mouse = MouseActions::new("mouse".into())
        .then(PointerAction::MoveToElement {
            element: element.clone(),
            duration: None,
            x,
            y,
        })
        .then(PointerAction::Down {
            button: MOUSE_BUTTON_LEFT,
        })
        .then(PointerAction::Up {
            button: MOUSE_BUTTON_LEFT,
        });
    client.perform_actions(mouse).await.unwrap();
}

/// Seeds, counts, second points (the first iterate) and parameters of
/// the page's orbits, once `condition` holds and each orbit's 10th
/// point is painted (read in one snapshot; see [`read_when`]).
async fn orbits_when(client: &Client, condition: &str) -> Vec<Value> {
    let tenth = "o.points[Math.min(10, o.points.length - 1)]";
    let all_painted = format!(
        "studio.orbits.every(o => o.points.length > 0 && {})",
        painted(&format!("{tenth}[0]"), &format!("{tenth}[1]"))
    );
    let read = format!(
        "return studio.orbits.map(o => ({{seed: o.seed, count: o.points.length, first: o.points[0], \
         second: o.points[1], error: o.error, params: o.params, \
         color: studio.colorAt(...studio.pixelOf(...{tenth}))}}));"
    );
    read_when(
        client,
        &format!("({condition}) && {all_painted}"),
        &read,
        60,
    )
    .await
    .as_array()
    .unwrap()
    .clone()
}

/// The page's orbits as they are now.
async fn orbits(client: &Client) -> Vec<Value> {
    orbits_when(client, "true").await
}

/// Each orbit's second point is the library's period map of its seed at
/// the page's parameters, and the orbit is drawn on the canvas.
fn check_against_library(orbits: &[Value], periods: usize) {
    for o in orbits {
        assert!(o["error"].is_null(), "{o}");
        assert_eq!(o["count"].as_u64().unwrap() as usize, periods + 1, "{o}");
        let seed: [f64; 2] = serde_json::from_value(o["seed"].clone()).unwrap();
        let params = ["A", "eps", "mu"].map(|k| o["params"][k].as_f64().unwrap());
        let (system, period) = kapitza_map(params);
        let mut integrator = Integrator::new(Method::Taylor { tol: 1e-10 }).unwrap();
        let y1 = period_map(&mut integrator, &system, period, &seed).unwrap();
        let first: [f64; 2] = serde_json::from_value(o["first"].clone()).unwrap();
        let second: [f64; 2] = serde_json::from_value(o["second"].clone()).unwrap();
        assert_eq!(first, [wrap_angle(seed[0]), seed[1]], "{o}");
        assert_eq!(second, [wrap_angle(y1[0]), y1[1]], "{o}");
        let color: Vec<u8> = serde_json::from_value(o["color"].clone()).unwrap();
        assert_ne!(
            &color[..3],
            &[255, 255, 255],
            "orbit not drawn at its 10th point: {o}"
        );
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
#[ignore = "needs Chromium and chromedriver (apt-get install chromium chromium-driver)"]
async fn browser_seeds_orbits_and_sweeps_a_parameter() {
    let listener = tokio::net::TcpListener::bind("127.0.0.1:0").await.unwrap();
    let studio = format!("http://{}/", listener.local_addr().unwrap());
    tokio::spawn(async move {
        axum::serve(listener, router(mechlab::models::MODELS))
            .await
            .unwrap()
    });
    let port = free_port();
    let driver = std::env::var("CHROMEDRIVER").unwrap_or_else(|_| "/usr/bin/chromedriver".into());
    let _driver = Driver::start(&driver, port);
    let client = connect(port).await;

    client.goto(&studio).await.unwrap();
    wait_for(&client, "window.studio && studio.ready", 30).await;
    orbits_follow_the_slider(&client).await;
    let folder = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("studio");
    std::fs::create_dir_all(&folder).unwrap();
    manifolds_and_a_branch_point(&client, &folder).await;
    sections_without_a_fast_phase(&client, &folder).await;
    a_slice_of_the_period_map(&client, &folder).await;
    the_mechanism_moves(&client, &folder).await;
    the_top_turns_in_space(&client, &folder).await;
    the_steady_motion_panel(&client, &folder).await;
    the_basins_layer(&client, &folder).await;
    the_address_and_the_declared_defaults(&client, &studio).await;
    client.close().await.unwrap();
}

/// The model named in the address opens, and the inputs of the declared
/// settings start from the library's and the studio's declarations (the
/// studio's interactive values), served at `/api/schema`. A shared address
/// restores the parameters, the axes, the view and the overlays, and the
/// address follows the page.
async fn the_address_and_the_declared_defaults(client: &Client, studio: &str) {
    client
        .goto(&format!("{studio}?model=four_bar"))
        .await
        .unwrap();
    wait_for(
        client,
        "window.studio && studio.ready && studio.model.name === 'four_bar'",
        30,
    )
    .await;
    let schema = mechlab_studio::calls::schemas();
    for (id, analysis, name) in [
        ("chaos-periods", "chaos_map", "periods"),
        ("basins-transient", "basins", "transient"),
        ("tol", "orbit", "tol"),
        ("periods", "orbit", "periods"),
        ("mechanism-time", "mechanism", "duration"),
    ] {
        let s = schema.iter().find(|s| s.analysis == analysis).unwrap();
        let declared = s.interactive.get(name).cloned().unwrap_or_else(|| {
            s.settings
                .iter()
                .find(|d| d.name == name)
                .unwrap()
                .default
                .clone()
        });
        let shown = client
            .execute(
                &format!("return Number(document.getElementById('{id}').value);"),
                vec![],
            )
            .await
            .unwrap();
        assert_eq!(shown.as_f64(), declared.as_f64(), "{id}");
    }
    let shared = "?model=kapitza&A=1.7&axes=0,1&x=-1,1&y=-0.5,0.5&show=levels,chaos";
    client.goto(&format!("{studio}{shared}")).await.unwrap();
    wait_for(
        client,
        "window.studio && studio.ready && studio.model.name === 'kapitza'",
        30,
    )
    .await;
    let restored = client
        .execute(
            "return [studio.params.A, studio.view.x, studio.view.y, \
             document.getElementById('show-chaos').checked, \
             document.getElementById('show-equilibria').checked];",
            vec![],
        )
        .await
        .unwrap();
    assert_eq!(
        restored,
        serde_json::json!([1.7, [-1, 1], [-0.5, 0.5], true, false])
    );
    // The address follows a change of the page.
    client
        .execute(
            "studio.params.A = 2.5; studio.view = {x: [-2, 2], y: [-1, 1]}; redraw(); return true;",
            vec![],
        )
        .await
        .unwrap();
    let address = read_when(
        client,
        "location.search.includes('A=2.5')",
        "return location.search;",
        10,
    )
    .await;
    let address = address.as_str().unwrap();
    assert!(
        address.contains("x=-2%2C2") && address.contains("show=levels%2Cchaos"),
        "{address}"
    );
}

/// Three clicked orbits of the Kapitza map, redrawn when the A slider moves.
async fn orbits_follow_the_slider(client: &Client) {
    select_model(client, "kapitza").await;
    let periods = client.find(Locator::Id("periods")).await.unwrap();
    periods.clear().await.unwrap();
    periods.send_keys("400").await.unwrap();

    let canvas = client.find(Locator::Id("plane")).await.unwrap();
    for (x, y) in [(-250.0, 60.0), (120.0, -140.0), (300.0, 200.0)] {
        click_at(client, &canvas, x, y).await;
    }
    let before = orbits_when(
        client,
        "studio.orbits.length === 3 && studio.orbits.every(o => o.done)",
    )
    .await;
    assert_eq!(before.len(), 3);
    check_against_library(&before, 400);
    let seeds: Vec<&Value> = before.iter().map(|o| &o["seed"]).collect();
    assert!(
        seeds[0] != seeds[1] && seeds[1] != seeds[2],
        "three different clicks: {seeds:?}"
    );

    // Move the A slider: every orbit is redrawn for the new value.
    let slider = client.find(Locator::Id("param-A")).await.unwrap();
    click_at(client, &slider, 30.0, 0.0).await;
    let after = orbits_when(
        client,
        "studio.params.A !== 1.5 && studio.orbits.every(o => o.done && o.params.A === studio.params.A)",
    )
    .await;
    check_against_library(&after, 400);
    for (b, a) in before.iter().zip(&after) {
        assert_eq!(b["seed"], a["seed"]);
        assert_ne!(b["second"], a["second"], "A moved, the orbit did not");
    }
}

/// The manifolds overlay at A = 1, and a shift-click continuing the upright in A.
async fn manifolds_and_a_branch_point(client: &Client, folder: &std::path::Path) {
    // The manifolds overlay at A = 1 (a saddle at the upright): W^u and
    // W^s drawn, a lobe area in the note.
    client
        .execute(
            "const a = document.getElementById('value-A'); a.value = '1'; a.dispatchEvent(new Event('change'));\
             document.getElementById('show-manifolds').click(); return true;",
            vec![],
        )
        .await
        .unwrap();
    wait_for(
        client,
        "studio.params.A === 1 && studio.manifolds && studio.manifolds.unstable.length > 100",
        60,
    )
    .await;
    wait_for(
        client,
        "document.getElementById('manifolds-note').textContent.includes('lobe area')",
        10,
    )
    .await;
    tokio::time::sleep(Duration::from_millis(300)).await;

    // Shift-click on the upright: its orbit continued in A (to 1.8 by
    // default) changes stability at the branch point A = 1.42038.
    client
        .execute(
            "const c = document.getElementById('plane'); const r = c.getBoundingClientRect();\
             const [px, py] = studio.pixelOf(0, 0);\
             const at = { clientX: r.left + px * r.width / c.width, clientY: r.top + py * r.height / c.height, bubbles: true, shiftKey: true };\
             c.dispatchEvent(new MouseEvent('mousedown', at)); c.dispatchEvent(new MouseEvent('mouseup', at)); return true;",
            vec![],
        )
        .await
        .unwrap();
    wait_for(client, "studio.branches !== null", 60).await;
    let at = client
        .execute(
            "return studio.branches.bifurcations.filter(b => b.kind === 'branch_point').map(b => b.parameter);",
            vec![],
        )
        .await
        .unwrap();
    let at: Vec<f64> = serde_json::from_value(at).unwrap();
    assert_eq!(at.len(), 1, "{at:?}");
    assert!((at[0] - 1.4203816679).abs() < 1e-6, "{at:?}");
    assert_eq!(
        orbits(client).await.len(),
        3,
        "a shift-click seeds no orbit"
    );
    tokio::time::sleep(Duration::from_millis(300)).await;

    let png = client.screenshot().await.unwrap();
    std::fs::write(folder.join("browser.png"), png).unwrap();
    eprintln!("screenshot: {}", folder.join("browser.png").display());
}

/// Duffing's unforced double well: the basins layer paints each start
/// in its attractor's colour (85 % over white), and a clicked orbit's
/// entry names the attractor its start ends on.
async fn the_basins_layer(client: &Client, folder: &std::path::Path) {
    select_model(client, "duffing").await;
    client
        .execute(
            "const g = document.getElementById('value-gamma'); g.value = '0'; g.dispatchEvent(new Event('change'));\
             document.getElementById('show-basins').click(); return true;",
            vec![],
        )
        .await
        .unwrap();
    // At four starts away from the attractors, most of the 3 × 3
    // canvas pixels around each (a grid line covers at most 3) are
    // the colour of the start's label.
    let painted = "studio.basins && studio.basins.pixels === 256 && studio.params.gamma === 0 && \
         [[0.3, 0.6], [0.7, 0.3], [0.45, 0.8], [0.2, 0.2]].every(([u, v]) => { \
           const x = studio.view.x[0] + u * (studio.view.x[1] - studio.view.x[0]); \
           const y = studio.view.y[0] + v * (studio.view.y[1] - studio.view.y[0]); \
           const want = studio.attractorColor(studio.attractorAt(x, y)).map(c => Math.round(0.85 * c + 0.15 * 255)); \
           const [px, py] = studio.pixelOf(x, y); let good = 0; \
           for (const dx of [-1, 0, 1]) for (const dy of [-1, 0, 1]) { \
             const got = studio.colorAt(px + dx, py + dy); \
             if (want.every((c, i) => Math.abs(c - got[i]) <= 2)) good += 1; } \
           return good >= 5; })";
    wait_for(client, painted, 60).await;
    let labels = client
        .execute("return [...new Set(studio.basins.labels)].sort();", vec![])
        .await
        .unwrap();
    assert_eq!(
        labels,
        serde_json::json!([0, 1]),
        "two wells, no diverged start"
    );
    client
        .execute("studio.seed(0.5, 0.4); return true;", vec![])
        .await
        .unwrap();
    wait_for(
        client,
        "document.getElementById('orbit-list').textContent.includes('attractor')",
        30,
    )
    .await;
    let png = client.screenshot().await.unwrap();
    std::fs::write(folder.join("basins.png"), png).unwrap();
}

/// Hénon–Heiles: its section with the MEGNO map behind, then a tilted plane.
async fn sections_without_a_fast_phase(client: &Client, folder: &std::path::Path) {
    // Hénon–Heiles has no fast phase: its Poincaré section at
    // E = 1/8, a clicked orbit's crossings drawn, the MEGNO map behind.
    select_model(client, "henon_heiles").await;
    client
        .execute(
            "document.getElementById('show-section').click(); document.getElementById('show-megno').click(); return true;",
            vec![],
        )
        .await
        .unwrap();
    wait_for(client, "studio.section && studio.megno !== null", 60).await;
    // The map's chaotic fraction with its class check beside it.
    let note = read_when(
        client,
        "document.getElementById('megno-note').textContent.includes('%')",
        "return document.getElementById('megno-note').textContent;",
        60,
    )
    .await;
    let note = note.as_str().unwrap_or_default();
    assert!(
        note.contains("chaotic") && note.contains("reclassified at a hundredth of the tolerance"),
        "{note}"
    );
    client
        .execute("studio.sectionSeed(0.1, 0.0); return true;", vec![])
        .await
        .unwrap();
    // Waits for the 20th crossing to be painted (the frame after the
    // orbit is done): a crossing not drawn times out.
    let crossing = "studio.orbits[0].points[20]";
    read_when(
        client,
        &format!(
            "{ONE_LONG_ORBIT} && {}",
            painted(&format!("{crossing}[0]"), &format!("{crossing}[1]"))
        ),
        "return true;",
        60,
    )
    .await;
    let png = client.screenshot().await.unwrap();
    std::fs::write(folder.join("section.png"), png).unwrap();

    // The tilted plane x + 0.5 y = 0: the page's axes become its chart.
    client
        .execute(
            "const m = document.getElementById('show-megno'); if (m.checked) m.click(); \
             const p = document.getElementById('section-plane'); p.value = 'x + 0.5*y'; p.dispatchEvent(new Event('change')); \
             studio.sectionSeed(0.1, 0.05); return true;",
            vec![],
        )
        .await
        .unwrap();
    wait_for(client, ONE_LONG_ORBIT, 60).await;
    let axes = client
        .execute("return studio.sectionAxes;", vec![])
        .await
        .unwrap();
    assert_eq!(axes, serde_json::json!(["y", "p_y − 0.5·p_x"]));
}

/// The shaken double pendulum: a section that is a slice of its period map.
async fn a_slice_of_the_period_map(client: &Client, folder: &std::path::Path) {
    // The shaken double pendulum has a fast phase: its section is a
    // slice of the period map, at the averaged energy H̄.
    select_model(client, "double_pendulum").await;
    let label = client
        .execute(
            "const m = document.getElementById('show-megno'); if (m.checked) m.click(); \
             const e = document.getElementById('energy'); e.value = -1.5; e.dispatchEvent(new Event('change')); \
             const v = document.getElementById('section-value'); v.value = Math.PI; v.dispatchEvent(new Event('change')); \
             document.getElementById('show-section').click(); \
             return [document.getElementById('section-controls').style.display, document.getElementById('section-energy-of').textContent];",
            vec![],
        )
        .await
        .unwrap();
    assert_eq!(label, serde_json::json!(["", "H̄"]));
    wait_for(client, "studio.section", 30).await;
    client
        .execute(
            "studio.sectionSeed(Math.PI + 0.3, 0.0); return true;",
            vec![],
        )
        .await
        .unwrap();
    // Drawn about π (the hanging rod), and the view moved onto it: the
    // 4th point painted (waited for; a point not drawn times out),
    // then every point read from the same snapshot.
    let drawn = format!(
        "studio.orbits.length === 1 && studio.orbits[0].done && studio.orbits[0].points.length > 5 && {}",
        painted("studio.orbits[0].points[3][0]", "studio.orbits[0].points[3][1]")
    );
    let about_pi = read_when(
        client,
        &drawn,
        "return studio.orbits[0].points.every(([q]) => q > 0);",
        60,
    )
    .await;
    assert_eq!(about_pi, serde_json::json!(true));
    let png = client.screenshot().await.unwrap();
    std::fs::write(folder.join("section_slice.png"), png).unwrap();
}

/// The four-bar: a click seeds an orbit and the mechanism moves beside
/// it, its crank pin B painted where the frame on show puts it.
async fn the_mechanism_moves(client: &Client, folder: &std::path::Path) {
    select_model(client, "four_bar").await;
    client
        .execute("studio.seed(0.35, 0.4); return true;", vec![])
        .await
        .unwrap();
    // Painted: the canvas pixel under B (index 2) of the frame on show
    // is the points' colour, read in the same turn as the frame.
    let painted = "studio.mechanism && studio.mechanismFrame > 30 && (() => { \
         const m = studio.mechanism, f = studio.mechanismFrame, [x, y] = m.frames[f][2]; \
         const c = document.getElementById('mechanism'), g = c.getContext('2d'); \
         const [x0, x1, y0, y1] = m.box, w = c.width, h = c.height; \
         const s = 0.85 * Math.min(w / (x1 - x0), h / (y1 - y0)); \
         const px = Math.round(w / 2 + (x - (x0 + x1) / 2) * s), py = Math.round(h / 2 - (y - (y0 + y1) / 2) * s); \
         const d = g.getImageData(px, py, 1, 1).data; return d[0] > 150 && d[1] < 120; })()";
    let frames = read_when(
        client,
        painted,
        "return studio.mechanism.frames.length;",
        60,
    )
    .await;
    assert_eq!(frames, serde_json::json!(601));
    let png = client.screenshot().await.unwrap();
    std::fs::write(folder.join("mechanism.png"), png).unwrap();
}

/// The heavy top found precessing steadily (hanging, Ω = 2) moves in
/// space from that motion, drawn as its frame: its centre is painted where
/// an orthographic view from azimuth a and elevation e about the way up z
/// puts it (screen right (−sin a, cos a, 0), screen up (−sin e cos a,
/// −sin e sin a, cos e), written here), and dragging the canvas 80 pixels
/// to the left turns the view by 0.8 radians, the centre painted where the
/// turned view puts it.
async fn the_top_turns_in_space(client: &Client, folder: &std::path::Path) {
    select_model(client, "heavy_top").await;
    client
        .execute(
            "const set = (id, v) => { document.getElementById(id).value = v; }; \
             set('steady-speed', 'phi'); set('steady-at', '2'); set('steady-rates', '2, 0, 0'); \
             set('steady-start', '0, 1.5, 0'); studio.runSteady(); return true;",
            vec![],
        )
        .await
        .unwrap();
    let centre_painted = "studio.mechanism && studio.mechanism.in_space && studio.mechanismFrame > 5 && (() => { \
         const m = studio.mechanism, p = m.frames[studio.mechanismFrame][0], v = studio.mechanismView; \
         const c = document.getElementById('mechanism'), g = c.getContext('2d'), w = c.width, h = c.height; \
         const [a, e] = [v.azimuth, v.elevation], s = 0.85 * Math.min(w, h) / (2 * m.radius); \
         const d = p.map((x, k) => x - m.middle[k]); \
         const right = -Math.sin(a) * d[0] + Math.cos(a) * d[1]; \
         const up = -Math.sin(e) * Math.cos(a) * d[0] - Math.sin(e) * Math.sin(a) * d[1] + Math.cos(e) * d[2]; \
         const px = Math.round(w / 2 + right * s), py = Math.round(h / 2 - up * s); \
         const pixel = g.getImageData(px, py, 1, 1).data; \
         return pixel[0] > 150 && pixel[1] < 120; })()";
    let before = read_when(
        client,
        centre_painted,
        "return [studio.mechanismView.azimuth, studio.mechanism.up, studio.mechanism.body_frames];",
        60,
    )
    .await;
    assert_eq!(
        before[1],
        serde_json::json!([0, 0, 1]),
        "up against gravity"
    );
    assert_eq!(before[2], serde_json::json!([[0, 1, 2, 3]]));
    client
        .execute(
            "const c = document.getElementById('mechanism'); \
             c.dispatchEvent(new PointerEvent('pointerdown', {clientX: 200, clientY: 100, pointerId: 7})); \
             c.dispatchEvent(new PointerEvent('pointermove', {clientX: 120, clientY: 100, pointerId: 7})); \
             c.dispatchEvent(new PointerEvent('pointerup', {clientX: 120, clientY: 100, pointerId: 7})); \
             return true;",
            vec![],
        )
        .await
        .unwrap();
    let after = read_when(
        client,
        centre_painted,
        "return studio.mechanismView.azimuth;",
        60,
    )
    .await;
    let turned = after.as_f64().unwrap() - before[0].as_f64().unwrap();
    assert!((turned - 0.8).abs() < 1e-12, "turned by {turned}");
    let png = client.screenshot().await.unwrap();
    std::fs::write(folder.join("mechanism_in_space.png"), png).unwrap();
}

/// Chaplygin's sleigh: the button linearises its straight glide; the
/// panel says the verdict and paints the sweep's boundary at u = 0 (the
/// red line at the canvas's middle for the sweep −2 … 2).
async fn the_steady_motion_panel(client: &Client, folder: &std::path::Path) {
    select_model(client, "chaplygin_sleigh").await;
    client
        .execute(
            "document.getElementById('steady-at').value = '1'; studio.runSteady(); return true;",
            vec![],
        )
        .await
        .unwrap();
    let boundary = "studio.steady && studio.steady.sweep && (() => { \
         const c = document.getElementById('steady'), g = c.getContext('2d'); \
         const d = g.getImageData(Math.round(c.width / 2), 10, 1, 1).data; return d[0] > 150 && d[1] < 100; })()";
    let note = read_when(
        client,
        boundary,
        "return document.getElementById('steady-note').textContent;",
        60,
    )
    .await;
    let note = note.as_str().unwrap();
    assert!(
        note.contains("asymptotically stable") && note.contains("-0.66666667"),
        "{note}"
    );
    // The panel's canvas as the page drew it (below the window's fold),
    // as a PNG data address, with the note.
    let url = client
        .execute(
            "return document.getElementById('steady').toDataURL();",
            vec![],
        )
        .await
        .unwrap();
    let text = format!("{}\n{note}\n", url.as_str().unwrap());
    std::fs::write(folder.join("steady_motion.txt"), text).unwrap();
}

/// Kapitza's period map from the library: its exact system at `params`
/// (A, ε, μ) and the forcing period.
fn kapitza_map(params: [f64; 3]) -> (kapitza::Exact, f64) {
    let exact = kapitza::Exact {
        params: kapitza::Params::from_values(&params),
    };
    (exact, 2.0 * std::f64::consts::PI * params[1])
}
