//! The attractor of the period map of a model of one degree of freedom in
//! its plane (q, p).

use super::types::{check_settings, spectra_to_accuracy, Spectra};
use super::{Attractor, AttractorError, AttractorSettings};
use crate::analysis::dimension::{box_counting, kaplan_yorke_dimension};
use crate::analysis::lyapunov::lyapunov_history;
use crate::analysis::period_map::orbit;
use crate::analysis::Refusal;
use crate::ode::{ErasedSystem, Integrator, Method, OdeError, Options, System};
use crate::registry::{Fixed, FixedSize, Model};

/// The attractor of the period map of `model`, of one degree of freedom,
/// at `params`.
pub(super) fn attractor(
    model: &Model,
    params: &[f64],
    settings: &AttractorSettings,
) -> Result<Attractor, AttractorError> {
    let name = model.info.name.to_string();
    let fixed = match model.sized {
        Some(FixedSize::Dof1(fixed)) => fixed,
        Some(_) => {
            return Err(Refusal::Dimension {
                model: name,
                dof: model.info.coordinates.len(),
                analysis: "the attractor",
                supported: "one degree of freedom (a period map of the plane)",
            }
            .into())
        }
        None => return Err(AttractorError::Refused(Refusal::contact_model(name))),
    };
    let period = match fixed.phase_period(params) {
        Some(t) if fixed.has_fast_phase() => t,
        _ => return Err(AttractorError::Refused(Refusal::no_fast_phase(name))),
    };
    check_settings(settings, &name)?;
    let named = Refusal::named_values(model.info, params)?;
    let system = fixed.exact(params);
    let periodic = model.dynamic.periodic()[0];
    let wrap = [periodic, false];
    let start = std::time::Instant::now();
    let mut integrator = Integrator::new(settings.method)?;
    let settled = *orbit(
        &mut integrator,
        &system,
        period,
        &settings.start,
        settings.transient,
        &wrap,
    )?
    .last()
    .expect("the start at least");
    let second = [settled[0] + 1e-3, settled[1]];
    let spectrum = |from: [f64; 2], periods: usize, every: usize| {
        let mut integrator = Integrator::new(settings.method)?;
        lyapunov_history::<_, 2, 6>(
            &mut integrator,
            &system,
            period,
            &from,
            0,
            periods,
            &wrap,
            every,
        )
    };
    let (spectra, points) = rayon::join(
        || {
            spectra_to_accuracy(settings, |periods| {
                let every = (periods / 200).max(1);
                let (first, other) = rayon::join(
                    || spectrum(settled, periods, every),
                    || spectrum(second, periods, 0),
                );
                let first = first?;
                Ok::<_, OdeError>(Spectra {
                    first: first.exponents,
                    history: first.history,
                    second: other?.exponents,
                })
            })
        },
        || {
            orbit(
                &mut integrator,
                &system,
                period,
                &settled,
                settings.points,
                &wrap,
            )
        },
    );
    let (spectra, error, lyapunov_periods, accuracy) = spectra?;
    let points = points?;
    let divergence = mean_divergence(&system, period, &points[..points.len().min(200)])?;
    let sides: Vec<f64> = (2..=9).map(|k| 0.5f64.powi(k)).collect();
    let counted = box_counting(&points, &sides, 2..sides.len() - 1);
    let first = spectra.first;
    Ok(Attractor {
        model: name,
        params: named,
        period,
        points: points.len(),
        lyapunov_per_time: first.iter().map(|l| l / period).collect(),
        lyapunov_sum: first.iter().sum(),
        kaplan_yorke_dimension: kaplan_yorke_dimension(&first),
        lyapunov_second_start: spectra.second,
        lyapunov_error: error,
        lyapunov_periods,
        accuracy,
        lyapunov: first,
        divergence_per_period: divergence,
        box_dimension: counted.dimension,
        box_sides: counted.sides,
        boxes: counted.boxes,
        seconds: start.elapsed().as_secs_f64(),
        convergence: spectra.history,
        orbit: points,
        periodic,
        pixels: settings.pixels,
        axes: [model.info.coordinates[0], model.info.momenta[0]],
    })
}

/// ∫₀ᵀ tr ∂f/∂y dt from each of `starts` along one period (Simpson's rule
/// at 64 intervals), averaged over the starts.
fn mean_divergence(
    system: &ErasedSystem<2>,
    period: f64,
    starts: &[[f64; 2]],
) -> Result<f64, OdeError> {
    const INTERVALS: usize = 64;
    let times: Vec<f64> = (1..=INTERVALS)
        .map(|k| period * k as f64 / INTERVALS as f64)
        .collect();
    let trace = |t: f64, y: &[f64; 2]| {
        system
            .jacobian(t, y)
            .map_or(f64::NAN, |j| j[0][0] + j[1][1])
    };
    let mut total = 0.0;
    for y0 in starts {
        let mut integrator = Integrator::new(Method::Dop853 {
            rtol: 1e-10,
            atol: 1e-10,
        })?;
        let states = integrator
            .solve(
                system,
                0.0,
                y0,
                times.last().copied().unwrap_or(0.0),
                Options::default().times(&times),
            )?
            .samples;
        let h = period / INTERVALS as f64;
        let mut sum = trace(0.0, y0);
        for (k, (t, y)) in times.iter().zip(&states).enumerate() {
            let weight = if k + 1 == INTERVALS {
                1.0
            } else if k % 2 == 0 {
                4.0
            } else {
                2.0
            };
            sum += weight * trace(*t, y);
        }
        total += sum * h / 3.0;
    }
    Ok(total / starts.len() as f64)
}
