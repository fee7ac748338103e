//! Steady motions of a model without constraints (Hamilton's equations in
//! [q; p]): a heavy top's steady precession, a conical pendulum. The
//! coordinates H does not depend on (cyclic: a top's precession and spin)
//! advance at constant rates; the others, the shape, stand still where
//! ∂H/∂q vanishes with those rates, found by Newton's method from a
//! guess. The cyclic momenta are conserved, so the linearisation is the
//! block of the field's Jacobian in the shape's (q, p): a perturbation of
//! a cyclic momentum is a neighbouring steady motion.
//!
//! The field's Jacobian is taken by central differences at steps h and
//! h/2; their eigenvalues' difference is added to each eigenvalue's
//! rounding bound ([`super::spectrum`]) as its error.

use nalgebra::{DMatrix, DVector};

use super::{spectrum, SteadyMotion, SteadyMotionError, Verdict};
use crate::registry::Model;

/// The field of `model` at t = 0.
fn field(model: &Model, params: &[f64], y: &[f64]) -> Result<Vec<f64>, SteadyMotionError> {
    let rates = model.dynamic.exact_rhs(params, 0.0, y);
    if rates.iter().all(|r| r.is_finite()) {
        Ok(rates)
    } else {
        Err(SteadyMotionError::Setting {
            model: model.info.name,
            what: format!("a state where the model's equations are finite, not {y:?}"),
        })
    }
}

/// The state [q; p] whose rates q' are `rates` (q' is linear in p).
pub fn with_rates(
    model: &Model,
    params: &[f64],
    q: &[f64],
    rates: &[f64],
) -> Result<Vec<f64>, SteadyMotionError> {
    let n = q.len();
    let state = |p: &[f64]| [q, p].concat();
    let at_rest = field(model, params, &state(&vec![0.0; n]))?;
    let mut response = DMatrix::zeros(n, n);
    for j in 0..n {
        let mut p = vec![0.0; n];
        p[j] = 1.0;
        let moved = field(model, params, &state(&p))?;
        for i in 0..n {
            response[(i, j)] = moved[i] - at_rest[i];
        }
    }
    let wanted = DVector::from_iterator(n, (0..n).map(|i| rates[i] - at_rest[i]));
    let p = response
        .lu()
        .solve(&wanted)
        .ok_or(SteadyMotionError::Setting {
            model: model.info.name,
            what: "a regular mass matrix at the guess (a singular chart there)".into(),
        })?;
    Ok(state(p.as_slice()))
}

