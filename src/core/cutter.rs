//! The disc cutter as a solid (thesis ch. 6): a constant-cross-section disc of
//! radius `R` whose rim, for `|y| <= T/2`, follows the tip profile
//! `rho(y) = R - r + sqrt(r^2 - y^2)` (eq. 38), closed by flat side faces in the
//! planes `y = +-T/2`. In the cutter frame (x rolling, y axle, z up) a rim
//! point at angle `theta` from the lowest point (positive towards +x) is
//! `(rho sin(theta), y, -rho cos(theta))`.
//!
//! The solid `{ |y| <= T/2, sqrt(x^2 + z^2) <= rho(y) }` is convex (`rho` is
//! concave), so a vertical line meets it in one segment; its lower end is
//! where the rock under the cutter must be cut to.
//!
//! **Flanks** (`cutter.flankAngle` > 0, the real CCS ring section): past the
//! tip's edges the section widens along straight flanks at the flank angle
//! `f` from the mid-plane down to the hub width `W`, then ends in flat faces
//! at `y = +-W/2`: `rho_full(y) = rho(T/2) - (|y| - T/2) / tan(f)` for
//! `T/2 < |y| <= W/2`. The solid `{ |y| <= W/2, sqrt(x^2 + z^2) <=
//! rho_full(y) }` stays convex as long as the flank is steeper than the tip
//! profile at its edge (`CutterParams::check_flanks` rejects the rest).
//! Flank angle 0 is the solid above, bit for bit.

use nalgebra::{Matrix3, Vector3};

use super::params::CutterParams;
use super::pose::Pose;

/// Where the lower end of a vertical line through the solid lies.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Face {
    /// On the rim, at axle coordinate `y`.
    Rim { y: f64 },
    /// On the side face `y = +T/2` (`+1`) or `y = -T/2` (`-1`); with flanks,
    /// the hub face `y = +-W/2`.
    Side(i8),
    /// On a flank, at axle coordinate `y` (`T/2 < |y| < W/2`).
    Flank { y: f64 },
}

/// A posed disc: geometry plus the pose's rotation, ready for queries.
#[derive(Debug, Clone, Copy)]
pub struct PosedDisc {
    pub radius: f64,
    pub half_width: f64,
    pub tip_radius: f64,
    /// Cutter-to-rock rotation.
    pub rot: Matrix3<f64>,
    /// Disc centre, rock frame.
    pub centre: Vector3<f64>,
    /// Half the hub width `W/2` with flanks, `half_width` without.
    pub hub_half_width: f64,
    /// `1 / tan(flank angle)`: how fast the flank's radius falls per unit of
    /// axle coordinate (0 without flanks).
    pub flank_cot: f64,
}

/// The angle at which every rim circle of a posed disc is lowest (its
/// circles are coaxial), `theta0`, its `sin_cos` found from the rotation
/// without trigonometry, and `m`, the amplitude of a circle's height per
/// unit radius (a point's height about its circle's centre is
/// `-m rho cos(theta - theta0)`; `m` is 0 with the axle vertical, every
/// point of a circle equally low, and `theta0` is then 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lowest {
    pub theta0: f64,
    pub sc: (f64, f64),
    pub m: f64,
}

impl PosedDisc {
    pub fn new(c: &CutterParams, pose: &Pose) -> Self {
        Self {
            radius: c.radius,
            half_width: 0.5 * c.tip_width,
            tip_radius: c.tip_radius,
            rot: *pose.cutter_rotation().matrix(),
            centre: pose.position,
            hub_half_width: if c.has_flanks() {
                0.5 * c.hub_width
            } else {
                0.5 * c.tip_width
            },
            flank_cot: if c.has_flanks() {
                1.0 / c.flank_angle.tan()
            } else {
                0.0
            },
        }
    }

    /// Does the section have flanks?
    #[inline]
    pub fn has_flanks(&self) -> bool {
        self.hub_half_width > self.half_width
    }

    /// Radius of the whole section at axle coordinate `y`, `|y| <= W/2`:
    /// the tip profile [`rho`](Self::rho) across the tip, the flanks beyond.
    #[inline]
    pub fn rho_full(&self, y: f64) -> f64 {
        let h = self.half_width;
        let a = y.abs();
        if a <= h {
            self.rho(y)
        } else {
            self.rho(h) - (a - h) * self.flank_cot
        }
    }

    /// `(sin f, cos f)` of the flank angle `f`: the flank's outward normal
    /// on side `s` is `sin f` along the radius and `s cos f` along the axle.
    #[inline]
    pub fn flank_normal(&self) -> (f64, f64) {
        let c = self.flank_cot;
        // cot f = c: sin f = 1 / sqrt(1 + c^2), cos f = c sin f
        let n = (1.0 + c * c).sqrt();
        (1.0 / n, c / n)
    }

    /// Rim radius at axle coordinate `y` (eq. 38), `|y| <= T/2`.
    #[inline]
    pub fn rho(&self, y: f64) -> f64 {
        let r = self.tip_radius;
        self.radius - r + (r * r - y * y).max(0.0).sqrt()
    }

    /// Outward unit normal of the rim at `(theta, y)`, cutter frame.
    #[inline]
    pub fn rim_normal_local(&self, theta: f64, y: f64) -> Vector3<f64> {
        let r = self.tip_radius;
        let c = (r * r - y * y).max(0.0).sqrt() / r;
        let s = y / r;
        Vector3::new(c * theta.sin(), s, -c * theta.cos())
    }

