//! Scene `kapitza_stability` (deliverables 1.5, 1.6): is the upper position
//! q = 0 of the pendulum with a vibrating pivot stable?
//!
//! q = 0, p = 0 is a T-periodic solution of the exact system for every A.
//! Its stability follows from the Floquet multipliers of the period map's
//! linearisation (the monodromy matrix M); the critical amplitude A* is the
//! lower edge of the stable window (generic `stability` analysis), the
//! averaged system predicts A* = √2 (V = cos q + A²/4 sin²q has V''(0) =
//! A²/2 − 1). Also: orbits near q = 0 either side of A*, the averaged
//! portraits, the (ε, A) stability chart with its boundaries located by
//! bisection, and A*(ε) against √2.
//!
//! Its settings are declared in `mechlab_studies`.

fn main() {
    mechlab::scene::run(mechlab::scenes::study_scene::<mechlab_studies::KapitzaStability>);
}
