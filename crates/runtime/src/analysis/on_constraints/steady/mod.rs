//! The linearisation of a steady motion of a constrained model: a motion
//! along which some coordinates (the *shape*: a bicycle's lean and steer)
//! stay still while others advance at constant rates (its position on the
//! ground, its heading, its wheels' rotations) and the model's equations,
//! seen from the shape, do not change.
//!
//! Such a motion is not an equilibrium of the full state, and with
//! nonholonomic constraints the tangent space of the constraints moves
//! along it (a rolling wheel's constraints turn with its heading), so the
//! restriction Zᵀ J Z of the field's Jacobian to an orthonormal basis of
//! that tangent space is not the linearisation of the shape's motion. What
//! is: the shape's accelerations as functions of the shape, its rates and
//! the held speeds, every other component of the state following from the
//! constraints. With y(r) the consistent state of the reduced coordinates
//! r = (shape, shape rates, held speeds), the linearisation is
//! A = P J S, where J is the field's exact Jacobian, S = ∂y/∂r solves the
//! linearised constraints C S = 0 for the dependent components (chosen
//! among the others by pivoting), and P picks the rates of r.

pub mod free;
pub mod spectrum;
pub mod study;

use nalgebra::{DMatrix, DVector};
use serde::Serialize;

use crate::ode::OdeError;
use crate::registry::ConstrainedSystems;
pub use spectrum::Verdict;

/// The linearisation of a steady motion ([`steady_motion`]).
#[derive(Clone, Debug, Serialize)]
pub struct SteadyMotion {
    /// The steady motion's state in the model's own form: [q; q'] on
    /// constraints, [q; p] for a model without them.
    pub state: Vec<f64>,
    /// The reduced state's names: the shape, its rates, then the held
    /// speeds, each but those that neither move nor are moved by the rest
    /// and stay where they are put (a neighbouring steady motion: a
    /// bicycle's speed on its upright motion).
    pub reduced: Vec<String>,
    /// A: the reduced state's rates against the reduced state.
    #[serde(serialize_with = "rows")]
    pub matrix: DMatrix<f64>,
    /// A's eigenvalues (re, im), by decreasing real part.
    pub eigenvalues: Vec<(f64, f64)>,
    /// Each eigenvalue's numerical error ([`spectrum`]).
    pub errors: Vec<f64>,
    pub verdict: Verdict,
}

/// A matrix as its rows.
fn rows<S: serde::Serializer>(m: &DMatrix<f64>, serializer: S) -> Result<S::Ok, S::Error> {
    let rows: Vec<Vec<f64>> = m.row_iter().map(|r| r.iter().copied().collect()).collect();
    rows.serialize(serializer)
}

/// Why a steady motion could not be linearised.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SteadyMotionError {
    #[error(transparent)]
    Ode(#[from] OdeError),
    #[error("model '{model}': the steady motion needs {what}")]
    Setting { model: &'static str, what: String },
    /// No state on the constraints with the shape and speeds given.
    #[error(
        "model '{model}': no state on the constraints with the shape and speeds given: {source}"
    )]
    OffConstraints {
        model: &'static str,
        source: crate::ode::holonomic::ConstraintError,
    },
    /// The constraints do not fix the other components from the shape and
    /// the held speeds.
    #[error("model '{model}': the constraints do not determine '{coordinate}' or its rate from the shape and the held speeds: hold its speed or add it to the shape")]
    Undetermined {
        model: &'static str,
        coordinate: String,
    },
    /// The state is not steady: a shape coordinate or a held speed
    /// accelerates.
    #[error("model '{model}': the state is not a steady motion: '{coordinate}'' = {acceleration:e} (at most {tolerance:e})")]
    NotSteady {
        model: &'static str,
        coordinate: String,
        acceleration: f64,
        tolerance: f64,
    },
    /// No steady state near the guess (a model without constraints, whose
    /// shape is looked for by Newton's method).
    #[error("model '{model}': no steady motion near the start at these rates: Newton's method {why}; give `start` nearer one, or other rates")]
    NotFound { model: &'static str, why: String },
    /// Moving a coordinate outside the shape changes the reduced motion,
    /// so the shape alone does not describe the motion's stability.
    #[error("model '{model}': moving '{coordinate}' changes the rates of the shape and the held speeds by {effect:e} per unit: add it to the shape")]
    NotSymmetric {
        model: &'static str,
        coordinate: String,
        effect: f64,
    },
}

