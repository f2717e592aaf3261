//! The box behind a rolling disc whose nodes its last cut already took as
//! low as this one would ([`Back`]), for upright and tilted discs.

use super::*;

/// What a rolling disc's cut need not visit behind it: a box in plan
/// about a heading, from `s[0]` to `s[1]` along the heading `u` from the
/// point `c`, and from `l[0]` to `l[1]` across it (towards `(-u.1, u.0)`).
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
/// tilted disc's box is `Back::tilted`'s), in the last pose's frame: `c`
/// its centre, `u` its heading along the travel, `(s', l')` a point's
/// coordinates along and across it. The solid is convex, so its lower
/// boundary `f'` at the last pose is a convex function in plan, and the
/// solid now is the last one moved by a turn `alpha` about the vertical
/// and a shift: the boundary now at `x` is `f'(x')` (`x'` the point that
/// moved to `x`) plus the rise `t_z`. Every node the last cut scanned lies
/// no higher than `f'` plus the elastic layer (a cut only lowers, and so do
/// the cuts of other discs and chips since), so a node at `x` can fall now
/// only if `f'(x') + t_z < f'(x)`. By convexity `f'(x') >= f'(x) - grad
/// f'(x) . D` (`D = x - x'`, affine in `x`: `D_u` along the heading, `D_l`
/// across). With `Q = sqrt(rho(l')^2 - s'^2)`, `grad f' . D = (s' D_u -
/// rho rho'(l') D_l) / Q`, and the section's radius `rho` falls away from
/// the mid-plane (`rho' l' <= 0`, `|rho'| <= S(|l'|)`, the slope at `|l'|`),
/// so behind the centre (`s' < 0`) the term across only counts where the
/// point moved away from the mid-plane (`l' D_l > 0`), and nodes where
/// `|s'| D_u >= R S(|l'|) max(sign(l') D_l, 0) + R max(-t_z, 0)` keep their
/// height. A turn swings the back to one side, by `|alpha| |s'|`, growing
/// with the distance behind: on that side the box is as wide as the slope
/// stays below three quarters of `D_u / (R |alpha|)` (a tight track's outer
/// wall is where the back scrubs; the quarter of `D_u` left over bounds `b`
/// as the whole-width box's margin did), on the other the whole section;
/// `D_u` and the rest of `D_l` are bounded over the section, which gives
/// the distance `b` behind the centre from which it holds. The box lies inside the last
/// solid's plan (its radius at the box's edge reaches the far end) and
/// where the last cut reached (inside its [`Front`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Back {
    pub(super) c: (f64, f64),
    pub(super) u: (f64, f64),
    pub(super) s: [f64; 2],
    pub(super) l: [f64; 2],
    /// For a tilted disc, the part of the box inside its core ([`Core`]).
    pub(super) core: Option<Core>,
}

/// How a disc moved in plan between its last pose and this one, in the
/// last pose's frame: `c0` and `c1` the two centres, `(cos_a, sin_a)` the
/// turn `alpha` from the last axle to this one, `u` the last heading (the
/// last axle `l0` turned a right angle, along the travel) and `w` across
/// it.
#[derive(Debug, Clone, Copy)]
struct Move {
    c0: (f64, f64),
    c1: (f64, f64),
    cs: (f64, f64),
    u: (f64, f64),
    w: (f64, f64),
}

impl Move {
    fn new(c0: (f64, f64), c1: (f64, f64), cs: (f64, f64), l0: (f64, f64)) -> Self {
        let (dx, dy) = (c1.0 - c0.0, c1.1 - c0.1);
        let mut u = (l0.1, -l0.0);
        if dx * u.0 + dy * u.1 < 0.0 {
            u = (-u.0, -u.1);
        }
        Move {
            c0,
            c1,
            cs,
            u,
            w: (-u.1, u.0),
        }
    }

