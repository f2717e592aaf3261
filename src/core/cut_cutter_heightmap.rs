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

use super::contact_law::smoothstep;
use super::cutter::{Columns, PosedDisc};
use super::heightmap::{Grid, HeightMap, Patch, TileRect};
use super::params::Numerics;

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

/// How far ahead of a moving disc its cut reaches: nodes past `limit` along
/// the plan direction of travel `dir` (`x dir.0 + y dir.1 > limit`) stay.
///
/// A rolling disc's next cuts, a sweep step further on, take every node
/// under its front arc lower again; lowering them now only to lower them
/// again is most of a cut's work (the front arc of a 19 in disc 6 mm deep
/// is 55 mm long, a sweep step 1 mm). A node's final height comes from the
/// cut whose lowest point passes nearest to it (half a sweep step), or
/// behind it for a disc going deeper; a disc climbing out of the rock
/// reaches lowest `R slope` ahead, so its cut reaches `2 R slope` further.
///
/// The contact then reads the rock ahead of the disc as it stands before
/// the disc, not a surface carved to the disc's own surface a sweep step
/// ago, which a height map holds only to its interpolation error (across
/// a 12.7 mm tip radius at 1 mm cells, 10 um against a 2 um elastic layer):
/// tilted discs' forces now converge with the cells. Where the uncut rock
/// begins the map steps up by the depth of the cut. Reaching further
/// ahead (past the still-there test's 4 mm) was tried: the 0-70 deg tilt
/// sweep's largest step grew from under 2 % to 2.26 % of F_N.
/// [`Front::of`] says when the bound holds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Front {
    pub dir: (f64, f64),
    pub limit: f64,
}

/// Velocity of the disc's lowest point `low` when its frame moves with
/// `velocity` and angular velocity `omega` (the spin about the axle moves
/// no part of the solid).
fn lowest_point_velocity(
    disc: &PosedDisc,
    low: &nalgebra::Vector3<f64>,
    velocity: &nalgebra::Vector3<f64>,
    omega: &nalgebra::Vector3<f64>,
) -> nalgebra::Vector3<f64> {
    let axle = disc.rot.column(1).into_owned();
    let w = omega - axle * omega.dot(&axle);
    velocity + w.cross(&(low - disc.centre))
}

/// How far a cut of `disc` whose frame moves with `velocity` and angular
/// velocity `omega` reaches: its [`Front`] ([`Front::of`]) and how much more
/// than the elastic layer it leaves over the disc (`plunge_lag`), from
/// the lowest point and its velocity found once; no front and no lag with
/// a plastic fraction below 1.
pub fn cut_reach(
    disc: &PosedDisc,
    velocity: &nalgebra::Vector3<f64>,
    omega: &nalgebra::Vector3<f64>,
    grid: &Grid,
    numerics: &Numerics,
    plastic_fraction: f64,
) -> (Option<Front>, f64) {
    if plastic_fraction != 1.0 {
        return (None, 0.0);
    }
    let low = disc.lowest_point();
    let v = lowest_point_velocity(disc, &low, velocity, omega);
    (
        Front::at(disc, &low, &v, grid, numerics),
        plunge_lag(&v, numerics),
    )
}

/// Descent (the downward share of the lowest point's velocity) from which
/// a plunging disc's cut stops short ([`plunge_lag`]): 1 in 2, where
/// [`Front::of`] stops bounding a rolling disc's cut ahead.
const PLUNGE_FROM: f64 = 0.447_213_595_499_958; // 1 / sqrt(5)

/// How far above a disc plunging into the rock its cut stops \[m\], on top
/// of the elastic layer, its lowest point moving with `v`: half a sweep
/// step for a disc going straight down, blended in from a descent of 1 in 2
/// (`PLUNGE_FROM`, where the cut stops being bounded ahead, [`Front::of`])
/// to twice that; 0 for any other motion (and, in [`cut_reach`], with a
/// plastic fraction below 1).
///
/// A disc pressed into the rock in Co-Simulation cut its pit to its own
/// surface at every step (20 um deeper a 1 ms step at 20 mm/s), and the
/// contact then read the pit's edges across the tip as the map's chord
/// between a cut and an uncut node: its normal force was up to 7.5 % below
/// the CSM force deeper than 1 mm, and from 0.8 to 1.5 mm deep up to 17 %
/// below Model Exchange's. Model Exchange cuts once a
/// sweep step of travel, so its rim runs into rock as it stands between
/// cuts. Cut short by half a sweep step, a plunging disc's pit stays as
/// far ahead of its rim on average in either interface, and the contact
/// reads its arcs up to the uncut face, as the CSM's plunged disc. The rock
/// left is cut once the disc stops (a disc at rest cuts in full) or rolls
/// on (its next cuts take it).
fn plunge_lag(v: &nalgebra::Vector3<f64>, numerics: &Numerics) -> f64 {
    let speed = v.norm();
    // slower than a micrometre a second: at rest
    if speed.is_nan() || speed <= 1e-6 {
        return 0.0;
    }
    let descent = -v.z / speed;
    0.5 * numerics.sweep_step * smoothstep((descent - PLUNGE_FROM) / PLUNGE_FROM)
}

