//! The performance figures of the Kapitza period map: the integrators'
//! overhead over bare right-hand-side calls, time to 1e-10, the peer ratio.

use crate::harness::{end_state, seconds_at, timed, BenchError, Row, Solver, PEER};
use mechlab::models::kapitza;
use mechlab::ode::{Method, System};
use std::cell::RefCell;
use std::collections::BTreeMap;
use std::hint::black_box;

/// The performance figures of the Kapitza period map (issue targets).
#[derive(serde::Serialize)]
pub struct Performance {
    bare_rhs_ns: f64,
    bare_rhs_latency_ns: f64,
    overhead_dop853: f64,
    overhead_rk4: f64,
    overhead_dop853_against_latency: f64,
    overhead_rk4_against_latency: f64,
    #[serde(rename = "seconds_to_1e-10")]
    seconds_to_1e_10: BTreeMap<String, f64>,
    #[serde(rename = "peer_seconds_to_1e-10")]
    peer_seconds_to_1e_10: Option<f64>,
    #[serde(rename = "best_method_at_1e-10")]
    best_method_at_1e_10: String,
    #[serde(rename = "periods_per_second_at_1e-10")]
    periods_per_second_at_1e_10: f64,
    #[serde(rename = "speedup_over_peer_at_1e-10")]
    speedup_over_peer_at_1e_10: Option<f64>,
    #[serde(rename = "dop853_speedup_over_peer_dop853_at_1e-10")]
    dop853_speedup_over_peer_dop853_at_1e_10: Option<f64>,
}

struct Recording<'a, S> {
    inner: &'a S,
    calls: RefCell<Vec<(f64, [f64; 2])>>,
}

impl<S: System<2>> System<2> for Recording<'_, S> {
    fn rhs(&self, t: f64, y: &[f64; 2]) -> [f64; 2] {
        self.calls.borrow_mut().push((t, *y));
        self.inner.rhs(t, y)
    }
}

/// Time per f-evaluation inside an integration over the time of one bare f,
/// timed as throughput (independent calls) and as latency (dependent calls).
struct Overhead {
    against_throughput: f64,
    against_latency: f64,
    bare: f64,
    latency: f64,
}

/// The performance figures, all measured in this run.
pub fn performance(
    system: &kapitza::Exact,
    y0: &[f64; 2],
    period: f64,
    periods: usize,
    rows: &[Row],
) -> Result<Performance, BenchError> {
    // Overhead: integration time / (f-evaluations × time of one bare f), the
    // bare f timed on exactly the (t, y) at which the integrator called it.
    let overhead = |method: Method| -> Result<Overhead, BenchError> {
        let recording = Recording {
            inner: system,
            calls: RefCell::new(Vec::new()),
        };
        end_state::<_, 2, 3>(Solver::Ours(method), &recording, y0, period, periods)?;
        let calls = recording.calls.into_inner();
        let ((_, evals), seconds) = timed(0.3, || {
            end_state::<_, 2, 3>(Solver::Ours(method), system, y0, period, periods)
        })?;
        // Throughput: independent evaluations, which the CPU overlaps.
        let (_, throughput_total) = timed(0.3, || {
            let mut sum = 0.0;
            for (t, y) in &calls {
                sum += system.rhs(black_box(*t), black_box(y))[1];
            }
            Ok(black_box(sum))
        })?;
        // Latency: each evaluation waits for the previous one, as the stages
        // of a Runge–Kutta step do (0 × previous result keeps the dependency).
        let (_, latency_total) = timed(0.3, || {
            let mut previous = 0.0;
            for (t, y) in &calls {
                let input = [y[0] + 0.0 * previous, y[1]];
                previous = system.rhs(*t, &input)[1];
            }
            Ok(black_box(previous))
        })?;
        let bare = throughput_total / calls.len() as f64;
        let latency = latency_total / calls.len() as f64;
        let per_eval = seconds / evals as f64;
        Ok(Overhead {
            against_throughput: per_eval / bare,
            against_latency: per_eval / latency,
            bare,
            latency,
        })
    };
    let dop853 = overhead(Method::parse("dop853", 1e-10)?)?;
    let rk4 = overhead(Method::Rk4 {
        step: period / 64.0,
    })?;
    let regular: Vec<&Row> = rows
        .iter()
        .filter(|r| r.problem == "kapitza_regular")
        .collect();
    let at = |method: &str| {
        let mine: Vec<&Row> = regular
            .iter()
            .copied()
            .filter(|r| r.method == method)
            .collect();
        seconds_at(&mine, 1e-10)
    };
    let ours: Vec<(&str, f64)> = ["rk4", "gauss4", "gauss6", "dop853", "radau5"]
        .iter()
        .filter_map(|m| at(m).map(|s| (*m, s)))
        .collect();
    let (best_method, best_seconds) = ours
        .iter()
        .copied()
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .ok_or(BenchError::NotReached(1e-10))?;
    let peer = at(PEER);
    Ok(Performance {
        bare_rhs_ns: dop853.bare * 1e9,
        bare_rhs_latency_ns: dop853.latency * 1e9,
        overhead_dop853: dop853.against_throughput,
        overhead_rk4: rk4.against_throughput,
        overhead_dop853_against_latency: dop853.against_latency,
        overhead_rk4_against_latency: rk4.against_latency,
        seconds_to_1e_10: ours.iter().map(|(m, s)| (m.to_string(), *s)).collect(),
        peer_seconds_to_1e_10: peer,
        best_method_at_1e_10: best_method.to_string(),
        periods_per_second_at_1e_10: periods as f64 / best_seconds,
        speedup_over_peer_at_1e_10: peer.map(|p| p / best_seconds),
        dop853_speedup_over_peer_dop853_at_1e_10: match (peer, at("dop853")) {
            (Some(p), Some(d)) => Some(p / d),
            _ => None,
        },
    })
}
