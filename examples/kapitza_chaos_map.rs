//! Scene `kapitza_chaos_map` (Study 1): the chaos map of the Kapitza period
//! map, every pixel (q, p) shaded by the fast Lyapunov indicator of its
//! orbit (dark = chaotic, light = regular). A preset of the generic
//! `chaos_map` scene: Kapitza at A = 1, ε = 0.1, Taylor at 1e-6.

fn main() {
    mechlab::scene::run(|| {
        mechlab::scenes::chaos_map_scene(
            mechlab::models::MODELS,
            "kapitza_chaos_map",
            &[("model", "kapitza"), ("A", "1")],
            None,
        )
    });
}