    /// Rim point at `(theta, y)`, cutter frame.
    #[inline]
    pub fn rim_point_local(&self, theta: f64, y: f64) -> Vector3<f64> {
        let rho = self.rho(y);
        Vector3::new(rho * theta.sin(), y, -rho * theta.cos())
    }

    #[inline]
    pub fn to_world(&self, local: &Vector3<f64>) -> Vector3<f64> {
        self.centre + self.rot * local
    }

    /// Lowest point of the whole disc, rock frame. The thesis's section in
    /// closed form (exact); with flanks, on the rim where the lowest points
    /// of the rim circles (one a slice across the tip, 201 slices) reach
    /// lowest, or at the hub's edge: exact for an upright or pitched disc,
    /// for a rolled one within (T/200)^2 / r of the true lowest point.
    /// (The sampled search was the only one until 2026-11-26; it cost a
    /// cutterhead step 3.5 % once every cut asked for it.)
    pub fn lowest_point(&self) -> Vector3<f64> {
        // the thesis's section: the tip's arc of radius `r` about the
        // circle `R - r` from the axle, cut at `|y| <= h`. Its point lowest
        // in the cutter-frame direction `d` (down) lies in the plane of the
        // axle and `d`, where `|d_r| rho(y) + d_y y` is largest: `y = r d_y`
        // (|d| = 1), or the tip's edge when that lies beyond it
        let d = -self.rot.row(2).transpose();
        let n_r = d.x.hypot(d.z);
        if !self.has_flanks() && n_r > 1e-9 {
            let y = (self.tip_radius * d.y).clamp(-self.half_width, self.half_width);
            let rho = self.rho(y);
            let local = Vector3::new(rho * d.x / n_r, y, rho * d.z / n_r);
            return self.to_world(&local);
        }
        let mut low = Vector3::new(0.0, 0.0, f64::INFINITY);
        for k in 0..=200 {
            let y = -self.half_width + 2.0 * self.half_width * k as f64 / 200.0;
            if let Some((t0, _)) = self.arc_below(y, self.rho(y), f64::MAX) {
                let p = self.to_world(&self.rim_point_local(t0, y));
                if p.z < low.z {
                    low = p;
                }
            }
        }
        if self.has_flanks() {
            // the flanks are straight in the section: their lowest points
            // are at the tip's edges (sampled above) or the hub's
            for y in [-self.hub_half_width, self.hub_half_width] {
                let rho = self.rho_full(y);
                if let Some((t0, _)) = self.arc_below(y, rho, f64::MAX) {
                    let p = self.to_world(&Vector3::new(rho * t0.sin(), y, -rho * t0.cos()));
                    if p.z < low.z {
                        low = p;
                    }
                }
            }
        }
        low
    }

    /// Lowest point of the solid on the vertical line through `(x, y)` of the
    /// rock frame: its height and the face it lies on; `None` when the line
    /// misses the disc.
    pub fn lower_boundary(&self, x: f64, y: f64) -> Option<(f64, Face)> {
        if self.has_flanks() {
            return self.lower_boundary_flanked(x, y);
        }
        self.lower_boundary_below(x, y, f64::INFINITY)
    }

    /// [`PosedDisc::lower_boundary`] when it lies below `cap`, else `None`.
    /// The cut asks whether a node stands above the disc, so it stops as soon
    /// as the search has climbed past the node: most nodes of a rolling
    /// cut's window were cut by the last pose and are rejected early.
    pub fn lower_boundary_below(&self, x: f64, y: f64, cap: f64) -> Option<(f64, Face)> {
        // local coordinates along the line: q(t) = a + t d, t the rock height
        let rt = self.rot.transpose();
        let a = rt * Vector3::new(x - self.centre.x, y - self.centre.y, -self.centre.z);
        self.column_lower_end(&a, &rt.column(2).into_owned(), cap)
    }

    /// [`PosedDisc::lower_boundary_below`] for the vertical line given in
    /// the cutter frame: `q(t) = a + t d`, `t` the rock height, `d` the
    /// rock's up axis in the cutter frame. A caller walking a row of nodes
    /// steps `a` instead of transforming each node.
    pub fn column_lower_end(
        &self,
        a: &Vector3<f64>,
        d: &Vector3<f64>,
        cap: f64,
    ) -> Option<(f64, Face)> {
        let (a, d) = (*a, *d);
        if self.has_flanks() {
            return self
                .column_lower_end_flanked(a, d)
                .filter(|&(t, _)| t < cap);
        }
        let h = self.half_width;
        if d.y.abs() < 1e-12 {
            // axle horizontal: the line stays in the plane y_local = a.y
            if a.y.abs() > h {
                return None;
            }
            // (the cut's formula: along d, b; across it in the plane, w)
            let rho = self.rho(a.y);
            let b = a.x * d.x + a.z * d.z;
            let w = a.x * d.z - a.z * d.x;
            let dd = rho * rho - w * w;
            if dd < 0.0 {
                return None;
            }
            return Some((-b - dd.sqrt(), Face::Rim { y: a.y }));
        }
        Columns::new(self, d).lower_end(&a, cap)
    }

