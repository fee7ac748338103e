//! Stabilisation by vibration on the constraints: Study 2's theory for
//! points with ideal holonomic constraints, in the model's own (possibly
//! redundant) coordinates.
//!
//! With fixed holonomic constraints g(q) = 0, L = ½ q'ᵀM q' + b(q, θ)·q' − V(q, θ)
//! and a fast phase θ whose coupling b has zero mean, the first-order
//! averaged motion is that of the effective potential
//!
//!   W(q) = mean_θ V + ½ mean_θ ⟨P b, b⟩,   P = M⁻¹ − M⁻¹Gᵀ(G M⁻¹ Gᵀ)⁻¹G M⁻¹,
//!
//! on the constraints: P is the inverse mass matrix projected on them, so
//! only the part of the vibration's impulse the constraints let through
//! counts. An equilibrium solves ∇W = Gᵀμ, g = 0; it is stable when the
//! stiffness on the tangent space, Zᵀ(∇²W − Σ μᵢ∇²gᵢ)Z, is positive
//! definite (the constraints' curvature enters through the multipliers μ).
//! The means over θ are exact quadratures (32 nodes: V and b are
//! trigonometric polynomials in θ of low degree), taken at the model's
//! sizes by `constrained::averaged`; ∇W and ∇²W are central differences
//! (errors about 1e-10 and 1e-8 of W's scale), ∇²g exact.
//!
//! The exact system answers too: where the equilibrium at rest relative to
//! the base is a periodic orbit of the vibrating system, its Floquet
//! multipliers on the constraints ([`super::monodromy_on_constraints`])
//! say whether it is stable, amplitude by amplitude.

use std::collections::BTreeMap;

use nalgebra::{DMatrix, DVector};

use super::{monodromy_on_constraints, ConstrainedError};
use crate::analysis::Refusal;
use crate::ode::holonomic::tangent_stability;
use crate::ode::{Integrator, Method, OdeError};
use crate::registry::ConstrainedSystems;
use crate::settings::{method, Declared, Range, SettingError, METHODS};

crate::declare_settings! {
    /// Stabilisation by vibration on the constraints of a constrained
    /// model: its equilibrium near the start, the averaged thresholds, and
    /// the exact Floquet multipliers on the constraints against the
    /// amplitude.
    pub struct LinkageOptions for "linkage" {
        /// The parameter that scales the vibration (auto: the model file's
        /// [fast_phase] amplitude).
        amplitude: Option<String> = None, Range::Any;
        /// The largest amplitude scanned (auto: twice the amplitude's value,
        /// 4 where it is 0).
        max_amplitude: Option<f64> = None, Range::Positive;
        /// Amplitudes scanned from 0.
        scan: usize = 40, Range::Count { min: 2, max: 100_000 };
        /// Where Newton's method starts, the coordinates (auto: the model
        /// file's start).
        start: Option<Vec<f64>> = None, Range::Any;
        /// Orbits drawn about the equilibrium, exact and averaged (0: none).
        orbits: usize = 6, Range::Count { min: 0, max: 1000 };
        /// The largest kick in the first coordinate's velocity of those orbits.
        kick: f64 = 0.6, Range::Positive;
        /// Periods of the fast phase per orbit.
        periods: usize = 300, Range::Count { min: 1, max: 10_000_000 };
        /// The integration method.
        method: String = "taylor".into(), Range::OneOf(METHODS);
        /// Its tolerance (taylor, dop853, radau5) or step size (rk4, gauss4,
        /// gauss6).
        tol: f64 = 1e-12, Range::Positive;
        /// Run the exact scan again at a hundredth of the tolerance, to
        /// state each window edge's error (no: none).
        check: bool = true, Range::Any;
        /// The error wanted on the exact windows' edges (auto: none asked;
        /// with `check`, each edge comes with its error). Given, `tol` is
        /// tightened a hundredfold until every edge's error is within it,
        /// or the result says why not.
        accuracy: Option<f64> = None, Range::Positive;
    }
}

impl LinkageOptions {
    /// The settings of [`vibration_stability`].
    pub fn resolve(&self) -> Result<VibrationSettings, SettingError> {
        Ok(VibrationSettings {
            amplitude: self.amplitude.clone(),
            max_amplitude: self.max_amplitude,
            start: self.start.clone(),
            scan: self.scan,
            method: method(Self::ANALYSIS, &self.method, self.tol)?,
            check: self.check,
            accuracy: self.accuracy,
        })
    }
}

