//! Walking one circle of the disc's surface through the rock: the rock
//! over a surface point (`rock_over`), the march from the lowest point to
//! the first arc's ends (`SliceWalk`: `march_from`, `find_start`) and the
//! refinement of those ends (`Walk`).

use super::*;

/// One rim circle (slice `y`) of a posed disc, parametrised for fast walks:
/// world point `base + ex * sin(theta) + ez * cos(theta)`.
pub(super) struct RimCircle {
    pub(super) base: Vector3<f64>,
    pub(super) ex: Vector3<f64>,
    pub(super) ez: Vector3<f64>,
}

impl RimCircle {
    /// The circle of radius `rho` about the axle at axle coordinate `y`.
    pub(super) fn new(disc: &PosedDisc, y: f64, rho: f64) -> Self {
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
    pub(super) fn overlap(
        &self,
        map: &HeightMap,
        s: f64,
        c: f64,
        dir: f64,
        look: f64,
    ) -> (f64, f64) {
        let p = self.base + self.ex * s + self.ez * c;
        // horizontal direction of the walk (d/dtheta of the point)
        let tx = dir * (self.ex.x * c - self.ez.x * s);
        let ty = dir * (self.ex.y * c - self.ez.y * s);
        rock_over(map, &p, tx, ty, 1e-12 * self.ex.norm_squared(), look)
    }

    /// The first of [`RimCircle::overlap`] alone: the rock over the rim
    /// here, without the look-ahead.
    #[inline]
    pub(super) fn overlap_here(&self, map: &HeightMap, s: f64, c: f64) -> f64 {
        let p = self.point(s, c);
        map.height(p.x, p.y) - p.z
    }

    #[inline(always)]
    pub(super) fn point(&self, s: f64, c: f64) -> Vector3<f64> {
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
    pub(super) fn out_of_rock(
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
    pub(super) fn crossings(&self, axis: usize, e: f64) -> Option<[f64; 2]> {
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

    pub(super) fn z(&self, theta: f64) -> f64 {
        self.base.z + self.ex.z * theta.sin() + self.ez.z * theta.cos()
    }

    /// [`RimCircle::z`] at the angle whose `sin_cos` is `(s, c)` (the same
    /// arithmetic: `sin_cos` is `(sin, cos)`).
    pub(super) fn z_sc(&self, (s, c): (f64, f64)) -> f64 {
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
///
/// (Inside the rock, most of a march's samples, it is one height read,
/// inlined into the walks; the look-ahead is a call of its own.)
#[inline(always)]
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
    (here, rock_ahead_of(map, p, (tx, ty), tiny, look, here))
}

/// [`rock_over`]'s look-ahead from a point `here` out of the rock: the
/// larger of `here` and the rock one `look` along `(tx, ty)` (or beside
/// it, where no node was cut).
#[inline(never)]
fn rock_ahead_of(
    map: &HeightMap,
    p: &Vector3<f64>,
    (tx, ty): (f64, f64),
    tiny: f64,
    look: f64,
    here: f64,
) -> f64 {
    let n2 = tx * tx + ty * ty;
    if n2 <= tiny {
        return here;
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
    here.max(z - p.z)
}

/// Refines a sign change of `f` between `t_in` (f > 0) and `t_out` (f <= 0)
/// by the Illinois variant of regula falsi, to `tol` in the argument.
pub(super) fn refine(
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
pub(super) const ANGLE_TOL: f64 = 1e-9;
/// Angular tolerance of the other slices' arc ends, which only weight the
/// lean across the tip: 1e-6 rad is 0.2 um of rim.
pub(super) const LEAN_TOL: f64 = 1e-6;

/// The march of one side of one slice, before its ends are refined: the
/// start is `a` exactly or bracketed by `[a_out, a]`, the end by `[b_in, b_out]`.
#[derive(Debug, Clone, Copy)]
pub struct Walk {
    pub(super) y: f64,
    pub(super) radius: f64,
    pub(super) dir: f64,
    pub(super) a: f64,
    pub(super) a_out: Option<(f64, f64, f64)>,
    pub(super) b_in: (f64, f64),
    pub(super) b_out: Option<(f64, f64)>,
    pub(super) u_max: f64,
    /// `a.sin_cos()` where the march has it (a start at the lowest point).
    pub(super) sc_a: Option<(f64, f64)>,
    /// `b_in.0.sin_cos()` and `b_out`'s, where the march has them (its
    /// samples' sines and cosines, turned from the lowest point's).
    pub(super) sc_b: (Option<SinCos>, Option<SinCos>),
    /// The rim's heights at the ends, once read (`Walk::end_heights`).
    pub(super) ends: Option<EndHeights>,
}

/// An angle's `sin_cos`.
pub(super) type SinCos = (f64, f64);

/// A finished arc with `sin_cos` of its `a` and `b`.
pub(super) type Finished = (Arc, [(f64, f64); 2]);

/// A circle as walked: its walks on both sides, which sides may carry load,
/// and where its surface drives (`None`: not found, the disc below the
/// rest speed or the circle out of reach).
pub(super) type Walked = ([Option<Walk>; 2], [bool; 2], Option<Driving>);

/// World heights of a walk's rim at its start `a`, at its last sample
/// inside `b_in`, and at the far end of its end's bracket (`b_out`, else
/// `b_in`): what the depth bounds and the unrefined ends read, once; with
/// `sin_cos` of `a` and `b_in`.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct EndHeights {
    pub(super) a: f64,
    pub(super) b_in: f64,
    pub(super) b_far: f64,
    pub(super) sc_a: (f64, f64),
    pub(super) sc_b_in: (f64, f64),
}

impl Walk {
    /// Depth of the arc if its end lay at `b` (`z(b) - z(a)`).
    pub(super) fn depth_to(&self, disc: &PosedDisc, b: f64) -> f64 {
        let rim = RimCircle::new(disc, self.y, self.radius);
        (rim.z(b) - rim.z(self.a)).max(0.0)
    }

    /// Largest depth the refined arc can have.
    pub fn depth_bound(&self, disc: &PosedDisc) -> f64 {
        self.depth_to(disc, self.b_out.map_or(self.b_in.0, |o| o.0))
    }

    /// The rim's heights at the walk's ends ([`EndHeights`]).
    pub(super) fn end_heights(&self, disc: &PosedDisc) -> EndHeights {
        if let Some(z) = self.ends {
            return z;
        }
        let rim = RimCircle::new(disc, self.y, self.radius);
        let sc_a = self.sc_a.unwrap_or_else(|| self.a.sin_cos());
        let sc_b_in = self.sc_b.0.unwrap_or_else(|| self.b_in.0.sin_cos());
        let b_in = rim.z_sc(sc_b_in);
        EndHeights {
            a: rim.z_sc(sc_a),
            b_in,
            b_far: self.b_out.map_or(b_in, |o| match self.sc_b.1 {
                Some(sc) => rim.z_sc(sc),
                None => rim.z(o.0),
            }),
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
    pub(super) fn finish_from(
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

/// One rim circle to walk (a tip slice, a side-face ring or a flank band):
/// the circle at axle coordinate `y` of radius `radius`, from its lowest
/// point `theta0` up to `reach` (at most half a turn) either way, in steps
/// of about `step` rad, looking `look` ahead.
#[derive(Debug, Clone, Copy)]
pub(super) struct SliceWalk {
    pub(super) y: f64,
    pub(super) radius: f64,
    pub(super) theta0: f64,
    /// `theta0.sin_cos()`, from the disc's rotation.
    pub(super) sc0: (f64, f64),
    pub(super) reach: f64,
    pub(super) step: f64,
    pub(super) look: f64,
    /// Whether the start search may pass over runs of samples that a bound
    /// of the rock under them shows to be out of it (`!num.search_every_sample`).
    pub(super) skip: bool,
}

impl SliceWalk {
    /// The walk of the circle `(y, radius)` over the part of it below
    /// `z_top`, in steps of about `step_len` of rim; `None` when none is
    /// (`low`: `disc.lowest()`).
    pub(super) fn below(
        disc: &PosedDisc,
        low: &Lowest,
        (y, radius): (f64, f64),
        z_top: f64,
        (step_len, look, skip): (f64, f64, bool),
    ) -> Option<Self> {
        let (theta0, reach) = disc.arc_below_at(low, y, radius, z_top)?;
        Some(Self {
            y,
            radius,
            theta0,
            sc0: low.sc,
            reach: reach.min(std::f64::consts::PI),
            step: step_len / radius,
            look,
            skip,
        })
    }

    /// The circle and the rock over its lowest point (at `self.sc0`).
    pub(super) fn start(&self, map: &HeightMap, disc: &PosedDisc) -> (RimCircle, f64) {
        let rim = RimCircle::new(disc, self.y, self.radius);
        let here0 = rim.overlap_here(map, self.sc0.0, self.sc0.1);
        (rim, here0)
    }

    /// Marches the sides `wanted` (`dir` = +1 towards cutter +x,
    /// then -1) and brackets each contact arc's ends, written into `out`
    /// (`[+1, -1]`; a side not walked is `None`): the circle and the rock
    /// over its lowest point read once. Each walk is
    /// some 150 bytes: built where it is kept, not copied there (a pair
    /// returned by value and stored was a `memcpy` of 300 bytes a circle).
    #[inline(always)]
    pub(super) fn march_into(
        &self,
        map: &HeightMap,
        disc: &PosedDisc,
        wanted: [bool; 2],
        out: &mut [Option<Walk>; 2],
    ) {
        let side = self.sides(map, disc);
        let dir = |k: usize| if k == 0 { 1.0 } else { -1.0 };
        for (k, w) in out.iter_mut().enumerate() {
            *w = if wanted[k] { side(dir(k)) } else { None };
        }
    }

    /// The march of one side (`dir`) of the circle, the circle and the rock
    /// over its lowest point read once for both.
    #[inline(always)]
    pub(super) fn sides<'a>(
        &'a self,
        map: &'a HeightMap,
        disc: &PosedDisc,
    ) -> impl Fn(f64) -> Option<Walk> + 'a {
        let (rim, here0) = self.start(map, disc);
        move |dir: f64| self.march_from(map, &rim, here0, dir)
    }

    /// Which sides (`[+1, -1]`) of the circle drive into the rock within
    /// their reach, for the surface element `e` on it (`d` its
    /// [`Element::driving`]), over more than `sliver` rad in all
    /// ([`DRIVE_SLIVER_CELLS`]).
    pub(super) fn sides_driving(&self, e: &Element, d: Driving, sliver: f64) -> [bool; 2] {
        let (t0, r) = (self.theta0, self.reach);
        [(t0, t0 + r), (t0 - r, t0)].map(|(lo, hi)| {
            let (parts, np) = e.driving_parts_on(d, lo, hi);
            parts[..np].iter().map(|p| p.1 - p.0).sum::<f64>() > sliver
        })
    }

    /// Whether walking the sides `wanted` (`[+1, -1]`;
    /// [`SliceWalk::march_into`]) finds a contact on one of them (its walk
    /// `is_some()`), without walking the arcs: the rock is over the rim at
    /// its lowest point, or on one of those sides within the reach.
    pub(super) fn touches(&self, map: &HeightMap, disc: &PosedDisc, wanted: [bool; 2]) -> bool {
        let (rim, here0) = self.start(map, disc);
        if here0 > 0.0 {
            return true;
        }
        let n = ((self.reach / self.step).ceil() as usize).max(1);
        [1.0, -1.0]
            .into_iter()
            .zip(wanted)
            .filter(|w| w.1)
            .map(|w| w.0)
            .any(|dir| {
                let dt = dir * self.reach / n as f64;
                self.find_start(map, &rim, here0, dir, dt).is_some()
            })
    }

    /// One side (`dir`) of [`SliceWalk::march_into`] on the circle `rim`
    /// from `theta0` (sine and cosine `sc0`), where the rock over the rim is
    /// `here0`.
    ///
    /// (Until the start is found only the rock over the rim itself is read:
    /// where it is positive the look-ahead is that same value, see
    /// [`rock_over`], and where it is not the walk has not started.)
    fn march_from(&self, map: &HeightMap, rim: &RimCircle, here0: f64, dir: f64) -> Option<Walk> {
        let (y, radius, theta0, reach, look) =
            (self.y, self.radius, self.theta0, self.reach, self.look);
        let (s0, c0) = self.sc0;
        let n = ((reach / self.step).ceil() as usize).max(1);
        let dt = dir * reach / n as f64;
        let (sd, cd) = sin_cos_near(dt, 0.0, (0.0, 1.0));
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
            let (t, tp, up, here) = self.find_start(map, rim, here0, dir, dt)?;
            u_max = here;
            // resume the coarse grid at the last grid angle before the start
            k = ((t - theta0) / dt).floor().max(0.0) as usize;
            (s, c) = (theta0 + dt * k as f64).sin_cos();
            (t, Some((tp, up, here)), t, here)
        };
        let (mut t_prev, mut u_prev) = (t_prev, u_prev);
        // `t_prev`'s sine and cosine where the march has them, and `b_out`'s
        let mut sc_prev_in = sc_a;
        let mut sc_out = None;
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
                        sc_out = Some((ss, cs));
                        break;
                    }
                    u_max = u_max.max(here_s);
                    t_prev = ts;
                    u_prev = ahead_s;
                    sc_prev_in = Some((ss, cs));
                }
                if out.is_some() || !at_top {
                    if out.is_none() {
                        sc_out = Some((s, c));
                    }
                    break out.or(Some((t, ahead)));
                }
                // inside up to the top: the arc ends there (k = n, so the
                // walk's next turn ends it)
            }
            u_max = u_max.max(here);
            t_prev = t;
            u_prev = ahead;
            sc_prev_in = Some((s, c));
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
            sc_b: (sc_prev_in, sc_out),
            ends: None,
        })
    }

    /// The start of a walk whose lowest point `theta0` (sine and cosine
    /// `sc0`) is out of the rock (`here0 <= 0`), on the side `dir` within
    /// `reach`, the coarse step being `dt`: the first angle where the rock is
    /// over the rim, the angle before it and the rock over the rim there, and
    /// the rock over the rim at the start. `None` when the rim stays out.
    fn find_start(
        &self,
        map: &HeightMap,
        rim: &RimCircle,
        here0: f64,
        dir: f64,
        dt: f64,
    ) -> Option<(f64, f64, f64, f64)> {
        let (radius, theta0, reach, look, skip) =
            (self.radius, self.theta0, self.reach, self.look, self.skip);
        let (s0, c0) = self.sc0;
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
pub(super) const START_FIRST: usize = 4;
pub(super) const START_RETRY: usize = 8;

/// How far \[m\] the rim must be above the nodes under it for
/// [`RimCircle::out_of_rock`] (a computed height may exceed its cell's
/// highest node by round-off).
pub(super) const OUT_OF_ROCK_MARGIN: f64 = 1e-9;

/// How far \[m\] [`RimCircle::out_of_rock`] widens the box of a run's points
/// beyond its bound of the rim between them.
pub(super) const OUT_OF_ROCK_PAD: f64 = 1e-9;

/// Samples of the start search tested as one run by
/// [`RimCircle::out_of_rock`].
pub(super) const START_RUN: usize = 16;

/// `(sin t, cos t)` from a nearby angle `t0` whose `(sin, cos)` is `sc0`:
/// `sc0` turned by `t - t0`, whose sine and cosine come from their Taylor
/// series (the terms left out are below 1e-19 for |t - t0| <= 0.05 rad),
/// or `t.sin_cos()` farther away. An end's refinement stays within one
/// step of the march from its last sample, and each of its trials cost a
/// `sin_cos` (3 % of a cutterhead step's instructions).
#[inline]
pub(super) fn sin_cos_near(t: f64, t0: f64, (s0, c0): (f64, f64)) -> (f64, f64) {
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
pub(super) fn advance_by(s: &mut f64, c: &mut f64, sd: f64, cd: f64) {
    let s1 = *s * cd + *c * sd;
    *c = *c * cd - *s * sd;
    *s = s1;
}

#[cfg(test)]
mod tests {
    use super::{sin_cos_near, RimCircle};
    use crate::core::heightmap::{Grid, HeightMap};
    use crate::core::params::CutterParams;
    use crate::core::{cutter::PosedDisc, Pose};
    use nalgebra::Vector3;

    /// The sines and cosines a march keeps for its last sample inside and
    /// the sample after it (turned step by step from the lowest point's) are
    /// those of the angles, on discs rolled and turned every way, their
    /// lowest points in the rock and above a groove in it.
    #[test]
    fn a_marchs_end_sines_and_cosines_are_its_angles() {
        let grid = Grid::new(-0.3, 0.3, -0.3, 0.3, 601, 601);
        let mut map = HeightMap::flat(grid, 0.0);
        // a groove 4 mm deep along x, 8 mm wide, under the discs' centres
        for i in 0..601 {
            for j in 296..=304 {
                map.set_node(i, j, -4e-3);
            }
        }
        let c = CutterParams::default();
        let mut next = crate::core::uniforms(0x1234_5678_9abc_def1_u64);
        let (mut checked, mut from_search) = (0, 0);
        for _ in 0..4000 {
            let (roll, yaw) = (1.0 * (2.0 * next() - 1.0), 3.1 * (2.0 * next() - 1.0));
            let depth = 8e-3 * next();
            let pose = Pose::new(0.0, 0.0, c.radius - depth, roll, 0.0, yaw);
            let disc = PosedDisc::new(&c, &pose);
            let y = disc.half_width * (2.0 * next() - 1.0);
            let low = disc.lowest();
            let walk =
                super::SliceWalk::below(&disc, &low, (y, disc.rho(y)), 0.01, (4e-3, 1e-3, true));
            let Some(walk) = walk else { continue };
            let side = walk.sides(&map, &disc);
            for dir in [1.0, -1.0] {
                let Some(w) = side(dir) else { continue };
                if w.sc_a.is_none() {
                    from_search += 1;
                }
                let close = |sc: (f64, f64), t: f64| {
                    let (s, c) = t.sin_cos();
                    assert!(
                        (sc.0 - s).abs() < 1e-13 && (sc.1 - c).abs() < 1e-13,
                        "{sc:?} {t}"
                    );
                };
                if let Some(sc) = w.sc_b.0 {
                    close(sc, w.b_in.0);
                    checked += 1;
                }
                match (w.sc_b.1, w.b_out) {
                    (Some(sc), Some(o)) => close(sc, o.0),
                    (None, None) => {}
                    other => panic!("{other:?}"),
                }
            }
        }
        assert!(checked > 600 && from_search > 20, "{checked} {from_search}");
    }

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