impl Front {
    /// The front of a cut of `disc` whose frame moves with `velocity` and
    /// angular velocity `omega` (the spin about the axle moves no part of
    /// the solid), on `grid` with `numerics`; `None` (cut the whole disc)
    /// when the disc is not rolling along: at rest, or moving up or down as
    /// steeply as 1 in 2 (plunging, lifting out), or with a plastic
    /// fraction below 1, where each cut only takes part of the excess and
    /// the number of cuts a node sees counts.
    pub fn of(
        disc: &PosedDisc,
        velocity: &nalgebra::Vector3<f64>,
        omega: &nalgebra::Vector3<f64>,
        grid: &Grid,
        numerics: &Numerics,
        plastic_fraction: f64,
    ) -> Option<Front> {
        cut_reach(disc, velocity, omega, grid, numerics, plastic_fraction).0
    }

    /// [`Front::of`] the disc whose lowest point `low` moves with `v`.
    fn at(
        disc: &PosedDisc,
        low: &nalgebra::Vector3<f64>,
        v: &nalgebra::Vector3<f64>,
        grid: &Grid,
        numerics: &Numerics,
    ) -> Option<Front> {
        let vh = v.x.hypot(v.y);
        // slower than a micrometre a second: at rest
        if vh.is_nan() || vh <= 1e-6 {
            return None;
        }
        let slope = v.z / vh;
        if slope.abs() > 0.5 {
            return None;
        }
        let dir = (v.x / vh, v.y / vh);
        let ahead =
            0.5 * numerics.sweep_step + grid.dx.hypot(grid.dy) + 2.0 * disc.radius * slope.max(0.0);
        Some(Front {
            dir,
            limit: low.x * dir.0 + low.y * dir.1 + ahead,
        })
    }

    /// Rows `j0..=j1` of `g` less those the front leaves no point of the
    /// world box `x` on (by more than 1e-8 m: a row's bounds are found to
    /// round-off, far within that), which [`Bounds::row`] finds empty;
    /// `None` when none is left. The front of a disc heading diagonally
    /// crosses the rows, and about half the footprint's rows lie ahead of
    /// it: finding them empty one by one was most of the row bounds' 7 % of
    /// a cutterhead step.
    fn rows_within(&self, g: &Grid, x: [f64; 2], j0: usize, j1: usize) -> Option<(usize, usize)> {
        let (k, m) = self.dir;
        // (a front across the rows, `|m|` small, bounds no row)
        if m.abs() < 1e-3 {
            return Some((j0, j1));
        }
        // the rows on which some x of the box has `k x + m y <= limit`:
        // `m y <= limit - min(k x)`
        let bound = (self.limit + 1e-8 - (k * x[0]).min(k * x[1])) / m;
        let v = (bound - g.y_min) / g.dy;
        let (j0, j1) = if m > 0.0 {
            // (below row 0: none; past the last: all)
            if v < 0.0 {
                return None;
            }
            (j0, j1.min(v.floor().min(usize::MAX as f64) as usize))
        } else {
            let first = v.ceil().max(0.0);
            if first > j1 as f64 {
                return None;
            }
            (j0.max(first as usize), j1)
        };
        (j0 <= j1).then_some((j0, j1))
    }
}

