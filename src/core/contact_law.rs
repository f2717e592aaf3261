//! kerf's contact law: the CSM pressure integrated over the part of the
//! disc's surface that is inside the rock and driving into it.
//!
//! **The surface.** The disc's surface is cut into circles about the axle:
//! rim circles, one per slice across the tip profile (axle coordinate `y`,
//! radius `rho(y)`), and rings on each side face that reaches the rock
//! (radius `r`; their load faded in over the first 10 deg of tilt,
//! [`face_weight`]). On each circle the contact query finds the arcs
//! `[t0, t1]` where the rock lies over the surface (see `contact_cutter_heightmap`). Over an arc,
//! the force density of a pressure `P` normal to the surface is, in the cutter
//! frame, `P (s sin(t) + c cos(t) + k)` for constant vectors `s, c, k`
//! (a [`Trig`]), and so is its moment about the centre: both integrate in
//! closed form. On the tip profile (slope angle `alpha`, `sin alpha = y/r`)
//! the element `rho dt dy / cos(alpha)` with normal `(cos a sin t, sin a,
//! -cos a cos t)` gives the density `rho dy (-sin t, -tan a, cos t)`: its
//! rolling part integrates to the slice's depth times `dy`, so **the rolling
//! force is the pressure times the cross-section of rock in front of the
//! disc** and the normal force the pressure times the plan area of the
//! contact, whatever the scene.
//!
//! **Driving into the rock.** A surface element carries pressure while it
//! moves into the rock: its normal velocity `v_n = (v + w x q) . n` is
//! positive. On a circle about the axle `v_n = A sin(t) + B cos(t) + C`, so the
//! driving part of an arc is found exactly. A rolling disc's leading arc
//! drives and its trailing arc does not; a plunging disc drives with both; a
//! disc pushed sideways with the side it is pushed towards; a spinning disc
//! in its own groove, or a side face sliding in its own plane, does not. It
//! must also drive into rock **that is still there**: where the disc moved
//! `look_ahead` of travel along its own twist finds, at the same point of its
//! surface, rock already cut to the disc's shape, it is re-rolling its own
//! groove, and only touching it. That test is made at three points of each arc's driving
//! part. Below [`V_REST`] of travel speed the law fades to the elastic
//! support of a cutter at rest: every element inside the rock pushes, so a
//! cutter pressed in and held keeps its load.
//!
//! **Pressure level.** The CSM closed form was fitted to the whole contact of
//! a fresh cut: `F_N = F_t cos(beta)`, `F_R = F_t sin(beta)`. The integral
//! over the round tip profile of the same fresh cut at penetration `p` is
//! below that (the profile's edges reach less deep than its crown). The
//! rolling and normal densities are scaled by `lambda_R(p) = F_R / I_R(p)`
//! and `lambda_N(p) = F_N / I_N(p)`, with `I(p)` the integral of this very
//! law over the fresh cut's slices; side components and moments take
//! `lambda_N`. A fresh straight cut on a flat face therefore reproduces the
//! CSM closed form to the accuracy of its arc ends, and every other scene
//! is the same pressure on a different wetted surface.
//!
//! **The pressure distribution.** `csm.psi` distributes the pressure along
//! each arc as `(u / L)^psi`, `u` the angle from the arc's far end (the free
//! surface), `L` its length; for `psi = 0` (the default) it is uniform and the
//! integrals are closed-form, otherwise they use Gauss-Legendre quadrature
//! on the variable that makes the weight flat.

use nalgebra::{Matrix3, Rotation3, Vector3};

use super::cutter::PosedDisc;
use super::pose::Twist;

/// Below this travel speed \[m/s\] of the disc (centre speed plus `R` times
/// the frame's turn rate, spin excluded) the law fades from driving contact
/// to the elastic support of a cutter at rest (smoothstep in speed).
pub const V_REST: f64 = 1.0e-3;

/// The lean of the axle out of the horizontal (`|axle_z|`, sin 10 deg) from
/// which a side face carries its full load; an upright disc's faces carry
/// none ([`face_weight`]). (5 deg until the cut stopped carving the front
/// arc: the face towards a turn then meets the wall it drives into, not a
/// sliver of it, carries about 1.7 times the load, and a 5 deg fade moved
/// the side force on a 1 m track by 3.3 % of F_N per 0.5 deg.)
pub const FACE_TILT: f64 = 0.1736;

/// The share of its load a side face carries on a disc whose axle has the
/// vertical component `axle_z`: 0 upright, rising smoothly to 1 at
/// [`FACE_TILT`]. An upright disc's faces are vertical, and a height map
/// cannot tell where a vertical wall stands within a cell: a face reading
/// it finds rock over the blur of the groove's own wall (a disc re-rolling
/// its groove on a 1 m track read 2.0 kN of side force at 1 mm cells and
/// 0.9 kN at 0.25 mm where the geometry has none), and its load jumps as
/// the wall passes a node (sliding off the rock's side edge, 4.3 kN a
/// sample). The faces fade in over the first 10 deg of tilt, so the load
/// stays continuous in the tilt (docs/head.md, "Upright discs turn too").
#[inline]
pub fn face_weight(axle_z: f64) -> f64 {
    smoothstep(axle_z.abs() / FACE_TILT)
}

