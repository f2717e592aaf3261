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

use nalgebra::Vector3;

use super::contact_law::{
    arc_load_in, face_weight, pressure_level, smoothstep, Driving, Element, Load, Motion,
};
use super::csm::{contact_angle, CsmLaw};
use super::cutter::{wrap, PosedDisc};
use super::heightmap::HeightMap;
use super::params::Numerics;
use super::pose::Twist;

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

/// One rim circle (slice `y`) of a posed disc, parametrised for fast walks:
/// world point `base + ex * sin(theta) + ez * cos(theta)`.
struct RimCircle {
    base: Vector3<f64>,
    ex: Vector3<f64>,
    ez: Vector3<f64>,
}

impl RimCircle {
    /// The circle of radius `rho` about the axle at axle coordinate `y`.
    fn new(disc: &PosedDisc, y: f64, rho: f64) -> Self {
        let r = &disc.rot;
        Self {
            base: disc.centre + r.column(1) * y,
            ex: r.column(0) * rho,
            ez: r.column(2) * -rho,
        }
    }

    /// Rock over rim at the angle with sine `s` and cosine `c`, walking in
    /// direction `dir`: `(plain, ahead)`, the overlap of the rock here and the
    /// larger of that and the overlap of the rock one look-ahead further along
    /// the walk (bilinear).
    #[inline(always)]
    fn overlap(&self, map: &HeightMap, s: f64, c: f64, dir: f64, look: f64) -> (f64, f64) {
        let p = self.base + self.ex * s + self.ez * c;
        // horizontal direction of the walk (d/dtheta of the point)
        let tx = dir * (self.ex.x * c - self.ez.x * s);
        let ty = dir * (self.ex.y * c - self.ez.y * s);
        rock_over(map, &p, tx, ty, 1e-12 * self.ex.norm_squared(), look)
    }

    /// The first of [`RimCircle::overlap`] alone: the rock over the rim
    /// here, without the look-ahead.
    #[inline]
    fn overlap_here(&self, map: &HeightMap, s: f64, c: f64) -> f64 {
        let p = self.point(s, c);
        map.height(p.x, p.y) - p.z
    }

    #[inline(always)]
    fn point(&self, s: f64, c: f64) -> Vector3<f64> {
        self.base + self.ex * s + self.ez * c
    }

    /// Turns `(s, c)` on by `(sd, cd)` `n` times, as `n` calls of
    /// [`advance_by`], and tells whether every rim point on the way is
    /// above every node of the cells under those points (by more than
    /// round-off): then none is inside the rock.
    ///
    /// The points are bounded from the run's first and last alone: each
    /// world coordinate of the rim is a sinusoid of the angle, `M cos(t -
    /// tm) + C`, which over `dt` strays at most `M (1 - cos(dt / 2)) <= M
    /// dt^2 / 8` beyond the larger of its ends (and below the smaller), and
    /// the height rises monotonically away from the lowest point, where
    /// every walk starts, so the first point is the lowest (a walk reaches
    /// half a turn at most). Reading every point cost a fifth of a contact
    /// beside an old groove.
    fn out_of_rock(
        &self,
        map: &HeightMap,
        s: &mut f64,
        c: &mut f64,
        (sd, cd): (f64, f64),
        n: usize,
    ) -> bool {
        advance_by(s, c, sd, cd);
        let first = self.point(*s, *c);
        for _ in 1..n {
            advance_by(s, c, sd, cd);
        }
        let last = self.point(*s, *c);
        // (`tan` of the step bounds the step, which is well below a
        // quarter turn; the points themselves carry the recurrence's
        // round-off, far below `OUT_OF_ROCK_PAD`)
        let span = (n - 1) as f64 * sd.abs() / cd;
        let stray = 0.125 * span * span;
        let pad = |axis: usize| {
            let m = (self.ex[axis] * self.ex[axis] + self.ez[axis] * self.ez[axis]).sqrt();
            m * stray + OUT_OF_ROCK_PAD
        };
        let (px, py) = (pad(0), pad(1));
        let (x0, x1) = if first.x < last.x {
            (first.x, last.x)
        } else {
            (last.x, first.x)
        };
        let (y0, y1) = if first.y < last.y {
            (first.y, last.y)
        } else {
            (last.y, first.y)
        };
        let z_min = if first.z < last.z { first.z } else { last.z };
        // the nodes of every cell a point lies in (a point's cell index
        // grows with its coordinate; off the map the height is `NO_ROCK`)
        let top = map.highest_node_under(x0 - px, x1 + px, y0 - py, y1 + py);
        // (a height is its nodes' weighted mean to a few ulps)
        top + OUT_OF_ROCK_MARGIN < z_min
    }

    /// Angles where the rim's world coordinate `axis` (0 = x, 1 = y) equals `e`.
    fn crossings(&self, axis: usize, e: f64) -> Option<[f64; 2]> {
        // base + ex sin + ez cos = e  <=>  m cos(theta - tm) = e - base
        let (a, b) = (self.ex[axis], self.ez[axis]);
        let m = (a * a + b * b).sqrt();
        let rhs = e - self.base[axis];
        if m < 1e-15 || rhs.abs() > m {
            return None;
        }
        let tm = a.atan2(b);
        let d = (rhs / m).acos();
        Some([tm + d, tm - d])
    }

    fn z(&self, theta: f64) -> f64 {
        self.base.z + self.ex.z * theta.sin() + self.ez.z * theta.cos()
    }

    /// [`RimCircle::z`] at the angle whose `sin_cos` is `(s, c)` (the same
    /// arithmetic: `sin_cos` is `(sin, cos)`).
    fn z_sc(&self, (s, c): (f64, f64)) -> f64 {
        self.base.z + self.ex.z * s + self.ez.z * c
    }
}

/// The rock over the surface point `p` met by a walk whose horizontal
/// direction is `(tx, ty)`: `(here, ahead)`, the overlap of the rock here and
/// the larger of that and the overlap of the rock one `look` further along
/// the walk, or diagonally ahead on either side where no node of the cell
/// has been cut, when the cell ahead has an uncut node itself: the edge of a
/// groove cut into the face is blurred across the walk as well, and the map
/// knows which nodes a cut lowered; a walk inside an older groove (the cell
/// ahead all cut) does not borrow that groove's uncut wall. Walks with
/// `tx^2 + ty^2 <= tiny` (vertical) do not look ahead.
#[inline]
pub fn rock_over(
    map: &HeightMap,
    p: &Vector3<f64>,
    tx: f64,
    ty: f64,
    tiny: f64,
    look: f64,
) -> (f64, f64) {
    let here = map.height(p.x, p.y) - p.z;
    if here > 0.0 {
        // inside the rock already: the look-ahead cannot change the sign
        return (here, here);
    }
    let n2 = tx * tx + ty * ty;
    if n2 <= tiny {
        return (here, here);
    }
    let k = look / n2.sqrt();
    let (ax, ay) = (k * tx, k * ty);
    let (mut z, uncut) = map.bilinear_any_uncut(p.x + ax, p.y + ay);
    if uncut {
        for (dx, dy) in [(ax - ay, ay + ax), (ax + ay, ay - ax)] {
            if let Some(u) = map.bilinear_uncut(p.x + dx, p.y + dy) {
                z = z.max(u);
            }
        }
    }
    (here, here.max(z - p.z))
}