/// A steady motion: the configuration, the shape coordinates (still along
/// it) and the held speeds (coordinates' rates, with their values); every
/// other rate follows from the constraints.
pub struct SteadySettings<'a> {
    pub q: &'a [f64],
    pub shape: &'a [usize],
    pub held: &'a [(usize, f64)],
}

/// Relative size below which a reduced rate counts as zero: the state's
/// steadiness, the symmetry in the other coordinates, the held speeds'
/// coupling (the field's Jacobian is exact to rounding).
const STEADY: f64 = 1e-9;

/// The linearisation of the steady motion `settings` of `model` at the
/// parameter values `params` (see the module's comment).
pub fn steady_motion(
    model: &dyn ConstrainedSystems,
    params: &[f64],
    settings: &SteadySettings,
) -> Result<SteadyMotion, SteadyMotionError> {
    let name = model.info().name;
    let names = model.info().coordinates;
    let n = names.len();
    let setting = |what: String| SteadyMotionError::Setting { model: name, what };
    if settings.q.len() != n {
        return Err(setting(format!(
            "{n} coordinates, not {}",
            settings.q.len()
        )));
    }
    if (settings.shape.is_empty() && settings.held.is_empty())
        || settings.shape.iter().any(|&i| i >= n)
    {
        return Err(setting(
            "at least one shape coordinate or held speed of the model".into(),
        ));
    }
    let shape = settings.shape;
    let held: Vec<usize> = settings.held.iter().map(|&(i, _)| i).collect();
    if held.iter().any(|i| *i >= n || shape.contains(i)) {
        return Err(setting(
            "held speeds of coordinates outside the shape".into(),
        ));
    }
    let state = steady_state(model, params, settings)?;
    let (field, constraints) = model.linearisation(params, 0.0, &state)?;
    let positions = constraints.nrows() - model.constraint_names().len();
    let map = ConsistentMap::new(name, names, &constraints, positions, shape, &held)?;
    let scale = field.amax().max(1.0);
    // Steady: the shape's and the held speeds' accelerations vanish.
    let accelerations = model.exact(params).rhs(0.0, &state)?;
    for &i in shape.iter().chain(&held) {
        let acceleration = accelerations[n + i];
        let tolerance = STEADY * scale * (1.0 + state.iter().fold(0.0_f64, |m, x| m.max(x.abs())));
        if acceleration.abs() > tolerance {
            return Err(SteadyMotionError::NotSteady {
                model: name,
                coordinate: names[i].into(),
                acceleration,
                tolerance,
            });
        }
    }
    // The rates of the reduced state's components.
    let rows = reduced_components(n, shape, &held);
    let reduced_of = |column: &DVector<f64>| -> DVector<f64> {
        let rates = &field * column;
        DVector::from_iterator(rows.len(), rows.iter().map(|&r| rates[r]))
    };
    // The other coordinates must be symmetries: moving one (with the
    // dependent components following) leaves the reduced motion alone.
    for (j, &i) in map.free_positions.iter().enumerate() {
        let effect = reduced_of(&map.free_position_columns[j]).amax();
        if effect > STEADY * scale {
            return Err(SteadyMotionError::NotSymmetric {
                model: name,
                coordinate: names[i].into(),
                effect,
            });
        }
    }
    let full = DMatrix::from_columns(&map.columns.iter().map(&reduced_of).collect::<Vec<_>>());
    // The first held speed drops out where it neither moves the rest nor
    // is moved by it and stays put itself: a neighbouring steady motion,
    // whose zero eigenvalue says nothing of this one's stability. (The
    // other held rates are the motion's own, neutral or not.)
    let s = 2 * shape.len();
    let speed_apart = !held.is_empty() && full.nrows() > 1 && {
        let coupled = (0..full.nrows())
            .filter(|&r| r != s)
            .any(|r| full[(r, s)].abs().max(full[(s, r)].abs()) > STEADY * scale);
        !coupled && full[(s, s)].abs() <= STEADY * scale
    };
    let kept: Vec<usize> = (0..full.nrows())
        .filter(|&c| !(speed_apart && c == s))
        .collect();
    let matrix = DMatrix::from_fn(kept.len(), kept.len(), |i, j| full[(kept[i], kept[j])]);
    let all_names = reduced_names(names, shape, &held);
    let reduced = kept.iter().map(|&k| all_names[k].clone()).collect();
    let (eigenvalues, errors) = spectrum::eigenvalues_with_errors(&matrix, field.amax());
    let verdict = Verdict::of(&eigenvalues, &errors);
    Ok(SteadyMotion {
        state,
        reduced,
        matrix,
        eigenvalues,
        errors,
        verdict,
    })
}