#[inline]
pub fn smoothstep(s: f64) -> f64 {
    let s = s.clamp(0.0, 1.0);
    s * s * (3.0 - 2.0 * s)
}

/// A vector function `s sin(t) + c cos(t) + k` of the angle `t` on a circle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Trig {
    pub s: Vector3<f64>,
    pub c: Vector3<f64>,
    pub k: Vector3<f64>,
}

impl Trig {
    #[inline]
    pub fn at(&self, t: f64) -> Vector3<f64> {
        let (st, ct) = t.sin_cos();
        self.s * st + self.c * ct + self.k
    }

    /// `integral from t0 to t1`.
    #[inline]
    pub fn integral(&self, t0: f64, t1: f64) -> Vector3<f64> {
        self.integral_sc(t0, t1, t0.sin_cos(), t1.sin_cos())
    }

    /// [`Trig::integral`] given `t0.sin_cos()` and `t1.sin_cos()`.
    #[inline]
    pub fn integral_sc(
        &self,
        t0: f64,
        t1: f64,
        (s0, c0): (f64, f64),
        (s1, c1): (f64, f64),
    ) -> Vector3<f64> {
        self.s * (c0 - c1) + self.c * (s1 - s0) + self.k * (t1 - t0)
    }
}

/// Force and moment (about the disc centre), cutter frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Load {
    pub force: Vector3<f64>,
    pub moment: Vector3<f64>,
}

impl Load {
    pub fn scaled(&self, w: f64) -> Load {
        Load {
            force: self.force * w,
            moment: self.moment * w,
        }
    }
}

impl std::ops::Add for Load {
    type Output = Load;
    fn add(mut self, o: Load) -> Load {
        self += o;
        self
    }
}

impl std::ops::AddAssign for Load {
    fn add_assign(&mut self, o: Load) {
        self.force += o.force;
        self.moment += o.moment;
    }
}

/// Where a circle's surface drives into the rock ([`Element::driving`]):
/// everywhere or nowhere (`All(drives)`), or within `h` of the angle `tm`
/// (`About(tm, h)`, repeating every turn).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Driving {
    All(bool),
    About(f64, f64),
}

/// One circle of the disc's surface about the axle, with the densities of a
/// unit pressure on it and the normal velocity of its points.
#[derive(Debug, Clone, Copy)]
pub struct Element {
    pub force: Trig,
    pub moment: Trig,
    /// `v_n(t) = a sin(t) + b cos(t) + c`; terms below `vn_eps` are noise.
    pub vn: (f64, f64, f64),
    pub vn_eps: f64,
    /// Axle coordinate and radius of the circle (cutter frame): the point at
    /// angle `t` is `(radius sin t, y, -radius cos t)`.
    pub y: f64,
    pub radius: f64,
}

/// The motion of the disc, as the law needs it.
#[derive(Debug, Clone, Copy)]
pub struct Motion {
    /// Centre velocity and angular velocity, cutter frame.
    pub v: Vector3<f64>,
    pub w: Vector3<f64>,
    /// 0 at rest, 1 once the disc travels faster than `V_REST`.
    pub moving: f64,
    /// Normal velocities below this are rounding noise \[m/s\].
    pub vn_eps: f64,
    /// Surface point (cutter frame) to where the same point of the surface
    /// is after `look_ahead` of travel of the frame, rock frame:
    /// `ahead_rot * q + ahead_pos`. The spin is left out: the surface is one of
    /// revolution, and the point at the same angle tells whether the disc
    /// ahead still meets rock where this one does.
    pub ahead_rot: Matrix3<f64>,
    pub ahead_pos: Vector3<f64>,
}

/// `exp` of a rotation vector and the `V` matrix of SE(3) (the integral of
/// the rotation over the step), for a body-fixed twist.
fn exp_and_v(phi: Vector3<f64>) -> (Matrix3<f64>, Matrix3<f64>) {
    let th = phi.norm();
    let k = phi.cross_matrix();
    let k2 = k * k;
    let (a, b) = if th < 1e-6 {
        (0.5 - th * th / 24.0, 1.0 / 6.0 - th * th / 120.0)
    } else {
        (
            (1.0 - th.cos()) / (th * th),
            (th - th.sin()) / (th * th * th),
        )
    };
    let e = *Rotation3::from_scaled_axis(phi).matrix();
    (e, Matrix3::identity() + k * a + k2 * b)
}

