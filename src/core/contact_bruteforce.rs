//! A slow, obviously correct reference for kerf's contact law
//! (`contact_law`, `contact_cutter_heightmap`): the oracle that holds the fast
//! query to the law on every scene, and for every later speed-up. Not the
//! default path.
//!
//! The disc's surface is sampled finely: `slices` rim circles across the tip
//! `rings` circles on each side face that reaches the rock (the hub faces
//! with flanks) and `flank_bands` circles along each flank, each walked from
//! its lowest point in steps of `ds` of arc. The same reading of the rock
//! (`rock_over`) decides, sample by sample, where the contact arc starts
//! (the first sample inside the rock) and ends (the first sample with no
//! rock here or one cell ahead). The pressure is summed sample by sample
//! (midpoint rule), masked where the surface does not move into the rock;
//! no walk step, no root refinement, no closed form. Every arc's share, the
//! side blend and the pressure level are the law's own functions.

use nalgebra::Vector3;

use super::contact_cutter_heightmap::{
    arc_contribution, assemble, face_below, flank_below, look_ahead, rock_over, slice_y,
    still_there_tolerance, Contact,
};
use super::contact_law::{face_weight, Element, Load, Motion};
use super::csm::CsmLaw;
use super::cutter::PosedDisc;
use super::heightmap::HeightMap;
use super::params::Numerics;
use super::pose::Twist;

/// How finely the oracle samples the surface.
#[derive(Debug, Clone, Copy)]
pub struct Resolution {
    /// Arc step \[m\].
    pub ds: f64,
    /// Rim circles across the tip.
    pub slices: usize,
    /// Circles across each side face, over the part of it
    /// that reaches below the highest rock under the disc.
    pub rings: usize,
    /// Circles along each flank, over the part of it that reaches below the
    /// highest rock under the disc (flanked discs only).
    pub flank_bands: usize,
}

impl Default for Resolution {
    /// 0.05 mm of arc, 101 slices (0.13 mm apart), 200 rings, 200 bands
    /// along each flank.
    fn default() -> Self {
        Self {
            ds: 5e-5,
            slices: 101,
            rings: 200,
            flank_bands: 200,
        }
    }
}

/// The contact of `disc` with `map` by brute force (rim and face loads,
/// penetration; no slip point).
pub fn contact_brute(
    map: &HeightMap,
    disc: &PosedDisc,
    law: &CsmLaw,
    num: &Numerics,
    elastic_depth: f64,
    twist: &Twist,
    res: &Resolution,
) -> Contact {
    let g = map.grid();
    let look = g.dx.max(g.dy);
    let o = Oracle {
        map,
        disc,
        law,
        motion: Motion::new(disc, twist, look_ahead(look, num)),
        look,
        eta: still_there_tolerance(elastic_depth, look, disc),
        elastic_depth,
        ds: res.ds,
    };
    let mut loads = [[Load::default(); 2]; 2];
    let mut depth = [0.0f64; 2];
    let mut spread = [0.0f64; 2];
    for c in o.circles(res) {
        for (s, dir) in [(0usize, 1.0f64), (1, -1.0)] {
            if let Some((load, arc_depth)) = o.arc(&c.e, dir) {
                depth[s] = depth[s].max(arc_depth * c.share);
                // (the side blend's depth over the tip's width: the oracle's
                // strips are all as wide, so the width drops out of it)
                if !c.face {
                    spread[s] += arc_depth;
                }
                loads[usize::from(c.face)][s] += load.scaled(c.share);
            }
        }
    }
    assemble(disc, law, res.slices, loads, depth, spread)
        .map(|(c, _)| c)
        .unwrap_or_default()
}

/// What every circle's walk reads: the disc, the rock, the law and the
/// motion, and the sampling step.
struct Oracle<'a> {
    map: &'a HeightMap,
    disc: &'a PosedDisc,
    law: &'a CsmLaw,
    motion: Motion,
    /// The larger side of a cell (the look-ahead's cell).
    look: f64,
    /// The still-there test's tolerance.
    eta: f64,
    elastic_depth: f64,
    /// Arc step \[m\].
    ds: f64,
}

/// A circle of the surface the oracle samples: its element, whether it is
/// on a side face or flank, and the share of its load it carries.
struct Sampled {
    e: Element,
    face: bool,
    share: f64,
}

