//! The batch Taylor method: every lane equals the scalar method's run bit
//! for bit (generated models with symbolic and numeric mass matrices, their
//! variational equations, the FLI), lanes that diverge or start from a NaN
//! end with the scalar error without disturbing the others, and only the
//! Taylor method has a batch mode.

use mechlab::analysis::floquet::{monodromies, monodromy};
use mechlab::analysis::lyapunov::{fast_lyapunov_indicator, fast_lyapunov_indicators};
use mechlab::models::{double_pendulum, kapitza, triple_pendulum};
use mechlab::ode::{
    Integrator, LaneIntegrator, Lanes, Method, OdeError, Orbit, Scalar, System, TaylorWork, LANES,
};

use crate::common::assert_streams_equal_scalar;

const TAYLOR: Method = Method::Taylor { tol: 1e-10 };

/// Every lane of a batch run against the scalar run of the same start.
fn assert_lanes_equal_scalar<S: System<N>, const N: usize>(
    system: &S,
    starts: &[[f64; N]; LANES],
    t1: f64,
) {
    let mut batch = LaneIntegrator::new(TAYLOR).unwrap();
    let ends = batch.advance(system, 0.0, starts, [true; LANES], t1);
    let mut scalar = Integrator::new(TAYLOR).unwrap();
    for (start, end) in starts.iter().zip(ends) {
        let expected = scalar.advance(system, 0.0, start, t1);
        assert_eq!(end, expected, "lane from {start:?}");
    }
    assert_eq!(batch.stats.steps, scalar.stats.steps);
    assert_eq!(batch.stats.f_evals, scalar.stats.f_evals);
}

/// Starts spread over the cylinder (q, p) for lane l.
fn spread<const N: usize>(l: usize) -> [f64; N] {
    std::array::from_fn(|i| 0.37 * (l as f64 + 1.0) - 0.21 * i as f64)
}

#[test]
fn every_lane_equals_the_scalar_run_bit_for_bit() {
    let kapitza = kapitza::Exact {
        params: kapitza::Params::default(),
    };
    assert_lanes_equal_scalar(&kapitza, &std::array::from_fn(spread), 2.0);
    let averaged = kapitza::Averaged {
        params: kapitza::Params::default(),
    };
    assert_lanes_equal_scalar(&averaged, &std::array::from_fn(spread), 3.0);
    let double = double_pendulum::Exact {
        params: double_pendulum::Params::default(),
    };
    assert_lanes_equal_scalar(&double, &std::array::from_fn(spread), 0.5);
    // Mass matrix solved by Cholesky in the recurrences, one per lane.
    let triple = triple_pendulum::Exact {
        params: triple_pendulum::Params::default(),
    };
    assert_lanes_equal_scalar(&triple, &std::array::from_fn(spread), 0.3);
}

#[test]
fn batch_fli_equals_the_scalar_fli_for_every_orbit() {
    let system = double_pendulum::Exact {
        params: double_pendulum::Params::default(),
    };
    let period = 2.0 * std::f64::consts::PI / system.params.nu;
    // Thirteen orbits streamed through eight lanes: lanes take new orbits
    // as theirs end, and three idle at the end.
    let starts: Vec<[f64; 4]> = (0..13).map(spread).collect();
    let w0 = [0.5; 4];
    let mut batch = LaneIntegrator::new(TAYLOR).unwrap();
    let values =
        fast_lyapunov_indicators::<_, 4, 8>(&mut batch, &system, period, &starts, &[w0], 20);
    let mut scalar = Integrator::new(TAYLOR).unwrap();
    for (start, value) in starts.iter().zip(values) {
        let expected =
            fast_lyapunov_indicator::<_, 4, 8>(&mut scalar, &system, period, start, &w0, 20);
        assert_eq!(value, expected, "orbit from {start:?}");
    }
    assert_eq!(batch.stats.f_evals, scalar.stats.f_evals);
}

/// y' = y², y = y₀/(1 − y₀t): blows up at t = 1/y₀.
struct BlowUp;
impl System<1> for BlowUp {
    fn rhs(&self, _t: f64, y: &[f64; 1]) -> [f64; 1] {
        [y[0] * y[0]]
    }
    fn taylor<Num: Scalar>(
        &self,
        _t: Num,
        y: &[Num; 1],
        order: usize,
        _work: &mut TaylorWork<Num>,
        out: &mut [[Num; 1]],
    ) -> bool {
        out[0] = *y;
        for k in 0..order {
            let mut square = Num::from(0.0);
            for j in 0..=k {
                square += out[j][0] * out[k - j][0];
            }
            out[k + 1] = [square * (1.0 / (k + 1) as f64)];
        }
        true
    }
}

