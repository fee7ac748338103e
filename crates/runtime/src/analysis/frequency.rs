//! Laskar's numerical analysis of fundamental frequencies (NAFF): the
//! frequencies and amplitudes of a quasi-periodic signal sampled at equal
//! steps, f(t) ≈ Σ a_k e^{iω_k t}.
//!
//! Each term is found on what the terms before it leave: the windowed
//! Fourier transform's largest peak (located by a radix-2 FFT), refined
//! by Newton's method on the derivative of |⟨f, e^{iωt}⟩|² to full
//! precision, then the amplitudes of all terms found so far solved
//! together in the window's inner product (the Gram–Schmidt step: the
//! exponentials are not orthogonal over a finite time). With the Hanning
//! window of order p the frequencies' error falls as T^−(2p+2) for a
//! quasi-periodic signal over a time T (Laskar 1993).
//!
//! Written here rather than taken from a crate: `rustfft` would add its
//! compile time to every fresh build for the one power-of-two transform
//! the coarse peak needs (the 30 lines of [`fft`], tested against the
//! direct sum).

/// The signal's numbers (nalgebra's, re-exported for callers without it).
pub use nalgebra::Complex;
use nalgebra::{DMatrix, DVector};
use std::f64::consts::PI;

/// The fewest samples a frequency analysis accepts.
pub const MIN_SAMPLES: usize = 16;

/// One term a e^{iωt} of the signal (t from the first sample).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Term {
    pub frequency: f64,
    #[serde(serialize_with = "complex_pair")]
    pub amplitude: Complex<f64>,
}

fn complex_pair<S: serde::Serializer>(z: &Complex<f64>, s: S) -> Result<S::Ok, S::Error> {
    serde::Serialize::serialize(&[z.re, z.im], s)
}

/// How a signal is analysed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NaffSettings {
    /// Terms to find (each on the residual of the ones before).
    pub terms: usize,
    /// The Hanning window's order p: χ_p(τ) ∝ (1 + cos πτ)^p on τ ∈ [−1, 1].
    pub window_order: u32,
}

impl Default for NaffSettings {
    fn default() -> Self {
        NaffSettings {
            terms: 4,
            window_order: 1,
        }
    }
}

/// Why a signal cannot be analysed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FrequencyError {
    #[error("{given} samples: a frequency analysis needs at least {MIN_SAMPLES}")]
    TooFewSamples { given: usize },
    #[error("the sample {index} is not finite")]
    NotFinite { index: usize },
    #[error("the time step must be finite and positive, got {0}")]
    Step(f64),
    #[error("the number of terms must be from 1 to a quarter of the samples ({max}), got {given}")]
    Terms { given: usize, max: usize },
    #[error("the window's order must be from 0 to 8, got {0}")]
    WindowOrder(u32),
}

/// The terms of `signal` (samples at t = 0, dt, 2dt, …), in the order
/// found (the largest first, as a rule).
pub fn naff(
    signal: &[Complex<f64>],
    dt: f64,
    settings: &NaffSettings,
) -> Result<Vec<Term>, FrequencyError> {
    let n = signal.len();
    if n < MIN_SAMPLES {
        return Err(FrequencyError::TooFewSamples { given: n });
    }
    if let Some(index) = signal
        .iter()
        .position(|z| !(z.re.is_finite() && z.im.is_finite()))
    {
        return Err(FrequencyError::NotFinite { index });
    }
    if !(dt.is_finite() && dt > 0.0) {
        return Err(FrequencyError::Step(dt));
    }
    if settings.terms == 0 || settings.terms > n / 4 {
        return Err(FrequencyError::Terms {
            given: settings.terms,
            max: n / 4,
        });
    }
    if settings.window_order > 8 {
        return Err(FrequencyError::WindowOrder(settings.window_order));
    }
    let analysis = Analysis::new(n, dt, settings.window_order);
    let mut frequencies: Vec<f64> = Vec::new();
    let mut amplitudes: Vec<Complex<f64>> = Vec::new();
    let mut residual = signal.to_vec();
    for _ in 0..settings.terms {
        let Some(frequency) = analysis.peak(&residual) else {
            break; // nothing left: the signal is a sum of the terms found
        };
        if frequencies
            .iter()
            .any(|&f| (f - frequency).abs() < 1e-12 * (1.0 + f.abs()))
        {
            break; // the same peak again: no new term resolvable
        }
        frequencies.push(frequency);
        amplitudes = analysis.amplitudes(signal, &frequencies);
        if frequencies.len() == settings.terms {
            break; // (no residual needed after the last term)
        }
        residual.copy_from_slice(signal);
        for (&f, &a) in frequencies.iter().zip(&amplitudes) {
            analysis.subtract(&mut residual, f, a);
        }
    }
    Ok(frequencies
        .into_iter()
        .zip(amplitudes)
        .map(|(frequency, amplitude)| Term {
            frequency,
            amplitude,
        })
        .collect())
}

