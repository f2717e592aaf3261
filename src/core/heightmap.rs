//! The rock face: a rectangular height map (thesis ch. 5), each cell split
//! into two triangles along its (0,0)-(1,1) diagonal, heights and slopes
//! interpolated linearly inside a triangle (eqs 18-32).
//!
//! Storage follows what a scene touches, not the extent of the face: nodes
//! live in square tiles of [`TILE`] x [`TILE`] that are allocated on the first
//! write; an untouched tile reads as the flat initial face `z0`. The tile
//! directory is a dense vector of `Option<Tile>` (16 bytes a tile), so a
//! 10 m x 10 m face at 1 mm cells costs 1.6 MB before anything is cut.
//!
//! Tiles are shared copy-on-write (`Arc`), and so are the directory's rows
//! of tiles: cloning a map (an FMU-state snapshot) shares every row, one
//! reference count per row of tiles (313 for a 10 m face), not per tile
//! (a bored 9.72 m face has 72 thousand tiles, whose counts cost 3 ms a
//! get + set of the state). The first write to a shared row copies that
//! row's directory (16 bytes a tile, sharing its tiles), the first write to
//! a shared tile that tile. A host that saves the state before every step
//! therefore pays for the rows and tiles the step cuts, not for the face.
//!
//! Cuts walk the map a row at a time ([`HeightMap::lower_row`]): a tile is
//! looked up and unshared once per run of a row inside it. Cuts far apart
//! can run at once on [`Patch`]es, disjoint rectangles of tiles peeled off
//! the directory as plain `&mut` slices ([`HeightMap::patches`]; no undo
//! record may be open).
//!
//! A step's undo record ([`HeightMap::begin_undo`]) logs each node write with
//! what it overwrote, and the tiles the step allocated: rolling back costs
//! what the step wrote, never the directory, and keeping a step costs no tile
//! copies (a record that held the tiles themselves made every step copy each
//! tile it cut, a quarter of a straight cut's time).

use std::sync::Arc;

/// Nodes along each side of a tile.
pub const TILE: usize = 32;
const TILE_NODES: usize = TILE * TILE;

/// Height returned outside the map: there is no rock there.
pub const NO_ROCK: f64 = f64::NEG_INFINITY;

/// Words of a tile's cut mask.
const MASK_WORDS: usize = TILE_NODES / 64;

#[derive(Debug, Clone, PartialEq)]
struct TileData {
    z: [f64; TILE_NODES],
    /// One bit per node: set once a cut or a chip has lowered it (loading a
    /// surface does not). The contact reads it to tell the blurred edge of a
    /// groove from the face it was cut from.
    cut: [u64; MASK_WORDS],
    /// Whether the tile's height bound may be stale, and where it was found.
    marks: BoundMarks,
}

/// What [`HeightMap::refresh_bounds`] keeps of a tile: whether a write
/// lowered a node at its height bound since the bound was last found (it
/// may lie above every node now), and the row of nodes it was found in
/// (read first the next time: a row of rock the cuts have not reached yet
/// usually holds it still). Bookkeeping, not the tile's content: tiles
/// compare equal whatever their marks. (Kept with the nodes, not in the
/// directory, whose slots stay two words.)
#[derive(Debug, Clone, Copy, Default)]
struct BoundMarks {
    stale: bool,
    hint: u8,
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
    fn cell_mask(&self, k: usize) -> u32 {
        let pair = |k: usize| (self.cut[k / 64] >> (k % 64) & 3) as u32;
        pair(k) | pair(k + TILE) << 2
    }
}

#[derive(Debug, Clone)]
struct Tile {
    d: Arc<TileData>,
    /// An upper bound of the heights in the tile: raised on writes that
    /// raise, and found again ([`HeightMap::refresh_bounds`]) once a write
    /// has lowered a node that stood at it ([`BoundMarks`]).
    z_max: f64,
}

impl Tile {
    /// The tile in `slot` for writing, allocated (flat at `z0`) if absent;
    /// and whether it was.
    fn for_writing(slot: &mut Option<Tile>, z0: f64) -> (&mut Tile, bool) {
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
    fn set(&mut self, k: usize, z: f64) {
        store(Arc::make_mut(&mut self.d), &mut self.z_max, k, z);
    }

    /// Lowers node `k` to `z` and marks it cut (copy on write, as `set`).
    fn lower(&mut self, k: usize, z: f64) {
        lower_in(Arc::make_mut(&mut self.d), &mut self.z_max, k, z);
    }
}

/// Writes node `k` of a tile's nodes `d` whose height bound is `z_max`:
/// the bound rises with the node, and a node lowered from the bound marks
/// it stale ([`BoundMarks`]).
#[inline]
fn store(d: &mut TileData, z_max: &mut f64, k: usize, z: f64) {
    d.marks.stale |= z < d.z[k] && d.z[k] >= *z_max;
    d.z[k] = z;
    if z > *z_max {
        *z_max = z;
    }
}

/// [`store`], and marks the node cut.
#[inline]
fn lower_in(d: &mut TileData, z_max: &mut f64, k: usize, z: f64) {
    store(d, z_max, k, z);
    d.cut[k / 64] |= 1u64 << (k % 64);
}

/// The highest of the tile's heights `z` on the map's grid (its first
/// `cols` nodes of its first `rows` rows: an edge tile's other nodes lie
/// off the grid) and the row it stands in, or `bound` as soon as a row
/// reaches it (nothing stands higher than the bound); row `hint` first,
/// then a row at a time, each in four lanes (the compiler keeps them in
/// vector registers).
fn tile_max(
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
fn tile_runs(i0: usize, i1: usize) -> impl Iterator<Item = (usize, usize)> {
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
trait Slot<'a> {
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
struct RowSlot<'a> {
    row: &'a mut Arc<[Option<Tile>]>,
    ti: usize,
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
fn lower_run<'a>(
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

/// A rectangle of tiles: columns `ti[0]..=ti[1]`, rows `tj[0]..=tj[1]`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TileRect {
    pub ti: [usize; 2],
    pub tj: [usize; 2],
}

impl TileRect {
    pub fn overlaps(&self, o: &TileRect) -> bool {
        self.ti[0] <= o.ti[1]
            && o.ti[0] <= self.ti[1]
            && self.tj[0] <= o.tj[1]
            && o.tj[0] <= self.tj[1]
    }
}

/// A writable view of a rectangle of a map's tiles ([`HeightMap::patches`]):
/// reads and cuts of the nodes inside it, as the map's own.
#[derive(Debug)]
pub struct Patch<'a> {
    grid: Grid,
    z0: f64,
    rect: TileRect,
    /// The rectangle's tiles, one slice per tile row.
    rows: Vec<&'a mut [Option<Tile>]>,
}

impl Patch<'_> {
    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    /// Slot and node index of node `(i, j)`, which must lie in the patch.
    #[inline]
    fn slot(&self, i: usize, j: usize) -> (usize, usize, usize) {
        let (ti, tj) = (i / TILE, j / TILE);
        debug_assert!(
            (self.rect.ti[0]..=self.rect.ti[1]).contains(&ti)
                && (self.rect.tj[0]..=self.rect.tj[1]).contains(&tj),
            "node ({i}, {j}) outside the patch"
        );
        (
            tj - self.rect.tj[0],
            ti - self.rect.ti[0],
            (j % TILE) * TILE + i % TILE,
        )
    }

