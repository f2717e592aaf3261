//! Contact between the posed disc and the height map (thesis ch. 7, extended).
//!
//! **Where the rim touches.** The tip is cut into `n` slices across its width
//! (axle coordinates `y_k` from `-T/2` to `T/2`, `y = 0` included). On each
//! slice's rim circle the query starts at the lowest point and walks outwards
//! on both sides, finding the first arc `[a, b]` where the rim is below the
//! rock; the ends are refined by regula falsi. The whole circle can be
//! reached, the upper rim included (the thesis searched only the lower half,
//! its limitation 10.1). Where neighbouring slices disagree on touching the
//! rock at an older groove's wall, the edge between them is found by
//! bisection and those slices carry the touching part of their strip
//! (`engaged_strips`), so the load follows the wall continuously. A strip
//! that a tilted disc's free edge crosses (`SPLIT_TILT`), or whose slice's
//! arc depth breaks with its neighbours' (`UNEVEN_DEPTH`), is integrated in
//! thirds rather than at its middle alone.
//!
//! **The leading edge.** A height map blurs the corner where the groove meets
//! uncut rock over one cell, so the rim's exit from the rock would be found up
//! to a cell too early (0.19 mm of depth at 1 mm cells, 5 % of the reference
//! force). Contact therefore starts where the rim is inside the rock itself,
//! and lasts while it is inside the rock here or one cell further along the
//! walk (read bilinearly: no diagonal, so +y and -y are treated alike). On a
//! flat face the exit is then exact; a rim hovering over its own groove does
//! not start a contact from the groove's walls.
//!
//! **The force** is kerf's contact law (`contact_law`): the CSM pressure
//! integrated over the arcs where the surface is inside the rock and driving
//! into it, on every rim slice and, for a tilted disc, on rings of its lower
//! side face. Both sides of each circle are walked from its lowest point;
//! the arcs of the side that cuts weigh `p^4 / (p+^4 + p-^4)` by the depth
//! each side's driving arcs reach, so a cutter at rest in its own symmetric
//! pit pushes straight up, and one at rest after rolling keeps the load of
//! its leading arc.
//!
//! **Elastic layer.** A cut leaves the rock `elastic_depth` inside the rim
//! (see `cut_cutter_heightmap`), so a cutter held still keeps its contact.
//! Each arc's load is faded in over that depth (`smoothstep(u /
//! elastic_depth)`, `u` the deepest the surface is inside the rock on the
//! arc), so lifting the cutter off its groove unloads it without a jump.
//!
//! **Where the code is.** [`contact`] (this file) runs the query in order:
//! - `circles.rs`: the circles of the surface to walk (rim slices, side-face
//!   rings, flank bands) and their parts below the rock's top;
//! - `walk.rs`: one circle walked through the rock from its lowest point to
//!   its first arc's refined ends;
//! - `strips.rs`: how much of each tip strip touches the rock (the edge
//!   found by bisection, strips integrated in thirds);
//! - `load.rs`: each arc's load, scaled by the rock still there ahead, and
//!   the contact assembled from the summed loads.

use nalgebra::Vector3;

use super::contact_law::{
    arc_load_in, face_weight, pressure_level, smoothstep, Driving, Element, Load, Motion,
};
use super::csm::{contact_angle, CsmLaw};
use super::cutter::{wrap, PosedDisc};
use super::heightmap::HeightMap;
use super::params::Numerics;
use super::pose::Twist;

mod circles;
mod load;
mod strips;
mod walk;

pub use circles::*;
pub use load::*;
use strips::*;
pub use walk::*;

/// One side of one slice: the first contact arc from the lowest point.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Arc {
    /// Angle where the contact starts (nearest the lowest point) and ends.
    pub a: f64,
    pub b: f64,
    /// World-vertical depth of the arc, `z(b) - z(a)`.
    pub depth: f64,
    /// Arc length on the rim.
    pub length: f64,
    /// Largest overlap of the rock itself over the rim met on the arc (no
    /// look-ahead): how far the rim is inside the rock, for the elastic fade.
    pub u_max: f64,
}

