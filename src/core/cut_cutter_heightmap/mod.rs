//! Cutting the rock (thesis ch. 8 and App. B), for the nodes under the disc
//! only: the thesis visited every node of the face at every step.
//!
//! Rock support is elastic-perfectly-plastic. The rock takes the rim
//! `elastic_depth` deep elastically; past that it yields (at the CSM
//! pressure, which is what the contact force carries). A cut therefore moves
//! each node that lies more than `elastic_depth` above the disc's lower
//! boundary down by `plastic_fraction` of that excess (1.0 is the thesis's
//! fully plastic ch. 8, 0.5 its App. B). The rock keeps touching the rim
//! through the elastic layer, so a cutter pressed in and held still keeps its
//! load instead of sinking through the rock (the thesis dropped the force to
//! zero one step after the rock under the cutter was removed).
//!
//! **Where the code is.** The cut itself ([`cut`], [`cut_patch`]: the walk
//! of a window's nodes) is in this file; beside it, what bounds the walk:
//! - `front.rs`: how far ahead of a moving disc its cut reaches;
//! - `back.rs`: the box behind a rolling disc that its last cut already took;
//! - `window.rs`: each row's nodes, from the footprint, the front and the box.

use super::contact_law::smoothstep;
use super::cutter::{Columns, PosedDisc};
use super::heightmap::{Grid, HeightMap, Patch, TileRect};
use super::params::Numerics;
use nalgebra::{Matrix3, Vector3};

mod back;
mod front;
mod window;

pub use back::*;
pub use front::*;
pub use window::*;

/// What one cut removed.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CutStats {
    /// Volume removed \[m3\] (node drop times cell area).
    pub volume: f64,
    /// Nodes lowered.
    pub nodes: usize,
}

/// Smallest node drop \[m\] that counts as a cut (keeps Model Exchange from
/// asking for events that would change nothing measurable).
pub const CUT_TOLERANCE: f64 = 1e-10;

/// The nodes a cut walks, a row at a time: `lower_row(j, i0, i1, f)` runs
/// `f` over the heights of nodes `i0..=i1` of row `j` in order and lowers
/// each node for which it returns a height. A read-only view stops at the
/// first such node instead and returns `true`.
trait Nodes {
    fn grid(&self) -> &Grid;
    fn lower_row(
        &mut self,
        j: usize,
        i0: usize,
        i1: usize,
        f: impl FnMut(f64) -> Option<f64>,
    ) -> bool;
}

/// The map and a patch of it are walked alike: they write and go on.
macro_rules! writable_nodes {
    ($t:ty) => {
        impl Nodes for $t {
            fn grid(&self) -> &Grid {
                <$t>::grid(self)
            }
            fn lower_row(
                &mut self,
                j: usize,
                i0: usize,
                i1: usize,
                f: impl FnMut(f64) -> Option<f64>,
            ) -> bool {
                <$t>::lower_row(self, j, i0, i1, f);
                false
            }
        }
    };
}
writable_nodes!(HeightMap);
writable_nodes!(Patch<'_>);

/// A view for probing: [`sweep_nodes`] without a fraction never writes.
struct ReadOnly<'a>(&'a HeightMap);

impl Nodes for ReadOnly<'_> {
    fn grid(&self) -> &Grid {
        self.0.grid()
    }
    fn lower_row(
        &mut self,
        j: usize,
        i0: usize,
        i1: usize,
        mut f: impl FnMut(f64) -> Option<f64>,
    ) -> bool {
        (i0..=i1).any(|i| f(self.0.node(i, j)).is_some())
    }
}

