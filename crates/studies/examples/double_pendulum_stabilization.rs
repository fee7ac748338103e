//! Scene `double_pendulum_stabilization` (deliverable 2.4): which equilibria
//! of the double pendulum does vertical vibration stabilise, and from which
//! amplitude on?
//!
//! For every equilibrium (φ1, φ2 ∈ {0, π}): the roots λ of det(C − λA) = 0
//! (from the generated mass matrix and potential Hessian), stability without
//! vibration, and for the unstable ones the threshold a* of the criterion
//! a² > g²/(mean(h²)|λ*|), as a closed formula and as a number. Then long
//! runs of the limiting system from a small neighbourhood slightly above a*
//! (stays near) and slightly below (leaves), and the exact system's
//! stability window in a at the given ν from its Floquet multipliers: its
//! lower edge is close to a*; its upper edge, where parametric resonance
//! destabilises the equilibrium again, the averaged system does not have.
//!
//! Its settings are declared in `mechlab_studies`.

fn main() {
    mechlab::scene::run(
        mechlab::scenes::study_scene::<mechlab_studies::DoublePendulumStabilization>,
    );
}
