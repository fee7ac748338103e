//! What the attractor analysis takes and gives, for either kind of model.

use crate::analysis::dimension::bounds;
use crate::analysis::Refusal;
use crate::ode::{Method, OdeError};
use crate::plot::{ColorMap, Figure, PanelSpec, Rgb};
use crate::settings::{method, Declared, Range, SettingError, METHODS};
use std::collections::BTreeMap;

crate::declare_settings! {
    /// The attractor of a forced, damped period map (a model of one degree
    /// of freedom, a constrained one on its constraints): its points, its
    /// Lyapunov spectrum with its error, and its dimensions.
    pub struct AttractorOptions for "attractor" {
        /// Where the orbit starts: the first coordinate and its momentum (a
        /// constrained model: its velocity).
        start: [f64; 2] = [1.0, 0.0], Range::Any;
        /// Periods dropped first.
        transient: usize = 500, Range::Count { min: 0, max: 100_000_000 };
        /// Points of the attractor.
        points: usize = 200_000, Range::Count { min: 1, max: 100_000_000 };
        /// Periods of each of the two Lyapunov runs.
        lyapunov_periods: usize = 16_000, Range::Count { min: 2, max: 100_000_000 };
        /// Pixels per side of the density image.
        pixels: usize = 500, Range::Count { min: 2, max: 4000 };
        /// The error wanted on the Lyapunov exponents (auto: none asked,
        /// each comes with its error). Given, both runs are lengthened until
        /// the error is within it (up to 10⁸ periods), or the result says
        /// why not. The error is statistical: a tighter tolerance does not
        /// lower it.
        accuracy: Option<f64> = None, Range::Positive;
        /// The integration method.
        method: String = "taylor".into(), Range::OneOf(METHODS);
        /// Its tolerance (taylor, dop853, radau5) or step size (rk4, gauss4,
        /// gauss6).
        tol: f64 = 1e-10, Range::Positive;
    }
}

impl AttractorOptions {
    /// The settings of the attractor analysis.
    pub fn resolve(&self) -> Result<AttractorSettings, SettingError> {
        Ok(AttractorSettings {
            method: method(Self::ANALYSIS, &self.method, self.tol)?,
            start: self.start,
            transient: self.transient,
            points: self.points,
            lyapunov_periods: self.lyapunov_periods,
            accuracy: self.accuracy,
            pixels: self.pixels,
        })
    }
}

/// What to compute, from [`AttractorOptions`].
#[derive(Clone, Debug)]
pub struct AttractorSettings {
    pub method: Method,
    /// Where the orbit starts (then a second start for the error, shifted
    /// by 10⁻³).
    pub start: [f64; 2],
    /// Periods dropped before anything is recorded.
    pub transient: usize,
    /// Points of the attractor drawn and counted.
    pub points: usize,
    /// Periods of each Lyapunov run.
    pub lyapunov_periods: usize,
    /// The error wanted on the exponents (None: reported, not chosen).
    pub accuracy: Option<f64>,
    /// Pixels per side of the density image.
    pub pixels: usize,
}