/// What a rolling disc's cut need not visit behind it: a box in plan
/// about its heading, from `s[0]` to `s[1]` along the heading `u` from the
/// disc centre `c`, within `half` of the centre plane across it.
///
/// Behind its lowest point a rolling disc's surface rises, so the rock its
/// last cut left there lies below it still, and a cut walked those nodes
/// (most of a cut's window: the back arc of a 19 in disc 6 mm deep is 54 mm
/// long, a sweep step 1 mm) only to lower none. [`Back::of`] finds, from the
/// pose `prev` of the disc's last cut on this map and the pose now, a box
/// in which that holds by the geometry alone, so that skipping it leaves
/// the face bit for bit as a whole cut does (`tests/cut_back.rs` holds that
/// on every path a cutterhead makes).
///
/// The argument, for an axle horizontal at both poses (a face disc; a
/// tilted disc's box is `Back::tilted`'s): the solid is convex, so its
/// lower boundary `f'` at the last pose is a convex function in plan, and
/// the solid now is the last one moved by a turn `alpha` about the
/// vertical and a shift: the boundary now at `x` is `f'(x')` (`x'` the
/// point that moved to `x`) plus the rise `t_z`. Every node the last cut
/// scanned lies no higher than `f'` plus the elastic layer (a cut only
/// lowers, and so do the cuts of other discs and chips since), so a node
/// at `x` can fall now only if
/// `f'(x') + t_z < f'(x)`. By convexity `f'(x') >= f'(x) - grad f'(x) . D`
/// (`D = x - x'`); with `s'` the distance along the heading from the last
/// centre (negative behind it), `Q = sqrt(rho^2 - s'^2)` and `S` the
/// largest slope of the disc's section, `grad f' . D = (s' D_u - rho
/// rho' D_l) / Q <= (-|s'| D_u + R S |D_l|) / Q`, so nodes where
/// `|s'| D_u >= R S |D_l| + R max(-t_z, 0)` keep their height. `D_u` (the
/// travel along the heading) and `|D_l|` (across it: crabbing, and `alpha
/// s` from the turn) are bounded over the disc, which gives the distance
/// `b` behind the centre from which that holds; across, the box keeps
/// clear of the last cut's side edges (`half`), and it lies where the last
/// cut reached (inside its [`Front`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Back {
    c: (f64, f64),
    u: (f64, f64),
    s: [f64; 2],
    half: f64,
    /// For a tilted disc, the part of the box inside its core ([`Core`]).
    core: Option<Core>,
}

/// The plan of a tilted disc's core (`|y| <= h`, `|q_xz| <= rho(h)`) about
/// the box's centre and heading: `(max(|l| - h_l, 0) / b)^2 + (s / a)^2
/// <= 1`, `s` along the heading and `l` across it; `a` and `b` shrunk by a
/// part in 1e9 and `h_l` by 1 nm, so that every point of it lies strictly
/// inside.
///
/// With a `hole`, the part of it over the lower side face is walked: the
/// face's plan, the ellipse `((l - l_c) / b_h)^2 + (s / a_h)^2 <= 1`, grown
/// by 1 nm, so that every point left out lies strictly outside it.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Core {
    a: f64,
    b: f64,
    h_l: f64,
    hole: Option<Hole>,
}

/// The lower side face's plan in a [`Core`]: centre `l_c` across the
/// heading, half-axes `a_h` along it and `b_h` across.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Hole {
    l_c: f64,
    a_h: f64,
    b_h: f64,
}