/// Refines a sign change of `f` between `t_in` (f > 0) and `t_out` (f <= 0)
/// by the Illinois variant of regula falsi, to `tol` in the argument.
fn refine(
    f: &dyn Fn(f64) -> f64,
    mut t_in: f64,
    mut t_out: f64,
    mut f_in: f64,
    mut f_out: f64,
    tol: f64,
) -> f64 {
    let mut side = 0;
    for _ in 0..100 {
        if (t_in - t_out).abs() < tol {
            break;
        }
        let mut t = t_in - f_in * (t_out - t_in) / (f_out - f_in);
        if !t.is_finite() || (t - t_in) * (t - t_out) >= 0.0 {
            t = 0.5 * (t_in + t_out);
        }
        let ft = f(t);
        if ft > 0.0 {
            t_in = t;
            f_in = ft;
            if side == 1 {
                f_out *= 0.5;
            }
            side = 1;
        } else {
            t_out = t;
            f_out = ft;
            if side == -1 {
                f_in *= 0.5;
            }
            side = -1;
        }
    }
    0.5 * (t_in + t_out)
}

/// Angular tolerance of the arc ends that can set the penetration: 1e-9 rad
/// is 0.2 nm of rim.
const ANGLE_TOL: f64 = 1e-9;
/// Angular tolerance of the other slices' arc ends, which only weight the
/// lean across the tip: 1e-6 rad is 0.2 um of rim.
const LEAN_TOL: f64 = 1e-6;

/// The march of one side of one slice, before its ends are refined: the
/// start is `a` exactly or bracketed by `[a_out, a]`, the end by `[b_in, b_out]`.
#[derive(Debug, Clone, Copy)]
pub struct Walk {
    y: f64,
    radius: f64,
    dir: f64,
    a: f64,
    a_out: Option<(f64, f64, f64)>,
    b_in: (f64, f64),
    b_out: Option<(f64, f64)>,
    u_max: f64,
    /// `a.sin_cos()` where the march has it (a start at the lowest point).
    sc_a: Option<(f64, f64)>,
    /// The rim's heights at the ends, once read (`Walk::end_heights`).
    ends: Option<EndHeights>,
}

/// A finished arc with `sin_cos` of its `a` and `b`.
type Finished = (Arc, [(f64, f64); 2]);

/// A circle as walked: its walks on both sides, which sides may carry load,
/// and where its surface drives (`None`: not found, the disc below the
/// rest speed or the circle out of reach).
type Walked = ([Option<Walk>; 2], [bool; 2], Option<Driving>);

/// Every circle's [`Walked`], as three arrays.
type WalkedCircles<'a> = (
    &'a mut [[Option<Walk>; 2]],
    &'a mut [[bool; 2]],
    &'a mut [Option<Driving>],
);

/// World heights of a walk's rim at its start `a`, at its last sample
/// inside `b_in`, and at the far end of its end's bracket (`b_out`, else
/// `b_in`): what the depth bounds and the unrefined ends read, once; with
/// `sin_cos` of `a` and `b_in`.
#[derive(Debug, Clone, Copy, Default)]
struct EndHeights {
    a: f64,
    b_in: f64,
    b_far: f64,
    sc_a: (f64, f64),
    sc_b_in: (f64, f64),
}

impl Walk {
    /// Depth of the arc if its end lay at `b` (`z(b) - z(a)`).
    fn depth_to(&self, disc: &PosedDisc, b: f64) -> f64 {
        let rim = RimCircle::new(disc, self.y, self.radius);
        (rim.z(b) - rim.z(self.a)).max(0.0)
    }

    /// Largest depth the refined arc can have.
    pub fn depth_bound(&self, disc: &PosedDisc) -> f64 {
        self.depth_to(disc, self.b_out.map_or(self.b_in.0, |o| o.0))
    }

    /// The rim's heights at the walk's ends ([`EndHeights`]).
    fn end_heights(&self, disc: &PosedDisc) -> EndHeights {
        if let Some(z) = self.ends {
            return z;
        }
        let rim = RimCircle::new(disc, self.y, self.radius);
        let sc_a = self.sc_a.unwrap_or_else(|| self.a.sin_cos());
        let sc_b_in = self.b_in.0.sin_cos();
        let b_in = rim.z_sc(sc_b_in);
        EndHeights {
            a: rim.z_sc(sc_a),
            b_in,
            b_far: self.b_out.map_or(b_in, |o| rim.z(o.0)),
            sc_a,
            sc_b_in,
        }
    }

    /// The arc, its ends refined by regula falsi to `ANGLE_TOL` (`refine`) or
    /// left at the last sample inside (for arcs whose weight is negligible).
    pub fn finish(
        &self,
        map: &HeightMap,
        disc: &PosedDisc,
        look: f64,
        refine_ends: bool,
        tol: f64,
    ) -> Arc {
        self.finish_from(map, disc, look, refine_ends, tol, &self.end_heights(disc))
            .0
    }