impl Motion {
    /// The motion of `disc` under `twist` (rock frame), looking `look_ahead`
    /// metres of travel ahead.
    pub fn new(disc: &PosedDisc, twist: &Twist, look_ahead: f64) -> Self {
        let rt = disc.rot.transpose();
        let v = rt * twist.velocity;
        let w = rt * twist.omega;
        // the frame turns with w less its spin about the axle (cutter y)
        let w_frame = Vector3::new(w.x, 0.0, w.z);
        let speed = v.norm() + w_frame.norm() * disc.radius;
        let moving = smoothstep(speed / V_REST);
        let (ahead_rot, ahead_pos) = if speed > 0.0 && look_ahead > 0.0 {
            let tau = look_ahead / speed;
            let (e, vm) = exp_and_v(w_frame * tau);
            (disc.rot * e, disc.centre + disc.rot * (vm * (v * tau)))
        } else {
            (disc.rot, disc.centre)
        };
        let vn_eps = 1e-12 * (v.norm() + w.norm() * disc.radius);
        Self {
            v,
            w,
            moving,
            vn_eps,
            ahead_rot,
            ahead_pos,
        }
    }

    /// Whether the side face `side` (+1 / -1 along the axle), reaching out to
    /// radius `r`, drives into the rock anywhere ahead of its lowest point
    /// (in the direction of travel; anywhere, when the disc does not travel
    /// along its rolling direction). A face's normal velocity is
    /// `side (w_z r sin t + w_x r cos t + v_y)`. Rolling straight it is zero:
    /// the face slides in its own plane. Turning, the face towards the
    /// turn's centre drives ahead of its lowest point and shaves the wall
    /// there; the other face drives only behind it, into the wall its own
    /// leading edge has just carved. The law loads a moving disc's face only
    /// where this holds.
    pub fn face_drives_ahead(&self, side: f64, r: f64) -> bool {
        let (a, b, c) = (side * self.w.z * r, side * self.w.x * r, side * self.v.y);
        // `a sin t + b cos t` peaks at `hypot(a, b)` where `sin t` has the
        // sign of `a`: ahead when that is the travel's sign (or the disc does
        // not travel); otherwise its most ahead is at an end, `t = 0` or `pi`
        let travel = self.v.x;
        let peak_ahead = travel.abs() <= self.vn_eps || travel.signum() * a > 0.0;
        let most = c + if peak_ahead { a.hypot(b) } else { b.abs() };
        most > self.vn_eps
    }

    /// The share of its driving load the side face `side` carries as the
    /// wall it drives into yields. The rock is elastic-perfectly-plastic
    /// (the law's elastic layer, `elastic_depth`): a face meets the wall at
    /// its leading edge and presses it more as it passes. Turning at
    /// curvature `k` (the frame's turn rate over the travel speed) or pushed
    /// sideways at slope `s` (sideways over forward speed), a flat face has
    /// pressed the wall point at its lowest point's cross-section by
    /// `d0 = side (k L^2 / 2 + s L)` on arriving there (`k` signed as the
    /// turn's direction of travel), `L` = `reach`, the
    /// face's reach ahead of the lowest point. The share is 0 while `d0` is
    /// inside the elastic layer, 1 from three layers on, smooth between; so
    /// a face's load fades in as a track's radius falls from about
    /// `L^2 / 2 elastic_depth` (625 m for a 50 mm reach and 2 um) to a third
    /// of it, instead of switching on in full at any curvature (a 60 deg disc
    /// 6 mm deep: -83 kN of side force on a 1000 m track, -13.5 kN straight,
    /// once cuts stopped carving the front arc). At rest, and for a disc not
    /// travelling along its heading, 1; the blend with rest follows
    /// `moving`.
    pub fn face_yield(&self, side: f64, reach: f64, elastic_depth: f64) -> f64 {
        let travel = self.v.x.abs();
        if travel <= self.vn_eps || elastic_depth <= 0.0 {
            return 1.0;
        }
        // the face's normal velocity at `u` ahead is `side (w_z u + v_y)`,
        // `u` of the travel's sign: its integral over the reach, per travel
        let d0 =
            side * (self.v.x.signum() * self.w.z * reach * reach * 0.5 + self.v.y * reach) / travel;
        let y = smoothstep((d0 / elastic_depth - 1.0) / 2.0);
        (1.0 - self.moving) + self.moving * y
    }

    /// The reach ahead of its lowest point of a cut by `disc` as deep as
    /// the rock at `z_top`: the half chord `sqrt(2 R p)` of its rim, the
    /// `reach` of [`Motion::face_yield`].
    pub fn face_reach(disc: &PosedDisc, z_top: f64) -> f64 {
        (2.0 * disc.radius * (z_top - disc.lowest_point().z).max(0.0)).sqrt()
    }

    /// Where the surface point `q` (cutter frame) is after the look-ahead.
    #[inline]
    pub fn ahead(&self, q: &Vector3<f64>) -> Vector3<f64> {
        self.ahead_rot * q + self.ahead_pos
    }
}