/// The contact of a posed disc with the rock.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Contact {
    pub in_contact: bool,
    /// Penetration `p` (eq. 54) \[m\].
    pub penetration: f64,
    /// Contact angle `phi = acos((R - p)/R)`.
    pub phi: f64,
    /// Cutting force of the rim on the cutter, rock frame \[N\].
    pub rim_force: Vector3<f64>,
    /// Where the rim force acts, offset from the disc centre, rock frame.
    pub application: Vector3<f64>,
    /// Lowest point of the contact (offset from the centre) and the rim's
    /// inward unit normal there, rock frame: where friction reads the slip.
    pub slip_point: Vector3<f64>,
    pub slip_normal: Vector3<f64>,
    /// Moment of the rim force about the disc centre, rock frame.
    pub rim_moment: Vector3<f64>,
    /// Force and moment (about the centre) of the side faces, rock frame.
    pub side_force: Vector3<f64>,
    pub side_moment: Vector3<f64>,
}

/// Axle coordinate of slice `k` of `n`: the centre of the k-th of `n` equal
/// strips across the tip (`n` odd, so the middle slice is `y = 0`).
#[inline]
pub fn slice_y(h: f64, n: usize, k: usize) -> f64 {
    -h + 2.0 * h * (k as f64 + 0.5) / n as f64
}