impl Back {
    /// The box for a cut of `disc` after a cut of the same disc at `prev`
    /// that reached no further than `prev_front` ahead, both with a full
    /// plastic fraction and the same elastic layer (the caller's to check);
    /// `None` where the argument does not hold: an axle not horizontal, a
    /// turn of more than 2.6 deg or too tight for the section's slope (the
    /// back swinging out faster than it rises), a move that is mostly not
    /// along the heading, or a box that would reach past `prev_front`.
    pub fn of(prev: &PosedDisc, prev_front: Option<Front>, disc: &PosedDisc) -> Option<Back> {
        let same = prev.radius == disc.radius
            && prev.half_width == disc.half_width
            && prev.tip_radius == disc.tip_radius
            && prev.hub_half_width == disc.hub_half_width
            && prev.flank_cot == disc.flank_cot;
        let (a0, a1) = (prev.rot.column(1), disc.rot.column(1));
        if !same {
            return None;
        }
        if a0.z.abs() > 1e-12 || a1.z.abs() > 1e-12 {
            return Self::tilted(prev, disc).filter(|b| b.behind(prev_front));
        }
        let (r, h, rt, hw) = (
            disc.radius,
            disc.half_width,
            disc.tip_radius,
            disc.hub_half_width,
        );
        if h >= rt {
            return None;
        }
        // largest slope of the section's radius across the axle
        let slope = (h / (rt * rt - h * h).sqrt()).max(if disc.has_flanks() {
            disc.flank_cot
        } else {
            0.0
        });
        let (n0, n1) = (a0.x.hypot(a0.y), a1.x.hypot(a1.y));
        let (l0, l1) = ((a0.x / n0, a0.y / n0), (a1.x / n1, a1.y / n1));
        // the turn from the last axle to this one (an axle turned end for
        // end is the same solid)
        let (mut cos_a, mut sin_a) = (l0.0 * l1.0 + l0.1 * l1.1, l0.0 * l1.1 - l0.1 * l1.0);
        if cos_a < 0.0 {
            (cos_a, sin_a) = (-cos_a, -sin_a);
        }
        if cos_a.is_nan() || cos_a < 0.999 {
            return None;
        }
        // the heading, the way the centre moved
        let (dx, dy) = (disc.centre.x - prev.centre.x, disc.centre.y - prev.centre.y);
        let t_z = disc.centre.z - prev.centre.z;
        let mut u = (l1.1, -l1.0);
        let mut d_u = dx * u.0 + dy * u.1;
        if d_u < 0.0 {
            u = (-u.0, -u.1);
            d_u = -d_u;
        }
        let d_l = (dx * -u.1 + dy * u.0).abs();
        let dn = dx.hypot(dy);
        // |alpha| (asin x <= 1.001 x for cos >= 0.999, rounded up)
        let aa = 1.01 * sin_a.abs();
        let c1 = 1.0 - cos_a;
        // how far a point of the solid lies from its centre in plan
        let reach = r.hypot(hw);
        let d_max = dn + (c1 + aa) * reach;
        // least D_u, and |D_l| <= l0 + aa |s|, over the solid (in the last
        // pose's frame: its axes are turned by alpha from these)
        let du_min = d_u - c1 * reach - aa * hw - aa * d_max;
        let l_0 = d_l + c1 * hw + aa * d_max;
        // |s'| >= |s| - d_u - e
        let e = aa * (reach + dn);
        let k = du_min - r * slope * aa;
        if !(du_min > 0.0 && k >= 0.25 * du_min) {
            return None;
        }
        let b = (r * slope * l_0 + r * (-t_z).max(0.0) + (d_u + e) * du_min) / k;
        let b = 1.05 * b + 1e-9;
        // across: the last cut's solid covers the box's width; along: its
        // section reaches the box's far end
        let half = hw - (d_l + aa * (reach + dn)) - 1e-9;
        let far = disc.rho_full(hw) + d_u - e - 1e-9;
        if !(half > 0.0 && far > b) {
            return None;
        }
        let back = Back {
            c: (disc.centre.x, disc.centre.y),
            u,
            s: [-far, -b],
            half,
            core: None,
        };
        back.behind(prev_front).then_some(back)
    }

    /// Whether the box lies behind the front of the last cut, which then
    /// scanned all of it.
    fn behind(&self, prev_front: Option<Front>) -> bool {
        prev_front.is_none_or(|f| {
            self.corners()
                .iter()
                .all(|p| p.0 * f.dir.0 + p.1 * f.dir.1 <= f.limit)
        })
    }