impl Element {
    /// Force and moment per unit pressure and unit angle at angle `t`.
    #[inline]
    pub fn load_at(&self, t: f64) -> Load {
        Load {
            force: self.force.at(t),
            moment: self.moment.at(t),
        }
    }

    /// Rim circle of the tip profile at axle coordinate `y`, for a strip of
    /// the tip `dy` wide.
    pub fn rim(disc: &PosedDisc, y: f64, dy: f64, m: &Motion) -> Self {
        let rho = disc.rho(y);
        let r = disc.tip_radius;
        let sa = (y / r).clamp(-1.0, 1.0);
        let ca = (1.0 - sa * sa).max(0.0).sqrt();
        let ta = sa / ca.max(1e-12);
        let g = rho * dy;
        let lever = g * (y - rho * ta);
        let kk = rho * sa - y * ca;
        Self {
            force: Trig {
                s: Vector3::new(-g, 0.0, 0.0),
                c: Vector3::new(0.0, 0.0, g),
                k: Vector3::new(0.0, -g * ta, 0.0),
            },
            moment: Trig {
                s: Vector3::new(0.0, 0.0, lever),
                c: Vector3::new(lever, 0.0, 0.0),
                k: Vector3::zeros(),
            },
            vn: (
                m.v.x * ca + m.w.z * kk,
                -m.v.z * ca + m.w.x * kk,
                m.v.y * sa,
            ),
            vn_eps: m.vn_eps,
            y,
            radius: rho,
        }
    }

    /// Ring of radius `r` on the side face `y = side * T/2` (outward normal
    /// `side * y`), for a band `dr` wide; with flanks, on the hub face
    /// `y = side * W/2`.
    pub fn ring(disc: &PosedDisc, side: f64, r: f64, dr: f64, m: &Motion) -> Self {
        let g = side * r * dr;
        let g2 = g * r;
        Self {
            force: Trig {
                s: Vector3::zeros(),
                c: Vector3::zeros(),
                k: Vector3::new(0.0, -g, 0.0),
            },
            moment: Trig {
                s: Vector3::new(0.0, 0.0, -g2),
                c: Vector3::new(-g2, 0.0, 0.0),
                k: Vector3::zeros(),
            },
            vn: (side * m.w.z * r, side * m.w.x * r, side * m.v.y),
            vn_eps: m.vn_eps,
            y: side * disc.hub_half_width,
            radius: r,
        }
    }

    /// Circle of a flank (a cone about the axle) at axle coordinate `y`
    /// (`T/2 < |y| < W/2`, side `sign(y)`), for a band `ds` wide along the
    /// flank. The outward normal is `(N sin t, Ny, -N cos t)` with `N = sin f`
    /// along the radius and `Ny = side cos f` along the axle (`f` the flank
    /// angle), the element `rho dt ds`: the same densities as a rim slice's
    /// (`N = cos a`, `Ny = sin a`, `ds = dy / cos a`) and a ring's (`N = 0`).
    pub fn flank(disc: &PosedDisc, y: f64, ds: f64, m: &Motion) -> Self {
        let rho = disc.rho_full(y);
        let (sn, cn) = disc.flank_normal();
        let (n, ny) = (sn, y.signum() * cn);
        let g = rho * ds;
        let lever = g * (y * n - rho * ny);
        let kk = rho * ny - y * n;
        Self {
            force: Trig {
                s: Vector3::new(-g * n, 0.0, 0.0),
                c: Vector3::new(0.0, 0.0, g * n),
                k: Vector3::new(0.0, -g * ny, 0.0),
            },
            moment: Trig {
                s: Vector3::new(0.0, 0.0, lever),
                c: Vector3::new(lever, 0.0, 0.0),
                k: Vector3::zeros(),
            },
            vn: (m.v.x * n + m.w.z * kk, -m.v.z * n + m.w.x * kk, m.v.y * ny),
            vn_eps: m.vn_eps,
            y,
            radius: rho,
        }
    }

    /// The surface point at angle `t`, cutter frame.
    #[inline]
    pub fn point(&self, t: f64) -> Vector3<f64> {
        self.point_sc(t.sin_cos())
    }

    /// [`Element::point`] at the angle whose `sin_cos` is `(s, c)`.
    #[inline]
    pub fn point_sc(&self, (s, c): (f64, f64)) -> Vector3<f64> {
        Vector3::new(self.radius * s, self.y, -self.radius * c)
    }

    #[inline]
    pub fn vn_at(&self, t: f64) -> f64 {
        let (s, c) = t.sin_cos();
        self.vn.0 * s + self.vn.1 * c + self.vn.2
    }

    /// The parts of `[lo, hi]` where `v_n > 0` (at most two intervals).
    pub fn driving_parts(&self, lo: f64, hi: f64) -> ([(f64, f64); 2], usize) {
        self.driving_parts_on(self.driving(), lo, hi)
    }