/// The contact of `disc` with `map` under `law` (kerf's law), for a disc
/// moving with `twist` (rock frame).
pub fn contact(
    map: &HeightMap,
    disc: &PosedDisc,
    law: &CsmLaw,
    num: &Numerics,
    elastic_depth: f64,
    twist: &Twist,
) -> Contact {
    let g = map.grid();
    let none = Contact::default();
    // highest rock anywhere under the disc
    let Some(z_top) = map.highest_within(disc.centre.x, disc.centre.y, disc.radius) else {
        return none;
    };
    if disc.footprint_below(z_top).is_none() {
        return none;
    }
    let cell = g.dx.min(g.dy);
    let look = g.dx.max(g.dy);
    let n = num.tip_slices;
    let h = disc.half_width;
    let motion = Motion::new(disc, twist, look_ahead(look, num));

    let axle_z = disc.rot[(2, 1)];
    let w_face = face_weight(axle_z);
    // each face's share as the wall it drives into yields
    // (`Motion::face_yield`), over the reach of a cut as deep as the
    // highest rock near the disc
    let w_sides = if w_face > 0.0 {
        let reach = Motion::face_reach(disc, z_top);
        [1.0, -1.0].map(|side| w_face * motion.face_yield(side, reach, elastic_depth))
    } else {
        [0.0; 2]
    };
    let mut circles = [Circle::default(); MAX_CIRCLES];
    let mut nc = surface_circles(&mut circles, disc, n, z_top, cell, w_face > 0.0);

    // a moving disc's side face that drives into the rock nowhere ahead of
    // its lowest point carries no load (`Motion::face_drives_ahead`): its
    // rings are not walked then, unless the rim touches nothing (the disc is
    // in contact if a ring touches). Rolling straight, that is both faces,
    // exactly as the law gives (the whole-arc part weighs 1 - moving = 0 and
    // no ring has a driving part); turning, the face away from the turn's
    // centre. Flank bands are cones, which a rolling disc does drive into:
    // always walked.
    let rings_idle =
        |side: f64| motion.moving >= 1.0 && !motion.face_drives_ahead(side, disc.rho(h));
    let idle = [rings_idle(-1.0), rings_idle(1.0)];
    let ring_idle = |c: &Circle| c.is_ring() && idle[usize::from(c.face > 0.0)];
    // per circle, both sides: march first, then refine the ends of the arcs
    // on every side whose weight in the blend can matter
    let mut walks = [[None::<Walk>; 2]; MAX_CIRCLES];
    let step_len = num.arc_step_cells * cell;
    let walk = (step_len, look, !num.search_every_sample);
    // A moving disc loads only the driving parts of its arcs (the whole-arc
    // part weighs 1 - moving = 0), so a side of a circle that drives
    // nowhere within its reach carries nothing, nor does one that drives a
    // sliver only (`DRIVE_SLIVER_CELLS`): `drives` marks the sides that
    // carry load (all of them below the rest speed), and only those set the
    // bounds that choose the refinement, the arc depths that split strips
    // and the slip point. The other sides are not walked (unless
    // `numerics.walk_every_side`):
    // - on a rim slice, once the driving side has found an arc (so that
    //   whether the slice touches, and the disc is in contact, stays as
    //   walking both sides finds it): the trailing side of a rolling disc;
    // - on a face circle (ring or flank band), once the rim touches: on a
    //   gauge disc turning on its track, one side of each ring (its side
    //   face turns into the wall ahead and away from it behind).
    let mut drives = [[true; 2]; MAX_CIRCLES];
    let every = num.walk_every_side;
    // (with each circle's `Element::driving` where it was found, which the
    // loads read again)
    let mut drivings = [None::<Driving>; MAX_CIRCLES];
    // (the walks, some 400 bytes a circle, are written where they are
    // kept: passed back in the tuple they were copied twice more)
    let walk_circle_into = |c: &Circle, rim_touches: bool, out: &mut [Option<Walk>; 2]| {
        let Some(w) = SliceWalk::below(disc, (c.y, c.radius), z_top, walk) else {
            *out = [None, None];
            return ([true; 2], None);
        };
        if motion.moving < 1.0 {
            w.march_into(map, disc, Sides::Wanted([true; 2]), out);
            return ([true; 2], None);
        }
        let e = c.element(disc, &motion);
        let driving = e.driving();
        let d = w.sides_driving(&e, driving, DRIVE_SLIVER_CELLS * look / c.radius);
        let sides = if every || (c.face != 0.0 && !rim_touches) {
            Sides::Wanted([true; 2])
        } else if c.face != 0.0 {
            Sides::Wanted(d)
        } else if d[0] == d[1] {
            Sides::Wanted([true; 2])
        } else {
            Sides::DrivingFirst(d)
        };
        w.march_into(map, disc, sides, out);
        (d, Some(driving))
    };
    let walk_circle = |c: &Circle, rim_touches: bool| -> Walked {
        let mut pair = [None, None];
        let (d, driving) = walk_circle_into(c, rim_touches, &mut pair);
        (pair, d, driving)
    };
    let mut rim_touches = false;
    for (ci, c) in circles[..nc].iter().enumerate() {
        if ring_idle(c) && rim_touches {
            continue;
        }
        (drives[ci], drivings[ci]) = walk_circle_into(c, rim_touches, &mut walks[ci]);
        rim_touches |= c.face == 0.0 && walks[ci].iter().any(Option::is_some);
    }
    // the rim slices as the part of their strip that touches the rock
    let walk_at = |y: f64| {
        let c = Circle {
            y,
            radius: disc.rho(y),
            ..Circle::default()
        };
        walk_circle(&c, true)
    };
    // (a disc at rest keeps the midpoint rule: lifted off its pit, the
    // circles that still touch alternate with the node rows, no single
    // edge; the rule blends in with the travel speed)
    let m = motion.moving;
    let (engaged, split) = if m > 0.0 {
        engaged_strips(
            h,
            n,
            |k| walks[k].iter().any(Option::is_some),
            |y| {
                SliceWalk::below(disc, (y, disc.rho(y)), z_top, walk)
                    .is_some_and(|w| w.touches(map, disc))
            },
            |y| {
                let rho = disc.rho(y);
                disc.arc_below(y, rho, z_top).is_none_or(|(theta0, _)| {
                    let p = disc.to_world(&disc.rim_point_local(theta0, y));
                    map.any_uncut(p.x, p.y)
                })
            },
        )
    } else {
        ([None; 101], [false; 101])
    };
    let w_strip = 2.0 * h / n as f64;
    for (k, e) in engaged.iter().enumerate().take(n) {
        if let Some((y, width)) = *e {
            let yk = slice_y(h, n, k);
            let (y, width) = if walks[k].iter().any(Option::is_some) {
                (yk + m * (y - yk), w_strip + m * (width - w_strip))
            } else {
                (y, m * width)
            };
            circles[k].y = y;
            circles[k].radius = disc.rho(y);
            circles[k].width = width;
            (walks[k], drives[k], drivings[k]) = if width > 0.0 {
                walk_at(y)
            } else {
                ([None, None], [true; 2], None)
            };
        }
    }
    // a strip a free edge crosses on a tilted disc is integrated in thirds:
    // its middle sample and one at the middle of each outer third, blended
    // in with the travel speed (like the edge search) and with the tilt
    // (`SPLIT_TILT`)
    let sm = m * smoothstep(axle_z.abs() / SPLIT_TILT);
    // (the samples of split strips follow the other circles)
    let n_main = nc;
    for (k, &sp) in split.iter().enumerate().take(n) {
        if sm <= 0.0 || !sp || nc + 2 > n_main + MAX_SUB {
            continue;
        }
        let yk = slice_y(h, n, k);
        split_in_thirds(
            &mut circles,
            (&mut walks, &mut drives, &mut drivings),
            &mut nc,
            (k, yk, w_strip),
            sm,
            &walk_at,
            disc,
        );
    }
    let mut lo = [0.0f64; 2];
    let mut hi = [0.0f64; 2];
    // (the rim's heights at each walk's ends are read once, for these
    // bounds, `depth_to(b_in)` and `depth_bound`, and the unrefined ends)
    for (pair, dr) in walks.iter_mut().zip(&drives).take(nc) {
        for s in 0..2 {
            if let Some(w) = &mut pair[s] {
                let z = w.end_heights(disc);
                w.ends = Some(z);
                if dr[s] {
                    lo[s] = lo[s].max((z.b_in - z.a).max(0.0));
                    hi[s] = hi[s].max((z.b_far - z.a).max(0.0));
                }
            }
        }
    }
    let matters = |s: usize| {
        let (me, other) = (hi[s].powi(4), lo[1 - s].powi(4));
        me + other == 0.0 || me / (me + other) > NEGLIGIBLE_WEIGHT
    };
    let refine_side = [matters(0), matters(1)];
    // circles that may turn out deepest get the fine tolerance
    let deepest_lo = lo[0].max(lo[1]);
    // (each arc with `sin_cos` of its ends, for its load)
    // (written where it is kept: a pair returned by value was copied)
    let finish_pair = |pair: &[Option<Walk>; 2], dr: [bool; 2], out: &mut [Option<Finished>; 2]| {
        // (the samples of strips split below read their heights here)
        let heights = |s: usize| pair[s].as_ref().map(|w| w.end_heights(disc));
        let z = [heights(0), heights(1)];
        // (`depth_bound`, from the heights, of the sides that may drive)
        let may_govern = (0..2)
            .filter(|&s| dr[s])
            .filter_map(|s| z[s])
            .any(|z| (z.b_far - z.a).max(0.0) >= deepest_lo);
        let tol = if may_govern { ANGLE_TOL } else { LEAN_TOL };
        for (s, o) in out.iter_mut().enumerate() {
            let z = z[s].unwrap_or_default();
            *o = pair[s]
                .as_ref()
                .map(|w| w.finish_from(map, disc, look, refine_side[s], tol, &z));
        }
    };
    // the rim slices' arcs first: a slice whose arc depth breaks with its
    // neighbours' (an arc end on an older groove's blurred wall or floor,
    // which moves steeply with the slice's place in its cell) is
    // integrated in thirds as well
    let mut slice_arcs = [[None::<Finished>; 2]; 101];
    for (k, a) in slice_arcs.iter_mut().enumerate().take(n) {
        finish_pair(&walks[k], drives[k], a);
    }
    if m > 0.0 && n >= 3 {
        // each slice's deepest loaded arc, found once (the strips split
        // below add circles, not slices)
        let mut depths = [0.0f64; 101];
        for (k, dk) in depths.iter_mut().enumerate().take(n) {
            *dk = (0..2)
                .filter(|&s| drives[k][s])
                .filter_map(|s| slice_arcs[k][s].map(|(a, _)| a.depth))
                .fold(0.0, f64::max);
        }
        let d = |k: usize| depths[k];
        let profile = |k: usize| disc.radius - disc.rho(slice_y(h, n, k));
        for k in 1..n - 1 {
            // (a slice carrying part of its strip at a wall splits that part)
            if circles[k].sub || circles[k].width <= 0.0 {
                continue;
            }
            let dev = (d(k) - 0.5 * (d(k - 1) + d(k + 1))).abs();
            // the tip profile's own curvature across the neighbours
            let own = 0.5 * (profile(k - 1) + profile(k + 1)) - profile(k);
            let lo = UNEVEN_DEPTH.max(3.0 * own.abs());
            let su = m * smoothstep((dev - lo) / lo);
            if su > 0.0 && nc + 2 <= n_main + MAX_SUB {
                let strip = (k, circles[k].y, circles[k].width);
                let walked = (&mut walks[..], &mut drives[..], &mut drivings[..]);
                split_in_thirds(&mut circles, walked, &mut nc, strip, su, &walk_at, disc);
            }
        }
    }
    let circles = &circles[..nc];

    // the load of every arc
    let psi = law.psi();
    let eta = still_there_tolerance(elastic_depth, look, disc);
    let mut loads = [[Load::default(); 2]; 2]; // [rim | face][side]
    let mut depth = [0.0f64; 2];
    let mut any = false;
    // the deepest rim arc, for the slip point, and the lean of the tip
    let mut gov: Option<(usize, f64)> = None;
    let mut sub_arcs = [[None::<Arc>; 2]; MAX_SUB];
    for (ci, c) in circles.iter().enumerate() {
        if ring_idle(c) {
            any |= walks[ci].iter().any(Option::is_some);
            continue;
        }
        // (a slice's arcs read where they are kept, not copied)
        let mut own = [None, None];
        let finished = if ci < n {
            &slice_arcs[ci]
        } else {
            finish_pair(&walks[ci], drives[ci], &mut own);
            &own
        };
        // (the circle's element and where it drives once, for both sides)
        let mut element = None;
        for s in 0..2 {
            let Some((arc, sc)) = finished[s] else {
                continue;
            };
            any = true;
            if !drives[ci][s] {
                // (drives a sliver at most: carries nothing)
                continue;
            }
            if c.face == 0.0 && ci >= n_main {
                sub_arcs[ci - n_main][s] = Some(arc);
            }
            let (e, driving) = *element.get_or_insert_with(|| {
                let e = c.element(disc, &motion);
                (e, drivings[ci].unwrap_or_else(|| e.driving()))
            });
            let (t0, t1, far_hi, sc01) = if arc.b >= arc.a {
                (arc.a, arc.b, true, (sc[0], sc[1]))
            } else {
                (arc.b, arc.a, false, (sc[1], sc[0]))
            };
            // (the driving parts once, for the load and the still-there test)
            let (parts, np) = e.driving_parts_on(driving, t0, t1);
            let (whole, drive) = arc_load_in(&e, (t0, t1), sc01, far_hi, psi, &parts[..np]);
            let (load, eff) = arc_contribution(
                map,
                disc,
                &motion,
                &e,
                (t0, t1),
                (whole, drive),
                (arc.u_max, law.regularisation(arc.depth)),
                elastic_depth,
                eta,
                Some(&parts[..np]),
            );
            // a slice that touches over part of its strip sets the depth
            // in proportion to that part, up to half its strip: a sliver of
            // contact entering a strip does not move the penetration
            let share = if c.sub {
                1.0
            } else if c.face == 0.0 {
                (2.0 * c.width / w_strip).min(1.0)
            } else {
                1.0
            };
            // a side face's rings carry its share (`face_weight`,
            // `Motion::face_yield`)
            let (load, eff) = if c.is_ring() {
                let w = w_sides[usize::from(c.face < 0.0)];
                (load.scaled(w), eff * w)
            } else {
                (load, eff)
            };
            depth[s] = depth[s].max(arc.depth * eff * share);
            // (the deepest rim arc that carries load: an arc a moving disc
            // leaves behind cuts nothing)
            if c.face == 0.0 && eff > 0.0 && gov.is_none_or(|(_, d)| arc.depth > d) {
                gov = Some((ci, arc.depth));
            }
            let part = usize::from(c.face != 0.0);
            let l = &mut loads[part][s];
            *l += load;
        }
    }
    if !any {
        return none;
    }
    // arcs that all carry nothing (no side reaches any depth) are no
    // contact either: the rim of a disc that has rolled past the end of its
    // rock still dips into its own groove's walls, which the map blurs
    // across a cell at the tip's edges, and reported touching rock with
    // every force zero
    let Some((mut c, (wp, wm))) = assemble(disc, law, n, loads, depth) else {
        return none;
    };
    // friction reads the slip where the cutting rim arc is lowest
    if let Some((kg, _)) = gov {
        // (the arcs that may carry load)
        let rim_arcs = |ci: usize| {
            let arcs = if ci < n {
                slice_arcs[ci].map(|f| f.map(|(a, _)| a))
            } else {
                sub_arcs[ci - n_main]
            };
            [0, 1].map(|s| arcs[s].filter(|_| drives[ci][s]))
        };
        let rim = (0..n)
            .chain(n_main..nc)
            .map(|k| (circles[k].y, circles[k].width / w_strip, rim_arcs(k)));
        (c.slip_point, c.slip_normal) = slip_point(disc, rim_arcs(kg), rim, (wp, wm));
    }
    c
}