    /// [`Walk::finish`], given the rim's heights at the walk's ends
    /// (`self.end_heights(disc)`); with `sin_cos` of the arc's `a` and `b`.
    fn finish_from(
        &self,
        map: &HeightMap,
        disc: &PosedDisc,
        look: f64,
        refine_ends: bool,
        tol: f64,
        z: &EndHeights,
    ) -> (Arc, [(f64, f64); 2]) {
        let rim = RimCircle::new(disc, self.y, self.radius);
        let dir = self.dir;
        let (a, z_a, sc_a) = match (self.a_out, refine_ends) {
            (Some((t_out, u_out, u_in)), true) => {
                let near = |t: f64| sin_cos_near(t, self.a, z.sc_a);
                let f_start = |t: f64| {
                    let (s, c) = near(t);
                    rim.overlap_here(map, s, c)
                };
                let a = refine(&f_start, self.a, t_out, u_in, u_out, tol);
                let sc = near(a);
                (a, rim.z_sc(sc), sc)
            }
            _ => (self.a, z.a, z.sc_a),
        };
        let (b, z_b, sc_b) = match (self.b_out, refine_ends) {
            (Some((t_out, u_out)), true) => {
                let near = |t: f64| sin_cos_near(t, self.b_in.0, z.sc_b_in);
                let f_end = |t: f64| {
                    let (s, c) = near(t);
                    rim.overlap(map, s, c, dir, look).1
                };
                let b = refine(&f_end, self.b_in.0, t_out, self.b_in.1, u_out, tol);
                let sc = near(b);
                (b, rim.z_sc(sc), sc)
            }
            (Some(_), false) => (self.b_in.0, z.b_in, z.sc_b_in),
            (None, _) => (self.b_in.0, z.b_in, z.sc_b_in),
        };
        // an arc that ends where the rock does (the map's edge: a block's
        // end face) is buried up to the rock's top there, not to where the
        // rim leaves it: its depth is the rock's at the last sample inside
        let z_top = match self.b_out {
            Some((_, u_out)) if !u_out.is_finite() => z_b.max(z.b_in + self.b_in.1),
            _ => z_b,
        };
        let arc = Arc {
            a,
            b,
            depth: (z_top - z_a).max(0.0),
            length: self.radius * (b - a).abs(),
            u_max: self.u_max,
        };
        (arc, [sc_a, sc_b])
    }
}

/// The sides (`[+1, -1]`) of a circle [`SliceWalk::march_into`] walks.
#[derive(Debug, Clone, Copy)]
enum Sides {
    /// The sides marked.
    Wanted([bool; 2]),
    /// The side marked (one of them) alone, and the other too where that
    /// one finds no arc (so that whether the slice touches stays as
    /// walking both sides finds it).
    DrivingFirst([bool; 2]),
}

/// One rim circle to walk (a tip slice, a side-face ring or a flank band):
/// the circle at axle coordinate `y` of radius `radius`, from its lowest
/// point `theta0` up to `reach` (at most half a turn) either way, in steps
/// of about `step` rad, looking `look` ahead.
#[derive(Debug, Clone, Copy)]
struct SliceWalk {
    y: f64,
    radius: f64,
    theta0: f64,
    reach: f64,
    step: f64,
    look: f64,
    /// Whether the start search may pass over runs of samples that a bound
    /// of the rock under them shows to be out of it (`!num.search_every_sample`).
    skip: bool,
}

impl SliceWalk {
    /// The walk of the circle `(y, radius)` over the part of it below
    /// `z_top`, in steps of about `step_len` of rim; `None` when none is.
    fn below(
        disc: &PosedDisc,
        (y, radius): (f64, f64),
        z_top: f64,
        (step_len, look, skip): (f64, f64, bool),
    ) -> Option<Self> {
        let (theta0, reach) = disc.arc_below(y, radius, z_top)?;
        Some(Self {
            y,
            radius,
            theta0,
            reach: reach.min(std::f64::consts::PI),
            step: step_len / radius,
            look,
            skip,
        })
    }

    /// The circle, its lowest point's sine and cosine, and the rock over it.
    fn start(&self, map: &HeightMap, disc: &PosedDisc) -> (RimCircle, f64, f64, f64) {
        let rim = RimCircle::new(disc, self.y, self.radius);
        let (s, c) = self.theta0.sin_cos();
        let here0 = rim.overlap_here(map, s, c);
        (rim, s, c, here0)
    }

    /// Marches the sides `sides` asks for (`dir` = +1 towards cutter +x,
    /// then -1) and brackets each contact arc's ends, written into `out`
    /// (`[+1, -1]`; a side not walked is `None`): the circle, the lowest
    /// point's sine and cosine and the rock over it read once. Each walk is
    /// some 150 bytes: built where it is kept, not copied there (a pair
    /// returned by value and stored was a `memcpy` of 300 bytes a circle).
    #[inline(always)]
    fn march_into(
        &self,
        map: &HeightMap,
        disc: &PosedDisc,
        sides: Sides,
        out: &mut [Option<Walk>; 2],
    ) {
        let side = self.sides(map, disc);
        let dir = |k: usize| if k == 0 { 1.0 } else { -1.0 };
        match sides {
            Sides::Wanted(wanted) => {
                for (k, w) in out.iter_mut().enumerate() {
                    *w = if wanted[k] { side(dir(k)) } else { None };
                }
            }
            Sides::DrivingFirst(drive) => {
                let first = usize::from(!drive[0]);
                out[first] = side(dir(first));
                out[1 - first] = if out[first].is_none() {
                    side(dir(1 - first))
                } else {
                    None
                };
            }
        }
    }

    /// The march of one side (`dir`) of the circle, the circle, its lowest
    /// point's sine and cosine and the rock over it read once for both.
    #[inline(always)]
    fn sides<'a>(
        &'a self,
        map: &'a HeightMap,
        disc: &PosedDisc,
    ) -> impl Fn(f64) -> Option<Walk> + 'a {
        let (rim, s, c, here0) = self.start(map, disc);
        move |dir: f64| {
            march_from(
                map,
                &rim,
                (self.y, self.radius),
                (self.theta0, s, c),
                here0,
                self.reach,
                dir,
                self.step,
                (self.look, self.skip),
            )
        }
    }

    /// Which sides (`[+1, -1]`) of the circle drive into the rock within
    /// their reach, for the surface element `e` on it (`d` its
    /// [`Element::driving`]), over more than `sliver` rad in all
    /// ([`DRIVE_SLIVER_CELLS`]).
    fn sides_driving(&self, e: &Element, d: Driving, sliver: f64) -> [bool; 2] {
        let (t0, r) = (self.theta0, self.reach);
        [(t0, t0 + r), (t0 - r, t0)].map(|(lo, hi)| {
            let (parts, np) = e.driving_parts_on(d, lo, hi);
            parts[..np].iter().map(|p| p.1 - p.0).sum::<f64>() > sliver
        })
    }

    /// Whether walking both sides ([`SliceWalk::march_into`]) finds a
    /// contact on either side (either walk `is_some()`), without walking
    /// the arcs.
    fn touches(&self, map: &HeightMap, disc: &PosedDisc) -> bool {
        let (rim, s, c, here0) = self.start(map, disc);
        if here0 > 0.0 {
            return true;
        }
        let n = ((self.reach / self.step).ceil() as usize).max(1);
        [1.0, -1.0].into_iter().any(|dir| {
            let dt = dir * self.reach / n as f64;
            find_start(
                map,
                &rim,
                self.radius,
                (self.theta0, s, c),
                here0,
                self.reach,
                dir,
                dt,
                (self.look, self.skip),
            )
            .is_some()
        })
    }
}

