//! Rock chips breaking out of the height map between grooves (thesis 2.3.4,
//! 2.3.5, 2.4, 10.3 and 12, after Gertsch et al. 2002).
//!
//! A disc crushes the rock under its tip; lateral cracks run sideways from
//! the crushed zone. Where a crack reaches a free surface (the wall of a
//! neighbouring groove, or the edge of the rock) within its reach, the rock
//! between breaks out as a chip. kerf models that as a change of the height
//! map, like a cut, so the force follows from the contact law on the changed
//! rock: after a chip there is less rock ahead of the disc; past the chip it
//! meets intact rock again, and the force saw-tooths.
//!
//! **Criterion** (a stated model, not a measured law): a lateral crack reaches
//! `kappa * p` sideways from the edge of the groove, `p` the depth of the
//! groove below the ridge beside it. The ridge to a neighbouring groove breaks
//! when its width at mid-depth is at most `kappa * p`; with spacing `S` and
//! tip width `T` that is `S - T <~ kappa * p`, so `kappa` sets the critical
//! `S / p`. `kappa` of 14-17 puts the specific-energy optimum of Colorado Red
//! Granite at `S / p` of 17-20, where published LCM work puts it.
//!
//! **When.** Chips break out in front of the disc, one after another along
//! its path, one chip length apart. The lengths are scattered about their mean
//! by a counter-based generator keyed by the seed and the chip's index, so a
//! run is bit-identical for a seed and the chips do not depend on how the host
//! steps: a chip breaks out where the travel of the crushed zone crosses the
//! next chip boundary, at the point on the path interpolated there, not at a
//! sub-step's pose. The number of chips per metre does not depend on speed.
//!
//! **Shape.** Over the chip's length, from the crushed zone under the disc's
//! lowest point, the chip surface runs straight across to the bottom of the
//! neighbouring groove (or level to the free edge). Nodes above it drop to it;
//! nodes below stay. Its plan is a rectangle `length` long, from the groove's
//! centre line to the neighbouring groove's bottom.

use nalgebra::Vector3;

use super::cut_cutter_heightmap::CUT_TOLERANCE;
use super::heightmap::{HeightMap, NO_ROCK};

/// The chip model's parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChipParams {
    /// Chips break out (`false`: exactly the rock model without chips).
    pub enabled: bool,
    /// Seed of the chip lengths' scatter.
    pub seed: i32,
    /// Lateral crack reach over groove depth \[1\].
    pub kappa: f64,
    /// Mean chip length along the cut \[m\].
    pub length: f64,
    /// Half-width of the uniform scatter of the chip length, as a share of
    /// the mean \[1\], in `[0, 1)`.
    pub length_spread: f64,
    /// Factor on the CSM pressure level while the pass is relieved \[1\]
    /// (`chipping.pressureScale`). The CSM's constants were fitted to LCM
    /// tests in which chips broke out, so its closed form holds the chips'
    /// effect on the mean force; kerf's chips remove that rock from the
    /// height map as well, and at the closed form's pressure a relieved pass
    /// carries only 0.67 of the closed form's mean. The default,
    /// [`PRESSURE_SCALE_DEFAULT`], brings the mean back. It scales the
    /// pressure (the law's `P'`), not the force: the saw-tooth still comes
    /// from the rock's shape. It applies only while the disc's pass breaks
    /// out chips ([`ChipState::relieved`]): a pass that breaks out none has
    /// the rock without chips, and it keeps the closed form's pressure.
    /// Without chips it does nothing (see
    /// [`ChipParams::pressure_scale_in_use`]).
    pub pressure_scale: f64,
}

/// Default of `chipping.pressureScale`: the factor that makes the mean
/// normal force of thesis Table 3's relieved LCM pass with chips (S = 51 mm,
/// p = 3.8 mm, the last of four passes) equal the CSM closed form at that
/// depth, 60.8 kN. Measured over 2 m of a 3 m pass (about 40 chips a side),
/// seeds 1-4: at factor 1 the mean is 40.5 kN (0.666), so 1.502, rounded
/// (`cargo test --release --test core_chipping calibrated -- --nocapture`
/// prints the measurement). Refitted on 2026-11-26 when cuts stopped
/// carving the disc's front arc (`cut_cutter_heightmap::Front`): with whole
/// cuts the mean was 39.0 kN (0.642) and the factor 1.56.
pub const PRESSURE_SCALE_DEFAULT: f64 = 1.50;