fn reduced_names(names: &[&str], shape: &[usize], held: &[usize]) -> Vec<String> {
    shape
        .iter()
        .map(|&i| names[i].to_string())
        .chain(shape.iter().map(|&i| format!("{}'", names[i])))
        .chain(held.iter().map(|&i| format!("{}'", names[i])))
        .collect()
}

/// The consistent state: q with the shape held, the shape's rates 0 and
/// the held speeds given, the other components moved onto the
/// constraints (positions by Newton's method, then the rates).
fn steady_state(
    model: &dyn ConstrainedSystems,
    params: &[f64],
    settings: &SteadySettings,
) -> Result<Vec<f64>, SteadyMotionError> {
    let n = settings.q.len();
    let mut y = settings.q.to_vec();
    y.resize(2 * n, 0.0);
    for &(i, v) in settings.held {
        y[n + i] = v;
    }
    let held: Vec<usize> = settings
        .shape
        .iter()
        .flat_map(|&i| [i, n + i])
        .chain(settings.held.iter().map(|&(i, _)| n + i))
        .collect();
    model.consistent(params, &mut y, &held).map_err(|source| {
        SteadyMotionError::OffConstraints {
            model: model.info().name,
            source,
        }
    })?;
    Ok(y)
}

/// S = ∂y/∂r for the reduced state r = (shape, shape rates, held speeds),
/// and the columns for moving each free (non-shape, non-dependent)
/// coordinate, the dependent components solved from C S = 0.
struct ConsistentMap {
    columns: Vec<DVector<f64>>,
    free_positions: Vec<usize>,
    free_position_columns: Vec<DVector<f64>>,
}

