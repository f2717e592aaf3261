//! A tile's storage: its nodes, cut mask and height bound, shared copy on
//! write, and a run of writes along one of its rows (`lower_run`).

use super::*;

#[derive(Debug, Clone, PartialEq)]
pub(super) struct TileData {
    pub(super) z: [f64; TILE_NODES],
    /// One bit per node: set once a cut or a chip has lowered it (loading a
    /// surface does not). The contact reads it to tell the blurred edge of a
    /// groove from the face it was cut from.
    pub(super) cut: [u64; MASK_WORDS],
    /// Whether the tile's height bound may be stale, and where it was found.
    pub(super) marks: BoundMarks,
}

/// What [`HeightMap::refresh_bounds`] keeps of a tile: whether a write
/// lowered a node at its height bound since the bound was last found (it
/// may lie above every node now), and the row of nodes it was found in
/// (read first the next time: a row of rock the cuts have not reached yet
/// usually holds it still). Bookkeeping, not the tile's content: tiles
/// compare equal whatever their marks. (Kept with the nodes, not in the
/// directory, whose slots stay two words.)
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct BoundMarks {
    pub(super) stale: bool,
    pub(super) hint: u8,
}

impl PartialEq for BoundMarks {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

// (a row of a tile lies inside one mask word: `TileData::cell_mask`)
const _: () = assert!(64 % TILE == 0);

impl TileData {
    /// The cut bits of the cell whose first node is `k` (not on the tile's
    /// last row or column), as [`HeightMap::cell_cut`] orders them: a row of
    /// the tile lies inside one mask word, so each pair of nodes along x is
    /// one shift.
    #[inline(always)]
    pub(super) fn cell_mask(&self, k: usize) -> u32 {
        let pair = |k: usize| (self.cut[k / 64] >> (k % 64) & 3) as u32;
        pair(k) | pair(k + TILE) << 2
    }
}

#[derive(Debug, Clone)]
pub(super) struct Tile {
    pub(super) d: Arc<TileData>,
    /// An upper bound of the heights in the tile: raised on writes that
    /// raise, and found again ([`HeightMap::refresh_bounds`]) once a write
    /// has lowered a node that stood at it ([`BoundMarks`]).
    pub(super) z_max: f64,
}

impl Tile {
    /// The tile in `slot` for writing, allocated (flat at `z0`) if absent;
    /// and whether it was.
    pub(super) fn for_writing(slot: &mut Option<Tile>, z0: f64) -> (&mut Tile, bool) {
        let allocated = slot.is_none();
        let tile = slot.get_or_insert_with(|| Tile {
            d: Arc::new(TileData {
                z: [z0; TILE_NODES],
                cut: [0; MASK_WORDS],
                marks: BoundMarks::default(),
            }),
            z_max: z0,
        });
        (tile, allocated)
    }

    /// Sets node `k` to `z` (copy on write: a tile shared with a snapshot
    /// is copied here, once).
    pub(super) fn set(&mut self, k: usize, z: f64) {
        store(Arc::make_mut(&mut self.d), &mut self.z_max, k, z);
    }