/// One side (`dir`) of [`SliceWalk::march_into`] on the circle `rim`
/// (`(y, radius)`) from `theta0` (sine `s0`, cosine `c0`), where the rock
/// over the rim is `here0`.
///
/// (Until the start is found only the rock over the rim itself is read:
/// where it is positive the look-ahead is that same value, see
/// [`rock_over`], and where it is not the walk has not started.)
#[allow(clippy::too_many_arguments)]
fn march_from(
    map: &HeightMap,
    rim: &RimCircle,
    (y, radius): (f64, f64),
    (theta0, s0, c0): (f64, f64, f64),
    here0: f64,
    reach: f64,
    dir: f64,
    step: f64,
    (look, skip): (f64, bool),
) -> Option<Walk> {
    let n = ((reach / step).ceil() as usize).max(1);
    let dt = dir * reach / n as f64;
    let (sd, cd) = dt.sin_cos();
    let (mut s, mut c) = (s0, c0);
    let advance = |s: &mut f64, c: &mut f64| advance_by(s, c, sd, cd);
    // contact starts where the rim is below the rock itself ...
    let mut k = 0;
    let mut u_max = here0.max(0.0);
    let mut sc_a = None;
    let (a, a_out, t_prev, u_prev) = if here0 > 0.0 {
        sc_a = Some((s0, c0));
        (theta0, None, theta0, here0)
    } else {
        let (t, tp, up, here) = find_start(
            map,
            rim,
            radius,
            (theta0, s0, c0),
            here0,
            reach,
            dir,
            dt,
            (look, skip),
        )?;
        u_max = here;
        // resume the coarse grid at the last grid angle before the start
        k = ((t - theta0) / dt).floor().max(0.0) as usize;
        (s, c) = (theta0 + dt * k as f64).sin_cos();
        (t, Some((tp, up, here)), t, here)
    };
    let (mut t_prev, mut u_prev) = (t_prev, u_prev);
    // ... and lasts while it is below the rock here or one cell ahead
    let b_out = loop {
        k += 1;
        if k > n {
            break None;
        }
        let sc_prev = (s, c);
        advance(&mut s, &mut c);
        let t = theta0 + dt * k as f64;
        let (here, ahead) = rim.overlap(map, s, c, dir, look);
        // the walk's last angle is where the rim rises to the highest rock
        // near the disc: the rock there is over the rim by round-off at
        // most, and whether it read inside or out decided whether the
        // whole last step was contact (the forces jumped as the pose moved
        // by round-off)
        let at_top = k == n && reach < std::f64::consts::PI;
        if ahead <= 0.0 || at_top {
            // The step is walked again at one cell of rim, so that the end
            // is the first exit to that resolution: where the rim grazes rock cut earlier, the rock
            // over it can dip to zero and back inside one step, and
            // refining the step's bracket found either exit as the pose
            // moved by round-off.
            let m = ((dt.abs() * radius / look).ceil() as usize).max(1);
            let (t0, dts) = (t_prev, (t - t_prev) / m as f64);
            let mut out = None;
            for j in 1..m {
                let ts = t0 + dts * j as f64;
                let (ss, cs) = sin_cos_near(ts, t - dt, sc_prev);
                let (here_s, ahead_s) = rim.overlap(map, ss, cs, dir, look);
                if ahead_s <= 0.0 {
                    out = Some((ts, ahead_s));
                    break;
                }
                u_max = u_max.max(here_s);
                t_prev = ts;
                u_prev = ahead_s;
            }
            if out.is_some() || !at_top {
                break out.or(Some((t, ahead)));
            }
            // inside up to the top: the arc ends there (k = n, so the
            // walk's next turn ends it)
        }
        u_max = u_max.max(here);
        t_prev = t;
        u_prev = ahead;
    };
    Some(Walk {
        y,
        radius,
        dir,
        a,
        a_out,
        b_in: (t_prev, u_prev),
        b_out,
        u_max,
        sc_a,
        ends: None,
    })
}

/// The start of a walk whose lowest point `theta0` (sine `s0`, cosine
/// `c0`) is out of the rock (`here0 <= 0`), on the side `dir` within
/// `reach`, the coarse step being `dt`: the first angle where the rock is
/// over the rim, the angle before it and the rock over the rim there, and
/// the rock over the rim at the start. `None` when the rim stays out.
#[allow(clippy::too_many_arguments)]
fn find_start(
    map: &HeightMap,
    rim: &RimCircle,
    radius: f64,
    (theta0, s0, c0): (f64, f64, f64),
    here0: f64,
    reach: f64,
    dir: f64,
    dt: f64,
    (look, skip): (f64, bool),
) -> Option<(f64, f64, f64, f64)> {
    // the lowest point is out of the rock: search for the start with a
    // step of half a cell of rim, so that a short arc (the rim meeting
    // the end face of the rock, a groove's shoulder) is not stepped over
    let fine = (look * 0.5 / radius).min(dt.abs());
    let m = ((reach / fine).ceil() as usize).max(1);
    let dtf = dir * reach / m as f64;
    // ... and at the angles where the rim crosses the edges of the map,
    // where rock begins with a vertical face and an arc can be shorter
    // than any step
    let g = map.grid();
    let mut extra = [0.0f64; 8];
    let mut ne = 0;
    for (axis, edges) in [(0usize, [g.x_min, g.x_max()]), (1, [g.y_min, g.y_max()])] {
        for e in edges {
            for t in rim.crossings(axis, e).into_iter().flatten() {
                let off = wrap(t - theta0) * dir;
                if off > 0.0 && off < reach {
                    extra[ne] = theta0 + off * dir;
                    ne += 1;
                }
            }
        }
    }
    // the angle before the current one and the rock over the rim there,
    // or that angle's sine and cosine where the rock was not read
    let mut prev = (theta0, Ok(here0));
    let visit = |t: f64, st: f64, ct: f64, prev: &mut (f64, Result<f64, (f64, f64)>)| {
        let here = rim.overlap_here(map, st, ct);
        if here > 0.0 {
            let up = prev.1.unwrap_or_else(|(s, c)| rim.overlap_here(map, s, c));
            return Some((t, prev.0, up, here));
        }
        *prev = (t, Ok(here));
        None
    };
    let grid = |kf: usize| theta0 + dtf * kf as f64;
    if ne > 0 {
        // the grid and the crossings, in walking order
        let mut angles: Vec<f64> = (1..=m).map(grid).collect();
        angles.extend_from_slice(&extra[..ne]);
        angles.sort_by(|p, q| ((p - theta0) * dir).total_cmp(&((q - theta0) * dir)));
        for &t in &angles {
            let (st, ct) = t.sin_cos();
            if let Some(f) = visit(t, st, ct, &mut prev) {
                return Some(f);
            }
        }
    } else {
        // on the even grid of angles (no map edge crossed, the usual
        // case) the rim point turns by a fixed rotation, as in the walk
        // below
        let (sdf, cdf) = dtf.sin_cos();
        let (mut sf, mut cf) = (s0, c0);
        let mut kf = 1;
        // the first sample a run may start at: past the first run's worth
        // (a start near the lowest point is found sample by sample), and
        // past a run that was not passed over (it is read sample by sample)
        let mut next_run = START_FIRST + 1;
        while kf <= m {
            // a run of samples that no node under them reaches is passed
            // over: a height is a weighted mean of its cell's nodes (the
            // rim grazing an old groove's floor searched its whole reach
            // sample by sample, 40 % of a contact beside a groove)
            // (the last run may be shorter)
            let end = (kf + START_RUN - 1).min(m);
            if skip && kf >= next_run {
                let (mut s1, mut c1) = (sf, cf);
                if rim.out_of_rock(map, &mut s1, &mut c1, (sdf, cdf), end + 1 - kf) {
                    (sf, cf) = (s1, c1);
                    prev = (grid(end), Err((s1, c1)));
                    kf = end + 1;
                    continue;
                }
                next_run = kf + START_RETRY;
            }
            advance_by(&mut sf, &mut cf, sdf, cdf);
            if let Some(f) = visit(grid(kf), sf, cf, &mut prev) {
                return Some(f);
            }
            kf += 1;
        }
    }
    None
}

