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
//! the arcs of each side weigh `d^4 / (d+^4 + d-^4)` by the depth `d` of
//! that side's driving rim arcs over the tip's width (each arc's depth times
//! its strip's width, summed), so a cutter at rest in its own symmetric pit
//! pushes straight up, one at rest after rolling keeps the load of its
//! leading arc, and a band of the tip where the rear of a turning disc
//! scrubs its groove's wall weighs as wide as it is (weighed by each side's
//! deepest arc, one slice in such a band took up to a fifth of the load).
//!
//! **Elastic layer.** A cut leaves the rock `elastic_depth` inside the rim
//! (see `cut_cutter_heightmap`), so a cutter held still keeps its contact.
//! Each arc's load is faded in over that depth (`smoothstep(u /
//! elastic_depth)`, `u` the deepest the surface is inside the rock on the
//! arc), so lifting the cutter off its groove unloads it without a jump.
//!
//! **Where the code is.** [`contact`] (this file) runs the query in order,
//! a stage a method of its `Query`, with the stages' work in the files
//! beside it:
//! - `circles.rs`: the circles of the surface to walk (rim slices, side-face
//!   rings, flank bands) and their parts below the rock's top;
//! - `walk.rs`: one circle walked through the rock from its lowest point to
//!   its first arc's refined ends;
//! - `strips.rs`: how much of each tip strip touches the rock (the edge
//!   found by bisection, strips integrated in thirds);
//! - `load.rs`: each arc's load, scaled by the rock still there ahead, and
//!   the contact assembled from the summed loads.

use arrayvec::ArrayVec;
use nalgebra::Vector3;

use super::contact_law::{
    arc_load_in, face_weight, pressure_level, smoothstep, Driving, Element, Load, Motion,
};
use super::csm::{contact_angle, CsmLaw};
use super::cutter::{wrap, Lowest, PosedDisc};
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
///
/// The query runs in stages, each a method of `Query`, on the circles of
/// the surface and their walks (`Surface`):
/// 1. `Query::walk_surface`: every circle walked from its lowest point;
/// 2. `Query::engage_strips`: each rim slice as the part of its strip
///    that touches the rock, and the strips a tilted disc's free edge
///    crosses integrated in thirds;
/// 3. `Query::refinement` and `Query::finish_slices`: the rim slices'
///    arc ends refined, and the slices whose arc depth breaks with their
///    neighbours' integrated in thirds;
/// 4. `Query::loads`: every arc's load, summed by part and side;
/// 5. `assemble` (the pressure level and the contact) and
///    `Query::slip` (where friction reads the slip).
pub fn contact(
    map: &HeightMap,
    disc: &PosedDisc,
    law: &CsmLaw,
    num: &Numerics,
    elastic_depth: f64,
    twist: &Twist,
) -> Contact {
    let none = Contact::default();
    let Some(q) = Query::new(map, disc, law, num, elastic_depth, twist) else {
        return none;
    };
    // (the circles and their walks, room for some 100 kB, and the slices'
    // finished arcs are filled in place, stage by stage; the circles and
    // walks only as far as they are used: a `Surface` that owned its arrays
    // was built and then copied, which doubled a step's cost, and
    // zero-filling the room a tilted disc needs was 1.9 % of an upright
    // disc's straight step)
    let mut circles = ArrayVec::new();
    let mut walks = ArrayVec::new();
    let mut drives = ArrayVec::new();
    let mut drivings = ArrayVec::new();
    let mut s = Surface {
        circles: &mut circles,
        n_main: 0,
        walks: &mut walks,
        drives: &mut drives,
        drivings: &mut drivings,
    };
    q.walk_surface(&mut s);
    q.engage_strips(&mut s);
    let refine = q.refinement(&mut s);
    let mut slice_arcs = ArrayVec::new();
    q.finish_slices(&mut s, &refine, &mut slice_arcs);
    let Some(sums) = q.loads(&s, &refine, &slice_arcs) else {
        return none;
    };
    // arcs that all carry nothing (no side reaches any depth) are no
    // contact either: the rim of a disc that has rolled past the end of its
    // rock still dips into its own groove's walls, which the map blurs
    // across a cell at the tip's edges, and reported touching rock with
    // every force zero
    let Some((mut c, weights)) = assemble(disc, law, q.n, sums.loads, sums.depth, sums.spread)
    else {
        return none;
    };
    if let Some((kg, _)) = sums.gov {
        (c.slip_point, c.slip_normal) = q.slip(&s, &slice_arcs, &sums, kg, weights);
    }
    c
}