/// Where friction reads the slip, and the rim's inward unit normal there
/// (offset from the centre, rock frame): at the start of the deepest rim
/// arcs `gov` (both sides blended by the weights `(wp, wm)`), across the
/// tip where the rim arcs' lengths centre. `rim`: each rim circle's axle
/// coordinate, the share of its strip it carries and its arcs.
fn slip_point(
    disc: &PosedDisc,
    gov: [Option<Arc>; 2],
    rim: impl Iterator<Item = (f64, f64, [Option<Arc>; 2])>,
    (wp, wm): (f64, f64),
) -> (Vector3<f64>, Vector3<f64>) {
    let [ap, am] = gov;
    let theta_slip = wp * ap.map_or(0.0, |a| a.a) + wm * am.map_or(0.0, |a| a.a);
    let (mut wsum, mut ysum) = (0.0, 0.0);
    for (y, share, pair) in rim {
        let len = |a: Option<Arc>| a.map_or(0.0, |a| a.length);
        // (a slice carrying part of its strip weighs in proportion)
        let w = (wp * len(pair[0]) + wm * len(pair[1])) * share;
        wsum += w;
        ysum += w * y;
    }
    let h = disc.half_width;
    let y_f = if wsum > 0.0 {
        (ysum / wsum).clamp(-h, h)
    } else {
        0.0
    };
    (
        disc.rot * disc.rim_point_local(theta_slip, y_f),
        -(disc.rot * disc.rim_normal_local(theta_slip, y_f)),
    )
}

