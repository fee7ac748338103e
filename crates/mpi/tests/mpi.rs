//! `mpirun -n 2` of the `chaos_map` scene (ranks taking tiles, the first
//! merging them) gives the single process's map bit for bit. Needs OpenMPI;
//! `cargo test --release -p mechlab-mpi` builds the example it runs
//! (docs/sweeps.md, "On a cluster").

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

#[test]
fn two_ranks_give_the_single_process_map() {
    let root = tempfile::tempdir().unwrap();
    let (single, ranks) = (root.path().join("single"), root.path().join("ranks"));
    let knobs = [
        "--set",
        "pixels=40",
        "--set",
        "periods=60",
        "--set",
        "tile_rows=3",
    ];
    let status = Command::new(example("chaos_map_mpi"))
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
        .arg(example("chaos_map_mpi"))
        .args(knobs)
        .arg("--out")
        .arg(&ranks)
        .status()
        .expect("mpirun (OpenMPI) is installed");
    assert!(status.success());
    let csv = |dir: &PathBuf| std::fs::read(dir.join("chaos_map.csv")).unwrap();
    assert_eq!(csv(&single), csv(&ranks), "the maps differ");
    let tiles = std::fs::read_dir(ranks.with_extension("tiles"))
        .unwrap()
        .next()
        .unwrap()
        .unwrap()
        .path();
    assert_eq!(
        std::fs::read_dir(tiles).unwrap().count(),
        14,
        "40 rows in tiles of 3"
    );
}