    /// The tip profile at axle coordinate `y` (clamped to the tip): its
    /// radius and how fast it falls with `y` (`y / sqrt(r^2 - y^2)`, kept
    /// finite at the edge), the slope the Newton solves of the lower
    /// boundary need.
    #[inline]
    fn tip_profile(&self, y: f64) -> (f64, f64) {
        let (h, r) = (self.half_width, self.tip_radius);
        let y = y.clamp(-h, h);
        let s2 = r * r - y * y;
        let sq = s2.max(0.0).sqrt();
        let root = if s2 >= 1e-300 { sq } else { 1e-300f64.sqrt() };
        (self.radius - r + sq, y / root)
    }

    /// The lowest rock height at which the solid meets the vertical plane
    /// swept by a row of vertical lines `q(t) = a + k step + t d` (`k` real;
    /// `step` has no axle component, so the row keeps its axle coordinate
    /// at each height): a lower bound of [`column_lower_end`] for every
    /// node of the row, found once. `None` when the plane misses the
    /// solid. Flank-less solids only (`None` with flanks, a caller must not
    /// use it then).
    ///
    /// In the plane, at rock height `t`, the lines' points `q_xz` run along
    /// `step`, so the nearest to the axle lies `w(t)` from it, `w` the
    /// offset across `step`, affine in `t`; the solid reaches that height
    /// where `|w(t)| <= rho(q_y(t))`, a convex condition solved like the
    /// column's.
    ///
    /// [`column_lower_end`]: Self::column_lower_end
    pub fn row_floor(
        &self,
        a: &Vector3<f64>,
        d: &Vector3<f64>,
        step: &Vector3<f64>,
    ) -> Option<f64> {
        if self.has_flanks() || d.y.abs() < 1e-12 {
            return None;
        }
        let h = self.half_width;
        let len = step.x.hypot(step.z);
        let (nx, nz) = (-step.z / len, step.x / len);
        let (w0, w1) = (a.x * nx + a.z * nz, d.x * nx + d.z * nz);
        let inv_dy = 1.0 / d.y;
        let (mut t1, mut t2) = ((-h - a.y) * inv_dy, (h - a.y) * inv_dy);
        if t1 > t2 {
            std::mem::swap(&mut t1, &mut t2);
        }
        // the solid lies within R of the axle
        let big = self.radius;
        let mut start = t1;
        if w1.abs() > 1e-15 {
            let (mut lo, mut hi) = ((-big - w0) / w1, (big - w0) / w1);
            if lo > hi {
                std::mem::swap(&mut lo, &mut hi);
            }
            if hi < t1 || lo > t2 {
                return None;
            }
            start = start.max(lo);
        } else if w0.abs() > big {
            return None;
        }
        let gd = |t: f64| {
            let w = w0 + w1 * t;
            let (rho, fall) = self.tip_profile(a.y + d.y * t);
            (w.abs() - rho, w1.copysign(w) + fall * d.y)
        };
        let (gt, st) = gd(start);
        if gt <= 0.0 {
            return Some(start);
        }
        first_root(gd, start, gt, st, t2)
    }

    /// [`lower_boundary`](Self::lower_boundary) of the flanked solid: the
    /// same solve with the slab `|y| <= W/2` and the piecewise `rho_full`
    /// (concave, so `g` stays convex and Newton from the slab's entry still
    /// climbs monotonically to the first root; at the tip/flank seam either
    /// one-sided slope is a subgradient, which keeps that property).
    fn lower_boundary_flanked(&self, x: f64, y: f64) -> Option<(f64, Face)> {
        let rt = self.rot.transpose();
        let a = rt * Vector3::new(x - self.centre.x, y - self.centre.y, -self.centre.z);
        self.column_lower_end_flanked(a, rt.column(2).into_owned())
    }

    /// [`lower_boundary_flanked`](Self::lower_boundary_flanked) for the
    /// line `q(t) = a + t d` of the cutter frame.
    fn column_lower_end_flanked(&self, a: Vector3<f64>, d: Vector3<f64>) -> Option<(f64, Face)> {
        let (h, hw) = (self.half_width, self.hub_half_width);
        let face_at = |qy: f64| {
            if qy.abs() <= h {
                Face::Rim { y: qy }
            } else {
                Face::Flank { y: qy }
            }
        };
        if d.y.abs() < 1e-12 {
            if a.y.abs() > hw {
                return None;
            }
            let rho = self.rho_full(a.y);
            let b = a.x * d.x + a.z * d.z;
            let c = a.x * a.x + a.z * a.z - rho * rho;
            let dd = b * b - c;
            if dd < 0.0 {
                return None;
            }
            return Some((-b - dd.sqrt(), face_at(a.y)));
        }
        let (mut t1, mut t2) = ((-hw - a.y) / d.y, (hw - a.y) / d.y);
        if t1 > t2 {
            std::mem::swap(&mut t1, &mut t2);
        }
        // the line enters the radius-R cylinder at t_r: below it, it is
        // outside the solid, and Newton may start there
        let (ca, cb) = (d.x * d.x + d.z * d.z, a.x * d.x + a.z * d.z);
        let cc = a.x * a.x + a.z * a.z - self.radius * self.radius;
        let mut t_r = f64::NEG_INFINITY;
        if ca > 0.0 {
            let disc2 = cb * cb - ca * cc;
            if disc2 < 0.0 {
                return None;
            }
            let (lo, hi) = ((-cb - disc2.sqrt()) / ca, (-cb + disc2.sqrt()) / ca);
            if hi < t1 || lo > t2 {
                return None;
            }
            t_r = lo;
        } else if cc > 0.0 {
            return None;
        }
        let r = self.tip_radius;
        let gd = |t: f64| {
            let q = a + d * t;
            let m0 = (q.x * q.x + q.z * q.z).sqrt();
            let y = q.y.clamp(-hw, hw);
            // d rho_full / dy: the tip profile's slope, or the flank's
            let drho = if y.abs() <= h {
                -y / (r * r - y * y).max(1e-300).sqrt()
            } else {
                -y.signum() * self.flank_cot
            };
            (
                m0 - self.rho_full(y),
                (q.x * d.x + q.z * d.z) / m0.max(1e-300) - drho * d.y,
            )
        };
        if gd(t1).0 <= 0.0 {
            let qy = a.y + d.y * t1;
            return Some((t1, Face::Side(if qy > 0.0 { 1 } else { -1 })));
        }
        let t = t1.max(t_r);
        let (gt, st) = gd(t);
        let inn = first_root(gd, t, gt, st, t2)?;
        let qy = (a.y + d.y * inn).clamp(-hw, hw);
        Some((inn, face_at(qy)))
    }

