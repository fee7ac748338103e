//! Chaos maps on a surface of section: MEGNO ⟨Y⟩ over a grid of the
//! section's accessible region at energy E, each pixel the orbit through
//! that point of the plane (its missing momentum solved from H = E), run
//! in the batch Taylor lanes on all cores; the chaotic fraction of the
//! accessible area.

use super::check::ClassCheck;
use super::lyapunov::megno_values;
use super::section::{on_plane, Chart, SectionError, SectionSettings};
use crate::analysis::Refusal;
use crate::ode::{LaneIntegrator, Method, OdeError};
use crate::plot::{ColorMap, Figure, PanelSpec};
use crate::registry::{Fixed, FixedSize, Model};
use rayon::prelude::*;

/// What a section's chaos map computes.
#[derive(Clone, Debug)]
pub struct SectionMapSettings {
    /// The plane, its crossing direction (the branch of the solved
    /// momentum), the energy, and the Taylor method's tolerance
    /// (`crossings` is not used).
    pub section: SectionSettings,
    /// Pixels per side.
    pub pixels: usize,
    /// The time each orbit runs.
    pub t_max: f64,
    /// The accessible region is searched for in [−extent, extent]² of the
    /// other coordinate and its momentum.
    pub extent: f64,
    /// Pixels run again at a hundredth of the tolerance to state how many
    /// change class (0: none).
    pub check: usize,
}

/// ⟨Y⟩ above this is chaos (regular orbits tend to 2, periodic ones to 0).
pub const CHAOS_THRESHOLD: f64 = 4.0;

/// A chaos map of a section.
#[derive(Debug, serde::Serialize)]
pub struct SectionMap {
    pub model: String,
    /// The energy, of H or, with a fast phase, of the averaged H̄.
    pub energy: f64,
    pub energy_of: &'static str,
    pub axes: [String; 2],
    /// The window: the other coordinate's range and its momentum's.
    pub window: [[f64; 2]; 2],
    pub pixels: usize,
    pub t_max: f64,
    /// Pixels where the energy is accessible, and how many of them have
    /// ⟨Y⟩ above [`CHAOS_THRESHOLD`]: the chaotic fraction by area.
    pub accessible: usize,
    pub chaotic: usize,
    pub chaotic_fraction: f64,
    /// Orbits the integrator could not follow (left out of both counts).
    pub failed: usize,
    /// The share of pixels a run at a hundredth of the tolerance
    /// reclassifies, from a sample: the chaotic fraction's numerical error
    /// (None: not checked).
    pub class_check: Option<ClassCheck>,
    /// Whether the `accuracy` asked for was reached, and at which
    /// tolerance.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub accuracy: Option<String>,
    pub seconds: f64,
    /// ⟨Y⟩ per pixel, row 0 at the bottom; NaN where the energy is not
    /// accessible.
    #[serde(skip)]
    pub megno: Vec<f64>,
}

/// The accessible region of a section at energy E as a grid of pixels:
/// what a map over a section (MEGNO's, the frequency map) runs its orbits
/// from.
pub(super) struct SectionGrid {
    pub fixed: &'static crate::registry::Erased<2, 4, 8, 20>,
    /// The other coordinate's range and its momentum's.
    pub window: [[f64; 2]; 2],
    pub pixels: usize,
    /// Each pixel's state on the plane (None where the energy is not
    /// accessible), row 0 at the bottom.
    pub seeds: Vec<Option<[f64; 4]>>,
    pub axes: [String; 2],
    pub energy_of: &'static str,
}