/// Walks the nodes of the window that lie more than `elastic_depth +
/// CUT_TOLERANCE` above the disc's lower boundary. With `fraction` it lowers
/// each by that share of its excess; without, it stops at the first one.
fn sweep_nodes<M: Nodes>(
    map: &mut M,
    w: &Window,
    disc: &PosedDisc,
    elastic_depth: f64,
    fraction: Option<f64>,
) -> (CutStats, bool) {
    let mut stats = CutStats::default();
    let g = *map.grid();
    let sweep = Sweep::new(disc, &g, elastic_depth, fraction);
    for j in w.j0..=w.j1 {
        let Some((r0, r1)) = w.row(j) else {
            continue;
        };
        // a row that keeps its axle coordinate (heading along a grid axis;
        // rounding of a spinning pose may leave it drifting by less than
        // 1e-15 m, nothing to the heights) lies in one vertical plane,
        // whose lowest point of the solid bounds the cut
        let flat_row = (sweep.step.y * (r1 - r0) as f64).abs() <= 1e-15;
        let (x0, y) = g.node_xy(r0, j);
        // (each node's local coordinates count from the row's first node,
        // whichever run of the row it lies in: a gap changes no height)
        let a0 = sweep.rt * Vector3::new(x0 - disc.centre.x, y - disc.centre.y, -disc.centre.z);
        for (i0, i1) in w.runs(j) {
            let run = (j, i0, i1);
            let stopped = if sweep.horizontal {
                sweep.upright_run(map, run, (a0, i0 - r0, flat_row), &mut stats)
            } else {
                sweep.tilted_run(map, run, (a0, i0 - r0, flat_row), &mut stats)
            };
            if stopped {
                return (stats, true);
            }
        }
    }
    (stats, stats.nodes > 0)
}

/// What a cut's walk of its window knows of the disc, found once a cut:
/// the vertical lines through the nodes in the disc's frame, and what a
/// node above the disc's lower boundary becomes.
struct Sweep<'a> {
    disc: &'a PosedDisc,
    /// The rock frame to the disc's.
    rt: Matrix3<f64>,
    /// The rock's vertical, and one node along a row, in the disc's frame.
    d: Vector3<f64>,
    step: Vector3<f64>,
    /// The axle is horizontal: each node's vertical line lies in a plane
    /// across the axle.
    horizontal: bool,
    /// A tilted flank-less disc's lines, with what depends on their
    /// direction found once a cut.
    columns: Option<Columns<'a>>,
    /// The solid's half-width: the hub's with flanks (`rho_full` is the tip
    /// profile across the tip, bit for bit).
    h: f64,
    lowering: Lowering,
}

/// What a node above the disc's lower boundary becomes: lowered by
/// `fraction` of its excess over the elastic layer, or, without a fraction
/// (a probe), only found.
#[derive(Clone, Copy)]
struct Lowering {
    elastic_depth: f64,
    fraction: Option<f64>,
    area: f64,
}

impl Lowering {
    /// What a node at `z` above the boundary `z_low` becomes (`None`: it
    /// stays).
    #[inline(always)]
    fn apply(self, stats: &mut CutStats, z: f64, z_low: f64) -> Option<f64> {
        let excess = z - (z_low + self.elastic_depth);
        if excess <= CUT_TOLERANCE {
            return None;
        }
        let Some(f) = self.fraction else {
            return Some(z);
        };
        let drop = f * excess;
        stats.volume += drop * self.area;
        stats.nodes += 1;
        Some(z - drop)
    }
}

impl<'a> Sweep<'a> {
    fn new(disc: &'a PosedDisc, g: &Grid, elastic_depth: f64, fraction: Option<f64>) -> Self {
        let rt = disc.rot.transpose();
        let d = rt.column(2).into_owned();
        let horizontal = d.y.abs() < 1e-12;
        Self {
            disc,
            rt,
            d,
            step: rt.column(0) * g.dx,
            horizontal,
            columns: (!horizontal && !disc.has_flanks()).then(|| Columns::new(disc, d)),
            h: disc.hub_half_width,
            lowering: Lowering {
                elastic_depth,
                fraction,
                area: g.cell_area(),
            },
        }
    }