#[test]
fn a_diverging_or_nan_lane_ends_alone_with_the_scalar_error() {
    // Lane 2 blows up at t = 0.5 before t1 = 1, lane 5 starts from NaN,
    // lane 7 is inactive.
    let starts: [[f64; 1]; LANES] = std::array::from_fn(|l| match l {
        2 => [2.0],
        5 => [f64::NAN],
        _ => [0.1 * l as f64 - 0.3],
    });
    let mut active = [true; LANES];
    active[7] = false;
    let mut batch = LaneIntegrator::new(TAYLOR).unwrap();
    let ends = batch.advance(&BlowUp, 0.0, &starts, active, 1.0);
    let mut scalar = Integrator::new(TAYLOR).unwrap();
    for (l, end) in ends.into_iter().enumerate() {
        match l {
            7 => assert_eq!(end, Ok(starts[7]), "an inactive lane is left as it was"),
            // Debug text: NaN ≠ NaN, but the errors must read the same.
            _ => assert_eq!(
                format!("{end:?}"),
                format!("{:?}", scalar.advance(&BlowUp, 0.0, &starts[l], 1.0)),
                "lane {l}"
            ),
        }
        let y0 = starts[l][0];
        match l {
            2 => assert!(matches!(
                end,
                Err(OdeError::NonFinite { .. } | OdeError::StepSizeUnderflow { .. })
            )),
            5 => assert!(matches!(end, Err(OdeError::NonFiniteInitialState { .. }))),
            7 => {}
            _ => {
                let exact = y0 / (1.0 - y0);
                assert!((end.unwrap()[0] - exact).abs() < 1e-9 * exact.abs().max(1.0));
            }
        }
    }
}

#[test]
fn lanes_out_of_steps_or_run_backwards_end_as_their_scalar_runs() {
    // Backwards in time, every lane with its own number of steps: lane l
    // from y₀ = −0.3 − 0.3 l, blowing up at t = 1/y₀, so lanes 6 and 7
    // diverge on the way to t = −0.5.
    let starts: [[f64; 1]; LANES] = std::array::from_fn(|l| [-0.3 - 0.3 * l as f64]);
    for max_steps in [1_000, 4] {
        let mut batch = LaneIntegrator::new(TAYLOR).unwrap();
        batch.max_steps = max_steps;
        let ends = batch.advance(&BlowUp, 0.0, &starts, [true; LANES], -0.5);
        let mut scalar = Integrator::new(TAYLOR).unwrap();
        scalar.max_steps = max_steps;
        let mut out_of_steps = 0;
        for (l, end) in ends.into_iter().enumerate() {
            let expected = scalar.advance(&BlowUp, 0.0, &starts[l], -0.5);
            assert_eq!(format!("{end:?}"), format!("{expected:?}"), "lane {l}");
            out_of_steps += usize::from(matches!(end, Err(OdeError::TooManySteps { .. })));
            if max_steps == 1_000 {
                let y0 = starts[l][0];
                let exact = y0 / (1.0 + 0.5 * y0);
                match end {
                    Ok(y) => assert!(l <= 5 && (y[0] - exact).abs() < 1e-9 * exact.abs()),
                    Err(_) => assert!(l >= 6, "lane {l}: {end:?}"),
                }
            }
        }
        // The budget of 4 steps stops some lanes and not others.
        if max_steps == 4 {
            assert!(out_of_steps > 0 && out_of_steps < LANES, "{out_of_steps}");
        }
        assert_eq!(batch.stats.f_evals, scalar.stats.f_evals);
    }
}