    /// [`HeightMap::node`] inside the patch.
    #[inline]
    pub fn node(&self, i: usize, j: usize) -> f64 {
        let (r, c, k) = self.slot(i, j);
        match &self.rows[r][c] {
            Some(tile) => tile.d.z[k],
            None => self.z0,
        }
    }

    /// [`HeightMap::set_node`] inside the patch. A node set may rise: the
    /// caller gives the map a new history when the patches are done
    /// ([`HeightMap::new_lineage`]).
    pub fn set_node(&mut self, i: usize, j: usize, z: f64) {
        let (r, c, k) = self.slot(i, j);
        Tile::for_writing(&mut self.rows[r][c], self.z0).0.set(k, z);
    }

    /// [`HeightMap::lower_row`] inside the patch.
    pub fn lower_row(
        &mut self,
        j: usize,
        i0: usize,
        i1: usize,
        mut f: impl FnMut(f64) -> Option<f64>,
    ) {
        for (i, n) in tile_runs(i0, i1) {
            let (r, c, k) = self.slot(i, j);
            lower_run(
                &mut self.rows[r][c],
                self.z0,
                k,
                n,
                &mut f,
                |_, _, _, _| {},
                || {},
            );
        }
    }

    /// [`HeightMap::lower_node`] inside the patch.
    pub fn lower_node(&mut self, i: usize, j: usize, z: f64) {
        let (r, c, k) = self.slot(i, j);
        Tile::for_writing(&mut self.rows[r][c], self.z0)
            .0
            .lower(k, z);
    }
}

/// Tiles are equal when their heights, cut masks and height bounds are
/// (the bound travels with a state's bytes: a state read back equals the
/// one it was written from, and replays as it does).
impl PartialEq for Tile {
    fn eq(&self, other: &Self) -> bool {
        self.z_max == other.z_max && (Arc::ptr_eq(&self.d, &other.d) || self.d == other.d)
    }
}

/// Grid geometry of the height map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    pub x_min: f64,
    pub y_min: f64,
    pub dx: f64,
    pub dy: f64,
    pub nx: usize,
    pub ny: usize,
    /// `1/dx`, `1/dy` and the last cell's far edge in cell units, for queries.
    inv_dx: f64,
    inv_dy: f64,
    u_max: f64,
    v_max: f64,
}

impl Grid {
    pub fn new(x_min: f64, x_max: f64, y_min: f64, y_max: f64, nx: usize, ny: usize) -> Self {
        let dx = (x_max - x_min) / (nx - 1) as f64;
        let dy = (y_max - y_min) / (ny - 1) as f64;
        Self {
            x_min,
            y_min,
            dx,
            dy,
            nx,
            ny,
            inv_dx: 1.0 / dx,
            inv_dy: 1.0 / dy,
            u_max: (nx - 1) as f64,
            v_max: (ny - 1) as f64,
        }
    }

    pub fn x_max(&self) -> f64 {
        self.x_min + self.dx * (self.nx - 1) as f64
    }

    pub fn y_max(&self) -> f64 {
        self.y_min + self.dy * (self.ny - 1) as f64
    }

    /// Coordinates of node `(i, j)` (0-based; eqs 67-68).
    #[inline]
    pub fn node_xy(&self, i: usize, j: usize) -> (f64, f64) {
        (
            self.x_min + self.dx * i as f64,
            self.y_min + self.dy * j as f64,
        )
    }

    /// Range of node indices whose coordinates lie in `[lo, hi]`, clipped to the grid.
    pub fn node_range(
        &self,
        x_lo: f64,
        x_hi: f64,
        y_lo: f64,
        y_hi: f64,
    ) -> Option<(usize, usize, usize, usize)> {
        let i0 = ((x_lo - self.x_min) / self.dx).ceil().max(0.0);
        let i1 = ((x_hi - self.x_min) / self.dx)
            .floor()
            .min((self.nx - 1) as f64);
        let j0 = ((y_lo - self.y_min) / self.dy).ceil().max(0.0);
        let j1 = ((y_hi - self.y_min) / self.dy)
            .floor()
            .min((self.ny - 1) as f64);
        if !(i0 <= i1 && j0 <= j1) {
            return None;
        }
        Some((i0 as usize, i1 as usize, j0 as usize, j1 as usize))
    }

    /// The cell holding `(x, y)`: its lower-left node `(i, j)` and the
    /// position inside it in cell units `(fu, fv)` in [0, 1]; `None` outside
    /// the map. Every query of [`HeightMap`] goes through here, so all agree
    /// on which cell (and triangle) a point lies in.
    #[inline]
    pub fn cell(&self, x: f64, y: f64) -> Option<(usize, usize, f64, f64)> {
        let u = (x - self.x_min) * self.inv_dx;
        let v = (y - self.y_min) * self.inv_dy;
        if !(u >= 0.0 && v >= 0.0 && u <= self.u_max && v <= self.v_max) {
            return None;
        }
        // (in signed integers: `u` and `v` lie in [0, `u_max`] and [0,
        // `v_max`] here, far below 2^53, where both conversions are exact
        // and the signed ones take less code)
        let i = (u as i64).min(self.nx as i64 - 2);
        let j = (v as i64).min(self.ny as i64 - 2);
        Some((i as usize, j as usize, u - i as f64, v - j as f64))
    }

    /// Area a node stands for (one cell).
    pub fn cell_area(&self) -> f64 {
        self.dx * self.dy
    }
}

/// The height map: grid, the flat base height and the tiles written so far.
#[derive(Debug, Clone, PartialEq)]
pub struct HeightMap {
    grid: Grid,
    z0: f64,
    tiles_x: usize,
    tiles_y: usize,
    /// The tile directory, a row of tiles (`tiles_x` of them) per `Arc`:
    /// tile `t` is `rows[t / tiles_x][t % tiles_x]`.
    rows: Vec<Arc<[Option<Tile>]>>,
    /// While a change may still be rolled back: what it wrote over. Kept
    /// between changes (empty) so that its buffers are reused.
    undo: Undo,
    /// Which history of cuts this map holds ([`Lineage`]).
    lineage: Lineage,
    /// An upper bound of every node ([`HeightMap::top`]).
    top: f64,
    /// Tiles whose bounds [`HeightMap::refresh_bounds`] is to find again.
    pending: Pending,
}

/// A map's history, for what a disc may assume of the rock it cut last:
/// kept while nodes only fall (cuts, chips), new whenever one may rise (a
/// node set, a tile loaded, a change rolled back) and in every clone (a
/// state restored is another history). Maps compare equal whatever their
/// lineages.
#[derive(Debug)]
struct Lineage(u64);

impl Lineage {
    fn fresh() -> Self {
        static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(1);
        Self(NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed))
    }
}

impl Clone for Lineage {
    fn clone(&self) -> Self {
        Self::fresh()
    }
}

impl PartialEq for Lineage {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

/// The tiles whose bounds may have gone stale since
/// [`HeightMap::refresh_bounds`]: those the map's own writes made stale, and
/// the rectangles it handed out as patches (whose writes it does not see).
/// Bookkeeping between two refreshes, not the map's content: maps compare
/// equal whatever is pending.
#[derive(Debug, Clone, Default)]
struct Pending {
    tiles: Vec<usize>,
    rects: Vec<TileRect>,
}

impl PartialEq for Pending {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

#[derive(Debug, Clone, PartialEq, Default)]
struct Undo {
    open: bool,
    /// Tiles the change allocated (absent before it).
    allocated: Vec<usize>,
    /// Node writes in order, with what they overwrote.
    writes: Vec<Overwritten>,
}

/// One node write of an open undo record and what it overwrote.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Overwritten {
    tile: usize,
    node: usize,
    z: f64,
    cut_word: u64,
    z_max: f64,
}

/// A point query on the surface: height and slopes of the triangle (eqs 27-32).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfacePoint {
    pub z: f64,
    pub dzdx: f64,
    pub dzdy: f64,
}

