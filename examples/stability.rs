//! Scene `stability`: stabilisation by vibration for any model with a fast
//! phase, by name. For every equilibrium of the system without vibration
//! that stays one of the averaged system: the roots λ of det(C − λA) = 0,
//! the threshold a* of the amplitude from V + V_vibr = C + a²K (or why there
//! is none), and the exact system's stability window from its Floquet
//! multipliers, drawn as the spectral radius against the amplitude. With
//! `--set chart=x,y`, the stability chart of one equilibrium in two
//! parameters, its boundaries located by bisection. A constrained model
//! is stabilised on its constraints, as the scene `linkage` does (its
//! settings then).
//!
//! `cargo run --release --example stability -- --set model=triple_pendulum`
//! `cargo run --release --example stability -- --set chart=eps,A --set chart_y_max=12`

fn main() {
    mechlab::scene::run(|| mechlab::scenes::stability_scene(mechlab::models::MODELS));
}
