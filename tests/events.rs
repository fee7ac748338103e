//! Dense output and event location: roots against closed forms, the far-side
//! convention, clean restarts, close and simultaneous events, a condition
//! already zero at the start, and two crossings inside one step.

use mechlab::ode::{
    states_at, Direction, Event, EventSettings, Integrator, Method, OdeError, Options, Scalar,
    System, TaylorWork,
};
use std::f64::consts::PI;

/// y'' = −y: y = (cos t, −sin t) from (1, 0).
struct Oscillator;
impl System<2> for Oscillator {
    fn rhs(&self, _t: f64, y: &[f64; 2]) -> [f64; 2] {
        [y[1], -y[0]]
    }
    /// Hand-written recurrences: x^[k+1] = v^[k]/(k+1), v^[k+1] = −x^[k]/(k+1).
    fn taylor<Num: Scalar>(
        &self,
        _t: Num,
        y: &[Num; 2],
        order: usize,
        _work: &mut TaylorWork<Num>,
        out: &mut [[Num; 2]],
    ) -> bool {
        out[0] = *y;
        for k in 0..order {
            let next = 1.0 / (k + 1) as f64;
            out[k + 1] = [out[k][1] * next, -out[k][0] * next];
        }
        true
    }
}

/// y' = 1: the state is the time, so steps are exact and conditions of t alone.
struct Clock;
impl System<1> for Clock {
    fn rhs(&self, _t: f64, _y: &[f64; 1]) -> [f64; 1] {
        [1.0]
    }
    /// y = y0 + (t − t0): every coefficient past the first vanishes, so the
    /// Taylor method's step rule meets its polynomial guard.
    fn taylor<Num: Scalar>(
        &self,
        _t: Num,
        y: &[Num; 1],
        order: usize,
        _work: &mut TaylorWork<Num>,
        out: &mut [[Num; 1]],
    ) -> bool {
        out[0] = *y;
        out[1] = [Num::from(1.0)];
        for row in &mut out[2..=order] {
            *row = [Num::from(0.0)];
        }
        true
    }
}

fn all_methods(tol: f64, step: f64) -> Vec<Method> {
    vec![
        Method::parse("dop853", tol).unwrap(),
        Method::parse("radau5", tol).unwrap(),
        Method::parse("rk4", step).unwrap(),
        Method::parse("gauss6", step).unwrap(),
        Method::parse("taylor", tol).unwrap(),
    ]
}

#[test]
fn dense_output_is_as_accurate_as_the_steps() {
    let times: Vec<f64> = (1..=200).map(|i| i as f64 * 0.05).collect();
    for (name, tol, bound) in [
        ("dop853", 1e-6, 1e-5),
        ("dop853", 1e-10, 1e-9),
        ("taylor", 1e-6, 1e-5),
        ("taylor", 1e-10, 1e-9),
    ] {
        let mut integrator = Integrator::new(Method::parse(name, tol).unwrap()).unwrap();
        let states = integrator
            .solve(
                &Oscillator,
                0.0,
                &[1.0, 0.0],
                times.last().copied().unwrap_or(0.0),
                Options::default().times(&times),
            )
            .map(|run| run.samples)
            .unwrap();
        let steps = integrator.stats.steps;
        assert!(
            steps < 200,
            "the samples must not force the steps ({steps})"
        );
        let worst = times
            .iter()
            .zip(&states)
            .map(|(t, y)| (y[0] - t.cos()).abs().max((y[1] + t.sin()).abs()))
            .fold(0.0f64, f64::max);
        assert!(worst < bound, "{name} {tol}: worst dense error {worst:e}");
    }
}

#[test]
fn dense_output_between_steps_is_as_good_as_at_the_steps() {
    // A wrong interpolant coefficient shows as errors of low order in h between
    // the steps, far above the global error seen at the step ends.
    for (name, tol) in [
        ("dop853", 1e-7),
        ("dop853", 1e-11),
        ("taylor", 1e-7),
        ("taylor", 1e-11),
    ] {
        let exact_error = |t: f64, y: &[f64; 2]| (y[0] - t.cos()).abs().max((y[1] + t.sin()).abs());
        let mut at_steps = 0.0f64;
        let mut ends = vec![0.0];
        Integrator::new(Method::parse(name, tol).unwrap())
            .unwrap()
            .solve(
                &Oscillator,
                0.0,
                &[1.0, 0.0],
                30.0,
                Options::default().observe(&mut |t, y| {
                    at_steps = at_steps.max(exact_error(t, y));
                    ends.push(t);
                }),
            )
            .unwrap();
        // Sample at 1/3 and 2/3 of every step.
        let times: Vec<f64> = ends
            .windows(2)
            .flat_map(|w| [w[0] + (w[1] - w[0]) / 3.0, w[0] + 2.0 * (w[1] - w[0]) / 3.0])
            .collect();
        let method = Method::parse(name, tol).unwrap();
        let states = states_at(method, &Oscillator, 0.0, &[1.0, 0.0], &times).unwrap();
        let between = times
            .iter()
            .zip(&states)
            .map(|(t, y)| exact_error(*t, y))
            .fold(0.0f64, f64::max);
        assert!(
            between < 2.0 * at_steps + 1e-15,
            "{name} {tol}: {between:e} between steps, {at_steps:e} at steps"
        );
    }
}