/// What to compute, from [`LinkageOptions`].
#[derive(Clone, Debug)]
pub struct VibrationSettings {
    /// The amplitude parameter (default: the model file's
    /// `[fast_phase] amplitude`).
    pub amplitude: Option<String>,
    /// The largest amplitude scanned (default: twice the value in the
    /// parameters, or 4 if it is 0).
    pub max_amplitude: Option<f64>,
    /// Where Newton's method starts (coordinates; default the model
    /// file's start).
    pub start: Option<Vec<f64>>,
    /// Amplitudes scanned between 0 and the largest.
    pub scan: usize,
    pub method: Method,
    /// Scan again at a hundredth of the tolerance for the edges' errors.
    pub check: bool,
    /// The error wanted on the edges (None: stated, not chosen).
    pub accuracy: Option<f64>,
}

/// The declared defaults.
impl Default for VibrationSettings {
    fn default() -> Self {
        LinkageOptions::default()
            .resolve()
            .expect("the declared defaults are valid")
    }
}

/// The exact system's verdict on the equilibrium.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub enum Exact {
    /// At rest relative to the base it is a periodic orbit of the exact
    /// system: its Floquet multipliers' moduli at the amplitude, whether
    /// it is stable (by the monodromy criterion that holds however short
    /// the period, [`crate::analysis::floquet::stability_margin`]), and
    /// the intervals of scanned amplitudes where it is (edges by
    /// bisection), each edge with its error: twice its distance to the
    /// same edge in a scan at a hundredth of the tolerance, plus the
    /// bisection's bracket (None: not checked, or a window's upper end
    /// that is the scan's end).
    Periodic {
        moduli: Vec<f64>,
        stable: bool,
        windows: Vec<[f64; 2]>,
        window_errors: Vec<[Option<f64>; 2]>,
        /// The two scans compared, or why none was; with an `accuracy`,
        /// whether it was reached.
        check: Option<String>,
    },
    /// The vibration moves the orbit off the averaged equilibrium (|P(y₀) − y₀|
    /// is `gap` after one period): its multipliers need the period map's
    /// fixed point on the constraints, which is not computed here.
    MovedByVibration { gap: f64 },
}

/// The averaged equilibrium near the start, its stability, the amplitudes
/// where that changes, and the exact system's verdict.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct VibrationStability {
    pub model: &'static str,
    pub params: BTreeMap<String, f64>,
    pub amplitude: String,
    pub amplitude_value: f64,
    /// q* on the constraints.
    pub equilibrium: Vec<f64>,
    /// μ: the constraints' reactions holding q* against ∇W.
    pub multipliers: Vec<f64>,
    /// ω² of the small oscillations of the averaged motion on the
    /// constraints (n − k of them, increasing): stable when all are > 0.
    pub squared_frequencies: Vec<f64>,
    pub averaged_stable: bool,
    /// Amplitudes in the scanned range where the smallest ω² changes sign.
    pub averaged_thresholds: Vec<f64>,
    pub exact: Exact,
    /// The scan: at each amplitude the smallest ω² of the averaged
    /// equilibrium and the largest Floquet modulus of the exact orbit
    /// (None where the vibration moves it).
    pub scan: Vec<ScanPoint>,
}

/// One amplitude of the scan.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ScanPoint {
    pub amplitude: f64,
    pub lowest_squared_frequency: f64,
    pub largest_modulus: Option<f64>,
}

