//! The thesis's direction rule (ch. 7.3-7.4, eqs 41-53), kept to reproduce
//! and compare with its Table 3 simulation.
//!
//! The cutting force `F_t(p)` (same CSM law and same penetration as kerf's
//! rule) acts along the mean normal `N` of the distinct rock triangles under
//! the penetrated rim points; it is applied at `f_p`, where the ray from the
//! disc centre to the centre of the penetrated plane (midway between the
//! first and last penetrated points, eq. 43) meets the rim torus — with the
//! ray direction normalised, which eq. 53 needs and the thesis omits. The
//! friction of eqs 55-60 reads the slip at `f_p` in the penetrated plane.

use std::collections::HashSet;

use nalgebra::Vector3;

use super::contact_cutter_heightmap::{contact, Contact};
use super::csm::CsmLaw;
use super::cutter::PosedDisc;
use super::heightmap::HeightMap;
use super::params::Numerics;
use super::pose::Twist;

pub fn contact_thesis(
    map: &HeightMap,
    disc: &PosedDisc,
    law: &CsmLaw,
    num: &Numerics,
    twist: &Twist,
) -> Contact {
    let base = contact(map, disc, law, num, num.elastic_depth, twist);
    if !base.in_contact || base.penetration <= 0.0 {
        return base;
    }
    let g = map.grid();
    let cell = g.dx.min(g.dy);
    let h = disc.half_width;
    let n = num.tip_slices;
    let mut seen = HashSet::new();
    let mut sum = Vector3::zeros();
    let mut first: Option<Vector3<f64>> = None;
    let mut last = Vector3::zeros();
    for k in 0..n {
        let y = -h + 2.0 * h * k as f64 / (n - 1) as f64;
        let rho = disc.rho(y);
        let step = 0.5 * cell / rho;
        // the thesis loops alpha over the lower half of the rim
        let m = (std::f64::consts::PI / step).ceil() as usize;
        for s in 0..=m {
            let th = -std::f64::consts::FRAC_PI_2 + std::f64::consts::PI * s as f64 / m as f64;
            let p = disc.to_world(&disc.rim_point_local(th, y));
            if map.height(p.x, p.y) > p.z {
                if let Some((id, nrm)) = map.triangle(p.x, p.y) {
                    if seen.insert(id) {
                        sum += Vector3::from(nrm);
                    }
                }
                first.get_or_insert(p);
                last = p;
            }
        }
    }
    let Some(first) = first else { return base };
    let nn = sum.norm();
    if nn == 0.0 {
        return base;
    }
    let normal = sum / nn;
    // point of force application (eqs 43-53, ray normalised)
    let pc = 0.5 * (first + last);
    let dp = (pc - disc.centre).normalize();
    let dl = disc.rot.transpose() * dp;
    let (big, r) = (disc.radius - disc.tip_radius, disc.tip_radius);
    let sin_t = dl.y.abs().min(1.0);
    let cos_t = (1.0 - sin_t * sin_t).sqrt();
    let disc_t = (r * r - big * big * sin_t * sin_t).max(0.0);
    let lf = big * cos_t + disc_t.sqrt();
    let fp = dp * lf;
    let fade = if base.rim_force.norm() > 0.0 {
        base.rim_force.norm() / law.force(base.penetration)
    } else {
        0.0
    };
    let rim_force = normal * law.force(base.penetration) * fade;
    Contact {
        rim_force,
        rim_moment: fp.cross(&rim_force),
        application: fp,
        slip_point: fp,
        slip_normal: normal,
        ..base
    }
}
