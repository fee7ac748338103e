//! Scene `double_pendulum_friction` (deliverable 2.5): Theorem 3 of the
//! averaging method with viscous friction Q1 = −μ φ1', Q2 = −μ(φ2' − φ1').
//!
//! Above a*, the stabilised equilibrium of the limiting system becomes
//! asymptotically stable: the eigenvalues of its linearisation (from the
//! generated averaged Jacobian) have negative real parts. The figure shows a
//! perturbation decaying in both systems, and the exact system's Floquet
//! multipliers inside the unit circle for several large ν: its spectral
//! radius against ν, beside exp(max Re λ · 2π/ν) that the averaged
//! eigenvalues predict.
//!
//! Its settings are declared in `mechlab_studies`.

fn main() {
    mechlab::scene::run(mechlab::scenes::study_scene::<mechlab_studies::DoublePendulumFriction>);
}