impl Default for ChipParams {
    fn default() -> Self {
        Self {
            enabled: false,
            seed: 1,
            kappa: 15.0,
            length: 0.05,
            length_spread: 0.5,
            pressure_scale: PRESSURE_SCALE_DEFAULT,
        }
    }
}

impl ChipParams {
    /// The factor the disc's force law puts on the CSM pressure: `pressure_scale`
    /// with chipping on, exactly 1 with it off (a model without chips does
    /// not depend on the chip parameters).
    pub fn pressure_scale_in_use(&self) -> f64 {
        if self.enabled {
            self.pressure_scale
        } else {
            1.0
        }
    }

    /// Length of chip `k` (0-based) of the seeded sequence \[m\].
    pub fn chip_length(&self, k: u64) -> f64 {
        let u = unit_hash(self.seed as u32 as u64, k);
        self.length * (1.0 + self.length_spread * (2.0 * u - 1.0))
    }
}

/// SplitMix64 of `(seed, k)` as a number in `[0, 1)`: counter-based, so
/// chip `k`'s length needs no generator state.
fn unit_hash(seed: u64, k: u64) -> f64 {
    let mut z = seed
        .wrapping_mul(0x9E37_79B9_7F4A_7C15)
        .wrapping_add(k.wrapping_add(1).wrapping_mul(0xBF58_476D_1CE4_E5B9));
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64
}

/// What the chip process carries from one cut to the next (part of the
/// discrete state).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChipState {
    /// Travel of the crushed zone (the disc's lowest point, in plan) while
    /// cutting \[m\].
    pub travel: f64,
    /// Index of the next chip in the seeded sequence.
    pub index: u64,
    /// Travel at which it breaks out \[m\]: the first after
    /// `chip_length(0)` of travel, chip `k` then `chip_length(k + 1)` long,
    /// reaching to the next boundary.
    pub next: f64,
    /// The lowest point at the last cut, while the disc is cutting.
    pub last_low: Option<[f64; 3]>,
    /// Chips broken out so far (one per side of a groove).
    pub count: u64,
    /// Rock removed as chips \[m3\].
    pub volume: f64,
    /// Chip boundaries the disc has crossed while cutting since the last one
    /// at which a chip broke out on this pass ([`NO_CHIP_YET`] before the
    /// pass's first chip; a jump to a new pass starts over). See
    /// [`ChipState::relieved`].
    pub quiet: u32,
}

/// [`ChipState::quiet`] of a pass that has broken out no chip yet.
pub const NO_CHIP_YET: u32 = u32::MAX;

/// Chip boundaries without a chip after which a pass counts as unrelieved
/// again ([`ChipState::relieved`]): 4 chip lengths, 0.2 m at the defaults.
pub const RELIEF_MEMORY: u32 = 4;

impl Default for ChipState {
    fn default() -> Self {
        Self {
            travel: 0.0,
            index: 0,
            next: 0.0,
            last_low: None,
            count: 0,
            volume: 0.0,
            quiet: NO_CHIP_YET,
        }
    }
}

impl ChipState {
    /// Whether the pass is relieved, for `chipping.pressureScale`: a chip
    /// broke out at one of its last [`RELIEF_MEMORY`] chip boundaries. The
    /// factor makes up for the rock kerf's chips take from ahead of the
    /// disc, which the CSM's constants already hold; a pass that breaks out
    /// none (the first pass on a fresh face, spacings past the critical
    /// one) has the rock without chips and keeps the closed form's
    /// pressure. A steady relieved pass (an LCM series, a cutterhead)
    /// breaks a chip at most boundaries; at some the ridge ahead has gone
    /// already, with an earlier chip, and the pass stays relieved across
    /// them. Before a pass's first chip (a chip length at least) it is not.
    pub fn relieved(&self) -> bool {
        self.quiet < RELIEF_MEMORY
    }

    /// The state before the first cut (all zero with chipping off, so a
    /// model without chips does not depend on the chip parameters).
    pub fn new(p: &ChipParams) -> Self {
        if !p.enabled {
            return Self::default();
        }
        Self {
            next: p.chip_length(0),
            ..Self::default()
        }
    }