    /// Where on the whole circle `v_n > 0`, for [`Element::driving_parts_on`]
    /// (which a caller with several arcs on one circle computes once).
    pub fn driving(&self) -> Driving {
        let (a, b, c) = self.vn;
        let m = a.hypot(b);
        if m <= c.abs() + self.vn_eps {
            return Driving::All(c > self.vn_eps);
        }
        // a sin + b cos = m cos(t - tm)
        let tm = a.atan2(b);
        let h = (-c / m).clamp(-1.0, 1.0).acos();
        Driving::About(tm, h)
    }

    /// [`Element::driving_parts`] given [`Element::driving`].
    pub fn driving_parts_on(&self, d: Driving, lo: f64, hi: f64) -> ([(f64, f64); 2], usize) {
        let mut out = [(0.0, 0.0); 2];
        let mut n = 0;
        let (tm, h) = match d {
            Driving::All(drives) => {
                if drives && hi > lo {
                    out[0] = (lo, hi);
                    n = 1;
                }
                return (out, n);
            }
            Driving::About(tm, h) => (tm, h),
        };
        let two_pi = 2.0 * std::f64::consts::PI;
        let k0 = ((0.5 * (lo + hi) - tm) / two_pi).round();
        for dk in [-1.0, 0.0, 1.0] {
            let centre = tm + two_pi * (k0 + dk);
            let (s, e) = ((centre - h).max(lo), (centre + h).min(hi));
            if e > s && n < 2 {
                out[n] = (s, e);
                n += 1;
            }
        }
        (out, n)
    }
}

/// Gauss-Legendre nodes and weights on [0, 1] (16 points).
fn gauss16() -> &'static [(f64, f64); 16] {
    static G: std::sync::OnceLock<[(f64, f64); 16]> = std::sync::OnceLock::new();
    G.get_or_init(|| {
        // Newton on P_16, Golub-Welsch free
        let n = 16usize;
        let mut out = [(0.0, 0.0); 16];
        for (i, slot) in out.iter_mut().enumerate() {
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 0.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                    p0 = p1;
                    p1 = p2;
                }
                dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / dp;
                x -= dx;
                if dx.abs() < 1e-15 {
                    break;
                }
            }
            let w = 2.0 / ((1.0 - x * x) * dp * dp);
            *slot = (0.5 * (1.0 - x), 0.5 * w);
        }
        out
    })
}

/// The load of a unit CSM pressure on the arc `[lo, hi]` of `e` whose far
/// end (the free surface) is `hi` when `far_hi`, split into the whole arc
/// and its driving part.
pub fn arc_load(e: &Element, lo: f64, hi: f64, far_hi: bool, psi: f64) -> (Load, Load) {
    if psi != 0.0 {
        return arc_load_quadrature(e, lo, hi, far_hi, psi, true);
    }
    let (parts, n) = e.driving_parts(lo, hi);
    arc_load_in(
        e,
        (lo, hi),
        (lo.sin_cos(), hi.sin_cos()),
        far_hi,
        psi,
        &parts[..n],
    )
}

/// [`arc_load`] with the ends' `sin_cos` and the arc's driving parts
/// given (`e.driving_parts(lo, hi)`), which a caller that needs them as
/// well computes once (only the closed form of `psi = 0` reads them).
pub fn arc_load_in(
    e: &Element,
    (lo, hi): (f64, f64),
    (sc_lo, sc_hi): ((f64, f64), (f64, f64)),
    far_hi: bool,
    psi: f64,
    parts: &[(f64, f64)],
) -> (Load, Load) {
    if psi == 0.0 {
        // (a driving part's end that is an end of the arc, bit for bit,
        // reuses its sine and cosine)
        let sc = |t: f64| {
            if t.to_bits() == lo.to_bits() {
                sc_lo
            } else if t.to_bits() == hi.to_bits() {
                sc_hi
            } else {
                t.sin_cos()
            }
        };
        let whole = Load {
            force: e.force.integral_sc(lo, hi, sc_lo, sc_hi),
            moment: e.moment.integral_sc(lo, hi, sc_lo, sc_hi),
        };
        let mut drive = Load::default();
        for &(a, b) in parts {
            let (sa, sb) = (sc(a), sc(b));
            drive += Load {
                force: e.force.integral_sc(a, b, sa, sb),
                moment: e.moment.integral_sc(a, b, sa, sb),
            };
        }
        return (whole, drive);
    }
    arc_load_quadrature(e, lo, hi, far_hi, psi, true)
}

/// The whole-arc part of [`arc_load`] alone.
pub fn arc_load_whole(e: &Element, lo: f64, hi: f64, far_hi: bool, psi: f64) -> Load {
    if psi == 0.0 {
        let (sc_lo, sc_hi) = (lo.sin_cos(), hi.sin_cos());
        return Load {
            force: e.force.integral_sc(lo, hi, sc_lo, sc_hi),
            moment: e.moment.integral_sc(lo, hi, sc_lo, sc_hi),
        };
    }
    arc_load_quadrature(e, lo, hi, far_hi, psi, false).0
}

