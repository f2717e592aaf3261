//! Contact between the posed disc and the height map (thesis ch. 7, extended).
//!
//! **Where the rim touches.** The tip is cut into `n` slices across its width
//! (axle coordinates `y_k` from `-T/2` to `T/2`, `y = 0` included). On each
//! slice's rim circle the query starts at the lowest point and walks outwards
//! on both sides, finding the first arc `[a, b]` where the rim is below the
//! rock; the ends are refined by regula falsi. The whole circle can be
//! reached, the upper rim included (the thesis searched only the lower half,
//! its limitation 10.1).
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
//! **Which arc cuts.** Each side of the lowest point gives an arc of depth
//! `p+` (towards cutter +x) and `p-`. A rolling cutter cuts with its leading
//! arc; behind the lowest point the rock was cut by the cutter itself and
//! carries (almost) nothing (Rostami's rear non-loading zone, thesis 3.2.2).
//! The arcs of the governing (deepest) slice are blended with weights
//! `p^4 / (p+^4 + p-^4)`: the leading arc wins, and a cutter at rest in its
//! own symmetric pit pushes straight up with no jump in between. Slices sit at
//! the centres of `n` equal strips of the tip, so none lies on the groove wall
//! that the height map blurs.
//!
//! **Force.** CSM gives the magnitude from `p` (eq. 54, the depth of the
//! governing slice) and its angle `beta = phi / (2 + psi)` from the lowest
//! point in the rim plane. Across the tip the force leans by the mean of the
//! tip-profile normals of the slices weighted by their contact arc length,
//! so a cut beside a groove or a tilted cutter gets the side force its
//! contact geometry gives, and a symmetric cut gets none.
//!
//! **Side faces.** Where a tilted disc's flat face lies in the rock, every
//! height-map node under it whose vertical meets the face pushes with the CSM
//! base pressure over its cell along the face normal, weighted like the rim's
//! arcs: nodes ahead of the contact's lowest point by the leading weight,
//! those behind by the trailing one.
//!
//! **Elastic layer.** A cut leaves the rock `elastic_depth` inside the rim
//! (see `cut_cutter_heightmap`), so a cutter held still keeps its contact.
//! The force is faded in over that depth (`smoothstep(u / elastic_depth)`,
//! `u` the deepest the rim is inside the rock on any slice), so lifting the
//! cutter off its groove unloads it without a jump up.

use nalgebra::Vector3;

use super::csm::{contact_angle, CsmLaw};
use super::cutter::{wrap, Face, PosedDisc};
use super::heightmap::HeightMap;
use super::params::Numerics;

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

#[inline]
fn smoothstep(s: f64) -> f64 {
    let s = s.clamp(0.0, 1.0);
    s * s * (3.0 - 2.0 * s)
}

/// One rim circle (slice `y`) of a posed disc, parametrised for fast walks:
/// world point `base + ex * sin(theta) + ez * cos(theta)`.
struct RimCircle {
    base: Vector3<f64>,
    ex: Vector3<f64>,
    ez: Vector3<f64>,
}

impl RimCircle {
    fn new(disc: &PosedDisc, y: f64) -> Self {
        let rho = disc.rho(y);
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
    #[inline]
    fn overlap(&self, map: &HeightMap, s: f64, c: f64, dir: f64, look: f64) -> (f64, f64) {
        let p = self.base + self.ex * s + self.ez * c;
        let here = map.height(p.x, p.y) - p.z;
        if here > 0.0 {
            // inside the rock already: the look-ahead cannot change the sign
            return (here, here);
        }
        // horizontal direction of the walk (d/dtheta of the point)
        let tx = dir * (self.ex.x * c - self.ez.x * s);
        let ty = dir * (self.ex.y * c - self.ez.y * s);
        let n2 = tx * tx + ty * ty;
        if n2 > 1e-12 * self.ex.norm_squared() {
            let k = look / n2.sqrt();
            (
                here,
                here.max(map.bilinear(p.x + k * tx, p.y + k * ty) - p.z),
            )
        } else {
            (here, here)
        }
    }

    /// Angles where the rim's world coordinate `axis` (0 = x, 1 = y) equals `e`.
    fn crossings(&self, axis: usize, e: f64) -> Vec<f64> {
        // base + ex sin + ez cos = e  <=>  m cos(theta - tm) = e - base
        let (a, b) = (self.ex[axis], self.ez[axis]);
        let m = (a * a + b * b).sqrt();
        let rhs = e - self.base[axis];
        if m < 1e-15 || rhs.abs() > m {
            return Vec::new();
        }
        let tm = a.atan2(b);
        let d = (rhs / m).acos();
        vec![tm + d, tm - d]
    }

    fn z(&self, theta: f64) -> f64 {
        self.base.z + self.ex.z * theta.sin() + self.ez.z * theta.cos()
    }
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
    dir: f64,
    a: f64,
    a_out: Option<(f64, f64, f64)>,
    b_in: (f64, f64),
    b_out: Option<(f64, f64)>,
    u_max: f64,
}

impl Walk {
    /// Depth of the arc if its end lay at `b` (`z(b) - z(a)`).
    fn depth_to(&self, disc: &PosedDisc, b: f64) -> f64 {
        let rim = RimCircle::new(disc, self.y);
        (rim.z(b) - rim.z(self.a)).max(0.0)
    }

