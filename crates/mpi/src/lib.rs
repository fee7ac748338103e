//! Tiled sweeps (chaos maps, basins) across the ranks of `mpirun`: each
//! rank computes the tiles k with k mod size = rank; after a barrier the
//! first merges them (all on disk by then) and writes the scene's files
//! while the others wait (they share its output folder). The results are
//! the single process's, bit for bit (tests/mpi.rs).

use mechlab::scene::SceneError;
use mechlab::scenes::TileSharing;
use mpi::traits::{Communicator, CommunicatorCollectives};

/// The ranks of `mpirun`.
pub struct Ranks {
    _universe: mpi::environment::Universe,
    world: mpi::topology::SimpleCommunicator,
}

impl Ranks {
    /// None for a single process (no `mpirun`, or one rank).
    pub fn start() -> Option<Ranks> {
        let universe = mpi::initialize()?;
        let world = universe.world();
        (world.size() >= 2).then_some(Ranks {
            _universe: universe,
            world,
        })
    }
}

impl TileSharing for Ranks {
    fn run(
        &self,
        count: usize,
        compute: &dyn Fn(Vec<usize>) -> Result<(), SceneError>,
        merge: &dyn Fn() -> Result<(), SceneError>,
    ) -> Result<(), SceneError> {
        let (rank, size) = (self.world.rank() as usize, self.world.size() as usize);
        let share: Vec<usize> = (0..count).filter(|k| k % size == rank).collect();
        eprintln!("rank {rank} of {size}: tiles {share:?}");
        let computed = compute(share);
        self.world.barrier();
        let written = match (rank, computed) {
            (0, Ok(())) => merge(),
            (_, computed) => computed,
        };
        self.world.barrier();
        written
    }
}