/// [`arc_load`] for `psi > 0`, by quadrature; the driving part only when
/// `drive_too` (else zero).
fn arc_load_quadrature(
    e: &Element,
    lo: f64,
    hi: f64,
    far_hi: bool,
    psi: f64,
    drive_too: bool,
) -> (Load, Load) {
    // (u/L)^psi du with u from the far end = L/(1+psi) dv, u = L v^(1/(1+psi))
    let len = hi - lo;
    let ex = 1.0 / (1.0 + psi);
    let scale = len * ex;
    let (mut whole, mut drive) = (Load::default(), Load::default());
    for &(v, w) in gauss16() {
        let u = len * v.powf(ex);
        let t = if far_hi { hi - u } else { lo + u };
        let l = e.load_at(t).scaled(w * scale);
        whole += l;
        if drive_too && e.vn_at(t) > e.vn_eps {
            drive += l;
        }
    }
    (whole, drive)
}

/// The motion of [`pressure_level`]'s fresh straight cut: rolling forwards
/// at unit speed, no look-ahead turn.
fn level_motion(disc: &PosedDisc) -> Motion {
    Motion {
        v: Vector3::new(1.0, 0.0, 0.0),
        w: Vector3::new(0.0, 1.0 / disc.radius, 0.0),
        moving: 1.0,
        vn_eps: 0.0,
        ahead_rot: Matrix3::identity(),
        ahead_pos: Vector3::zeros(),
    }
}