/// Why the analysis could not be made.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum VibrationError {
    #[error(transparent)]
    Setting(#[from] SettingError),
    #[error(transparent)]
    Refused(#[from] Refusal),
    #[error("'{model}': the averaging on constraints needs fixed holonomic constraints and a mass matrix that the vibration does not move; write the coordinates relative to the vibrating base")]
    MovingConstraints { model: &'static str },
    #[error("'{model}': the vibration's coupling b has a mean of {mean:e} at q*: a gyroscopic averaged system, whose stability W alone does not decide")]
    Gyroscopic { model: &'static str, mean: f64 },
    #[error("'{model}': no equilibrium of the averaged system on the constraints near the start at {amplitude} = {value} (|∇W − Gᵀμ|, |g| still {residual:e} after Newton's method)")]
    NoEquilibrium {
        model: &'static str,
        amplitude: String,
        value: f64,
        residual: f64,
    },
    #[error(transparent)]
    Ode(#[from] OdeError),
    #[error(transparent)]
    Constrained(#[from] ConstrainedError),
}

/// The averaged system of `model` at `params`.
struct Averaged<'a> {
    model: &'a dyn ConstrainedSystems,
    params: Vec<f64>,
}

/// An equilibrium of the averaged system and its stiffness.
struct Equilibrium {
    q: Vec<f64>,
    multipliers: Vec<f64>,
    squared_frequencies: Vec<f64>,
}

impl Averaged<'_> {
    /// W(q) and the mean of b.
    fn effective(&self, q: &[f64]) -> Result<(f64, DVector<f64>), VibrationError> {
        let name = self.model.info().name;
        let means = self
            .model
            .phase_means(&self.params, q)?
            .ok_or(VibrationError::MovingConstraints { model: name })?;
        let mean = DVector::from_vec(means.coupling);
        Ok((means.potential + means.vibrational, mean))
    }

    fn w(&self, q: &[f64]) -> Result<f64, VibrationError> {
        Ok(self.effective(q)?.0)
    }

    fn step(q: &[f64], i: usize, scale: f64) -> f64 {
        scale * (1.0 + q[i].abs())
    }

    fn gradient(&self, q: &[f64]) -> Result<DVector<f64>, VibrationError> {
        let mut gradient = DVector::zeros(q.len());
        for i in 0..q.len() {
            let h = Self::step(q, i, 1e-5);
            let (mut plus, mut minus) = (q.to_vec(), q.to_vec());
            plus[i] += h;
            minus[i] -= h;
            gradient[i] = (self.w(&plus)? - self.w(&minus)?) / (2.0 * h);
        }
        Ok(gradient)
    }

    fn hessian(&self, q: &[f64]) -> Result<DMatrix<f64>, VibrationError> {
        let n = q.len();
        let mut hessian = DMatrix::zeros(n, n);
        let at = |di: (usize, f64), dj: (usize, f64)| {
            let mut x = q.to_vec();
            x[di.0] += di.1;
            x[dj.0] += dj.1;
            self.w(&x)
        };
        for i in 0..n {
            let hi = Self::step(q, i, 1e-4);
            for j in i..n {
                let hj = Self::step(q, j, 1e-4);
                let value =
                    (at((i, hi), (j, hj))? - at((i, hi), (j, -hj))? - at((i, -hi), (j, hj))?
                        + at((i, -hi), (j, -hj))?)
                        / (4.0 * hi * hj);
                hessian[(i, j)] = value;
                hessian[(j, i)] = value;
            }
        }
        Ok(hessian)
    }

    /// Newton's method on ∇W = Gᵀμ, g = 0 from `start`, then the stiffness
    /// on the tangent space there.
    fn equilibrium(
        &self,
        start: &[f64],
        amplitude: (&str, f64),
    ) -> Result<Equilibrium, VibrationError> {
        let name = self.model.info().name;
        let n = start.len();
        let mut q = start.to_vec();
        let mut residual = f64::INFINITY;
        let mut multipliers = DVector::zeros(0);
        for _ in 0..30 {
            let rest = self.model.statics(&self.params, 0.0, &q)?;
            let (g, value) = (&rest.jacobian, &rest.residual);
            let k = g.nrows();
            let gradient = self.gradient(&q)?;
            if multipliers.len() != k {
                multipliers = (g * g.transpose())
                    .lu()
                    .solve(&(g * &gradient))
                    .unwrap_or_else(|| DVector::zeros(k));
            }
            let force = &gradient - g.transpose() * &multipliers;
            residual = force.amax().max(value.amax());
            if residual <= 1e-9 {
                break;
            }
            let mut curvature = self.hessian(&q)?;
            for (mu, h) in
                multipliers
                    .iter()
                    .zip(self.model.constraint_hessians(&self.params, 0.0, &q)?)
            {
                curvature -= h * *mu;
            }
            let mut kkt = DMatrix::zeros(n + k, n + k);
            kkt.view_mut((0, 0), (n, n)).copy_from(&curvature);
            kkt.view_mut((0, n), (n, k)).copy_from(&(-g.transpose()));
            kkt.view_mut((n, 0), (k, n)).copy_from(g);
            let mut rhs = DVector::zeros(n + k);
            rhs.rows_mut(0, n).copy_from(&(-force));
            rhs.rows_mut(n, k).copy_from(&(-value));
            let Some(step) = kkt.lu().solve(&rhs) else {
                break;
            };
            for i in 0..n {
                q[i] += step[i];
            }
            multipliers += step.rows(n, k);
        }
        if !(residual <= 1e-7) {
            return Err(VibrationError::NoEquilibrium {
                model: name,
                amplitude: amplitude.0.into(),
                value: amplitude.1,
                residual,
            });
        }
        let rest = self.model.statics(&self.params, 0.0, &q)?;
        let stiffness = tangent_stability(
            &rest.mass,
            &rest.jacobian,
            &self.gradient(&q)?,
            &self.hessian(&q)?,
            &self.model.constraint_hessians(&self.params, 0.0, &q)?,
        );
        let squared_frequencies = stiffness
            .and_then(|s| {
                let l = s.mass.clone().cholesky()?.l();
                let l_inv = l.try_inverse()?;
                let reduced = &l_inv * s.stiffness * l_inv.transpose();
                let mut values: Vec<f64> = reduced
                    .symmetric_eigen()
                    .eigenvalues
                    .iter()
                    .copied()
                    .collect();
                values.sort_by(f64::total_cmp);
                Some(values)
            })
            .unwrap_or_default();
        Ok(Equilibrium {
            q,
            multipliers: multipliers.iter().copied().collect(),
            squared_frequencies,
        })
    }
}

/// The stability of `model`'s equilibrium near the start under the
/// vibration, averaged and exact (see the module's comment).
pub fn vibration_stability(
    model: &dyn ConstrainedSystems,
    params: &[f64],
    settings: &VibrationSettings,
) -> Result<VibrationStability, VibrationError> {
    let info = model.info();
    let name = info.name;
    let named = Refusal::named_values(info, params)?;
    if model.phase_period(params).is_none() {
        return Err(Refusal::no_fast_phase(name).into());
    }
    if !model.stationary() {
        return Err(VibrationError::MovingConstraints { model: name });
    }
    let amplitude = match settings.amplitude.as_deref().or(info.amplitude) {
        Some(a) => a.to_string(),
        None => {
            return Err(Refusal::Setting {
                model: name.into(),
                requirement: "name the amplitude parameter (the model file names none in [fast_phase] amplitude)",
            }
            .into())
        }
    };
    let index = Refusal::parameter_index(info, &amplitude)?;
    let value = params[index];
    let at = |a: f64| -> Result<Averaged<'_>, VibrationError> {
        let mut p = params.to_vec();
        p[index] = a;
        Ok(Averaged { model, params: p })
    };
    let n = info.coordinates.len();
    let start = match &settings.start {
        Some(q) if q.len() != n => {
            return Err(Refusal::state_length(name, "start", q.len(), n).into())
        }
        Some(q) => q.clone(),
        None => model.start(params)[..n].to_vec(),
    };
    let here = at(value)?;
    let found = here.equilibrium(&start, (&amplitude, value))?;
    let (_, mean) = here.effective(&found.q)?;
    if mean.amax() > 1e-9 {
        return Err(VibrationError::Gyroscopic {
            model: name,
            mean: mean.amax(),
        });
    }
    let most = settings
        .max_amplitude
        .unwrap_or(if value > 0.0 { 2.0 * value } else { 4.0 });
    let amplitudes: Vec<f64> = (0..=settings.scan.max(1))
        .map(|k| most * k as f64 / settings.scan.max(1) as f64)
        .collect();
    let (thresholds, lowest_along) = thresholds_along(&at, &amplitudes, &found.q, &amplitude)?;
    let (exact, largest) = checked_verdict(model, params, index, &found.q, &amplitudes, settings)?;
    let scan = amplitudes
        .iter()
        .zip(lowest_along)
        .zip(largest)
        .map(
            |((&amplitude, lowest_squared_frequency), largest_modulus)| ScanPoint {
                amplitude,
                lowest_squared_frequency,
                largest_modulus,
            },
        )
        .collect();
    Ok(VibrationStability {
        model: name,
        params: named,
        amplitude,
        amplitude_value: value,
        averaged_stable: found.squared_frequencies.first().is_some_and(|w| *w > 0.0),
        equilibrium: found.q,
        multipliers: found.multipliers,
        squared_frequencies: found.squared_frequencies,
        averaged_thresholds: thresholds,
        exact,
        scan,
    })
}

/// The smallest ω² at each of `amplitudes` (the equilibrium followed from
/// `start`, each amplitude's from the last's) and the amplitudes where it
/// changes sign, by bisection.
fn thresholds_along<'a>(
    at: &dyn Fn(f64) -> Result<Averaged<'a>, VibrationError>,
    amplitudes: &[f64],
    start: &[f64],
    amplitude: &str,
) -> Result<(Vec<f64>, Vec<f64>), VibrationError> {
    let lowest = |a: f64, from: &[f64]| -> Result<(f64, Vec<f64>), VibrationError> {
        let e = at(a)?.equilibrium(from, (amplitude, a))?;
        Ok((
            e.squared_frequencies.first().copied().unwrap_or(f64::NAN),
            e.q,
        ))
    };
    let mut thresholds = Vec::new();
    let mut lowest_along = Vec::new();
    let mut previous: Option<(f64, f64, Vec<f64>)> = None;
    for &a in amplitudes {
        let from = previous.as_ref().map_or(start.to_vec(), |p| p.2.clone());
        let (omega2, q) = lowest(a, &from)?;
        lowest_along.push(omega2);
        if let Some((a0, w0, q0)) = &previous {
            if (*w0 > 0.0) != (omega2 > 0.0) {
                let (mut lo, mut hi, mut q_lo) = (*a0, a, q0.clone());
                let positive_at_lo = *w0 > 0.0;
                for _ in 0..40 {
                    let mid = 0.5 * (lo + hi);
                    let (w, q_mid) = lowest(mid, &q_lo)?;
                    if (w > 0.0) == positive_at_lo {
                        lo = mid;
                        q_lo = q_mid;
                    } else {
                        hi = mid;
                    }
                }
                thresholds.push(0.5 * (lo + hi));
            }
        }
        previous = Some((a, omega2, q));
    }
    Ok((thresholds, lowest_along))
}

/// Whether [q; 0] is a periodic orbit of the exact system at the
/// amplitude in `params`, and if so its multipliers and the stable
/// intervals of `amplitudes` (edges by bisection); and the largest modulus
/// at each of `amplitudes` where it is periodic.
fn exact_verdict(
    model: &dyn ConstrainedSystems,
    params: &[f64],
    index: usize,
    q: &[f64],
    amplitudes: &[f64],
    method: Method,
) -> Result<(Exact, Vec<Option<f64>>), VibrationError> {
    let mut y0 = q.to_vec();
    y0.resize(2 * q.len(), 0.0);
    // The moduli of the multipliers at amplitude a and whether they are
    // stable, or the orbit's gap.
    let moduli_at = |a: f64| -> Result<Result<(Vec<f64>, bool), f64>, VibrationError> {
        let mut p = params.to_vec();
        p[index] = a;
        let period = model
            .phase_period(&p)
            .ok_or_else(|| Refusal::no_fast_phase(model.info().name))?;
        let mut integrator = Integrator::new(method)?;
        let end = model
            .exact(&p)
            .solve(&mut integrator, 0.0, &y0, period, Default::default())?
            .y;
        let gap = end
            .iter()
            .zip(&y0)
            .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
        if !(gap <= 1e-8) {
            return Ok(Err(gap));
        }
        let (_, restricted) = monodromy_on_constraints(model, &p, method, period, &y0)?;
        let mut moduli: Vec<f64> = restricted
            .complex_eigenvalues()
            .iter()
            .map(|z| z.norm())
            .collect();
        moduli.sort_by(f64::total_cmp);
        let stable = crate::analysis::floquet::stability_margin(&restricted, period) <= 0.0;
        Ok(Ok((moduli, stable)))
    };
    let (moduli, stable_here) = match moduli_at(params[index])? {
        Ok(found) => found,
        Err(gap) => {
            let none = vec![None; amplitudes.len()];
            return Ok((Exact::MovedByVibration { gap }, none));
        }
    };
    let verdict = |a: f64| -> Result<Option<bool>, VibrationError> {
        Ok(moduli_at(a)?.ok().map(|(_, stable)| stable))
    };
    let mut windows: Vec<[f64; 2]> = Vec::new();
    let mut largest = Vec::with_capacity(amplitudes.len());
    let mut open: Option<f64> = None;
    let mut last: Option<(f64, bool)> = None;
    for &a in amplitudes {
        let here = moduli_at(a)?.ok();
        largest.push(here.as_ref().and_then(|(m, _)| m.last().copied()));
        let Some(now) = here.map(|(_, stable)| stable) else {
            continue;
        };
        let edge = match last {
            Some((a0, before)) if before != now => {
                let (mut lo, mut hi) = (a0, a);
                for _ in 0..40 {
                    let mid = 0.5 * (lo + hi);
                    if verdict(mid)? == Some(before) {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                Some(0.5 * (lo + hi))
            }
            None if now => Some(a),
            _ => None,
        };
        match (edge, now) {
            (Some(e), true) => open = Some(e),
            (Some(e), false) => windows.extend(open.take().map(|o| [o, e])),
            _ => {}
        }
        last = Some((a, now));
    }
    if let (Some(o), Some((a, true))) = (open, last) {
        windows.push([o, a]);
    }
    let exact = Exact::Periodic {
        stable: stable_here,
        moduli,
        window_errors: vec![[None, None]; windows.len()],
        windows,
        check: None,
    };
    Ok((exact, largest))
}

impl Exact {
    /// The verdict in words: the moduli, the windows with their edges'
    /// errors, the check.
    pub fn describe(&self) -> String {
        let Exact::Periodic {
            moduli,
            stable,
            windows,
            window_errors,
            check,
        } = self
        else {
            return format!("exact: {self:?}");
        };
        let error = |e: &Option<f64>| e.map_or(String::new(), |e| format!(" ± {e:.1e}"));
        let windows: Vec<String> = (windows.iter().zip(window_errors))
            .map(|(w, e)| format!("[{}{}, {}{}]", w[0], error(&e[0]), w[1], error(&e[1])))
            .collect();
        let verdict = if *stable { "stable" } else { "unstable" };
        let check = check.as_ref().map_or(String::new(), |c| format!(" ({c})"));
        format!(
            "exact: {verdict}, moduli {moduli:?}; stable for {}{check}",
            match windows.is_empty() {
                true => "no scanned amplitude".to_string(),
                false => windows.join(", "),
            }
        )
    }
}

/// [`exact_verdict`] with its edges' errors where `settings.check` asks
/// for them, from the scan again at a hundredth of the tolerance; with an
/// `accuracy`, the tolerance tightened a hundredfold until every edge's
/// error is within it.
fn checked_verdict(
    model: &dyn ConstrainedSystems,
    params: &[f64],
    index: usize,
    q: &[f64],
    amplitudes: &[f64],
    settings: &VibrationSettings,
) -> Result<(Exact, Vec<Option<f64>>), VibrationError> {
    let scan_end = amplitudes.last().copied().unwrap_or(0.0);
    let name = model.info().name;
    Refusal::accuracy_within_reach(name, "the windows' edges", settings.accuracy, scan_end)?;
    let scan = |method: Method| exact_verdict(model, params, index, q, amplitudes, method);
    // The bisection's bracket: 40 halvings of the scan's step.
    let step = amplitudes.get(1).map_or(0.0, |a| a - amplitudes[0]);
    let bracket = step / 2f64.powi(40);
    let (mut result, checked) = crate::analysis::check::checked_run(
        settings.method,
        settings.check,
        settings.accuracy,
        scan,
        |current, again| edge_errors(&mut current.0, &again.0, bracket, scan_end),
        |current| largest_edge_error(&current.0, scan_end),
    )?;
    if let (Some(checked), Exact::Periodic { check, .. }) = (checked, &mut result.0) {
        *check = Some(match checked.accuracy {
            Some(accuracy) => format!("{}: {accuracy}", checked.runs),
            None => checked.runs,
        });
    }
    Ok(result)
}

/// The largest error of a window's edge (∞ where one is not stated; an
/// upper end at the scan's end is not an edge).
fn largest_edge_error(exact: &Exact, scan_end: f64) -> f64 {
    let Exact::Periodic {
        windows,
        window_errors,
        ..
    } = exact
    else {
        return f64::INFINITY;
    };
    let mut worst: f64 = 0.0;
    for (window, errors) in windows.iter().zip(window_errors) {
        for side in 0..2 {
            if side == 0 || window[1] != scan_end {
                worst = worst.max(errors[side].unwrap_or(f64::INFINITY));
            }
        }
    }
    worst
}

/// Each window edge's error in `exact` from the same scan's `again`:
/// twice the distance to the nearest edge of its side there, plus the
/// bisection's `bracket` (None where `again` has none, or for an upper end
/// at the scan's end).
fn edge_errors(exact: &mut Exact, again: &Exact, bracket: f64, scan_end: f64) {
    let (
        Exact::Periodic {
            windows,
            window_errors,
            ..
        },
        Exact::Periodic {
            windows: others, ..
        },
    ) = (exact, again)
    else {
        return;
    };
    for (window, errors) in windows.iter().zip(window_errors.iter_mut()) {
        for side in 0..2 {
            if side == 1 && window[1] == scan_end {
                continue;
            }
            let nearest = (others.iter())
                .map(|w| (w[side] - window[side]).abs())
                .min_by(f64::total_cmp);
            errors[side] = nearest.map(|d| 2.0 * d + bracket);
        }
    }
}

impl VibrationStability {
    /// Two panels over the scanned amplitudes: the averaged equilibrium's
    /// smallest ω² (stable above zero, the thresholds in red), and the
    /// exact orbit's largest Floquet modulus (stable at 1).
    pub fn figure(&self) -> crate::plot::Figure {
        use crate::plot::{Figure, PanelSpec, BLACK, GREY, RED};
        use crate::registry::display_name;
        let amplitude = display_name(&self.amplitude);
        let span = |values: &mut dyn Iterator<Item = f64>| {
            let (lo, hi) = values
                .filter(|v| v.is_finite())
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
                    (l.min(v), h.max(v))
                });
            (
                lo - 0.05 * (hi - lo).max(1e-9),
                hi + 0.05 * (hi - lo).max(1e-9),
            )
        };
        let x = (0.0, self.scan.last().map_or(1.0, |p| p.amplitude));
        let omega = span(
            &mut self
                .scan
                .iter()
                .map(|p| p.lowest_squared_frequency)
                .chain([0.0]),
        );
        let moduli: Vec<(f64, f64)> = self
            .scan
            .iter()
            .filter_map(|p| Some((p.amplitude, p.largest_modulus?)))
            .collect();
        let rho = span(&mut moduli.iter().map(|p| p.1).chain([1.0]));
        let titles = [
            format!("{}: averaged, smallest ω² on the constraints", self.model),
            format!("{}: exact, largest Floquet modulus", self.model),
        ];
        let specs = [
            PanelSpec::new(&titles[0], &amplitude, "ω²", x, omega),
            PanelSpec::new(
                &titles[1],
                &amplitude,
                "|ρ|",
                x,
                (rho.0.min(0.99), rho.1.max(1.01)),
            ),
        ];
        let mut figure = Figure::grid(2, 1, 560, 420, &specs);
        let lowest: Vec<(f64, f64)> = self
            .scan
            .iter()
            .map(|p| (p.amplitude, p.lowest_squared_frequency))
            .collect();
        figure.line(0, &lowest, BLACK);
        figure.dashed_line(0, &[(x.0, 0.0), (x.1, 0.0)], GREY);
        for a in &self.averaged_thresholds {
            figure.line(0, &[(*a, omega.0), (*a, omega.1)], RED);
            figure.line(
                1,
                &[(*a, 0.99f64.min(rho.0)), (*a, 1.01f64.max(rho.1))],
                RED,
            );
        }
        figure.line(1, &moduli, BLACK);
        figure.dashed_line(1, &[(x.0, 1.0), (x.1, 1.0)], GREY);
        figure
    }
}

/// Orbits about an equilibrium on the plane of the first coordinate and
/// its velocity: the exact period map's points and the averaged motion's
/// curves from the same seeds (the equilibrium kicked by `spread` · k /
/// `count` in that velocity, put on the constraints with the plane's
/// components held).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Orbits {
    pub model: &'static str,
    pub axes: [String; 2],
    pub seeds: Vec<Vec<f64>>,
    #[serde(skip)]
    pub exact: Vec<Vec<(f64, f64)>>,
    #[serde(skip)]
    pub averaged: Vec<Vec<(f64, f64)>>,
}

