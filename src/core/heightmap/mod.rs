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
//!
//! **Where the code is.** This file holds the map and its reads and writes;
//! `grid.rs` the grid's geometry, `tile.rs` a tile's storage and its runs of
//! writes, `patch.rs` the writable rectangles of tiles that cuts far apart
//! use at once, `undo.rs` a step's undo record.

use std::sync::Arc;

mod grid;
mod patch;
mod tile;
mod undo;

pub use grid::Grid;
pub use patch::{Patch, TileRect};
use tile::*;
use undo::*;

/// Nodes along each side of a tile.
pub const TILE: usize = 32;
const TILE_NODES: usize = TILE * TILE;

/// Height returned outside the map: there is no rock there.
pub const NO_ROCK: f64 = f64::NEG_INFINITY;

/// Words of a tile's cut mask.
const MASK_WORDS: usize = TILE_NODES / 64;

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
        self.highest_over([x - r, x + r, y - r, y + r])
    }

    /// An upper bound of the rock over the plan box `[x0, x1, y0, y1]`
    /// plus a cell (the nodes of that box; [`HeightMap::max_height`]),
    /// `None` when the box misses the map: over a disc's plan box
    /// ([`PosedDisc::plan_box`]), the highest rock the disc can meet, from
    /// fewer tiles than [`HeightMap::highest_within`]'s square (a thin strip
    /// for an upright disc).
    ///
    /// [`PosedDisc::plan_box`]: crate::core::cutter::PosedDisc::plan_box
    pub fn highest_over(&self, [x0, x1, y0, y1]: [f64; 4]) -> Option<f64> {
        let g = self.grid();
        g.node_range(x0 - g.dx, x1 + g.dx, y0 - g.dy, y1 + g.dy)
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

    // (`tile_rect` and `patches`: patch.rs; `begin_undo`, `commit_undo` and
    // `rollback`: undo.rs)

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
mod tests;
