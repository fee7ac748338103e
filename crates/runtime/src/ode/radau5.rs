//! Radau IIA of order 5 for stiff systems, after Hairer & Wanner's RADAU5
//! (Solving ODE II, §IV.8): three collocation stages, L-stable, solved by a
//! simplified Newton iteration with the Jacobian at the step start, and the
//! same embedded error estimate (filtered through (γ₀/h − J)⁻¹, so that it
//! stays bounded on stiff components) and step-size rules.
//!
//! The Newton system couples the three stages, a dense 3N × 3N matrix here:
//! for the small systems of mechlab that is cheaper than RADAU5's complex
//! transformation and needs no constants beyond the Butcher tableau. Its
//! buffer is allocated once per call, not per step.

use super::driver::{Attempt, Schedule, Stepper};
use super::{OdeError, Stats, Step, System, Tolerances};

const SQ6: f64 = 2.449489742783178;
const C: [f64; 3] = [(4.0 - SQ6) / 10.0, (4.0 + SQ6) / 10.0, 1.0];
const A: [[f64; 3]; 3] = [
    [
        (88.0 - 7.0 * SQ6) / 360.0,
        (296.0 - 169.0 * SQ6) / 1800.0,
        (-2.0 + 3.0 * SQ6) / 225.0,
    ],
    [
        (296.0 + 169.0 * SQ6) / 1800.0,
        (88.0 + 7.0 * SQ6) / 360.0,
        (-2.0 - 3.0 * SQ6) / 225.0,
    ],
    [(16.0 - SQ6) / 36.0, (16.0 + SQ6) / 36.0, 1.0 / 9.0],
];
/// Weights of the embedded error estimate (RADAU5's DD1..DD3).
const DD: [f64; 3] = [
    -(13.0 + 7.0 * SQ6) / 3.0,
    (-13.0 + 7.0 * SQ6) / 3.0,
    -1.0 / 3.0,
];
const MAX_NEWTON: usize = 7;

/// LU factorisation with partial pivoting of an n × n row-major matrix, in place.
fn lu_factor(a: &mut [f64], n: usize, pivots: &mut [usize]) -> bool {
    for k in 0..n {
        let p = (k..n)
            .max_by(|&i, &j| a[i * n + k].abs().total_cmp(&a[j * n + k].abs()))
            .unwrap();
        pivots[k] = p;
        if a[p * n + k] == 0.0 || !a[p * n + k].is_finite() {
            return false;
        }
        if p != k {
            for j in 0..n {
                a.swap(k * n + j, p * n + j);
            }
        }
        let pivot = a[k * n + k];
        for i in k + 1..n {
            let factor = a[i * n + k] / pivot;
            a[i * n + k] = factor;
            for j in k + 1..n {
                a[i * n + j] -= factor * a[k * n + j];
            }
        }
    }
    true
}

/// Solves with the factors of [`lu_factor`] (whole rows were swapped, so all
/// row exchanges are applied to b before the forward substitution).
fn lu_solve(a: &[f64], n: usize, pivots: &[usize], b: &mut [f64]) {
    for (k, &p) in pivots.iter().enumerate().take(n) {
        b.swap(k, p);
    }
    for k in 0..n {
        for i in k + 1..n {
            b[i] -= a[i * n + k] * b[k];
        }
    }
    for k in (0..n).rev() {
        for j in k + 1..n {
            b[k] -= a[k * n + j] * b[j];
        }
        b[k] /= a[k * n + k];
    }
}

/// An accepted step; inside it, the collocation polynomial through
/// (0, y₀), (cᵢ, y₀ + Zᵢ).
pub(super) struct Radau5Step<const N: usize> {
    t0: f64,
    y0: [f64; N],
    h: f64,
    t1: f64,
    y1: [f64; N],
    z: [[f64; N]; 3],
}

impl<const N: usize> Step<N> for Radau5Step<N> {
    fn start(&self) -> (f64, &[f64; N]) {
        (self.t0, &self.y0)
    }
    fn end(&self) -> (f64, &[f64; N]) {
        (self.t1, &self.y1)
    }
    fn state_at(&mut self, t: f64) -> Result<[f64; N], OdeError> {
        let s = (t - self.t0) / self.h;
        // Lagrange basis on the nodes 0, c1, c2, c3, for the nodes cᵢ.
        let weights: [f64; 3] = std::array::from_fn(|i| {
            let mut w = s / C[i];
            for (j, cj) in C.iter().enumerate() {
                if j != i {
                    w *= (s - cj) / (C[i] - cj);
                }
            }
            w
        });
        Ok(std::array::from_fn(|k| {
            self.y0[k] + (0..3).map(|i| weights[i] * self.z[i][k]).sum::<f64>()
        }))
    }
}

