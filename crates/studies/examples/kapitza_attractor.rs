//! Scene `kapitza_attractor` (deliverable 1.7): a strange attractor of the
//! dissipative period map of the pendulum with a vibrating pivot. With
//! friction μ > 0 the map contracts areas by exp(−μT) per period, so orbits
//! settle on an attractor; at the default parameters (found by a scan of
//! (ε, A, μ) for a positive largest Lyapunov exponent, see the README) it is
//! a folded, layered set like the Hénon attractor. Draws the attractor after
//! transients, a zoom on its layers, the box-counting plot, and reports the
//! Lyapunov exponents (their sum is −μT) and the box-counting dimension.
//!
//! Its settings are declared in `mechlab_studies`.

fn main() {
    mechlab::scene::run(mechlab::scenes::study_scene::<mechlab_studies::KapitzaAttractor>);
}
