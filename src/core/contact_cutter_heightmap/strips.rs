//! The tip's strips as the part of each that touches the rock: the edge
//! between touching and free slices found by bisection (`engaged_strips`),
//! and strips integrated in thirds (`split_in_thirds`).

use super::*;

/// Bisections that place the edge of the contact across the tip: the
/// interval between two samples is split to `2^-EDGE_BISECTIONS` of its width.
pub(super) const EDGE_BISECTIONS: usize = 6;
/// After this many bisections the edge is told free or not (at the middle
/// of its bracket, an eighth of the interval): a free edge needs no more.
pub(super) const FREE_AFTER: usize = 5;

/// The strip a free edge lies in, between samples `i` and `i + 1` of the
/// tip (sample 0 the tip's edge `-h`, sample `k + 1` slice `k`, sample
/// `n + 1` the edge `h`), read at `c`, the middle of its bracket.
pub(super) fn split_strip(h: f64, n: usize, i: usize, c: f64) -> usize {
    if i == 0 {
        0
    } else if i == n || c < -h + 2.0 * h * i as f64 / n as f64 {
        i - 1
    } else {
        i
    }
}

/// Tilt (the sine of the axle's slope) from which a strip that a free edge
/// crosses is split in thirds (`engaged_strips`); blended in from upright.
///
/// Near a free edge the outermost touching slice's arc starts at its lowest
/// point, a few micrometres inside the elastic layer, and is carried on by
/// the look-ahead; on a tilted disc's upper side that start comes and goes
/// as the tilt moves the circle a few tens of micrometres against the cut
/// its neighbours leave, switching a ninth of the tip (36 -> 36.5 degrees:
/// 5.2 % of the reference normal force). Integrating that strip in thirds
/// cuts the switch to a third. An upright disc keeps the midpoint rule at
/// its free edges (a fresh cut's sides, shallower than 1.7 mm): the pressure
/// level is calibrated on it, so fresh cuts stay the closed form bit for bit.
pub(super) const SPLIT_TILT: f64 = 0.087;

/// Depth \[m\] by which a slice's arc must break with the mean of its
/// neighbours' before its strip is integrated in thirds (fully at twice
/// that); at least three times the tip profile's own curvature there.
pub(super) const UNEVEN_DEPTH: f64 = 0.3e-3;

/// Splits rim slice `k`'s strip (middle `yk`, width `w`) in thirds,
/// blended in by `s`: the slice keeps `1 - 2 s / 3` of its strip and two
/// new circles at the middles of the outer thirds, walked by `walk_at`,
/// carry `s / 3` each.
pub(super) fn split_in_thirds(
    surface: &mut Surface,
    (k, yk, w): (usize, f64, f64),
    s: f64,
    walk_at: &dyn Fn(f64) -> Walked,
    disc: &PosedDisc,
) {
    surface.circles[k].width = w * (1.0 - 2.0 * s / 3.0);
    surface.circles[k].sub = true;
    for y in [yk - w / 3.0, yk + w / 3.0] {
        let c = Circle {
            y,
            radius: disc.rho(y),
            width: s * w / 3.0,
            face: 0.0,
            flank: false,
            sub: true,
        };
        surface.push(c, walk_at(y));
    }
}