/// The window and the sums over the samples.
struct Analysis {
    dt: f64,
    /// χ_p at each sample, its mean 1.
    window: Vec<f64>,
}

impl Analysis {
    fn new(n: usize, dt: f64, order: u32) -> Self {
        let last = (n - 1) as f64;
        let mut window: Vec<f64> = (0..n)
            .map(|j| (1.0 + (PI * (2.0 * j as f64 / last - 1.0)).cos()).powi(order as i32))
            .collect();
        let mean = window.iter().sum::<f64>() / n as f64;
        window.iter_mut().for_each(|w| *w /= mean);
        Analysis { dt, window }
    }

    /// e^{−iωt_j} for every sample, by rotation, restarted exactly every
    /// 64 samples (the rounding of a long product stays below 1e-14).
    fn for_each_phase(&self, omega: f64, mut visit: impl FnMut(usize, Complex<f64>)) {
        let step = Complex::from_polar(1.0, -omega * self.dt);
        let mut phase = Complex::new(1.0, 0.0);
        for j in 0..self.window.len() {
            if j % 64 == 0 {
                phase = Complex::from_polar(1.0, -omega * self.dt * j as f64);
            }
            visit(j, phase);
            phase *= step;
        }
    }

    /// The signal times the window.
    fn windowed(&self, f: &[Complex<f64>]) -> Vec<Complex<f64>> {
        f.iter().zip(&self.window).map(|(z, w)| z * w).collect()
    }

    /// ⟨f, e^{iωt}⟩ and its first two derivatives in ω, from the windowed
    /// signal.
    fn transform(&self, windowed: &[Complex<f64>], omega: f64) -> [Complex<f64>; 3] {
        let mut sums = [Complex::new(0.0, 0.0); 3];
        self.for_each_phase(omega, |j, phase| {
            let t = j as f64 * self.dt;
            let term = windowed[j] * phase;
            sums[0] += term;
            sums[1] += term * t;
            sums[2] += term * (t * t);
        });
        let n = windowed.len() as f64;
        // d/dω e^{−iωt} = −it e^{−iωt}, d²/dω² = −t² e^{−iωt}.
        [
            sums[0] / n,
            sums[1] * Complex::new(0.0, -1.0 / n),
            -sums[2] / n,
        ]
    }

    /// The frequency of the largest peak of |⟨f, e^{iωt}⟩|, or None if f
    /// vanishes.
    fn peak(&self, f: &[Complex<f64>]) -> Option<f64> {
        let n = f.len();
        let size = n.next_power_of_two();
        let windowed = self.windowed(f);
        let mut data = vec![Complex::new(0.0, 0.0); size];
        data[..n].copy_from_slice(&windowed);
        fft(&mut data);
        let (k, largest) = data
            .iter()
            .enumerate()
            .map(|(k, z)| (k, z.norm()))
            .max_by(|a, b| a.1.total_cmp(&b.1))?;
        if largest == 0.0 {
            return None;
        }
        let bin = 2.0 * PI / (size as f64 * self.dt);
        // The peak between the bins by a parabola through the logarithms
        // of the three magnitudes about it (exact for a Gaussian peak,
        // close for the window's), a fraction of a bin from the maximum.
        let magnitude = |k: usize| data[k % size].norm().max(f64::MIN_POSITIVE).ln();
        let (left, centre, right) = (magnitude(k + size - 1), largest.ln(), magnitude(k + 1));
        let curvature = left - 2.0 * centre + right;
        let offset = match curvature < 0.0 {
            true => (0.5 * (left - right) / curvature).clamp(-0.5, 0.5),
            false => 0.0,
        };
        // The DFT's bin k is the frequency k·bin, aliased into (−π/dt, π/dt].
        let k = k as f64 + offset;
        let coarse = match k <= (size / 2) as f64 {
            true => k * bin,
            false => (k - size as f64) * bin,
        };
        Some(self.refine(&windowed, coarse, bin))
    }

