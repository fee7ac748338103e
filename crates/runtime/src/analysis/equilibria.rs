//! The one equilibrium finder of every analysis: Newton's method on a
//! potential's gradient from a grid of starts, at any number of degrees of
//! freedom. `stability` runs it on V (the generated gradient and C), and
//! `explore` on V + V_vibr (its gradient by central differences): both
//! search the same starts with Newton's method, stopped as their
//! gradient's kind allows ([`Convergence`]), and judge what they find.

use crate::ode::wrap_angle;
use crate::registry::DynamicModel;
use nalgebra::{DMatrix, DVector};
use std::f64::consts::PI;

/// Beyond 3 degrees of freedom, coordinates that are not angles start at
/// these values.
const LENGTHS: [f64; 7] = [-2.0, -1.0, -0.5, 0.0, 0.5, 1.0, 2.0];

/// The whole grid of starts is searched up to this many (4⁸: an 8-link
/// chain).
pub const GRID_STARTS: usize = 65_536;

/// Beyond [`GRID_STARTS`], this many starts are sampled from the grid, so
/// that the search costs the same at any number of degrees of freedom.
pub const SAMPLED_STARTS: usize = 4_096;

/// The starts of a search, and the grid they come from.
#[derive(Clone, Debug)]
pub struct Starts {
    pub points: Vec<Vec<f64>>,
    pub search: Search,
}

/// How much of the grid of starts a search covered.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Search {
    /// Starts searched from.
    pub starts: usize,
    /// Points of the whole grid (its size in `f64`, which 12 values per
    /// coordinate overflow in `usize` beyond 17 coordinates).
    pub grid: f64,
}

impl Search {
    /// Whether the starts were a sample of the grid: equilibria may have
    /// been missed.
    pub fn sampled(&self) -> bool {
        (self.starts as f64) < self.grid
    }
}

impl std::fmt::Display for Search {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.sampled() {
            write!(
                f,
                "{} starts sampled from a grid of {:.3e} (every angle at 0 and −π among them): equilibria elsewhere may be missed",
                self.starts, self.grid
            )
        } else {
            write!(f, "the whole grid of {} starts", self.starts)
        }
    }
}

/// The grid of starts. Up to 3 degrees of freedom, 12 values per
/// coordinate: angles at −π + 2πk/12, others at −2 + 4k/12 (0 and −π among
/// them, where symmetric models have their equilibria; a vibrated triple
/// pendulum has over a hundred). Beyond, each angle at the multiples of
/// 2π/4 and each other coordinate at `LENGTHS`. A grid larger than
/// [`GRID_STARTS`] is sampled (`sample`).
pub fn starts(periodic: &[bool]) -> Starts {
    let axis: Vec<Vec<f64>> = periodic
        .iter()
        .map(|&p| match (periodic.len() <= 3, p) {
            (true, true) => (0..12)
                .map(|k| -PI + 2.0 * PI * (k as f64 / 12.0))
                .collect(),
            (true, false) => (0..12).map(|k| -2.0 + 4.0 * (k as f64 / 12.0)).collect(),
            (false, true) => (0..4)
                .map(|k| wrap_angle(2.0 * PI * k as f64 / 4.0))
                .collect(),
            (false, false) => LENGTHS.to_vec(),
        })
        .collect();
    let grid: f64 = axis.iter().map(|a| a.len() as f64).product();
    let points: Vec<Vec<f64>> = if grid <= GRID_STARTS as f64 {
        let total = grid as usize;
        (0..total)
            .map(|mut k| {
                axis.iter()
                    .map(|values| {
                        let x = values[k % values.len()];
                        k /= values.len();
                        x
                    })
                    .collect()
            })
            .collect()
    } else {
        sample(&axis, periodic, SAMPLED_STARTS)
    };
    Starts {
        search: Search {
            starts: points.len(),
            grid,
        },
        points,
    }
}