/// What every stage of [`contact`] reads: the disc, the rock, the law and
/// the motion, and what is derived from them once.
struct Query<'a> {
    map: &'a HeightMap,
    disc: &'a PosedDisc,
    /// Where the disc's rim circles are lowest (`disc.lowest()`).
    low: Lowest,
    law: &'a CsmLaw,
    elastic_depth: f64,
    /// The highest rock anywhere under the disc.
    z_top: f64,
    /// Tip slices, half the tip's width and the width of a slice's strip.
    n: usize,
    h: f64,
    w_strip: f64,
    /// The larger side of a cell (the look-ahead's cell).
    look: f64,
    /// The spacing of the side faces' rings and the flanks' bands
    /// (`numerics.ring_step_cells` cells) \[m\].
    ring_step: f64,
    motion: Motion,
    /// The axle's slope (world z of its unit vector).
    axle_z: f64,
    /// How much the side faces carry at this tilt (`face_weight`), and
    /// each face's share as the wall it drives into yields
    /// (`Motion::face_yield`), faces +y and -y.
    w_face: f64,
    w_sides: [f64; 2],
    /// Faces -y and +y whose rings carry nothing (`Query::ring_idle`).
    idle: [bool; 2],
    /// Every walk's sample step, look-ahead and whether it passes over runs
    /// the rock cannot reach.
    walk: (f64, f64, bool),
    /// `numerics.walk_every_side`.
    every: bool,
}

/// The circles of the surface the query walks and what their walks found,
/// filled in stage by stage; the four lists have a place a circle.
struct Surface<'s> {
    /// The first `n_main` from `surface_circles` (the rim slices first),
    /// then the samples of split strips.
    circles: &'s mut ArrayVec<Circle, MAX_CIRCLES>,
    n_main: usize,
    /// Each circle's walks, both sides.
    walks: &'s mut ArrayVec<[Option<Walk>; 2], MAX_CIRCLES>,
    /// The sides of each circle that may carry load: a moving disc's side
    /// that drives nowhere within its reach, or a sliver only
    /// (`DRIVE_SLIVER_CELLS`), carries nothing; only the sides that carry
    /// load set the bounds that choose the refinement, the arc depths that
    /// split strips and the slip point.
    drives: &'s mut ArrayVec<[bool; 2], MAX_CIRCLES>,
    /// Each circle's `Element::driving` where it was found, which the loads
    /// read again.
    drivings: &'s mut ArrayVec<Option<Driving>, MAX_CIRCLES>,
}

impl Surface<'_> {
    /// Circles in use.
    fn nc(&self) -> usize {
        self.circles.len()
    }

    /// Adds circle `c` as walked (`walked`).
    fn push(&mut self, c: Circle, (walks, drives, driving): Walked) {
        self.circles.push(c);
        self.walks.push(walks);
        self.drives.push(drives);
        self.drivings.push(driving);
    }

    /// Whether circle `k` touches the rock on either side.
    fn touches(&self, k: usize) -> bool {
        self.walks[k].iter().any(Option::is_some)
    }
}

/// Which arc ends are refined how finely: the sides whose blend weight can
/// matter, and the arc depth from which a circle may turn out deepest (it
/// then gets the fine tolerance).
struct Refinement {
    sides: [bool; 2],
    deepest_lo: f64,
}

/// Every arc's load summed, with what the assembly and the slip point read.
struct Sums {
    /// `[rim | face][side]`.
    loads: [[Load; 2]; 2],
    /// The depth each side's loaded arcs reach.
    depth: [f64; 2],
    /// Each side's rim arcs' depths summed over the tip's width: each arc's
    /// depth times the share of its load it keeps (`eff`) times the width of
    /// its strip that touches (the side blend's measure, `assemble`).
    spread: [f64; 2],
    /// The deepest rim arc that carries load (its circle and depth): an arc
    /// a moving disc leaves behind cuts nothing.
    gov: Option<(usize, f64)>,
    /// The arcs of the split strips' samples (circles from `n_main` on).
    sub_arcs: [[Option<Arc>; 2]; MAX_SUB],
}