impl ConsistentMap {
    /// `constraints`: C, its first `positions` rows the position
    /// constraints' (zero in the rates' columns).
    fn new(
        model: &'static str,
        names: &[&str],
        constraints: &DMatrix<f64>,
        positions: usize,
        shape: &[usize],
        held: &[usize],
    ) -> Result<Self, SteadyMotionError> {
        let n = names.len();
        let undetermined = |i: usize| SteadyMotionError::Undetermined {
            model,
            coordinate: names[i % n].into(),
        };
        // Dependent positions, pivoted among those outside the shape on the
        // position rows; then dependent rates, among those outside the
        // shape and the held speeds, on the velocity rows. A rate left over
        // is not fixed by the constraints: it must be held or in the shape.
        let position_rows = constraints.rows(0, positions).into_owned();
        let velocity_rows = constraints
            .rows(positions, constraints.nrows() - positions)
            .into_owned();
        let position_candidates: Vec<usize> = (0..n).filter(|i| !shape.contains(i)).collect();
        let rate_candidates: Vec<usize> = (0..n)
            .filter(|i| !shape.contains(i) && !held.contains(i))
            .map(|i| n + i)
            .collect();
        let mut dependent = pivot_columns(&position_rows, &position_candidates);
        if dependent.len() < rank(&position_rows) {
            return Err(undetermined(
                position_candidates.first().copied().unwrap_or(0),
            ));
        }
        let dependent_rates = pivot_columns(&velocity_rows, &rate_candidates);
        if let Some(&free) = rate_candidates
            .iter()
            .find(|c| !dependent_rates.contains(c))
        {
            return Err(undetermined(free));
        }
        dependent.extend(dependent_rates);
        let c_dep = DMatrix::from_fn(constraints.nrows(), dependent.len(), |r, c| {
            constraints[(r, dependent[c])]
        });
        let solver = (!c_dep.is_empty()).then(|| c_dep.svd(true, true));
        let complete = |known: usize| -> Result<DVector<f64>, SteadyMotionError> {
            let mut column = DVector::zeros(2 * n);
            column[known] = 1.0;
            let Some(solver) = &solver else {
                return Ok(column); // nothing depends on the others
            };
            let rhs = -(constraints * &column);
            let x = solver
                .solve(&rhs, 1e-13 * constraints.amax().max(1.0))
                .map_err(|_| undetermined(known))?;
            for (c, &d) in dependent.iter().enumerate() {
                column[d] = x[c];
            }
            Ok(column)
        };
        let columns = reduced_components(n, shape, held)
            .into_iter()
            .map(complete)
            .collect::<Result<Vec<_>, _>>()?;
        let free_positions: Vec<usize> = position_candidates
            .into_iter()
            .filter(|i| !dependent.contains(i))
            .collect();
        let free_position_columns = free_positions
            .iter()
            .map(|&k| complete(k))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(ConsistentMap {
            columns,
            free_positions,
            free_position_columns,
        })
    }
}

/// The reduced state's components in [q; q']: the shape, its rates, the
/// held speeds.
fn reduced_components(n: usize, shape: &[usize], held: &[usize]) -> Vec<usize> {
    shape
        .iter()
        .copied()
        .chain(shape.iter().map(|&i| n + i))
        .chain(held.iter().map(|&i| n + i))
        .collect()
}

fn rank(m: &DMatrix<f64>) -> usize {
    if m.is_empty() {
        return 0; // (a model without position constraints: no rows)
    }
    let values = m.singular_values();
    let largest = values.iter().fold(0.0_f64, |a, x| a.max(*x));
    values.iter().filter(|&&s| s > 1e-10 * largest).count()
}

/// Columns of `m` among `candidates`, chosen greedily by the largest
/// remaining norm after removing the chosen ones' span (a column-pivoted
/// Gram–Schmidt), until the rest is negligible.
fn pivot_columns(m: &DMatrix<f64>, candidates: &[usize]) -> Vec<usize> {
    let mut remaining: Vec<(usize, DVector<f64>)> = candidates
        .iter()
        .map(|&c| (c, m.column(c).into_owned()))
        .collect();
    let scale = m.amax().max(f64::MIN_POSITIVE);
    let mut chosen = Vec::new();
    while let Some((k, _)) = remaining
        .iter()
        .enumerate()
        .max_by(|a, b| a.1 .1.norm().total_cmp(&b.1 .1.norm()))
    {
        let (column, vector) = remaining.swap_remove(k);
        let norm = vector.norm();
        if norm <= 1e-10 * scale {
            break;
        }
        let unit = vector / norm;
        for (_, v) in remaining.iter_mut() {
            let projection = unit.dot(v);
            *v -= &unit * projection;
        }
        chosen.push(column);
    }
    chosen
}