/// [`Orbits`] of `model` about `q` over `periods` of the fast phase.
pub fn orbits_about(
    model: &dyn ConstrainedSystems,
    params: &[f64],
    q: &[f64],
    (count, spread, periods): (usize, f64, usize),
    method: Method,
) -> Result<Orbits, VibrationError> {
    let info = model.info();
    let n = q.len();
    let axes = [0, n];
    let period = model
        .phase_period(params)
        .ok_or_else(|| Refusal::no_fast_phase(info.name))?;
    let constraint = |source| ConstrainedError::Constraint {
        model: info.name,
        t: 0.0,
        source,
    };
    // The averaged flow on constraints has no Taylor recurrences: DOP853
    // at the same tolerance runs its curves.
    let averaged_method = match method {
        Method::Taylor { tol } => Method::Dop853 {
            rtol: tol,
            atol: tol,
        },
        other => other,
    };
    let map_times: Vec<f64> = (0..=periods).map(|k| k as f64 * period).collect();
    let curve_times: Vec<f64> = (0..=8 * periods.min(500))
        .map(|k| k as f64 * periods as f64 * period / (8 * periods.min(500)) as f64)
        .collect();
    let plane = |states: &[Vec<f64>]| states.iter().map(|y| (y[0], y[n])).collect::<Vec<_>>();
    let mut orbits = Orbits {
        model: info.name,
        axes: [info.coordinates[0].to_string(), info.momenta[0].to_string()],
        seeds: Vec::new(),
        exact: Vec::new(),
        averaged: Vec::new(),
    };
    for k in 1..=count {
        let mut seed = q.to_vec();
        seed.resize(2 * n, 0.0);
        seed[n] = spread * k as f64 / count as f64;
        model
            .consistent(params, &mut seed, &axes)
            .map_err(constraint)?;
        let exact = super::run(model, params, Some(&seed), method, &map_times)?;
        orbits.exact.push(plane(&exact.states));
        let averaged = model
            .averaged_states(params, averaged_method, &seed, &curve_times)?
            .ok_or(VibrationError::MovingConstraints { model: info.name })?;
        orbits.averaged.push(plane(&averaged));
        orbits.seeds.push(seed);
    }
    Ok(orbits)
}

