//! Scene `kapitza_period_map` (deliverables 1.2–1.4): orbits of the period map
//! of the pendulum with a vibrating pivot on the unrolled cylinder
//! (q mod 2π, p). Without q0/p0 it draws the portraits of three presets
//! (A = 0: the ordinary pendulum; small A: chaos near the separatrices;
//! larger A: a wide chaotic sea) or of the given A; with q0 and p0 it
//! computes one orbit and reports its final state and cost.
//!
//! Its settings are declared in `mechlab_studies`.

fn main() {
    mechlab::scene::run(mechlab::scenes::study_scene::<mechlab_studies::KapitzaPeriodMap>);
}