impl Oracle<'_> {
    /// The circles to sample: the rim slices across the tip, then rings on
    /// each side face the law loads, then bands along each flank, each over
    /// the part of it that can reach the highest rock under the disc.
    fn circles(&self, res: &Resolution) -> Vec<Sampled> {
        let (disc, motion) = (self.disc, &self.motion);
        let h = disc.half_width;
        let mut circles: Vec<Sampled> = (0..res.slices)
            .map(|k| Sampled {
                e: Element::rim(
                    disc,
                    slice_y(h, res.slices, k),
                    2.0 * h / res.slices as f64,
                    motion,
                ),
                face: false,
                share: 1.0,
            })
            .collect();
        // the highest rock under the disc, which bounds the side face's rings
        // and the flanks' bands to the part that can reach the rock at all
        let top = self
            .map
            .highest_within(disc.centre.x, disc.centre.y, disc.radius);
        let w_face = face_weight(disc.rot[(2, 1)]);
        for side in [1.0f64, -1.0] {
            // the law loads a moving disc's face only where it drives ahead of
            // its lowest point (`Motion::face_drives_ahead`)
            let loaded = motion.moving < 1.0 || motion.face_drives_ahead(side, disc.rho(h));
            let Some((r_lo, r_hi)) = top
                .filter(|_| w_face > 0.0 && loaded)
                .and_then(|t| face_below(disc, side, t))
            else {
                continue;
            };
            // the face's share as the wall it drives into yields, as the fast
            // contact takes it (`Motion::face_yield`)
            let reach = top.map_or(0.0, |t| Motion::face_reach(disc, t));
            let share = w_face * motion.face_yield(side, reach, self.elastic_depth);
            let dr = (r_hi - r_lo) / res.rings as f64;
            for j in 0..res.rings {
                let r = r_lo + dr * (j as f64 + 0.5);
                circles.push(Sampled {
                    e: Element::ring(disc, side, r, dr, motion),
                    face: true,
                    share,
                });
            }
        }
        if disc.has_flanks() {
            // the flanks, finely, where they can reach the rock at all
            let (sn, _) = disc.flank_normal();
            for side in [1.0f64, -1.0] {
                let Some((s_lo, s_hi)) = top.and_then(|t| flank_below(disc, side, t)) else {
                    continue;
                };
                let ds = (s_hi - s_lo) / res.flank_bands as f64;
                for j in 0..res.flank_bands {
                    let s = s_lo + ds * (j as f64 + 0.5);
                    let y = side * (h + s * sn);
                    circles.push(Sampled {
                        e: Element::flank(disc, y, ds, motion),
                        face: true,
                        share: 1.0,
                    });
                }
            }
        }
        circles
    }

    /// The first contact arc on side `dir` of the circle `e`, sampled from
    /// its lowest point: its load (the law's share of it, `arc_contribution`)
    /// and its depth weighed by that share, or `None` if the circle meets no
    /// rock on that side.
    fn arc(&self, e: &Element, dir: f64) -> Option<(Load, f64)> {
        let (map, disc) = (self.map, self.disc);
        let (theta0, reach) = disc.arc_below(e.y, e.radius, f64::INFINITY)?;
        let reach = reach.min(std::f64::consts::PI);
        let dt = self.ds / e.radius;
        let m = (reach / dt).ceil() as usize;
        let world = |t: f64| disc.to_world(&e.point(t));
        // walk: the first sample inside the rock starts the arc, the
        // first with no rock here or ahead ends it
        let mut first = None;
        let mut last = 0usize;
        let mut u_max = 0.0f64;
        for i in 0..m {
            let t = theta0 + dir * dt * (i as f64 + 0.5);
            let p = world(t);
            let tan = disc.rot * Vector3::new(t.cos(), 0.0, t.sin()) * (dir * e.radius);
            let (here, ahead) = rock_over(map, &p, tan.x, tan.y, 1e-24, self.look);
            if first.is_none() {
                if here > 0.0 {
                    first = Some(i);
                    last = i;
                    u_max = here;
                }
            } else if ahead > 0.0 {
                last = i;
                u_max = u_max.max(here);
            } else {
                break;
            }
        }
        let i0 = first?;
        // arc ends at the sample edges
        let (ta, tb) = (
            theta0 + dir * dt * i0 as f64,
            theta0 + dir * dt * (last + 1) as f64,
        );
        let (t0, t1) = if tb >= ta { (ta, tb) } else { (tb, ta) };
        let len = t1 - t0;
        let psi = self.law.psi();
        let (mut whole, mut drive) = (Load::default(), Load::default());
        for i in i0..=last {
            let t = theta0 + dir * dt * (i as f64 + 0.5);
            // distance from the far end, for the psi distribution
            let u = (tb - t).abs();
            let w = if psi == 0.0 { 1.0 } else { (u / len).powf(psi) };
            let l = e.load_at(t).scaled(w * dt);
            whole += l;
            if e.vn_at(t) > e.vn_eps {
                drive += l;
            }
        }
        let arc_depth = (world(tb).z - world(ta).z).max(0.0);
        let (load, eff) = arc_contribution(
            map,
            disc,
            &self.motion,
            e,
            (t0, t1),
            (whole, drive),
            (u_max, self.law.regularisation(arc_depth)),
            self.elastic_depth,
            self.eta,
            None,
        );
        Some((load, arc_depth * eff))
    }
}