    /// [`Back::of`] for a disc whose axle is not horizontal (a gauge
    /// cutter), before the front is checked: the argument above without
    /// the section's slope, which a tilted disc's lower boundary does not
    /// bound (it is steep at the disc's lowest point, on its silhouette).
    ///
    /// The solid now is the last one turned by `alpha` about the vertical
    /// and shifted (both axles rise alike; a disc is the same solid
    /// whatever its spin), so its lower boundary is `f(x) = f'(x') + t_z`
    /// at `x`, and by convexity `f(x) >= f'(x)` wherever `n . V <= 0`, `n`
    /// the outward normal of the last solid's lower boundary over `x` and
    /// `V = (D, t_z)`, `D = x - x'`, how the solid moved there (`D` is
    /// affine in `x`). That point is on the tip (the torus `|y| <= h`), on
    /// the lower side face, or on the edge between them, whose normals are
    /// the two's mixtures:
    /// - on the tip, `n = cos(psi) e(theta) + sin(psi) a` with `|psi| <=
    ///   asin(h / r_t)`; along the last heading `n_u = cos(psi) sin(theta)
    ///   = cos(psi) s' / rho <= -cos(psi_max) |s'| / R` behind the last
    ///   centre (`s' < 0`), across it `|n_l| <= N_l = |a_z| + sin(psi_max)
    ///   |a_l|`, and `n_z t_z <= max(-t_z, 0)`. With `D_u >= D_min` over
    ///   the box and `|D_l| <= d_l + k |s'|` (the turn's share grows with
    ///   the distance behind), `n . V <= 0` from `s' <= -b'`, `b' = (N_l
    ///   d_l + max(-t_z, 0)) / (cos(psi_max) D_min / R - N_l k)`;
    /// - on the lower side face `n = -sign(a_z) a`, and `n . V` is checked
    ///   at the box's corners: the face moving in its own plane or away from
    ///   the rock under it (a turn one way). The other way, or a tilted disc
    ///   diving or crabbing into its lower face's side, the nodes over the
    ///   face are walked (the [`Core`]'s hole: the face's plan, an ellipse,
    ///   over which the lower boundary is the face), and only those over the
    ///   tip are left out. A gauge cutter leaning out from its head's axis
    ///   turns that way: the back of its lower face swings out into the
    ///   wall it shaves, while its tip's back still rises from its groove.
    ///
    /// The box is taken in the last pose's frame, and only its part inside
    /// the plan of the last solid's core ([`Core`]: the two tip edges'
    /// ellipses and the band between) is left out: there `f'` is finite
    /// and has a slope. Flank-less discs only. `tests/cut_back.rs` holds
    /// the claim node by node against the two solids.
    fn tilted(prev: &PosedDisc, disc: &PosedDisc) -> Option<Back> {
        if disc.has_flanks() || disc.half_width >= disc.tip_radius {
            return None;
        }
        let (r, h, rt) = (disc.radius, disc.half_width, disc.tip_radius);
        let a0 = prev.rot.column(1).into_owned();
        let mut a1 = disc.rot.column(1).into_owned();
        // (an axle turned end for end is the same solid)
        if a0.dot(&a1) < 0.0 {
            a1 = -a1;
        }
        let (n0, n1) = (a0.x.hypot(a0.y), a1.x.hypot(a1.y));
        if (a1.z - a0.z).abs() > 1e-12 || !(n0 > 1e-6 && n1 > 1e-6) {
            return None;
        }
        let (l0, l1) = ((a0.x / n0, a0.y / n0), (a1.x / n1, a1.y / n1));
        let (cos_a, sin_a) = (l0.0 * l1.0 + l0.1 * l1.1, l0.0 * l1.1 - l0.1 * l1.0);
        if cos_a.is_nan() || cos_a < 0.999 {
            return None;
        }
        let (c0, c1) = (prev.centre, disc.centre);
        let (dx, dy) = (c1.x - c0.x, c1.y - c0.y);
        let t_z = c1.z - c0.z;
        // the last heading (horizontal in the last disc's plane), along
        // the travel, and across it
        let mut u = (l0.1, -l0.0);
        if dx * u.0 + dy * u.1 < 0.0 {
            u = (-u.0, -u.1);
        }
        let w = (-u.1, u.0);
        let (ax_l, ax_z) = (a0.x * w.0 + a0.y * w.1, a0.z);
        // the move `(D_u, D_l)` of the point at `(s', l')` of the last
        // frame: now at x, it was at `x' = c0 + R(-alpha) (x - c1)`
        let moved = |sp: f64, lp: f64| {
            let (x, y) = (c0.x + sp * u.0 + lp * w.0, c0.y + sp * u.1 + lp * w.1);
            let (vx, vy) = (x - c1.x, y - c1.y);
            let (mx, my) = (
                x - c0.x - cos_a * vx - sin_a * vy,
                y - c0.y + sin_a * vx - cos_a * vy,
            );
            (mx * u.0 + my * u.1, mx * w.0 + my * w.1)
        };
        let corners = |s: [f64; 2], half: f64| {
            [(s[0], -half), (s[0], half), (s[1], -half), (s[1], half)].map(|(sp, lp)| moved(sp, lp))
        };
        // the core's plan, and the box about it from 0.45 rho_h behind the
        // centre (a 19 in gauge disc 6 mm deep and tilted 10 deg reaches
        // 55 mm)
        let rho_h = disc.rho(h);
        let mut core = Core {
            a: rho_h * (1.0 - 1e-9),
            b: rho_h * ax_z.abs() * (1.0 - 1e-9),
            h_l: h * n0 - 1e-9,
            hole: None,
        };
        let half = core.h_l + core.b;
        let far = 0.45 * rho_h;
        // the move is affine in the place: `D = D(0) + k_s s' + k_l l'`;
        // least along the heading over the box, and across it at most
        // `|D_l(0)| + |k_l| half + |k_s| |s'|` (the turn's share grows with
        // the distance behind, as the tip's bound does)
        let d0 = moved(0.0, 0.0);
        let (ds, dl) = (moved(1.0, 0.0), moved(0.0, 1.0));
        let (ks, kl) = ((ds.0 - d0.0, ds.1 - d0.1), (dl.0 - d0.0, dl.1 - d0.1));
        let du_min = d0.0 - ks.0.abs() * far - kl.0.abs() * half;
        let cos_psi = (rt * rt - h * h).sqrt() / rt;
        let n_l = (ax_z.abs() + h / rt * n0).min(1.0);
        let gain = cos_psi * du_min / r - n_l * ks.1.abs();
        let need = n_l * (d0.1.abs() + kl.1.abs() * half + 1e-15) + (-t_z).max(0.0);
        if !(du_min > 0.0 && gain > 0.0 && core.b > 0.0 && core.h_l >= 0.0) {
            return None;
        }
        let b = 1.05 * need / gain + 1e-9;
        if b >= far {
            return None;
        }
        let s = [-far, -b];
        // the lower side face moves in its plane or away from the rock
        let lower = -ax_z.signum();
        let face_clear = corners(s, half)
            .iter()
            .all(|&(_, d_l)| lower * (ax_l * d_l + ax_z * t_z) <= 1e-13 * ax_z.abs());
        if !face_clear {
            // (the lower face lies at y = -h sign(a_z) on the axle)
            core.hole = Some(Hole {
                l_c: -h * ax_z.signum() * ax_l,
                a_h: rho_h + 1e-9,
                b_h: rho_h * ax_z.abs() + 1e-9,
            });
        }
        Some(Back {
            c: (c0.x, c0.y),
            u,
            s,
            half,
            core: Some(core),
        })
    }