/// Samples of the start search read one by one before the first run is
/// tested, and after a run that was not passed over before the next is:
/// where the start is near, a run test is wasted work. Set from
/// `examples/scene_cost` (its measured pass alone, callgrind
/// `--toggle-collect='*measured_pass*'`: beside 2 and 4 mm, gauge, tilted
/// 30 deg) and `examples/head_cost`, after the run test came to read only
/// a run's ends: 4 and 8 against 8 and 4 (the gauge cutter 0.4 % cheaper,
/// the passes beside a groove 5-6 % dearer), 2 and 8 (beside a groove 3 %
/// cheaper, the gauge cutter and the head 1 % and 0.1 % dearer), 4 and 4,
/// 1 and 8 and 2 and 16; runs of 32 or 64 samples cost the head more than
/// runs of 16.
const START_FIRST: usize = 4;
const START_RETRY: usize = 8;

/// How far \[m\] the rim must be above the nodes under it for
/// [`RimCircle::out_of_rock`] (a computed height may exceed its cell's
/// highest node by round-off).
const OUT_OF_ROCK_MARGIN: f64 = 1e-9;

/// How far \[m\] [`RimCircle::out_of_rock`] widens the box of a run's points
/// beyond its bound of the rim between them.
const OUT_OF_ROCK_PAD: f64 = 1e-9;

/// Samples of the start search tested as one run by
/// [`RimCircle::out_of_rock`].
const START_RUN: usize = 16;

/// `(sin t, cos t)` from a nearby angle `t0` whose `(sin, cos)` is `sc0`:
/// `sc0` turned by `t - t0`, whose sine and cosine come from their Taylor
/// series (the terms left out are below 1e-19 for |t - t0| <= 0.05 rad),
/// or `t.sin_cos()` farther away. An end's refinement stays within one
/// step of the march from its last sample, and each of its trials cost a
/// `sin_cos` (3 % of a cutterhead step's instructions).
#[inline]
fn sin_cos_near(t: f64, t0: f64, (s0, c0): (f64, f64)) -> (f64, f64) {
    let d = t - t0;
    if d.abs() > 0.05 {
        return t.sin_cos();
    }
    let d2 = d * d;
    let sd = d * (1.0 - d2 / 6.0 * (1.0 - d2 / 20.0 * (1.0 - d2 / 42.0 * (1.0 - d2 / 72.0))));
    let cd = 1.0 - d2 / 2.0 * (1.0 - d2 / 12.0 * (1.0 - d2 / 30.0 * (1.0 - d2 / 56.0)));
    (s0 * cd + c0 * sd, c0 * cd - s0 * sd)
}

/// Turns the rim angle whose sine and cosine are `(s, c)` by the angle
/// whose sine and cosine are `(sd, cd)`.
#[inline]
fn advance_by(s: &mut f64, c: &mut f64, sd: f64, cd: f64) {
    let s1 = *s * cd + *c * sd;
    *c = *c * cd - *s * sd;
    *s = s1;
}

/// On a moving disc, a side of a circle whose surface drives into the rock
/// over less than this many cells of its rim in all (within its reach)
/// carries no load, and need not be walked (`contact`). A disc that rolls
/// while it advances into the face (every disc of a boring head) drives the
/// trailing side of each circle within `v_advance / v_rolling` rad of its
/// lowest point, on rock it has just cut: 0.3 mm/s against 0.6 m/s on the
/// reference head's track of 2 m, 5e-4 rad, 0.1 mm of rim. Those slivers
/// changed no disc's mean force by more than 1e-11 of itself over 300 steps
/// of the reference head, while walking them was an eighth of its step; a
/// sliver ten times longer (1e-2 rad) moves the centre disc by 0.45 %.
/// Set in cells, the sliver shrinks with them: a finer run drops less.
pub const DRIVE_SLIVER_CELLS: f64 = 0.2;

/// A side whose blend weight cannot exceed this is not refined: its arcs
/// change the force by less than this fraction.
const NEGLIGIBLE_WEIGHT: f64 = 1e-14;

/// Most rings sampled across a tilted disc's side face (midpoint rule in
/// the radius; each ring's arcs are exact).
const MAX_RINGS: usize = 24;

/// Most bands sampled along each flank (midpoint rule along the flank;
/// each band's arcs are exact).
const MAX_FLANK_BANDS: usize = 24;

/// Most samples added by splitting strips (two a strip).
const MAX_SUB: usize = 16;

/// Room for every circle: rim slices, rings, flank bands and the samples of
/// split strips.
const MAX_CIRCLES: usize = 101 + 2 * MAX_RINGS + 2 * MAX_FLANK_BANDS + MAX_SUB;