impl SectionGrid {
    /// The grid of `pixels`² over the accessible region of the section of
    /// a 2-degree `model` (`analysis` names the map for its refusals).
    pub(super) fn new(
        model: &Model,
        params: &[f64],
        section: &SectionSettings,
        (pixels, extent): (usize, f64),
        analysis: &'static str,
    ) -> Result<SectionGrid, SectionError> {
        let name = model.info.name.to_string();
        let fixed = match model.sized {
            Some(FixedSize::Dof2(fixed)) => fixed,
            Some(_) => {
                return Err(Refusal::Dimension {
                    model: name,
                    dof: model.info.coordinates.len(),
                    analysis,
                    supported: "2",
                }
                .into())
            }
            None => {
                return Err(SectionError::Refused(Refusal::without_hamiltonian_form(
                    model,
                )))
            }
        };
        let bad =
            |requirement: &'static str| SectionError::from(Refusal::setting(&name, requirement));
        if pixels < 2 || !(extent > 0.0) {
            return Err(bad("pixels ≥ 2, t_max and extent positive"));
        }
        crate::budget::check_map(pixels).map_err(OdeError::from)?;
        let chart = Chart::new(section, 2, &fixed.periodic())
            .ok_or_else(|| bad(super::section::PLANE_COEFFICIENTS))?;
        let energy = super::section::seed_energy(model, params)
            .ok_or_else(|| bad(super::section::NO_AVERAGED_HAMILTONIAN))?;
        let energy = |y: &[f64; 4]| energy(y);
        // The least H over the solved momentum at a point of the plane.
        let least = |q: f64, p: f64| chart.least_energy(&[q, p], &energy);
        let centre = chart.centred(|q| least(q, 0.0), section.energy).centre();
        let region = Region::find(&least, section.energy, extent, centre).ok_or_else(|| {
            SectionError::NoSeeds {
                model: name.clone(),
            }
        })?;
        let window = region.window();
        let at = |i: usize, range: [f64; 2]| {
            range[0] + (range[1] - range[0]) * (i as f64 + 0.5) / pixels as f64
        };
        let seeds = (0..pixels * pixels)
            .into_par_iter()
            .map(|k| {
                let (q, p) = (at(k % pixels, window[0]), at(k / pixels, window[1]));
                region
                    .contains(q, p)
                    .then(|| on_plane::<4>(&[q, p], &chart, section, &energy).ok())
                    .flatten()
            })
            .collect();
        Ok(SectionGrid {
            fixed,
            window,
            pixels,
            seeds,
            axes: chart.axes(&model.info.state_names()),
            energy_of: if fixed.has_fast_phase() { "H̄" } else { "H" },
        })
    }
}