    /// Bounding box in plan (rock frame, `[x_lo, x_hi, y_lo, y_hi]`) of the
    /// whole solid, without trigonometry: the solid lies in the radius-`R`
    /// cylinder about the axle `a`, `hub_half_width` either side of the
    /// centre, and a radius-`R` circle in the plane normal to `a` spans
    /// `R sqrt(1 - a_x^2)` either side of its centre along x (and so on
    /// along y).
    pub fn plan_box(&self) -> [f64; 4] {
        // padding for rounding
        const PAD: f64 = 1e-9;
        let a = self.rot.column(1);
        let (r, hw) = (self.radius, self.hub_half_width);
        let ex = r * (1.0 - a.x * a.x).max(0.0).sqrt() + hw * a.x.abs() + PAD;
        let ey = r * (1.0 - a.y * a.y).max(0.0).sqrt() + hw * a.y.abs() + PAD;
        let (cx, cy) = (self.centre.x, self.centre.y);
        [cx - ex, cx + ex, cy - ey, cy + ey]
    }

    /// Bounding box (rock frame, `[x_lo, x_hi, y_lo, y_hi]`) of the part of the
    /// solid below height `z_top`, or `None` when the whole disc is above it.
    pub fn footprint_below(&self, z_top: f64) -> Option<[f64; 4]> {
        // padding for rounding
        const PAD: f64 = 1e-9;
        if self.has_flanks() {
            return self.footprint_flanked(z_top);
        }
        let rho = self.radius;
        let axle = self.rot.column(1).into_owned();
        if axle.z.abs() > 1e-12 {
            // A tilted axle: every point of the solid shifted along the axle
            // to the lower end cap (s0 = -h sign(a_z)) gets no higher, and
            // lands in that cap's radius-R disc; so the part below z_top lies
            // in the cap disc's segment below z_top swept back along the axle
            // segment (Minkowski sum with {0, 2h sign(a_z) a}).
            let s0 = -self.half_width * axle.z.signum();
            let bb = self.arc_box(s0, rho, z_top)?;
            let sweep = axle * (2.0 * self.half_width * axle.z.signum());
            return Some([
                bb[0] + sweep.x.min(0.0) - PAD,
                bb[1] + sweep.x.max(0.0) + PAD,
                bb[2] + sweep.y.min(0.0) - PAD,
                bb[3] + sweep.y.max(0.0) + PAD,
            ]);
        }
        // Axle horizontal: every rim circle (radius rho(y) <= R, in a vertical
        // plane, centre on the axle segment) lies inside the radius-R circle
        // about the same centre, and a horizontal plane cuts that cylinder in
        // two lines parallel to the axle, so the part of the solid below z_top
        // lies in the hull of the radius-R arcs below z_top at the two ends of
        // the axle segment.
        // Each such arc lies in the vertical plane through its end of the
        // axle (at the centre's height) and spans that point +- L along the
        // plane's horizontal direction u: L = sqrt(R^2 - dz^2) while z_top
        // lies dz below the centre, R once it is above.
        let dz = self.centre.z - z_top;
        if dz > rho {
            return None;
        }
        let l = if dz > 0.0 {
            (rho * rho - dz * dz).max(0.0).sqrt()
        } else {
            rho
        };
        let (hx, hy) = (axle.x * self.half_width, axle.y * self.half_width);
        // u = (-axle.y, axle.x): its extents along x and y
        let (ux, uy) = ((axle.y * l).abs(), (axle.x * l).abs());
        let (cx, cy) = (self.centre.x, self.centre.y);
        Some([
            cx - hx.abs() - ux - PAD,
            cx + hx.abs() + ux + PAD,
            cy - hy.abs() - uy - PAD,
            cy + hy.abs() + uy + PAD,
        ])
    }