impl HeightMap {
    /// A flat face at height `z0`; allocates only the tile directory.
    pub fn flat(grid: Grid, z0: f64) -> Self {
        let tiles_x = grid.nx.div_ceil(TILE);
        let tiles_y = grid.ny.div_ceil(TILE);
        Self {
            grid,
            z0,
            tiles_x,
            tiles_y,
            // every row the same empty one: a write unshares its row
            #[allow(clippy::rc_clone_in_vec_init)]
            rows: vec![Arc::from(vec![None; tiles_x]); tiles_y],
            undo: Undo::default(),
            lineage: Lineage::fresh(),
            top: z0,
            pending: Pending::default(),
        }
    }

    /// An upper bound of every node's height: the highest the rock reaches
    /// anywhere on the face. Cuts and chips only lower nodes, so it is the
    /// initial face's top (`z0` on a flat face) unless a node is set above
    /// it: [`set_node`](Self::set_node) and [`load_tile`](Self::load_tile)
    /// raise it, and [`new_lineage`](Self::new_lineage) (nodes set through
    /// patches) finds it again from the tiles' bounds.
    pub fn top(&self) -> f64 {
        self.top
    }

    /// This map's history of cuts: the same number while its nodes have
    /// only fallen since, another after anything that may raise one, and
    /// in a clone.
    pub fn lineage(&self) -> u64 {
        self.lineage.0
    }

    /// Starts a new history: nodes may have risen (set through patches).
    /// The bounds of the tiles written are found again
    /// ([`refresh_bounds`](Self::refresh_bounds)), and the
    /// [`top`](Self::top) from them (a scan of the tile directory).
    pub fn new_lineage(&mut self) {
        self.lineage = Lineage::fresh();
        self.refresh_bounds();
        self.top = self
            .tiles()
            .flatten()
            .map(|t| t.z_max)
            .fold(self.z0, f64::max);
    }

    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    pub fn base_height(&self) -> f64 {
        self.z0
    }

    /// Number of tiles allocated (touched) so far.
    pub fn allocated_tiles(&self) -> usize {
        self.tiles().filter(|t| t.is_some()).count()
    }

    /// Every slot of the directory, in tile order.
    fn tiles(&self) -> impl Iterator<Item = &Option<Tile>> {
        self.rows.iter().flat_map(|r| r.iter())
    }

    /// Slot of tile `t`.
    #[inline]
    fn slot(&self, t: usize) -> &Option<Tile> {
        &self.rows[t / self.tiles_x][t % self.tiles_x]
    }

    /// Slot of the tile in tile row `tj`, column `ti`, for writing: the
    /// row's directory is unshared first (copy on write).
    #[inline]
    fn slot_mut(&mut self, tj: usize, ti: usize) -> &mut Option<Tile> {
        &mut Arc::make_mut(&mut self.rows[tj])[ti]
    }

    /// Bytes held by the map (directory plus allocated tiles; a tile shared
    /// with a clone counts in each).
    pub fn memory_bytes(&self) -> usize {
        self.tile_count() * std::mem::size_of::<Option<Tile>>()
            + self.allocated_tiles() * std::mem::size_of::<TileData>()
    }

    /// Rows and columns of nodes of tile `(tj, ti)` that lie on the grid
    /// (all `TILE` of each but in the last tiles of a row or column).
    fn on_grid(&self, tj: usize, ti: usize) -> (usize, usize) {
        (
            (self.grid.ny - tj * TILE).min(TILE),
            (self.grid.nx - ti * TILE).min(TILE),
        )
    }

    /// Tile row, tile column and node index in the tile of node `(i, j)`.
    #[inline]
    fn tile_index(&self, i: usize, j: usize) -> (usize, usize, usize) {
        (j / TILE, i / TILE, (j % TILE) * TILE + i % TILE)
    }

    /// Height of node `(i, j)` (0-based, must be inside the grid).
    #[inline]
    pub fn node(&self, i: usize, j: usize) -> f64 {
        let (tj, ti, k) = self.tile_index(i, j);
        match &self.rows[tj][ti] {
            Some(tile) => tile.d.z[k],
            None => self.z0,
        }
    }

    /// Node `k` of the tile in tile row `tj`, column `ti` for writing: the
    /// tile allocated on first write, and the node's old value logged when
    /// an undo record is open.
    fn tile_mut(&mut self, tj: usize, ti: usize, k: usize) -> &mut Tile {
        let t = tj * self.tiles_x + ti;
        let z0 = self.z0;
        let open = self.undo.open;
        let slot = &mut Arc::make_mut(&mut self.rows[tj])[ti];
        let (tile, allocated) = Tile::for_writing(slot, z0);
        if allocated && open {
            self.undo.allocated.push(t);
        }
        if open {
            self.undo.writes.push(Overwritten {
                tile: t,
                node: k,
                z: tile.d.z[k],
                cut_word: tile.d.cut[k / 64],
                z_max: tile.z_max,
            });
        }
        tile
    }

    /// Sets node `(i, j)`, allocating its tile on first write (a surface
    /// being loaded: the node does not count as cut).
    pub fn set_node(&mut self, i: usize, j: usize, z: f64) {
        self.lineage = Lineage::fresh();
        if z > self.top {
            self.top = z;
        }
        self.write_node(i, j, |tile, k| tile.set(k, z));
    }

    /// Lowers node `(i, j)` to `z` by a cut or a chip, and marks it cut.
    pub fn lower_node(&mut self, i: usize, j: usize, z: f64) {
        self.write_node(i, j, |tile, k| tile.lower(k, z));
    }

    /// Writes node `(i, j)` of its tile (`write(tile, k)`, undo record
    /// included), noting the tile if the write makes its bound stale.
    fn write_node(&mut self, i: usize, j: usize, write: impl FnOnce(&mut Tile, usize)) {
        let (tj, ti, k) = self.tile_index(i, j);
        let tile = self.tile_mut(tj, ti, k);
        let was = tile.d.marks.stale;
        write(tile, k);
        if tile.d.marks.stale && !was {
            self.pending.tiles.push(tj * self.tiles_x + ti);
        }
    }