/// The steady motion of `model` with the coordinates' `rates` (the
/// shape's 0), its shape moved from `guess` by Newton's method until the
/// shape's momenta stand still, and its linearisation.
pub fn free_steady_motion(
    model: &Model,
    params: &[f64],
    guess: &[f64],
    rates: &[f64],
    shape: &[usize],
) -> Result<SteadyMotion, SteadyMotionError> {
    let names = model.info.coordinates;
    let n = names.len();
    let mut q = guess.to_vec();
    let residual = |q: &[f64]| -> Result<Vec<f64>, SteadyMotionError> {
        let y = with_rates(model, params, q, rates)?;
        let f = field(model, params, &y)?;
        Ok(shape.iter().map(|&i| f[n + i]).collect())
    };
    let scale = {
        let y = with_rates(model, params, &q, rates)?;
        field(model, params, &y)?
            .iter()
            .fold(1.0_f64, |m, x| m.max(x.abs()))
    };
    let tolerance = 1e-12 * scale;
    let not_found = |why: String| SteadyMotionError::NotFound {
        model: model.info.name,
        why,
    };
    let mut r = residual(&q)?;
    for _ in 0..40 {
        if r.iter().all(|x| x.abs() <= tolerance) {
            break;
        }
        let mut jacobian = DMatrix::zeros(shape.len(), shape.len());
        for (c, &j) in shape.iter().enumerate() {
            let h = 1e-7 * (1.0 + q[j].abs());
            let (mut up, mut down) = (q.clone(), q.clone());
            up[j] += h;
            down[j] -= h;
            let (a, b) = (residual(&up), residual(&down));
            let (Ok(a), Ok(b)) = (a, b) else {
                return Err(not_found(format!("reached a singular chart at {q:?}")));
            };
            for k in 0..shape.len() {
                jacobian[(k, c)] = (a[k] - b[k]) / (2.0 * h);
            }
        }
        let Some(step) = jacobian.lu().solve(&DVector::from_vec(r.clone())) else {
            return Err(not_found(format!("met a singular Jacobian at {q:?}")));
        };
        for (c, &j) in shape.iter().enumerate() {
            q[j] -= step[c];
        }
        r = residual(&q).map_err(|_| not_found(format!("reached a singular chart at {q:?}")))?;
    }
    if let Some((k, worst)) = r
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
        .filter(|(_, x)| x.abs() > 1e-9 * scale)
    {
        return Err(not_found(format!(
            "left the momentum of '{}' changing by {worst:e}",
            names[shape[k]]
        )));
    }
    let state = with_rates(model, params, &q, rates)?;
    // The other coordinates must be cyclic.
    if let Some((j, effect)) = (0..n)
        .filter(|j| !shape.contains(j))
        .map(|j| (j, column(model, params, &state, j, 1e-6)))
        .map(|(j, c)| c.map(|c| (j, c.amax())))
        .collect::<Result<Vec<_>, _>>()?
        .into_iter()
        .find(|(_, effect)| *effect > 1e-7 * scale)
    {
        return Err(SteadyMotionError::NotSymmetric {
            model: model.info.name,
            coordinate: names[j].into(),
            effect,
        });
    }
    let reduced: Vec<usize> = shape
        .iter()
        .copied()
        .chain(shape.iter().map(|&i| n + i))
        .collect();
    let block = |h: f64| -> Result<DMatrix<f64>, SteadyMotionError> {
        let columns = reduced
            .iter()
            .map(|&j| column(model, params, &state, j, h))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(DMatrix::from_fn(reduced.len(), reduced.len(), |r, c| {
            columns[c][reduced[r]]
        }))
    };
    let (coarse, matrix) = (block(2e-6)?, block(1e-6)?);
    let (eigenvalues, mut errors) = spectrum::eigenvalues_with_errors(&matrix, scale);
    // The coarse step's eigenvalues alone (no condition numbers).
    let coarse_values = coarse.complex_eigenvalues();
    for (value, error) in eigenvalues.iter().zip(errors.iter_mut()) {
        let moved = coarse_values
            .iter()
            .map(|c| (c.re - value.0).hypot(c.im - value.1))
            .fold(f64::INFINITY, f64::min);
        *error += moved;
    }
    let verdict = Verdict::of(&eigenvalues, &errors);
    let names = shape
        .iter()
        .map(|&i| names[i].to_string())
        .chain(shape.iter().map(|&i| format!("p_{}", names[i])))
        .collect();
    Ok(SteadyMotion {
        state,
        reduced: names,
        matrix,
        eigenvalues,
        errors,
        verdict,
    })
}

/// ∂f/∂y_j at `y` by central differences at the relative step `h`.
fn column(
    model: &Model,
    params: &[f64],
    y: &[f64],
    j: usize,
    h: f64,
) -> Result<DVector<f64>, SteadyMotionError> {
    let step = h * (1.0 + y[j].abs());
    let (mut up, mut down) = (y.to_vec(), y.to_vec());
    up[j] += step;
    down[j] -= step;
    let (a, b) = (field(model, params, &up)?, field(model, params, &down)?);
    Ok(DVector::from_iterator(
        a.len(),
        a.iter().zip(&b).map(|(x, y)| (x - y) / (2.0 * step)),
    ))
}

/// The coordinates the field depends on at `y` (the others cyclic): the
/// shape of a model without constraints.
pub fn dependent_coordinates(
    model: &Model,
    params: &[f64],
    y: &[f64],
) -> Result<Vec<usize>, SteadyMotionError> {
    let n = model.info.coordinates.len();
    let scale = field(model, params, y)?
        .iter()
        .fold(1.0_f64, |m, x| m.max(x.abs()));
    let mut shape = Vec::new();
    for j in 0..n {
        if column(model, params, y, j, 1e-6)?.amax() > 1e-7 * scale {
            shape.push(j);
        }
    }
    Ok(shape)
}
