//! `mpirun -n 2` of the `chaos_map` and `basins` scenes (ranks taking
//! tiles, the first merging them) gives the single process's results bit
//! for bit. Needs OpenMPI; `cargo test --release -p mechlab-mpi` builds
//! the examples it runs (docs/sweeps.md, "On a cluster").

use std::path::PathBuf;
use std::process::Command;

fn example(name: &str) -> PathBuf {
    // target/<profile>/deps/<test> → target/<profile>/examples/<name>
    let exe = std::env::current_exe().unwrap();
    exe.parent()
        .unwrap()
        .parent()
        .unwrap()
        .join("examples")
        .join(name)
}

/// Runs the scene `example` with `knobs` alone (tile_rows=0) and under
/// `mpirun -n 2`; returns both runs' `file` and the ranks' tile folder.
fn alone_and_by_two_ranks(
    example_name: &str,
    knobs: &[&str],
    file: &str,
) -> (Vec<u8>, Vec<u8>, usize) {
    let root = tempfile::tempdir().unwrap();
    let (single, ranks) = (root.path().join("single"), root.path().join("ranks"));
    let status = Command::new(example(example_name))
        .args(knobs)
        .args(["--set", "tile_rows=0", "--out"])
        .arg(&single)
        .status()
        .unwrap();
    assert!(status.success());
    let status = Command::new("mpirun")
        .args([
            "--allow-run-as-root",
            "--oversubscribe",
            "-n",
            "2",
            "-x",
            "RAYON_NUM_THREADS=1",
        ])
        .arg(example(example_name))
        .args(knobs)
        .arg("--out")
        .arg(&ranks)
        .status()
        .expect("mpirun (OpenMPI) is installed");
    assert!(status.success());
    let tiles = std::fs::read_dir(ranks.with_extension("tiles"))
        .unwrap()
        .next()
        .unwrap()
        .unwrap()
        .path();
    (
        std::fs::read(single.join(file)).unwrap(),
        std::fs::read(ranks.join(file)).unwrap(),
        std::fs::read_dir(tiles).unwrap().count(),
    )
}

#[test]
fn two_ranks_give_the_single_process_map() {
    let knobs = [
        "--set",
        "pixels=40",
        "--set",
        "periods=60",
        "--set",
        "tile_rows=3",
    ];
    let (single, ranks, tiles) = alone_and_by_two_ranks("chaos_map_mpi", &knobs, "chaos_map.csv");
    assert!(single == ranks, "the maps differ");
    assert_eq!(tiles, 14, "40 rows in tiles of 3");
}

/// The basins of Duffing's driven well by two ranks (scouts run by each,
/// the rows' tiles shared) equal the single process's, label for label.
#[test]
fn two_ranks_give_the_single_process_basins() {
    let knobs = [
        "--set",
        "pixels=48",
        "--set",
        "transient=60",
        "--set",
        "tile_rows=5",
    ];
    let (single, ranks, tiles) = alone_and_by_two_ranks("basins_mpi", &knobs, "basins.csv");
    assert!(single == ranks, "the basins differ");
    assert_eq!(tiles, 10, "48 rows in tiles of 5");
}