impl<'a> Query<'a> {
    /// The query's set-up; `None` when no rock reaches the disc.
    fn new(
        map: &'a HeightMap,
        disc: &'a PosedDisc,
        law: &'a CsmLaw,
        num: &Numerics,
        elastic_depth: f64,
        twist: &Twist,
    ) -> Option<Self> {
        let g = map.grid();
        // highest rock anywhere under the disc
        let z_top = map.highest_within(disc.centre.x, disc.centre.y, disc.radius)?;
        disc.footprint_below(z_top)?;
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
        // a moving disc's side face that drives into the rock nowhere ahead
        // of its lowest point carries no load (`Motion::face_drives_ahead`):
        // its rings are not walked then, unless the rim touches nothing (the
        // disc is in contact if a ring touches). Rolling straight, that is
        // both faces, exactly as the law gives (the whole-arc part weighs
        // 1 - moving = 0 and no ring has a driving part); turning, the face
        // away from the turn's centre. Flank bands are cones, which a
        // rolling disc does drive into: always walked.
        let rings_idle =
            |side: f64| motion.moving >= 1.0 && !motion.face_drives_ahead(side, disc.rho(h));
        Some(Self {
            map,
            disc,
            low: disc.lowest(),
            law,
            elastic_depth,
            z_top,
            n,
            h,
            w_strip: 2.0 * h / n as f64,
            look,
            ring_step: num.ring_step_cells * cell,
            motion,
            axle_z,
            w_face,
            w_sides,
            idle: [rings_idle(-1.0), rings_idle(1.0)],
            walk: (num.arc_step_cells * cell, look, !num.search_every_sample),
            every: num.walk_every_side,
        })
    }

    /// A ring of a side face that carries nothing (`Query::new`).
    fn ring_idle(&self, c: &Circle) -> bool {
        c.is_ring() && self.idle[usize::from(c.face > 0.0)]
    }

    /// Walks circle `c` into `out` (both sides, or the sides that may carry
    /// load); returns those sides and where the circle drives.
    ///
    /// A moving disc loads only the driving parts of its arcs (the
    /// whole-arc part weighs 1 - moving = 0), so the sides that do not
    /// carry load (`Surface::drives`) are not walked (unless
    /// `numerics.walk_every_side`):
    /// - on a rim slice, the trailing side of a rolling disc (rock it alone
    ///   touches adds nothing to the load; until the twenty-first session
    ///   it was walked where the driving side found no arc, so that whether
    ///   the slice touched stayed as walking both sides found it: over an
    ///   old groove's floor that searched the whole reach behind for
    ///   nothing);
    /// - on a face circle (ring or flank band), once the rim touches: on a
    ///   gauge disc turning on its track, one side of each ring (its side
    ///   face turns into the wall ahead and away from it behind).
    ///
    /// (The walks, some 400 bytes a circle, are written where they are
    /// kept: passed back in the tuple they were copied twice more.)
    fn walk_circle_into(
        &self,
        c: &Circle,
        rim_touches: bool,
        out: &mut [Option<Walk>; 2],
    ) -> ([bool; 2], Option<Driving>) {
        let (disc, map) = (self.disc, self.map);
        let Some(w) = SliceWalk::below(disc, &self.low, (c.y, c.radius), self.z_top, self.walk)
        else {
            *out = [None, None];
            return ([true; 2], None);
        };
        if self.motion.moving < 1.0 {
            w.march_into(map, disc, [true; 2], out);
            return ([true; 2], None);
        }
        let e = c.element(disc, &self.motion);
        let driving = e.driving();
        let d = w.sides_driving(&e, driving, DRIVE_SLIVER_CELLS * self.look / c.radius);
        let sides = if self.every || (c.face != 0.0 && !rim_touches) {
            [true; 2]
        } else if c.face == 0.0 && d[0] == d[1] {
            // (a rim slice that drives on both sides, or on neither)
            [true; 2]
        } else {
            d
        };
        w.march_into(map, disc, sides, out);
        (d, Some(driving))
    }

    /// The rim circle at axle coordinate `y`, walked.
    fn walk_at(&self, y: f64) -> Walked {
        let c = Circle {
            y,
            radius: self.disc.rho(y),
            ..Circle::default()
        };
        let mut pair = [None, None];
        let (d, driving) = self.walk_circle_into(&c, true, &mut pair);
        (pair, d, driving)
    }