/// The MEGNO map of the section of a 2-degree autonomous `model`.
pub fn section_map(
    model: &Model,
    params: &[f64],
    settings: &SectionMapSettings,
) -> Result<SectionMap, SectionError> {
    let name = model.info.name.to_string();
    let s = &settings.section;
    let bad = |requirement: &'static str| SectionError::from(Refusal::setting(&name, requirement));
    if !(settings.t_max > 0.0) {
        return Err(bad("pixels ≥ 2, t_max and extent positive"));
    }
    let method = Method::Taylor { tol: s.tol };
    method.validate()?;
    let start = std::time::Instant::now();
    let grid = SectionGrid::new(
        model,
        params,
        s,
        (settings.pixels, settings.extent),
        "a section's MEGNO map",
    )?;
    let fixed = grid.fixed;
    let chunk = megno_interval(fixed.has_fast_phase(), fixed.phase_period(params), s.phase)
        .ok_or_else(|| bad("with a fast phase the map starts its orbits at phase 0"))?;
    let n = grid.pixels;
    let system = fixed.exact(params);
    let chunks = (settings.t_max / chunk).ceil() as usize;
    let w0 = [0.5; 4];
    // ⟨Y⟩ of the pixels `ks` by `method`, streamed through one batch
    // integrator: NaN where the energy is not accessible, +∞ where the run
    // failed.
    let megno_of = |ks: &[usize], method| -> Result<Vec<f64>, SectionError> {
        let seeds: Vec<(usize, [f64; 4])> = (ks.iter().enumerate())
            .filter_map(|(i, &k)| grid.seeds[k].map(|y| (i, y)))
            .collect();
        let mut block = vec![f64::NAN; ks.len()];
        let mut integrator = LaneIntegrator::new(method)?;
        let starts: Vec<[f64; 4]> = seeds.iter().map(|(_, y)| *y).collect();
        let values = megno_values::<_, 4, 8>(&mut integrator, &system, chunk, &starts, &w0, chunks);
        for ((i, _), value) in seeds.iter().zip(values) {
            block[*i] = value.unwrap_or(f64::INFINITY);
        }
        Ok(block)
    };
    let rows: Vec<Vec<f64>> = super::row_blocks(0..n, n)
        .into_par_iter()
        .map(|rows| megno_of(&(rows.start * n..rows.end * n).collect::<Vec<_>>(), method))
        .collect::<Result<_, _>>()?;
    let megno: Vec<f64> = rows.into_iter().flatten().collect();
    let failed = megno.iter().filter(|v| **v == f64::INFINITY).count();
    let accessible = megno.iter().filter(|v| v.is_finite()).count();
    let chaotic = megno
        .iter()
        .filter(|v| v.is_finite() && **v > CHAOS_THRESHOLD)
        .count();
    let class = |y: f64| y.is_finite().then_some(y > CHAOS_THRESHOLD);
    let class_check = match settings.check {
        0 => None,
        count => {
            let rerun = super::check::rerun_sample(n * n, count, method, |ks, method| {
                megno_of(ks, method)
            })?;
            let census = rerun.census;
            let pairs = (rerun.pixels.iter())
                .zip(rerun.values)
                .map(|(&k, again)| (class(megno[k]), class(again)));
            Some(ClassCheck::new(pairs, rerun.runs, census))
        }
    };
    Ok(SectionMap {
        model: name,
        energy: s.energy,
        energy_of: grid.energy_of,
        axes: grid.axes,
        window: grid.window,
        pixels: n,
        t_max: chunks as f64 * chunk,
        accessible,
        chaotic,
        chaotic_fraction: chaotic as f64 / accessible.max(1) as f64,
        failed,
        class_check,
        accuracy: None,
        seconds: start.elapsed().as_secs_f64(),
        megno,
    })
}

/// The time between MEGNO's samples: 2, or with a fast phase the whole
/// number of periods nearest 2 (the lanes restart the time at 0 after
/// each: the field must be the same there), the orbits from phase 0.
fn megno_interval(fast_phase: bool, period: Option<f64>, phase: f64) -> Option<f64> {
    match (fast_phase, period) {
        (false, _) => Some(2.0),
        (true, Some(period)) if period > 0.0 && phase == 0.0 => {
            Some((2.0 / period).round().max(1.0) * period)
        }
        (true, _) => None,
    }
}

/// The region of the plane where H = E is accessible (the least H below
/// E) and connected to the origin (else the largest such region: beyond a
/// barrier the energy may be accessible again on an open branch), from a
/// 400² scan of [−extent, extent]² about (centre, 0).
struct Region {
    extent: f64,
    /// The scan's centre in the first coordinate (0, or π for an angle
    /// accessible only there).
    centre: f64,
    inside: Vec<bool>,
}

const SCAN: usize = 400;

/// The i-th of the scan's points on [−extent, extent].
fn scan_point(extent: f64, i: usize) -> f64 {
    -extent + 2.0 * extent * i as f64 / (SCAN - 1) as f64
}