#[cfg(test)]
mod tests {
    use super::{sin_cos_near, RimCircle};
    use crate::core::heightmap::{Grid, HeightMap};
    use crate::core::params::CutterParams;
    use crate::core::{cutter::PosedDisc, Pose};
    use nalgebra::Vector3;

    /// `out_of_rock` passes over a run above the nodes under it, and not
    /// over one with a node above a rim point, nor over one a node
    /// reaches by less than the margin; off the map there is no rock, and
    /// the run is passed over.
    #[test]
    fn out_of_rock_passes_over_runs_no_node_reaches() {
        // (node rows at y = -0.5 and 0.5 mm: the rim at y = 0 runs mid-cell)
        let grid = Grid::new(-0.3, 0.3, -0.0505, 0.0495, 601, 101);
        let c = CutterParams::default();
        // the lowest point 1 mm above a face at 0
        let disc = PosedDisc::new(&c, &Pose::new(0.0, 0.0, c.radius + 1e-3, 0.0, 0.0, 0.0));
        let rim = RimCircle::new(&disc, 0.0, c.radius);
        let step = (1e-3 / c.radius).sin_cos();
        let run = |map: &HeightMap| {
            let (mut s, mut co) = (0.0, 1.0);
            rim.out_of_rock(map, &mut s, &mut co, step, 16)
        };
        let mut map = HeightMap::flat(grid, 0.0);
        assert!(run(&map));
        // a node 5 mm ahead (the run reaches 16 mm) up into the rim
        map.set_node(305, 50, 1.2e-3);
        assert!(!run(&map));
        // a node of a cell under the run, just under the run's lowest rim
        // point (its first)
        map.set_node(305, 50, 0.0);
        let z = disc.centre.z - c.radius * (1e-3 / c.radius).cos();
        map.set_node(305, 51, z - 1e-6);
        assert!(run(&map));
        map.set_node(305, 51, z - 1e-10);
        assert!(!run(&map), "within the margin");
        // off the map
        let far = PosedDisc::new(&c, &Pose::new(5.0, 0.0, c.radius - 1e-3, 0.0, 0.0, 0.0));
        let rim = RimCircle::new(&far, 0.0, c.radius);
        let (mut s, mut co) = (0.0, 1.0);
        assert!(rim.out_of_rock(&map, &mut s, &mut co, step, 16));
    }