    /// Finds again the bound of every tile a write has made stale since the
    /// last refresh (the highest of its nodes, read until a row reaches the
    /// old bound), so that the bounds follow the face down as it is bored
    /// (`max_height`, and with it every window and walk, reads them). The
    /// discs' cuts call it after each sub-step's cuts; its cost follows the
    /// tiles written, not the face.
    pub fn refresh_bounds(&mut self) {
        let Pending { tiles, rects } = std::mem::take(&mut self.pending);
        let tx = self.tiles_x;
        let in_rects = rects.iter().flat_map(|r| {
            (r.tj[0]..=r.tj[1]).flat_map(move |tj| (r.ti[0]..=r.ti[1]).map(move |ti| tj * tx + ti))
        });
        for t in tiles.iter().copied().chain(in_rects) {
            if !self.slot(t).as_ref().is_some_and(|tile| tile.d.marks.stale) {
                continue;
            }
            let (tj, ti) = (t / tx, t % tx);
            let (rows, cols) = self.on_grid(tj, ti);
            if let Some(tile) = self.slot_mut(tj, ti) {
                let d = Arc::make_mut(&mut tile.d);
                let hint = usize::from(d.marks.hint);
                let (m, row) = tile_max(&d.z, tile.z_max, hint, rows, cols);
                tile.z_max = m;
                d.marks = BoundMarks {
                    stale: false,
                    hint: row as u8,
                };
            }
        }
        // (the buffers kept for the next time)
        self.pending = Pending { tiles, rects };
        self.pending.tiles.clear();
        self.pending.rects.clear();
    }

    /// Runs `f(z)` over the heights of nodes `i0..=i1` of row `j`, in order,
    /// and lowers each node for which it returns a height to that height (as
    /// [`lower_node`](Self::lower_node), undo record included). A cut's row
    /// at a time: each tile is looked up and unshared once, not per node.
    pub fn lower_row(
        &mut self,
        j: usize,
        i0: usize,
        i1: usize,
        mut f: impl FnMut(f64) -> Option<f64>,
    ) {
        for (i, n) in tile_runs(i0, i1) {
            let (tj, ti, k) = self.tile_index(i, j);
            let t = tj * self.tiles_x + ti;
            let undo = &mut self.undo;
            let open = undo.open;
            let mut allocated = false;
            let stale = lower_run(
                RowSlot {
                    row: &mut self.rows[tj],
                    ti,
                },
                self.z0,
                k,
                n,
                &mut f,
                |node, z, cut_word, z_max| {
                    if open {
                        undo.writes.push(Overwritten {
                            tile: t,
                            node,
                            z,
                            cut_word,
                            z_max,
                        });
                    }
                },
                || allocated = true,
            );
            if allocated && self.undo.open {
                self.undo.allocated.push(t);
            }
            if stale {
                self.pending.tiles.push(t);
            }
        }
    }

    /// The tiles holding nodes `i0..=i1` x `j0..=j1`.
    pub fn tile_rect(&self, i0: usize, i1: usize, j0: usize, j1: usize) -> TileRect {
        TileRect {
            ti: [i0 / TILE, i1 / TILE],
            tj: [j0 / TILE, j1 / TILE],
        }
    }

