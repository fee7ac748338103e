//! Integrators over fixed-size states.

/// An ODE y' = f(t, y) on a fixed-size state, optionally with its Jacobian.
pub trait System<const N: usize> {
    fn rhs(&self, t: f64, y: &[f64; N]) -> [f64; N];
    /// ∂f/∂y, when the system knows it (generated models do).
    fn jacobian(&self, _t: f64, _y: &[f64; N]) -> Option<[[f64; N]; N]> {
        None
    }
}
