//! Scene `basins` across the ranks of `mpirun` (the same knobs, files and
//! numbers as `examples/basins.rs`; one process without `mpirun`).
//!
//! `cargo build --release -p mechlab-mpi --example basins_mpi`
//! `mpirun -n 4 target/release/examples/basins_mpi --set tile_rows=16`

fn main() {
    mechlab::scene::run(|| {
        let ranks = mechlab_mpi::Ranks::start();
        let sharing = ranks
            .as_ref()
            .map(|r| r as &dyn mechlab::scenes::TileSharing);
        mechlab::scenes::basins_scene(mechlab::models::MODELS, sharing)
    });
}
