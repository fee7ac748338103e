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

use super::{check_finite, Observer, OdeError, Stats, Step, StepControl, System};

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
struct Radau5Step<const N: usize> {
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

/// Integrates from t0 to t1, starting with (and leaving in) the control's step size.
pub(super) fn integrate<S: System<N>, const N: usize>(
    control: &mut StepControl,
    system: &S,
    t0: f64,
    y0: &[f64; N],
    t1: f64,
    stats: &mut Stats,
    observe: Observer<'_, N>,
) -> Result<(f64, [f64; N]), OdeError> {
    // RADAU5's tolerance transformation: the estimate is O(h⁴) while the local
    // error is O(h⁶), so tol → 0.1 tol^(2/3) makes the global error track tol.
    let rtol = 0.1 * control.rtol.powf(2.0 / 3.0);
    let atol = rtol * control.atol / control.rtol;
    let newton_tol = (10.0 * f64::EPSILON / rtol).max(0.03f64.min(rtol.sqrt()));
    let gamma0 = 30.0 / (6.0 + 81f64.cbrt() - 9f64.cbrt());
    let n3 = 3 * N;
    let mut newton = vec![0.0; n3 * n3];
    let mut newton_pivots = vec![0usize; n3];
    let mut filter = vec![0.0; N * N];
    let mut filter_pivots = vec![0usize; N];
    let mut rhs = vec![0.0; n3];

    let direction = (t1 - t0).signum();
    let span = (t1 - t0).abs();
    let mut t = t0;
    let mut y = *y0;
    let mut h = control.next_step.unwrap_or(1e-6 * span.max(1e-3)).min(span);
    let mut first = true;
    let mut rejected = false;
    let mut steps = 0u64;
    loop {
        if steps >= control.max_steps {
            return Err(OdeError::TooManySteps {
                t,
                max_steps: control.max_steps,
            });
        }
        let f0 = system.rhs(t, &y);
        stats.f_evals += 1;
        let jac = match system.jacobian(t, &y) {
            Some(j) => j,
            None => {
                // Forward differences, as RADAU5 does without an analytic Jacobian.
                let mut j = [[0.0; N]; N];
                for col in 0..N {
                    let delta = (f64::EPSILON * y[col].abs().max(1e-5)).sqrt();
                    let mut yd = y;
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
        let scale: [f64; N] = std::array::from_fn(|i| atol + rtol * y[i].abs());
        // Attempt steps from (t, y) until one is accepted.
        loop {
            steps += 1;
            let remaining = (t1 - t).abs();
            let last = h >= remaining * (1.0 - 1e-12);
            let h_try = if last { remaining } else { h };
            if h_try < 1e-14 * t.abs().max(1.0) {
                return Err(OdeError::StepSizeUnderflow { t, h: h_try });
            }
            let hs = direction * h_try;
            // Newton matrix I − h (A ⊗ J).
            for i in 0..3 {
                for a in 0..N {
                    for j in 0..3 {
                        for b in 0..N {
                            let identity = if i == j && a == b { 1.0 } else { 0.0 };
                            newton[(i * N + a) * n3 + j * N + b] =
                                identity - hs * A[i][j] * jac[a][b];
                        }
                    }
                }
            }
            if !lu_factor(&mut newton, n3, &mut newton_pivots) {
                return Err(OdeError::NoConvergence {
                    t,
                    h: hs,
                    y: y.to_vec(),
                });
            }
            // Simplified Newton iteration for the stage increments Z.
            let mut z = [[0.0; N]; 3];
            let mut previous_norm = 0.0f64;
            let mut contraction = 1.0f64;
            let mut converged = false;
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
                        rhs[i * N + k] = -z[i][k] + hs * acc;
                    }
                }
                lu_solve(&newton, n3, &newton_pivots, &mut rhs);
                let mut norm = 0.0;
                for i in 0..3 {
                    for k in 0..N {
                        z[i][k] += rhs[i * N + k];
                        norm += (rhs[i * N + k] / scale[k]).powi(2);
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
                if contraction * norm <= newton_tol {
                    converged = true;
                    break;
                }
                previous_norm = norm.max(f64::MIN_POSITIVE);
            }
            if !converged {
                stats.rejected += 1;
                rejected = true;
                h = 0.5 * h_try;
                continue;
            }
            let y_new: [f64; N] = std::array::from_fn(|k| y[k] + z[2][k]);
            // Error estimate (γ₀/h − J)⁻¹ (f(t, y) + Σ dᵢ Zᵢ / h).
            for a in 0..N {
                for b in 0..N {
                    filter[a * N + b] = if a == b { gamma0 / hs } else { 0.0 } - jac[a][b];
                }
            }
            if !lu_factor(&mut filter, N, &mut filter_pivots) {
                return Err(OdeError::NoConvergence {
                    t,
                    h: hs,
                    y: y.to_vec(),
                });
            }
            let f2: [f64; N] =
                std::array::from_fn(|k| (0..3).map(|i| DD[i] * z[i][k]).sum::<f64>() / hs);
            let error_norm = |e: &[f64]| -> f64 {
                let sum: f64 = (0..N).map(|k| (e[k] / scale[k]).powi(2)).sum();
                (sum / N as f64).sqrt().max(1e-10)
            };
            let mut e: [f64; N] = std::array::from_fn(|k| f0[k] + f2[k]);
            lu_solve(&filter, N, &filter_pivots, &mut e);
            let mut err = error_norm(&e);
            if err >= 1.0 && (first || rejected) {
                let shifted: [f64; N] = std::array::from_fn(|k| y[k] + e[k]);
                let f1 = system.rhs(t, &shifted);
                stats.f_evals += 1;
                for k in 0..N {
                    e[k] = f1[k] + f2[k];
                }
                lu_solve(&filter, N, &filter_pivots, &mut e);
                err = error_norm(&e);
            }
            if !err.is_finite() {
                stats.rejected += 1;
                rejected = true;
                h = 0.1 * h_try;
                continue;
            }
            let safety = 0.9 * (2 * MAX_NEWTON + 1) as f64 / (2 * MAX_NEWTON + iterations) as f64;
            let quotient = (err.powf(0.25) / safety).clamp(1.0 / 8.0, 5.0);
            let mut h_new = h_try / quotient;
            if err < 1.0 {
                check_finite(t + hs, &y_new)?;
                let t_new = if last { t1 } else { t + hs };
                stats.steps += 1;
                if rejected {
                    h_new = h_new.min(h_try);
                }
                first = false;
                rejected = false;
                let mut view = Radau5Step {
                    t0: t,
                    y0: y,
                    h: hs,
                    t1: t_new,
                    y1: y_new,
                    z,
                };
                let flow = observe(&mut view)?;
                t = t_new;
                y = y_new;
                if let Some(end) = control.end_of_run(flow, last, (t, y), h, h_try, h_new) {
                    return Ok(end);
                }
                h = h_new;
                break;
            }
            stats.rejected += 1;
            h = if first { 0.1 * h_try } else { h_new };
            rejected = true;
        }
    }
}