/// `lambda_R(p)` and `lambda_N(p)`: the CSM rolling and normal force at `p`
/// over the same law's integral on a fresh straight cut at `p` with `n`
/// slices, each slice's arc weighed by `reg(its depth)` as the law weighs it
/// (0 where that integral vanishes).
pub fn pressure_level(
    disc: &PosedDisc,
    n: usize,
    p: f64,
    psi: f64,
    f_t: f64,
    beta: f64,
    reg: &dyn Fn(f64) -> f64,
) -> (f64, f64) {
    let h = disc.half_width;
    let dy = 2.0 * h / n as f64;
    let (mut ir, mut inn) = (0.0, 0.0);
    for k in 0..n {
        let y = -h + dy * (k as f64 + 0.5);
        let rho = disc.rho(y);
        let pk = p - (disc.radius - rho);
        if pk <= 0.0 {
            continue;
        }
        let cos_phi = ((rho - pk) / rho).clamp(-1.0, 1.0);
        let (fx, fz) = if psi == 0.0 {
            // `arc_load_whole` of the rim element (`Element::rim`) from the
            // lowest point to `phi` in closed form: its rolling and normal
            // parts are `-g (1 - cos phi)` and `g sin phi`, `g = rho dy`
            // (the angle itself only enters the axial part, unused here)
            let sin_phi = ((1.0 - cos_phi) * (1.0 + cos_phi)).sqrt();
            let g = rho * dy;
            (-g * (1.0 - cos_phi), g * sin_phi)
        } else {
            let e = Element::rim(disc, y, dy, &level_motion(disc));
            let f = arc_load_whole(&e, 0.0, cos_phi.acos(), true, psi).force;
            (f.x, f.z)
        };
        let w = reg(pk);
        ir -= fx * w;
        inn += fz * w;
    }
    let lr = if ir > 0.0 { f_t * beta.sin() / ir } else { 0.0 };
    let ln = if inn > 0.0 {
        f_t * beta.cos() / inn
    } else {
        0.0
    };
    (lr, ln)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::params::CutterParams;
    use crate::core::pose::Pose;

    fn disc() -> PosedDisc {
        PosedDisc::new(
            &CutterParams::default(),
            &Pose::new(0.0, 0.0, 0.3, 0.0, 0.0, 0.0),
        )
    }

    #[test]
    fn closed_form_matches_quadrature_and_psi_zero() {
        let d = disc();
        let m = Motion::new(&d, &Twist::new([1.0, 0.2, -0.1], [0.3, 4.0, 0.5]), 0.0);
        let e = Element::rim(&d, 0.004, 1e-3, &m);
        let (w0, d0) = arc_load(&e, -0.1, 0.3, true, 0.0);
        // tiny psi: quadrature of the same integrand
        let (w1, _) = arc_load(&e, -0.1, 0.3, true, 1e-12);
        assert!((w0.force - w1.force).norm() < 1e-9 * w0.force.norm());
        assert!((w0.moment - w1.moment).norm() < 1e-9 * w0.moment.norm().max(1e-12));
        // brute-force midpoint sums of the driving part
        let n = 200_000;
        let mut f = Vector3::zeros();
        for i in 0..n {
            let t = -0.1 + 0.4 * (i as f64 + 0.5) / n as f64;
            if e.vn_at(t) > 0.0 {
                f += e.force.at(t) * (0.4 / n as f64);
            }
        }
        assert!(
            (f - d0.force).norm() < 1e-6 * w0.force.norm(),
            "{f} {}",
            d0.force
        );
    }

    /// `pressure_level`'s own closed form at `psi = 0` (the arc's end sine
    /// from its cosine) gives the level of `arc_load_whole`'s (both ends'
    /// `sin_cos`) to round-off, on an upright and a tilted disc, shallow and
    /// deep.
    #[test]
    fn pressure_level_at_psi_zero_is_the_whole_arcs_level() {
        let c = CutterParams::default();
        let reg = |d: f64| (d / 1e-3).min(1.0);
        for roll in [0.0, 0.5] {
            let d = PosedDisc::new(&c, &Pose::new(0.0, 0.0, 0.3, roll, 0.0, 0.0));
            for p in [2e-4, 1e-3, 3.8e-3, 0.012] {
                let (lr, ln) = pressure_level(&d, 9, p, 0.0, 1e5, 0.1, &reg);
                // the same sums through `arc_load_whole`
                let still = level_motion(&d);
                let dy = 2.0 * d.half_width / 9.0;
                let (mut ir, mut inn) = (0.0, 0.0);
                for k in 0..9 {
                    let y = -d.half_width + dy * (k as f64 + 0.5);
                    let rho = d.rho(y);
                    let pk = p - (d.radius - rho);
                    if pk > 0.0 {
                        let phi = ((rho - pk) / rho).acos();
                        let e = Element::rim(&d, y, dy, &still);
                        let f = arc_load_whole(&e, 0.0, phi, true, 0.0).force;
                        ir -= f.x * reg(pk);
                        inn += f.z * reg(pk);
                    }
                }
                let (er, en) = (1e5 * 0.1f64.sin() / ir, 1e5 * 0.1f64.cos() / inn);
                assert!(lr > 0.0 && ln > 0.0, "p = {p}");
                assert!((lr - er).abs() < 1e-12 * er, "p = {p}: {lr} {er}");
                assert!((ln - en).abs() < 1e-12 * en, "p = {p}: {ln} {en}");
            }
        }
    }

    #[test]
    fn driving_parts_cover_exactly_the_positive_normal_velocity() {
        let d = disc();
        for (v, w) in [
            ([1.0, 0.0, 0.0], [0.0, 4.6, 0.0]),
            ([0.0, 0.0, -1.0], [0.0, 0.0, 0.0]),
            ([0.3, 0.5, 0.1], [0.2, 1.0, 2.0]),
            ([-1.0, 0.0, 0.0], [0.0, -4.6, 0.0]),
        ] {
            let m = Motion::new(&d, &Twist::new(v, w), 0.0);
            for y in [-0.006, 0.0, 0.003] {
                let e = Element::rim(&d, y, 1e-3, &m);
                let (parts, n) = e.driving_parts(-2.0, 2.5);
                for i in 0..1000 {
                    let t = -2.0 + 4.5 * (i as f64 + 0.5) / 1000.0;
                    let inside = parts[..n].iter().any(|&(a, b)| t > a && t < b);
                    let vn = e.vn_at(t);
                    if vn.abs() > 1e-9 {
                        assert_eq!(inside, vn > 0.0, "t={t} vn={vn} {v:?} {w:?} y={y}");
                    }
                }
                // the closed form of v_n agrees with (v + w x q) . n
                let t = 0.7;
                let q = e.point(t);
                let r = d.tip_radius;
                let (sa, ca) = (y / r, (1.0 - (y / r).powi(2)).sqrt());
                let nrm = Vector3::new(ca * t.sin(), sa, -ca * t.cos());
                let direct = (m.v + m.w.cross(&q)).dot(&nrm);
                assert!(
                    (direct - e.vn_at(t)).abs() < 1e-12,
                    "{direct} {}",
                    e.vn_at(t)
                );
            }
        }
    }

    #[test]
    fn rolling_work_of_a_fresh_arc_is_the_slice_cross_section() {
        // the rolling density integrates to (1 - cos phi) rho dy = depth * dy
        let d = disc();
        let m = Motion::new(
            &d,
            &Twist::new([1.0, 0.0, 0.0], [0.0, 1.0 / d.radius, 0.0]),
            0.0,
        );
        let e = Element::rim(&d, 0.002, 1e-3, &m);
        let rho = d.rho(0.002);
        let pk = 0.003;
        let phi = ((rho - pk) / rho).acos();
        let (w, dr) = arc_load(&e, 0.0, phi, true, 0.0);
        assert!((-w.force.x - pk * 1e-3).abs() < 1e-15);
        assert_eq!(w, dr);
    }

    #[test]
    fn look_ahead_follows_a_circle_exactly() {
        // a disc heading +x on a circle of radius 0.5 about (0, 0.5): after
        // 0.1 m of travel its centre is on the circle and heads along it
        let d = PosedDisc::new(
            &CutterParams::default(),
            &Pose::new(0.0, 0.0, 0.2, 0.0, 0.0, 0.0),
        );
        let rt = 0.5;
        let tw = Twist::new([1.0, 0.0, 0.0], [0.0, 1.0 / d.radius, 1.0 / rt]);
        let m = Motion::new(&d, &tw, 0.1);
        let c = m.ahead(&Vector3::zeros());
        // look-ahead travel counts the frame's turn at the rim: 1 + R/rt m/s
        let s = 0.1 / (1.0 + d.radius / rt);
        assert!(
            ((c.x.powi(2) + (c.y - rt).powi(2)).sqrt() - rt).abs() < 1e-12,
            "{c}"
        );
        assert!((c.x - rt * (s / rt).sin()).abs() < 1e-12, "{c}");
    }

    #[test]
    fn only_the_face_towards_a_turn_or_a_push_drives_ahead_of_its_lowest_point() {
        // an upright disc heading +x, rolling at 1 m/s; its face y = +h
        // (side +1) looks towards +y
        let d = PosedDisc::new(
            &CutterParams::default(),
            &Pose::new(0.0, 0.0, 0.2, 0.0, 0.0, 0.0),
        );
        let r = d.rho(d.half_width);
        let drives = |v: [f64; 3], wz: f64| {
            let m = Motion::new(&d, &Twist::new(v, [0.0, 1.0 / d.radius, wz]), 0.0);
            [m.face_drives_ahead(1.0, r), m.face_drives_ahead(-1.0, r)]
        };
        // straight: both faces slide in their own planes
        assert_eq!(drives([1.0, 0.0, 0.0], 0.0), [false, false]);
        // turning towards +y (centre at +y): the face towards the centre
        // drives ahead of its lowest point, the other only behind it
        assert_eq!(drives([1.0, 0.0, 0.0], 1.0 / 0.5), [true, false]);
        assert_eq!(drives([1.0, 0.0, 0.0], -1.0 / 0.5), [false, true]);
        // rolling backwards, the turn's leading half is the other one
        assert_eq!(drives([-1.0, 0.0, 0.0], 1.0 / 0.5), [false, true]);
        // pushed sideways: the face it is pushed towards, everywhere
        assert_eq!(drives([1.0, 0.1, 0.0], 0.0), [true, false]);
        // not travelling along its rolling direction (plunging, turning in
        // place): the whole circle counts as ahead
        assert_eq!(drives([0.0, 0.0, -0.1], 1.0), [true, true]);
    }

    #[test]
    fn a_face_carries_its_load_once_the_wall_it_presses_yields() {
        // the same disc; a face reaching 50 mm ahead, a 2 um elastic layer:
        // on a track of radius R it has pressed the wall at its lowest point
        // by 0.05^2 / 2 R (1.25 um at 1000 m, 4.2 um at 300 m)
        let d = PosedDisc::new(
            &CutterParams::default(),
            &Pose::new(0.0, 0.0, 0.2, 0.0, 0.0, 0.0),
        );
        let (reach, e) = (0.05, 2e-6);
        let share = |v: [f64; 3], wz: f64| {
            let m = Motion::new(&d, &Twist::new(v, [0.0, 1.0 / d.radius, wz]), 0.0);
            [m.face_yield(1.0, reach, e), m.face_yield(-1.0, reach, e)]
        };
        // straight, and on a 1000 m track: inside the elastic layer
        assert_eq!(share([1.0, 0.0, 0.0], 0.0), [0.0, 0.0]);
        assert_eq!(share([1.0, 0.0, 0.0], 1e-3), [0.0, 0.0]);
        // 4.2 um on a 300 m track: between one and three layers
        let [a, b] = share([1.0, 0.0, 0.0], 1.0 / 300.0);
        assert!(a > 0.3 && a < 0.8 && b == 0.0, "{a} {b}");
        // a head's track: the full share; turning the other way, the other
        // face; rolling backwards, the turn's leading half is the other face
        assert_eq!(share([1.0, 0.0, 0.0], 1.0 / 4.83), [1.0, 0.0]);
        assert_eq!(share([1.0, 0.0, 0.0], -1.0 / 4.83), [0.0, 1.0]);
        assert_eq!(share([-1.0, 0.0, 0.0], 1.0 / 4.83), [0.0, 1.0]);
        // pushed sideways at 1 % of the travel: 500 um, the full share
        assert_eq!(share([1.0, 0.01, 0.0], 0.0), [1.0, 0.0]);
        // at rest, and not travelling along the heading: the whole share
        assert_eq!(share([0.0, 0.0, 0.0], 0.0), [1.0, 1.0]);
        assert_eq!(share([0.0, 0.0, -0.1], 1.0), [1.0, 1.0]);
    }
}