/// The linearisations along a family of steady motions, one held speed
/// scaled ([`speed_sweep`]).
#[derive(Clone, Debug, Serialize)]
pub struct SpeedSweep {
    pub speeds: Vec<f64>,
    /// At each speed, the eigenvalues (re, im) by decreasing real part.
    pub eigenvalues: Vec<Vec<(f64, f64)>>,
    /// Their errors.
    pub errors: Vec<Vec<f64>>,
    /// The speeds asked for where the motion is not steady (a family of
    /// steady motions that ends: a top too slow to precess steadily).
    pub without_steady_motion: Vec<f64>,
    /// Where the motion turns unstable or stops being so (an eigenvalue's
    /// real part above its error) between two of the speeds, located by
    /// bisection to 1e-12 (relative to the speed): the family's stability
    /// boundaries, a bicycle's weave and capsize speeds.
    pub boundaries: Vec<Boundary>,
}

/// A speed where the steady motion gains or loses its stability.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Boundary {
    pub speed: f64,
    /// Its error: the bisection's bracket and the real part's error over
    /// its slope there.
    pub error: f64,
    /// Whether the motion is unstable just below this speed and not just
    /// above it (else the other way round).
    pub unstable_below: bool,
}

/// [`steady_motion`] at each of `speeds`, the first held speed of
/// `settings` set to speed × its rate there (the rate per unit speed: the
/// rear wheel's 1/rR for a bicycle's forward speed; the others held as
/// given), and the stability boundaries between them.
pub fn speed_sweep(
    model: &dyn ConstrainedSystems,
    params: &[f64],
    settings: &SteadySettings,
    speeds: &[f64],
) -> Result<SpeedSweep, SteadyMotionError> {
    let Some(&(swept, per_unit)) = settings.held.first() else {
        return Err(SteadyMotionError::Setting {
            model: model.info().name,
            what: "a held speed to sweep".into(),
        });
    };
    let at = |speed: f64| -> Result<SteadyMotion, SteadyMotionError> {
        let mut held = settings.held.to_vec();
        held[0] = (swept, speed * per_unit);
        let settings = SteadySettings {
            held: &held,
            ..*settings
        };
        steady_motion(model, params, &settings)
    };
    sweep_with(&at, speeds)
}

/// The linearisations `at` each of `speeds` and the stability boundaries
/// between them; a speed where the motion is not steady (a family of
/// steady motions that ends) is listed, not linearised.
pub fn sweep_with(
    at: &dyn Fn(f64) -> Result<SteadyMotion, SteadyMotionError>,
    speeds: &[f64],
) -> Result<SpeedSweep, SteadyMotionError> {
    let mut kept = Vec::new();
    let mut without_steady_motion = Vec::new();
    for &v in speeds {
        match at(v) {
            Ok(motion) => kept.push((v, motion)),
            Err(SteadyMotionError::NotSteady { .. } | SteadyMotionError::NotFound { .. }) => {
                without_steady_motion.push(v)
            }
            Err(e) => return Err(e),
        }
    }
    let mut boundaries = Vec::new();
    for pair in kept.windows(2) {
        let ((low, below), (high, above)) = (&pair[0], &pair[1]);
        let unstable_at_a = below.verdict.is_unstable();
        if unstable_at_a == above.verdict.is_unstable() {
            continue;
        }
        let (mut a, mut b) = (*low, *high);
        while (b - a).abs() > 1e-12 * (1.0 + a.abs().max(b.abs())) {
            let middle = 0.5 * (a + b);
            if at(middle)?.verdict.is_unstable() == unstable_at_a {
                a = middle;
            } else {
                b = middle;
            }
        }
        let (speed, error) = crossing(at, 0.5 * (a + b))?;
        boundaries.push(Boundary {
            speed,
            error: error + (b - a).abs(),
            unstable_below: unstable_at_a == (high > low),
        });
    }
    Ok(SpeedSweep {
        speeds: kept.iter().map(|k| k.0).collect(),
        eigenvalues: kept.iter().map(|k| k.1.eigenvalues.clone()).collect(),
        errors: kept.iter().map(|k| k.1.errors.clone()).collect(),
        without_steady_motion,
        boundaries,
    })
}