    /// Newton's method on g(ω) = d|A|²/dω, A = ⟨f, e^{iωt}⟩, kept within
    /// one bin of the coarse peak (bisecting on the sign of g when a step
    /// leaves the bracket), until a step is below 1e-13 of the frequency
    /// (or of a bin, near zero).
    fn refine(&self, windowed: &[Complex<f64>], coarse: f64, bin: f64) -> f64 {
        let slope = |omega: f64| {
            let [a, d1, d2] = self.transform(windowed, omega);
            let g = 2.0 * (a.conj() * d1).re;
            let dg = 2.0 * (d1.conj() * d1 + a.conj() * d2).re;
            (g, dg)
        };
        let (mut low, mut high) = (coarse - bin, coarse + bin);
        let mut omega = coarse;
        for _ in 0..40 {
            let (g, dg) = slope(omega);
            // |A|² rises where g > 0: the maximum lies above.
            if g > 0.0 {
                low = omega;
            } else {
                high = omega;
            }
            let newton = omega - g / dg;
            // (A converged step lands on the bracket's end: kept.)
            let next = match dg < 0.0 && newton >= low && newton <= high {
                true => newton,
                false => 0.5 * (low + high),
            };
            if (next - omega).abs() <= 1e-15 * omega.abs().max(bin) {
                return next;
            }
            omega = next;
        }
        omega
    }

    /// The amplitudes of the exponentials at `frequencies` that fit f best
    /// in the window's inner product: G a = b, G the exponentials' Gram
    /// matrix, b their products with f.
    fn amplitudes(&self, f: &[Complex<f64>], frequencies: &[f64]) -> Vec<Complex<f64>> {
        let k = frequencies.len();
        let gram = DMatrix::from_fn(k, k, |l, m| {
            // ⟨e_m, e_l⟩: the window's transform at ω_l − ω_m.
            let mut sum = Complex::new(0.0, 0.0);
            self.for_each_phase(frequencies[l] - frequencies[m], |j, phase| {
                sum += phase * self.window[j];
            });
            sum / self.window.len() as f64
        });
        let windowed = self.windowed(f);
        let products = DVector::from_iterator(
            k,
            frequencies.iter().map(|&w| self.transform(&windowed, w)[0]),
        );
        match gram.lu().solve(&products) {
            Some(a) => a.iter().copied().collect(),
            None => products.iter().copied().collect(),
        }
    }

    /// f ← f − a e^{iωt}.
    fn subtract(&self, f: &mut [Complex<f64>], omega: f64, a: Complex<f64>) {
        self.for_each_phase(-omega, |j, phase| f[j] -= a * phase);
    }
}

/// The discrete Fourier transform X_k = Σ x_j e^{−2πijk/n} in place, n a
/// power of two (iterative radix-2).
pub fn fft(data: &mut [Complex<f64>]) {
    let n = data.len();
    assert!(n.is_power_of_two(), "a power of two");
    if n == 1 {
        return;
    }
    let bits = n.trailing_zeros();
    for i in 0..n {
        let j = i.reverse_bits() >> (usize::BITS - bits);
        if i < j {
            data.swap(i, j);
        }
    }
    let mut length = 2;
    while length <= n {
        let root = Complex::from_polar(1.0, -2.0 * PI / length as f64);
        for start in (0..n).step_by(length) {
            let mut w = Complex::new(1.0, 0.0);
            for k in 0..length / 2 {
                let (a, b) = (data[start + k], data[start + k + length / 2] * w);
                data[start + k] = a + b;
                data[start + k + length / 2] = a - b;
                w *= root;
            }
        }
        length *= 2;
    }
}