/// The radii `[r_lo, r_hi]` of the side face on `side` (the hub face with
/// flanks, at `y = side W/2`) whose circles reach below `z_top`: a circle
/// of radius `r` reaches down to `centre.z + a_z side W/2 - m r`. `None`
/// when the whole face is above `z_top`.
pub fn face_below(disc: &PosedDisc, side: f64, z_top: f64) -> Option<(f64, f64)> {
    let hw = disc.hub_half_width;
    let r_hi = disc.rho_full(hw);
    let m = disc.rot[(2, 0)].hypot(disc.rot[(2, 2)]);
    let r_lo = if m > 1e-12 {
        ((disc.centre.z + disc.rot[(2, 1)] * side * hw - z_top) / m).max(0.0)
    } else {
        0.0
    };
    (r_lo < r_hi).then_some((r_lo, r_hi))
}

/// The part `[s_lo, s_hi]` of the flank on `side` (`s` the distance along
/// the flank from the tip's edge) whose circles reach below `z_top`: the
/// lowest point of a circle about the axle is `centre.z + a_z y - m rho`,
/// linear in `s` along the straight flank. `None` without flanks or when
/// the whole flank is above `z_top`.
pub fn flank_below(disc: &PosedDisc, side: f64, z_top: f64) -> Option<(f64, f64)> {
    if !disc.has_flanks() {
        return None;
    }
    let (h, hw) = (disc.half_width, disc.hub_half_width);
    let (sn, cn) = disc.flank_normal();
    // on the flank at angle f, y = side (h + s sin f), rho = rho(h) - s cos f
    let len = (hw - h) / sn;
    let m = disc.rot[(2, 0)].hypot(disc.rot[(2, 2)]);
    let az = disc.rot[(2, 1)];
    let z0 = disc.centre.z + az * side * h - m * disc.rho(h);
    let k = az * side * sn + m * cn;
    let (mut lo, mut hi) = (0.0f64, len);
    if k > 1e-15 {
        hi = hi.min((z_top - z0) / k);
    } else if k < -1e-15 {
        lo = lo.max((z_top - z0) / k);
    } else if z0 >= z_top {
        return None;
    }
    (hi > lo).then_some((lo, hi))
}

/// The look-ahead of the "rock still there" test, in cells of at least
/// [`STILL_THERE_CELL`]: long enough to reach past the scallops a swept cut
/// leaves between its sub-steps.
const LOOK_AHEAD_CELLS: f64 = 4.0;

/// The cell size below which the still-there test keeps its scale \[m\].
/// The test is a law, not only a numerical device: a surface driving into
/// rock at a grazing angle, such as a tilted disc's side face shaving the
/// thin wedge a curved track leaves on the groove's wall (docs/head.md),
/// meets only a few micrometres more rock per cell of travel. Were the
/// look-ahead and the tolerance to shrink with the cells, how much of that
/// face counts would move with them (the outer gauge cutter's side force by
/// 38 % of its normal force between 0.25 and 0.5 mm cells). Held at the
/// default cell's scale, an element counts in full where it meets more than
/// 22 um of rock within 4 mm of travel, and not at all below 12 um (a
/// 12.7 mm tip radius, 2 um elastic depth: the thesis's and the reference
/// head's discs), at every cell size from 1 mm down.
pub const STILL_THERE_CELL: f64 = 1.0e-3;

/// Below this penetration \[m\] the pressure level keeps its value at this
/// depth. The CSM charges the full tip width (`T R phi`) at any depth, while a
/// round tip shallower than this touches less than three quarters of it
/// (9.9 of 13 mm at 1 mm for the thesis's disc): the closed form's level
/// there would charge a sliver of contact for a full-width cut. Fresh cuts
/// from 1 mm down are the CSM closed form exactly.
pub const LEVEL_DEPTH: f64 = 1.0e-3;

/// The look-ahead travel \[m\] for cells of `look` (the larger side), and
/// at least one sweep step.
pub fn look_ahead(look: f64, num: &Numerics) -> f64 {
    (LOOK_AHEAD_CELLS * look.max(STILL_THERE_CELL)).max(num.sweep_step)
}

/// How much deeper than the elastic layer the rock ahead must reach to
/// count as still there: the elastic depth, or the height-map's own
/// interpolation error across the tip profile (`cell^2 / (8 r)`, cells of at
/// least [`STILL_THERE_CELL`]), whichever is larger.
pub fn still_there_tolerance(elastic_depth: f64, look: f64, disc: &PosedDisc) -> f64 {
    let look = look.max(STILL_THERE_CELL);
    elastic_depth.max(0.125 * look * look / disc.tip_radius)
}

/// Halvings of the look-ahead path that find where it leaves the rock
/// ([`rock_ahead`]): 4 mm to under 0.1 um.
const ROCK_END_HALVINGS: usize = 16;

/// The rock over the surface point `q` (cutter frame) of `disc` after
/// `motion`'s look-ahead: `height - z` where the point is then, or, where
/// that lies off the rock (past the map's edge: the map holds no other
/// [`NO_ROCK`](super::heightmap::NO_ROCK), and a height read across it is
/// not finite) while the point now is on it, where the straight path
/// between the two leaves the rock.
///
/// The look-ahead asks whether the disc will still meet rock where this
/// part of it meets rock now. Rolling off the end of a block, it will, up
/// to the block's end: the block's last rock is crushed like the rest.
/// Read at `ahead` alone, the end of the rock ended the driving load a
/// third at a time as the three samples passed it (jumps of 15.5 kN, a
/// quarter of the reference cut's normal force, 16 and 8 mm before the
/// rock's end); the load now falls with the arc that is left.
#[inline]
fn rock_ahead(map: &HeightMap, disc: &PosedDisc, motion: &Motion, q: &Vector3<f64>) -> f64 {
    let ahead = motion.ahead(q);
    let u = map.height(ahead.x, ahead.y) - ahead.z;
    if u.is_finite() {
        return u;
    }
    rock_to_the_end(map, &disc.to_world(q), &ahead, u)
}

/// [`rock_ahead`] where the point after the look-ahead, `ahead`, lies off
/// the rock (`u` there): the rock where the path from `here` leaves it.
#[cold]
#[inline(never)]
fn rock_to_the_end(map: &HeightMap, here: &Vector3<f64>, ahead: &Vector3<f64>, u: f64) -> f64 {
    let over = |x: &Vector3<f64>| map.height(x.x, x.y) - x.z;
    if !over(here).is_finite() {
        return u;
    }
    let (mut on, mut off) = (0.0, 1.0);
    for _ in 0..ROCK_END_HALVINGS {
        let mid = 0.5 * (on + off);
        if over(&here.lerp(ahead, mid)).is_finite() {
            on = mid;
        } else {
            off = mid;
        }
    }
    over(&here.lerp(ahead, on))
}