#[test]
fn crossings_are_located_on_the_far_side_of_the_root() {
    let g = |_t: f64, y: &[f64; 2]| y[0];
    for method in all_methods(1e-10, 0.01) {
        let events = [Event::new(&g).direction(Direction::Falling).non_terminal()];
        let settings = EventSettings {
            time_tolerance: 1e-9,
            ..Default::default()
        };
        let run = Integrator::new(method)
            .unwrap()
            .solve(
                &Oscillator,
                0.0,
                &[1.0, 0.0],
                10.0,
                Options::default().events(&events, settings),
            )
            .unwrap();
        assert!(!run.terminated);
        let roots: Vec<f64> = run.hits.iter().map(|h| h.t).collect();
        assert_eq!(
            roots.len(),
            2,
            "{}: falling roots of cos t on [0, 10]: {roots:?}",
            method.name()
        );
        for (hit, exact) in run.hits.iter().zip([0.5 * PI, 2.5 * PI]) {
            assert!(!hit.rising);
            let lag = hit.t - exact;
            assert!(
                lag > -1e-9 && lag < 3e-9,
                "{}: root {} vs {exact}",
                method.name(),
                hit.t
            );
            assert!(hit.y[0] < 0.0, "far side: the condition has its new sign");
        }
    }
}

#[test]
fn a_terminal_event_stops_and_the_run_restarts_cleanly() {
    let g = |_t: f64, y: &[f64; 2]| y[0];
    for method in all_methods(1e-11, 0.005) {
        let mut integrator = Integrator::new(method).unwrap();
        let events = [Event::new(&g)];
        let first = integrator
            .solve(
                &Oscillator,
                0.0,
                &[1.0, 0.0],
                10.0,
                Options::default().events(&events, EventSettings::default()),
            )
            .unwrap();
        assert!(first.terminated);
        assert!(
            (first.t - 0.5 * PI).abs() < 1e-9,
            "{}: {}",
            method.name(),
            first.t
        );
        // Restart from the reported state: the same root is not found again.
        let second = integrator
            .solve(
                &Oscillator,
                first.t,
                &first.y,
                10.0,
                Options::default().events(&events, EventSettings::default()),
            )
            .unwrap();
        assert!(second.terminated && second.hits.len() == 1 && second.hits[0].rising);
        assert!(
            (second.t - 1.5 * PI).abs() < 1e-8,
            "{}: {}",
            method.name(),
            second.t
        );
    }
}

#[test]
fn a_condition_zero_at_the_start_is_not_an_event() {
    // −sin t is exactly zero at t = 0; its first crossing is at π.
    let g = |_t: f64, y: &[f64; 2]| y[1];
    let events = [Event::new(&g)];
    let run = Integrator::new(Method::parse("dop853", 1e-12).unwrap())
        .unwrap()
        .solve(
            &Oscillator,
            0.0,
            &[1.0, 0.0],
            10.0,
            Options::default().events(&events, EventSettings::default()),
        )
        .unwrap();
    assert!((run.t - PI).abs() < 1e-10, "{}", run.t);
    assert!(run.hits[0].rising);
}

#[test]
fn close_and_simultaneous_events_are_reported_in_order() {
    let g1 = |t: f64, _y: &[f64; 1]| t - 1.0;
    let g2 = |t: f64, _y: &[f64; 1]| t - 1.0 - 1e-6;
    let g3 = |t: f64, _y: &[f64; 1]| t - 1.0 - 1e-14;
    let events = [
        Event::new(&g1).non_terminal(),
        Event::new(&g2).non_terminal(),
        Event::new(&g3).non_terminal(),
    ];
    for method in [
        Method::parse("dop853", 1e-8).unwrap(),
        Method::Rk4 { step: 0.7 },
        Method::parse("taylor", 1e-8).unwrap(),
    ] {
        let run = Integrator::new(method)
            .unwrap()
            .solve(
                &Clock,
                0.0,
                &[0.0],
                2.0,
                Options::default().events(&events, EventSettings::default()),
            )
            .unwrap();
        let order: Vec<usize> = run.hits.iter().map(|h| h.event).collect();
        assert_eq!(order.len(), 3, "{}: {:?}", method.name(), run.hits);
        // g1 and g3 are within the tolerance of each other: one time, past both roots.
        assert_eq!(run.hits[0].t, run.hits[1].t);
        assert!(run.hits[0].t >= 1.0 + 1e-14 && run.hits[0].t < 1.0 + 2e-12);
        assert!(order[..2].contains(&0) && order[..2].contains(&2) && order[2] == 1);
        assert!((run.hits[2].t - (1.0 + 1e-6)).abs() < 2e-12);
    }
}

