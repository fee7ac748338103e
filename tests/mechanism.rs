//! The mechanism drawn moving: the generated points against positions
//! written here by hand along the same motion, every drawn model's
//! animation from its start, and the errors of a drawing.

use mechlab::analysis::mechanism::{animate, Frames, MechanismError};
use mechlab::analysis::Refusal;
use mechlab::models::kapitza;
use mechlab::ode::holonomic::ConstraintError;
use mechlab::ode::Method;

const METHOD: Method = Method::Dop853 {
    rtol: 1e-12,
    atol: 1e-12,
};

/// Kapitza's pivot at (0, Aε cos(t/ε)) and its bob one length away at the
/// angle q from the upward vertical, frame by frame.
#[test]
fn kapitzas_bob_is_where_its_angle_puts_it() {
    let model = mechlab::models::by_name("kapitza").unwrap();
    let p = kapitza::Params::default();
    let params = p.values();
    let start = [2.9, 0.3];
    let frames = Frames {
        duration: 3.0,
        count: 301,
    };
    let animation = animate(model, &params, METHOD, &start, &[0, 1], frames).unwrap();
    let flows = model.flows().unwrap();
    let states = flows
        .exact(&params)
        .states_at(METHOD, 0.0, &start, &frames.times())
        .unwrap();
    assert_eq!(
        (animation.points, animation.bars),
        (&["pivot", "bob"][..], &[[0, 1]][..])
    );
    for ((t, y), points) in animation.times.iter().zip(&states).zip(&animation.frames) {
        let pivot = p.A * p.eps * (t / p.eps).cos();
        let bob = [y[0].sin(), pivot + y[0].cos()];
        assert!(
            points[0][0] == 0.0 && (points[0][1] - pivot).abs() < 1e-15,
            "the pivot at t = {t}"
        );
        assert!(
            (points[1][0] - bob[0]).abs() < 1e-15 && (points[1][1] - bob[1]).abs() < 1e-15,
            "the bob at t = {t}: {:?} against {bob:?}",
            points[1]
        );
    }
}

/// Every model whose file names points or bodies (the users' and the
/// test models) is drawn from its start (a constrained model's start is on
/// its constraints) over a few of its own periods: the first frame is the
/// drawing of the start, every point of every frame finite (a singular one
/// would be a named error), a drawing in the plane has z = 0 and each
/// body's frame stays rigid ([`assert_rigid`]). A motion that leaves the
/// model's domain from there (a spring through zero length) is skipped
/// with the integrator's named error.
#[test]
fn every_drawn_model_moves_from_its_start() {
    let mut drawn = 0;
    let models = mechlab::models::MODELS.iter();
    for handle in models.chain(mechlab_test_models::MODELS) {
        let (info, model) = (handle.info, handle.dynamic);
        let Some(drawing) = info.drawing else {
            println!("{}: names no points (not drawn)", info.name);
            continue;
        };
        let Some(flows) = handle.flows() else {
            continue; // (a contact model cannot name points: the reader refuses them)
        };
        let params = model.defaults();
        let mut start = flows.base_state(&params);
        let n = info.coordinates.len();
        start[n] += 0.1; // a little speed along the first coordinate
        if handle.constrained.is_none() {
            // Off the origin of the coordinates (a polar chart's singular point).
            start[..n].iter_mut().for_each(|q| *q += 0.5);
        }
        let duration = 3.0 * flows.phase_period(&params).unwrap_or(1.0);
        let frames = Frames {
            duration,
            count: 31,
        };
        let held: Vec<usize> = (0..1).chain(n..n + 1).collect();
        let animation = match animate(handle, &params, METHOD, &start, &held, frames) {
            Ok(animation) => animation,
            Err(MechanismError::Ode(e)) => {
                println!(
                    "{}: skipped, its motion from {start:?} stops: {e}",
                    info.name
                );
                continue;
            }
            // The speed given to the first coordinate, held, cannot be made
            // consistent (a moving constraint that fixes it at t = 0).
            Err(
                e @ MechanismError::Inconsistent {
                    source: ConstraintError::SingularChart { .. },
                    ..
                },
            ) => {
                println!("{}: skipped, {e}", info.name);
                continue;
            }
            Err(e) => panic!("{}: {e}", info.name),
        };
        drawn += 1;
        assert_eq!(animation.frames.len(), 31, "{}", info.name);
        assert_eq!(
            animation.frames[0],
            (drawing.at)(0.0, &animation.start[..n], &params),
            "{}: the first frame draws the start",
            info.name
        );
        for points in &animation.frames {
            assert_eq!(points.len(), drawing.points.len(), "{}", info.name);
            assert!(
                points.iter().flatten().all(|x| x.is_finite()),
                "{}",
                info.name
            );
            assert!(
                drawing.in_space || points.iter().all(|p| p[2] == 0.0),
                "{}: drawn in the plane",
                info.name
            );
        }
        assert_rigid(&animation);
    }
    assert!(drawn > 0, "no model was drawn");
}

