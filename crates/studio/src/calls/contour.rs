//! Level sets of a function sampled on a grid, by marching squares: each
//! grid cell whose corners straddle the level gets one or two segments
//! between the crossing points on its edges (linear interpolation).

/// A function sampled at the nodes of an n×n grid over a rectangle.
#[derive(Clone, Debug)]
pub struct Field {
    ranges: [(f64, f64); 2],
    n: usize,
    /// Row-major from the lower left: node (i, j) at j·n + i.
    values: Vec<f64>,
}

impl Field {
    /// Samples `f` at n×n nodes spanning `ranges` (corners included).
    pub fn sample(ranges: [(f64, f64); 2], n: usize, f: impl Fn(f64, f64) -> f64) -> Field {
        let n = n.max(2);
        let mut values = Vec::with_capacity(n * n);
        for j in 0..n {
            for i in 0..n {
                let (x, y) = node(&ranges, n, i, j);
                values.push(f(x, y));
            }
        }
        Field { ranges, n, values }
    }

    /// `count` levels at evenly spaced quantiles of the finite samples (so
    /// that the curves spread over the picture rather than crowd where the
    /// function is steep).
    pub fn quantiles(&self, count: usize) -> Vec<f64> {
        let mut finite: Vec<f64> = self
            .values
            .iter()
            .copied()
            .filter(|v| v.is_finite())
            .collect();
        if finite.is_empty() {
            return Vec::new();
        }
        finite.sort_by(f64::total_cmp);
        let mut levels: Vec<f64> = (1..=count)
            .map(|k| finite[(k * (finite.len() - 1)) / (count + 1)])
            .collect();
        levels.dedup();
        levels
    }

    /// The segments (x₀, y₀, x₁, y₁) of the level set f = level. Cells with
    /// a non-finite corner are skipped.
    pub fn segments(&self, level: f64) -> Vec<[f64; 4]> {
        let n = self.n;
        let mut out = Vec::new();
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                // Corners counter-clockwise from the lower left.
                let corners = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)];
                let f = corners.map(|(a, b)| self.values[b * n + a] - level);
                if f.iter().any(|v| !v.is_finite()) {
                    continue;
                }
                // Crossing points on the edges k → k+1 whose ends differ in sign.
                let crossings: Vec<[f64; 2]> = (0..4)
                    .filter_map(|k| {
                        let (a, b) = (f[k], f[(k + 1) % 4]);
                        ((a < 0.0) != (b < 0.0)).then(|| {
                            let t = a / (a - b);
                            let (pa, pb) = (corners[k], corners[(k + 1) % 4]);
                            let (xa, ya) = node(&self.ranges, n, pa.0, pa.1);
                            let (xb, yb) = node(&self.ranges, n, pb.0, pb.1);
                            [xa + t * (xb - xa), ya + t * (yb - ya)]
                        })
                    })
                    .collect();
                match crossings.len() {
                    2 => out.push([
                        crossings[0][0],
                        crossings[0][1],
                        crossings[1][0],
                        crossings[1][1],
                    ]),
                    // A saddle cell: pair the crossings by the sign at the
                    // centre (the mean of the corners).
                    4 => {
                        let centre_negative = f.iter().sum::<f64>() < 0.0;
                        let first_negative = f[0] < 0.0;
                        let (p, q) = if centre_negative == first_negative {
                            ((0, 1), (2, 3))
                        } else {
                            ((1, 2), (3, 0))
                        };
                        for (a, b) in [p, q] {
                            out.push([
                                crossings[a][0],
                                crossings[a][1],
                                crossings[b][0],
                                crossings[b][1],
                            ]);
                        }
                    }
                    _ => {}
                }
            }
        }
        out
    }
}

fn node(ranges: &[(f64, f64); 2], n: usize, i: usize, j: usize) -> (f64, f64) {
    let at = |(lo, hi): (f64, f64), k: usize| lo + (hi - lo) * k as f64 / (n - 1) as f64;
    (at(ranges[0], i), at(ranges[1], j))
}