    /// Writable views of the given rectangles of tiles, which must not
    /// overlap (`None` if they do), so that cuts far apart can run at once.
    /// Only while no undo record is open: a patch's writes are not logged.
    pub fn patches(&mut self, rects: &[TileRect]) -> Option<Vec<Patch<'_>>> {
        assert!(!self.undo.open, "patches cannot log undo");
        self.pending.rects.extend_from_slice(rects);
        // every rectangle is one run of tiles per tile row; the runs of all
        // rectangles, in directory order, are peeled off the rows they lie
        // in (each such row unshared first)
        let mut runs: Vec<(usize, usize, usize, usize)> = rects
            .iter()
            .enumerate()
            .flat_map(|(r, rc)| {
                (rc.tj[0]..=rc.tj[1]).map(move |tj| (tj, rc.ti[0], rc.ti[1] - rc.ti[0] + 1, r))
            })
            .collect();
        runs.sort_unstable();
        if runs
            .iter()
            .any(|&(tj, ti, len, _)| tj >= self.tiles_y || ti + len > self.tiles_x)
        {
            return None;
        }
        let mut rows: Vec<Vec<&mut [Option<Tile>]>> = rects.iter().map(|_| Vec::new()).collect();
        let mut runs = runs.into_iter().peekable();
        for (tj, row) in self.rows.iter_mut().enumerate() {
            if runs.peek().is_none_or(|r| r.0 != tj) {
                continue;
            }
            let mut rest: &mut [Option<Tile>] = Arc::make_mut(row);
            let mut at = 0;
            while let Some((_, start, len, r)) = runs.next_if(|r| r.0 == tj) {
                if start < at {
                    return None;
                }
                let (_, tail) = std::mem::take(&mut rest).split_at_mut(start - at);
                let (run, tail) = tail.split_at_mut(len);
                rows[r].push(run);
                rest = tail;
                at = start + len;
            }
        }
        let (grid, z0) = (self.grid, self.z0);
        Some(
            rects
                .iter()
                .zip(rows)
                .map(|(&rect, rows)| Patch {
                    grid,
                    z0,
                    rect,
                    rows,
                })
                .collect(),
        )
    }

    /// Has a cut or a chip lowered node `(i, j)`?
    #[inline]
    pub fn is_cut(&self, i: usize, j: usize) -> bool {
        let (tj, ti, k) = self.tile_index(i, j);
        match &self.rows[tj][ti] {
            Some(tile) => tile.d.cut[k / 64] >> (k % 64) & 1 == 1,
            None => false,
        }
    }

    /// The heights of the four nodes of the cell whose lower-left node is
    /// `(i, j)` (both inside the grid, `i + 1`, `j + 1` too): `[(i, j),
    /// (i + 1, j), (i, j + 1), (i + 1, j + 1)]`, each as [`HeightMap::node`]
    /// reads it. A cell inside one tile (all but the last row and column of
    /// a tile's cells) looks its tile up once.
    #[inline(always)]
    fn cell_nodes(&self, i: usize, j: usize) -> [f64; 4] {
        if i % TILE < TILE - 1 && j % TILE < TILE - 1 {
            let (tj, ti, k) = self.tile_index(i, j);
            match &self.rows[tj][ti] {
                Some(tile) => {
                    let z = &tile.d.z[k..k + TILE + 2];
                    [z[0], z[1], z[TILE], z[TILE + 1]]
                }
                None => [self.z0; 4],
            }
        } else {
            [
                self.node(i, j),
                self.node(i + 1, j),
                self.node(i, j + 1),
                self.node(i + 1, j + 1),
            ]
        }
    }

    /// Which of the four nodes of the cell at `(i, j)` (as
    /// [`HeightMap::cell_nodes`]) a cut or a chip has lowered, a mask as
    /// [`HeightMap::is_cut`] reads them:
    /// bit 0 node `(i, j)`, 1 `(i + 1, j)`, 2 `(i, j + 1)`, 3 `(i + 1, j + 1)`.
    #[inline(always)]
    fn cell_cut(&self, i: usize, j: usize) -> u32 {
        if i % TILE < TILE - 1 && j % TILE < TILE - 1 {
            let (tj, ti, k) = self.tile_index(i, j);
            match &self.rows[tj][ti] {
                Some(tile) => tile.d.cell_mask(k),
                None => 0,
            }
        } else {
            self.is_cut(i, j) as u32
                | (self.is_cut(i + 1, j) as u32) << 1
                | (self.is_cut(i, j + 1) as u32) << 2
                | (self.is_cut(i + 1, j + 1) as u32) << 3
        }
    }

    /// [`HeightMap::cell_nodes`] and [`HeightMap::cell_cut`] from one tile
    /// lookup.
    #[inline(always)]
    fn cell_nodes_cut(&self, i: usize, j: usize) -> ([f64; 4], u32) {
        if i % TILE < TILE - 1 && j % TILE < TILE - 1 {
            let (tj, ti, k) = self.tile_index(i, j);
            match &self.rows[tj][ti] {
                Some(tile) => {
                    let z = &tile.d.z[k..k + TILE + 2];
                    ([z[0], z[1], z[TILE], z[TILE + 1]], tile.d.cell_mask(k))
                }
                None => ([self.z0; 4], 0),
            }
        } else {
            (self.cell_nodes(i, j), self.cell_cut(i, j))
        }
    }

    /// An upper bound of the rock within `r` plus a cell of `(x, y)` in
    /// plan (the nodes of that square; [`HeightMap::max_height`]), `None`
    /// when the square misses the map: the highest rock a disc of radius
    /// `r` centred over `(x, y)` can meet.
    pub fn highest_within(&self, x: f64, y: f64, r: f64) -> Option<f64> {
        let g = self.grid();
        g.node_range(x - r - g.dx, x + r + g.dx, y - r - g.dy, y + r + g.dy)
            .map(|(i0, i1, j0, j1)| self.max_height(i0, i1, j0, j1))
    }

    /// The highest node of the cells ([`Grid::cell`]) that points in
    /// `[x0, x1] x [y0, y1]` lie in, read node by node; [`NO_ROCK`] when
    /// the box misses the map. A tight bound over a few cells, where
    /// [`HeightMap::max_height`] gives the tiles' bounds.
    pub fn highest_node_under(&self, x0: f64, x1: f64, y0: f64, y1: f64) -> f64 {
        let g = &self.grid;
        let (u0, u1) = ((x0 - g.x_min) * g.inv_dx, (x1 - g.x_min) * g.inv_dx);
        let (v0, v1) = ((y0 - g.y_min) * g.inv_dy, (y1 - g.y_min) * g.inv_dy);
        if !(u1 >= 0.0 && v1 >= 0.0 && u0 <= g.u_max && v0 <= g.v_max) {
            return NO_ROCK;
        }
        // (as `Grid::cell`: the index of a coordinate, at most the last
        // cell's; the box clipped to the map)
        let last_i = g.nx as i64 - 2;
        let last_j = g.ny as i64 - 2;
        let i0 = (u0.max(0.0) as i64).min(last_i) as usize;
        let i1 = (u1.min(g.u_max) as i64).min(last_i) as usize + 1;
        let j0 = (v0.max(0.0) as i64).min(last_j) as usize;
        let j1 = (v1.min(g.v_max) as i64).min(last_j) as usize + 1;
        let mut m = NO_ROCK;
        if i0 / TILE == i1 / TILE && j0 / TILE == j1 / TILE {
            // (one tile, the usual case)
            return match &self.rows[j0 / TILE][i0 / TILE] {
                Some(tile) => {
                    let (a, b) = (i0 % TILE, i1 % TILE);
                    for j in j0 % TILE..=j1 % TILE {
                        for &z in &tile.d.z[j * TILE + a..=j * TILE + b] {
                            m = if z > m { z } else { m };
                        }
                    }
                    m
                }
                None => self.z0,
            };
        }
        for j in j0..=j1 {
            for i in i0..=i1 {
                let z = self.node(i, j);
                m = if z > m { z } else { m };
            }
        }
        m
    }

    /// An upper bound of the node heights with indices in the given ranges.
    pub fn max_height(&self, i0: usize, i1: usize, j0: usize, j1: usize) -> f64 {
        // (a disc's box spans some 250 tiles at 1 mm cells, read for every
        // contact and every cut's window: a plain comparison, no NaN
        // reaches a bound, and an absent tile read once as `z0`)
        let mut m = NO_ROCK;
        let mut absent = false;
        for row in &self.rows[j0 / TILE..=j1 / TILE] {
            for t in &row[i0 / TILE..=i1 / TILE] {
                match t {
                    Some(tile) => {
                        if tile.z_max > m {
                            m = tile.z_max;
                        }
                    }
                    None => absent = true,
                }
            }
        }
        if absent && self.z0 > m {
            m = self.z0;
        }
        m
    }

    /// Surface height and slope at `(x, y)`, or `None` outside the map.
    /// Lower triangle (`xx1/dx >= yy1/dy`): nodes (0,0), (1,0), (1,1);
    /// upper triangle: (0,0), (0,1), (1,1) — thesis eqs 27-32, with the
    /// lower/upper test written on normalised cell coordinates.
    #[inline]
    pub fn point(&self, x: f64, y: f64) -> Option<SurfacePoint> {
        let g = &self.grid;
        let (i, j, fu, fv) = g.cell(x, y)?;
        let [z00, z10, z01, z11] = self.cell_nodes(i, j);
        let (dzdx, dzdy) = if fu >= fv {
            ((z10 - z00) / g.dx, (z11 - z10) / g.dy)
        } else {
            ((z11 - z01) / g.dx, (z01 - z00) / g.dy)
        };
        Some(SurfacePoint {
            z: z00 + dzdx * fu * g.dx + dzdy * fv * g.dy,
            dzdx,
            dzdy,
        })
    }

    /// The triangle under `(x, y)`: an id unique over the map and its unit
    /// upward normal (thesis eqs 41-42), or `None` outside the map.
    pub fn triangle(&self, x: f64, y: f64) -> Option<(u64, [f64; 3])> {
        let g = &self.grid;
        let p = self.point(x, y)?;
        let (i, j, fu, fv) = g.cell(x, y)?;
        let lower = fu >= fv;
        let id = ((j * g.nx + i) as u64) * 2 + lower as u64;
        let n = (p.dzdx * p.dzdx + p.dzdy * p.dzdy + 1.0).sqrt();
        Some((id, [-p.dzdx / n, -p.dzdy / n, 1.0 / n]))
    }

    /// Bilinear interpolation of the cell holding `(x, y)`, [`NO_ROCK`]
    /// outside the map. Unlike the triangles it has no diagonal, so it treats
    /// +y and -y alike; the contact walk uses it to look ahead.
    #[inline]
    pub fn bilinear(&self, x: f64, y: f64) -> f64 {
        let Some((i, j, fu, fv)) = self.grid.cell(x, y) else {
            return NO_ROCK;
        };
        bilerp(self.cell_nodes(i, j), fu, fv)
    }

    /// [`HeightMap::bilinear`] and [`HeightMap::any_uncut`] at one point,
    /// the cell looked up once.
    #[inline]
    pub fn bilinear_any_uncut(&self, x: f64, y: f64) -> (f64, bool) {
        let Some((i, j, fu, fv)) = self.grid.cell(x, y) else {
            return (NO_ROCK, false);
        };
        let (z, cut) = self.cell_nodes_cut(i, j);
        (bilerp(z, fu, fv), cut != 0b1111)
    }

    /// Does the cell holding `(x, y)` have a node no cut has lowered?
    #[inline]
    pub fn any_uncut(&self, x: f64, y: f64) -> bool {
        self.grid
            .cell(x, y)
            .is_some_and(|(i, j, _, _)| self.cell_cut(i, j) != 0b1111)
    }

    /// Bilinear height of the cell holding `(x, y)` when no cut has lowered
    /// any of its four nodes, else `None`: where the rock is still the face
    /// it was cut from.
    #[inline]
    pub fn bilinear_uncut(&self, x: f64, y: f64) -> Option<f64> {
        let (i, j, fu, fv) = self.grid.cell(x, y)?;
        let (z, cut) = self.cell_nodes_cut(i, j);
        (cut == 0).then(|| bilerp(z, fu, fv))
    }

    /// Surface height at `(x, y)`, [`NO_ROCK`] outside the map (the same
    /// triangles as [`HeightMap::point`], without the slopes).
    #[inline(always)]
    pub fn height(&self, x: f64, y: f64) -> f64 {
        let Some((i, j, fu, fv)) = self.grid.cell(x, y) else {
            return NO_ROCK;
        };
        let [z00, z10, z01, z11] = self.cell_nodes(i, j);
        if fu >= fv {
            z00 + (z10 - z00) * fu + (z11 - z10) * fv
        } else {
            z00 + (z11 - z01) * fu + (z01 - z00) * fv
        }
    }

    /// Indices of the tiles written so far, with their heights (row-major
    /// inside a tile; nodes past the grid edge hold `z0`) and their cut masks
    /// (bit `k % 64` of word `k / 64` for node `k`).
    pub fn touched_tiles(&self) -> impl Iterator<Item = (usize, &[f64], &[u64])> {
        self.tiles()
            .enumerate()
            .filter_map(|(k, t)| t.as_ref().map(|t| (k, &t.d.z[..], &t.d.cut[..])))
    }

    /// Words of a tile's cut mask.
    pub const MASK_WORDS: usize = MASK_WORDS;

    pub fn tile_count(&self) -> usize {
        self.tiles_x * self.tiles_y
    }

    /// Starts recording what the writes change, for [`HeightMap::rollback`].
    pub fn begin_undo(&mut self) {
        self.undo.open = true;
        self.undo.allocated.clear();
        self.undo.writes.clear();
    }

    /// Keeps the writes since [`HeightMap::begin_undo`] and stops recording.
    pub fn commit_undo(&mut self) {
        self.undo.open = false;
        self.undo.allocated.clear();
        self.undo.writes.clear();
    }

    /// Puts back every tile written since [`HeightMap::begin_undo`] and
    /// stops recording.
    pub fn rollback(&mut self) {
        self.lineage = Lineage::fresh();
        if self.undo.open {
            let u = std::mem::take(&mut self.undo);
            let tx = self.tiles_x;
            for w in u.writes.iter().rev() {
                if let Some(tile) = self.slot_mut(w.tile / tx, w.tile % tx) {
                    let d = Arc::make_mut(&mut tile.d);
                    d.z[w.node] = w.z;
                    d.cut[w.node / 64] = w.cut_word;
                    tile.z_max = w.z_max;
                    d.marks.stale = false;
                }
            }
            for &t in &u.allocated {
                *self.slot_mut(t / tx, t % tx) = None;
            }
            // (the bounds are the ones before the change, as found then)
            self.pending.tiles.clear();
            self.pending.rects.clear();
        }
    }

    /// The bound on tile `k`'s heights that the map keeps (the one
    /// [`max_height`](Self::max_height) reads): exact after a load or a
    /// [`refresh_bounds`](Self::refresh_bounds), an upper bound in between.
    /// A state carries it, so that a map read back scans and walks exactly
    /// as the one it was written from.
    pub fn tile_bound(&self, k: usize) -> f64 {
        self.slot(k).as_ref().map_or(self.z0, |t| t.z_max)
    }

    /// Restores a tile written by [`HeightMap::touched_tiles`], with its
    /// height bound ([`tile_bound`](Self::tile_bound); never below the
    /// tile's highest node on the grid, whatever the caller passes).
    pub fn load_tile(&mut self, k: usize, z: &[f64], cut: &[u64], bound: f64) -> Option<()> {
        if k >= self.tile_count() || z.len() != TILE_NODES || cut.len() != MASK_WORDS {
            return None;
        }
        let mut d = Arc::new(TileData {
            z: [0.0; TILE_NODES],
            cut: [0; MASK_WORDS],
            marks: BoundMarks::default(),
        });
        let dm = Arc::make_mut(&mut d);
        dm.z.copy_from_slice(z);
        dm.cut.copy_from_slice(cut);
        let (rows, cols) = self.on_grid(k / self.tiles_x, k % self.tiles_x);
        let z_max = (0..rows)
            .flat_map(|r| &d.z[r * TILE..r * TILE + cols])
            .copied()
            .fold(bound, f64::max);
        self.lineage = Lineage::fresh();
        self.top = self.top.max(z_max);
        *self.slot_mut(k / self.tiles_x, k % self.tiles_x) = Some(Tile { d, z_max });
        Some(())
    }
}

