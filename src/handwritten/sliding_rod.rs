//! The deformable Painlevé–Klein rod of Study 3 (docs/studies.md, Study 3) in its sliding
//! phase: both points move right (σ₁ = σ₂ = +1), no switching. State
//! (x₁, x₂, x₁', x₂'). The rod is a visco-elastic element with reaction
//! R = k δ/ε² + ν δ'/ε, which makes the system stiff as ε → 0 (eigenvalues of
//! order 1/ε). Hand-written until `models/painleve_klein.toml` exists
//! (Study 3 brings Coulomb contacts to the model format).

use crate::ode::System;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlidingRod {
    pub d: f64,
    pub l: f64,
    pub x1_force: f64,
    pub y1_force: f64,
    pub mu1: f64,
    pub x2_force: f64,
    pub y2_force: f64,
    pub mu2: f64,
    pub k: f64,
    pub nu: f64,
    pub eps: f64,
}

impl SlidingRod {
    /// The worked example of Study 3 (docs/studies.md) at the given ε.
    pub fn worked_example(eps: f64) -> SlidingRod {
        SlidingRod {
            d: 0.8,
            l: 1.0,
            x1_force: 3.6,
            y1_force: 0.8,
            mu1: 0.525,
            x2_force: 0.0,
            y2_force: -2.4,
            mu2: 2.85,
            k: 1.0,
            nu: 1.0,
            eps,
        }
    }

    /// Deformation δ, its rate δ', and the rod reaction R.
    pub fn deformation(&self, y: &[f64; 4]) -> (f64, f64, f64) {
        let dx = y[0] - y[1];
        let length = dx.hypot(self.d);
        let delta = length - self.l;
        let delta_rate = (y[2] - y[3]) * dx / length;
        let r = self.k * delta / (self.eps * self.eps) + self.nu * delta_rate / self.eps;
        (delta, delta_rate, r)
    }

    /// A state with both points at speed `v` and deformation δ; x₁ = 0.
    pub fn state_with_deformation(&self, delta: f64, v: f64) -> [f64; 4] {
        let dx = ((self.l + delta).powi(2) - self.d * self.d).sqrt();
        [0.0, -dx, v, v]
    }
}

impl System<4> for SlidingRod {
    fn rhs(&self, _t: f64, y: &[f64; 4]) -> [f64; 4] {
        let dx = y[0] - y[1];
        let length = dx.hypot(self.d);
        let (cos_phi, sin_phi) = (dx / length, self.d / length);
        let (_, _, r) = self.deformation(y);
        let n1 = r * sin_phi - self.y1_force;
        let n2 = -self.y2_force - r * sin_phi;
        [
            y[2],
            y[3],
            self.x1_force - r * cos_phi - self.mu1 * n1.abs(),
            self.x2_force + r * cos_phi - self.mu2 * n2.abs(),
        ]
    }
}