    /// The move `(D_u, D_l)` of the point at `(s', l')` of the last frame:
    /// now at `x`, it was at `x' = c0 + R(-alpha) (x - c1)`.
    #[inline]
    fn at(&self, sp: f64, lp: f64) -> (f64, f64) {
        let (c0, c1, (cos_a, sin_a), u, w) = (self.c0, self.c1, self.cs, self.u, self.w);
        let (x, y) = (c0.0 + sp * u.0 + lp * w.0, c0.1 + sp * u.1 + lp * w.1);
        let (vx, vy) = (x - c1.0, y - c1.1);
        let (mx, my) = (
            x - c0.0 - cos_a * vx - sin_a * vy,
            y - c0.1 + sin_a * vx - cos_a * vy,
        );
        (mx * u.0 + my * u.1, mx * w.0 + my * w.1)
    }
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
pub(super) struct Core {
    pub(super) a: f64,
    pub(super) b: f64,
    pub(super) h_l: f64,
    pub(super) hole: Option<Hole>,
}

/// The lower side face's plan in a [`Core`]: centre `l_c` across the
/// heading, half-axes `a_h` along it and `b_h` across.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Hole {
    pub(super) l_c: f64,
    pub(super) a_h: f64,
    pub(super) b_h: f64,
}

impl Back {
    /// The box for a cut of `disc` after a cut of the same disc at `prev`
    /// that reached no further than `prev_front` ahead, both with a full
    /// plastic fraction and the same elastic layer (the caller's to check);
    /// `None` where the argument does not hold: a turn of more than 2.6 deg,
    /// a move that is mostly not along the heading (no travel left over the
    /// section), or a box that would reach past `prev_front`. An axle that
    /// is not horizontal takes `Back::tilted`'s argument.
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
        // the section's slope: the tip's at its edge, the flanks' beyond
        let tip_slope = h / (rt * rt - h * h).sqrt();
        let most = tip_slope.max(if disc.has_flanks() {
            disc.flank_cot
        } else {
            0.0
        });
        // how far across the axle the slope stays at most `k`
        let within = |k: f64| {
            if k >= most {
                hw
            } else if k >= tip_slope {
                h
            } else {
                k * rt / (1.0 + k * k).sqrt()
            }
        };
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
        let (c0, c1) = (prev.centre, disc.centre);
        let t_z = c1.z - c0.z;
        // the move, affine in the place: `D(0) + k_s s' + k_l l'`
        let mv = Move::new((c0.x, c0.y), (c1.x, c1.y), (cos_a, sin_a), l0);
        let (u, moved) = (mv.u, |sp: f64, lp: f64| mv.at(sp, lp));
        let d0 = moved(0.0, 0.0);
        let (ds, dl) = (moved(1.0, 0.0), moved(0.0, 1.0));
        let (ks, kl) = ((ds.0 - d0.0, ds.1 - d0.1), (dl.0 - d0.0, dl.1 - d0.1));
        // least D_u over the section (|s'| <= R, |l'| <= W/2)
        let du_min = d0.0 - ks.0.abs() * r - kl.0.abs() * hw;
        if du_min.is_nan() || du_min <= 0.0 {
            return None;
        }
        // one side of the mid-plane: `swing`, how fast the move away from
        // the mid-plane grows with the distance behind, and `d`, that move
        // at the centre; the box's width on that side and the distance
        // behind from which it holds (the slope there is kept to three
        // quarters of what the travel outruns: half left the 0.2 m track's
        // outer side narrowed, for 6 % more instructions a step)
        let side = |swing: f64, d: f64| {
            let k = if swing > 0.0 {
                most.min(0.75 * du_min / (r * swing))
            } else {
                most
            };
            let half = within(k);
            let gain = du_min - r * k * swing;
            let need = r * k * (d.max(0.0) + kl.1.abs() * half) + r * (-t_z).max(0.0);
            (half, need / gain)
        };
        // behind the centre (s' < 0) `D_l` grows by `-k_s.1 |s'|`
        let (h_pos, b_pos) = side((-ks.1).max(0.0), d0.1);
        let (h_neg, b_neg) = side(ks.1.max(0.0), -d0.1);
        let b = 1.05 * b_pos.max(b_neg) + 1e-9;
        // along: the last solid's section reaches the box's far end
        let far = disc.rho_full(h_pos.max(h_neg)) - 1e-9;
        if !(far > b && b.is_finite()) {
            return None;
        }
        let back = Back {
            c: (c0.x, c0.y),
            u,
            s: [-far, -b],
            l: [-(h_neg - 1e-9), h_pos - 1e-9],
            core: None,
        };
        back.behind(prev_front).then_some(back)
    }

    /// Whether the box lies behind the front of the last cut, which then
    /// scanned all of it.
    pub(super) fn behind(&self, prev_front: Option<Front>) -> bool {
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
    ///   at the box's corners (it is affine in the place, so they bound it):
    ///   the face moving in its own plane or away from the rock under it (a
    ///   turn one way). Where it moves into the rock at the box's near end
    ///   only, the box is shortened at that end to where `n . V` changes
    ///   sign along its edges, if at least half of it is left: a gauge disc
    ///   leaning out from its head's axis, descending as the head bores, has
    ///   its lower face turn into the wall within a millimetre or so behind
    ///   its lowest point and away from it further back. Otherwise (a turn
    ///   the other way, or a tilted disc diving or crabbing into its lower
    ///   face's side) the nodes over the face are walked (the [`Core`]'s
    ///   hole: the face's plan, an ellipse, over which the lower boundary is
    ///   the face), and only those over the tip are left out.
    ///
    /// The box is taken in the last pose's frame, and only its part inside
    /// the plan of the last solid's core ([`Core`]: the two tip edges'
    /// ellipses and the band between) is left out: there `f'` is finite
    /// and has a slope. Flank-less discs only. `tests/cut_back.rs` holds
    /// the claim node by node against the two solids.
    pub(super) fn tilted(prev: &PosedDisc, disc: &PosedDisc) -> Option<Back> {
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
        let t_z = c1.z - c0.z;
        // the last heading (horizontal in the last disc's plane), along
        // the travel, and the move
        let mv = Move::new((c0.x, c0.y), (c1.x, c1.y), (cos_a, sin_a), l0);
        let (u, w) = (mv.u, mv.w);
        let (ax_l, ax_z) = (a0.x * w.0 + a0.y * w.1, a0.z);
        let moved = |sp: f64, lp: f64| mv.at(sp, lp);
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
        let mut s = [-far, -b];
        // the lower side face moves in its plane or away from the rock:
        // `n . V` at each corner (affine in the place, so the corners bound
        // it over the box)
        let lower = -ax_z.signum();
        let tol = 1e-13 * ax_z.abs();
        let face_moves =
            |s: [f64; 2]| corners(s, half).map(|(_, d_l)| lower * (ax_l * d_l + ax_z * t_z));
        let clear = |v: [f64; 4]| v.iter().all(|&x| x <= tol);
        let mut face_clear = clear(face_moves(s));
        if !face_clear {
            // `n . V` is affine along the box too: where it is positive at
            // the near end only, the face is clear behind the place along
            // each edge where it changes sign, and the box shortened to
            // there leaves out the whole core (the face's plan too), where
            // the hole below would walk all of the face's (the gauge discs
            // of a head turning: n . V falls from 1e-7 at the near end to
            // -8e-6 at the far one, the sign changing a millimetre behind)
            let v = face_moves(s);
            // corners: [(far, -), (far, +), (near, -), (near, +)]
            let mut near = s[1];
            for (v_far, v_near) in [(v[0], v[2]), (v[1], v[3])] {
                if v_near > 0.0 {
                    near = if v_far < 0.0 {
                        near.min(s[1] - (s[1] - s[0]) * v_near / (v_near - v_far))
                    } else {
                        s[0]
                    };
                }
            }
            // (a margin of a part in 1e6 of the box, and the corners checked
            // again as they stand)
            let short = [s[0], near - 1e-6 * (s[1] - s[0])];
            if short[1] - short[0] >= 0.5 * (s[1] - s[0]) && clear(face_moves(short)) {
                s = short;
                face_clear = true;
            }
        }
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
            l: [-half, half],
            core: Some(core),
        })
    }

    /// The box's corners in plan.
    pub(super) fn corners(&self) -> [(f64, f64); 4] {
        let (u, l) = (self.u, (-self.u.1, self.u.0));
        let at = |s: f64, d: f64| (self.c.0 + s * u.0 + d * l.0, self.c.1 + s * u.1 + d * l.1);
        [
            at(self.s[0], self.l[0]),
            at(self.s[0], self.l[1]),
            at(self.s[1], self.l[0]),
            at(self.s[1], self.l[1]),
        ]
    }

    /// Whether a cut leaves node `(i, j)` of `g` out (for tests that hold
    /// the box to the solids it comes from, node by node).
    pub fn leaves_out(&self, g: &Grid, i: usize, j: usize) -> bool {
        self.gap(g, j, i, i).is_some()
    }

    /// The nodes of row `j` inside the box, within `i0..=i1`, if any.
    pub(super) fn gap(&self, g: &Grid, j: usize, i0: usize, i1: usize) -> Option<(usize, usize)> {
        self.rows().gap(g, j, i0, i1)
    }

    /// The box's stretch of each row, as bounds affine in the row's `y`
    /// (found once a cut, read at every row).
    pub(super) fn rows(&self) -> BackRows {
        let (u, l) = (self.u, (-self.u.1, self.u.0));
        BackRows {
            back: *self,
            strips: [
                Strip::new(u.0, u.1, self.s[0], self.s[1]),
                Strip::new(l.0, l.1, self.l[0], self.l[1]),
            ],
            core: self.core.map(|c| c.rows(self.u)),
        }
    }
}

