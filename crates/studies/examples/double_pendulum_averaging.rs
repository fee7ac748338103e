//! Scene `double_pendulum_averaging` (deliverable 2.2): Theorem 2 of the
//! averaging method on the double pendulum with a vibrating base.
//!
//! For every amplitude a and every initial state (a grid of cases), the exact
//! system at large ν and the limiting (averaged) system start from the same
//! (q, p); the figure shows φ1, φ2 of both against t, the deviations
//! |exact − limit| (of order 1/ν), and both systems' generalised velocities,
//! which differ by O(1) at the fast time scale: the velocities converge only
//! weakly, not uniformly.
//!
//! Its settings are declared in `mechlab_studies`.

fn main() {
    mechlab::scene::run(mechlab::scenes::study_scene::<mechlab_studies::DoublePendulumAveraging>);
}