/// Why an attractor cannot be had.
#[derive(Debug, thiserror::Error)]
pub enum AttractorError {
    /// The analysis does not apply to this kind of model.
    #[error(transparent)]
    Refused(#[from] crate::analysis::Refusal),
    #[error(transparent)]
    Ode(#[from] OdeError),
    /// A constrained model's start with no state on its constraints near,
    /// or constraints that degenerate on the way.
    #[error(transparent)]
    Constrained(#[from] crate::analysis::on_constraints::ConstrainedError),
    /// A declared setting's value refused.
    #[error(transparent)]
    Setting(#[from] SettingError),
}

/// The attractor, as measured.
#[derive(Debug, serde::Serialize)]
pub struct Attractor {
    pub model: String,
    pub params: BTreeMap<String, f64>,
    pub period: f64,
    pub points: usize,
    /// Lyapunov exponents per period, decreasing, from the first start.
    pub lyapunov: Vec<f64>,
    /// The same per unit time.
    pub lyapunov_per_time: Vec<f64>,
    /// From the second start, a check of the first.
    pub lyapunov_second_start: Vec<f64>,
    /// Each exponent's error: three standard errors of the first run's
    /// mean from the means of its blocks ([`BLOCKS`] of equal length), or
    /// the two starts' difference where that is larger.
    pub lyapunov_error: Vec<f64>,
    /// Periods of each of the two runs (more than `lyapunov_periods` where
    /// an accuracy asked for more).
    pub lyapunov_periods: usize,
    /// Whether the `accuracy` asked for was reached, and with how long
    /// runs.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub accuracy: Option<String>,
    /// Σλ per period, and ∫₀ᵀ div f dt averaged along the orbit (measured
    /// from the Jacobian's trace, not from the tangent flow): equal for a
    /// correct spectrum (−k T for a damping k).
    pub lyapunov_sum: f64,
    pub divergence_per_period: f64,
    pub box_dimension: f64,
    pub kaplan_yorke_dimension: f64,
    /// Box sides (fractions of the extent) and their counts.
    pub box_sides: Vec<f64>,
    pub boxes: Vec<usize>,
    pub seconds: f64,
    /// (periods, exponents so far) of the first run.
    #[serde(skip)]
    pub convergence: Vec<(usize, Vec<f64>)>,
    #[serde(skip)]
    pub orbit: Vec<[f64; 2]>,
    /// Which coordinate is an angle (drawn in [−π, π)).
    #[serde(skip)]
    pub periodic: bool,
    #[serde(skip)]
    pub pixels: usize,
    /// The coordinate's and momentum's names, for the axes.
    #[serde(skip)]
    pub axes: [&'static str; 2],
}

/// The blocks a Lyapunov run is cut into for its statistical error.
pub const BLOCKS: usize = 20;

/// The two starts' Lyapunov runs: the first's exponents and running
/// estimates, the second's exponents.
pub(crate) struct Spectra {
    pub first: Vec<f64>,
    pub history: Vec<(usize, Vec<f64>)>,
    pub second: Vec<f64>,
}

/// Each exponent's error (see [`Attractor::lyapunov_error`]): from the
/// running estimates A(t) of the first run at `history`'s times, the
/// blocks' means (t_j A_j − t_{j−1} A_{j−1}) / (t_j − t_{j−1}).
pub(crate) fn lyapunov_errors(spectra: &Spectra) -> Vec<f64> {
    let history = &spectra.history;
    let blocks = BLOCKS.min(history.len());
    let ends: Vec<&(usize, Vec<f64>)> = (1..=blocks)
        .map(|j| &history[j * history.len() / blocks - 1])
        .collect();
    (0..spectra.first.len())
        .map(|k| {
            let difference = (spectra.first[k] - spectra.second[k]).abs();
            if blocks < 4 {
                return difference;
            }
            let (mut before, mut means) = ((0.0, 0.0), Vec::with_capacity(blocks));
            for (t, a) in &ends {
                let (t, sum) = (*t as f64, *t as f64 * a[k]);
                means.push((sum - before.1) / (t - before.0));
                before = (t, sum);
            }
            let mean = means.iter().sum::<f64>() / blocks as f64;
            let variance =
                means.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / (blocks - 1) as f64;
            (3.0 * (variance / blocks as f64).sqrt()).max(difference)
        })
        .collect()
}

/// The longest runs an accuracy may ask for.
const MOST_PERIODS: usize = 100_000_000;

/// The two runs `run(periods)` at `settings.lyapunov_periods`, and where an
/// accuracy is asked, again longer while the error is larger (a
/// statistical error falls as 1/√periods: each rerun is as long as that
/// predicts with a fifth more, and at least twice as long; none where it
/// predicts more than [`MOST_PERIODS`]), with the periods run and what was
/// reached.
pub(crate) fn spectra_to_accuracy<E>(
    settings: &AttractorSettings,
    mut run: impl FnMut(usize) -> Result<Spectra, E>,
) -> Result<(Spectra, Vec<f64>, usize, Option<String>), E> {
    let mut periods = settings.lyapunov_periods;
    loop {
        let spectra = run(periods)?;
        let errors = lyapunov_errors(&spectra);
        let Some(accuracy) = settings.accuracy else {
            return Ok((spectra, errors, periods, None));
        };
        let largest = errors.iter().copied().fold(0.0, f64::max);
        if largest <= accuracy {
            let said = format!("accuracy {accuracy:e} reached with runs of {periods} periods");
            return Ok((spectra, errors, periods, Some(said)));
        }
        let wanted = periods as f64 * 1.2 * (largest / accuracy).powi(2);
        if wanted > MOST_PERIODS as f64 {
            let said = format!(
                "accuracy {accuracy:e} NOT reached: error {largest:.1e} with runs of {periods} periods; the error is statistical, and {accuracy:e} would take about {wanted:.0e} periods, more than the {MOST_PERIODS:e} it runs"
            );
            return Ok((spectra, errors, periods, Some(said)));
        }
        periods = (wanted as usize).max(2 * periods).min(MOST_PERIODS);
    }
}

/// The settings' sanity and the memory they ask for, as named errors.
pub(crate) fn check_settings(
    settings: &AttractorSettings,
    name: &str,
) -> Result<(), AttractorError> {
    let settings_error = |requirement: &'static str| Refusal::setting(name, requirement);
    if settings.points < 100 || settings.lyapunov_periods < 10 || settings.pixels < 10 {
        return Err(settings_error("points ≥ 100, lyapunov_periods ≥ 10 and pixels ≥ 10").into());
    }
    if !settings.start.iter().all(|x| x.is_finite()) {
        return Err(settings_error("the start must be finite").into());
    }
    crate::budget::check(
        || {
            format!(
                "{} points of the attractor and {1} × {1} pixels",
                settings.points, settings.pixels
            )
        },
        settings.points as u128 + settings.pixels as u128 * settings.pixels as u128,
        2 * std::mem::size_of::<f64>(),
    )
    .map_err(OdeError::from)?;
    Ok(())
}

impl Attractor {
    /// The density of the attractor's points (log scale) and the
    /// convergence of the Lyapunov exponents.
    pub fn figure(&self) -> Figure {
        let (lo, hi) = bounds(&self.orbit);
        let (q_range, p_range) = (
            if self.periodic {
                (-std::f64::consts::PI, std::f64::consts::PI)
            } else {
                let pad = 0.03 * (hi[0] - lo[0]);
                (lo[0] - pad, hi[0] + pad)
            },
            {
                let pad = 0.03 * (hi[1] - lo[1]);
                (lo[1] - pad, hi[1] + pad)
            },
        );
        let n = self.pixels;
        let mut counts = vec![0usize; n * n];
        for y in &self.orbit {
            let i = ((y[0] - q_range.0) / (q_range.1 - q_range.0) * n as f64).floor();
            let j = ((y[1] - p_range.0) / (p_range.1 - p_range.0) * n as f64).floor();
            if (0.0..n as f64).contains(&i) && (0.0..n as f64).contains(&j) {
                counts[j as usize * n + i as usize] += 1;
            }
        }
        let top = (*counts.iter().max().unwrap_or(&1)).max(1) as f64;
        let shade: Vec<f64> = counts
            .iter()
            .map(|&c| {
                if c == 0 {
                    f64::NAN
                } else {
                    (c as f64).ln_1p() / top.ln_1p()
                }
            })
            .collect();
        let titles = [
            format!(
                "{}: attractor of the period map, {} points, D_box = {:.3}, D_KY = {:.3}",
                self.model, self.points, self.box_dimension, self.kaplan_yorke_dimension
            ),
            format!(
                "Lyapunov exponents per period: {:.4} ± {:.1e}, {:.4} ± {:.1e} (sum {:.4}, ∫div f {:.4})",
                self.lyapunov[0],
                self.lyapunov_error[0],
                self.lyapunov[1],
                self.lyapunov_error[1],
                self.lyapunov_sum,
                self.divergence_per_period
            ),
        ];
        let last = self.convergence.last().map_or(1, |(k, _)| *k) as f64;
        let (low, high) = self
            .convergence
            .iter()
            .skip(self.convergence.len() / 10)
            .flat_map(|(_, l)| l.iter().copied())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
                (a.min(x), b.max(x))
            });
        let pad = 0.1 * (high - low).max(1e-3);
        let specs = [
            PanelSpec::new(&titles[0], self.axes[0], self.axes[1], q_range, p_range),
            PanelSpec::new(
                &titles[1],
                "periods",
                "λ",
                (0.0, last),
                (low - pad, high + pad),
            ),
        ];
        let mut figure = Figure::grid(2, 1, 720, 640, &specs);
        figure.shaded_map(0, n, n, &shade, ColorMap::Viridis, "log density");
        for k in 0..self.lyapunov.len() {
            let line: Vec<(f64, f64)> = self
                .convergence
                .iter()
                .map(|(t, l)| (*t as f64, l[k]))
                .collect();
            figure.line(1, &line, crate::plot::palette(k));
        }
        let sum = self.divergence_per_period;
        figure.line(1, &[(0.0, sum), (last, sum)], Rgb(120, 120, 120));
        figure
    }
}

impl crate::outputs::Outputs for Attractor {
    fn figures(&self) -> Vec<(String, Figure)> {
        vec![("attractor.png".into(), self.figure())]
    }
    fn tables(&self) -> Vec<crate::outputs::Table> {
        use crate::outputs::Table;
        let convergence = self.convergence.iter().map(|(k, l)| (*k, l[0], l[1]));
        vec![
            Table::new(
                "attractor.csv",
                &["q", "p"],
                self.orbit.iter().map(|y| (y[0], y[1])),
            ),
            Table::new(
                "lyapunov_convergence.csv",
                &["periods", "lambda_1", "lambda_2"],
                convergence,
            ),
        ]
    }
}
