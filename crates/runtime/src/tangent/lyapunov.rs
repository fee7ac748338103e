//! Lyapunov exponents of a period map (per iteration) and the fast Lyapunov
//! indicator (FLI) used to shade chaos maps.

use super::variational::Variational;
use crate::ode::wrap_angle;
use crate::ode::{Integrator, LaneIntegrator, Method, OdeError, Orbit, System};
use nalgebra::DMatrix;

/// The full Lyapunov spectrum of the period map (exponents per period, in
/// decreasing order), by QR re-orthonormalisation after every period.
/// M = N + N². Starts from `y0`; the first `transient` periods are skipped.
pub fn lyapunov_spectrum<S: System<N>, const N: usize, const M: usize>(
    integrator: &mut Integrator,
    system: &S,
    period: f64,
    y0: &[f64; N],
    transient: usize,
    periods: usize,
    wrap: &[bool],
) -> Result<(Vec<f64>, [f64; N]), OdeError> {
    let run =
        lyapunov_history::<S, N, M>(integrator, system, period, y0, transient, periods, wrap, 0)?;
    Ok((run.exponents, run.end))
}

/// A spectrum's run: the exponents (per period, decreasing), where the orbit
/// ended, and the running estimates every `every` periods.
pub struct SpectrumRun<const N: usize> {
    pub exponents: Vec<f64>,
    pub end: [f64; N],
    /// (periods, the exponents so far in the order of the final ones).
    pub history: Vec<(usize, Vec<f64>)>,
}

/// [`lyapunov_spectrum`] with the running estimates recorded every
/// `every` periods (none for 0): their convergence.
#[allow(clippy::too_many_arguments)]
pub fn lyapunov_history<S: System<N>, const N: usize, const M: usize>(
    integrator: &mut Integrator,
    system: &S,
    period: f64,
    y0: &[f64; N],
    transient: usize,
    periods: usize,
    wrap: &[bool],
    every: usize,
) -> Result<SpectrumRun<N>, OdeError> {
    assert_eq!(M, N + N * N, "the spectrum needs M = N + N²");
    let variational = Variational::<S, N, M>::new(system);
    let mut y = *y0;
    for _ in 0..transient {
        y = integrator.advance(system, 0.0, &y, period)?;
    }
    let mut basis: Vec<[f64; N]> = (0..N)
        .map(|k| std::array::from_fn(|i| f64::from(u8::from(i == k))))
        .collect();
    let mut sums = vec![0.0; N];
    let mut history = Vec::new();
    for done in 1..=periods {
        let z = integrator.advance(
            &variational,
            0.0,
            &Variational::<S, N, M>::pack(&y, &basis),
            period,
        )?;
        y = Variational::<S, N, M>::state(&z);
        for (x, w) in y.iter_mut().zip(wrap) {
            if *w {
                *x = wrap_angle(*x);
            }
        }
        let m = DMatrix::from_fn(N, N, |i, k| Variational::<S, N, M>::tangent(&z, k)[i]);
        let qr = m.qr();
        let (q, r) = (qr.q(), qr.r());
        for k in 0..N {
            sums[k] += r[(k, k)].abs().ln();
            basis[k] = std::array::from_fn(|i| q[(i, k)] * r[(k, k)].signum());
        }
        if every > 0 && done % every == 0 {
            history.push((done, sorted(sums.iter().map(|s| s / done as f64).collect())));
        }
    }
    Ok(SpectrumRun {
        exponents: sorted(sums.iter().map(|s| s / periods as f64).collect()),
        end: y,
        history,
    })
}

fn sorted(mut exponents: Vec<f64>) -> Vec<f64> {
    exponents.sort_by(|a, b| b.total_cmp(a));
    exponents
}

/// Fast Lyapunov indicator of the period map: max over iterations of
/// ln‖w‖ for one tangent vector w started at `w0`, renormalised when large
/// (the logarithms are accumulated). M = 2N.
pub fn fast_lyapunov_indicator<S: System<N>, const N: usize, const M: usize>(
    integrator: &mut Integrator,
    system: &S,
    period: f64,
    y0: &[f64; N],
    w0: &[f64; N],
    periods: usize,
) -> Result<f64, OdeError> {
    let variational = Variational::<S, N, M>::new(system);
    let z = Variational::<S, N, M>::pack(y0, &[*w0]);
    let mut fli = Fli::<N, M>::new(w0);
    integrator.stream(&variational, &z, period, periods, &mut |z| {
        fli.after_segment(z);
        true
    })?;
    Ok(fli.value())
}

/// The FLI of every orbit started at `starts`, integrated [`crate::ode::LANES`] at a
/// time by the batch Taylor method (a lane whose orbit ends takes the next
/// one); each orbit's value (or error) is the one
/// [`fast_lyapunov_indicator`] gives it with the same tolerance.
pub fn fast_lyapunov_indicators<S: System<N>, const N: usize, const M: usize>(
    integrator: &mut LaneIntegrator,
    system: &S,
    period: f64,
    starts: &[[f64; N]],
    tangents: &[[f64; N]],
    periods: usize,
) -> Vec<Result<f64, OdeError>> {
    if periods == 0 {
        return vec![Ok(f64::NEG_INFINITY); starts.len()];
    }
    in_lanes(
        integrator,
        system,
        period,
        starts,
        tangents,
        periods,
        Fli::<N, M>::new,
    )
}