impl Region {
    fn find(
        least: &(dyn Fn(f64, f64) -> f64 + Sync),
        energy: f64,
        extent: f64,
        centre: f64,
    ) -> Option<Region> {
        let at = |i: usize| scan_point(extent, i);
        let open: Vec<bool> = (0..SCAN * SCAN)
            .into_par_iter()
            .map(|k| least(centre + at(k % SCAN), at(k / SCAN)) < energy)
            .collect();
        // The connected regions, by flood fill; the one holding the origin.
        let mut label = vec![usize::MAX; SCAN * SCAN];
        let mut sizes = Vec::new();
        for seed in 0..open.len() {
            if !open[seed] || label[seed] != usize::MAX {
                continue;
            }
            let id = sizes.len();
            let (mut stack, mut size) = (vec![seed], 0);
            label[seed] = id;
            while let Some(k) = stack.pop() {
                size += 1;
                let (i, j) = (k % SCAN, k / SCAN);
                let neighbours = [
                    (i > 0).then(|| k - 1),
                    (i + 1 < SCAN).then(|| k + 1),
                    (j > 0).then(|| k - SCAN),
                    (j + 1 < SCAN).then(|| k + SCAN),
                ];
                for n in neighbours.into_iter().flatten() {
                    if open[n] && label[n] == usize::MAX {
                        label[n] = id;
                        stack.push(n);
                    }
                }
            }
            sizes.push(size);
        }
        let middle = (SCAN / 2) * SCAN + SCAN / 2;
        let chosen = match label[middle] {
            usize::MAX => (0..sizes.len()).max_by_key(|&id| sizes[id])?,
            id => id,
        };
        Some(Region {
            extent,
            centre,
            inside: label.iter().map(|&l| l == chosen).collect(),
        })
    }

    fn cell(&self, x: f64) -> Option<usize> {
        let i = ((x + self.extent) / (2.0 * self.extent) * (SCAN - 1) as f64).round();
        (0.0..SCAN as f64).contains(&i).then_some(i as usize)
    }

    fn contains(&self, q: f64, p: f64) -> bool {
        matches!((self.cell(q - self.centre), self.cell(p)), (Some(i), Some(j)) if self.inside[j * SCAN + i])
    }

    /// Its bounding box, padded by one scan cell.
    fn window(&self) -> [[f64; 2]; 2] {
        let at = |i: usize| scan_point(self.extent, i);
        let cell = 2.0 * self.extent / (SCAN - 1) as f64;
        let cells: Vec<(usize, usize)> = (0..self.inside.len())
            .filter(|&k| self.inside[k])
            .map(|k| (k % SCAN, k / SCAN))
            .collect();
        let range = |pick: fn(&(usize, usize)) -> usize| {
            let (lo, hi) = cells
                .iter()
                .map(pick)
                .fold((usize::MAX, 0), |(a, b), k| (a.min(k), b.max(k)));
            [at(lo) - cell, at(hi) + cell]
        };
        let q = range(|c| c.0);
        [[q[0] + self.centre, q[1] + self.centre], range(|c| c.1)]
    }
}

impl SectionMap {
    /// ⟨Y⟩ from 0 to 8 (Viridis; white where the energy is not
    /// accessible).
    pub fn figure(&self) -> Figure {
        let checked = self.class_check.as_ref().map_or(String::new(), |c| {
            format!(" ({} of {} rechecked change)", c.changed, c.sampled)
        });
        let title = format!(
            "{}: MEGNO ⟨Y⟩ at {} = {}, t = {}; ⟨Y⟩ > {CHAOS_THRESHOLD} on {:.1} %{checked}",
            self.model,
            self.energy_of,
            self.energy,
            super::section::short(self.t_max),
            100.0 * self.chaotic_fraction
        );
        let spec = PanelSpec::new(
            &title,
            &self.axes[0],
            &self.axes[1],
            (self.window[0][0], self.window[0][1]),
            (self.window[1][0], self.window[1][1]),
        );
        let mut figure = Figure::single(720, 660, spec);
        let shades: Vec<f64> = self
            .megno
            .iter()
            .map(|v| {
                if v.is_nan() {
                    f64::NAN
                } else {
                    (v / 8.0).clamp(0.0, 1.0)
                }
            })
            .collect();
        figure.shaded_map(
            0,
            self.pixels,
            self.pixels,
            &shades,
            ColorMap::Viridis,
            "⟨Y⟩ / 8",
        );
        figure
    }
}