/// `count` starts from the grid `axis`, the same on every run: half of them
/// with every angle at 0 or −π and every other coordinate at 0 (all such
/// corners where they are fewer, else all angles at 0, all at −π and a
/// sample: the equilibria of chains and other symmetric models), the rest
/// anywhere on the grid.
fn sample(axis: &[Vec<f64>], periodic: &[bool], count: usize) -> Vec<Vec<f64>> {
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    let mut next = move || {
        // SplitMix64.
        state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    };
    let angles = periodic.iter().filter(|p| **p).count();
    let corner = |bits: u64| -> Vec<f64> {
        let mut k = 0;
        periodic
            .iter()
            .map(|&p| {
                if !p {
                    return 0.0;
                }
                let up = bits >> k & 1 == 0;
                k += 1;
                if up {
                    0.0
                } else {
                    -PI
                }
            })
            .collect()
    };
    let corners = 1_u64.checked_shl(angles as u32).unwrap_or(u64::MAX);
    let mut points: Vec<Vec<f64>> = if corners <= (count / 2) as u64 {
        (0..corners).map(corner).collect()
    } else {
        // Every angle at 0 and every one at −π first.
        let mut some = vec![corner(0), corner(u64::MAX)];
        some.extend((2..count / 2).map(|_| corner(next())));
        some
    };
    while points.len() < count {
        let point = axis
            .iter()
            .map(|values| values[(next() % values.len() as u64) as usize])
            .collect();
        points.push(point);
    }
    points
}

/// When Newton's iterate is a root.
#[derive(Clone, Copy, Debug)]
pub enum Convergence {
    /// An exact gradient: the step falls below 10⁻¹³ of q's size within 60
    /// iterations, where the gradient is below 10⁻⁹ of the Hessian's scale.
    Exact,
    /// A gradient with a noise floor (differences): the iterate after at
    /// most 50 steps (fewer once a step is below 10⁻¹², or where the
    /// Hessian is singular) whose gradient's norm is at most `gradient`,
    /// its last step below 10⁻⁶ of q's size (not one walking off to where
    /// the potential flattens, as k/(1 + x²) at x ~ 10⁶).
    Noisy { gradient: f64 },
}

/// Newton's method for gradient(q) = 0 from `q`; None unless it converges.
/// With an exact gradient, a Hessian singular along a cyclic coordinate (a
/// pole, a family of equilibria) gets the least-squares step, in the other
/// directions.
pub fn newton(
    gradient: impl Fn(&[f64]) -> Vec<f64>,
    hessian: impl Fn(&[f64]) -> DMatrix<f64>,
    mut q: Vec<f64>,
    convergence: Convergence,
) -> Option<Vec<f64>> {
    let norm = |g: &[f64]| g.iter().map(|x| x * x).sum::<f64>().sqrt();
    let iterations = match convergence {
        Convergence::Exact => 60,
        Convergence::Noisy { .. } => 50,
    };
    let mut settled = false;
    for _ in 0..iterations {
        let g = gradient(&q);
        // At an equilibrium already (a start on a degenerate one, whose
        // Hessian cannot be solved with). A gradient of differences takes
        // its step from there as from anywhere.
        if matches!(convergence, Convergence::Exact) && g.iter().all(|x| *x == 0.0) {
            return Some(q);
        }
        let h = hessian(&q);
        let g = DVector::from_column_slice(&g);
        let step = match (h.clone().lu().solve(&g), convergence) {
            (Some(step), _) => step,
            (None, Convergence::Exact) => h.svd(true, true).solve(&g, 1e-12).ok()?,
            // Where the Hessian of differences is singular, the iterate
            // stands and is judged by its gradient.
            (None, Convergence::Noisy { .. }) => {
                settled = true;
                break;
            }
        };
        for (x, s) in q.iter_mut().zip(step.iter()) {
            *x -= s;
        }
        if !q.iter().all(|x| x.is_finite()) {
            return None;
        }
        match convergence {
            Convergence::Exact => {
                let size = 1.0 + q.iter().map(|x| x.abs()).fold(0.0, f64::max);
                if step.norm() < 1e-13 * size {
                    let g = gradient(&q);
                    let scale = 1.0 + hessian(&q).amax();
                    let largest = g.iter().map(|x| x.abs()).fold(0.0, f64::max);
                    return (largest < 1e-9 * scale).then_some(q);
                }
            }
            Convergence::Noisy { .. } => {
                let size = 1.0 + q.iter().map(|x| x.abs()).fold(0.0, f64::max);
                settled = step.norm() < 1e-6 * size;
                if step.norm() < 1e-12 {
                    break;
                }
            }
        }
    }
    match convergence {
        Convergence::Exact => None,
        Convergence::Noisy {
            gradient: tolerance,
        } => (settled && norm(&gradient(&q)) <= tolerance).then_some(q),
    }
}

