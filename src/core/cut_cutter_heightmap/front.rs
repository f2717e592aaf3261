//! How far ahead of a moving disc its cut reaches ([`Front`]), and how
//! much rock a disc plunging into the face leaves (`plunge_lag`).

use super::*;

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
pub(super) fn lowest_point_velocity(
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
pub(super) const PLUNGE_FROM: f64 = 0.447_213_595_499_958; // 1 / sqrt(5)

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
pub(super) fn plunge_lag(v: &nalgebra::Vector3<f64>, numerics: &Numerics) -> f64 {
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
    pub(super) fn at(
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
    pub(super) fn rows_within(
        &self,
        g: &Grid,
        x: [f64; 2],
        j0: usize,
        j1: usize,
    ) -> Option<(usize, usize)> {
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