    /// Stage 1: the surface's circles (`surface_circles`), each walked
    /// from its lowest point, but the idle rings once the rim touches.
    fn walk_surface(&self, s: &mut Surface) {
        let rings = self.w_face > 0.0;
        surface_circles(
            s.circles,
            self.disc,
            self.n,
            self.z_top,
            self.ring_step,
            rings,
        );
        s.n_main = s.nc();
        let mut rim_touches = false;
        for (ci, c) in s.circles.iter().enumerate() {
            // (each walk written where it is kept)
            s.walks.push([None, None]);
            let (drives, driving) = if self.ring_idle(c) && rim_touches {
                ([true; 2], None)
            } else {
                self.walk_circle_into(c, rim_touches, &mut s.walks[ci])
            };
            s.drives.push(drives);
            s.drivings.push(driving);
            rim_touches |= c.face == 0.0 && s.walks[ci].iter().any(Option::is_some);
        }
    }

    /// Stage 2: the rim slices as the part of their strip that touches the
    /// rock (`engaged_strips`), and a strip a free edge crosses on a tilted
    /// disc integrated in thirds: its middle sample and one at the middle
    /// of each outer third, blended in with the travel speed (like the edge
    /// search) and with the tilt (`SPLIT_TILT`).
    ///
    /// (A disc at rest keeps the midpoint rule: lifted off its pit, the
    /// circles that still touch alternate with the node rows, no single
    /// edge; the rule blends in with the travel speed.)
    fn engage_strips(&self, s: &mut Surface) {
        let (disc, map, z_top, walk) = (self.disc, self.map, self.z_top, self.walk);
        let low = &self.low;
        let (h, n, w_strip) = (self.h, self.n, self.w_strip);
        let m = self.motion.moving;
        let mut engaged: ArrayVec<Option<(f64, f64)>, 101> = (0..n).map(|_| None).collect();
        let mut split: ArrayVec<bool, 101> = (0..n).map(|_| false).collect();
        if m > 0.0 {
            let probe = self.probe_sides(s);
            engaged_strips(
                h,
                n,
                |k| s.touches(k),
                |y| {
                    SliceWalk::below(disc, low, (y, disc.rho(y)), z_top, walk)
                        .is_some_and(|w| w.touches(map, disc, probe))
                },
                |y| {
                    let rho = disc.rho(y);
                    disc.arc_below_at(low, y, rho, z_top)
                        .is_none_or(|(theta0, _)| {
                            let p = disc.to_world(&disc.rim_point_local(theta0, y));
                            map.any_uncut(p.x, p.y)
                        })
                },
                &mut engaged,
                &mut split,
            );
        }
        for (k, e) in engaged.iter().enumerate() {
            if let Some((y, width)) = *e {
                let yk = slice_y(h, n, k);
                let (y, width) = if s.touches(k) {
                    (yk + m * (y - yk), w_strip + m * (width - w_strip))
                } else {
                    (y, m * width)
                };
                s.circles[k].y = y;
                s.circles[k].radius = disc.rho(y);
                s.circles[k].width = width;
                (s.walks[k], s.drives[k], s.drivings[k]) = if width > 0.0 {
                    self.walk_at(y)
                } else {
                    ([None, None], [true; 2], None)
                };
            }
        }
        let sm = m * smoothstep(self.axle_z.abs() / SPLIT_TILT);
        // (the samples of split strips follow the other circles)
        for (k, &sp) in split.iter().enumerate() {
            if sm <= 0.0 || !sp || s.nc() + 2 > s.n_main + MAX_SUB {
                continue;
            }
            let yk = slice_y(h, n, k);
            split_in_thirds(s, (k, yk, w_strip), sm, &|y| self.walk_at(y), disc);
        }
    }

    /// The sides of a circle the edge search (`engaged_strips`) asks
    /// whether it touches the rock: for a disc rolling along (the whole
    /// load the driving one, `Motion::moving` 1) whose tip slices all
    /// drive on the same one side, that side alone; else (and with
    /// `numerics.walk_every_side`) both.
    ///
    /// A rolling disc's trailing side carries no load, so rock it alone
    /// touches adds nothing to a strip; asked on both sides, a circle over
    /// an old groove (the rim above the floor at its lowest point) was
    /// searched to the end of its reach behind as well as ahead, and found
    /// nothing on either: the edge search was a quarter of a pass beside a
    /// groove. In every scene measured (`examples/scene_bits`,
    /// `contact_scenes`, `slice_convergence`, `offset_steps`,
    /// `offset_convergence`, the reference head over 300 steps) no circle
    /// touched behind alone, and the forces are the same bit for bit;
    /// `tests/contact_skip.rs` holds them so against asking both sides.
    fn probe_sides(&self, s: &Surface) -> [bool; 2] {
        let first = s.drives[0];
        if self.every
            || self.motion.moving < 1.0
            || first[0] == first[1]
            || s.drives[1..self.n].iter().any(|d| *d != first)
        {
            [true; 2]
        } else {
            first
        }
    }

