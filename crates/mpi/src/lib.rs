//! A chaos map across the ranks of `mpirun`: each rank computes the tiles
//! k with k mod size = rank; after a barrier the first merges them (all on
//! disk by then) and writes the scene's files while the others wait (they
//! share its output folder). The maps are the single process's, bit for
//! bit (tests/mpi.rs).

use mechlab::analysis::chaos_map::{ChaosMap, ChaosMapError, ChaosMapSettings};
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
        settings: &ChaosMapSettings,
        map: &dyn Fn(&ChaosMapSettings) -> Result<ChaosMap, ChaosMapError>,
        write: &dyn Fn(&ChaosMap) -> Result<(), SceneError>,
    ) -> Result<(), SceneError> {
        let Some(tiles) = &settings.tiles else {
            return Err(SceneError::Inconsistent {
                knobs: "tile_rows",
                reason: "under mpirun the ranks share the map by tiles: set tile_rows > 0",
            });
        };
        let (rank, size) = (self.world.rank() as usize, self.world.size() as usize);
        let count = settings.pixels.div_ceil(tiles.rows.max(1));
        let share: Vec<usize> = (0..count).filter(|k| k % size == rank).collect();
        eprintln!("rank {rank} of {size}: tiles {share:?}");
        let mut mine = settings.clone();
        if let Some(tiles) = &mut mine.tiles {
            tiles.only = Some(share);
        }
        let computed = match map(&mine) {
            Err(ChaosMapError::Partial) | Ok(_) => Ok(()),
            Err(e) => Err(e),
        };
        self.world.barrier();
        let written = match (rank, computed) {
            (0, Ok(())) => {
                let mut all = settings.clone();
                if let Some(tiles) = &mut all.tiles {
                    tiles.only = None;
                }
                map(&all).map_err(SceneError::from).and_then(|m| write(&m))
            }
            (_, computed) => computed.map_err(SceneError::from),
        };
        self.world.barrier();
        written
    }
}