/// One arc's share of the load: its whole-arc and driving loads blended by
/// how fast the disc moves, the driving part weighed by whether the rock it
/// drives into is still there (three points of its longest driving part,
/// carried `look_ahead` along the motion), all faded by how deep the rock
/// reaches over the arc (`u_max`) and by the law's regularisation at the
/// arc's depth `reg` (an arc shallower than `numerics.pReg` grows linearly
/// from first touch, as the CSM law does). Returns the load and the fraction
/// of the whole arc's force it keeps (which scales the arc's depth in the
/// side blend).
#[allow(clippy::too_many_arguments)]
pub fn arc_contribution(
    map: &HeightMap,
    disc: &PosedDisc,
    motion: &Motion,
    e: &Element,
    (t0, t1): (f64, f64),
    (whole, drive): (Load, Load),
    (u_max, reg): (f64, f64),
    elastic_depth: f64,
    eta: f64,
) -> (Load, f64) {
    arc_contribution_in(
        map,
        disc,
        motion,
        e,
        (t0, t1),
        (whole, drive),
        (u_max, reg),
        elastic_depth,
        eta,
        None,
    )
}

/// [`arc_contribution`], given the arc's driving parts
/// (`e.driving_parts(t0, t1)`) when the caller has them.
#[allow(clippy::too_many_arguments)]
fn arc_contribution_in(
    map: &HeightMap,
    disc: &PosedDisc,
    motion: &Motion,
    e: &Element,
    (t0, t1): (f64, f64),
    (whole, drive): (Load, Load),
    (u_max, reg): (f64, f64),
    elastic_depth: f64,
    eta: f64,
    parts: Option<&[(f64, f64)]>,
) -> (Load, f64) {
    let sigma = motion.moving;
    let mut still_there = 1.0;
    if sigma > 0.0 && drive.force != Vector3::zeros() {
        let own;
        let parts = match parts {
            Some(p) => p,
            None => {
                own = e.driving_parts(t0, t1);
                &own.0[..own.1]
            }
        };
        if let Some(&(a, b)) = parts
            .iter()
            .max_by(|p, q| (p.1 - p.0).total_cmp(&(q.1 - q.0)))
        {
            let mut sum = 0.0;
            for f in [0.25, 0.5, 0.75] {
                let u = rock_ahead(map, disc, motion, &e.point(a + (b - a) * f));
                sum += smoothstep((u - elastic_depth - eta) / eta);
            }
            still_there = sum / 3.0;
        }
    }
    let fade = smoothstep(u_max / elastic_depth) * reg;
    let load = (whole.scaled(1.0 - sigma) + drive.scaled(sigma * still_there)).scaled(fade);
    let wn = whole.force.norm();
    let eff = if wn > 0.0 {
        (load.force.norm() / wn).min(1.0)
    } else {
        0.0
    };
    (load, eff)
}

/// The contact from the summed loads `[rim | face][side]` (cutter frame,
/// unit pressure) and each side's effective depth: the side blend
/// `p^4 / (p+^4 + p-^4)`, the penetration, the pressure level of `n` slices
/// and the rock-frame forces. `None` when no side reaches any depth. Also
/// returns the blend weights.
pub fn assemble(
    disc: &PosedDisc,
    law: &CsmLaw,
    n: usize,
    loads: [[Load; 2]; 2],
    depth: [f64; 2],
) -> Option<(Contact, (f64, f64))> {
    let (wp, wm) = {
        let (a, b) = (depth[0].powi(4), depth[1].powi(4));
        if a + b > 0.0 {
            (a / (a + b), b / (a + b))
        } else {
            (0.5, 0.5)
        }
    };
    let p = wp * depth[0] + wm * depth[1];
    if p <= 0.0 {
        return None;
    }
    // the pressure level that makes a fresh straight cut the CSM closed form,
    // held at its LEVEL_DEPTH value below that depth
    let phi = contact_angle(disc.radius, p.min(2.0 * disc.radius));
    let pl = p.max(LEVEL_DEPTH);
    let phl = contact_angle(disc.radius, pl.min(2.0 * disc.radius));
    let reg = |d: f64| law.regularisation(d);
    let (lr, ln) = pressure_level(
        disc,
        n,
        pl,
        law.psi(),
        law.force(pl),
        law.resultant_angle(phl),
        &reg,
    );
    let finish = |l: [Load; 2]| {
        let f = l[0].force * wp + l[1].force * wm;
        let m = l[0].moment * wp + l[1].moment * wm;
        let f = Vector3::new(lr * f.x, ln * f.y, ln * f.z);
        (disc.rot * f, disc.rot * (m * ln))
    };
    let (rim_force, rim_moment) = finish(loads[0]);
    let (side_force, side_moment) = finish(loads[1]);
    let application = if rim_force.norm_squared() > 0.0 {
        rim_force.cross(&rim_moment) / rim_force.norm_squared()
    } else {
        Vector3::zeros()
    };
    Some((
        Contact {
            in_contact: true,
            penetration: p,
            phi,
            rim_force,
            rim_moment,
            application,
            side_force,
            side_moment,
            ..Contact::default()
        },
        (wp, wm),
    ))
}

/// Bisections that place the edge of the contact across the tip: the
/// interval between two samples is split to `2^-EDGE_BISECTIONS` of its width.
const EDGE_BISECTIONS: usize = 6;
/// After this many bisections the edge is told free or not (at the middle
/// of its bracket, an eighth of the interval): a free edge needs no more.
const FREE_AFTER: usize = 5;