    /// Which arc ends are refined how finely, from the rim's heights at
    /// each walk's ends (read once here, for these bounds, `depth_to(b_in)`
    /// and `depth_bound`, and the unrefined ends; kept in the walks).
    fn refinement(&self, s: &mut Surface) -> Refinement {
        let mut lo = [0.0f64; 2];
        let mut hi = [0.0f64; 2];
        for (pair, dr) in s.walks.iter_mut().zip(s.drives.iter()) {
            for side in 0..2 {
                if let Some(w) = &mut pair[side] {
                    let z = w.end_heights(self.disc);
                    w.ends = Some(z);
                    if dr[side] {
                        lo[side] = lo[side].max((z.b_in - z.a).max(0.0));
                        hi[side] = hi[side].max((z.b_far - z.a).max(0.0));
                    }
                }
            }
        }
        let matters = |s: usize| {
            let (me, other) = (hi[s].powi(4), lo[1 - s].powi(4));
            me + other == 0.0 || me / (me + other) > NEGLIGIBLE_WEIGHT
        };
        Refinement {
            sides: [matters(0), matters(1)],
            deepest_lo: lo[0].max(lo[1]),
        }
    }

    /// One circle's walks finished into arcs, with `sin_cos` of their ends
    /// for their loads. (Written where they are kept: a pair returned by
    /// value was copied.)
    fn finish_pair(
        &self,
        r: &Refinement,
        pair: &[Option<Walk>; 2],
        dr: [bool; 2],
        out: &mut [Option<Finished>; 2],
    ) {
        let disc = self.disc;
        // (the samples of strips split later read their heights here)
        let heights = |s: usize| pair[s].as_ref().map(|w| w.end_heights(disc));
        let z = [heights(0), heights(1)];
        // (`depth_bound`, from the heights, of the sides that may drive)
        let may_govern = (0..2)
            .filter(|&s| dr[s])
            .filter_map(|s| z[s])
            .any(|z| (z.b_far - z.a).max(0.0) >= r.deepest_lo);
        let tol = if may_govern { ANGLE_TOL } else { LEAN_TOL };
        for (s, o) in out.iter_mut().enumerate() {
            let z = z[s].unwrap_or_default();
            *o = pair[s]
                .as_ref()
                .map(|w| w.finish_from(self.map, disc, self.look, r.sides[s], tol, &z));
        }
    }

    /// Stage 3: the rim slices' arcs finished into `slice_arcs`; then a
    /// slice whose arc depth breaks with its neighbours' (an arc end on an
    /// older groove's blurred wall or floor, which moves steeply with the
    /// slice's place in its cell) is integrated in thirds as well
    /// (`UNEVEN_DEPTH`).
    fn finish_slices(
        &self,
        s: &mut Surface,
        r: &Refinement,
        slice_arcs: &mut ArrayVec<[Option<Finished>; 2], 101>,
    ) {
        let (n, h, disc) = (self.n, self.h, self.disc);
        for k in 0..n {
            let mut a = [None, None];
            self.finish_pair(r, &s.walks[k], s.drives[k], &mut a);
            slice_arcs.push(a);
        }
        let m = self.motion.moving;
        if m <= 0.0 || n < 3 {
            return;
        }
        // each slice's deepest loaded arc, found once (the strips split
        // below add circles, not slices)
        let depths: ArrayVec<f64, 101> = (0..n)
            .map(|k| {
                (0..2)
                    .filter(|&side| s.drives[k][side])
                    .filter_map(|side| slice_arcs[k][side].map(|(a, _)| a.depth))
                    .fold(0.0, f64::max)
            })
            .collect();
        let d = |k: usize| depths[k];
        let profile = |k: usize| disc.radius - disc.rho(slice_y(h, n, k));
        for k in 1..n - 1 {
            // (a slice carrying part of its strip at a wall splits that part)
            if s.circles[k].sub || s.circles[k].width <= 0.0 {
                continue;
            }
            let dev = (d(k) - 0.5 * (d(k - 1) + d(k + 1))).abs();
            // the tip profile's own curvature across the neighbours
            let own = 0.5 * (profile(k - 1) + profile(k + 1)) - profile(k);
            let lo = UNEVEN_DEPTH.max(3.0 * own.abs());
            let su = m * smoothstep((dev - lo) / lo);
            if su > 0.0 && s.nc() + 2 <= s.n_main + MAX_SUB {
                let strip = (k, s.circles[k].y, s.circles[k].width);
                split_in_thirds(s, strip, su, &|y| self.walk_at(y), disc);
            }
        }
    }