#[test]
fn two_crossings_inside_one_step_are_found_by_the_interior_samples() {
    // (t − 1)(t − 1.25) is positive at both ends of the RK4 step [0.9, 1.8].
    let g = |t: f64, _y: &[f64; 1]| (t - 1.0) * (t - 1.25);
    let events = [Event::new(&g).non_terminal()];
    let run = |samples: usize| {
        Integrator::new(Method::Rk4 { step: 0.9 })
            .unwrap()
            .solve(
                &Clock,
                0.0,
                &[0.0],
                2.7,
                Options::default().events(
                    &events,
                    EventSettings {
                        interior_samples: samples,
                        ..Default::default()
                    },
                ),
            )
            .unwrap()
            .hits
    };
    assert!(
        run(0).is_empty(),
        "without samples both crossings hide in one step"
    );
    let hits = run(2);
    assert_eq!(hits.len(), 2);
    assert!((hits[0].t - 1.0).abs() < 1e-11 && !hits[0].rising);
    assert!((hits[1].t - 1.25).abs() < 1e-11 && hits[1].rising);
}

#[test]
fn bad_event_settings_are_errors() {
    let g = |t: f64, _y: &[f64; 1]| t - 1.0;
    let events = [Event::new(&g)];
    let error = Integrator::new(Method::Rk4 { step: 0.1 })
        .unwrap()
        .solve(
            &Clock,
            0.0,
            &[0.0],
            2.0,
            Options::default().events(
                &events,
                EventSettings {
                    time_tolerance: 0.0,
                    ..Default::default()
                },
            ),
        )
        .unwrap_err();
    assert!(matches!(error, OdeError::InvalidSetting { .. }));
    assert!(error.to_string().contains("event time tolerance"));
}

#[test]
fn one_run_gives_output_times_events_and_steps_together() {
    // A terminal event at the first root of cos t (t = π/2) ends the
    // samples there; every sample and step end is on the exact solution.
    let g = |_: f64, y: &[f64; 2]| y[0];
    let events = [Event::new(&g)];
    let times: Vec<f64> = (0..=40).map(|i| i as f64 * 0.1).collect();
    let mut steps = 0;
    let mut worst_step = 0.0f64;
    let mut observe = |t: f64, y: &[f64; 2]| {
        steps += 1;
        worst_step = worst_step.max((y[0] - t.cos()).abs());
    };
    let options = Options::default()
        .times(&times)
        .events(&events, EventSettings::default())
        .observe(&mut observe);
    let run = Integrator::new(Method::parse("dop853", 1e-12).unwrap())
        .unwrap()
        .solve(&Oscillator, 0.0, &[1.0, 0.0], 4.0, options)
        .unwrap();
    assert!(
        run.terminated && (run.t - 0.5 * PI).abs() < 1e-10,
        "{}",
        run.t
    );
    assert_eq!(run.samples.len(), 16, "0, 0.1, …, 1.5 come before π/2");
    for (t, y) in times.iter().zip(&run.samples) {
        assert!((y[0] - t.cos()).abs() < 1e-10 && (y[1] + t.sin()).abs() < 1e-10);
    }
    assert!(
        steps > 0 && worst_step < 1e-10,
        "{steps} steps, {worst_step:e}"
    );
    let backwards = Integrator::new(Method::parse("dop853", 1e-12).unwrap())
        .unwrap()
        .solve(
            &Oscillator,
            0.0,
            &[1.0, 0.0],
            -1.0,
            Options::default().times(&[0.0, -0.5, -1.0]),
        )
        .unwrap();
    for (t, y) in [0.0f64, -0.5, -1.0].iter().zip(&backwards.samples) {
        assert!((y[0] - t.cos()).abs() < 1e-10, "{t}: {y:?}");
    }
    let unordered = Integrator::new(Method::parse("dop853", 1e-12).unwrap())
        .unwrap()
        .solve(
            &Oscillator,
            0.0,
            &[1.0, 0.0],
            1.0,
            Options::default().times(&[0.5, 0.2]),
        );
    assert!(matches!(unordered, Err(OdeError::InvalidSetting { .. })));
}
