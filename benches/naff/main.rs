//! Benchmark `naff` (`cargo bench --bench naff`): mechlab's NAFF on the
//! signals `benches/nafflib_peer.py` gives nafflib, printed as JSON lines
//! (the peer script runs both and prints the ratios). Each signal is
//! f_j = e^{2πi Q₁ j} + 0.4 e^{2πi Q₂ j + 0.3i}, j = 0 … n−1 (tunes per
//! sample, as nafflib counts them); each row: the first tune's error,
//! the second's, and the best of 20 runs' seconds for two terms.

use mechlab::analysis::frequency::{naff, Complex, NaffSettings};
use std::f64::consts::PI;
use std::time::Instant;

/// The tunes of the peer's signals (the script uses the same).
const Q1: f64 = 0.312_345_678_9;
const Q2: f64 = 0.123_456_789_0 * std::f64::consts::SQRT_2;

fn main() {
    for window_order in [1, 2] {
        for n in [1024usize, 4096, 16384] {
            let signal: Vec<Complex<f64>> = (0..n)
                .map(|j| {
                    let t = j as f64;
                    Complex::from_polar(1.0, 2.0 * PI * Q1 * t)
                        + Complex::from_polar(0.4, 2.0 * PI * Q2 * t + 0.3)
                })
                .collect();
            let settings = NaffSettings {
                terms: 2,
                window_order,
            };
            let mut best = f64::INFINITY;
            let mut terms = Vec::new();
            for _ in 0..20 {
                let start = Instant::now();
                terms = naff(&signal, 1.0, &settings).expect("a valid signal");
                best = best.min(start.elapsed().as_secs_f64());
            }
            let tune = |k: usize| terms[k].frequency / (2.0 * PI);
            println!(
                "{{\"window_order\": {window_order}, \"n\": {n}, \"error1\": {:.3e}, \"error2\": {:.3e}, \"seconds\": {best:.6e}}}",
                (tune(0) - Q1).abs(),
                (tune(1) - Q2).abs()
            );
        }
    }
}
