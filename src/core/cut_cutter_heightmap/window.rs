//! The nodes a cut may lower ([`Window`]): each row's bounds from the
//! disc's footprint, its heading and its front, less the box behind it.

use super::*;

/// The nodes a cut at this pose may lower: rows `j0..=j1`, and in each row
/// the nodes between two bounds on x.
///
/// The part of the disc below the highest rock near it lies in a box about
/// the disc's heading (found as the world box of the disc turned about the
/// vertical so that it heads along x); a row's nodes are those inside both
/// that box and the world box. A disc heading diagonally (most discs of a
/// cutterhead) scanned the whole world box of its footprint, up to six
/// times the nodes. The highest rock is taken twice: near the whole disc,
/// then under that first footprint only, which is tighter on a face that
/// is not flat (a cutterhead's face steps by a revolution's penetration).
#[derive(Debug, Clone)]
pub struct Window {
    pub(super) j0: usize,
    pub(super) j1: usize,
    /// Each row's node range (`rows[j - j0]`, `None`: none), found once:
    /// the tiles a cut writes and the cut itself read the same rows.
    pub(super) rows: Vec<Option<(usize, usize)>>,
    /// The part of each row's range a [`Back`] box leaves out, if any.
    pub(super) gaps: Vec<Option<(usize, usize)>>,
}

/// The bounds a [`Window`]'s rows are clipped to: the world box
/// `[x_lo, x_hi]`, the heading box (`u = x cos + y sin` in `[u_lo, u_hi]`,
/// `v = -x sin + y cos` in `[v_lo, v_hi]` about the rock origin) and the
/// front, each as a [`Strip`] (a strip across the heading box that is level
/// in `y` does not clip: the world box holds it).
pub(super) struct Bounds {
    pub(super) x: [f64; 2],
    pub(super) strips: [Option<Strip>; 3],
}

impl Bounds {
    pub(super) fn new(x: [f64; 2], (c, s): (f64, f64), uv: [f64; 4], front: Option<Front>) -> Self {
        let slope = |k: f64, m: f64, lo: f64, hi: f64| match Strip::new(k, m, lo, hi) {
            st @ Strip::Slope { .. } => Some(st),
            Strip::Level { .. } => None,
        };
        Self {
            x,
            strips: [
                slope(c, s, uv[0], uv[1]),
                slope(-s, c, uv[2], uv[3]),
                front.map(|f| Strip::new(f.dir.0, f.dir.1, f64::NEG_INFINITY, f.limit)),
            ],
        }
    }
}

impl Window {
    /// The tiles of `map` holding every node the window scans, or `None`
    /// when it scans none.
    pub fn tiles(&self, map: &HeightMap) -> Option<TileRect> {
        self.node_box()
            .map(|[i0, i1, j0, j1]| map.tile_rect(i0, i1, j0, j1))
    }

    /// The box `[i0, i1, j0, j1]` of every node the window scans, or `None`
    /// when it scans none: each row's first and last node outside its gap,
    /// read off the row and the gap (what [`Window::runs`] would walk; its
    /// chained runs cost some 50 instructions a row here, 1.7 % of a
    /// cutterhead's step).
    pub(super) fn node_box(&self) -> Option<[usize; 4]> {
        let (mut lo, mut hi, mut jl, mut jh) = (usize::MAX, 0, usize::MAX, 0);
        for (k, row) in self.rows.iter().enumerate() {
            let Some((i0, i1)) = *row else { continue };
            let (a, b) = match self.gaps.get(k).copied().flatten() {
                None => (i0, i1),
                // the runs are [i0, g0 - 1] if g0 > i0 and [g1 + 1, i1] if
                // g1 < i1
                Some((g0, g1)) => match (g0 > i0, g1 < i1) {
                    (true, true) => (i0, i1),
                    (true, false) => (i0, g0 - 1),
                    (false, true) => (g1 + 1, i1),
                    (false, false) => continue,
                },
            };
            let j = self.j0 + k;
            (lo, hi, jl, jh) = (lo.min(a), hi.max(b), jl.min(j), jh.max(j));
        }
        (jl <= jh).then_some([lo, hi, jl, jh])
    }

