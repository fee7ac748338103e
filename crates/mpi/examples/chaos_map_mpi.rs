//! Scene `chaos_map` across the ranks of `mpirun` (the same knobs, files
//! and numbers as `examples/chaos_map.rs`; one process without `mpirun`).
//!
//! `cargo build --release -p mechlab-mpi --example chaos_map_mpi`
//! `mpirun -n 4 target/release/examples/chaos_map_mpi --set tile_rows=10`

fn main() {
    mechlab::scene::run(|| {
        let ranks = mechlab_mpi::Ranks::start();
        let sharing = ranks
            .as_ref()
            .map(|r| r as &dyn mechlab::scenes::TileSharing);
        mechlab::scenes::chaos_map_scene(mechlab::models::MODELS, "chaos_map", &[], sharing)
    });
}