    /// The box's corners in plan.
    fn corners(&self) -> [(f64, f64); 4] {
        let (u, l) = (self.u, (-self.u.1, self.u.0));
        let at = |s: f64, d: f64| (self.c.0 + s * u.0 + d * l.0, self.c.1 + s * u.1 + d * l.1);
        [
            at(self.s[0], -self.half),
            at(self.s[0], self.half),
            at(self.s[1], -self.half),
            at(self.s[1], self.half),
        ]
    }

    /// Whether a cut leaves node `(i, j)` of `g` out (for tests that hold
    /// the box to the solids it comes from, node by node).
    pub fn leaves_out(&self, g: &Grid, i: usize, j: usize) -> bool {
        self.gap(g, j, i, i).is_some()
    }

    /// The nodes of row `j` inside the box, within `i0..=i1`, if any.
    fn gap(&self, g: &Grid, j: usize, i0: usize, i1: usize) -> Option<(usize, usize)> {
        self.rows().gap(g, j, i0, i1)
    }

    /// The box's stretch of each row, as bounds affine in the row's `y`
    /// (found once a cut, read at every row).
    fn rows(&self) -> BackRows {
        let (u, l) = (self.u, (-self.u.1, self.u.0));
        BackRows {
            back: *self,
            strips: [
                Strip::new(u.0, u.1, self.s[0], self.s[1]),
                Strip::new(l.0, l.1, -self.half, self.half),
            ],
        }
    }
}

/// `a_lo <= k x + m y <= a_hi` on a row `y`, for `|k| > 1e-12`, as bounds on
/// `x` affine in `y`: `lo + slope y <= x <= hi + slope y`; else the
/// condition on `y` alone (`k`, `m`, `a_lo`, `a_hi` kept). A window's rows
/// read each bound with one multiply-add, where a division by `k` each
/// row was a tenth of a cut's instructions.
#[derive(Debug, Clone, Copy)]
enum Strip {
    Slope { lo: f64, hi: f64, slope: f64 },
    Level { m: f64, a_lo: f64, a_hi: f64 },
}

impl Strip {
    fn new(k: f64, m: f64, a_lo: f64, a_hi: f64) -> Self {
        if k.abs() > 1e-12 {
            let (p, q) = (a_lo / k, a_hi / k);
            Strip::Slope {
                lo: p.min(q),
                hi: p.max(q),
                slope: -m / k,
            }
        } else {
            Strip::Level { m, a_lo, a_hi }
        }
    }

    /// `[lo, hi]` clipped to the strip on row `y`; `None` when a level
    /// strip misses the row.
    #[inline]
    fn clip(&self, y: f64, lo: f64, hi: f64) -> Option<(f64, f64)> {
        match *self {
            Strip::Slope {
                lo: a,
                hi: b,
                slope,
            } => Some((lo.max(a + slope * y), hi.min(b + slope * y))),
            Strip::Level { m, a_lo, a_hi } => {
                let b = y * m;
                (b >= a_lo && b <= a_hi).then_some((lo, hi))
            }
        }
    }
}

/// A [`Back`] box ready to clip rows ([`Back::rows`]).
#[derive(Debug, Clone, Copy)]
struct BackRows {
    back: Back,
    strips: [Strip; 2],
}

impl BackRows {
    /// [`Back::gap`].
    fn gap(&self, g: &Grid, j: usize, i0: usize, i1: usize) -> Option<(usize, usize)> {
        let b = &self.back;
        let y = g.y_min + g.dy * j as f64 - b.c.1;
        // x - c.x in [lo, hi]
        let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
        for s in &self.strips {
            (lo, hi) = s.clip(y, lo, hi)?;
        }
        if let Some(core) = &b.core {
            (lo, hi) = core.clip(y, b.u, lo, hi)?;
        }
        // rounding: a node on the edge is walked
        let pad = 1e-9;
        let x0 = g.x_min - b.c.0;
        let k0 = ((lo + pad - x0) / g.dx).ceil().max(i0 as f64);
        let k1 = ((hi - pad - x0) / g.dx).floor().min(i1 as f64);
        node_pair(k0, k1)
    }
}

