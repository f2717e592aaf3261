//! The circles of the disc's surface that the query walks (`Circle`,
//! `surface_circles`): the tip's rim slices, the side faces' rings and the
//! flanks' bands, and the parts of each below the rock's top.

use super::*;

/// On a moving disc, a side of a circle whose surface drives into the rock
/// over less than this many cells of its rim in all (within its reach)
/// carries no load, and need not be walked (`contact`). A disc that rolls
/// while it advances into the face (every disc of a boring head) drives the
/// trailing side of each circle within `v_advance / v_rolling` rad of its
/// lowest point, on rock it has just cut: 0.3 mm/s against 0.6 m/s on the
/// reference head's track of 2 m, 5e-4 rad, 0.1 mm of rim. Those slivers
/// changed no disc's mean force by more than 1e-11 of itself over 300 steps
/// of the reference head, while walking them was an eighth of its step; a
/// sliver ten times longer (1e-2 rad) moves the centre disc by 0.45 %.
/// Set in cells, the sliver shrinks with them: a finer run drops less.
pub const DRIVE_SLIVER_CELLS: f64 = 0.2;

/// A side whose blend weight cannot exceed this is not refined: its arcs
/// change the force by less than this fraction.
pub(super) const NEGLIGIBLE_WEIGHT: f64 = 1e-14;

/// Most bands `numerics.ring_step_cells` wide that a tilted disc's side
/// face is cut into ([`face_rings`]; each ring's arcs are exact).
pub(super) const MAX_RINGS: usize = 24;

/// Bands of the side face ([`face_rings`]) that one graded ring stands for.
pub(super) const RING_GRADE: usize = 3;

/// Most bands sampled along each flank (midpoint rule along the flank;
/// each band's arcs are exact).
pub(super) const MAX_FLANK_BANDS: usize = 24;

/// Most samples added by splitting strips (two a strip).
pub(super) const MAX_SUB: usize = 16;

/// Room for every circle: rim slices, rings, flank bands and the samples of
/// split strips.
pub(super) const MAX_CIRCLES: usize = 101 + 2 * MAX_RINGS + 2 * MAX_FLANK_BANDS + MAX_SUB;

/// The radii `[r_lo, r_hi]` of the side face on `side` (the hub face with
/// flanks, at `y = side W/2`) whose circles reach below `z_top`: a circle
/// of radius `r` reaches down to `centre.z + a_z side W/2 - m r`. `None`
/// when the whole face is above `z_top`.
pub fn face_below(disc: &PosedDisc, side: f64, z_top: f64) -> Option<(f64, f64)> {
    let hw = disc.hub_half_width;
    let r_hi = disc.rho_full(hw);
    let m = disc.rot[(2, 0)].hypot(disc.rot[(2, 2)]);
    let r_lo = if m > 1e-12 {
        ((disc.centre.z + disc.rot[(2, 1)] * side * hw - z_top) / m).max(0.0)
    } else {
        0.0
    };
    (r_lo < r_hi).then_some((r_lo, r_hi))
}

/// The rings (radius, width) a side face's band `[r_lo, r_hi]` that can
/// reach the rock ([`face_below`]) is sampled by, `ring_step` \[m\] the
/// spacing of its bands.
///
/// The band is cut into `nr` bands of equal width (`ring_step` or wider:
/// 2 to [`MAX_RINGS`]). The outermost keeps its ring at its middle: the
/// deepest ring sets the side's depth, and so the penetration, as with
/// rings at every band. The rest of the band, `[r_lo, r_hi - dr]`, gets one
/// ring for every [`RING_GRADE`] bands, graded towards `r_lo`. There the
/// face meets the rock's top (where that is flat): a ring of radius `r`
/// reaches `m (r - r_lo)` below it (`m` the sine of the axle's tilt from
/// the vertical), so the arc it cuts from the rock, and its load, rise like
/// `sqrt(r - r_lo)`, and the midpoint rule in the radius converged like its
/// rings' spacing to the power 1.5. In `u = sqrt((r - r_lo) / L)` (`L` the graded length) each
/// ring's piece is an interval of equal width; its ring lies where `sqrt`
/// takes its mean over the piece, `u = 2/3 (u1^3 - u0^3) / (u1^2 - u0^2)`,
/// and carries the piece's width, so a load `sqrt(r - r_lo)` is summed
/// exactly, and so is a constant one; a factor on the square root that
/// changes by a fraction `a` over the band errs by some `3e-3 a` with 8
/// rings (test `graded_rings_sum_a_square_root_onset_better_than_a_ring_a_band`;
/// the gauge cutters' factor changes by 2-6 %). What it does to the gauge
/// cutters' loads and cost, measured: README, "Speed and accuracy"
/// (`examples/ring_steps`, and the report's brute-force oracle, which puts
/// 200 rings on the face).
pub(super) fn face_rings(r_lo: f64, r_hi: f64, ring_step: f64) -> impl Iterator<Item = (f64, f64)> {
    let nr = (((r_hi - r_lo) / ring_step).ceil() as usize).clamp(2, MAX_RINGS);
    let dr = (r_hi - r_lo) / nr as f64;
    let ng = (nr - 1).div_ceil(RING_GRADE);
    let l = dr * (nr - 1) as f64;
    let graded = (0..ng).map(move |j| {
        let (u0, u1) = (j as f64 / ng as f64, (j + 1) as f64 / ng as f64);
        let u = (2.0 / 3.0) * (u1 * u1 * u1 - u0 * u0 * u0) / (u1 * u1 - u0 * u0);
        (r_lo + l * u * u, l * (u1 * u1 - u0 * u0))
    });
    std::iter::once((r_lo + dr * (nr as f64 - 0.5), dr)).chain(graded)
}