    /// The node range of row `j` (gap included), or `None`.
    pub(super) fn row(&self, j: usize) -> Option<(usize, usize)> {
        self.rows.get(j.wrapping_sub(self.j0)).copied().flatten()
    }

    /// How many nodes the cut walks.
    pub fn nodes(&self) -> usize {
        (self.j0..=self.j1)
            .flat_map(|j| self.runs(j))
            .map(|(i0, i1)| i1 - i0 + 1)
            .sum()
    }

    /// The node ranges of row `j` the cut walks: its range less its gap
    /// (none, one or two runs).
    pub(super) fn runs(&self, j: usize) -> impl Iterator<Item = (usize, usize)> {
        let row = self.row(j);
        let gap = self.gaps.get(j.wrapping_sub(self.j0)).copied().flatten();
        let [a, b] = match (row, gap) {
            (Some((i0, i1)), Some((g0, g1))) => [
                (g0 > i0).then(|| (i0, g0 - 1)),
                (g1 < i1).then(|| (g1 + 1, i1)),
            ],
            (row, _) => [row, None],
        };
        a.into_iter().chain(b)
    }
}

impl Bounds {
    /// The node range of row `j`, or `None`.
    pub(super) fn row(&self, g: &Grid, j: usize) -> Option<(usize, usize)> {
        let y = g.y_min + g.dy * j as f64;
        let [mut lo, mut hi] = self.x;
        for s in self.strips.iter().flatten() {
            (lo, hi) = s.clip(y, lo, hi)?;
        }
        // rounding: a node on the edge stays in
        let pad = 1e-9;
        let i0 = ((lo - pad - g.x_min) / g.dx).ceil().max(0.0);
        let i1 = ((hi + pad - g.x_min) / g.dx).floor().min((g.nx - 1) as f64);
        node_pair(i0, i1)
    }
}

/// The window of a cut at this pose on `map` (`None`: nothing to scan),
/// reaching no further than `front` ahead.
/// On a map a cut at another place has lowered since, it is still a window
/// of this cut: lower rock only shrinks the part of the disc below it.
pub fn node_window(
    map: &HeightMap,
    disc: &PosedDisc,
    front: Option<Front>,
    back: Option<Back>,
) -> Option<Window> {
    let g = map.grid();
    // (the rock under the disc's whole plan box bounds the part to scan;
    // the square of side 2R about the centre read some 200 tiles' bounds,
    // the most L2 misses of a head's step in callgrind's cache model)
    let z_top = map.highest_over(disc.plan_box())?;
    let bb = disc.footprint_below(z_top)?;
    let (i0, i1, j0, j1) = g.node_range(bb[0], bb[1], bb[2], bb[3])?;
    let z_top = map.max_height(i0, i1, j0, j1).min(z_top);
    let bb = disc.footprint_below(z_top)?;
    let (_, _, j0, j1) = g.node_range(bb[0], bb[1], bb[2], bb[3])?;
    // the disc turned by -heading about the rock's vertical axis
    let heading = disc.rot[(1, 0)].atan2(disc.rot[(0, 0)]);
    let (s, c) = heading.sin_cos();
    let turn = nalgebra::Matrix3::new(c, s, 0.0, -s, c, 0.0, 0.0, 0.0, 1.0);
    let turned = PosedDisc {
        rot: turn * disc.rot,
        centre: turn * disc.centre,
        ..*disc
    };
    let uv = turned.footprint_below(z_top)?;
    let bounds = Bounds::new([bb[0], bb[1]], (c, s), uv, front);
    let (j0, j1) = front.map_or(Some((j0, j1)), |f| f.rows_within(g, bounds.x, j0, j1))?;
    let rows: Vec<Option<(usize, usize)>> = (j0..=j1).map(|j| bounds.row(g, j)).collect();
    let gaps = match back.map(|b| b.rows()) {
        Some(b) => (j0..=j1)
            .zip(&rows)
            .map(|(j, r)| r.and_then(|(i0, i1)| b.gap(g, j, i0, i1)))
            .collect(),
        None => Vec::new(),
    };
    Some(Window { j0, j1, rows, gaps })
}

/// How many nodes [`cut`] or [`would_cut`] at this pose would scan at most.
pub fn window_nodes(map: &HeightMap, disc: &PosedDisc) -> usize {
    node_window(map, disc, None, None).map_or(0, |w| w.nodes())
}