/// `(k0, k1)` as node indices when `k0 <= k1`: both whole, `k0 >= 0` and
/// below 2^53 (a row's clipped bounds), so converting through `i64` is exact
/// and takes less code than the conversion to `usize`, which saturates at
/// both ends (a window's rows are found for every cut: some 5 000 rows a
/// step of the reference head).
#[inline(always)]
fn node_pair(k0: f64, k1: f64) -> Option<(usize, usize)> {
    (k0 <= k1).then_some((k0 as i64 as usize, k1 as i64 as usize))
}

impl Core {
    /// `[lo, hi]` (of `x` about the centre, on the row `y` about it, `u`
    /// the heading) clipped to the core: the union of its three convex
    /// parts' stretches of the row, the band `|l| <= h_l` and the ellipses
    /// at `l = +-h_l`, each an interval; `None` when none is left.
    fn clip(&self, y: f64, u: (f64, f64), lo: f64, hi: f64) -> Option<(f64, f64)> {
        // s = x u.0 + y u.1, l = -x u.1 + y u.0
        let (su, s0) = (u.0, y * u.1);
        let (lu, l0) = (-u.1, y * u.0);
        let (mut a, mut b) = (f64::INFINITY, f64::NEG_INFINITY);
        let mut join = |p: f64, q: f64| {
            if p <= q {
                a = a.min(p);
                b = b.max(q);
            }
        };
        // the band: |l| <= h_l, |s| <= a
        let mut band = (f64::NEG_INFINITY, f64::INFINITY);
        for (k, c, lim) in [(lu, l0, self.h_l), (su, s0, self.a)] {
            if k.abs() > 1e-12 {
                let (p, q) = ((-lim - c) / k, (lim - c) / k);
                band = (band.0.max(p.min(q)), band.1.min(p.max(q)));
            } else if c.abs() > lim {
                band = (1.0, 0.0);
            }
        }
        join(band.0, band.1);
        // the ellipses: ((l -+ h_l) / b)^2 + (s / a)^2 <= 1
        for off in [self.h_l, -self.h_l] {
            if let Some((p, q)) = ellipse_chord((su, s0), (lu, l0), off, self.a, self.b) {
                join(p, q);
            }
        }
        let (lo, hi) = (lo.max(a), hi.min(b));
        if lo > hi {
            return None;
        }
        let Some(hole) = &self.hole else {
            return Some((lo, hi));
        };
        // less the hole's stretch of the row: the longer of what is left
        // on either side of it
        let Some((e0, e1)) = ellipse_chord((su, s0), (lu, l0), hole.l_c, hole.a_h, hole.b_h) else {
            return Some((lo, hi));
        };
        let (below, above) = ((lo, hi.min(e0)), (lo.max(e1), hi));
        let longer = if below.1 - below.0 >= above.1 - above.0 {
            below
        } else {
            above
        };
        (longer.0 < longer.1).then_some(longer)
    }
}

/// The stretch of a row inside the ellipse `((l - l_c) / b)^2 + (s / a)^2
/// <= 1`, the row's point at `x` being `s = su x + s0`, `l = lu x + l0`;
/// `None` when the row misses it. (Inlined by force: called out of line,
/// the gauge scene's step took 1.2 % more instructions.)
#[inline(always)]
fn ellipse_chord(
    (su, s0): (f64, f64),
    (lu, l0): (f64, f64),
    l_c: f64,
    a: f64,
    b: f64,
) -> Option<(f64, f64)> {
    let (p, q) = (lu / b, (l0 - l_c) / b);
    let (m, n) = (su / a, s0 / a);
    let qa = p * p + m * m;
    let qb = p * q + m * n;
    let qc = q * q + n * n - 1.0;
    let disc = qb * qb - qa * qc;
    if !(qa > 0.0 && disc >= 0.0) {
        return None;
    }
    let root = disc.sqrt();
    Some(((-qb - root) / qa, (-qb + root) / qa))
}

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
    j0: usize,
    j1: usize,
    /// Each row's node range (`rows[j - j0]`, `None`: none), found once:
    /// the tiles a cut writes and the cut itself read the same rows.
    rows: Vec<Option<(usize, usize)>>,
    /// The part of each row's range a [`Back`] box leaves out, if any.
    gaps: Vec<Option<(usize, usize)>>,
}