    /// Brute force holds the run test: on tilted, turned discs, over runs
    /// of 1 to 32 samples anywhere on the rim's lower half, with a node
    /// raised to about the height of a rim point of the run, a run
    /// `out_of_rock` passes over has no sample the rock is over (the start
    /// search would have found none there).
    #[test]
    fn out_of_rock_passes_over_no_sample_inside_the_rock() {
        let grid = Grid::new(-0.3, 0.3, -0.3, 0.3, 601, 601);
        let c = CutterParams::default();
        let mut next = crate::core::uniforms(0x2545_f491_4f6c_dd1d_u64);
        let (mut passed, mut refused, mut bulges) = (0, 0, 0);
        for _ in 0..40000 {
            let (roll, yaw) = (1.2 * (2.0 * next() - 1.0), 3.1 * (2.0 * next() - 1.0));
            let pose = Pose::new(0.0, 0.0, c.radius - 2e-3, roll, 0.0, yaw);
            let disc = PosedDisc::new(&c, &pose);
            let y = disc.half_width * (2.0 * next() - 1.0);
            let rho = disc.rho(y);
            let Some((theta0, _)) = disc.arc_below(y, rho, 0.5) else {
                continue;
            };
            let rim = RimCircle::new(&disc, y, rho);
            let dir = if next() < 0.5 { 1.0 } else { -1.0 };
            let dt = dir * 0.5e-3 / rho;
            let step = dt.sin_cos();
            let n = 1 + (next() * 32.0) as usize;
            // (half the runs straddle the angle where the rim's world x or
            // y turns, if that lies on the walk's quarter turn: there the
            // rim bulges beyond its ends)
            let axis = usize::from(next() < 0.5);
            let t_turn = rim.ex[axis].atan2(rim.ez[axis]);
            let off = [t_turn, t_turn + std::f64::consts::PI]
                .map(|t| super::wrap(t - theta0) * dir)
                .into_iter()
                .find(|&o| o > 0.0 && o < std::f64::consts::FRAC_PI_2);
            let k0 = match off {
                Some(o) if next() < 0.5 => ((o / dt.abs()) as usize).saturating_sub(n / 2).max(1),
                _ => 1 + (next() * 60.0) as usize,
            };
            // the samples, as the search turns to them
            let (mut s, mut co) = theta0.sin_cos();
            for _ in 0..k0 - 1 {
                super::advance_by(&mut s, &mut co, step.0, step.1);
            }
            let (s_run, c_run) = (s, co);
            let mut pts = Vec::new();
            for _ in 0..n {
                super::advance_by(&mut s, &mut co, step.0, step.1);
                pts.push(rim.point(s, co));
            }
            // a node near one sample, raised to about the rim there; or,
            // where the rim between the run's ends bulges into cells the
            // box of its ends misses, the nodes of such a cell outside the
            // nodes of the ends' cells, far over the rim
            let cell = |p: &Vector3<f64>| grid.cell(p.x, p.y).unwrap();
            let (a, b) = (cell(&pts[0]), cell(&pts[n - 1]));
            let cols = a.0.min(b.0)..=a.0.max(b.0) + 1;
            let rows = a.1.min(b.1)..=a.1.max(b.1) + 1;
            let nodes = |q: &Vector3<f64>| {
                let (i, j, _, _) = cell(q);
                [(i, j), (i + 1, j), (i, j + 1), (i + 1, j + 1)]
                    .map(|(i, j)| (!cols.contains(&i) || !rows.contains(&j)).then_some((i, j)))
            };
            let outside = pts.iter().find(|q| nodes(q).iter().any(Option::is_some));
            let mut map;
            if let Some(q) = outside {
                bulges += 1;
                let low = pts.iter().map(|p| p.z).fold(f64::INFINITY, f64::min);
                map = HeightMap::flat(grid, low - 1e-6);
                for (i, j) in nodes(q).into_iter().flatten() {
                    map.set_node(i, j, q.z + 1.0);
                }
            } else {
                let q = pts[(next() * n as f64) as usize];
                let (i, j, _, _) = cell(&q);
                let (i, j) = (i + usize::from(next() < 0.5), j + usize::from(next() < 0.5));
                map = HeightMap::flat(grid, q.z - 0.05);
                map.set_node(i, j, q.z + 2e-4 * (2.0 * next() - 1.0));
            }
            let (mut s1, mut c1) = (s_run, c_run);
            if rim.out_of_rock(&map, &mut s1, &mut c1, step, n) {
                passed += 1;
                for p in &pts {
                    assert!(
                        map.height(p.x, p.y) - p.z <= 0.0,
                        "roll {roll} yaw {yaw} y {y}"
                    );
                }
            } else {
                refused += 1;
            }
            // (it turns the angle as the search does)
            assert_eq!((s1, c1), (s, co));
        }
        assert!(
            passed > 5000 && refused > 5000 && bulges > 100,
            "{passed} passed, {refused} refused, {bulges} bulges"
        );
    }

    #[test]
    fn sin_cos_near_equals_sin_cos_to_rounding() {
        let mut worst: f64 = 0.0;
        for i in 0..2000 {
            let t0 = -7.0 + 0.0071 * i as f64;
            for k in -20..=20 {
                let t = t0 + 0.06 * k as f64 / 20.0;
                let (s, c) = sin_cos_near(t, t0, t0.sin_cos());
                let (s1, c1) = t.sin_cos();
                worst = worst.max((s - s1).abs()).max((c - c1).abs());
            }
        }
        assert!(worst < 4e-16, "worst {worst:e}");
    }
}