/// The rim slices that touch the rock over part of their strip only, into
/// `out` (one entry for each of the `n` slices, `None` on entry): `Some((y, width))`, the
/// middle and width of the touching part (width 0: none); `None`, the slice
/// as it is. `split` (`false` on entry) marks the strips to integrate in
/// thirds, where an edge is free (below).
///
/// Whether a circle touches the rock is a yes/no reading of the height map
/// (the rim inside the interpolated rock by micrometres; for a disc rolling
/// along, on the side of the circle that drives alone,
/// `Query::probe_sides`). Where the wall of a groove cut earlier (or by
/// another part of a tilted disc) meets rock the disc is in, the answer
/// switches within a hundredth of a cell of a node row, so sampling each
/// slice at its middle switched the whole strip's
/// load (a ninth of the tip) on or off as that middle crossed a node row.
/// Here the edge of the contact is found by bisection between neighbouring
/// samples (the slices' middles and the tip's edges) that answer
/// differently, and each slice carries the touching part of its strip,
/// sampled at that part's middle: the load grows with the touching width.
///
/// An edge where the rock beyond is uncut face (`free(y)`: the rim rises out
/// of the face, as at the sides of a fresh groove) is left at the strip
/// boundary, as the midpoint rule puts it: the arcs there shrink to nothing
/// by themselves, and the map's chord between the last cut and the first
/// uncut node row lies below the round tip, so bisection would place such
/// an edge up to half a cell inside the true one. A fresh cut is therefore
/// unchanged, bit for bit. (Whether an edge is free is read at its bracket
/// after `FREE_AFTER` bisections.)
pub(super) fn engaged_strips(
    h: f64,
    n: usize,
    touches_slice: impl Fn(usize) -> bool,
    touches: impl Fn(f64) -> bool,
    free: impl Fn(f64) -> bool,
    out: &mut [Option<(f64, f64)>],
    split: &mut [bool],
) {
    let w = 2.0 * h / n as f64;
    // strip boundaries: b(k) is the lower edge of strip k, b(n) = h
    let b = |k: usize| {
        if k == 0 {
            -h
        } else if k == n {
            h
        } else {
            -h + w * k as f64
        }
    };
    // the samples across the tip with their answers: the edges and the
    // slices; sample i + 1 is slice i
    // (arrays sized by `n`, not by the 101 slices at most: filling those
    // and returning `out` touched some 7 kB a contact, for 9 slices)
    let mut pts = ArrayVec::<(f64, bool), 103>::new();
    pts.push((-h, touches(-h)));
    pts.extend((0..n).map(|k| (slice_y(h, n, k), touches_slice(k))));
    pts.push((h, touches(h)));
    if pts.iter().all(|p| p.1) {
        return;
    }
    // the touching spans across the tip
    let mut spans = ArrayVec::<(f64, f64), 52>::new();
    let mut open: Option<f64> = pts[0].1.then_some(-h);
    for i in 0..n + 1 {
        let ((ya, ta), (yb, tb)) = (pts[i], pts[i + 1]);
        if ta == tb {
            continue;
        }
        let (mut lo, mut hi) = (ya, yb); // lo answers ta, hi answers tb
        let mut edge = None;
        for j in 0..EDGE_BISECTIONS {
            if j == FREE_AFTER && free(0.5 * (lo + hi)) {
                // the boundary between the two samples' strips; the strip
                // the edge lies in (sample i is slice i - 1) is split
                edge = Some(b(i));
                split[split_strip(h, n, i, 0.5 * (lo + hi))] = true;
                break;
            }
            let m = 0.5 * (lo + hi);
            if touches(m) == ta {
                lo = m;
            } else {
                hi = m;
            }
        }
        let edge = edge.unwrap_or(0.5 * (lo + hi));
        if ta {
            if let Some(s) = open.take() {
                // (spans past the 52nd are left out)
                let _ = spans.try_push((s, edge));
            }
        } else {
            open = Some(edge);
        }
    }
    if let Some(s) = open {
        let _ = spans.try_push((s, h));
    }
    for (k, o) in out.iter_mut().enumerate() {
        let (lo, hi) = (b(k), b(k + 1));
        if spans.iter().any(|&(s, e)| s <= lo && e >= hi) {
            continue;
        }
        let (mut total, mut best) = (0.0f64, (0.0f64, 0.0f64));
        for &(s, e) in &spans {
            let (s, e) = (s.max(lo), e.min(hi));
            if e > s {
                total += e - s;
                if e - s > best.1 - best.0 {
                    best = (s, e);
                }
            }
        }
        *o = Some((0.5 * (best.0 + best.1), total));
    }
    // a split strip keeps its middle as the middle third's sample; one that
    // carries part of its strip at a wall is not split as well
    for (sp, o) in split.iter_mut().zip(out.iter()) {
        if o.is_some_and(|(_, wd)| wd > 0.0) {
            *sp = false;
        }
    }
}