/// The bounds a [`Window`]'s rows are clipped to: the world box
/// `[x_lo, x_hi]`, the heading box (`u = x cos + y sin` in `[u_lo, u_hi]`,
/// `v = -x sin + y cos` in `[v_lo, v_hi]` about the rock origin) and the
/// front, each as a [`Strip`] (a strip across the heading box that is level
/// in `y` does not clip: the world box holds it).
struct Bounds {
    x: [f64; 2],
    strips: [Option<Strip>; 3],
}

impl Bounds {
    fn new(x: [f64; 2], (c, s): (f64, f64), uv: [f64; 4], front: Option<Front>) -> Self {
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
    fn node_box(&self) -> Option<[usize; 4]> {
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
    fn row(&self, j: usize) -> Option<(usize, usize)> {
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
    fn runs(&self, j: usize) -> impl Iterator<Item = (usize, usize)> {
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
    fn row(&self, g: &Grid, j: usize) -> Option<(usize, usize)> {
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
    let z_top = map.highest_within(disc.centre.x, disc.centre.y, disc.radius)?;
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
    let area = g.cell_area();
    let rt = disc.rot.transpose();
    let d = rt.column(2).into_owned();
    let horizontal = d.y.abs() < 1e-12;
    // a tilted flank-less disc's lines, with what depends on their
    // direction found once a cut
    let columns = (!horizontal && !disc.has_flanks()).then(|| Columns::new(disc, d));
    let step = rt.column(0) * g.dx;
    // the solid's half-width: the hub's with flanks (`rho_full` is the tip
    // profile across the tip, bit for bit)
    let h = disc.hub_half_width;
    // what a node above the boundary `z_low` becomes (`None`: it stays)
    let lower = |stats: &mut CutStats, z: f64, z_low: f64| {
        let excess = z - (z_low + elastic_depth);
        if excess <= CUT_TOLERANCE {
            return None;
        }
        // without a fraction (a probe) the node only tells that it would fall
        let Some(f) = fraction else {
            return Some(z);
        };
        let drop = f * excess;
        stats.volume += drop * area;
        stats.nodes += 1;
        Some(z - drop)
    };
    for j in w.j0..=w.j1 {
        let Some((r0, r1)) = w.row(j) else {
            continue;
        };
        // a row that keeps its axle coordinate (heading along a grid axis;
        // rounding of a spinning pose may leave it drifting by less than
        // 1e-15 m, nothing to the heights) lies in one vertical plane,
        // whose lowest point of the solid bounds the cut
        let flat_row = (step.y * (r1 - r0) as f64).abs() <= 1e-15;
        let (x0, y) = g.node_xy(r0, j);
        // (each node's local coordinates count from the row's first node,
        // whichever run of the row it lies in: a gap changes no height)
        let a0 = rt * nalgebra::Vector3::new(x0 - disc.centre.x, y - disc.centre.y, -disc.centre.z);
        for (i0, i1) in w.runs(j) {
            let skipped = i0 - r0;
            let stats = &mut stats;
            let stopped = if horizontal {
                // Axle horizontal: the vertical line through a node stays in the
                // plane y_local = q.y and meets the rim circle of radius
                // rho(q.y) there. With b = q.d (d is a unit vector in the x-z
                // plane) and w the offset across d in that plane, the lower
                // boundary is -b - sqrt(rho^2 - w^2). q.y, b and w are affine
                // along the row: node k's are start + k * step.
                let a = a0;
                let (b0, db) = (a.x * d.x + a.z * d.z, step.x * d.x + step.z * d.z);
                let (w0, dw) = (a.x * d.z - a.z * d.x, step.x * d.z - step.z * d.x);
                let (y0, dy) = (a.y, step.y);
                // (the plane's solid is the rim circle at y_local)
                let floor = if flat_row && y0.abs() <= h {
                    disc.centre.z - disc.rho_full(y0) + elastic_depth + CUT_TOLERANCE
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
                    lower(stats, z, -(b0 + k * db) - disc2.sqrt())
                })
            } else {
                let mut a = a0;
                for _ in 0..skipped {
                    a += step;
                }
                // (a plane that misses the solid: nothing to cut in the row)
                let floor = if flat_row && !disc.has_flanks() {
                    disc.row_floor(&a0, &d, &step)
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
                    let z_low = match &columns {
                        Some(c) => c.lower_end(&q, cap)?.0,
                        None => disc.column_lower_end(&q, &d, cap)?.0,
                    };
                    lower(stats, z, z_low)
                })
            };
            if stopped {
                return (*stats, true);
            }
        }
    }
    (stats, stats.nodes > 0)
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