/// `q` with its angles (flagged in `periodic`) in [−π, π).
pub fn wrapped(mut q: Vec<f64>, periodic: &[bool]) -> Vec<f64> {
    for (x, p) in q.iter_mut().zip(periodic) {
        if *p {
            *x = wrap_angle(*x);
        }
    }
    q
}

/// An equilibrium of the effective potential (V + V_vibr, or V).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Equilibrium {
    pub q: Vec<f64>,
    /// Eigenvalues of the Hessian, ascending: of the reduced system where
    /// the equilibrium is one of a family along cyclic coordinates.
    pub hessian_eigenvalues: Vec<f64>,
    pub verdict: Verdict,
    /// The cyclic coordinates (indices) along which this equilibrium is one
    /// of a family: reported once, judged on the system reduced by them
    /// (Routh's reduction with their conserved momenta at 0, where the
    /// amended potential is V itself).
    pub family_along: Vec<usize>,
    /// The mass matrix is singular here only along cyclic coordinates (the
    /// pole of spherical coordinates, where the azimuth degenerates): the
    /// chart is singular, but the reduced system is regular and judges it.
    pub pole: bool,
}

/// What the second-order test of the effective potential says of an
/// equilibrium. An eigenvalue within round-off of zero (10⁻⁸ of the
/// largest) decides nothing: a degenerate minimum such as x⁴, or a family
/// of equilibria along a cyclic coordinate, is never called unstable.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// A strict minimum: every eigenvalue positive.
    Stable,
    /// A direction of negative curvature.
    Unstable,
    /// No negative eigenvalue, but one within round-off of zero.
    InconclusiveAtSecondOrder,
    /// The mass matrix is singular there (a pole of polar or spherical
    /// coordinates): the chart cannot judge it; other coordinates can.
    SingularChart,
}

impl Verdict {
    /// The verdict of a Hessian with these eigenvalues.
    pub fn of(eigenvalues: &[f64]) -> Verdict {
        let scale = eigenvalues.iter().fold(1.0f64, |m, l| m.max(l.abs()));
        let round_off = 1e-8 * scale;
        if eigenvalues.iter().any(|&l| l < -round_off) {
            Verdict::Unstable
        } else if eigenvalues.iter().all(|&l| l > round_off) {
            Verdict::Stable
        } else {
            Verdict::InconclusiveAtSecondOrder
        }
    }
}

impl std::fmt::Display for Verdict {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Verdict::Stable => "stable",
            Verdict::Unstable => "unstable",
            Verdict::InconclusiveAtSecondOrder => "inconclusive at second order",
            Verdict::SingularChart => {
                "singular chart (the mass matrix is singular here: judge it in other coordinates)"
            }
        })
    }
}

/// Whether V has one value, no slope and no curvature at every point (to
/// 10⁻¹² of its size): then every configuration is an equilibrium, and a
/// search would list its starts.
fn is_flat(
    points: &[Vec<f64>],
    v: &dyn Fn(&[f64]) -> f64,
    gradient: &dyn Fn(&[f64]) -> Vec<f64>,
    hessian: &dyn Fn(&[f64]) -> nalgebra::DMatrix<f64>,
) -> bool {
    let Some(first) = points.first() else {
        return false;
    };
    let v0 = v(first);
    let small = 1e-12 * (1.0 + v0.abs());
    points.iter().all(|q| {
        (v(q) - v0).abs() <= small
            && gradient(q).iter().all(|g| g.abs() <= small)
            && hessian(q).amax() <= small
    })
}