    /// Lowers node `k` to `z` and marks it cut (copy on write, as `set`).
    pub(super) fn lower(&mut self, k: usize, z: f64) {
        lower_in(Arc::make_mut(&mut self.d), &mut self.z_max, k, z);
    }
}

/// Writes node `k` of a tile's nodes `d` whose height bound is `z_max`:
/// the bound rises with the node, and a node lowered from the bound marks
/// it stale ([`BoundMarks`]).
#[inline]
pub(super) fn store(d: &mut TileData, z_max: &mut f64, k: usize, z: f64) {
    d.marks.stale |= z < d.z[k] && d.z[k] >= *z_max;
    d.z[k] = z;
    if z > *z_max {
        *z_max = z;
    }
}

/// [`store`], and marks the node cut.
#[inline]
pub(super) fn lower_in(d: &mut TileData, z_max: &mut f64, k: usize, z: f64) {
    store(d, z_max, k, z);
    d.cut[k / 64] |= 1u64 << (k % 64);
}

/// The highest of the tile's heights `z` on the map's grid (its first
/// `cols` nodes of its first `rows` rows: an edge tile's other nodes lie
/// off the grid) and the row it stands in, or `bound` as soon as a row
/// reaches it (nothing stands higher than the bound); row `hint` first,
/// then a row at a time, each in four lanes (the compiler keeps them in
/// vector registers).
pub(super) fn tile_max(
    z: &[f64; TILE_NODES],
    bound: f64,
    hint: usize,
    rows: usize,
    cols: usize,
) -> (f64, usize) {
    let row_max = |r: usize| {
        let quads = z[r * TILE..r * TILE + cols].chunks_exact(4);
        let rest = quads.remainder();
        let mut lanes = [NO_ROCK; 4];
        for q in quads {
            for (l, &v) in lanes.iter_mut().zip(q) {
                *l = if v > *l { v } else { *l };
            }
        }
        lanes
            .into_iter()
            .chain(rest.iter().copied())
            .fold(NO_ROCK, |m, l| if l > m { l } else { m })
    };
    let hint = hint.min(rows - 1);
    let (mut m, mut at) = (row_max(hint), hint);
    if m >= bound {
        return (bound, hint);
    }
    for r in (0..rows).filter(|&r| r != hint) {
        let v = row_max(r);
        if v > m {
            (m, at) = (v, r);
            if m >= bound {
                return (bound, r);
            }
        }
    }
    (m, at)
}

/// Nodes `i0..=i1` of a row as runs inside one tile each: `(first, count)`.
pub(super) fn tile_runs(i0: usize, i1: usize) -> impl Iterator<Item = (usize, usize)> {
    let mut i = i0;
    std::iter::from_fn(move || {
        (i <= i1).then(|| {
            let last = ((i / TILE + 1) * TILE - 1).min(i1);
            let run = (i, last - i + 1);
            i = last + 1;
            run
        })
    })
}

/// A directory slot that [`lower_run`] reads until its first write and
/// only then takes for writing (a map's shared row is unshared then, not
/// by a run that writes nothing).
pub(super) trait Slot<'a> {
    fn read(&self) -> &Option<Tile>;
    fn write(self) -> &'a mut Option<Tile>;
}

/// A slot of a patch (its rows are the map's own already).
impl<'a> Slot<'a> for &'a mut Option<Tile> {
    fn read(&self) -> &Option<Tile> {
        self
    }
    fn write(self) -> &'a mut Option<Tile> {
        self
    }
}

/// A slot of a map's row of tiles, which may be shared with a snapshot.
pub(super) struct RowSlot<'a> {
    pub(super) row: &'a mut Arc<[Option<Tile>]>,
    pub(super) ti: usize,
}

impl<'a> Slot<'a> for RowSlot<'a> {
    fn read(&self) -> &Option<Tile> {
        &self.row[self.ti]
    }
    fn write(self) -> &'a mut Option<Tile> {
        &mut Arc::make_mut(self.row)[self.ti]
    }
}

/// Runs `f(z)` over nodes `k0, k0 + 1, ..` (`n` of them) of the tile in
/// `slot`, in order; where it returns a height the node is lowered to it and
/// marked cut. Until the first write the tile is only read (an untouched one
/// reads `z0`); at the first write it is allocated or unshared once, and
/// `log(k, z, cut_word, z_max)` hears what each write overwrites. Returns
/// whether the run made the tile's bound stale (lowered a node at it).
pub(super) fn lower_run<'a>(
    slot: impl Slot<'a>,
    z0: f64,
    k0: usize,
    n: usize,
    f: &mut impl FnMut(f64) -> Option<f64>,
    mut log: impl FnMut(usize, f64, u64, f64),
    on_alloc: impl FnOnce(),
) -> bool {
    let mut k = k0;
    let end = k0 + n;
    let first = {
        // the tile's heights, looked up once for the read-only stretch
        let heights = slot.read().as_ref().map(|t| &t.d.z);
        loop {
            if k == end {
                return false;
            }
            let z = heights.map_or(z0, |h| h[k]);
            k += 1;
            if let Some(nz) = f(z) {
                break nz;
            }
        }
    };
    let (tile, allocated) = Tile::for_writing(slot.write(), z0);
    if allocated {
        on_alloc();
    }
    let Tile { d, z_max } = tile;
    let d = Arc::make_mut(d);
    let was_stale = d.marks.stale;
    let mut write = |d: &mut TileData, k: usize, nz: f64| {
        log(k, d.z[k], d.cut[k / 64], *z_max);
        lower_in(d, z_max, k, nz);
    };
    write(d, k - 1, first);
    while k < end {
        if let Some(nz) = f(d.z[k]) {
            write(d, k, nz);
        }
        k += 1;
    }
    d.marks.stale && !was_stale
}

/// Tiles are equal when their heights, cut masks and height bounds are
/// (the bound travels with a state's bytes: a state read back equals the
/// one it was written from, and replays as it does).
impl PartialEq for Tile {
    fn eq(&self, other: &Self) -> bool {
        self.z_max == other.z_max && (Arc::ptr_eq(&self.d, &other.d) || self.d == other.d)
    }
}