/// The part `[s_lo, s_hi]` of the flank on `side` (`s` the distance along
/// the flank from the tip's edge) whose circles reach below `z_top`: the
/// lowest point of a circle about the axle is `centre.z + a_z y - m rho`,
/// linear in `s` along the straight flank. `None` without flanks or when
/// the whole flank is above `z_top`.
pub fn flank_below(disc: &PosedDisc, side: f64, z_top: f64) -> Option<(f64, f64)> {
    if !disc.has_flanks() {
        return None;
    }
    let (h, hw) = (disc.half_width, disc.hub_half_width);
    let (sn, cn) = disc.flank_normal();
    // on the flank at angle f, y = side (h + s sin f), rho = rho(h) - s cos f
    let len = (hw - h) / sn;
    let m = disc.rot[(2, 0)].hypot(disc.rot[(2, 2)]);
    let az = disc.rot[(2, 1)];
    let z0 = disc.centre.z + az * side * h - m * disc.rho(h);
    let k = az * side * sn + m * cn;
    let (mut lo, mut hi) = (0.0f64, len);
    if k > 1e-15 {
        hi = hi.min((z_top - z0) / k);
    } else if k < -1e-15 {
        lo = lo.max((z_top - z0) / k);
    } else if z0 >= z_top {
        return None;
    }
    (hi > lo).then_some((lo, hi))
}

/// A circle of the disc's surface about the axle that the query walks.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Circle {
    /// Axle coordinate and radius.
    pub(super) y: f64,
    pub(super) radius: f64,
    /// Strip width across the tip (rim) or band width (ring).
    pub(super) width: f64,
    /// 0 for a rim slice, the face's side (+1 / -1) for a ring or a flank.
    pub(super) face: f64,
    /// A flank band (`width` is then its width along the flank).
    pub(super) flank: bool,
    /// A rim sample of a split strip: its depth counts in full (not in
    /// proportion to its width) in the penetration.
    pub(super) sub: bool,
}

impl Circle {
    /// A ring of a side face (not a rim slice, not a flank band).
    pub(super) fn is_ring(&self) -> bool {
        self.face != 0.0 && !self.flank
    }

    /// The surface element of the law on this circle.
    pub(super) fn element(&self, disc: &PosedDisc, motion: &Motion) -> Element {
        if self.face == 0.0 {
            Element::rim(disc, self.y, self.width, motion)
        } else if self.flank {
            Element::flank(disc, self.y, self.width, motion)
        } else {
            Element::ring(disc, self.face, self.radius, self.width, motion)
        }
    }
}

