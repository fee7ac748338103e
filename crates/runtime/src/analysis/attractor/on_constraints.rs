//! The attractor of a constrained model's period map, on its constraints:
//! a model of one degree of freedom there (a tangent space of dimension 2
//! in the constrained phase space), seen in the chart of its first
//! coordinate and that coordinate's velocity.
//!
//! The Lyapunov spectrum is that of the period map restricted to the
//! tangent spaces: with Z_k an orthonormal basis of the tangent space at
//! the k-th iterate and Φ_k the full monodromy of [q; q'] over the period
//! from it, the maps A_k = Z_{k+1}ᵀ Φ_k Z_k (2 × 2) are multiplied in QR
//! form, so the constraints' spurious directions never enter. The
//! divergence it is checked against is measured apart: the flow's
//! divergence on the constraint manifold, tr(Zᵀ J Z) (Z at each time),
//! integrated over a period along the orbit.

use nalgebra::DMatrix;

use super::types::{check_settings, spectra_to_accuracy, Spectra};
use super::{Attractor, AttractorError, AttractorSettings};
use crate::analysis::dimension::{box_counting, kaplan_yorke_dimension};
use crate::analysis::on_constraints::ConstrainedError;
use crate::analysis::Refusal;
use crate::ode::{wrap_angle, AnyOptions, Integrator, Method, OdeError};
use crate::registry::{ConstrainedSystems, Model};

/// The attractor of `model`'s period map on its constraints at `params`;
/// `settings.start` gives the first coordinate and its velocity, the other
/// components go onto the constraints.
pub(super) fn attractor(
    model: &Model,
    constrained: &dyn ConstrainedSystems,
    params: &[f64],
    settings: &AttractorSettings,
) -> Result<Attractor, AttractorError> {
    let name = model.info.name;
    let period = match constrained.phase_period(params) {
        Some(t) if constrained.has_fast_phase() => t,
        _ => return Err(Refusal::no_fast_phase(name).into()),
    };
    check_settings(settings, name)?;
    let named = Refusal::named_values(model.info, params)?;
    let n = model.info.coordinates.len();
    let chart = [0, n];
    let on_constraints = |start: [f64; 2]| -> Result<Vec<f64>, AttractorError> {
        let mut y = constrained.start(params);
        (y[0], y[n]) = (start[0], start[1]);
        constrained
            .consistent(params, &mut y, &chart)
            .map_err(|source| constraint_error(name, 0.0, source))?;
        Ok(y)
    };
    let y0 = on_constraints(settings.start)?;
    let dimension = basis_at(constrained, params, 0.0, &y0, name)?.ncols();
    if dimension != 2 {
        return Err(Refusal::Dimension {
            model: name.into(),
            dof: dimension / 2,
            analysis: "the attractor",
            supported: "one degree of freedom on its constraints (a period map of the plane)",
        }
        .into());
    }
    let clock = std::time::Instant::now();
    let system = constrained.exact(params);
    let iterates = |from: &[f64], count: usize| -> Result<Vec<Vec<f64>>, AttractorError> {
        let mut integrator = Integrator::new(settings.method)?;
        let mut states = Vec::with_capacity(count);
        system.stream(&mut integrator, from, period, count, &mut |y| {
            states.push(y.to_vec());
            true
        })?;
        Ok(states)
    };
    let settled = iterates(&y0, settings.transient)?.pop().unwrap_or(y0);
    let second = on_constraints([settled[0] + 1e-3, settled[n]])?;
    let spectrum = |from: &[f64], periods: usize, every: usize| {
        restricted_spectrum(
            constrained,
            params,
            settings.method,
            period,
            from,
            periods,
            every,
        )
    };
    let (spectra, orbit) = rayon::join(
        || {
            spectra_to_accuracy(settings, |periods| {
                let every = (periods / 200).max(1);
                let (first, other) = rayon::join(
                    || spectrum(&settled, periods, every),
                    || spectrum(&second, periods, 0),
                );
                let ((first, history), (second, _)) = (first?, other?);
                Ok::<_, AttractorError>(Spectra {
                    first,
                    history,
                    second,
                })
            })
        },
        || iterates(&settled, settings.points),
    );
    let (spectra, lyapunov_error, lyapunov_periods, accuracy) = spectra?;
    let first = spectra.first;
    let orbit = orbit?;
    let periodic = model.dynamic.periodic()[0];
    let points: Vec<[f64; 2]> = orbit
        .iter()
        .map(|y| [if periodic { wrap_angle(y[0]) } else { y[0] }, y[n]])
        .collect();
    let mut divergence = 0.0;
    let sample = &orbit[..orbit.len().min(200)];
    for y in sample {
        divergence += divergence_over_period(constrained, params, period, y, name)?;
    }
    divergence /= sample.len().max(1) as f64;
    let sides: Vec<f64> = (2..=9).map(|k| 0.5f64.powi(k)).collect();
    let counted = box_counting(&points, &sides, 2..sides.len() - 1);
    Ok(Attractor {
        model: name.into(),
        params: named,
        period,
        points: points.len(),
        lyapunov_per_time: first.iter().map(|l| l / period).collect(),
        lyapunov_sum: first.iter().sum(),
        kaplan_yorke_dimension: kaplan_yorke_dimension(&first),
        lyapunov_error,
        lyapunov_periods,
        accuracy,
        lyapunov_second_start: spectra.second,
        lyapunov: first,
        divergence_per_period: divergence,
        box_dimension: counted.dimension,
        box_sides: counted.sides,
        boxes: counted.boxes,
        seconds: clock.elapsed().as_secs_f64(),
        convergence: spectra.history,
        orbit: points,
        periodic,
        pixels: settings.pixels,
        axes: [model.info.coordinates[0], model.info.momenta[0]],
    })
}

