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

use super::cutter::PosedDisc;
use super::heightmap::HeightMap;

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

fn node_window(map: &HeightMap, disc: &PosedDisc) -> Option<(usize, usize, usize, usize)> {
    let g = map.grid();
    let r = disc.radius;
    let (i0, i1, j0, j1) = g.node_range(
        disc.centre.x - r - g.dx,
        disc.centre.x + r + g.dx,
        disc.centre.y - r - g.dy,
        disc.centre.y + r + g.dy,
    )?;
    let z_top = map.max_height(i0, i1, j0, j1);
    let bb = disc.footprint_below(z_top)?;
    g.node_range(bb[0], bb[1], bb[2], bb[3])
}

/// Visits every node of the window that lies more than `elastic_depth +
/// CUT_TOLERANCE` above the disc's lower boundary, with that excess; stops
/// early when `visit` returns `false`.
fn for_each_excess(
    map: &HeightMap,
    disc: &PosedDisc,
    elastic_depth: f64,
    mut visit: impl FnMut(usize, usize, f64) -> bool,
) {
    let Some((i0, i1, j0, j1)) = node_window(map, disc) else {
        return;
    };
    let g = *map.grid();
    let rt = disc.rot.transpose();
    let d = rt.column(2).into_owned();
    if d.y.abs() < 1e-12 {
        // axle horizontal: the local coordinates are affine along a row and
        // the lower boundary is the rim circle of radius rho(y_local)
        let step = rt.column(0) * g.dx;
        let h = disc.half_width;
        for j in j0..=j1 {
            let (x0, y) = g.node_xy(i0, j);
            let mut a =
                rt * nalgebra::Vector3::new(x0 - disc.centre.x, y - disc.centre.y, -disc.centre.z);
            for i in i0..=i1 {
                if a.y.abs() <= h {
                    let rho = disc.rho(a.y);
                    let b = a.x * d.x + a.z * d.z;
                    let disc2 = b * b - (a.x * a.x + a.z * a.z - rho * rho);
                    if disc2 >= 0.0 {
                        let excess = map.node(i, j) - (-b - disc2.sqrt() + elastic_depth);
                        if excess > CUT_TOLERANCE && !visit(i, j, excess) {
                            return;
                        }
                    }
                }
                a += step;
            }
        }
        return;
    }
    for j in j0..=j1 {
        for i in i0..=i1 {
            let (x, y) = g.node_xy(i, j);
            if let Some((zl, _)) = disc.lower_boundary(x, y) {
                let excess = map.node(i, j) - (zl + elastic_depth);
                if excess > CUT_TOLERANCE && !visit(i, j, excess) {
                    return;
                }
            }
        }
    }
}

/// Cuts the rock at the disc's pose.
pub fn cut(
    map: &mut HeightMap,
    disc: &PosedDisc,
    elastic_depth: f64,
    plastic_fraction: f64,
) -> CutStats {
    let mut drops = Vec::new();
    for_each_excess(map, disc, elastic_depth, |i, j, excess| {
        drops.push((i, j, plastic_fraction * excess));
        true
    });
    let area = map.grid().cell_area();
    let mut stats = CutStats::default();
    for (i, j, drop) in drops {
        let z = map.node(i, j);
        map.set_node(i, j, z - drop);
        stats.volume += drop * area;
        stats.nodes += 1;
    }
    stats
}

/// Would [`cut`] at this pose lower any node?
pub fn would_cut(map: &HeightMap, disc: &PosedDisc, elastic_depth: f64) -> bool {
    let mut any = false;
    for_each_excess(map, disc, elastic_depth, |_, _, _| {
        any = true;
        false
    });
    any
}