impl Orbits {
    /// The exact period map's points (a colour per orbit) over the averaged
    /// motion's curves (black).
    pub fn figure(&self) -> crate::plot::Figure {
        use crate::plot::{palette, Figure, PanelSpec, BLACK};
        use crate::registry::display_name;
        let all = self.exact.iter().chain(&self.averaged).flatten();
        let (mut x, mut y) = (
            (f64::INFINITY, f64::NEG_INFINITY),
            (f64::INFINITY, f64::NEG_INFINITY),
        );
        for p in all.filter(|p| p.0.is_finite() && p.1.is_finite()) {
            x = (x.0.min(p.0), x.1.max(p.0));
            y = (y.0.min(p.1), y.1.max(p.1));
        }
        let pad = |r: (f64, f64)| {
            let d = 0.05 * (r.1 - r.0).max(1e-9);
            (r.0 - d, r.1 + d)
        };
        let title = format!(
            "{}: exact period map (points) and averaged motion (lines)",
            self.model
        );
        let x_name = display_name(&self.axes[0]);
        let y_name = format!("{x_name}′");
        let spec = PanelSpec::new(&title, &x_name, &y_name, pad(x), pad(y));
        let mut figure = Figure::single(720, 620, spec);
        for (k, (exact, averaged)) in self.exact.iter().zip(&self.averaged).enumerate() {
            figure.line(0, averaged, BLACK);
            figure.points(0, exact.iter().copied(), palette(k), 2);
        }
        figure
    }
}