/// Each body's frame is rigid and right-handed: its three axes (tip −
/// centre) keep the length of the first frame's, equal for the three, and
/// stay orthogonal, x × y along +z, to 1e-9 of their length (a body in
/// Euler parameters keeps their unit norm to its constraint's tolerance).
fn assert_rigid(animation: &mechlab::analysis::mechanism::Animation) {
    let sub = |a: [f64; 3], b: [f64; 3]| std::array::from_fn(|i| a[i] - b[i]);
    let dot = |a: [f64; 3], b: [f64; 3]| (0..3).map(|i| a[i] * b[i]).sum::<f64>();
    for &[centre, x, y, z] in animation.body_frames {
        let axes = |points: &[[f64; 3]]| -> [[f64; 3]; 3] {
            [x, y, z].map(|tip| sub(points[tip], points[centre]))
        };
        let length = dot(axes(&animation.frames[0])[0], axes(&animation.frames[0])[0]).sqrt();
        let name = animation.points[centre];
        let tolerance = 1e-9 * length.max(1e-300);
        for (t, points) in animation.times.iter().zip(&animation.frames) {
            let [ax, ay, az] = axes(points);
            for (i, a) in [ax, ay, az].into_iter().enumerate() {
                let size = dot(a, a).sqrt();
                assert!(
                    (size - length).abs() <= tolerance,
                    "{}: body '{name}', axis {i} of length {size} at t = {t}, not {length}",
                    animation.model
                );
            }
            let cross = [
                ax[1] * ay[2] - ax[2] * ay[1],
                ax[2] * ay[0] - ax[0] * ay[2],
                ax[0] * ay[1] - ax[1] * ay[0],
            ];
            let square = length * length;
            assert!(
                dot(ax, ay).abs() <= tolerance * length
                    && dot(ay, az).abs() <= tolerance * length
                    && dot(az, ax).abs() <= tolerance * length
                    && (dot(cross, az) - square * length).abs() <= 3.0 * tolerance * square,
                "{}: body '{name}' is not an orthonormal right-handed frame at t = {t}",
                animation.model
            );
        }
    }
}

#[test]
fn a_drawing_that_cannot_be_made_says_why() {
    let frames = Frames {
        duration: 1.0,
        count: 10,
    };
    let duffing = mechlab::models::by_name("duffing").unwrap();
    let error = animate(
        duffing,
        &duffing.dynamic.defaults(),
        METHOD,
        &[0.1, 0.0],
        &[0, 1],
        frames,
    )
    .unwrap_err();
    assert!(matches!(error, MechanismError::NotDrawn { .. }), "{error}");
    let kapitza = mechlab::models::by_name("kapitza").unwrap();
    let params = kapitza::Params::default().values();
    for (frames, start, what) in [
        (
            Frames {
                duration: f64::NAN,
                count: 10,
            },
            vec![0.1, 0.0],
            "duration",
        ),
        (
            Frames {
                duration: 1.0,
                count: 1,
            },
            vec![0.1, 0.0],
            "frames",
        ),
        (frames, vec![0.1, 0.0, 0.0], "start"),
    ] {
        let error = animate(kapitza, &params, METHOD, &start, &[0, 1], frames).unwrap_err();
        assert!(
            matches!(
                error,
                MechanismError::Refused(Refusal::Setting { .. } | Refusal::StateLength { .. })
            ),
            "{what}: {error}"
        );
        assert!(error.to_string().contains("kapitza"), "{error}");
    }
}

/// The Taylor method draws a constrained mechanism as DOP853 does: the
/// four-bar's points in every frame to 1e-8.
#[test]
fn the_taylor_method_draws_the_four_bar_as_dop853_does() {
    let four_bar = mechlab::models::by_name("four_bar").unwrap();
    let frames = Frames {
        duration: 2.0,
        count: 40,
    };
    let draw = |method| {
        animate(
            four_bar,
            &four_bar.dynamic.defaults(),
            method,
            &[0.3, 0.0, -0.3, 0.2, 0.0, 0.0],
            &[0, 3],
            frames,
        )
        .unwrap()
    };
    let (taylor, dop853) = (draw(Method::Taylor { tol: 1e-13 }), draw(METHOD));
    assert_eq!(taylor.frames.len(), dop853.frames.len());
    for (a, b) in taylor.frames.iter().zip(&dop853.frames) {
        for (p, q) in a.iter().zip(b) {
            assert!(
                (p[0] - q[0]).abs() < 1e-8 && (p[1] - q[1]).abs() < 1e-8,
                "{p:?} against {q:?}"
            );
        }
    }
}