/// Why no equilibria were searched for.
#[derive(Clone, Debug, PartialEq, serde::Serialize, thiserror::Error)]
pub enum NotSearched {
    #[error("the model has no effective potential (a contact model)")]
    NoPotential,
    /// A constrained model: its equilibria lie on the constraints.
    #[error("the model is constrained: its equilibria lie on the constraints, where no effective potential is searched yet")]
    OnConstraints,
    /// The effective potential is the same, with no slope and no
    /// curvature, at every start (a free body; a vibration whose force is
    /// O(1) at frequency 1/ε, whose effect is below first-order averaging).
    #[error("the effective potential is flat (the same value, no slope and no curvature at every start): every configuration is an equilibrium, neutral at this order")]
    Flat,
}

/// Equilibria of the effective potential: this finder (the starts and
/// steps `stability` uses)
/// on its gradient by central differences with the generated Hessian, at
/// any number of degrees of freedom; duplicates (angles modulo 2π, and
/// along cyclic coordinates) merged.
pub fn effective_equilibria(
    model: &dyn DynamicModel,
    params: &[f64],
) -> Result<(Vec<Equilibrium>, Search), NotSearched> {
    let periodic = model.periodic();
    let n = periodic.len();
    if model.effective_potential(params, &vec![0.0; n]).is_none() {
        return Err(NotSearched::NoPotential);
    }
    let v = |q: &[f64]| model.effective_potential(params, q).unwrap_or(f64::NAN);
    // At the angles wrapped into [−π, π): Newton may wander many turns
    // away, where a step of 10⁻⁶·|q| is no longer small and the
    // differences of a periodic V vanish by aliasing (the triple
    // pendulum's search reported 123 points with |∇V| ≈ 1 as equilibria).
    let gradient = |q: &[f64]| -> Vec<f64> {
        let q = wrapped(q.to_vec(), &periodic);
        (0..n)
            .map(|i| {
                let h = 1e-6 * (1.0 + q[i].abs());
                let (mut a, mut b) = (q.to_vec(), q.to_vec());
                a[i] += h;
                b[i] -= h;
                (v(&a) - v(&b)) / (2.0 * h)
            })
            .collect()
    };
    let cyclic = cyclic_coordinates(model, params, n);
    let kept: Vec<usize> = (0..n).filter(|i| !cyclic.contains(i)).collect();
    let hessian = |q: &[f64]| {
        let h = model
            .effective_potential_hessian(params, q)
            .unwrap_or_else(|| vec![f64::NAN; n * n]);
        nalgebra::DMatrix::from_row_slice(n, n, &h)
    };
    let starts = starts(&periodic);
    if is_flat(&starts.points, &v, &gradient, &hessian) {
        return Err(NotSearched::Flat);
    }
    let mut found: Vec<Equilibrium> = Vec::new();
    for start in starts.points {
        // The differences' noise floor: a root is where the gradient is
        // below 10⁻⁷.
        let convergence = Convergence::Noisy { gradient: 1e-7 };
        let Some(q) = newton(gradient, hessian, start, convergence) else {
            continue;
        };
        let mut q = wrapped(q, &periodic);
        let hm = hessian(&q);
        let sym = (&hm + hm.transpose()) * 0.5;
        // The reduced system's Hessian: the rows and columns of the cyclic
        // coordinates dropped.
        let reduced =
            nalgebra::DMatrix::from_fn(kept.len(), kept.len(), |a, b| sym[(kept[a], kept[b])]);
        let mut eigenvalues: Vec<f64> = reduced.symmetric_eigenvalues().iter().copied().collect();
        eigenvalues.sort_by(f64::total_cmp);
        // At the singular point itself the Hamiltonian's 1/sin²θ terms make
        // every curvature 0·∞; a step of 10⁻⁶ off it along the kept
        // coordinates tells which momenta the singularity is along.
        let singular = !singular_momenta(model, params, &q).is_empty();
        let near: Vec<f64> = (0..n)
            .map(|i| q[i] + if cyclic.contains(&i) { 0.0 } else { 1e-6 })
            .collect();
        let along = singular_momenta(model, params, &near);
        let pole = singular && !along.is_empty() && along.iter().all(|i| cyclic.contains(i));
        let verdict = if !singular || pole {
            Verdict::of(&eigenvalues)
        } else {
            Verdict::SingularChart
        };
        // Newton converges only linearly on a degenerate equilibrium (x⁴
        // gives the gradient x³) and the gradient's differences have a noise
        // floor, so its starts end up to 10⁻³ apart: one equilibrium, kept
        // where the gradient is least.
        let radius = match verdict {
            Verdict::InconclusiveAtSecondOrder => 1e-3,
            _ => 1e-6,
        };
        let norm = |q: &[f64]| gradient(q).iter().map(|x| x * x).sum::<f64>().sqrt();
        let same = found.iter().position(|e| {
            let along = |i: &usize| !cyclic.contains(i);
            e.q.iter()
                .zip(&q)
                .zip(&periodic)
                .enumerate()
                .filter(|(i, _)| along(i))
                .all(|(_, ((a, b), p))| {
                    let d = if *p { wrap_angle(a - b) } else { a - b };
                    d.abs() < radius * (1.0 + b.abs())
                })
        });
        // A family's representative: its cyclic coordinates at 0.
        for &i in &cyclic {
            q[i] = 0.0;
        }
        let equilibrium = Equilibrium {
            q,
            verdict,
            hessian_eigenvalues: eigenvalues,
            family_along: cyclic.clone(),
            pole,
        };
        match same {
            Some(k) if norm(&equilibrium.q) < norm(&found[k].q) => found[k] = equilibrium,
            Some(_) => {}
            None => found.push(equilibrium),
        }
    }
    Ok((found, starts.search))
}