/// The `linkage` analysis's result: the stability on the constraints
/// (its summary) and the orbits about the equilibrium.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Linkage {
    #[serde(flatten)]
    pub stability: VibrationStability,
    #[serde(skip)]
    pub orbits: Option<Orbits>,
}

/// The stability of `options` on the constraints of `model`, and its
/// orbits where `options.orbits` asks for them.
pub fn linkage(
    model: &dyn ConstrainedSystems,
    params: &[f64],
    options: &LinkageOptions,
) -> Result<Linkage, VibrationError> {
    let settings = options.resolve()?;
    let stability = vibration_stability(model, params, &settings)?;
    let orbits = match options.orbits {
        0 => None,
        count => {
            let shape = (count, options.kick, options.periods);
            let q = &stability.equilibrium;
            Some(orbits_about(model, params, q, shape, settings.method)?)
        }
    };
    Ok(Linkage { stability, orbits })
}

impl crate::outputs::Outputs for Linkage {
    fn figures(&self) -> Vec<(String, crate::plot::Figure)> {
        let mut figures = vec![("linkage.png".into(), self.stability.figure())];
        if let Some(orbits) = &self.orbits {
            figures.push(("orbits.png".into(), orbits.figure()));
        }
        figures
    }
    fn tables(&self) -> Vec<crate::outputs::Table> {
        let result = &self.stability;
        let rows = result.scan.iter().map(|p| {
            let modulus = p.largest_modulus.unwrap_or(f64::NAN);
            (p.amplitude, p.lowest_squared_frequency, modulus)
        });
        let header = [
            result.amplitude.as_str(),
            "lowest_omega2",
            "largest_modulus",
        ];
        vec![crate::outputs::Table::new("scan.csv", &header, rows)]
    }
    fn lines(&self) -> Vec<String> {
        let result = &self.stability;
        let verdict = if result.averaged_stable {
            "stable"
        } else {
            "unstable"
        };
        vec![
            format!(
                "{}: equilibrium q* = {:?}, averaged ω² = {:?} ({verdict}); thresholds in {}: {:?}",
                result.model,
                result.equilibrium,
                result.squared_frequencies,
                result.amplitude,
                result.averaged_thresholds
            ),
            result.exact.describe(),
        ]
    }
}