    /// Records a pose on the disc's path whose lowest point is `low` (`cut`:
    /// whether the disc removed rock there) and breaks out the chips whose
    /// boundaries the travel since the last pose crossed, where the disc is
    /// cutting. Chip boundaries are places on the path (travel counts in the
    /// air too), so they do not depend on how the path was stepped. A move
    /// longer than `max_step` in plan is a jump, not a path (a host starting
    /// a new pass): it is not travel, and nothing breaks out across it.
    pub fn after_cut(
        &mut self,
        map: &mut HeightMap,
        p: &ChipParams,
        low: Vector3<f64>,
        cut: bool,
        half_width: f64,
        max_step: f64,
    ) -> ChipStats {
        self.after_cut_curved(map, p, low, cut, half_width, max_step, 0.0)
    }

    /// [`ChipState::after_cut`] on a path that curves in plan with
    /// `curvature` (1/m, positive turning left of the travel; a disc on a
    /// cutterhead track of radius `r` turns with `1 / r`): the chips follow
    /// the path's arc instead of its tangent, so successive chips tile a
    /// curved track as they tile a straight one.
    #[allow(clippy::too_many_arguments)]
    pub fn after_cut_curved(
        &mut self,
        map: &mut HeightMap,
        p: &ChipParams,
        low: Vector3<f64>,
        cut: bool,
        half_width: f64,
        max_step: f64,
        curvature: f64,
    ) -> ChipStats {
        // radii over 1 km are straight (the arc's formulas would lose the
        // lateral offset to round-off against 1 / curvature)
        let curvature = if curvature.abs() < 1e-3 {
            0.0
        } else {
            curvature
        };
        let mut stats = ChipStats::default();
        if let Some(prev) = self.last_low {
            let prev = Vector3::from(prev);
            let (dx, dy) = (low.x - prev.x, low.y - prev.y);
            let ds = dx.hypot(dy);
            if ds > max_step {
                // a new pass: relieved once it breaks out its own chips
                self.quiet = NO_CHIP_YET;
            }
            if ds > 0.0 && ds <= max_step {
                let heading = [dx / ds, dy / ds];
                let end = self.travel + ds;
                while self.next <= end {
                    // chip `index` runs from its boundary to the next one, so
                    // the chips of a path tile it without gaps or overlaps
                    let length = p.chip_length(self.index + 1);
                    if cut {
                        let f = (self.next - self.travel) / ds;
                        let b = Breakout {
                            origin: prev + (low - prev) * f,
                            heading,
                            // on an arc the tangent at fraction f of the step
                            // is the chord turned by (f - 1/2) of its angle
                            turn: (f - 0.5) * ds * curvature,
                            half_width,
                            length,
                            kappa: p.kappa,
                            curvature,
                        };
                        let s = break_out(map, &b);
                        stats.count += s.count;
                        stats.volume += s.volume;
                        self.quiet = if s.count > 0 {
                            0
                        } else {
                            self.quiet.saturating_add(1)
                        };
                    }
                    self.index += 1;
                    self.next += length;
                }
                self.travel = end;
            }
        }
        self.last_low = Some(low.into());
        self.count += stats.count;
        self.volume += stats.volume;
        stats
    }
}

/// Chips broken out by one call.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ChipStats {
    pub count: u64,
    pub volume: f64,
}

/// One place where chips may break out: both sides of a groove, over a length
/// ahead of the crushed zone.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Breakout {
    /// The crushed zone: the disc's lowest point, rock frame.
    pub origin: Vector3<f64>,
    /// Direction of travel in plan (unit): on a curved path the chord of
    /// the step the chip broke out in.
    pub heading: [f64; 2],
    /// Angle from `heading` to the path's tangent at `origin` \[rad\] (0 on a
    /// straight path). It only locates the centre of curvature exactly
    /// ([`Breakout::centre`]); the chip's plan is laid out along `heading`.
    pub turn: f64,
    /// Half the groove's width (the tip's) \[m\].
    pub half_width: f64,
    /// Length of the chip along the travel \[m\].
    pub length: f64,
    /// Crack reach over groove depth.
    pub kappa: f64,
    /// Curvature of the path in plan (1/m, positive turning left of the
    /// heading; 0 straight). The chip's plan is then a sector of the
    /// annulus about the centre of curvature, clipped at that centre.
    pub curvature: f64,
}

impl Breakout {
    /// Whether the path is straight (see [`ChipState::after_cut_curved`]).
    fn straight(&self) -> bool {
        self.curvature == 0.0
    }

