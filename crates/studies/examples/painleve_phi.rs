//! Scene `painleve_phi` (deliverables 3.1, 3.2): the broken line
//! Φ(R) = 2R + σ(μ1*|R − Y1*| − μ2*|R + Y2*|) of the rigid Painlevé–Klein rod.
//!
//! Every qualitatively different graph (by the signs of its three slopes) is
//! drawn for an example, with the region of (μ1*, μ2*, Y1*, Y2*, σ) where
//! it occurs as inequalities (Δ = μ2* − μ1*, S = μ1* + μ2*, o = +1 if
//! Y1* < −Y2*) and as region plots in the (μ1*, μ2*) plane for σo = +1 and
//! σo = −1. For the given parameters, every root R* of X* = Φ(R) for σ = ±1
//! with its Painlevé case.
//!
//! Its settings are declared in `mechlab_studies`.

fn main() {
    mechlab::scene::run(mechlab::scenes::study_scene::<mechlab_studies::PainlevePhi>);
}