/// The FLI of each start after `periods` periods of `system` (or the
/// orbit's error) and the f-evaluations spent, with an integrator of its
/// own: the Taylor method streams the orbits through its lanes, the others
/// run them one by one. M = 2N.
pub fn fli_of_starts<S: System<N>, const N: usize, const M: usize>(
    system: &S,
    method: Method,
    period: f64,
    starts: &[[f64; N]],
    tangents: &[[f64; N]],
    periods: usize,
) -> Result<(Vec<Result<f64, OdeError>>, u64), OdeError> {
    Ok(match method {
        Method::Taylor { .. } => {
            let mut integrator = LaneIntegrator::new(method)?;
            let values = fast_lyapunov_indicators::<_, N, M>(
                &mut integrator,
                system,
                period,
                starts,
                tangents,
                periods,
            );
            (values, integrator.stats.f_evals)
        }
        _ => {
            let mut integrator = Integrator::new(method)?;
            let mut values = Vec::with_capacity(starts.len());
            for (k, y0) in starts.iter().enumerate() {
                let fli = fast_lyapunov_indicator::<_, N, M>(
                    &mut integrator,
                    system,
                    period,
                    y0,
                    tangent_of(tangents, k),
                    periods,
                );
                if fli.is_err() {
                    // A clean state for the next orbit.
                    integrator = Integrator::new(method)?;
                }
                values.push(fli);
            }
            (values, integrator.stats.f_evals)
        }
    })
}

/// MEGNO ⟨Y⟩ (Cincotta and Simó) of every orbit started at `starts` over
/// `chunks` chunks of time `chunk`, [`crate::ode::LANES`] at a time by the
/// batch Taylor method: with L(t) = ln(‖w(t)‖/‖w₀‖),
/// Y(t) = (2/t)∫₀ᵗ s dL = 2(L − (1/t)∫₀ᵗ L ds) and ⟨Y⟩ its running mean,
/// both by the trapezoid rule over the chunks. ⟨Y⟩ tends to 2 on a
/// quasi-periodic orbit, 0 on a stable periodic one, and grows as λt/2 on
/// a chaotic one: a threshold with no tuning to the run's length.
pub fn megno_values<S: System<N>, const N: usize, const M: usize>(
    integrator: &mut LaneIntegrator,
    system: &S,
    chunk: f64,
    starts: &[[f64; N]],
    w0: &[f64; N],
    chunks: usize,
) -> Vec<Result<f64, OdeError>> {
    if chunks == 0 {
        return vec![Ok(0.0); starts.len()];
    }
    in_lanes(
        integrator,
        system,
        chunk,
        starts,
        std::slice::from_ref(w0),
        chunks,
        |w0| Megno::<N, M>::new(w0, chunk),
    )
}

/// Start k's tangent vector: its own, or the one all starts share.
fn tangent_of<const N: usize>(tangents: &[[f64; N]], k: usize) -> &[f64; N] {
    match tangents {
        [shared] => shared,
        own => &own[k],
    }
}

/// An indicator of one orbit's tangent vector, taken in after every
/// segment of its run.
trait TangentIndicator<const M: usize>: Copy {
    /// Takes in the state [y; w] after a segment (and may renormalise w).
    fn after_segment(&mut self, z: &mut [f64; M]);
    fn value(&self) -> f64;
}

/// Every orbit from `starts` with its tangent vector (`tangents`: one per
/// start, or one for all), `segments` segments of length `segment` in the
/// batch lanes, each with the indicator `indicator` makes of its tangent
/// vector; its value, or the orbit's error.
fn in_lanes<S: System<N>, I: TangentIndicator<M>, const N: usize, const M: usize>(
    integrator: &mut LaneIntegrator,
    system: &S,
    segment: f64,
    starts: &[[f64; N]],
    tangents: &[[f64; N]],
    segments: usize,
    indicator: impl Fn(&[f64; N]) -> I,
) -> Vec<Result<f64, OdeError>> {
    let variational = Variational::<S, N, M>::new(system);
    let packed: Vec<[f64; M]> = starts
        .iter()
        .enumerate()
        .map(|(k, y0)| Variational::<S, N, M>::pack(y0, &[*tangent_of(tangents, k)]))
        .collect();
    let orbits = Orbit::of_one_system(&variational, segment, &packed);
    let mut state: Vec<(I, usize)> = (0..starts.len())
        .map(|k| (indicator(tangent_of(tangents, k)), 0))
        .collect();
    let errors = integrator.stream(&orbits, |k, z| {
        let (indicator, done) = &mut state[k];
        indicator.after_segment(z);
        *done += 1;
        *done < segments
    });
    errors
        .into_iter()
        .zip(state)
        .map(|(error, (indicator, _))| match error {
            Some(e) => Err(e),
            None => Ok(indicator.value()),
        })
        .collect()
}

