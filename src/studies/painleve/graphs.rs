//! The broken line Φ(R) of the rigid rod (`painleve_phi`): every graph
//! class with an example and its region, and the roots of X* = Φ(R) for
//! given parameters.

use super::{
    class_example, painleve_case, phi, phi_slope, reduced, rigid_rod_roots, slope_signs,
    GraphClass, Params, Reduced, GRAPH_CLASSES,
};
use crate::plot::{palette, Figure, PanelSpec, BLACK, GREY, RED};

/// The roots for the given parameters and one σ.
#[derive(serde::Serialize)]
pub struct Given {
    pub sigma: f64,
    pub signs: String,
    pub roots: Vec<f64>,
    /// Φ'(R) > 0 at each root.
    pub rising: Vec<bool>,
    pub case: &'static str,
}

/// One point of a region plot: σo, μ1*, μ2*, the class's slope signs.
pub type RegionPoint = (i32, f64, f64, String);

#[derive(serde::Serialize)]
pub struct PhiGraphs {
    pub classes: &'static [GraphClass],
    /// X*, μ1*, μ2*, Y1*, Y2*, cos φ0 of the given parameters.
    pub reduced: Reduced,
    pub given: Vec<Given>,
    /// Per class its example and that example's roots.
    #[serde(skip)]
    pub examples: Vec<(Reduced, Vec<f64>)>,
    #[serde(skip)]
    pub regions: Vec<RegionPoint>,
    #[serde(skip)]
    pub region_pixels: usize,
}

/// Φ on [lo, hi] at 401 points.
fn graph(q: &Reduced, sigma: f64, lo: f64, hi: f64) -> Vec<(f64, f64)> {
    (0..=400)
        .map(|i| lo + (hi - lo) * i as f64 / 400.0)
        .map(|r| (r, phi(r, sigma, q)))
        .collect()
}

/// The classes with their examples (each checked to be of its class), the
/// region of each in the (μ1*, μ2*) plane for σo = ±1, and the roots for
/// `params` with σ = ±1.
pub fn phi_graphs(params: &Params, region_pixels: usize) -> PhiGraphs {
    let q = reduced(params);
    let examples = (0..GRAPH_CLASSES.len())
        .map(|k| {
            let e = class_example(k);
            debug_assert_eq!(slope_signs(1.0, &e), GRAPH_CLASSES[k].signs);
            let roots = rigid_rod_roots(1.0, &e);
            (e, roots)
        })
        .collect();
    let given = [1.0, -1.0]
        .into_iter()
        .map(|sigma| {
            let roots = rigid_rod_roots(sigma, &q);
            Given {
                sigma,
                signs: slope_signs(sigma, &q),
                case: painleve_case(roots.len()),
                rising: roots
                    .iter()
                    .map(|r| phi_slope(*r, sigma, &q) > 0.0)
                    .collect(),
                roots,
            }
        })
        .collect();
    let n = region_pixels;
    let mut regions = Vec::new();
    for (sigma_o, y2) in [(1, -3.0), (-1, 0.0)] {
        for i in 0..n {
            for j in 0..n {
                let mu1 = 5.0 * (i as f64 + 0.5) / n as f64;
                let mu2 = 5.0 * (j as f64 + 0.5) / n as f64;
                let signs = slope_signs(1.0, &Reduced::sample(mu1, mu2, y2));
                if GRAPH_CLASSES.iter().any(|c| c.signs == signs) {
                    regions.push((sigma_o, mu1, mu2, signs));
                }
            }
        }
    }
    PhiGraphs {
        classes: &GRAPH_CLASSES,
        reduced: q,
        given,
        examples,
        regions,
        region_pixels,
    }
}

impl PhiGraphs {
    /// Six example graphs, the two region plots, the given parameters' Φ.
    pub fn figure(&self) -> Figure {
        let q = &self.reduced;
        let mut titles: Vec<String> = self
            .examples
            .iter()
            .zip(self.classes)
            .map(|((_, roots), c)| {
                format!("slopes {}: {} roots of X* = Φ(R)", c.signs, roots.len())
            })
            .collect();
        titles.push("regions, σo = +1".into());
        titles.push("regions, σo = −1".into());
        titles.push(format!(
            "given: X* = {:.3}, σ = +1 (blue), −1 (red)",
            q.x_star
        ));
        let span = |values: &mut dyn Iterator<Item = f64>| {
            let (a, b) = values.fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(v), h.max(v)));
            (a - 0.5, b + 0.5)
        };
        let mut specs = Vec::new();
        let mut ranges = Vec::new();
        for (k, (e, _)) in self.examples.iter().enumerate() {
            let (lo, hi) = (e.y1.min(-e.y2) - 2.0, e.y1.max(-e.y2) + 2.0);
            let values = span(&mut graph(e, 1.0, lo, hi).into_iter().map(|p| p.1));
            ranges.push((lo, hi));
            specs.push(PanelSpec::new(&titles[k], "R", "Φ", (lo, hi), values));
        }
        let n = self.examples.len();
        specs.push(PanelSpec::new(
            &titles[n],
            "μ₁*",
            "μ₂*",
            (0.0, 5.0),
            (0.0, 5.0),
        ));
        specs.push(PanelSpec::new(
            &titles[n + 1],
            "μ₁*",
            "μ₂*",
            (0.0, 5.0),
            (0.0, 5.0),
        ));
        let (glo, ghi) = (q.y1.min(-q.y2) - 3.0, q.y1.max(-q.y2) + 3.0);
        let mut given = [1.0, -1.0]
            .iter()
            .flat_map(|s| graph(q, *s, glo, ghi))
            .map(|p| p.1)
            .chain([q.x_star]);
        specs.push(PanelSpec::new(
            &titles[n + 2],
            "R",
            "Φ",
            (glo, ghi),
            span(&mut given),
        ));
        let mut figure = Figure::grid(3, 3, 480, 360, &specs);
        for (k, ((e, roots), (lo, hi))) in self.examples.iter().zip(&ranges).enumerate() {
            figure.line(k, &graph(e, 1.0, *lo, *hi), palette(k));
            figure.line(k, &[(*lo, e.x_star), (*hi, e.x_star)], GREY);
            figure.points(k, roots.iter().map(|r| (*r, e.x_star)), BLACK, 7);
        }
        let size = (480 / self.region_pixels as i64).max(1) + 1;
        for (sigma_o, mu1, mu2, signs) in &self.regions {
            let k = self
                .classes
                .iter()
                .position(|c| c.signs == *signs)
                .unwrap_or(0);
            let panel = if *sigma_o == 1 { n } else { n + 1 };
            figure.points(panel, [(*mu1, *mu2)], palette(k), size);
        }
        let legend: Vec<(String, _)> = self
            .classes
            .iter()
            .enumerate()
            .map(|(k, c)| (c.signs.to_string(), palette(k)))
            .collect();
        figure.legend(n, &legend[..3]);
        figure.legend(
            n + 1,
            &[
                legend[0].clone(),
                legend[3].clone(),
                legend[4].clone(),
                legend[5].clone(),
            ],
        );
        for (sigma, color) in [(1.0, palette(0)), (-1.0, RED)] {
            figure.line(n + 2, &graph(q, sigma, glo, ghi), color);
            figure.points(
                n + 2,
                rigid_rod_roots(sigma, q).iter().map(|r| (*r, q.x_star)),
                color,
                7,
            );
        }
        figure.line(n + 2, &[(glo, q.x_star), (ghi, q.x_star)], GREY);
        figure
    }
}
