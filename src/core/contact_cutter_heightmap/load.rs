//! What an arc carries (`arc_contribution`): the law's load over its
//! driving part, scaled by how much of the rock ahead is still there
//! (`rock_ahead`), and the contact assembled from the summed loads
//! (`assemble`).

use super::*;

/// The look-ahead of the "rock still there" test, in cells of at least
/// [`STILL_THERE_CELL`]: long enough to reach past the scallops a swept cut
/// leaves between its sub-steps.
pub(super) const LOOK_AHEAD_CELLS: f64 = 4.0;

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
pub(super) const ROCK_END_HALVINGS: usize = 16;

/// The rock over the surface point `q` (cutter frame) of `disc` after
/// `motion`'s look-ahead: `height - z` where the point is then, or, where
/// that lies off the rock (past the map's edge: the map holds no other
/// [`NO_ROCK`](crate::core::heightmap::NO_ROCK), and a height read across it is
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
pub(super) fn rock_ahead(
    map: &HeightMap,
    disc: &PosedDisc,
    motion: &Motion,
    q: &Vector3<f64>,
) -> f64 {
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
pub(super) fn rock_to_the_end(
    map: &HeightMap,
    here: &Vector3<f64>,
    ahead: &Vector3<f64>,
    u: f64,
) -> f64 {
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

/// An arc's driving parts (`Element::driving_parts_on`) and the `sin_cos`
/// of its ends, as [`arc_contribution`] takes them.
pub type PartsAndEnds<'a> = (&'a [(f64, f64)], [SinCos; 2]);

/// One arc's share of the load: its whole-arc and driving loads blended by
/// how fast the disc moves, the driving part weighed by whether the rock it
/// drives into is still there (three points of its longest driving part,
/// carried `look_ahead` along the motion), all faded by how deep the rock
/// reaches over the arc (`u_max`) and by the law's regularisation at the
/// arc's depth `reg` (an arc shallower than `numerics.pReg` grows linearly
/// from first touch, as the CSM law does). Returns the load and the fraction
/// of the whole arc's force it keeps (which scales the arc's depth in the
/// penetration and the side blend). `parts`: the arc's driving parts
/// (`e.driving_parts(t0, t1)`) and the `sin_cos` of `t0` and `t1`, when
/// the caller has them.
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
    parts: Option<PartsAndEnds>,
) -> (Load, f64) {
    let sigma = motion.moving;
    let mut still_there = 1.0;
    if sigma > 0.0 && drive.force != Vector3::zeros() {
        let own;
        let (parts, ends) = match parts {
            Some((p, sc)) => (p, Some(sc)),
            None => {
                own = e.driving_parts(t0, t1);
                (&own.0[..own.1], None)
            }
        };
        if let Some(&(a, b)) = parts
            .iter()
            .max_by(|p, q| (p.1 - p.0).total_cmp(&(q.1 - q.0)))
        {
            // the part's quarter points, turned from its middle by a
            // quarter of it (one `sin_cos` for the three, none where the
            // part is the whole arc, whose ends' the caller has: a rolling
            // disc's rim arcs drive all along)
            let (m, q) = (0.5 * (a + b), 0.25 * (b - a));
            let sc_m = match ends {
                Some(sc) if a == t0 && b == t1 => {
                    mid_sin_cos(sc, b - a).unwrap_or_else(|| m.sin_cos())
                }
                _ => m.sin_cos(),
            };
            let mut sum = 0.0;
            for sc in [
                sin_cos_near(m - q, m, sc_m),
                sc_m,
                sin_cos_near(m + q, m, sc_m),
            ] {
                let u = rock_ahead(map, disc, motion, &e.point_sc(sc));
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
/// unit pressure), each side's effective depth (its deepest loaded arc) and
/// its rim arcs' depths summed over the tip's width (`spread`): the side
/// blend `d^4 / (d+^4 + d-^4)` of the spreads (of the depths where no rim arc
/// carries any), the penetration (the depths so blended), the pressure level
/// of `n` slices and the rock-frame forces. `None` when no side reaches any
/// depth. Also returns the blend weights.
pub fn assemble(
    disc: &PosedDisc,
    law: &CsmLaw,
    n: usize,
    loads: [[Load; 2]; 2],
    depth: [f64; 2],
    spread: [f64; 2],
) -> Option<(Contact, (f64, f64))> {
    let (wp, wm) = {
        let by = if spread[0] + spread[1] > 0.0 {
            spread
        } else {
            depth
        };
        let (a, b) = (by[0].powi(4), by[1].powi(4));
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

/// `sin_cos` of the middle of an arc `span` rad long (less than half a
/// turn) from its ends' (`[(sin a, cos a), (sin b, cos b)]`): their unit
/// vectors' sum, normalised, to a few ulps; `None` past 3 rad, where that
/// sum grows short.
#[inline]
pub(super) fn mid_sin_cos([(s0, c0), (s1, c1)]: [SinCos; 2], span: f64) -> Option<SinCos> {
    if span.abs() > 3.0 {
        return None;
    }
    let (s, c) = (s0 + s1, c0 + c1);
    let n = (s * s + c * c).sqrt();
    Some((s / n, c / n))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_arcs_middle_from_its_ends_is_the_middles_sin_cos() {
        // arcs anywhere on the circle, up to 3 rad long, either way round
        let mut worst = 0.0f64;
        for i in 0..4000 {
            let a = -7.0 + 14.0 * ((i * 7919) % 4000) as f64 / 4000.0;
            let span =
                3.0 * ((i * 104_729) % 1000) as f64 / 1000.0 * if i % 2 == 0 { 1.0 } else { -1.0 };
            let b = a + span;
            let (s, c) = mid_sin_cos([a.sin_cos(), b.sin_cos()], b - a).expect("within 3 rad");
            let (sm, cm) = (0.5 * (a + b)).sin_cos();
            worst = worst.max((s - sm).abs()).max((c - cm).abs());
        }
        // (1.1e-15 at worst, near 3 rad, where the sum is 0.14 long)
        assert!(worst < 2e-15, "{worst:e}");
        assert_eq!(
            mid_sin_cos([(0.0, 1.0), (0.0, -1.0)], std::f64::consts::PI),
            None
        );
    }
}