/// ln(‖w‖/‖w₀‖) of a tangent vector, with the logarithms of its
/// renormalisations kept (w is divided by its norm past 10¹⁰⁰).
#[derive(Clone, Copy, Debug)]
struct TangentGrowth<const N: usize, const M: usize> {
    norm0: f64,
    log_scale: f64,
}

impl<const N: usize, const M: usize> TangentGrowth<N, M> {
    fn new(w0: &[f64; N]) -> Self {
        assert_eq!(M, 2 * N, "one tangent vector needs M = 2N");
        TangentGrowth {
            norm0: w0.iter().map(|x| x * x).sum::<f64>().sqrt(),
            log_scale: 0.0,
        }
    }

    /// ln(‖w‖/‖w₀‖) at the state [y; w]; renormalises w when large.
    fn log_growth(&mut self, z: &mut [f64; M]) -> f64 {
        let norm = z[N..].iter().map(|x| x * x).sum::<f64>().sqrt();
        let growth = self.log_scale + (norm / self.norm0).ln();
        if norm > 1e100 {
            self.log_scale += norm.ln();
            for x in &mut z[N..] {
                *x /= norm;
            }
        }
        growth
    }
}

/// One orbit's MEGNO so far.
#[derive(Clone, Copy, Debug)]
struct Megno<const N: usize, const M: usize> {
    growth: TangentGrowth<N, M>,
    chunk: f64,
    t: f64,
    /// L, ∫L, Y and ∫Y at t.
    log_norm: f64,
    log_integral: f64,
    y: f64,
    y_integral: f64,
    mean: f64,
}

impl<const N: usize, const M: usize> Megno<N, M> {
    fn new(w0: &[f64; N], chunk: f64) -> Self {
        Megno {
            growth: TangentGrowth::new(w0),
            chunk,
            t: 0.0,
            log_norm: 0.0,
            log_integral: 0.0,
            y: 0.0,
            y_integral: 0.0,
            mean: 0.0,
        }
    }
}

impl<const N: usize, const M: usize> TangentIndicator<M> for Megno<N, M> {
    fn after_segment(&mut self, z: &mut [f64; M]) {
        let log_norm = self.growth.log_growth(z);
        let h = self.chunk;
        self.t += h;
        self.log_integral += 0.5 * h * (self.log_norm + log_norm);
        self.log_norm = log_norm;
        let y = 2.0 * (log_norm - self.log_integral / self.t);
        self.y_integral += 0.5 * h * (self.y + y);
        self.y = y;
        self.mean = self.y_integral / self.t;
    }

    fn value(&self) -> f64 {
        self.mean
    }
}

/// One orbit's FLI so far: the largest ln(‖w‖/‖w₀‖).
#[derive(Clone, Copy, Debug)]
struct Fli<const N: usize, const M: usize> {
    growth: TangentGrowth<N, M>,
    value: f64,
}

impl<const N: usize, const M: usize> Fli<N, M> {
    fn new(w0: &[f64; N]) -> Self {
        Fli {
            growth: TangentGrowth::new(w0),
            value: f64::NEG_INFINITY,
        }
    }
}

impl<const N: usize, const M: usize> TangentIndicator<M> for Fli<N, M> {
    fn after_segment(&mut self, z: &mut [f64; M]) {
        self.value = self.value.max(self.growth.log_growth(z));
    }

    fn value(&self) -> f64 {
        self.value
    }
}

/// Grey levels for a chaos map from FLI values after `iterations` periods.
#[derive(Clone, Debug, PartialEq)]
pub struct FliShading {
    /// One value in [0, 1] per input (1 = most chaotic).
    pub shades: Vec<f64>,
    /// ln(iterations): the FLI of a regular orbit, whose tangent vectors grow linearly.
    pub regular_level: f64,
    /// Share of values above twice the regular level.
    pub chaotic_fraction: f64,
}

/// Whether an FLI after `iterations` periods marks a chaotic orbit: above
/// 2 ln N, twice the level of a regular orbit (whose tangent vectors grow
/// at most linearly).
pub fn fli_is_chaotic(fli: f64, iterations: usize) -> bool {
    fli > 2.0 * (iterations as f64).ln()
}

/// Shades FLI values from the regular level (white) to the 99th percentile
/// (black), so that a few extreme orbits do not wash out the map.
pub fn fli_shading(fli: &[f64], iterations: usize) -> FliShading {
    let mut sorted: Vec<f64> = fli.iter().copied().filter(|x| x.is_finite()).collect();
    sorted.sort_by(f64::total_cmp);
    let low = (iterations as f64).ln();
    let high = sorted
        .get((sorted.len() as f64 * 0.99) as usize)
        .copied()
        .unwrap_or(low)
        .max(low + 1.0);
    FliShading {
        shades: fli
            .iter()
            .map(|x| ((x - low) / (high - low)).clamp(0.0, 1.0))
            .collect(),
        regular_level: low,
        chaotic_fraction: fli
            .iter()
            .filter(|x| fli_is_chaotic(**x, iterations))
            .count() as f64
            / fli.len().max(1) as f64,
    }
}