/// The boundary near `speed`, where the verdict changes (a real part at
/// its error): moved by a secant step to where that real part is 0, and
/// how far it may be from the true one (the real part's error over its
/// slope there).
fn crossing(
    at: &dyn Fn(f64) -> Result<SteadyMotion, SteadyMotionError>,
    speed: f64,
) -> Result<(f64, f64), SteadyMotionError> {
    let h = 1e-6 * (1.0 + speed.abs());
    let nearest_axis = |m: &SteadyMotion| {
        m.eigenvalues
            .iter()
            .zip(&m.errors)
            .min_by(|p, q| p.0 .0.abs().total_cmp(&q.0 .0.abs()))
            .map_or((0.0, 0.0), |(v, e)| (v.0, *e))
    };
    let (here, below, above) = (at(speed)?, at(speed - h)?, at(speed + h)?);
    let ((re, error), (low, _), (high, _)) = (
        nearest_axis(&here),
        nearest_axis(&below),
        nearest_axis(&above),
    );
    let slope = (high - low) / (2.0 * h);
    // A crossing the slope resolves (a real part through zero, not the
    // square root of a pair meeting on the axis) moves to its zero.
    if slope.abs() > 0.0 && (re / slope).abs() < h {
        Ok((speed - re / slope, error / slope.abs()))
    } else if slope.abs() > 0.0 {
        Ok((speed, error / slope.abs()))
    } else {
        Ok((speed, f64::INFINITY))
    }
}

impl SpeedSweep {
    /// The eigenvalues against the speed (real parts blue, imaginary parts
    /// grey, as in Meijaard et al.'s figure of the bicycle), each boundary
    /// in the legend.
    pub fn figure(&self, title: &str, speed_label: &str) -> crate::plot::Figure {
        use crate::plot::{Figure, PanelSpec, BLUE, GREY, RED};
        let points = |part: fn(&(f64, f64)) -> f64| -> Vec<(f64, f64)> {
            self.speeds
                .iter()
                .zip(&self.eigenvalues)
                .flat_map(|(&v, values)| values.iter().map(move |e| (v, part(e))))
                .collect()
        };
        let (real, imaginary) = (points(|e| e.0), points(|e| e.1.abs()));
        let x = self
            .speeds
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            });
        // The interesting range: the imaginary parts' and the real parts
        // above the fastest decay's, clipped below at −10.
        let top = imaginary
            .iter()
            .chain(&real)
            .fold(0.0_f64, |m, p| m.max(p.1));
        let bottom = real.iter().fold(0.0_f64, |m, p| m.min(p.1)).max(-10.0);
        let margin = 0.05 * (top - bottom).max(1e-3);
        let mut figure = Figure::single(
            900,
            560,
            PanelSpec::new(
                title,
                speed_label,
                "eigenvalues: Re (blue), |Im| (grey)",
                x,
                (bottom - margin, top + margin),
            ),
        );
        figure.points(0, imaginary, GREY, 2);
        figure.points(0, real, BLUE, 2);
        figure.line(0, &[(x.0, 0.0), (x.1, 0.0)], crate::plot::BLACK);
        let legend: Vec<(String, crate::plot::Rgb)> = self
            .boundaries
            .iter()
            .map(|b| {
                let side = if b.unstable_below {
                    "unstable below, not above"
                } else {
                    "unstable above, not below"
                };
                (format!("{:.9} ± {:.0e} ({side})", b.speed, b.error), RED)
            })
            .collect();
        if !legend.is_empty() {
            figure.legend(0, &legend);
        }
        figure
    }
}