    /// Nodes `i0..=i1` of row `j` under a horizontal axle; `a0` is the local
    /// point of the row's first node, which lies `skipped` nodes before
    /// `i0`, and `flat` says the row keeps its axle coordinate. Returns
    /// whether a probe stopped.
    ///
    /// The vertical line through a node stays in the plane y_local = q.y
    /// and meets the rim circle of radius rho(q.y) there. With b = q.d (d
    /// is a unit vector in the x-z plane) and w the offset across d in that
    /// plane, the lower boundary is -b - sqrt(rho^2 - w^2). q.y, b and w
    /// are affine along the row: node k's are start + k * step.
    ///
    /// (The two kinds of run take the row's parts as arguments: a struct
    /// of them built for each run made a gauge cutter's step 0.6 % dearer,
    /// 235.4 against 234.0 k instructions, `tools/instr_per_step.py`.)
    #[inline(always)]
    fn upright_run<M: Nodes>(
        &self,
        map: &mut M,
        (j, i0, i1): (usize, usize, usize),
        (a0, skipped, flat): (Vector3<f64>, usize, bool),
        stats: &mut CutStats,
    ) -> bool {
        let (a, d, step, disc, h) = (a0, &self.d, &self.step, self.disc, self.h);
        let lowering = self.lowering;
        let (b0, db) = (a.x * d.x + a.z * d.z, step.x * d.x + step.z * d.z);
        let (w0, dw) = (a.x * d.z - a.z * d.x, step.x * d.z - step.z * d.x);
        let (y0, dy) = (a.y, step.y);
        // (the plane's solid is the rim circle at y_local)
        let floor = if flat && y0.abs() <= h {
            disc.centre.z - disc.rho_full(y0) + lowering.elastic_depth + CUT_TOLERANCE
        } else {
            f64::NEG_INFINITY
        };
        let mut k = skipped as f64 - 1.0;
        map.lower_row(j, i0, i1, |z| {
            k += 1.0;
            if z <= floor {
                return None;
            }
            let qy = y0 + k * dy;
            if qy.abs() > h {
                return None;
            }
            let rho = disc.rho_full(qy);
            let w = w0 + k * dw;
            let disc2 = rho * rho - w * w;
            if disc2 < 0.0 {
                return None;
            }
            lowering.apply(stats, z, -(b0 + k * db) - disc2.sqrt())
        })
    }

    /// [`Sweep::upright_run`] under a tilted axle: each node's vertical line
    /// solved for its lower end in the solid below the node.
    #[inline(always)]
    fn tilted_run<M: Nodes>(
        &self,
        map: &mut M,
        (j, i0, i1): (usize, usize, usize),
        (a0, skipped, flat): (Vector3<f64>, usize, bool),
        stats: &mut CutStats,
    ) -> bool {
        let (disc, d, step) = (self.disc, &self.d, self.step);
        let (lowering, columns) = (self.lowering, self.columns.as_ref());
        let elastic_depth = lowering.elastic_depth;
        let mut a = a0;
        for _ in 0..skipped {
            a += step;
        }
        // (a plane that misses the solid: nothing to cut in the row)
        let floor = if flat && !disc.has_flanks() {
            disc.row_floor(&a0, d, &step)
                .map_or(f64::INFINITY, |t| t + elastic_depth + CUT_TOLERANCE)
        } else {
            f64::NEG_INFINITY
        };
        map.lower_row(j, i0, i1, |z| {
            // local coordinates are affine along a row
            let q = a;
            a += step;
            if z <= floor {
                return None;
            }
            let cap = z - elastic_depth - CUT_TOLERANCE;
            let z_low = match columns {
                Some(c) => c.lower_end(&q, cap)?.0,
                None => disc.column_lower_end(&q, d, cap)?.0,
            };
            lowering.apply(stats, z, z_low)
        })
    }
}

/// Cuts the rock at the disc's pose, no further than `front` ahead and
/// leaving out the `back` box.
pub fn cut(
    map: &mut HeightMap,
    disc: &PosedDisc,
    elastic_depth: f64,
    plastic_fraction: f64,
    (front, back): (Option<Front>, Option<Back>),
) -> CutStats {
    match node_window(map, disc, front, back) {
        Some(w) => sweep_nodes(map, &w, disc, elastic_depth, Some(plastic_fraction)).0,
        None => CutStats::default(),
    }
}

/// [`cut`] on a patch of the map that holds the window's tiles
/// ([`Window::tiles`]), with a window found on the map before the patch
/// was taken (or since): the same nodes fall, to the same heights.
pub fn cut_patch(
    patch: &mut Patch<'_>,
    w: &Window,
    disc: &PosedDisc,
    elastic_depth: f64,
    plastic_fraction: f64,
) -> CutStats {
    sweep_nodes(patch, w, disc, elastic_depth, Some(plastic_fraction)).0
}

/// Would [`cut`] at this pose lower any node?
pub fn would_cut(map: &HeightMap, disc: &PosedDisc, elastic_depth: f64) -> bool {
    node_window(map, disc, None, None)
        .is_some_and(|w| sweep_nodes(&mut ReadOnly(map), &w, disc, elastic_depth, None).1)
}

#[cfg(test)]
mod tests {
    use super::{Bounds, Front, Window};
    use crate::core::heightmap::Grid;