#[test]
fn a_stream_ends_each_orbit_with_its_scalar_segments() {
    // Ten orbits over three segments [0, 0.2] each, every segment started
    // from 1.5 × the last end: orbit 3 (y₀ = 3, then 11.25) blows up in
    // its second segment, orbit 6 starts from NaN, orbit 8 is stopped after
    // one segment; the others run on.
    let starts: Vec<[f64; 1]> = (0..10)
        .map(|k| match k {
            3 => [3.0],
            6 => [f64::NAN],
            _ => [0.1 * k as f64 - 0.4],
        })
        .collect();
    let segments = |k: usize| if k == 8 { 1 } else { 3 };
    let mut ends: Vec<Vec<[f64; 1]>> = vec![Vec::new(); starts.len()];
    let mut done = vec![0; starts.len()];
    let mut batch = LaneIntegrator::new(TAYLOR).unwrap();
    let errors = batch.stream(&Orbit::of_one_system(&BlowUp, 0.2, &starts), |k, y| {
        done[k] += 1;
        ends[k].push(*y);
        y[0] *= 1.5; // each segment starts from a changed state, as the FLI's renormalisation
        done[k] < segments(k)
    });
    let mut scalar = Integrator::new(TAYLOR).unwrap();
    for (k, start) in starts.iter().enumerate() {
        let mut samples = Vec::new();
        let expected = scalar.stream(&BlowUp, start, 0.2, segments(k), &mut |y| {
            samples.push(*y);
            y[0] *= 1.5;
            true
        });
        assert_eq!(ends[k], samples, "orbit {k}'s segment ends");
        assert_eq!(
            format!("{:?}", errors[k]),
            format!("{:?}", expected.err()),
            "orbit {k}"
        );
    }
    assert_eq!(ends[3].len(), 1, "orbit 3 diverges in its second segment");
    assert!(matches!(
        errors[3],
        Some(OdeError::NonFinite { .. } | OdeError::StepSizeUnderflow { .. })
    ));
    assert!(matches!(
        errors[6],
        Some(OdeError::NonFiniteInitialState { .. })
    ));
    assert_eq!(done[8], 1);
    assert_eq!(batch.stats.steps, scalar.stats.steps);
    assert_eq!(batch.stats.f_evals, scalar.stats.f_evals);
}

/// Lanes with their own parameters and ends (a sweep over parameters):
/// Kapitza at 13 points (A, ε) streamed through 8 lanes, each to its own
/// period, and the triple pendulum at 9 (masses, lengths: a Cholesky
/// factor per lane), each equal to its scalar run bit for bit; a lane
/// whose orbit has length 0 returns its start, one from NaN its error.
#[test]
fn lanes_with_their_own_parameters_equal_scalar_runs() {
    let kapitza: Vec<kapitza::Exact> = (0..13)
        .map(|k| kapitza::Exact {
            params: kapitza::Params {
                A: 0.5 + 0.3 * k as f64,
                eps: 0.05 + 0.02 * k as f64,
                mu: 0.01 * k as f64,
            },
        })
        .collect();
    let orbits: Vec<Orbit<_, 2>> = kapitza
        .iter()
        .enumerate()
        .map(|(k, system)| Orbit {
            system,
            start: spread(k),
            end: match k {
                4 => 0.0,
                _ => 2.0 * std::f64::consts::PI * system.params.eps,
            },
        })
        .collect();
    assert_streams_equal_scalar(&orbits);
    let triple: Vec<triple_pendulum::Exact> = (0..9)
        .map(|k| {
            let params = triple_pendulum::Params {
                m2: 0.5 + 0.2 * k as f64,
                l3: 1.5 - 0.1 * k as f64,
                ..Default::default()
            };
            triple_pendulum::Exact { params }
        })
        .collect();
    let orbits: Vec<Orbit<_, 6>> = triple
        .iter()
        .enumerate()
        .map(|(k, system)| Orbit {
            system,
            start: if k == 6 { [f64::NAN; 6] } else { spread(k) },
            end: 0.2 + 0.01 * k as f64,
        })
        .collect();
    assert_streams_equal_scalar(&orbits);
}

/// The monodromy matrices of a sweep over (A, ε) in lanes, each over its
/// own period, equal the scalar ones bit for bit.
#[test]
fn monodromies_in_lanes_equal_the_scalar_ones() {
    let problems: Vec<(kapitza::Exact, f64, [f64; 2])> = (0..11)
        .map(|k| {
            let params = kapitza::Params {
                A: 1.0 + 0.25 * k as f64,
                eps: 0.1 + 0.01 * k as f64,
                mu: 0.0,
            };
            let period = 2.0 * std::f64::consts::PI * params.eps;
            (kapitza::Exact { params }, period, [0.0, 0.0])
        })
        .collect();
    let (batch, stats) = monodromies::<_, 2, 6>(TAYLOR, &problems);
    let mut f_evals = 0;
    for ((system, period, y0), result) in problems.iter().zip(batch) {
        let mut scalar = Integrator::new(TAYLOR).unwrap();
        let expected = monodromy::<_, 2, 6>(&mut scalar, system, *period, y0);
        assert_eq!(result, expected, "{:?}", system.params);
        f_evals += scalar.stats.f_evals;
    }
    assert_eq!(stats.f_evals, f_evals);
}