    /// [`footprint_below`](Self::footprint_below) of the flanked solid: the
    /// union of the boxes of its pieces, the tip slab (`|y| <= T/2`, radius
    /// at most `R`) and each flank cut into slabs of axle coordinate, each
    /// within the radius of its inner end (the flank narrows outwards). A
    /// slab `[y0, y1]` of radius at most `rho` lies, as in the plain case, in
    /// its lower end cap's radius-`rho` disc swept along the slab (tilted
    /// axle) or in the hull of its two end caps' arcs (horizontal axle). Thin
    /// slabs keep the box near the flank itself, where one slab for the whole
    /// solid would sweep the tip's radius `R` out to the hub.
    fn footprint_flanked(&self, z_top: f64) -> Option<[f64; 4]> {
        const PAD: f64 = 1e-9;
        let (h, hw) = (self.half_width, self.hub_half_width);
        let mut bb = [
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        let mut any = false;
        let mut add = |b: Option<[f64; 4]>| {
            if let Some(b) = b {
                any = true;
                bb = [
                    bb[0].min(b[0]),
                    bb[1].max(b[1]),
                    bb[2].min(b[2]),
                    bb[3].max(b[3]),
                ];
            }
        };
        add(self.slab_box(-h, h, self.radius, z_top));
        // slabs that over-reach the flank's radius by at most 1 mm (32 at most)
        let n = ((hw - h) * self.flank_cot / 1e-3).ceil().clamp(1.0, 32.0) as usize;
        let dy = (hw - h) / n as f64;
        for k in 0..n {
            let (y0, y1) = (h + dy * k as f64, h + dy * (k + 1) as f64);
            let rho = self.rho_full(y0);
            add(self.slab_box(y0, y1, rho, z_top));
            add(self.slab_box(-y1, -y0, rho, z_top));
        }
        any.then_some([bb[0] - PAD, bb[1] + PAD, bb[2] - PAD, bb[3] + PAD])
    }

    /// Box of the part below `z_top` of the slab `y0 <= y <= y1` of the
    /// radius-`rho` cylinder about the axle (see [`footprint_flanked`](Self::footprint_flanked)).
    fn slab_box(&self, y0: f64, y1: f64, rho: f64, z_top: f64) -> Option<[f64; 4]> {
        let axle = self.rot.column(1).into_owned();
        if axle.z.abs() > 1e-12 {
            let (low, sweep) = if axle.z > 0.0 {
                (y0, axle * (y1 - y0))
            } else {
                (y1, -axle * (y1 - y0))
            };
            let bb = self.arc_box(low, rho, z_top)?;
            return Some([
                bb[0] + sweep.x.min(0.0),
                bb[1] + sweep.x.max(0.0),
                bb[2] + sweep.y.min(0.0),
                bb[3] + sweep.y.max(0.0),
            ]);
        }
        let a = self.arc_box(y0, rho, z_top)?;
        let b = self.arc_box(y1, rho, z_top)?;
        Some([
            a[0].min(b[0]),
            a[1].max(b[1]),
            a[2].min(b[2]),
            a[3].max(b[3]),
        ])
    }

    /// Box (rock frame, `[x_lo, x_hi, y_lo, y_hi]`) of the radius-`rho` disc
    /// segment at axle coordinate `y` that lies below `z_top`: the segment is
    /// bounded by its arc, whose box is set by the arc's end points and the
    /// x/y extremes inside it.
    fn arc_box(&self, y: f64, rho: f64, z_top: f64) -> Option<[f64; 4]> {
        let (t0, dt) = self.arc_below(y, rho, z_top)?;
        let mut bb = [
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        let mut add = |th: f64| {
            let p = self.to_world(&Vector3::new(rho * th.sin(), y, -rho * th.cos()));
            bb[0] = bb[0].min(p.x);
            bb[1] = bb[1].max(p.x);
            bb[2] = bb[2].min(p.y);
            bb[3] = bb[3].max(p.y);
        };
        add(t0 - dt);
        add(t0 + dt);
        for axis in 0..2 {
            let tm = self.rot[(axis, 0)].atan2(-self.rot[(axis, 2)]);
            for th in [tm, tm + std::f64::consts::PI] {
                if wrap(th - t0).abs() <= dt {
                    add(th);
                }
            }
        }
        Some(bb)
    }

    /// The arc of the rim circle at axle coordinate `y` (radius `rho`) lying
    /// below height `z_top`: centre angle and half-width, or `None`.
    pub fn arc_below(&self, y: f64, rho: f64, z_top: f64) -> Option<(f64, f64)> {
        self.arc_below_at(&self.lowest(), y, rho, z_top)
    }

    /// [`PosedDisc::arc_below`] given the disc's [`PosedDisc::lowest`] (the
    /// same arithmetic: a caller with many circles finds it once).
    pub fn arc_below_at(&self, low: &Lowest, y: f64, rho: f64, z_top: f64) -> Option<(f64, f64)> {
        // world z(theta) = c_z + r21 y + rho (r20 sin - r22 cos)
        let s = (z_top - self.centre.z - self.rot[(2, 1)] * y) / rho;
        if low.m < 1e-12 {
            return (s > 0.0).then_some((0.0, std::f64::consts::PI));
        }
        let c = -s / low.m; // need cos(theta - theta0) >= c
        if c > 1.0 {
            return None;
        }
        Some((low.theta0, c.max(-1.0).acos()))
    }

    /// Where every rim circle of the disc is lowest ([`Lowest`]).
    pub fn lowest(&self) -> Lowest {
        // world z(theta) = ... + rho (a sin + b cos), a sin + b cos =
        // m cos(theta - tm): lowest at theta0 = tm + pi
        let (a, b) = (self.rot[(2, 0)], -self.rot[(2, 2)]);
        let m = (a * a + b * b).sqrt();
        if m < 1e-12 {
            return Lowest {
                theta0: 0.0,
                sc: (0.0, 1.0),
                m,
            };
        }
        let tm = a.atan2(b);
        Lowest {
            theta0: wrap(tm + std::f64::consts::PI),
            sc: (-a / m, -b / m),
            m,
        }
    }
}

/// [`PosedDisc::column_lower_end`] of a flank-less disc for many vertical
/// lines of one direction `d` whose axle component is not zero (a tilted
/// disc's cut, a line a node): what depends on `d` alone is found once (the
/// disc's own call copied both vectors and found `1 / d_y` and `1 /
/// |d_xz|^2` again at every node). Each line's solve does the same
/// arithmetic as that call, bit for bit.
#[derive(Debug, Clone, Copy)]
pub struct Columns<'a> {
    disc: &'a PosedDisc,
    d: Vector3<f64>,
    inv_dy: f64,
    ca: f64,
    inv_ca: f64,
    r2: f64,
}

impl<'a> Columns<'a> {
    /// The lines of direction `d` (`d.y != 0`) through `disc` (no flanks).
    pub fn new(disc: &'a PosedDisc, d: Vector3<f64>) -> Self {
        let ca = d.x * d.x + d.z * d.z;
        Self {
            disc,
            d,
            inv_dy: 1.0 / d.y,
            ca,
            inv_ca: 1.0 / ca,
            r2: disc.radius * disc.radius,
        }
    }

