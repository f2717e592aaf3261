//! A step's undo record: each node write with what it overwrote, and the
//! tiles the step allocated.

use super::*;

#[derive(Debug, Clone, PartialEq, Default)]
pub(super) struct Undo {
    pub(super) open: bool,
    /// Tiles the change allocated (absent before it).
    pub(super) allocated: Vec<usize>,
    /// Node writes in order, with what they overwrote.
    pub(super) writes: Vec<Overwritten>,
}

/// One node write of an open undo record and what it overwrote.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Overwritten {
    pub(super) tile: usize,
    pub(super) node: usize,
    pub(super) z: f64,
    pub(super) cut_word: u64,
    pub(super) z_max: f64,
}

impl HeightMap {
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
}
