//! Scene `averaging`: Theorem 2 on any model with a fast phase, by name. The
//! exact and the averaged system run from the same state [q; p] for each
//! value of the parameter that sets the phase's frequency ν; the figure
//! shows each coordinate's largest deviation over [0, t_obs] against ν on
//! log axes with the fitted line (slope −1 where the theorem holds), and
//! ν × deviation levelling off.
//!
//! `cargo run --release --example averaging -- --set model=triple_pendulum`

fn main() {
    mechlab::scene::run(|| {
        mechlab::scenes::averaging_scene(mechlab::models::MODELS, "averaging", &[])
    });
}
