//! The first-order averaged motion on fixed holonomic constraints, as an
//! ODE on [q; q'].
//!
//! For fixed constraints and a mass matrix the vibration does not move,
//! the averaged motion is that of the Lagrangian ½ q'ᵀM q' − W(q) on the
//! same constraints, W = V̄ + V_vibr (see `analysis::on_constraints::
//! vibration`). Its free force is the mean over the phase of the exact
//! free force at (q, q') (the vibration's coupling b has zero mean, and
//! so has its time derivative) less ∇V_vibr, V_vibr = ½ mean⟨P b̃, b̃⟩:
//! the means are quadratures over 32 phases, ∇V_vibr central differences.

use super::{dot, solve_constrained, OnConstraints};
use crate::linalg::Cholesky;
use crate::ode::System;

/// Phases of the quadratures over θ.
const NODES: usize = 32;

/// The averaged motion of a model's forms (with `period` the fast phase's).
#[derive(Clone, Debug)]
pub struct AveragedOnConstraints<const N: usize, const K: usize, const S: usize> {
    pub exact: OnConstraints<N, K, S>,
    pub period: f64,
}

impl<const N: usize, const K: usize, const S: usize> AveragedOnConstraints<N, K, S> {
    fn phase_time(&self, j: usize) -> f64 {
        self.period * j as f64 / NODES as f64
    }

    /// V_vibr(q) = ½ mean⟨P b̃, b̃⟩, P the inverse mass matrix projected on
    /// the constraints (at t = 0: they do not move).
    pub fn vibrational_potential(&self, q: &[f64; N]) -> f64 {
        self.phase_means(q).vibrational
    }

    /// At q: the means over the phase of V and b, and V_vibr.
    pub fn phase_means(&self, q: &[f64; N]) -> PhaseMeans {
        let forms = &self.exact.0;
        let mass = Cholesky::new(forms.mass_matrix(0.0, q));
        let g = forms.constraint_jacobian(0.0, q);
        let m_inv_gt: [[f64; N]; K] = std::array::from_fn(|r| mass.solve(g[r]));
        let schur: [[f64; K]; K] =
            std::array::from_fn(|a| std::array::from_fn(|c| dot(&g[a], &m_inv_gt[c])));
        let schur = Cholesky::semidefinite(schur);
        let mut potential = 0.0;
        let couplings: Vec<[f64; N]> = (0..NODES)
            .map(|j| {
                potential += forms.potential(self.phase_time(j), q) / NODES as f64;
                forms.linear_term(self.phase_time(j), q)
            })
            .collect();
        let mean: [f64; N] =
            std::array::from_fn(|i| couplings.iter().map(|b| b[i]).sum::<f64>() / NODES as f64);
        let mut sum = 0.0;
        for b in &couplings {
            let b: [f64; N] = std::array::from_fn(|i| b[i] - mean[i]);
            let m_inv_b = mass.solve(b);
            let g_m_inv_b: [f64; K] = std::array::from_fn(|r| dot(&g[r], &m_inv_b));
            let mu = schur.solve(g_m_inv_b);
            let p_b: [f64; N] = std::array::from_fn(|i| {
                m_inv_b[i] - (0..K).map(|r| m_inv_gt[r][i] * mu[r]).sum::<f64>()
            });
            sum += dot(&p_b, &b);
        }
        PhaseMeans {
            potential,
            coupling: mean.to_vec(),
            vibrational: 0.5 * sum / NODES as f64,
        }
    }
}

/// The means over the fast phase at a configuration: of V, of the
/// vibration's coupling b (zero where the averaging applies), and the
/// vibrational potential ½ mean⟨P b̃, b̃⟩.
#[derive(Clone, Debug, PartialEq)]
pub struct PhaseMeans {
    pub potential: f64,
    pub coupling: Vec<f64>,
    pub vibrational: f64,
}

impl<const N: usize, const K: usize, const S: usize> System<S> for AveragedOnConstraints<N, K, S> {
    fn rhs(&self, _t: f64, y: &[f64; S]) -> [f64; S] {
        let forms = &self.exact.0;
        let (q, v) = OnConstraints::<N, K, S>::split(y);
        let mut free = [0.0; N];
        for j in 0..NODES {
            let f = forms.free_forces(self.phase_time(j), &q, &v);
            for i in 0..N {
                free[i] += f[i] / NODES as f64;
            }
        }
        for i in 0..N {
            let h = 1e-6 * (1.0 + q[i].abs());
            let (mut plus, mut minus) = (q, q);
            plus[i] += h;
            minus[i] -= h;
            free[i] -= (self.vibrational_potential(&plus) - self.vibrational_potential(&minus))
                / (2.0 * h);
        }
        let (accelerations, _) = solve_constrained(
            forms.mass_matrix(0.0, &q),
            forms.constraint_jacobian(0.0, &q),
            free,
            forms.constraint_bias(0.0, &q, &v),
        );
        std::array::from_fn(|i| {
            if i < N {
                y[N + i]
            } else {
                accelerations[i - N]
            }
        })
    }
}
