//! Scene `double_pendulum_convergence` (Study 2, 2.3): the largest deviation
//! of φ₁, φ₂ between the exact system and the limiting one from the same
//! state, over t ∈ [0, 5], for 8 values of ν from 100 to 10⁴: slope −1, and
//! ν × deviation levels off. A preset of the generic `averaging` scene.

fn main() {
    mechlab::scene::run(|| {
        mechlab::scenes::averaging_scene(
            mechlab::models::MODELS,
            "double_pendulum_convergence",
            &[
                ("model", "double_pendulum"),
                ("values", "geometric:100,10000,8"),
                ("t_obs", "5"),
                ("y0", "0.2,-0.1,0,0"),
            ],
        )
    });
}
