//! The Chirikov standard map on the cylinder,
//! (q, p) ↦ (q + p + ε sin q, p + ε sin q), and its tangent map.

use super::period_map::wrap_angle;
use crate::outputs::{Outputs, Table};
use crate::plot::{palette, ColorMap, Figure, PanelSpec};
use crate::tangent::lyapunov::fli_shading;
use rayon::prelude::*;
use std::f64::consts::PI;

/// One iterate; q is kept in [−π, π), p unwrapped.
pub fn standard_map(eps: f64, (q, p): (f64, f64)) -> (f64, f64) {
    let p_next = p + eps * q.sin();
    (wrap_angle(q + p_next), p_next)
}

/// Fast Lyapunov indicator after `iterations`: max ln‖w‖ of the tangent map.
pub fn standard_map_fli(eps: f64, start: (f64, f64), iterations: usize) -> f64 {
    let (mut q, mut p) = start;
    let (mut dq, mut dp) = (1.0, 0.0);
    let mut log_scale: f64 = 0.0;
    let mut fli = f64::NEG_INFINITY;
    for _ in 0..iterations {
        let k = eps * q.cos();
        dp += k * dq;
        dq += dp;
        let p_next = p + eps * q.sin();
        q = wrap_angle(q + p_next);
        p = p_next;
        let norm = dq.hypot(dp);
        fli = fli.max(log_scale + norm.ln());
        if norm > 1e100 {
            log_scale += norm.ln();
            dq /= norm;
            dp /= norm;
        }
    }
    fli
}

crate::declare_settings! {
    /// Orbits of the Chirikov standard map and its chaos map, every pixel
    /// shaded by the fast Lyapunov indicator of its orbit (dark: chaotic):
    /// the stochastic web.
    pub struct StandardMapOptions for "standard_map" {
        /// The map's parameter ε.
        eps: f64 = 0.16, crate::settings::Range::Any;
        /// Chaos map resolution (pixels per side).
        pixels: usize = 600, crate::settings::Range::Count { min: 2, max: 10_000 };
        /// Iterations per pixel for the FLI.
        iterations: usize = 500, crate::settings::Range::Count { min: 2, max: 100_000_000 };
        /// Orbits in the orbit picture.
        orbits: usize = 40, crate::settings::Range::Count { min: 1, max: 100_000 };
        /// Iterates per orbit.
        length: usize = 3000, crate::settings::Range::Count { min: 1, max: 100_000_000 };
    }
}

/// The orbits and the FLI map of the standard map.
#[derive(serde::Serialize)]
pub struct StandardMapStudy {
    pub eps: f64,
    pub pixels: usize,
    pub iterations: usize,
    /// Share of pixels whose FLI is above twice the regular level.
    pub chaotic_fraction: f64,
    /// ln(iterations): the FLI of a regular orbit.
    pub fli_regular_level: f64,
    pub seconds: f64,
    /// Per orbit, its iterates (q, p), p wrapped to [−π, π).
    #[serde(skip)]
    pub orbits: Vec<Vec<(f64, f64)>>,
    /// The FLI per pixel, rows from the bottom.
    #[serde(skip)]
    pub fli: Vec<f64>,
    /// Its shading in [0, 1].
    #[serde(skip)]
    pub shades: Vec<f64>,
}

/// The pixel centre of cell `k` of a `pixels`² grid over [−π, π)².
fn pixel_centre(k: usize, pixels: usize) -> (f64, f64) {
    let (i, j) = (k % pixels, k / pixels);
    let at = |i: usize| -PI + 2.0 * PI * (i as f64 + 0.5) / pixels as f64;
    (at(i), at(j))
}

/// Orbits from a spread of starts, and the FLI map (pixels in parallel,
/// in a deterministic order).
pub fn standard_map_study(o: &StandardMapOptions) -> StandardMapStudy {
    let orbits = (0..o.orbits)
        .map(|k| {
            let mut x = (
                0.3 * (k as f64 * 2.399).sin() * PI,
                -PI + 2.0 * PI * (k as f64 + 0.5) / o.orbits as f64,
            );
            (0..o.length)
                .map(|_| {
                    let point = x;
                    x = standard_map(o.eps, x);
                    x.1 = (x.1 + PI).rem_euclid(2.0 * PI) - PI;
                    point
                })
                .collect()
        })
        .collect();
    let start = std::time::Instant::now();
    let fli: Vec<f64> = (0..o.pixels * o.pixels)
        .into_par_iter()
        .map(|k| standard_map_fli(o.eps, pixel_centre(k, o.pixels), o.iterations))
        .collect();
    let seconds = start.elapsed().as_secs_f64();
    let shading = fli_shading(&fli, o.iterations);
    StandardMapStudy {
        eps: o.eps,
        pixels: o.pixels,
        iterations: o.iterations,
        chaotic_fraction: shading.chaotic_fraction,
        fli_regular_level: shading.regular_level,
        seconds,
        orbits,
        fli,
        shades: shading.shades,
    }
}

impl StandardMapStudy {
    /// The orbits, a colour each.
    pub fn orbits_figure(&self) -> Figure {
        let title = format!("standard map orbits, ε = {}", self.eps);
        let spec = PanelSpec::new(&title, "q", "p", (-PI, PI), (-PI, PI));
        let mut figure = Figure::single(800, 800, spec);
        for (k, orbit) in self.orbits.iter().enumerate() {
            figure.points(0, orbit.iter().copied(), palette(k), 1);
        }
        figure
    }

    /// The FLI map in `colors`.
    pub fn chaos_map_figure(&self, colors: ColorMap) -> Figure {
        let title = format!(
            "FLI chaos map, ε = {}, {} iterations",
            self.eps, self.iterations
        );
        let spec = PanelSpec::new(&title, "q", "p", (-PI, PI), (-PI, PI));
        let n = self.pixels;
        let mut figure = Figure::single(n + 90, n + 75, spec);
        let label = "FLI: regular level (0) to the 99th percentile (1)";
        figure.shaded_map(0, n, n, &self.shades, colors, label);
        figure
    }

    /// (orbit, iterate, q, p) of every orbit.
    pub fn orbit_rows(&self) -> impl Iterator<Item = (usize, usize, f64, f64)> + '_ {
        self.orbits.iter().enumerate().flat_map(|(k, orbit)| {
            orbit
                .iter()
                .enumerate()
                .map(move |(n, &(q, p))| (k, n, q, p))
        })
    }

    /// (q, p, fli) of every pixel.
    pub fn map_rows(&self) -> impl Iterator<Item = (f64, f64, f64)> + '_ {
        self.fli.iter().enumerate().map(|(k, &f)| {
            let (q, p) = pixel_centre(k, self.pixels);
            (q, p, f)
        })
    }
}

impl Outputs for StandardMapStudy {
    fn figures(&self) -> Vec<(String, Figure)> {
        vec![
            ("orbits.png".into(), self.orbits_figure()),
            (
                "chaos_map.png".into(),
                self.chaos_map_figure(ColorMap::Grey),
            ),
            (
                "chaos_map_viridis.png".into(),
                self.chaos_map_figure(ColorMap::Viridis),
            ),
        ]
    }
    fn tables(&self) -> Vec<Table> {
        vec![
            Table::new(
                "orbits.csv",
                &["orbit", "iterate", "q", "p"],
                self.orbit_rows(),
            ),
            Table::new("chaos_map.csv", &["q", "p", "fli"], self.map_rows()),
        ]
    }
}