/// The cyclic coordinates: H does not depend on them (probed at scattered
/// states and times), so their momenta are conserved and equilibria come
/// in families along them.
pub(crate) fn cyclic_coordinates(model: &dyn DynamicModel, params: &[f64], n: usize) -> Vec<usize> {
    let probes: Vec<(f64, Vec<f64>)> = (0..8)
        .map(|k| {
            let y = (0..2 * n)
                .map(|i| (1.7 * (k * 2 * n + i) as f64 + 0.3).sin() * 1.3)
                .collect();
            (0.37 * k as f64, y)
        })
        .collect();
    (0..n)
        .filter(|&i| {
            probes.iter().all(|(t, y)| {
                let h = 1e-5;
                let (mut a, mut b) = (y.clone(), y.clone());
                a[i] += h;
                b[i] -= h;
                let slope =
                    (model.energy(params, *t, &a) - model.energy(params, *t, &b)) / (2.0 * h);
                slope.abs() < 1e-8
            })
        })
        .collect()
}

/// The momenta along which the mass matrix A is singular at q: H is
/// ½ pᵀA⁻¹p + …, so the curvature of H along each momentum, read from
/// three energies, is A⁻¹'s diagonal, which blows up where A is singular.
pub(crate) fn singular_momenta(model: &dyn DynamicModel, params: &[f64], q: &[f64]) -> Vec<usize> {
    let n = q.len();
    let energy = |p: &[f64]| {
        let mut y = q.to_vec();
        y.extend_from_slice(p);
        model.energy(params, 0.0, &y)
    };
    let zero = energy(&vec![0.0; n]);
    (0..n)
        .filter(|&i| {
            let mut p = vec![0.0; n];
            p[i] = 1.0;
            let plus = energy(&p);
            p[i] = -1.0;
            let curvature = 0.5 * (plus + energy(&p)) - zero;
            !(curvature.is_finite() && curvature.abs() < 1e10)
        })
        .collect()
}