/// The Lyapunov exponents per period of the period map restricted to the
/// tangent spaces (decreasing), from `periods` periods after `y0`, and
/// (every `every` periods) their running values.
#[allow(clippy::type_complexity)]
fn restricted_spectrum(
    model: &dyn ConstrainedSystems,
    params: &[f64],
    method: Method,
    period: f64,
    y0: &[f64],
    periods: usize,
    every: usize,
) -> Result<(Vec<f64>, Vec<(usize, Vec<f64>)>), AttractorError> {
    let name = model.info().name;
    let mut integrator = Integrator::new(method)?;
    let mut y = y0.to_vec();
    let mut basis = basis_at(model, params, 0.0, &y, name)?;
    let mut frame = DMatrix::<f64>::identity(basis.ncols(), basis.ncols());
    let mut sums = vec![0.0; basis.ncols()];
    let mut history = Vec::new();
    for done in 1..=periods {
        let (mut end, monodromy) = model.monodromy(params, &mut integrator, period, &y)?;
        // The period's end is the phase's start: the constraints there are t = 0's.
        model
            .project(params, 0.0, &mut end)
            .map_err(|source| constraint_error(name, done as f64 * period, source))?;
        let next = basis_at(model, params, 0.0, &end, name)?;
        let qr = (next.transpose() * monodromy * &basis * &frame).qr();
        for (sum, r) in sums.iter_mut().zip(qr.r().diagonal().iter()) {
            *sum += r.abs().ln();
        }
        frame = qr.q();
        (y, basis) = (end, next);
        if every > 0 && done % every == 0 {
            history.push((done, sorted(&sums, done)));
        }
    }
    Ok((sorted(&sums, periods), history))
}

/// The running exponents, decreasing.
fn sorted(sums: &[f64], periods: usize) -> Vec<f64> {
    let mut exponents: Vec<f64> = sums.iter().map(|s| s / periods as f64).collect();
    exponents.sort_by(|a, b| b.total_cmp(a));
    exponents
}

/// ∫₀ᵀ tr(Zᵀ J Z) dt along the orbit from `y0` (Simpson's rule at 64
/// intervals): the divergence of the flow on the constraint manifold.
fn divergence_over_period(
    model: &dyn ConstrainedSystems,
    params: &[f64],
    period: f64,
    y0: &[f64],
    name: &'static str,
) -> Result<f64, AttractorError> {
    const INTERVALS: usize = 64;
    let h = period / INTERVALS as f64;
    let system = model.exact(params);
    let trace = |t: f64, y: &[f64]| -> Result<f64, AttractorError> {
        let z = basis_at(model, params, t, y, name)?;
        let jacobian = system
            .jacobian(t, y)?
            .ok_or(OdeError::NonFinite { t, y: y.to_vec() })?;
        Ok((z.transpose() * jacobian * z).trace())
    };
    // One solve with dense output (a stream's segments each start at t = 0,
    // as a period map's do).
    let times: Vec<f64> = (1..=INTERVALS).map(|k| k as f64 * h).collect();
    let mut integrator = Integrator::new(Method::Dop853 {
        rtol: 1e-10,
        atol: 1e-10,
    })?;
    let mut states = vec![y0.to_vec()];
    states.extend(
        system
            .solve(
                &mut integrator,
                0.0,
                y0,
                period,
                AnyOptions::default().times(&times),
            )?
            .samples,
    );
    let mut sum = 0.0;
    for (k, y) in states.iter().enumerate() {
        let weight = match k {
            0 => 1.0,
            k if k == INTERVALS => 1.0,
            k if k % 2 == 1 => 4.0,
            _ => 2.0,
        };
        sum += weight * trace(k as f64 * h, y)?;
    }
    Ok(sum * h / 3.0)
}

/// An orthonormal basis of the tangent space at (t, y), or the error of
/// degenerate constraints there.
fn basis_at(
    model: &dyn ConstrainedSystems,
    params: &[f64],
    t: f64,
    y: &[f64],
    name: &'static str,
) -> Result<DMatrix<f64>, AttractorError> {
    model.tangent_basis(params, t, y)?.ok_or_else(|| {
        constraint_error(
            name,
            t,
            crate::ode::holonomic::ConstraintError::Singular {
                q: y[..y.len() / 2].to_vec(),
            },
        )
    })
}

fn constraint_error(
    model: &'static str,
    t: f64,
    source: crate::ode::holonomic::ConstraintError,
) -> AttractorError {
    ConstrainedError::Constraint { model, t, source }.into()
}
