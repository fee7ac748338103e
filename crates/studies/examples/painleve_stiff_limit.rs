//! Scene `painleve_stiff_limit`: the worked example as the rod stiffens,
//! ε = 0.1, 0.03, 0.01, 0.001.
//!
//! Both cases start from the same rod force R(0) as the worked example (the
//! deformation scaled as δ(0) ∝ ε², so that the reduced deformation equation
//! sees the same start): in the regular case R(t) settles to the rigid rod's
//! R* within a time O(ε); in the impact case the stop, the reversal and the
//! final stop happen ever more abruptly. The stiff rod needs the stiff
//! method: Radau IIA 5 between switches. Reported per run: the event times,
//! wall time and steps.
//!
//! Its settings are declared in `mechlab_studies`.

fn main() {
    mechlab::scene::run(mechlab::scenes::study_scene::<mechlab_studies::PainleveStiffLimit>);
}