/// The circles of the disc's surface the query walks: the `n` rim slices,
/// then rings on each side face (the hub faces with flanks) over the part of
/// it that reaches below `z_top` (when `rings`: the faces carry load), then
/// bands along the flanks, both about `ring_step` apart \[m\], pushed onto
/// `circles` (empty before).
pub(super) fn surface_circles(
    circles: &mut ArrayVec<Circle, MAX_CIRCLES>,
    disc: &PosedDisc,
    n: usize,
    z_top: f64,
    ring_step: f64,
    rings: bool,
) {
    let h = disc.half_width;
    for k in 0..n {
        let y = slice_y(h, n, k);
        circles.push(Circle {
            y,
            radius: disc.rho(y),
            width: 2.0 * h / n as f64,
            face: 0.0,
            flank: false,
            sub: false,
        });
    }
    for side in [1.0f64, -1.0] {
        let Some((r_lo, r_hi)) = face_below(disc, side, z_top).filter(|_| rings) else {
            continue;
        };
        for (radius, width) in face_rings(r_lo, r_hi, ring_step) {
            circles.push(Circle {
                y: side * h,
                radius,
                width,
                face: side,
                flank: false,
                sub: false,
            });
        }
    }
    for side in [1.0f64, -1.0] {
        if let Some((s_lo, s_hi)) = flank_below(disc, side, z_top) {
            let (sn, _) = disc.flank_normal();
            let nb = (((s_hi - s_lo) / ring_step).ceil() as usize).clamp(2, MAX_FLANK_BANDS);
            let ds = (s_hi - s_lo) / nb as f64;
            for j in 0..nb {
                let s = s_lo + ds * (j as f64 + 0.5);
                let y = side * (h + s * sn);
                circles.push(Circle {
                    y,
                    radius: disc.rho_full(y),
                    width: ds,
                    face: side,
                    flank: true,
                    sub: false,
                });
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn face_rings_tile_the_band_and_keep_the_outermost_band_s_ring() {
        for (r_lo, r_hi, step) in [
            (0.2067, 0.2141, 0.5e-3),
            (0.2128, 0.2370, 0.5e-3),
            (0.1, 0.1001, 1e-3),
            (0.2, 0.26, 0.1e-3),
        ] {
            let rings: Vec<(f64, f64)> = face_rings(r_lo, r_hi, step).collect();
            let nr = (((r_hi - r_lo) / step).ceil() as usize).clamp(2, MAX_RINGS);
            let dr = (r_hi - r_lo) / nr as f64;
            assert_eq!(rings.len(), 1 + (nr - 1).div_ceil(RING_GRADE));
            // the outermost band's ring, where rings at every band put it
            assert_eq!(rings[0], (r_lo + dr * (nr as f64 - 0.5), dr));
            let total: f64 = rings.iter().map(|r| r.1).sum();
            assert!(
                (total - (r_hi - r_lo)).abs() < 1e-12 * r_hi,
                "{total} {r_lo} {r_hi}"
            );
            // each graded ring inside its own piece, the pieces in order
            let mut lo = r_lo;
            for &(r, w) in &rings[1..] {
                assert!(r > lo && r < lo + w, "{r} not in [{lo}, {}]", lo + w);
                lo += w;
            }
            assert!((lo - (r_hi - dr)).abs() < 1e-12 * r_hi);
        }
    }

    /// A ring's load rises like `sqrt(r - r_lo)` from the band's inner edge
    /// (times a factor that varies slowly): the graded rings sum the square
    /// root exactly, and with the factor closer than a ring a band, with a
    /// third of the rings.
    #[test]
    fn graded_rings_sum_a_square_root_onset_better_than_a_ring_a_band() {
        let (r_lo, r_hi, step): (f64, f64, f64) = (0.2128, 0.2370, 1e-3);
        let len = r_hi - r_lo;
        let exact = |a: f64| {
            // integral of sqrt(x) (1 + a x / len) over [0, len]
            len.powf(1.5) * (2.0 / 3.0 + a * 2.0 / 5.0)
        };
        let f = |r: f64, a: f64| (r - r_lo).sqrt() * (1.0 + a * (r - r_lo) / len);
        // (the factor on the gauge cutters varies by 2-6 % over the band;
        // the error grows with its slope, and past some 20 % a ring a band
        // sums it better)
        for a in [0.0, 0.06, -0.06, 0.15, -0.15] {
            let graded: f64 = face_rings(r_lo, r_hi, step).map(|(r, w)| w * f(r, a)).sum();
            let nr = (len / step).ceil() as usize;
            let dr = len / nr as f64;
            let banded: f64 = (0..nr)
                .map(|j| dr * f(r_lo + dr * (j as f64 + 0.5), a))
                .sum();
            let (eg, eb) = (
                (graded / exact(a) - 1.0).abs(),
                (banded / exact(a) - 1.0).abs(),
            );
            assert!(eg < eb, "a = {a}: graded {eg:e}, a ring a band {eb:e}");
            assert!(eg < 6e-4, "a = {a}: graded {eg:e}");
        }
        // the square root alone: exact on the graded part, the outer band
        // by its midpoint
        let rings: Vec<(f64, f64)> = face_rings(r_lo, r_hi, step).collect();
        let l = len - rings[0].1;
        let graded: f64 = rings[1..].iter().map(|&(r, w)| w * (r - r_lo).sqrt()).sum();
        assert!((graded / (2.0 / 3.0 * l.powf(1.5)) - 1.0).abs() < 1e-12);
    }
}