    /// Plan point at arc length `xi` along the path from the origin and
    /// lateral offset `l` (positive left of the path).
    pub fn plan_point(&self, xi: f64, l: f64) -> (f64, f64) {
        let [hx, hy] = self.heading;
        let k = self.curvature;
        let (u, w) = if k == 0.0 {
            (xi, l)
        } else {
            let (s, c) = (k * xi).sin_cos();
            (s * (1.0 / k - l), 1.0 / k - c * (1.0 / k - l))
        };
        (
            self.origin.x + hx * u - hy * w,
            self.origin.y + hy * u + hx * w,
        )
    }

    /// Inverse of [`Breakout::plan_point`]: `(xi, l)` of the plan point
    /// `(x, y)`; a point past the centre of curvature maps to an arc
    /// length beyond half a turn.
    pub fn path_coords(&self, x: f64, y: f64) -> (f64, f64) {
        let [hx, hy] = self.heading;
        let (dx, dy) = (x - self.origin.x, y - self.origin.y);
        let (u, w) = (dx * hx + dy * hy, -dx * hy + dy * hx);
        if self.straight() {
            return (u, w);
        }
        let k = self.curvature;
        let s = k.signum();
        let a = 1.0 / k - w;
        let rho = u.hypot(a);
        ((s * u).atan2(s * a) / k, 1.0 / k - s * rho)
    }

    /// The path's centre of curvature in plan (`None` on a straight path):
    /// `1 / curvature` to the left of the tangent at the origin. The chip's
    /// sector, laid out along the chord, has its own centre up to half a
    /// step's chord (`(f - 1/2) ds`) from this one.
    pub fn centre(&self) -> Option<(f64, f64)> {
        if self.straight() {
            return None;
        }
        let [hx, hy] = self.heading;
        let (s, c) = self.turn.sin_cos();
        let (tx, ty) = (c * hx - s * hy, s * hx + c * hy);
        let k = self.curvature;
        Some((self.origin.x - ty / k, self.origin.y + tx / k))
    }

    /// Unit lateral direction (left) at arc length `xi`.
    fn lateral(&self, xi: f64) -> (f64, f64) {
        let [hx, hy] = self.heading;
        let (s, c) = (self.curvature * xi).sin_cos();
        // local normal (-sin, cos) turned into the rock frame
        let (u, w) = (-s, c);
        (hx * u - hy * w, hy * u + hx * w)
    }
}

/// Where a lateral crack on one side of the groove meets a free surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Relief {
    /// Lateral distance from the groove's centre line to the chip's far end \[m\].
    pub reach: f64,
    /// Height of the chip surface there.
    pub z_far: f64,
}

/// Finds the free surface a crack from the groove at `b` reaches on side
/// `side` (+1: left of the heading, -1: right), scanning the rock across the
/// path at the middle of the chip's length. `None`: the ridge stands.
pub fn relief(map: &HeightMap, b: &Breakout, side: f64) -> Option<Relief> {
    let g = map.grid();
    let step = 0.5 * g.dx.min(g.dy);
    let (lx, ly) = b.lateral(0.5 * b.length);
    let (lx, ly) = (lx * side, ly * side);
    let (mx, my) = b.plan_point(0.5 * b.length, 0.0);
    let at = |eta: f64| map.height(mx + lx * eta, my + ly * eta);
    let zb = b.origin.z;
    // the ridge's top, met first beside the groove
    let mut z_top = f64::NEG_INFINITY;
    let mut eta = b.half_width;
    loop {
        let z = at(eta);
        if z == NO_ROCK {
            // the rock ends: a free face, chip breaks out level to it
            let depth = z_top - zb;
            return (z_top > zb && eta - b.half_width <= b.kappa * depth).then_some(Relief {
                reach: eta,
                z_far: zb,
            });
        }
        z_top = z_top.max(z);
        let depth = z_top - zb;
        if depth > 0.0 && z < z_top - 0.5 * depth {
            // past mid-depth into a neighbouring groove (or a chip's crater)
            if eta - b.half_width > b.kappa * depth {
                return None;
            }
            // its bottom: the lowest rock on the way across it
            let (mut z_far, mut reach) = (z, eta);
            let mut e = eta;
            while e < eta + 4.0 * b.half_width {
                e += step;
                let z = at(e);
                if z == NO_ROCK || z > z_top - 0.5 * depth {
                    break;
                }
                if z < z_far {
                    z_far = z;
                    reach = e;
                }
            }
            return Some(Relief { reach, z_far });
        }
        if depth > 0.0 && eta - b.half_width > b.kappa * depth {
            return None;
        }
        if eta - b.half_width > 1e3 * b.half_width {
            return None;
        }
        eta += step;
    }
}

