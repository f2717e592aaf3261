//! Writable rectangles of a map's tiles (`HeightMap::patches`), so that
//! cuts far apart can run at once.

use super::*;

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

impl HeightMap {
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
}