    /// Stage 4: the load of every arc, summed by part and side; `None` when
    /// no circle touches the rock.
    fn loads(
        &self,
        s: &Surface,
        r: &Refinement,
        slice_arcs: &[[Option<Finished>; 2]],
    ) -> Option<Sums> {
        let (map, disc, motion) = (self.map, self.disc, &self.motion);
        let (n, n_main) = (self.n, s.n_main);
        let psi = self.law.psi();
        let eta = still_there_tolerance(self.elastic_depth, self.look, disc);
        let mut sums = Sums {
            loads: [[Load::default(); 2]; 2],
            depth: [0.0; 2],
            spread: [0.0; 2],
            gov: None,
            sub_arcs: [[None; 2]; MAX_SUB],
        };
        let mut any = false;
        for (ci, c) in s.circles.iter().enumerate() {
            if self.ring_idle(c) {
                any |= s.touches(ci);
                continue;
            }
            // (a slice's arcs read where they are kept, not copied)
            let mut own = [None, None];
            let finished = if ci < n {
                &slice_arcs[ci]
            } else {
                self.finish_pair(r, &s.walks[ci], s.drives[ci], &mut own);
                &own
            };
            // (the circle's element and where it drives once, for both sides)
            let mut element = None;
            for (side, f) in finished.iter().enumerate() {
                let Some((arc, sc)) = *f else {
                    continue;
                };
                any = true;
                if !s.drives[ci][side] {
                    // (drives a sliver at most: carries nothing)
                    continue;
                }
                if c.face == 0.0 && ci >= n_main {
                    sums.sub_arcs[ci - n_main][side] = Some(arc);
                }
                let (e, driving) = *element.get_or_insert_with(|| {
                    let e = c.element(disc, motion);
                    (e, s.drivings[ci].unwrap_or_else(|| e.driving()))
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
                    motion,
                    &e,
                    (t0, t1),
                    (whole, drive),
                    (arc.u_max, self.law.regularisation(arc.depth)),
                    self.elastic_depth,
                    eta,
                    Some((&parts[..np], [sc01.0, sc01.1])),
                );
                // a slice that touches over part of its strip sets the depth
                // in proportion to that part, up to half its strip: a sliver of
                // contact entering a strip does not move the penetration
                let share = if c.sub {
                    1.0
                } else if c.face == 0.0 {
                    (2.0 * c.width / self.w_strip).min(1.0)
                } else {
                    1.0
                };
                // a side face's rings carry its share (`face_weight`,
                // `Motion::face_yield`)
                let (load, eff) = if c.is_ring() {
                    let w = self.w_sides[usize::from(c.face < 0.0)];
                    (load.scaled(w), eff * w)
                } else {
                    (load, eff)
                };
                sums.depth[side] = sums.depth[side].max(arc.depth * eff * share);
                if c.face == 0.0 {
                    sums.spread[side] += c.width * arc.depth * eff;
                }
                // (the deepest rim arc that carries load)
                if c.face == 0.0 && eff > 0.0 && sums.gov.is_none_or(|(_, d)| arc.depth > d) {
                    sums.gov = Some((ci, arc.depth));
                }
                sums.loads[usize::from(c.face != 0.0)][side] += load;
            }
        }
        any.then_some(sums)
    }

    /// Stage 5: where friction reads the slip ([`slip_point`]), the rim arc
    /// `kg` the deepest that cuts, and the sides weighed `weights`.
    fn slip(
        &self,
        s: &Surface,
        slice_arcs: &[[Option<Finished>; 2]],
        sums: &Sums,
        kg: usize,
        weights: (f64, f64),
    ) -> (Vector3<f64>, Vector3<f64>) {
        let (n, n_main) = (self.n, s.n_main);
        // (the arcs that may carry load)
        let rim_arcs = |ci: usize| {
            let arcs = if ci < n {
                slice_arcs[ci].map(|f| f.map(|(a, _)| a))
            } else {
                sums.sub_arcs[ci - n_main]
            };
            [0, 1].map(|side| arcs[side].filter(|_| s.drives[ci][side]))
        };
        let rim = (0..n).chain(n_main..s.nc()).map(|k| {
            (
                s.circles[k].y,
                s.circles[k].width / self.w_strip,
                rim_arcs(k),
            )
        });
        slip_point(self.disc, rim_arcs(kg), rim, weights)
    }
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