#[test]
fn only_the_taylor_method_has_a_batch_mode() {
    let dop853 = Method::parse("dop853", 1e-8).unwrap();
    assert_eq!(
        LaneIntegrator::new(dop853).err(),
        Some(OdeError::NoBatchMode("dop853"))
    );
    assert!(LaneIntegrator::new(Method::Taylor { tol: 0.0 }).is_err());
    // Lane arithmetic is the scalar arithmetic, lane by lane.
    let x = Lanes(std::array::from_fn(|l| l as f64 - 2.5));
    let y = (x * x - x / 3.0).sqrt() + 1.0;
    for l in 0..LANES {
        let a = l as f64 - 2.5;
        assert_eq!(y.0[l].to_bits(), ((a * a - a / 3.0).sqrt() + 1.0).to_bits());
    }
}

/// The straight-line sin/cos against libm within 2 ulps; the step rule's
/// log2 and exp2 within 1e-12 over the ranges the integrators meet.
#[test]
fn straight_line_kernels_match_libm() {
    use mechlab::ode::kernels::{exp2, log2, sin_cos};
    let close = |a: f64, b: f64, tol: f64| (a - b).abs() <= tol * b.abs().max(1.0);
    let mut x = 0.123_f64;
    for i in 0..200_000 {
        // A spread of magnitudes from 1e-8 to 8e5, both signs.
        x = (x * 7.31 + 0.377).fract();
        let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
        let arg = sign * 10f64.powf(-8.0 + 13.9 * x);
        let (s, c) = sin_cos(arg);
        let (ls, lc) = arg.sin_cos();
        assert!(close(s, ls, 2.0 * f64::EPSILON), "sin {arg}: {s} vs {ls}");
        assert!(close(c, lc, 2.0 * f64::EPSILON), "cos {arg}: {c} vs {lc}");
        let r = 10f64.powf(-300.0 + 600.0 * x);
        assert!(close(log2(r), r.log2(), 1e-12), "log2 {r}");
        let y = sign * 1000.0 * x;
        assert!(((exp2(y) - y.exp2()) / y.exp2()).abs() <= 1e-12, "exp2 {y}");
    }
    assert_eq!(sin_cos(1e7), 1e7f64.sin_cos());
    assert!(sin_cos(f64::NAN).0.is_nan());
}

/// A field whose series is NaN past order 0 (as at a model's singular
/// point, where a quotient divides by 0).
struct NanSeries;
impl System<1> for NanSeries {
    fn rhs(&self, _t: f64, _y: &[f64; 1]) -> [f64; 1] {
        [f64::NAN]
    }
    fn taylor<Num: Scalar>(
        &self,
        _t: Num,
        y: &[Num; 1],
        order: usize,
        _work: &mut TaylorWork<Num>,
        out: &mut [[Num; 1]],
    ) -> bool {
        out[0] = *y;
        for row in &mut out[1..=order] {
            *row = [Num::from(f64::NAN)];
        }
        true
    }
}

/// NaN coefficients are a non-finite state where the step starts, in a
/// stream and in its scalar run alike, not a vanishing (exact) series
/// whose step would run to the end of time.
#[test]
fn nan_coefficients_stop_the_run_where_they_appear() {
    let mut batch = LaneIntegrator::new(TAYLOR).unwrap();
    let errors = batch.stream(&Orbit::of_one_system(&NanSeries, 0.5, &[[1.0]]), |_, _| {
        true
    });
    let mut scalar = Integrator::new(TAYLOR).unwrap();
    let expected = scalar.stream(&NanSeries, &[1.0], 0.5, 3, &mut |_| true);
    assert_eq!(errors[0], expected.err());
    assert!(
        matches!(errors[0], Some(OdeError::NonFinite { t, .. }) if t == 0.0),
        "{:?}",
        errors[0]
    );
}