    /// The lower end below `cap` of the line `q(t) = a + t d`
    /// ([`PosedDisc::column_lower_end`]). (Kept out of line: inlined into
    /// the cut's walk of a row, the tilted 30 deg scene's step took more
    /// instructions than before, 119.9 against 118.7 k; out of line 116.7 k.)
    #[inline(never)]
    pub fn lower_end(&self, a: &Vector3<f64>, cap: f64) -> Option<(f64, Face)> {
        let (disc, d, a) = (self.disc, &self.d, *a);
        let h = disc.half_width;
        // general pose: slab |q_y| <= h gives t in [t1, t2]; inside it the
        // convex g(t) = |q_xz(t)| - rho(q_y(t)) must be <= 0
        let inv_dy = self.inv_dy;
        let (mut t1, mut t2) = ((-h - a.y) * inv_dy, (h - a.y) * inv_dy);
        if t1 > t2 {
            std::mem::swap(&mut t1, &mut t2);
        }
        if t1 >= cap {
            return None;
        }
        // the solid lies in the radius-R cylinder about the axle: a line that
        // misses the cylinder within the slab misses the disc; where it
        // enters the cylinder, |q_xz| = R >= rho, so the solid's lower end
        // lies no lower than that
        let (ca, cb) = (self.ca, a.x * d.x + a.z * d.z);
        let cc = a.x * a.x + a.z * a.z - self.r2;
        let mut start = t1;
        if ca > 0.0 {
            let disc2 = cb * cb - ca * cc;
            if disc2 < 0.0 {
                return None;
            }
            let (root, inv_ca) = (disc2.sqrt(), self.inv_ca);
            let (lo, hi) = ((-cb - root) * inv_ca, (-cb + root) * inv_ca);
            if hi < t1 || lo > t2 {
                return None;
            }
            start = start.max(lo);
        } else if cc > 0.0 {
            return None;
        }
        if start >= cap {
            return None;
        }
        // g and its slope together: they share the point and both square
        // roots (the same values `rho` and a separate slope would compute)
        let gd = |t: f64| {
            let q = a + d * t;
            let m0 = (q.x * q.x + q.z * q.z).sqrt();
            let (rho, fall) = disc.tip_profile(q.y);
            let g = m0 - rho;
            (g, (q.x * d.x + q.z * d.z) / m0.max(1e-300) + fall * d.y)
        };
        if start == t1 && gd(t1).0 <= 0.0 {
            let qy = a.y + d.y * t1;
            return Some((t1, Face::Side(if qy > 0.0 { 1 } else { -1 })));
        }
        // g is convex, positive at `start` (outside the cylinder, or at t1 with
        // g(t1) > 0): Newton from there climbs monotonically to its first root
        // while g falls; if g stops falling first, its minimum is positive
        // and the line misses the disc. Every iterate is a lower bound of the
        // root, so one at or past `cap` ends the search.
        let t = start;
        let (gt, st) = gd(start);
        if gt <= 0.0 {
            // entered the cylinder where the rim is at radius R: the root
            return Some((
                start,
                Face::Rim {
                    y: (a.y + d.y * start).clamp(-h, h),
                },
            ));
        }
        let inn = first_root(gd, t, gt, st, t2.min(cap))?;
        let qy = (a.y + d.y * inn).clamp(-h, h);
        Some((inn, Face::Rim { y: qy }))
    }
}

/// The first root of a convex `g` by Newton from `t`, where `g(t) = gt > 0`
/// with slope `st` and `t` lies left of that root: the iterates climb
/// monotonically, each a lower bound of the root. `gd(t)` gives `g` and its
/// slope together. `None` when `g` stops falling first (its minimum is
/// positive: no root) or an iterate passes `limit` (the root lies beyond
/// it).
fn first_root(
    gd: impl Fn(f64) -> (f64, f64),
    mut t: f64,
    mut gt: f64,
    mut slope: f64,
    limit: f64,
) -> Option<f64> {
    for _ in 0..60 {
        if slope >= 0.0 {
            return None;
        }
        let next = t - gt / slope;
        if next > limit {
            return None;
        }
        let (gn, sn) = gd(next);
        if gn <= 1e-13 || next - t < 1e-13 {
            return Some(next);
        }
        t = next;
        gt = gn;
        slope = sn;
    }
    None
}

/// Wraps an angle into (-pi, pi].
pub fn wrap(a: f64) -> f64 {
    let two_pi = 2.0 * std::f64::consts::PI;
    let w = (a + std::f64::consts::PI).rem_euclid(two_pi) - std::f64::consts::PI;
    if w <= -std::f64::consts::PI {
        w + two_pi
    } else {
        w
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn disc(pose: Pose) -> PosedDisc {
        PosedDisc::new(&CutterParams::default(), &pose)
    }

    /// The lowest point's sine and cosine from the rotation are those of
    /// `arc_below`'s angle, on discs rolled, pitched and turned every way.
    #[test]
    fn lowest_sin_cos_is_that_of_the_lowest_points_angle() {
        let mut next = crate::core::uniforms(0x9e37_79b9_7f4a_7c15_u64);
        for _ in 0..2000 {
            let mut a = || 3.1 * (2.0 * next() - 1.0);
            let d = disc(Pose::new(0.0, 0.0, 0.3, a(), 0.5 * a(), a()));
            let (t0, _) = d.arc_below(0.0, d.radius, f64::MAX).unwrap();
            let (s, c) = d.lowest().sc;
            let (s0, c0) = t0.sin_cos();
            assert!(
                (s - s0).abs() < 1e-14 && (c - c0).abs() < 1e-14,
                "{s} {s0} {c} {c0}"
            );
        }
        // upright, and with the axle vertical (every point of a rim circle
        // equally low: the angle 0)
        let up = disc(Pose::new(0.0, 0.0, 0.3, 0.0, 0.0, 0.0));
        assert_eq!(up.lowest().sc, (0.0, 1.0));
        let flat = disc(Pose::new(
            0.0,
            0.0,
            0.3,
            std::f64::consts::FRAC_PI_2,
            0.0,
            0.0,
        ));
        assert_eq!(flat.arc_below(0.0, flat.radius, f64::MAX).unwrap().0, 0.0);
        assert_eq!(flat.lowest().sc, (0.0, 1.0));
    }

    #[test]
    fn upright_lower_boundary_is_the_rim_circle() {
        let d = disc(Pose::new(1.0, 2.0, 0.5, 0.0, 0.0, 0.0));
        let (z, f) = d.lower_boundary(1.0, 2.0).unwrap();
        assert!((z - (0.5 - 0.2159)).abs() < 1e-12);
        assert_eq!(f, Face::Rim { y: 0.0 });
        let (z, _) = d.lower_boundary(1.03, 2.004).unwrap();
        let rho = d.rho(0.004);
        assert!((z - (0.5 - (rho * rho - 0.03f64.powi(2)).sqrt())).abs() < 1e-12);
        assert!(d.lower_boundary(1.0, 2.0066).is_none());
        assert!(d.lower_boundary(1.3, 2.0).is_none());
    }

    #[test]
    fn general_solver_agrees_with_closed_form_and_finds_side_faces() {
        // a tiny roll forces the general path; it must agree with the upright answer
        let up = disc(Pose::new(0.0, 0.0, 0.3, 0.0, 0.0, 0.0));
        let tilt = disc(Pose::new(0.0, 0.0, 0.3, 0.0, 0.0, 1e-9));
        for &(x, y) in &[(0.0, 0.0), (0.05, 0.003), (-0.1, -0.006)] {
            let a = up.lower_boundary(x, y).unwrap().0;
            let b = tilt.lower_boundary(x, y).unwrap().0;
            assert!((a - b).abs() < 1e-8, "{a} {b}");
        }
        // rolled 60 deg: beside the tip the lowest point of a vertical line is on a side face
        let r60 = disc(Pose::new(0.0, 0.0, 0.3, 0.0, 0.0, 60f64.to_radians()));
        // the face y_local = +T/2 faces down-and-sideways: with roll +60 the axle
        // y points up and towards +y, so the lower face is y_local = -T/2 on the -y side
        let (_, f) = r60.lower_boundary(0.0, -0.05).unwrap();
        assert_eq!(f, Face::Side(-1));
        // a point on that face is at height consistent with the plane of the face
        let (z, _) = r60.lower_boundary(0.0, -0.05).unwrap();
        let q = r60.rot.transpose() * (Vector3::new(0.0, -0.05, z) - r60.centre);
        assert!((q.y + 0.0065).abs() < 1e-9, "{q}");
    }

    #[test]
    fn arc_below_matches_the_contact_angle_of_an_upright_disc() {
        let d = disc(Pose::new(0.0, 0.0, 0.2159 - 0.0038, 0.0, 0.0, 0.0));
        let (t0, dt) = d.arc_below(0.0, 0.2159, 0.0).unwrap();
        assert!(t0.abs() < 1e-12);
        assert!((dt - 0.187897).abs() < 1e-6);
        let bb = d.footprint_below(0.0).unwrap();
        assert!(
            (bb[1] - 0.2159 * dt.sin()).abs() < 1e-9 && (bb[0] + 0.2159 * dt.sin()).abs() < 1e-9
        );
        assert!(bb[3] >= 0.0065 && bb[3] < 0.0065 + 1e-3);
    }

    /// Yaw, pitch and roll of the box tests: upright, turned, tilted both
    /// ways and all three at once.
    const BOX_POSES: [(f64, f64, f64); 6] = [
        (0.0, 0.0, 0.0),
        (0.3, 0.1, 0.0),
        (0.0, 0.0, 0.5),
        (0.7, -0.2, 1.0),
        (0.0, 0.0, -1.2),
        (1.0, 0.4, 0.3),
    ];

    #[test]
    fn footprint_holds_every_point_the_disc_reaches_below_the_top() {
        // brute force over a fine grid: wherever a vertical meets the solid
        // below z_top, the point must lie in the footprint box
        for &(yaw, pitch, roll) in &BOX_POSES {
            let pose = Pose::new(0.0, 0.0, 0.2, yaw, pitch, roll);
            let d = disc(pose);
            let z_top = 0.0;
            let bb = d.footprint_below(z_top);
            let n = 300;
            for a in 0..=n {
                for b in 0..=n {
                    let x = -0.25 + 0.5 * a as f64 / n as f64;
                    let y = -0.25 + 0.5 * b as f64 / n as f64;
                    if let Some((zl, _)) = d.lower_boundary(x, y) {
                        if zl < z_top {
                            let bb =
                                bb.unwrap_or_else(|| panic!("pose {yaw} {pitch} {roll}: no box"));
                            assert!(
                                x >= bb[0] && x <= bb[1] && y >= bb[2] && y <= bb[3],
                                "pose {yaw} {pitch} {roll}: ({x}, {y}) outside {bb:?}"
                            );
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn the_plan_box_holds_the_whole_solid_and_no_more() {
        // every point of the surface (rim, side faces and, flanked, the
        // flanks out to the hub) lies in the box; and the box is tight:
        // the points reach within 0.1 mm of each of its sides, plus what
        // the section loses of the radius R towards its ends (the box takes
        // R over the whole width)
        let plain = CutterParams::default();
        let flanked = CutterParams {
            flank_angle: 0.35,
            hub_width: 0.05,
            ..CutterParams::default()
        };
        for c in [&plain, &flanked] {
            // (and a disc rolled almost onto its side)
            for &(yaw, pitch, roll) in BOX_POSES.iter().chain([&(2.0, 0.0, 1.5)]) {
                let d = PosedDisc::new(c, &Pose::new(0.1, -0.2, 0.3, yaw, pitch, roll));
                let bb = d.plan_box();
                let mut reach = [
                    f64::INFINITY,
                    f64::NEG_INFINITY,
                    f64::INFINITY,
                    f64::NEG_INFINITY,
                ];
                let (ny, nt, nr) = (200, 720, 20);
                for k in 0..=ny {
                    let y = -d.hub_half_width + 2.0 * d.hub_half_width * k as f64 / ny as f64;
                    let rho = d.rho_full(y);
                    // the circle at y, and at the two ends the face's disc
                    let radii: Vec<f64> = if k == 0 || k == ny {
                        (0..=nr).map(|j| rho * j as f64 / nr as f64).collect()
                    } else {
                        vec![rho]
                    };
                    for i in 0..nt {
                        let t = std::f64::consts::TAU * i as f64 / nt as f64;
                        for &r in &radii {
                            let p = d.to_world(&Vector3::new(r * t.sin(), y, -r * t.cos()));
                            assert!(
                                p.x >= bb[0] && p.x <= bb[1] && p.y >= bb[2] && p.y <= bb[3],
                                "pose {yaw} {pitch} {roll}: {p} outside {bb:?}"
                            );
                            reach = [
                                reach[0].min(p.x),
                                reach[1].max(p.x),
                                reach[2].min(p.y),
                                reach[3].max(p.y),
                            ];
                        }
                    }
                }
                let slack = d.radius - d.rho_full(d.hub_half_width) + 1e-4;
                for (side, (b, r)) in bb.iter().zip(reach).enumerate() {
                    assert!(
                        (b - r).abs() < slack,
                        "pose {yaw} {pitch} {roll}: side {side} {b} against {r}"
                    );
                }
            }
        }
    }

    #[test]
    fn the_lowest_point_in_closed_form_is_the_lowest_of_a_fine_scan() {
        let c = CutterParams::default();
        for roll in [0.0f64, 0.001, 0.1, 0.5, 1.0, 1.2, -0.7, 1.5] {
            for (pitch, yaw) in [(0.0, 0.0), (0.2, 0.3), (-0.1, 2.0)] {
                let d = PosedDisc::new(&c, &Pose::new(0.1, -0.2, 0.3, yaw, pitch, roll));
                let low = d.lowest_point();
                // every rim slice's lowest point, 4001 slices, lies no lower
                let mut scan = f64::INFINITY;
                for k in 0..=4000 {
                    let y = -d.half_width + 2.0 * d.half_width * k as f64 / 4000.0;
                    if let Some((t0, _)) = d.arc_below(y, d.rho(y), f64::MAX) {
                        scan = scan.min(d.to_world(&d.rim_point_local(t0, y)).z);
                    }
                }
                assert!(low.z <= scan + 1e-12, "roll {roll}: {} above {scan}", low.z);
                assert!(scan - low.z < 1e-8, "roll {roll}: {} against {scan}", low.z);
                // and it lies on the disc's surface
                let q = d.rot.transpose() * (low - d.centre);
                let rho = q.x.hypot(q.z);
                assert!((rho - d.rho(q.y)).abs() < 1e-12 && q.y.abs() <= d.half_width + 1e-15);
            }
        }
    }
}