    /// Largest depth the refined arc can have.
    pub fn depth_bound(&self, disc: &PosedDisc) -> f64 {
        self.depth_to(disc, self.b_out.map_or(self.b_in.0, |o| o.0))
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
        let rim = RimCircle::new(disc, self.y);
        let dir = self.dir;
        let a = match (self.a_out, refine_ends) {
            (Some((t_out, u_out, u_in)), true) => {
                let f_start = |t: f64| {
                    let (s, c) = t.sin_cos();
                    rim.overlap(map, s, c, dir, look).0
                };
                refine(&f_start, self.a, t_out, u_in, u_out, tol)
            }
            _ => self.a,
        };
        let b = match (self.b_out, refine_ends) {
            (Some((t_out, u_out)), true) => {
                let f_end = |t: f64| {
                    let (s, c) = t.sin_cos();
                    rim.overlap(map, s, c, dir, look).1
                };
                refine(&f_end, self.b_in.0, t_out, self.b_in.1, u_out, tol)
            }
            (Some(_), false) => self.b_in.0,
            (None, _) => self.b_in.0,
        };
        Arc {
            a,
            b,
            depth: (rim.z(b) - rim.z(a)).max(0.0),
            length: disc.rho(self.y) * (b - a).abs(),
            u_max: self.u_max,
        }
    }
}

/// Marches one side (`dir` = +1 towards cutter +x) of one slice from the
/// lowest point `theta0` up to `theta0 + dir * reach`, in steps of about
/// `step`, and brackets the contact arc's ends.
#[allow(clippy::too_many_arguments)]
pub fn march(
    map: &HeightMap,
    disc: &PosedDisc,
    y: f64,
    theta0: f64,
    reach: f64,
    dir: f64,
    step: f64,
    look: f64,
) -> Option<Walk> {
    let rim = RimCircle::new(disc, y);
    let n = ((reach / step).ceil() as usize).max(1);
    let dt = dir * reach / n as f64;
    let (sd, cd) = dt.sin_cos();
    let (mut s, mut c) = theta0.sin_cos();
    let advance = |s: &mut f64, c: &mut f64| {
        let s1 = *s * cd + *c * sd;
        *c = *c * cd - *s * sd;
        *s = s1;
    };
    // contact starts where the rim is below the rock itself ...
    let (here0, ahead0) = rim.overlap(map, s, c, dir, look);
    let mut k = 0;
    let mut u_max = here0.max(0.0);
    let (a, a_out, t_prev, u_prev) = if here0 > 0.0 {
        (theta0, None, theta0, ahead0)
    } else {
        // the lowest point is out of the rock: search for the start with a
        // step of half a cell of rim, so that a short arc (the rim meeting
        // the end face of the rock, a groove's shoulder) is not stepped over
        let fine = (look * 0.5 / disc.rho(y)).min(dt.abs());
        let m = ((reach / fine).ceil() as usize).max(1);
        let dtf = dir * reach / m as f64;
        // ... and at the angles where the rim crosses the edges of the map,
        // where rock begins with a vertical face and an arc can be shorter
        // than any step
        let mut angles: Vec<f64> = (1..=m).map(|kf| theta0 + dtf * kf as f64).collect();
        let g = map.grid();
        for (axis, edges) in [(0usize, [g.x_min, g.x_max()]), (1, [g.y_min, g.y_max()])] {
            for e in edges {
                for t in rim.crossings(axis, e) {
                    let off = wrap(t - theta0) * dir;
                    if off > 0.0 && off < reach {
                        angles.push(theta0 + off * dir);
                    }
                }
            }
        }
        angles.sort_by(|p, q| ((p - theta0) * dir).total_cmp(&((q - theta0) * dir)));
        let (mut tp, mut up) = (theta0, here0);
        let mut found = None;
        for &t in &angles {
            let (st, ct) = t.sin_cos();
            let (here, ahead) = rim.overlap(map, st, ct, dir, look);
            if here > 0.0 {
                found = Some((t, tp, up, here, ahead));
                break;
            }
            tp = t;
            up = here;
        }
        let (t, tp, up, here, ahead) = found?;
        u_max = here;
        // resume the coarse grid at the last grid angle before the start
        k = ((t - theta0) / dt).floor().max(0.0) as usize;
        (s, c) = (theta0 + dt * k as f64).sin_cos();
        (t, Some((tp, up, here)), t, ahead)
    };
    let (mut t_prev, mut u_prev) = (t_prev, u_prev);
    // ... and lasts while it is below the rock here or one cell ahead
    let b_out = loop {
        k += 1;
        if k > n {
            break None;
        }
        advance(&mut s, &mut c);
        let t = theta0 + dt * k as f64;
        let (here, ahead) = rim.overlap(map, s, c, dir, look);
        if ahead <= 0.0 {
            break Some((t, ahead));
        }
        u_max = u_max.max(here);
        t_prev = t;
        u_prev = ahead;
    };
    Some(Walk {
        y,
        dir,
        a,
        a_out,
        b_in: (t_prev, u_prev),
        b_out,
        u_max,
    })
}

/// A side whose blend weight cannot exceed this is not refined: its arcs
/// change the force by less than this fraction.
const NEGLIGIBLE_WEIGHT: f64 = 1e-14;

/// The contact of `disc` with `map` under `law` (kerf's direction rule).
pub fn contact(
    map: &HeightMap,
    disc: &PosedDisc,
    law: &CsmLaw,
    num: &Numerics,
    elastic_depth: f64,
) -> Contact {
    let g = map.grid();
    let none = Contact::default();
    // highest rock anywhere under the disc
    let r = disc.radius;
    let Some((i0, i1, j0, j1)) = g.node_range(
        disc.centre.x - r - g.dx,
        disc.centre.x + r + g.dx,
        disc.centre.y - r - g.dy,
        disc.centre.y + r + g.dy,
    ) else {
        return none;
    };
    let z_top = map.max_height(i0, i1, j0, j1);
    if disc.footprint_below(z_top).is_none() {
        return none;
    }
    let cell = g.dx.min(g.dy);
    let look = g.dx.max(g.dy);
    let n = num.tip_slices;
    let h = disc.half_width;
    let tr = disc.tip_radius;

    // per slice, both sides: march first, then refine the ends of the arcs
    // on every side whose weight in the blend can matter
    let mut walks = [[None::<Walk>; 2]; 101];
    for (k, pair) in walks.iter_mut().enumerate().take(n) {
        let y = slice_y(h, n, k);
        let rho = disc.rho(y);
        let Some((theta0, reach)) = disc.arc_below(y, rho, z_top) else {
            continue;
        };
        let step = num.arc_step_cells * cell / rho;
        for (s, dir) in [(0usize, 1.0f64), (1, -1.0)] {
            pair[s] = march(
                map,
                disc,
                y,
                theta0,
                reach.min(std::f64::consts::PI),
                dir,
                step,
                look,
            );
        }
    }
    let mut lo = [0.0f64; 2];
    let mut hi = [0.0f64; 2];
    for pair in walks.iter().take(n) {
        for s in 0..2 {
            if let Some(w) = pair[s] {
                lo[s] = lo[s].max(w.depth_to(disc, w.b_in.0));
                hi[s] = hi[s].max(w.depth_bound(disc));
            }
        }
    }
    let matters = |s: usize| {
        let (me, other) = (hi[s].powi(4), lo[1 - s].powi(4));
        me + other == 0.0 || me / (me + other) > NEGLIGIBLE_WEIGHT
    };
    let refine_side = [matters(0), matters(1)];
    // slices that may turn out deepest get the fine tolerance
    let deepest_lo = lo[0].max(lo[1]);
    let mut arcs = [[None::<Arc>; 2]; 101];
    let mut gov: Option<(usize, f64)> = None;
    for k in 0..n {
        let may_govern = walks[k]
            .iter()
            .flatten()
            .any(|w| w.depth_bound(disc) >= deepest_lo);
        let tol = if may_govern { ANGLE_TOL } else { LEAN_TOL };
        for s in 0..2 {
            let arc = walks[k][s].map(|w| w.finish(map, disc, look, refine_side[s], tol));
            if let Some(a) = arc {
                if gov.is_none_or(|(_, d)| a.depth > d) {
                    gov = Some((k, a.depth));
                }
            }
            arcs[k][s] = arc;
        }
    }
    let mut c = Contact::default();
    let any_rim = gov.is_some();
    let (kg, _) = gov.unwrap_or((0, 0.0));
    let [ap, am] = arcs[kg];
    let (pp, pm) = (ap.map_or(0.0, |a| a.depth), am.map_or(0.0, |a| a.depth));
    let (wp, wm) = match (ap, am) {
        (Some(_), None) => (1.0, 0.0),
        (None, Some(_)) => (0.0, 1.0),
        _ => {
            let (a, b) = (pp.powi(4), pm.powi(4));
            if a + b > 0.0 {
                (a / (a + b), b / (a + b))
            } else {
                (0.5, 0.5)
            }
        }
    };
    if any_rim {
        let frac = law.resultant_fraction();
        let mut d_plane = Vector3::zeros();
        let mut theta_slip = 0.0;
        for (arc, w) in [(ap, wp), (am, wm)] {
            if let (Some(arc), true) = (arc, w > 0.0) {
                let tf = arc.a + (arc.b - arc.a) * frac;
                d_plane += w * Vector3::new(-tf.sin(), 0.0, tf.cos());
                theta_slip += w * arc.a;
            }
        }
        // elastic fade: the deepest the rim is inside the rock on any slice
        let u_in = arcs
            .iter()
            .take(n)
            .flatten()
            .flatten()
            .fold(0.0f64, |m, a| m.max(a.u_max));
        let fade = smoothstep(u_in / elastic_depth);
        let (mut lat, mut vert, mut wsum, mut ysum) = (0.0, 0.0, 0.0, 0.0);
        for (k, pair) in arcs.iter().enumerate().take(n) {
            let y = slice_y(h, n, k);
            let len = |a: Option<Arc>| a.map_or(0.0, |a| a.length);
            let w = wp * len(pair[0]) + wm * len(pair[1]);
            lat -= w * y / tr;
            vert += w * (tr * tr - y * y).max(0.0).sqrt() / tr;
            wsum += w;
            ysum += w * y;
        }
        let dn = d_plane.norm();
        if dn > 0.0 && wsum > 0.0 {
            let dp = d_plane / dn;
            let dir = Vector3::new(dp.x * vert, lat, dp.z * vert).normalize();
            let p = wp * pp + wm * pm;
            c.penetration = p;
            c.phi = contact_angle(disc.radius, p.min(2.0 * disc.radius));
            c.rim_force = disc.rot * (dir * law.force(p) * fade);
            let theta_f = (-dp.x).atan2(dp.z);
            let y_f = (ysum / wsum).clamp(-h, h);
            c.application = disc.rot * disc.rim_point_local(theta_f, y_f);
            c.slip_point = disc.rot * disc.rim_point_local(theta_slip, y_f);
            c.slip_normal = -(disc.rot * disc.rim_normal_local(theta_slip, y_f));
            c.in_contact = true;
        }
    }
    // side faces: only a disc whose axle is not horizontal can put a side
    // face under the rock along a vertical
    if disc.rot[(2, 1)].abs() > 1e-12 {
        let (f, m, touched) = side_faces(map, disc, law, num, elastic_depth, z_top, &c, (wp, wm));
        c.side_force = f;
        c.side_moment = m;
        c.in_contact |= touched;
    }
    c
}

/// Load of a tilted disc's flat side faces: every node under a face whose
/// vertical meets the face below the rock pushes with the CSM base pressure
/// over its cell along the face normal, with the rim's leading/trailing
/// weights `w` on either side of the contact's lowest point. Returns the
/// force and moment (about the centre, rock frame) and whether any node
/// touched.
#[allow(clippy::too_many_arguments)]
fn side_faces(
    map: &HeightMap,
    disc: &PosedDisc,
    law: &CsmLaw,
    num: &Numerics,
    elastic_depth: f64,
    z_top: f64,
    rim: &Contact,
    (wp, wm): (f64, f64),
) -> (Vector3<f64>, Vector3<f64>, bool) {
    let g = map.grid();
    let (mut force, mut moment, mut touched) = (Vector3::zeros(), Vector3::zeros(), false);
    let Some(bb) = disc.footprint_below(z_top) else {
        return (force, moment, touched);
    };
    let Some((i0, i1, j0, j1)) = g.node_range(bb[0], bb[1], bb[2], bb[3]) else {
        return (force, moment, touched);
    };
    let p_ref = rim.penetration.max(num.p_reg);
    let pressure = law.base_pressure(p_ref, contact_angle(disc.radius, p_ref));
    // a face sliding in its own plane stays in elastic touch with the rock it
    // cut behind the lowest point, which carries the trailing weight only
    let x_split = (disc.rot.transpose() * rim.slip_point).x;
    for j in j0..=j1 {
        for i in i0..=i1 {
            let (x, y) = g.node_xy(i, j);
            let Some((zl, Face::Side(s))) = disc.lower_boundary(x, y) else {
                continue;
            };
            let u = map.node(i, j) - zl;
            if u <= 0.0 {
                continue;
            }
            let q = Vector3::new(x, y, zl) - disc.centre;
            let w = if (disc.rot.transpose() * q).x >= x_split {
                wp
            } else {
                wm
            };
            let n_out = disc.rot * Vector3::new(0.0, s as f64, 0.0);
            let area = g.cell_area() / n_out.z.abs().max(0.1);
            let f = -n_out * (pressure * area * w * smoothstep(u / elastic_depth));
            force += f;
            moment += q.cross(&f);
            touched = true;
        }
    }
    (force, moment, touched)
}