/// The method's state: the transformed tolerances, the Newton and
/// error-filter matrices (allocated once per run), and what is known at the
/// current point: f, the Jacobian and the error scale, computed once for all
/// the attempts from it.
pub(super) struct Radau5<const N: usize> {
    rtol: f64,
    atol: f64,
    newton_tol: f64,
    newton: Vec<f64>,
    newton_pivots: Vec<usize>,
    filter: Vec<f64>,
    filter_pivots: Vec<usize>,
    rhs: Vec<f64>,
    /// (t, y) is a new point: f0, the Jacobian and the scale are due.
    fresh: bool,
    f0: [f64; N],
    jac: [[f64; N]; N],
    scale: [f64; N],
    /// No step accepted yet in this run.
    first: bool,
    /// The last attempt was rejected.
    rejected: bool,
    /// The stage increments of the last accepted step (its dense output).
    z: [[f64; N]; 3],
}

impl<const N: usize> Radau5<N> {
    pub fn new(tolerances: Tolerances) -> Radau5<N> {
        // RADAU5's tolerance transformation: the estimate is O(h⁴) while the local
        // error is O(h⁶), so tol → 0.1 tol^(2/3) makes the global error track tol.
        let rtol = 0.1 * tolerances.rtol.powf(2.0 / 3.0);
        let atol = rtol * tolerances.atol / tolerances.rtol;
        let n3 = 3 * N;
        Radau5 {
            rtol,
            atol,
            newton_tol: (10.0 * f64::EPSILON / rtol).max(0.03f64.min(rtol.sqrt())),
            newton: vec![0.0; n3 * n3],
            newton_pivots: vec![0; n3],
            filter: vec![0.0; N * N],
            filter_pivots: vec![0; N],
            rhs: vec![0.0; n3],
            fresh: true,
            f0: [0.0; N],
            jac: [[0.0; N]; N],
            scale: [0.0; N],
            first: true,
            rejected: false,
            z: [[0.0; N]; 3],
        }
    }

    /// f, the Jacobian (the system's, or forward differences as RADAU5
    /// takes without one) and the error scale at a new point.
    fn at_point<S: System<N>>(&mut self, system: &S, t: f64, y: &[f64; N], stats: &mut Stats) {
        let f0 = system.rhs(t, y);
        stats.f_evals += 1;
        self.jac = match system.jacobian(t, y) {
            Some(j) => j,
            None => {
                let mut j = [[0.0; N]; N];
                for col in 0..N {
                    let delta = (f64::EPSILON * y[col].abs().max(1e-5)).sqrt();
                    let mut yd = *y;
                    yd[col] += delta;
                    let fd = system.rhs(t, &yd);
                    for row in 0..N {
                        j[row][col] = (fd[row] - f0[row]) / delta;
                    }
                }
                stats.f_evals += N as u64;
                j
            }
        };
        stats.jac_evals += 1;
        self.f0 = f0;
        self.scale = std::array::from_fn(|i| self.atol + self.rtol * y[i].abs());
        self.fresh = false;
    }

    /// The stage increments Z of a step of size hs by the simplified Newton
    /// iteration, with the number of iterations; `None` when it does not
    /// converge (the step is retried smaller), an error when the Newton
    /// matrix is singular.
    fn solve_stages<S: System<N>>(
        &mut self,
        system: &S,
        t: f64,
        y: &[f64; N],
        hs: f64,
        stats: &mut Stats,
    ) -> Result<Option<([[f64; N]; 3], usize)>, OdeError> {
        let n3 = 3 * N;
        // Newton matrix I − h (A ⊗ J).
        for i in 0..3 {
            for a in 0..N {
                for j in 0..3 {
                    for b in 0..N {
                        let identity = if i == j && a == b { 1.0 } else { 0.0 };
                        self.newton[(i * N + a) * n3 + j * N + b] =
                            identity - hs * A[i][j] * self.jac[a][b];
                    }
                }
            }
        }
        if !lu_factor(&mut self.newton, n3, &mut self.newton_pivots) {
            return Err(OdeError::NoConvergence {
                t,
                h: hs,
                y: y.to_vec(),
            });
        }
        let mut z = [[0.0; N]; 3];
        let mut previous_norm = 0.0f64;
        let mut contraction = 1.0f64;
        let mut iterations = 0;
        while iterations < MAX_NEWTON {
            iterations += 1;
            stats.iterations += 1;
            let f: [[f64; N]; 3] = std::array::from_fn(|i| {
                system.rhs(t + C[i] * hs, &std::array::from_fn(|k| y[k] + z[i][k]))
            });
            stats.f_evals += 3;
            for i in 0..3 {
                for k in 0..N {
                    let mut acc = 0.0;
                    for j in 0..3 {
                        acc += A[i][j] * f[j][k];
                    }
                    self.rhs[i * N + k] = -z[i][k] + hs * acc;
                }
            }
            lu_solve(&self.newton, n3, &self.newton_pivots, &mut self.rhs);
            let mut norm = 0.0;
            for i in 0..3 {
                for k in 0..N {
                    z[i][k] += self.rhs[i * N + k];
                    norm += (self.rhs[i * N + k] / self.scale[k]).powi(2);
                }
            }
            let norm = (norm / n3 as f64).sqrt();
            if !norm.is_finite() {
                break;
            }
            if iterations > 1 {
                let theta = norm / previous_norm;
                if theta >= 0.99 {
                    break;
                }
                contraction = theta / (1.0 - theta);
            }
            if contraction * norm <= self.newton_tol {
                return Ok(Some((z, iterations)));
            }
            previous_norm = norm.max(f64::MIN_POSITIVE);
        }
        Ok(None)
    }

