//! Scene `painleve_klein_impact` (deliverables 3.5, 3.6 and the worked
//! example): the Painlevé–Klein rod with exact stick–slip switching.
//!
//! For each initial x2(0) (x1 = 0, x1' = x2' = 10): the full dynamics of the
//! two points on rough guides joined by the visco-elastic rod, integrated by
//! the switching integrator of `mechlab::contact` on the generated contact
//! model. Each case gets a row of panels: the phase curve on (δ, δ'), R(t),
//! v1(t) and v2(t), with the switching events marked; the table of events
//! (time, point, case of the scheme, v1, v2, R) and the final state (rest,
//! or sliding with constant acceleration) go to `summary.json` and
//! `events.csv`. x2(0) = −0.65 starts inside the basin of the stable
//! equilibrium of the deformation equation, −0.78 outside it.
//!
//! Its settings are declared in `mechlab_studies`.

fn main() {
    mechlab::scene::run(mechlab::scenes::study_scene::<mechlab_studies::PainleveKleinImpact>);
}