/// `a_lo <= k x + m y <= a_hi` on a row `y`, for `|k| > 1e-12`, as bounds on
/// `x` affine in `y`: `lo + slope y <= x <= hi + slope y`; else the
/// condition on `y` alone (`k`, `m`, `a_lo`, `a_hi` kept). A window's rows
/// read each bound with one multiply-add, where a division by `k` each
/// row was a tenth of a cut's instructions.
#[derive(Debug, Clone, Copy)]
pub(super) enum Strip {
    Slope { lo: f64, hi: f64, slope: f64 },
    Level { m: f64, a_lo: f64, a_hi: f64 },
}

impl Strip {
    pub(super) fn new(k: f64, m: f64, a_lo: f64, a_hi: f64) -> Self {
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
    pub(super) fn clip(&self, y: f64, lo: f64, hi: f64) -> Option<(f64, f64)> {
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
pub(super) struct BackRows {
    pub(super) back: Back,
    pub(super) strips: [Strip; 2],
    pub(super) core: Option<CoreRows>,
}

impl BackRows {
    /// [`Back::gap`].
    pub(super) fn gap(&self, g: &Grid, j: usize, i0: usize, i1: usize) -> Option<(usize, usize)> {
        let b = &self.back;
        let y = g.y_min + g.dy * j as f64 - b.c.1;
        // x - c.x in [lo, hi]
        let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
        for s in &self.strips {
            (lo, hi) = s.clip(y, lo, hi)?;
        }
        if let Some(core) = &self.core {
            (lo, hi) = core.clip(y, lo, hi)?;
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
pub(super) fn node_pair(k0: f64, k1: f64) -> Option<(usize, usize)> {
    (k0 <= k1).then_some((k0 as i64 as usize, k1 as i64 as usize))
}

impl Core {
    /// [`CoreRows::clip`]'s constants for a box heading `u`, found once a
    /// cut and read at every row (a tilted disc's window has some 70 rows:
    /// dividing at each row took the gauge scene's steps 0.8 % more wall
    /// time, 0.4 % more instructions).
    fn rows(&self, u: (f64, f64)) -> CoreRows {
        // s = x u.0 + y u.1, l = -x u.1 + y u.0
        let (su, lu) = (u.0, -u.1);
        let axis = |k: f64, lim: f64| Axis {
            inv_k: if k.abs() > 1e-12 { 1.0 / k } else { 0.0 },
            lim,
        };
        CoreRows {
            u,
            band: [axis(lu, self.h_l), axis(su, self.a)],
            ellipses: [
                Chord::new(su, lu, self.h_l, self.a, self.b),
                Chord::new(su, lu, -self.h_l, self.a, self.b),
            ],
            hole: self.hole.map(|h| Chord::new(su, lu, h.l_c, h.a_h, h.b_h)),
        }
    }
}

/// A [`Core`] ready to clip rows, its constants found once a cut
/// ([`Core::rows`]): the reciprocals a row's bounds divide by, and each
/// ellipse's quadratic in `x` less its row's terms.
#[derive(Debug, Clone, Copy)]
pub(super) struct CoreRows {
    u: (f64, f64),
    /// The band's two conditions, `|l| <= h_l` and `|s| <= a`.
    band: [Axis; 2],
    ellipses: [Chord; 2],
    hole: Option<Chord>,
}

/// `|k x + c| <= lim` on a row: `inv_k` is `1 / k`, or 0 where `|k| <= 1e-12`
/// (then the condition is on the row alone).
#[derive(Debug, Clone, Copy)]
struct Axis {
    inv_k: f64,
    lim: f64,
}

/// The stretch of a row inside the ellipse `((l - l_c) / b)^2 + (s / a)^2
/// <= 1`, the row's point at `x` being `s = su x + s0`, `l = lu x + l0`: a
/// quadratic in `x` whose leading terms are the heading's, `p = lu / b`,
/// `m = su / a`, `qa = p^2 + m^2` (with its reciprocal, `1 / a`, `1 / b`
/// and `l_c / b`). (Its row's part is inlined by force: called out of
/// line, the gauge scene's step took 1.2 % more instructions.)
#[derive(Debug, Clone, Copy)]
struct Chord {
    p: f64,
    m: f64,
    qa: f64,
    inv_qa: f64,
    inv_a: f64,
    inv_b: f64,
    lc_b: f64,
}

impl Chord {
    fn new(su: f64, lu: f64, l_c: f64, a: f64, b: f64) -> Self {
        let (p, m) = (lu / b, su / a);
        let qa = p * p + m * m;
        Chord {
            p,
            m,
            qa,
            inv_qa: 1.0 / qa,
            inv_a: 1.0 / a,
            inv_b: 1.0 / b,
            lc_b: l_c / b,
        }
    }

    /// The row's stretch inside the ellipse (`s0`, `l0`: the row's terms).
    #[inline(always)]
    fn at(&self, s0: f64, l0: f64) -> Option<(f64, f64)> {
        let q = l0 * self.inv_b - self.lc_b;
        let n = s0 * self.inv_a;
        let qb = self.p * q + self.m * n;
        let qc = q * q + n * n - 1.0;
        let disc = qb * qb - self.qa * qc;
        if !(self.qa > 0.0 && disc >= 0.0) {
            return None;
        }
        let root = disc.sqrt();
        Some(((-qb - root) * self.inv_qa, (-qb + root) * self.inv_qa))
    }
}

impl CoreRows {
    /// `[lo, hi]` (of `x` about the centre, on the row `y` about it)
    /// clipped to the core: the union of its three convex parts' stretches
    /// of the row, the band `|l| <= h_l` and the ellipses at `l = +-h_l`,
    /// each an interval, less the hole's stretch if any (the longer of what
    /// is left on either side of it); `None` when none is left.
    #[inline]
    pub(super) fn clip(&self, y: f64, lo: f64, hi: f64) -> Option<(f64, f64)> {
        let (s0, l0) = (y * self.u.1, y * self.u.0);
        let (mut a, mut b) = (f64::INFINITY, f64::NEG_INFINITY);
        let mut join = |p: f64, q: f64| {
            if p <= q {
                a = a.min(p);
                b = b.max(q);
            }
        };
        let mut band = (f64::NEG_INFINITY, f64::INFINITY);
        for (ax, c) in [(&self.band[0], l0), (&self.band[1], s0)] {
            if ax.inv_k != 0.0 {
                let (p, q) = ((-ax.lim - c) * ax.inv_k, (ax.lim - c) * ax.inv_k);
                band = (band.0.max(p.min(q)), band.1.min(p.max(q)));
            } else if c.abs() > ax.lim {
                band = (1.0, 0.0);
            }
        }
        join(band.0, band.1);
        for e in &self.ellipses {
            if let Some((p, q)) = e.at(s0, l0) {
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
        let Some((e0, e1)) = hole.at(s0, l0) else {
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