    /// The error estimate (γ₀/h − J)⁻¹ (f(t, y) + Σ dᵢ Zᵢ / h), filtered once
    /// more through f at the shifted point after a first step or a
    /// rejection, as RADAU5 does.
    fn error<S: System<N>>(
        &mut self,
        system: &S,
        t: f64,
        y: &[f64; N],
        hs: f64,
        z: &[[f64; N]; 3],
        stats: &mut Stats,
    ) -> Result<f64, OdeError> {
        let gamma0 = 30.0 / (6.0 + 81f64.cbrt() - 9f64.cbrt());
        for a in 0..N {
            for b in 0..N {
                self.filter[a * N + b] = if a == b { gamma0 / hs } else { 0.0 } - self.jac[a][b];
            }
        }
        if !lu_factor(&mut self.filter, N, &mut self.filter_pivots) {
            return Err(OdeError::NoConvergence {
                t,
                h: hs,
                y: y.to_vec(),
            });
        }
        let f2: [f64; N] =
            std::array::from_fn(|k| (0..3).map(|i| DD[i] * z[i][k]).sum::<f64>() / hs);
        let scale = self.scale;
        let error_norm = |e: &[f64]| -> f64 {
            let sum: f64 = (0..N).map(|k| (e[k] / scale[k]).powi(2)).sum();
            (sum / N as f64).sqrt().max(1e-10)
        };
        let mut e: [f64; N] = std::array::from_fn(|k| self.f0[k] + f2[k]);
        lu_solve(&self.filter, N, &self.filter_pivots, &mut e);
        let mut err = error_norm(&e);
        if err >= 1.0 && (self.first || self.rejected) {
            let shifted: [f64; N] = std::array::from_fn(|k| y[k] + e[k]);
            let f1 = system.rhs(t, &shifted);
            stats.f_evals += 1;
            for k in 0..N {
                e[k] = f1[k] + f2[k];
            }
            lu_solve(&self.filter, N, &self.filter_pivots, &mut e);
            err = error_norm(&e);
        }
        Ok(err)
    }
}

impl<S: System<N>, const N: usize> Stepper<S, N> for Radau5<N> {
    type Accepted<'a>
        = Radau5Step<N>
    where
        S: 'a;

    fn schedule(&self) -> Schedule {
        Schedule::Adaptive {
            snap: 1e-12,
            compensated: false,
            underflow: 1e-14,
        }
    }

    fn begin(
        &mut self,
        _system: &S,
        t0: f64,
        _y0: &[f64; N],
        t1: f64,
        carried: Option<f64>,
        _stats: &mut Stats,
    ) -> Result<f64, OdeError> {
        (self.fresh, self.first, self.rejected) = (true, true, false);
        Ok(carried.unwrap_or(1e-6 * (t1 - t0).abs().max(1e-3)))
    }

    fn attempt(
        &mut self,
        system: &S,
        t: f64,
        y: &[f64; N],
        hs: f64,
        _t_end: f64,
        stats: &mut Stats,
    ) -> Result<Attempt<N>, OdeError> {
        if self.fresh {
            self.at_point(system, t, y, stats);
        }
        let h_try = hs.abs();
        let Some((z, iterations)) = self.solve_stages(system, t, y, hs, stats)? else {
            self.rejected = true;
            return Ok(Attempt::Rejected { retry: 0.5 * h_try });
        };
        let err = self.error(system, t, y, hs, &z, stats)?;
        if !err.is_finite() {
            self.rejected = true;
            return Ok(Attempt::Rejected { retry: 0.1 * h_try });
        }
        let safety = 0.9 * (2 * MAX_NEWTON + 1) as f64 / (2 * MAX_NEWTON + iterations) as f64;
        let quotient = (err.powf(0.25) / safety).clamp(1.0 / 8.0, 5.0);
        let h_new = h_try / quotient;
        if err >= 1.0 {
            let retry = if self.first { 0.1 * h_try } else { h_new };
            self.rejected = true;
            return Ok(Attempt::Rejected { retry });
        }
        (self.fresh, self.first, self.rejected) = (true, false, false);
        self.z = z;
        Ok(Attempt::Accepted {
            y: std::array::from_fn(|k| y[k] + z[2][k]),
            next: h_new,
        })
    }

    fn accepted<'a>(
        &'a mut self,
        _system: &'a S,
        (t0, y0): (f64, [f64; N]),
        (t1, y1): (f64, [f64; N]),
        h: f64,
        _stats: &'a mut Stats,
    ) -> Radau5Step<N> {
        Radau5Step {
            t0,
            y0,
            h,
            t1,
            y1,
            z: self.z,
        }
    }
}