/// Bilinear interpolation of a cell's node heights `[z00, z10, z01, z11]`
/// at `(fu, fv)` in cell units.
#[inline]
fn bilerp([z00, z10, z01, z11]: [f64; 4], fu: f64, fv: f64) -> f64 {
    let a = z00 + (z10 - z00) * fu;
    let b = z01 + (z11 - z01) * fu;
    a + (b - a) * fv
}

#[cfg(test)]
mod tests {
    use super::*;

    fn small() -> HeightMap {
        HeightMap::flat(Grid::new(0.0, 1.0, 0.0, 2.0, 11, 21), 0.5)
    }

    /// A tile read back keeps the height bound it was written with: the cut
    /// windows and the contact's arc walk start from that bound, so a bound
    /// recomputed exactly on reading (tighter than one left by cuts) made a
    /// state read back from bytes replay differently.
    #[test]
    fn a_tile_read_back_keeps_its_height_bound() {
        let g = Grid::new(0.0, 0.1, 0.0, 0.1, 101, 101);
        let mut m = HeightMap::flat(g, 0.5);
        m.lower_node(3, 3, 0.49);
        m.lower_node(4, 3, 0.47);
        for j in 0..TILE {
            for i in 0..TILE {
                m.lower_node(i, j, 0.4); // the whole tile cut: its bound stays 0.5
            }
        }
        let (k, z, cut) = m.touched_tiles().next().unwrap();
        let (z, cut) = (z.to_vec(), cut.to_vec());
        assert_eq!(m.tile_bound(k), 0.5);
        let mut back = HeightMap::flat(g, 0.5);
        back.load_tile(k, &z, &cut, m.tile_bound(k)).unwrap();
        assert_eq!(back.max_height(0, 31, 0, 31), m.max_height(0, 31, 0, 31));
        // a bound below the tile's own nodes is no bound: the nodes win
        back.load_tile(k, &z, &cut, 0.0).unwrap();
        assert_eq!(back.tile_bound(k), 0.4);
    }

    #[test]
    fn a_row_lowers_as_its_nodes_do_and_rolls_back() {
        let g = Grid::new(0.0, 0.2, 0.0, 0.2, 201, 201);
        let mut m = HeightMap::flat(g, 0.5);
        m.set_node(40, 7, 0.45);
        let snapshot = m.clone(); // shares the tile: the row must unshare it
        let before = m.clone();
        let mut want = m.clone();
        // a row across three tiles (0, 1, 2; tile 2 untouched so far)
        let lower = |i: usize, z: f64| i.is_multiple_of(3).then_some(z - 1e-3 * i as f64);
        for i in 20..=70 {
            if let Some(z) = lower(i, want.node(i, 7)) {
                want.lower_node(i, 7, z);
            }
        }
        m.begin_undo();
        let mut i = 20;
        m.lower_row(7, 20, 70, |z| {
            let out = lower(i, z);
            i += 1;
            out
        });
        assert_eq!(i, 71, "every node seen once");
        let mut kept = m.clone();
        kept.commit_undo();
        assert!(kept == want && m.is_cut(69, 7) && !m.is_cut(70, 7));
        assert!(snapshot == before, "the snapshot's tile was not written");
        m.rollback();
        assert!(m == before);
    }