    /// A window's node box (the tiles a cut takes) is the box of the runs
    /// it walks, row by row, on windows with and without gaps: gaps inside
    /// a row, at either end, over a whole row and over none, and rows with
    /// no nodes.
    #[test]
    fn a_windows_node_box_is_the_box_of_its_runs() {
        let mut next = crate::core::uniforms(0x2545_f491_4f6c_dd1d_u64);
        let mut pick = |n: usize| ((next() * n as f64) as usize).min(n - 1);
        let (mut gapped, mut empty) = (0, 0);
        for _ in 0..20000 {
            let j0 = pick(50);
            let n = 1 + pick(12);
            let rows: Vec<Option<(usize, usize)>> = (0..n)
                .map(|_| {
                    (pick(5) > 0).then(|| {
                        let i0 = pick(40);
                        (i0, i0 + pick(8))
                    })
                })
                .collect();
            let gaps: Vec<Option<(usize, usize)>> = if pick(3) == 0 {
                Vec::new()
            } else {
                rows.iter()
                    .map(|r| {
                        r.filter(|_| pick(3) > 0).map(|(i0, i1)| {
                            let g0 = i0 + pick(i1 - i0 + 1);
                            (g0, g0 + pick(i1 - g0 + 1))
                        })
                    })
                    .collect()
            };
            gapped += usize::from(gaps.iter().any(Option::is_some));
            let w = Window {
                j0,
                j1: j0 + n - 1,
                rows,
                gaps,
            };
            let mut b: Option<[usize; 4]> = None;
            for j in w.j0..=w.j1 {
                for (i0, i1) in w.runs(j) {
                    let v = b.get_or_insert([i0, i1, j, j]);
                    *v = [v[0].min(i0), v[1].max(i1), v[2].min(j), v[3].max(j)];
                }
            }
            empty += usize::from(b.is_none());
            assert_eq!(w.node_box(), b, "{w:?}");
        }
        assert!(
            gapped > 5000 && empty > 10,
            "{gapped} gapped, {empty} empty"
        );
    }

    /// The rows a front leaves out ([`Front::rows_within`]) are rows the
    /// window's own bounds find empty, for fronts in every direction
    /// (including along and across the grid) and heading boxes turned
    /// every way, and a front does leave rows out.
    #[test]
    fn rows_a_front_leaves_out_hold_no_node() {
        let g = Grid::new(-0.3, 0.3, -0.3, 0.3, 601, 601);
        let mut next = crate::core::uniforms(0x9e37_79b9_7f4a_7c15_u64);
        let (mut left_out, mut cases) = (0usize, 0usize);
        for case in 0..20000 {
            // a quarter of the headings and fronts on the grid's axes (to
            // round-off), the rest anywhere
            let (heading, travel) = if case % 4 == 0 {
                let axis = std::f64::consts::FRAC_PI_2 * ((case / 4) % 4) as f64;
                let h = axis + 1e-13 * (next() - 0.5);
                (h, h + 1e-13 * (next() - 0.5))
            } else {
                let h = 2.0 * std::f64::consts::PI * next();
                (h, h + 0.3 * (next() - 0.5))
            };
            let (s, c) = heading.sin_cos();
            let (cx, cy) = (0.2 * (next() - 0.5), 0.2 * (next() - 0.5));
            let (uc, vc) = (cx * c + cy * s, -cx * s + cy * c);
            let (len, half) = (0.02 + 0.06 * next(), 0.003 + 0.01 * next());
            let uv = [uc - len, uc + len, vc - half, vc + half];
            let reach = len.hypot(half);
            let x = [cx - reach * next(), cx + reach * next()];
            let dir = (travel.cos(), travel.sin());
            let limit = cx * dir.0 + cy * dir.1 + 0.004 * (next() - 0.3);
            let front = Front { dir, limit };
            let bounds = Bounds::new(x, (c, s), uv, Some(front));
            let (j0, j1) = g
                .node_range(x[0], x[1], cy - reach, cy + reach)
                .map(|r| (r.2, r.3))
                .unwrap();
            let kept = front.rows_within(&g, x, j0, j1);
            for j in j0..=j1 {
                let inside = kept.is_some_and(|(a, b)| (a..=b).contains(&j));
                if !inside {
                    left_out += 1;
                    assert!(
                        bounds.row(&g, j).is_none(),
                        "case {case}: row {j} holds nodes"
                    );
                }
            }
            cases += 1;
        }
        assert!(
            left_out > 10 * cases,
            "{left_out} rows left out in {cases} cases"
        );
    }
}
