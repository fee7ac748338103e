//! Sweeps cut into tiles: each tile is written to its own file when done,
//! a rerun computes only the missing ones, and the merged tiles equal a
//! single run bit for bit (the chaos maps' rows, the stability charts'
//! columns; job arrays and MPI ranks take tiles by index).

/// A sweep cut into deterministic tiles of `rows` rows each (the last may
/// be shorter; a row is a chaos map's row of pixels, a stability chart's
/// column), written as `<folder>/<fingerprint>/tile_<k>.bin` when done
/// (the fingerprint hashes the model, parameters and settings, so another
/// sweep never mixes in). A run loads the tiles present and computes the
/// others, so an interrupted run resumes; every row is computed from
/// scratch, so the merged sweep equals a single run's bit for bit.
#[derive(Clone, Debug)]
pub struct Tiles {
    pub folder: std::path::PathBuf,
    pub rows: usize,
    /// Compute only these tiles and stop before merging (a job of a job
    /// array, an MPI rank): None computes every missing tile and merges.
    pub only: Option<Vec<usize>>,
}

/// Why a tile cannot be read or written.
#[derive(Debug, thiserror::Error)]
pub enum TileError {
    #[error("{}: {source}", path.display())]
    Io {
        path: std::path::PathBuf,
        source: std::io::Error,
    },
    #[error("{}: a tile of another sweep (settings, model or parameters differ): remove the folder or choose another", path.display())]
    OtherSweep { path: std::path::PathBuf },
    #[error("{}: not a complete tile file", path.display())]
    Truncated { path: std::path::PathBuf },
    #[error("tile {tile} does not exist: the sweep has {count} tiles")]
    NoSuchTile { tile: usize, count: usize },
}

const TILE_MAGIC: &[u8; 16] = b"mechlab-tile-v1\n";

/// A tile on disk: magic, the sweep's fingerprint, its f-evaluations, then
/// its FLI values as little-endian f64 (exact, infinities included).
fn write_tile(
    path: &std::path::Path,
    fingerprint: u64,
    f_evals: u64,
    values: &[f64],
) -> Result<(), TileError> {
    let io = |source| TileError::Io {
        path: path.to_path_buf(),
        source,
    };
    let mut bytes = Vec::with_capacity(32 + 8 * values.len());
    bytes.extend_from_slice(TILE_MAGIC);
    bytes.extend_from_slice(&fingerprint.to_le_bytes());
    bytes.extend_from_slice(&f_evals.to_le_bytes());
    for v in values {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    // Unique per process: two runs of one sweep at once (two jobs given the
    // same tile) each write whole files, and the last rename wins.
    let partial = path.with_extension(format!("partial.{}", std::process::id()));
    std::fs::write(&partial, &bytes).map_err(io)?;
    std::fs::rename(&partial, path).map_err(io)
}

/// The tile at `path` if it exists: (f-evaluations, values).
fn read_tile(
    path: &std::path::Path,
    fingerprint: u64,
    count: usize,
) -> Result<Option<(u64, Vec<f64>)>, TileError> {
    let bytes = match std::fs::read(path) {
        Ok(bytes) => bytes,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(source) => {
            return Err(TileError::Io {
                path: path.to_path_buf(),
                source,
            })
        }
    };
    let word =
        |k: usize| u64::from_le_bytes(bytes[16 + 8 * k..24 + 8 * k].try_into().expect("8 bytes"));
    if bytes.len() != 32 + 8 * count || &bytes[..16] != TILE_MAGIC {
        return Err(TileError::Truncated {
            path: path.to_path_buf(),
        });
    }
    if word(0) != fingerprint {
        return Err(TileError::OtherSweep {
            path: path.to_path_buf(),
        });
    }
    let values = (0..count).map(|k| f64::from_bits(word(2 + k))).collect();
    Ok(Some((word(1), values)))
}

/// FNV-1a of the text: a fingerprint stable across runs and platforms.
pub(crate) fn fingerprint(text: &str) -> u64 {
    text.bytes().fold(0xcbf29ce484222325, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x100000001b3)
    })
}

/// Computes the missing tiles (or only `tiles.only`) of a sweep of
/// `row_count` rows of `row_len` values each (`rows_of` computes a range of
/// rows: their values and f-evaluations), then merges every tile into the
/// sweep's values and f-evaluations; None if only some tiles were asked for.
/// `unit` names a row in the progress lines ("rows", "columns").
pub(crate) fn run_tiles<E: From<TileError>>(
    tiles: &Tiles,
    fingerprint: u64,
    (row_count, row_len, unit): (usize, usize, &str),
    rows_of: &dyn Fn(std::ops::Range<usize>) -> Result<(Vec<f64>, u64), E>,
) -> Result<Option<(Vec<f64>, u64)>, E> {
    let rows = tiles.rows.max(1);
    let count = row_count.div_ceil(rows);
    let span = |k: usize| k * rows..((k + 1) * rows).min(row_count);
    let folder = tiles.folder.join(format!("{fingerprint:016x}"));
    let path = |k: usize| folder.join(format!("tile_{k}.bin"));
    std::fs::create_dir_all(&folder).map_err(|source| {
        E::from(TileError::Io {
            path: folder.clone(),
            source,
        })
    })?;
    let wanted: Vec<usize> = match &tiles.only {
        Some(only) => {
            if let Some(&tile) = only.iter().find(|&&k| k >= count) {
                return Err(TileError::NoSuchTile { tile, count }.into());
            }
            only.clone()
        }
        None => (0..count).collect(),
    };
    let mut merged = vec![None; count];
    for k in wanted.iter().copied() {
        let size = span(k).len() * row_len;
        let tile = match read_tile(&path(k), fingerprint, size).map_err(E::from)? {
            Some(tile) => tile,
            None => {
                let (values, evals) = rows_of(span(k))?;
                write_tile(&path(k), fingerprint, evals, &values).map_err(E::from)?;
                eprintln!("tile {}/{count} done ({} {unit})", k + 1, span(k).len());
                (evals, values)
            }
        };
        merged[k] = Some(tile);
    }
    if tiles.only.is_some() {
        return Ok(None);
    }
    let (mut values, mut f_evals) = (Vec::with_capacity(row_count * row_len), 0);
    for tile in merged.into_iter().flatten() {
        f_evals += tile.0;
        values.extend(tile.1);
    }
    Ok(Some((values, f_evals)))
}