    #[test]
    fn patches_read_and_cut_as_the_map_and_refuse_to_overlap() {
        let g = Grid::new(0.0, 0.2, 0.0, 0.2, 201, 201);
        let mut m = HeightMap::flat(g, 0.5);
        m.lower_node(40, 40, 0.4);
        let mut want = m.clone();
        let a = m.tile_rect(30, 70, 35, 50); // tiles 0..=2 x 1..=1
        let b = m.tile_rect(100, 140, 0, 120); // tiles 3..=4 x 0..=3
        assert!(!a.overlaps(&b) && a.overlaps(&m.tile_rect(64, 64, 40, 40)));
        assert!(m.patches(&[a, m.tile_rect(60, 99, 40, 40)]).is_none());
        let mut p = m.patches(&[b, a]).unwrap();
        assert_eq!(p[1].node(40, 40), 0.4);
        assert_eq!(p[1].node(70, 50), 0.5);
        p[1].lower_node(33, 47, 0.3);
        p[0].lower_node(140, 0, 0.2);
        want.lower_node(33, 47, 0.3);
        want.lower_node(140, 0, 0.2);
        assert!(m == want);
        assert!(m.is_cut(140, 0) && m.is_cut(33, 47));
    }

    /// After a refresh every tile's bound is the highest of its nodes on
    /// the grid (an edge tile's nodes off it left out), whatever lowered
    /// them: rows, single nodes, chips-like scattered writes, patches, set
    /// nodes; before it, the bound is never below a node; a rollback puts
    /// the bounds back with the nodes. Brute force over 300 rounds of
    /// random writes on a map whose last tiles overhang the grid.
    #[test]
    fn refreshed_bounds_are_the_highest_node_of_each_tile() {
        let g = Grid::new(0.0, 0.1, 0.0, 0.07, 101, 71); // 4 x 3 tiles, the last ones partial
        let mut m = HeightMap::flat(g, 0.0);
        let mut u = crate::core::uniforms(0xb0b0);
        let exact = |m: &HeightMap, t: usize| {
            let (tj, ti) = (t / m.tiles_x, t % m.tiles_x);
            let mut top = NO_ROCK;
            for j in tj * TILE..((tj + 1) * TILE).min(g.ny) {
                for i in ti * TILE..((ti + 1) * TILE).min(g.nx) {
                    top = top.max(m.node(i, j));
                }
            }
            top
        };
        let check_bounds = |m: &HeightMap, refreshed: bool| {
            for t in 0..m.tile_count() {
                if m.slot(t).is_some() {
                    let (b, e) = (m.tile_bound(t), exact(m, t));
                    assert!(b >= e, "tile {t}: bound {b} below node {e}");
                    if refreshed {
                        assert_eq!(b, e, "tile {t}");
                    }
                }
            }
        };
        let mut lowered = 0;
        for round in 0..300 {
            let before = m.clone();
            let undo = round % 7 == 3;
            if undo {
                m.begin_undo();
            }
            for _ in 0..(1 + (u() * 6.0) as usize) {
                let (i, j) = ((u() * g.nx as f64) as usize, (u() * g.ny as f64) as usize);
                let by = 1e-4 * (1.0 + 20.0 * u());
                match (u() * 4.0) as usize {
                    // (whole rows, so that whole tiles come down)
                    0 => m.lower_row(j, 0, g.nx - 1, |z| Some(z - by)),
                    1 => m.lower_node(i, j, m.node(i, j) - by),
                    2 => m.set_node(i, j, m.node(i, j) - by),
                    _ if !undo => {
                        let rect = m.tile_rect(i, (i + 10).min(g.nx - 1), j, j);
                        let mut p = m.patches(&[rect]).unwrap();
                        p[0].lower_row(j, i, (i + 10).min(g.nx - 1), |z| Some(z - by));
                    }
                    _ => {}
                }
                lowered += 1;
            }
            check_bounds(&m, false);
            if undo {
                m.rollback();
                assert_eq!(m, before);
                for t in 0..m.tile_count() {
                    assert_eq!(m.tile_bound(t), before.tile_bound(t));
                }
            } else {
                m.refresh_bounds();
                check_bounds(&m, true);
            }
        }
        // (the bounds came down: every tile's nodes were all lowered)
        assert!(lowered > 600);
        let down = (0..m.tile_count()).filter(|&t| m.tile_bound(t) < -1e-4);
        assert_eq!(down.count(), 4, "of 12");
    }

    /// The face's top bounds every node: cuts leave it, a node set above
    /// it raises it, a loaded tile raises it to the tile's bound, and a new
    /// lineage (nodes set through patches) finds it from the tiles again.
    #[test]
    fn the_top_bounds_every_node() {
        let g = Grid::new(0.0, 0.2, 0.0, 0.2, 201, 201);
        let mut m = HeightMap::flat(g, 0.5);
        assert_eq!(m.top(), 0.5);
        m.lower_node(10, 10, 0.4);
        m.lower_row(20, 0, 200, |z| Some(z - 0.1));
        assert_eq!(m.top(), 0.5);
        m.set_node(150, 10, 0.45);
        assert_eq!(m.top(), 0.5);
        m.set_node(150, 10, 0.6);
        assert_eq!(m.top(), 0.6);
        let k = m.touched_tiles().next().unwrap().0;
        let mut back = HeightMap::flat(g, 0.5);
        back.load_tile(k, &[0.2; TILE_NODES], &[0; MASK_WORDS], 0.7)
            .unwrap();
        assert_eq!(back.top(), 0.7);
        // through a patch: unknown to the map until the new lineage
        let mut p = HeightMap::flat(g, 0.5);
        let rect = p.tile_rect(100, 120, 100, 120);
        p.patches(&[rect]).unwrap()[0].set_node(110, 110, 0.9);
        assert_eq!(p.top(), 0.5);
        p.new_lineage();
        assert_eq!(p.top(), 0.9);
        let highest = (0..g.ny)
            .flat_map(|j| (0..g.nx).map(move |i| (i, j)))
            .map(|(i, j)| p.node(i, j))
            .fold(NO_ROCK, f64::max);
        assert_eq!(highest, 0.9);
    }