/// Breaks out the chips at `b` on both sides of the groove: lowers every node
/// above the chip surface to it. Returns the chips and the volume removed.
pub fn break_out(map: &mut HeightMap, b: &Breakout) -> ChipStats {
    let mut stats = ChipStats::default();
    for side in [1.0, -1.0] {
        let Some(r) = relief(map, b, side) else {
            continue;
        };
        let v = lower_to_chip(map, b, side, &r);
        if v > 0.0 {
            stats.count += 1;
            stats.volume += v;
        }
    }
    stats
}

/// Lowers the nodes of one side's chip; returns the volume removed.
fn lower_to_chip(map: &mut HeightMap, b: &Breakout, side: f64, r: &Relief) -> f64 {
    let g = *map.grid();
    // on a curved path the inner side's chip ends at the centre of curvature
    let inner = b.curvature * side > 0.0;
    let reach = if inner {
        r.reach.min(1.0 / b.curvature.abs())
    } else {
        r.reach
    };
    // ... and when it reaches it, a node within half a cell of the path's
    // centre of curvature is at the apex of the chip's sector, whatever its
    // angle there: it drops with every chip that reaches the centre. Without
    // this, a node on a cutterhead's axis lies in no chip (its angle about
    // the sector's own centre, a fraction of a millimetre away, is always
    // outside the sector) and grows by the advance each revolution, a spike
    // among the craters about it.
    let apex = match b.centre() {
        Some(c) if inner && r.reach >= 1.0 / b.curvature.abs() => Some(c),
        _ => None,
    };
    let apex_r2 = (0.5 * g.dx.min(g.dy)).powi(2);
    // plan outline of the chip, for the node window (its arcs sampled finely
    // enough that their bulge between samples stays under a cell)
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    let parts = if b.straight() { 1 } else { 16 };
    for k in 0..=parts {
        let xi = b.length * k as f64 / parts as f64;
        for eta in [0.0, reach] {
            let (x, y) = b.plan_point(xi, side * eta);
            (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
        }
    }
    let pad = if parts == 1 { 0.0 } else { g.dx.max(g.dy) };
    let Some((i0, i1, j0, j1)) = g.node_range(x0 - pad, x1 + pad, y0 - pad, y1 + pad) else {
        return 0.0;
    };
    let slope = (r.z_far - b.origin.z) / r.reach;
    let mut dropped = 0.0;
    for j in j0..=j1 {
        for i in i0..=i1 {
            let (x, y) = g.node_xy(i, j);
            let (xi, l) = b.path_coords(x, y);
            let eta = side * l;
            let at_apex =
                apex.is_some_and(|(cx, cy)| (x - cx).powi(2) + (y - cy).powi(2) < apex_r2);
            let eta = if at_apex {
                reach
            } else if !(0.0..=b.length).contains(&xi) || !(0.0..=reach).contains(&eta) {
                continue;
            } else {
                eta
            };
            let z_chip = b.origin.z + slope * eta;
            let z = map.node(i, j);
            if z - z_chip > CUT_TOLERANCE {
                map.lower_node(i, j, z_chip);
                dropped += z - z_chip;
            }
        }
    }
    dropped * g.cell_area()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::heightmap::Grid;

    /// A flat face at 0 with straight grooves along x: each `(y, depth,
    /// width)` a rectangular groove.
    fn grooved(grooves: &[(f64, f64, f64)]) -> HeightMap {
        let g = Grid::new(0.0, 0.4, -0.15, 0.15, 401, 301);
        let mut m = HeightMap::flat(g, 0.0);
        for j in 0..g.ny {
            for i in 0..g.nx {
                let (_, y) = g.node_xy(i, j);
                for &(yc, d, w) in grooves {
                    if (y - yc).abs() <= 0.5 * w + 1e-12 {
                        m.set_node(i, j, -d);
                    }
                }
            }
        }
        m
    }

    fn at(y: f64, kappa: f64) -> Breakout {
        Breakout {
            origin: Vector3::new(0.1, y, -0.004),
            heading: [1.0, 0.0],
            turn: 0.0,
            half_width: 0.0065,
            length: 0.05,
            kappa,
            curvature: 0.0,
        }
    }

    #[test]
    fn ridge_to_a_near_groove_breaks_and_the_far_side_stands() {
        // this groove at y = 0, the neighbour 51 mm to the right (-y), 4 mm deep
        let mut m = grooved(&[(0.0, 0.004, 0.013), (-0.051, 0.004, 0.013)]);
        let b = at(0.0, 15.0);
        assert!(
            relief(&m, &b, 1.0).is_none(),
            "left: 140 mm of rock, no relief"
        );
        let r = relief(&m, &b, -1.0).expect("the 38 mm ridge is within 15 x 4 mm");
        assert!((r.reach - 0.051).abs() < 0.0066, "{r:?}");
        assert!((r.z_far + 0.004).abs() < 1e-12);
        let s = break_out(&mut m, &b);
        assert_eq!(s.count, 1);
        // the ridge (38 mm wide, 4 mm high) plus the rest of this groove's
        // half over 50 mm: cells counted at 1 mm, so within a cell row
        let ridge = 0.038 * 0.004 * 0.05;
        assert!(
            (s.volume - ridge).abs() < 0.15 * ridge,
            "{} vs {}",
            s.volume,
            ridge
        );
        // the face between the grooves is now at the groove bottom
        assert!((m.height(0.12, -0.025) + 0.004).abs() < 1e-12);
        // outside the chip's length it stands
        assert_eq!(m.height(0.16, -0.025), 0.0);
        assert_eq!(m.height(0.09, -0.025), 0.0);
    }

    #[test]
    fn a_ridge_wider_than_the_crack_reach_stands() {
        let mut m = grooved(&[(0.0, 0.004, 0.013), (-0.051, 0.004, 0.013)]);
        // 38 mm ridge, 4 mm deep: breaks for kappa >= 9.5, stands below
        assert!(relief(&m, &at(0.0, 9.0), -1.0).is_none());
        assert!(relief(&m, &at(0.0, 10.0), -1.0).is_some());
        let before = m.clone();
        assert_eq!(break_out(&mut m, &at(0.0, 9.0)), ChipStats::default());
        assert_eq!(m, before);
    }

    #[test]
    fn a_pass_is_relieved_from_its_first_chip_until_chips_stop() {
        // the neighbouring groove (51 mm away) ends at x = 0.15 m
        let mut m = grooved(&[(0.0, 0.004, 0.013), (-0.051, 0.004, 0.013)]);
        let g = *m.grid();
        for j in 0..g.ny {
            for i in 0..g.nx {
                let (x, y) = g.node_xy(i, j);
                if x >= 0.15 && y < -0.02 {
                    m.set_node(i, j, 0.0);
                }
            }
        }
        let p = ChipParams {
            enabled: true,
            length_spread: 0.0,
            ..ChipParams::default()
        };
        let mut s = ChipState::new(&p);
        let mut seen = vec![];
        for k in 0..=400 {
            let x = k as f64 * 0.001;
            s.after_cut(&mut m, &p, Vector3::new(x, 0.0, -0.004), true, 0.0065, 0.01);
            seen.push((x, s.relieved()));
        }
        let at = |x: f64| seen.iter().find(|q| q.0 >= x - 1e-9).unwrap().1;
        // not before the first chip (its boundary at 50 mm), then relieved
        assert!(!at(0.049));
        assert!(at(0.051) && at(0.14));
        // past the groove's end no chip breaks: four 50 mm boundaries later
        // (the last chip at 0.1 m, whose rock reached to 0.15 m) unrelieved
        assert!(at(0.299));
        assert!(!at(0.301) && !at(0.4));
        assert!(s.quiet >= RELIEF_MEMORY);
        // a jump to a new pass starts over
        let mut t = s;
        t.quiet = 0;
        t.after_cut(
            &mut m,
            &p,
            Vector3::new(0.1, 0.0, -0.004),
            true,
            0.0065,
            0.01,
        );
        assert_eq!(t.quiet, NO_CHIP_YET);
        assert!(!ChipState::new(&p).relieved() && !ChipState::default().relieved());
    }

    #[test]
    fn the_edge_of_the_rock_is_a_free_surface() {
        // groove 30 mm from the edge y = -0.15
        let mut m = grooved(&[(-0.12, 0.004, 0.013)]);
        let b = at(-0.12, 15.0);
        let r = relief(&m, &b, -1.0).expect("edge 23.5 mm away");
        assert!((r.z_far + 0.004).abs() < 1e-15);
        assert!(break_out(&mut m, &b).count == 1);
        assert!((m.height(0.12, -0.145) + 0.004).abs() < 1e-12);
    }

    #[test]
    fn chip_lengths_are_seeded_scattered_and_bounded() {
        let p = ChipParams::default();
        let l: Vec<f64> = (0..2000).map(|k| p.chip_length(k)).collect();
        let mean = l.iter().sum::<f64>() / l.len() as f64;
        assert!((mean - p.length).abs() < 0.03 * p.length, "{mean}");
        assert!(l
            .iter()
            .all(|&x| x >= 0.5 * p.length && x <= 1.5 * p.length));
        assert_eq!(l[17], p.chip_length(17));
        let q = ChipParams { seed: 2, ..p };
        assert_ne!(l[17], q.chip_length(17));
        let none = ChipParams {
            length_spread: 0.0,
            ..p
        };
        assert_eq!(none.chip_length(5), p.length);
    }

    #[test]
    fn chips_break_where_the_travel_crosses_their_boundary_however_it_is_stepped() {
        let p = ChipParams {
            enabled: true,
            ..ChipParams::default()
        };
        let run = |step: f64| {
            let mut m = grooved(&[(0.0, 0.004, 0.013), (-0.051, 0.004, 0.013)]);
            let mut s = ChipState::new(&p);
            let mut x = 0.0;
            s.after_cut(&mut m, &p, Vector3::new(x, 0.0, -0.004), true, 0.0065, 0.01);
            while x < 0.3 {
                x = (x + step).min(0.3);
                s.after_cut(&mut m, &p, Vector3::new(x, 0.0, -0.004), true, 0.0065, 0.01);
            }
            (s, m)
        };
        let (a, ma) = run(0.001);
        let (b, mb) = run(0.0037);
        assert!(a.count >= 4, "{a:?}");
        assert_eq!(a.count, b.count);
        assert_eq!(a.index, b.index);
        assert!((a.volume - b.volume).abs() < 1e-12 * a.volume);
        assert!((a.travel - 0.3).abs() < 1e-12);
        // same craters, node for node
        for j in 0..301 {
            for i in 0..401 {
                assert!((ma.node(i, j) - mb.node(i, j)).abs() < 1e-12);
            }
        }
        // a jump (new pass) is no travel; a path in the air breaks nothing
        let mut m = grooved(&[(0.0, 0.004, 0.013), (-0.051, 0.004, 0.013)]);
        let mut s = ChipState::new(&p);
        s.after_cut(
            &mut m,
            &p,
            Vector3::new(0.0, 0.0, -0.004),
            true,
            0.0065,
            0.01,
        );
        s.after_cut(
            &mut m,
            &p,
            Vector3::new(0.3, 0.0, -0.004),
            true,
            0.0065,
            0.01,
        );
        assert_eq!((s.count, s.travel), (0, 0.0));
        let mut x = 0.3;
        while x > 0.1 {
            x -= 0.005;
            s.after_cut(
                &mut m,
                &p,
                Vector3::new(x, 0.0, -0.004),
                false,
                0.0065,
                0.01,
            );
        }
        assert!((s.travel - 0.2).abs() < 1e-9 && s.index >= 2, "{s:?}");
        assert_eq!((s.count, s.volume), (0, 0.0));
    }

    #[test]
    fn on_a_curved_path_the_chip_is_a_sector_of_the_annulus() {
        // two circular grooves about (0.2, 0) at radii 0.1 and 0.15 m, 4 mm
        // deep, 13 mm wide; a disc on the inner one travels anticlockwise
        // (turning left, curvature 1 / 0.1)
        let g = Grid::new(0.0, 0.4, -0.2, 0.2, 401, 401);
        let mut m = HeightMap::flat(g, 0.0);
        for j in 0..g.ny {
            for i in 0..g.nx {
                let (x, y) = g.node_xy(i, j);
                let r = (x - 0.2).hypot(y);
                if (r - 0.1).abs() <= 0.0065 || (r - 0.15).abs() <= 0.0065 {
                    m.set_node(i, j, -0.004);
                }
            }
        }
        // at angle 0 on the inner groove: (0.3, 0), heading +y; left is
        // towards the centre (0.2, 0)
        let b = Breakout {
            origin: Vector3::new(0.3, 0.0, -0.004),
            heading: [0.0, 1.0],
            turn: 0.0,
            half_width: 0.0065,
            length: 0.05,
            kappa: 15.0,
            curvature: 10.0,
        };
        // plan_point and path_coords are inverse, on both sides
        for (xi, l) in [(0.0, 0.0), (0.03, 0.02), (0.05, -0.05), (0.01, 0.09)] {
            let (x, y) = b.plan_point(xi, l);
            let (a, c) = b.path_coords(x, y);
            assert!(
                (a - xi).abs() < 1e-12 && (c - l).abs() < 1e-12,
                "{xi} {l}: {a} {c}"
            );
        }
        // along the arc, lateral offset l lies at radius 0.1 - l from the centre
        let (x, y) = b.plan_point(0.04, -0.05);
        assert!(((x - 0.2).hypot(y) - 0.15).abs() < 1e-12);
        // the right side (outwards) reaches the outer groove across the 37 mm
        // ridge; the inner side 187 mm of rock across the centre, which stands
        assert!(relief(&m, &b, 1.0).is_none());
        let r = relief(&m, &b, -1.0).expect("the ridge breaks");
        assert!((r.reach - 0.05).abs() < 0.007, "{r:?}");
        let s = break_out(&mut m, &b);
        assert_eq!(s.count, 1);
        // the ridge is down to the groove bottom over the chip's angle
        // (0.05 m of arc at 0.1 m: 0.5 rad), at mid-ridge radius 0.125 m
        let at = |a: f64, r: f64| m.height(0.2 + r * a.cos(), r * a.sin());
        for a in [0.05, 0.25, 0.45] {
            assert!(
                (at(a, 0.125) + 0.004).abs() < 1e-12,
                "angle {a}: {}",
                at(a, 0.125)
            );
        }
        // and stands past its ends on the arc
        assert_eq!(at(0.55, 0.125), 0.0);
        assert_eq!(at(-0.05, 0.125), 0.0);
        // the volume: the ridge's annular sector, 4 mm high (one cell row)
        let sector = 0.5 * 0.5 * (0.1435f64.powi(2) - 0.1065f64.powi(2)) * 0.004;
        assert!(
            (s.volume - sector).abs() < 0.15 * sector,
            "{} vs {sector}",
            s.volume
        );
    }
    #[test]
    fn a_node_at_the_centre_of_curvature_drops_with_a_chip_that_reaches_it() {
        // a disc on a circular groove of radius 0.05 m about the node
        // (0.2, 0); inside it a crater 15 mm in radius whose floor falls
        // towards -x, and at its centre one node still at the face: the
        // spike a cutterhead's axis grew when no chip's sector held it
        let g = Grid::new(0.0, 0.4, -0.2, 0.2, 401, 401);
        let mut m = HeightMap::flat(g, 0.0);
        let (ic, jc) = (200, 200);
        let (cx, cy) = g.node_xy(ic, jc);
        for j in 0..g.ny {
            for i in 0..g.nx {
                let (x, y) = g.node_xy(i, j);
                let r = (x - cx).hypot(y - cy);
                if (r - 0.05).abs() <= 0.0065 {
                    m.set_node(i, j, -0.004);
                } else if r <= 0.015 && (i, j) != (ic, jc) {
                    m.set_node(i, j, -0.005 - 0.1 * (cx + 0.015 - x));
                }
            }
        }
        // at angle 0 on the groove, travelling anticlockwise (left towards
        // the centre); the step's chord is 0.01 rad behind the tangent, so
        // the sector laid out along it has its centre 0.5 mm off the node
        let turn = 0.01f64;
        let b = Breakout {
            origin: Vector3::new(cx + 0.05, cy, -0.004),
            heading: [turn.sin(), turn.cos()],
            turn,
            half_width: 0.0065,
            length: 0.01,
            kappa: 15.0,
            curvature: 20.0,
        };
        let (ox, oy) = b.centre().unwrap();
        assert!((ox - cx).hypot(oy - cy) < 1e-12, "{ox} {oy}");
        let (xi, l) = b.path_coords(cx, cy);
        assert!(
            !(0.0..=b.length).contains(&xi) && (l - 0.05).abs() < 1e-3,
            "{xi} {l}"
        );
        // the crack crosses the 28.5 mm of rock to the crater, whose lowest
        // point in reach lies past the centre: the chip reaches the centre
        let r = relief(&m, &b, 1.0).expect("the ridge breaks");
        assert!(r.reach > 0.05, "{r:?}");
        let s = break_out(&mut m, &b);
        assert!(s.count >= 1);
        // the node at the centre drops to the chip surface there
        let slope = (r.z_far - b.origin.z) / r.reach;
        let want = b.origin.z + slope * 0.05;
        assert!(
            (m.node(ic, jc) - want).abs() < 1e-12,
            "{} vs {want}",
            m.node(ic, jc)
        );
    }
}
