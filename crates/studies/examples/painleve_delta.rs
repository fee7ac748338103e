//! Scene `painleve_delta` (deliverables 3.3, 3.4): the deformation equation
//! (25) of the sliding rod, δ'' = cos²φ0 (X* − Φ(R)), R = k ε⁻² δ + ν ε⁻¹ δ'.
//!
//! Its equilibria are δ* = ε² R*/k for every root R* of X* = Φ(R); the
//! eigenvalues of the linearisation solve λ² + c Φ' ν/ε λ + c Φ' k/ε² = 0
//! (c = cos²φ0): a saddle where Φ' < 0, a centre (ν = 0) or a stable focus
//! or node (ν > 0) where Φ' > 0. Phase portraits on (δ, δ') for an example
//! of each graph class of `painleve_phi`, first ν = 0 then ν ≠ 0, and for the
//! given parameters; equilibria marked (black: stable, red: unstable).
//!
//! Its settings are declared in `mechlab_studies`.

fn main() {
    mechlab::scene::run(mechlab::scenes::study_scene::<mechlab_studies::PainleveDelta>);
}