    /// The fast cell reads (the cut mask two nodes a shift, the tiles'
    /// height bound) against node-by-node reads, on a map cut in a
    /// scattered pattern across tile edges and mask words, with absent
    /// tiles between.
    #[test]
    fn cell_masks_and_height_bounds_match_node_by_node_reads() {
        let g = Grid::new(0.0, 0.2, 0.0, 0.2, 201, 201);
        let mut m = HeightMap::flat(g, 0.5);
        for j in 0..120 {
            for i in 0..120 {
                // (a pattern with every cell shape: no tile fully cut, none
                // untouched in the block, tile (3, 3) left absent)
                if (i * 7 + j * 13) % 5 < 2 && !(96..128).contains(&i) {
                    m.lower_node(i, j, 0.5 - 1e-3 * ((i + j) % 7) as f64);
                }
            }
        }
        m.set_node(150, 10, 0.6); // a raised node: the bound rises
        for j in 0..g.ny - 1 {
            for i in 0..g.nx - 1 {
                let each = m.is_cut(i, j) as u32
                    | (m.is_cut(i + 1, j) as u32) << 1
                    | (m.is_cut(i, j + 1) as u32) << 2
                    | (m.is_cut(i + 1, j + 1) as u32) << 3;
                assert_eq!(m.cell_cut(i, j), each, "cell ({i}, {j})");
                assert_eq!(m.cell_nodes_cut(i, j).1, each, "cell ({i}, {j})");
            }
        }
        let highest = |i0: usize, i1: usize, j0: usize, j1: usize| {
            (j0..=j1)
                .flat_map(|j| (i0..=i1).map(move |i| (i, j)))
                .map(|(i, j)| m.node(i, j))
                .fold(NO_ROCK, f64::max)
        };
        for (i0, i1, j0, j1) in [
            (0, 31, 0, 31),
            (5, 130, 40, 70),
            (97, 127, 97, 127),
            (140, 200, 0, 20),
        ] {
            // (a bound: at least every node, and exact where no cut lowered
            // the tile's top)
            assert!(m.max_height(i0, i1, j0, j1) >= highest(i0, i1, j0, j1));
        }
        assert_eq!(m.max_height(97, 127, 97, 127), 0.5); // the absent tile reads z0
        assert_eq!(m.max_height(140, 200, 0, 20), 0.6);
        assert_eq!(m.max_height(0, 95, 0, 95), 0.5);
    }

    #[test]
    fn flat_face_reads_z0_everywhere_and_nothing_outside() {
        let m = small();
        assert_eq!(m.height(0.37, 1.21), 0.5);
        assert_eq!(m.height(1.0, 2.0), 0.5);
        assert_eq!(m.height(-1e-9, 1.0), NO_ROCK);
        assert_eq!(m.height(0.5, 2.0 + 1e-9), NO_ROCK);
        assert_eq!(m.allocated_tiles(), 0);
    }

    #[test]
    fn triangles_interpolate_a_plane_exactly_and_split_on_the_diagonal() {
        let mut m = small();
        // plane z = 2x - 3y + 1 is reproduced exactly by both triangles
        for i in 0..11 {
            for j in 0..21 {
                let (x, y) = m.grid().node_xy(i, j);
                m.set_node(i, j, 2.0 * x - 3.0 * y + 1.0);
            }
        }
        for &(x, y) in &[(0.33, 0.71), (0.36, 0.72), (0.99, 1.99), (0.0, 0.0)] {
            let p = m.point(x, y).unwrap();
            assert!((p.z - (2.0 * x - 3.0 * y + 1.0)).abs() < 1e-12);
            assert!((p.dzdx - 2.0).abs() < 1e-9 && (p.dzdy + 3.0).abs() < 1e-9);
        }
        // one raised node (1,1) of cell (0..1,0..1): lower triangle (fu > fv)
        // uses nodes (0,0),(1,0),(1,1); upper uses (0,0),(0,1),(1,1)
        let mut m = small();
        m.set_node(1, 0, 1.5); // only in the lower triangle
        let lower = m.height(0.08, 0.02); // fu = 0.8, fv = 0.2
        let upper = m.height(0.02, 0.08); // fu = 0.2, fv = 0.8
        assert!((lower - (0.5 + 1.0 * (0.8 - 0.2))).abs() < 1e-12, "{lower}");
        assert_eq!(upper, 0.5);
    }

    #[test]
    fn clones_share_tiles_until_written() {
        let mut a = small();
        a.set_node(1, 1, 0.25);
        a.set_node(10, 20, 0.125); // same tile (the map is smaller than one tile)
        let b = a.clone();
        let shared = |m: &HeightMap, n: &HeightMap| {
            m.tiles()
                .zip(n.tiles())
                .filter(|(x, y)| matches!((x, y), (Some(x), Some(y)) if Arc::ptr_eq(&x.d, &y.d)))
                .count()
        };
        assert_eq!(shared(&a, &b), a.allocated_tiles());
        let mut c = b.clone();
        c.set_node(1, 1, 0.0);
        // the write copied the tile for c alone: a and b are unchanged and still share
        assert_eq!(a.node(1, 1), 0.25);
        assert_eq!(b.node(1, 1), 0.25);
        assert_eq!(c.node(1, 1), 0.0);
        assert_eq!(c.node(10, 20), 0.125);
        assert_eq!(shared(&a, &b), 1);
        assert_eq!(shared(&a, &c), 0);
        assert_ne!(a, c);
        assert_eq!(a, b);
        // the directory's rows are shared too, until a write unshares one
        let rows_shared = |m: &HeightMap, n: &HeightMap| {
            m.rows
                .iter()
                .zip(&n.rows)
                .filter(|(x, y)| Arc::ptr_eq(x, y))
                .count()
        };
        assert_eq!(rows_shared(&a, &b), a.rows.len());
        assert_eq!(rows_shared(&a, &c), a.rows.len() - 1);
    }

    #[test]
    fn a_clone_shares_the_rows_of_tiles_until_a_write_and_a_read_only_walk_keeps_them() {
        // 4 x 3 tiles; rows of tiles 0 and 2 written
        let g = Grid::new(0.0, 0.127, 0.0, 0.095, 128, 96);
        let mut m = HeightMap::flat(g, 0.0);
        m.set_node(5, 5, -0.001);
        m.set_node(100, 70, -0.002);
        let snap = m.clone();
        let same = |a: &HeightMap, b: &HeightMap, r: usize| Arc::ptr_eq(&a.rows[r], &b.rows[r]);
        // a walk that lowers nothing leaves every row shared
        m.lower_row(5, 0, 127, |_| None);
        assert!((0..3).all(|r| same(&m, &snap, r)));
        // a write unshares its row only; the other rows stay shared
        m.lower_row(70, 90, 110, |z| (z > -0.0015).then_some(-0.0015));
        assert!(same(&m, &snap, 0) && same(&m, &snap, 1) && !same(&m, &snap, 2));
        assert_eq!(m.node(100, 70), -0.002);
        assert_eq!(m.node(95, 70), -0.0015);
        assert_eq!(snap.node(95, 70), 0.0);
        // patches unshare the rows they cover and write through them
        let mut p = m.clone();
        let rect = p.tile_rect(0, 40, 0, 40); // tiles 0..=1 x 0..=1
        let mut patches = p.patches(&[rect]).unwrap();
        patches[0].lower_row(33, 0, 40, |z| Some(z - 0.001));
        drop(patches);
        assert!(!same(&p, &m, 0) && !same(&p, &m, 1) && same(&p, &m, 2));
        assert_eq!(p.node(40, 33), -0.001);
        assert_eq!(m.node(40, 33), 0.0);
        // out of range rectangles are refused
        let bad = TileRect {
            ti: [3, 4],
            tj: [0, 0],
        };
        assert!(p.patches(&[bad]).is_none());
    }

    #[test]
    fn writes_allocate_only_their_tile() {
        let mut m = HeightMap::flat(Grid::new(0.0, 10.0, 0.0, 10.0, 10_001, 10_001), 0.0);
        assert!(m.memory_bytes() < 2_000_000, "{}", m.memory_bytes());
        m.set_node(5000, 5000, -0.001);
        assert_eq!(m.allocated_tiles(), 1);
        assert_eq!(m.node(5000, 5000), -0.001);
        assert_eq!(m.node(5001, 5000), 0.0);
        assert!(m.max_height(4990, 5010, 4990, 5010) >= 0.0);
    }
}