/// The strip a free edge lies in, between samples `i` and `i + 1` of the
/// tip (sample 0 the tip's edge `-h`, sample `k + 1` slice `k`, sample
/// `n + 1` the edge `h`), read at `c`, the middle of its bracket.
fn split_strip(h: f64, n: usize, i: usize, c: f64) -> usize {
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
const SPLIT_TILT: f64 = 0.087;

/// Depth \[m\] by which a slice's arc must break with the mean of its
/// neighbours' before its strip is integrated in thirds (fully at twice
/// that); at least three times the tip profile's own curvature there.
const UNEVEN_DEPTH: f64 = 0.3e-3;

/// Splits rim slice `k`'s strip (middle `yk`, width `w`) in thirds,
/// blended in by `s`: the slice
/// keeps `1 - 2 s / 3` of its strip and two new circles at the middles of
/// the outer thirds carry `s / 3` each.
#[allow(clippy::too_many_arguments)]
fn split_in_thirds(
    circles: &mut [Circle],
    (walks, drives, drivings): WalkedCircles<'_>,
    nc: &mut usize,
    (k, yk, w): (usize, f64, f64),
    s: f64,
    walk_at: &dyn Fn(f64) -> Walked,
    disc: &PosedDisc,
) {
    circles[k].width = w * (1.0 - 2.0 * s / 3.0);
    circles[k].sub = true;
    for y in [yk - w / 3.0, yk + w / 3.0] {
        circles[*nc] = Circle {
            y,
            radius: disc.rho(y),
            width: s * w / 3.0,
            face: 0.0,
            flank: false,
            sub: true,
        };
        (walks[*nc], drives[*nc], drivings[*nc]) = walk_at(y);
        *nc += 1;
    }
}

/// The rim slices that touch the rock over part of their strip only:
/// `Some((y, width))`, the middle and width of the touching part (width 0:
/// none); `None`, the slice as it is.
///
/// Whether a circle touches the rock is a yes/no reading of the height map
/// (the rim inside the interpolated rock by micrometres). Where the wall of
/// a groove cut earlier (or by another part of a tilted disc) meets rock the
/// disc is in, the answer switches within a hundredth of a cell of a node
/// row, so sampling each slice at its middle switched the whole strip's
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
fn engaged_strips(
    h: f64,
    n: usize,
    touches_slice: impl Fn(usize) -> bool,
    touches: impl Fn(f64) -> bool,
    free: impl Fn(f64) -> bool,
) -> ([Option<(f64, f64)>; 101], [bool; 101]) {
    let mut out = [None; 101];
    let mut split = [false; 101];
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
    let mut pts = [(0.0f64, false); 103];
    for k in 0..n {
        pts[k + 1] = (slice_y(h, n, k), touches_slice(k));
    }
    pts[0] = (-h, touches(-h));
    pts[n + 1] = (h, touches(h));
    let pts = &pts[..n + 2];
    if pts.iter().all(|p| p.1) {
        return (out, split);
    }
    // the touching spans across the tip
    let mut spans = [(0.0f64, 0.0f64); 52];
    let mut ns = 0;
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
                if ns < spans.len() {
                    spans[ns] = (s, edge);
                    ns += 1;
                }
            }
        } else {
            open = Some(edge);
        }
    }
    if let Some(s) = open {
        if ns < spans.len() {
            spans[ns] = (s, h);
            ns += 1;
        }
    }
    let spans = &spans[..ns];
    for (k, o) in out.iter_mut().enumerate().take(n) {
        let (lo, hi) = (b(k), b(k + 1));
        if spans.iter().any(|&(s, e)| s <= lo && e >= hi) {
            continue;
        }
        let (mut total, mut best) = (0.0f64, (0.0f64, 0.0f64));
        for &(s, e) in spans {
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
    for (sp, o) in split.iter_mut().zip(out.iter()).take(n) {
        if o.is_some_and(|(_, wd)| wd > 0.0) {
            *sp = false;
        }
    }
    (out, split)
}

/// A circle of the disc's surface about the axle that the query walks.
#[derive(Debug, Clone, Copy, Default)]
struct Circle {
    /// Axle coordinate and radius.
    y: f64,
    radius: f64,
    /// Strip width across the tip (rim) or band width (ring).
    width: f64,
    /// 0 for a rim slice, the face's side (+1 / -1) for a ring or a flank.
    face: f64,
    /// A flank band (`width` is then its width along the flank).
    flank: bool,
    /// A rim sample of a split strip: its depth counts in full (not in
    /// proportion to its width) in the side blend.
    sub: bool,
}

impl Circle {
    /// A ring of a side face (not a rim slice, not a flank band).
    fn is_ring(&self) -> bool {
        self.face != 0.0 && !self.flank
    }

    /// The surface element of the law on this circle.
    fn element(&self, disc: &PosedDisc, motion: &Motion) -> Element {
        if self.face == 0.0 {
            Element::rim(disc, self.y, self.width, motion)
        } else if self.flank {
            Element::flank(disc, self.y, self.width, motion)
        } else {
            Element::ring(disc, self.face, self.radius, self.width, motion)
        }
    }
}

/// The circles of the disc's surface the query walks: the `n` rim slices,
/// then rings on each side face (the hub faces with flanks) over the part of
/// it that reaches below `z_top` (when `rings`: the faces carry load), then
/// bands along the flanks, written from the start of `circles`; returns
/// their count. (Filled in place: the array is some 10 kB.)
fn surface_circles(
    circles: &mut [Circle; MAX_CIRCLES],
    disc: &PosedDisc,
    n: usize,
    z_top: f64,
    cell: f64,
    rings: bool,
) -> usize {
    let h = disc.half_width;
    let mut nc = 0;
    for k in 0..n {
        let y = slice_y(h, n, k);
        circles[nc] = Circle {
            y,
            radius: disc.rho(y),
            width: 2.0 * h / n as f64,
            face: 0.0,
            flank: false,
            sub: false,
        };
        nc += 1;
    }
    for side in [1.0f64, -1.0] {
        let Some((r_lo, r_hi)) = face_below(disc, side, z_top).filter(|_| rings) else {
            continue;
        };
        let nr = (((r_hi - r_lo) / (0.5 * cell)).ceil() as usize).clamp(2, MAX_RINGS);
        let dr = (r_hi - r_lo) / nr as f64;
        for j in 0..nr {
            circles[nc] = Circle {
                y: side * h,
                radius: r_lo + dr * (j as f64 + 0.5),
                width: dr,
                face: side,
                flank: false,
                sub: false,
            };
            nc += 1;
        }
    }
    for side in [1.0f64, -1.0] {
        if let Some((s_lo, s_hi)) = flank_below(disc, side, z_top) {
            let (sn, _) = disc.flank_normal();
            let nb = (((s_hi - s_lo) / (0.5 * cell)).ceil() as usize).clamp(2, MAX_FLANK_BANDS);
            let ds = (s_hi - s_lo) / nb as f64;
            for j in 0..nb {
                let s = s_lo + ds * (j as f64 + 0.5);
                let y = side * (h + s * sn);
                circles[nc] = Circle {
                    y,
                    radius: disc.rho_full(y),
                    width: ds,
                    face: side,
                    flank: true,
                    sub: false,
                };
                nc += 1;
            }
        }
    }
    nc
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
            let (load, eff) = arc_contribution_in(
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
