//! Every tunable of the model in one struct with a `Default` that is the
//! thesis reference scene (Ericsson 2010, Table 2). The FMI parameters map
//! one-to-one onto these fields (see modelDescription.xml).

pub use super::chip_heightmap::ChipParams;
use super::error::{KerfError, Result};

/// Disc geometry (thesis ch. 6, constant-cross-section disc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CutterParams {
    /// Disc radius `R` \[m\] (`cutter.radius`).
    pub radius: f64,
    /// Tip width `T` \[m\] (`cutter.tipWidth`).
    pub tip_width: f64,
    /// Tip profile radius `r` \[m\] (`cutter.tipRadius`): `R(y) = R - r + sqrt(r^2 - y^2)`.
    pub tip_radius: f64,
    /// Flank angle \[rad\] (`cutter.flankAngle`): the real CCS ring section.
    /// Past the tip's edges (`y = +-T/2`) the section widens along straight
    /// flanks that make this angle with the disc's mid-plane, down to the hub
    /// width; 0 (the default, the thesis) is the flat side faces at `+-T/2`.
    pub flank_angle: f64,
    /// Hub width `W` \[m\] (`cutter.hubWidth`): where the flanks end in flat
    /// faces at `y = +-W/2` (only with `flank_angle > 0`).
    pub hub_width: f64,
}

/// Which base-pressure law gives `P'` (`csm.variant`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CsmVariant {
    /// 1: thesis eq. 15, `P' = C cbrt(ucs^2 bts S / sqrt(R T))`.
    Thesis = 1,
    /// 2: Rostami (1997) as usually cited, `P' = C cbrt(ucs^2 bts S / (phi sqrt(R T)))`.
    Rostami1997 = 2,
    /// 3: Ozdemir & Rostami (1993) eq. 2, `P'1 = -32628 + 521 sqrt(ucs)` (psi, imperial).
    Ozdemir1 = 3,
    /// 4: Ozdemir & Rostami (1993) eq. 3 (seven-term linear regression, imperial).
    Ozdemir2 = 4,
    /// 5: Ozdemir & Rostami (1993) eq. 4 (eight-term regression, imperial).
    Ozdemir3 = 5,
}

impl CsmVariant {
    pub fn from_index(i: i32) -> Option<Self> {
        Some(match i {
            1 => Self::Thesis,
            2 => Self::Rostami1997,
            3 => Self::Ozdemir1,
            4 => Self::Ozdemir2,
            5 => Self::Ozdemir3,
            _ => return None,
        })
    }
}

/// Rock strength and the CSM force law (thesis ch. 3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CsmParams {
    /// Uniaxial compressive strength \[Pa\] (`rock.ucs`).
    pub ucs: f64,
    /// Brazilian tensile strength \[Pa\] (`rock.bts`).
    pub bts: f64,
    /// CSM constant `C` \[1\] (`csm.C`).
    pub c: f64,
    /// Spacing between cuts `S` \[m\] (`csm.spacing`).
    pub spacing: f64,
    /// Pressure-distribution exponent `psi` \[1\] (`csm.psi`).
    pub psi: f64,
    /// Base-pressure law (`csm.variant`).
    pub variant: CsmVariant,
}

/// Sliding friction between rim and rock (thesis ch. 7.6 and App. A).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrictionParams {
    /// Sliding friction coefficient (`friction.mu`).
    pub mu: f64,
    /// Slip speed at which `mu` is reached (`friction.vs`) \[m/s\].
    pub vs: f64,
}

/// The height map (thesis ch. 5) and its deformation (ch. 8, App. B).
#[derive(Debug, Clone, PartialEq)]
pub struct RockParams {
    pub x_min: f64,
    pub x_max: f64,
    pub y_min: f64,
    pub y_max: f64,
    /// Nodes along x (`rock.nx`), at least 2.
    pub nx: usize,
    /// Nodes along y (`rock.ny`), at least 2.
    pub ny: usize,
    /// Height of the initial flat face \[m\] (`rock.z0`).
    pub z0: f64,
    /// Surface file to start from instead of the flat face ("" = flat).
    pub initial_surface: String,
    /// Where `fmi2Terminate` writes the surface ("" = nowhere).
    pub final_surface: String,
    /// Share of the penetration made permanent, in (0, 1] (`rock.plasticFraction`).
    pub plastic_fraction: f64,
}

/// How the direction of the cutting force is found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DirectionRule {
    /// 1 (default): kerf's rule. In the rim plane the resultant lies at
    /// `beta = phi / (2 + psi)` from the lowest contact point towards the
    /// leading edge of the contact arc; across the tip it leans by the
    /// load-weighted mean normal of the tip profile and side faces.
    Kerf = 1,
    /// 2: the thesis's rule (eqs 41-43): mean normal of the penetrated rock
    /// triangles, force applied where the ray to the penetrated-plane centre
    /// meets the rim.
    Thesis = 2,
}

/// Numerical settings: each trades speed against accuracy; `docs/speed-vs-error.md`
/// measures the trade.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Numerics {
    /// Slices across the tip profile used to find the contact (odd, >= 3).
    pub tip_slices: usize,
    /// Step of the contact-arc walk along the rim, in mesh cells of arc
    /// length (the arc ends are then refined by regula falsi to 1e-9 rad).
    /// Contact features narrower than this can be stepped over.
    pub arc_step_cells: f64,
    /// Spacing of the circles sampled across a side face of a tilted disc
    /// (its rings) and along each flank (its bands), in mesh cells: the
    /// face's band that can reach the rock is cut into bands this wide,
    /// at least 2 and at most `MAX_RINGS` (24) a face; the outermost keeps
    /// a ring at its middle and the rest get one ring for every
    /// `RING_GRADE` (3) bands, graded towards the face's inner edge
    /// (`face_rings`). The flanks' bands are each sampled at their middle.
    /// The side face is what loads a gauge cutter's bearing sideways, and
    /// its rings are most of a gauge cutter's contact (`examples/ring_steps`
    /// measures the trade).
    pub ring_step_cells: f64,
    /// Thickness of the elastic layer of the rock \[m\]: the rock yields once
    /// the rim is this far inside it; after a cut the rock keeps touching the
    /// rim through this layer, which is what lets a cutter at rest carry load.
    pub elastic_depth: f64,
    /// Below this penetration \[m\] the CSM law, whose slope `dF/dp` is
    /// infinite at `p = 0`, is replaced by a quadratic with the same value and
    /// slope at `p_reg`.
    pub p_reg: f64,
    /// Largest travel \[m\] of any rim point between two cuts of a swept
    /// (Co-Simulation) step; longer steps are cut in sub-steps this long.
    /// A sub-step `s` leaves scallops `(s/2)^2 / (2R)` high (0.58 um at
    /// 1 mm), inside the elastic layer.
    pub sweep_step: f64,
    /// Direction rule of the cutting force.
    pub direction: DirectionRule,
    /// Cut the whole disc at every cut, its front arc too (`false`, the
    /// default: a rolling disc's cut reaches only half a sweep step ahead
    /// of its lowest point, since its next cuts take the front arc again;
    /// see `cut_cutter_heightmap::Front`). Not an FMU parameter: a switch
    /// for tests and reports that compare the two.
    pub cut_ahead: bool,
    /// Walk the whole window behind the disc at every cut (`false`, the
    /// default: a cut leaves out the box behind a rolling disc where the
    /// disc's last cut already lies below it, see
    /// `cut_cutter_heightmap::Back`; the face is the same bit for bit).
    /// Not an FMU parameter: a switch for the tests that hold the two equal.
    pub cut_behind: bool,
    /// Read the rock at every sample of the contact's start search
    /// (`false`, the default: a run of samples whose rim is above every node
    /// of the cells under it is passed over, see
    /// `contact_cutter_heightmap::RimCircle::out_of_rock`; the contact is
    /// the same bit for bit). Not an FMU parameter: a switch for the tests
    /// that hold the two equal.
    pub search_every_sample: bool,
    /// Walk both sides of every circle of the disc's surface (`false`, the
    /// default: on a disc moving faster than the law's rest speed, a side
    /// that drives into the rock over no more than a sliver of its reach
    /// carries no load and is not walked (a face circle's, once the rim
    /// touches), and the edge search across the tip asks a rolling disc's
    /// circles about the side all its slices drive on alone; see
    /// `contact_cutter_heightmap::contact`). Not an FMU parameter: a switch
    /// for the tests that hold the two equal.
    pub walk_every_side: bool,
}

#[derive(Debug, Clone, PartialEq, Default)]
pub struct Params {
    pub cutter: CutterParams,
    pub csm: CsmParams,
    pub friction: FrictionParams,
    pub rock: RockParams,
    pub numerics: Numerics,
    pub chipping: ChipParams,
}

impl Default for CutterParams {
    fn default() -> Self {
        Self {
            radius: 0.2159,
            tip_width: 0.013,
            tip_radius: 0.0127,
            flank_angle: 0.0,
            hub_width: HUB_WIDTH_DEFAULT,
        }
    }
}

impl Default for CsmParams {
    fn default() -> Self {
        Self {
            ucs: 158e6,
            bts: 6.78e6,
            c: 2.12,
            spacing: 0.051,
            psi: 0.0,
            variant: CsmVariant::Thesis,
        }
    }
}

impl Default for FrictionParams {
    /// `mu = 0.3`: dry steel on hard rock lies at 0.3-0.5 and wetted faces at
    /// 0.2-0.3; 0.3 is the middle of what TBM face conditions give. It only
    /// acts on slip (skid, side slide), never on pure rolling.
    /// `vs = 0.01 m/s`: one percent of the cutting speed, small enough that a
    /// skidding cutter feels full friction, large enough to keep the STEP smooth
    /// for an implicit solver.
    fn default() -> Self {
        Self { mu: 0.3, vs: 0.01 }
    }
}

impl Default for RockParams {
    /// A 1.5 m x 0.2 m face at 1 mm cells that holds the 1 m reference cut
    /// from x = 0 to x = 1 m along y = 0.
    fn default() -> Self {
        Self {
            x_min: -0.25,
            x_max: 1.25,
            y_min: -0.1,
            y_max: 0.1,
            nx: 1501,
            ny: 201,
            z0: 0.0,
            initial_surface: String::new(),
            final_surface: String::new(),
            plastic_fraction: 1.0,
        }
    }
}

impl Default for Numerics {
    fn default() -> Self {
        Self {
            tip_slices: 9,
            arc_step_cells: 4.0,
            ring_step_cells: 0.5,
            elastic_depth: 2.0e-6,
            p_reg: 5.0e-5,
            sweep_step: 1.0e-3,
            direction: DirectionRule::Kerf,
            cut_ahead: false,
            cut_behind: false,
            search_every_sample: false,
            walk_every_side: false,
        }
    }
}

/// Default hub width \[m\]: the ring width of a 17 in CCS disc at its
/// hub (docs/flanks.md says where the number comes from). It only acts once
/// `cutter.flankAngle > 0`.
pub const HUB_WIDTH_DEFAULT: f64 = 0.0762;

impl CutterParams {
    /// Does the section have flanks (`flank_angle > 0` and `W > T`)?
    pub fn has_flanks(&self) -> bool {
        self.flank_angle > 0.0 && self.hub_width > self.tip_width
    }

    /// Largest flank angle that keeps the solid convex: the flank must be
    /// steeper (nearer the mid-plane) than the tip profile at its edge,
    /// whose normal leans `asin(T / 2r)` off the radius, so the angle may not
    /// exceed `pi/2 - asin(T / 2r)` (59.2 deg for the thesis's disc).
    pub fn max_flank_angle(&self) -> f64 {
        std::f64::consts::FRAC_PI_2
            - (0.5 * self.tip_width / self.tip_radius)
                .clamp(-1.0, 1.0)
                .asin()
    }

    /// The rules of the flanked section (beyond the bounds): with flanks on,
    /// the hub is at least as wide as the tip, the flank no shallower than
    /// the tip's edge (a shallower one would make the section non-convex:
    /// that case is rejected rather than silently hulled), and the flank
    /// reaches the hub width before the axle.
    pub fn check_flanks(&self) -> Result<()> {
        if self.flank_angle == 0.0 {
            return Ok(());
        }
        if self.hub_width < self.tip_width {
            return Err(KerfError::BadParameter {
                name: "cutter.hubWidth",
                value: self.hub_width,
                why: "must be at least cutter.tipWidth when cutter.flankAngle > 0".into(),
            });
        }
        let max = self.max_flank_angle();
        if self.flank_angle > max {
            return Err(KerfError::BadParameter {
                name: "cutter.flankAngle",
                value: self.flank_angle,
                why: format!(
                    "must not exceed pi/2 - asin(tipWidth / (2 tipRadius)) = {max} rad: a flank shallower than the tip profile's edge makes the disc's section non-convex"
                )
                .into(),
            });
        }
        let h = 0.5 * self.tip_width;
        let r = self.tip_radius;
        let rho_edge = self.radius - r + (r * r - h * h).max(0.0).sqrt();
        let drop = (0.5 * self.hub_width - h) / self.flank_angle.tan();
        if drop >= rho_edge {
            return Err(KerfError::BadParameter {
                name: "cutter.hubWidth",
                value: self.hub_width,
                why: format!(
                    "the flanks at cutter.flankAngle = {} rad would reach the axle before widening to the hub: (hubWidth - tipWidth)/2 / tan(flankAngle) = {drop} m must stay below the tip's edge radius {rho_edge} m",
                    self.flank_angle
                )
                .into(),
            });
        }
        Ok(())
    }
}

#[path = "bounds.rs"]
mod bounds_table;
pub use bounds_table::*;

/// The allowed range `[min, max]` of a numeric parameter (by its FMI name).
pub fn bounds(name: &str) -> Option<(f64, f64)> {
    PARAMETER_BOUNDS
        .iter()
        .find(|(n, _, _)| *n == name)
        .map(|&(_, lo, hi)| (lo, hi))
}

/// `value` within the bounds of `name` (NaN never is).
pub fn check_bounds(name: &'static str, value: f64) -> Result<()> {
    let (min, max) = bounds(name).expect("a parameter without a row in bounds.rs");
    if value >= min && value <= max {
        Ok(())
    } else {
        Err(KerfError::BadParameter {
            name,
            value,
            why: format!("outside its allowed range [{min:e}, {max:e}]").into(),
        })
    }
}

fn rule(name: &'static str, value: f64, why: String) -> KerfError {
    KerfError::BadParameter {
        name,
        value,
        why: why.into(),
    }
}

impl Params {
    /// Checks every parameter against its bounds ([`PARAMETER_BOUNDS`]) and
    /// the rules between parameters; the first violation is the error.
    pub fn validate(&self) -> Result<()> {
        let c = &self.cutter;
        let s = &self.csm;
        let f = &self.friction;
        let r = &self.rock;
        let n = &self.numerics;
        let ch = &self.chipping;
        for (name, v) in [
            ("cutter.radius", c.radius),
            ("cutter.tipWidth", c.tip_width),
            ("cutter.tipRadius", c.tip_radius),
            ("cutter.flankAngle", c.flank_angle),
            ("cutter.hubWidth", c.hub_width),
            ("rock.ucs", s.ucs),
            ("rock.bts", s.bts),
            ("csm.C", s.c),
            ("csm.spacing", s.spacing),
            ("csm.psi", s.psi),
            ("friction.mu", f.mu),
            ("friction.vs", f.vs),
            ("rock.xMin", r.x_min),
            ("rock.xMax", r.x_max),
            ("rock.yMin", r.y_min),
            ("rock.yMax", r.y_max),
            ("rock.nx", r.nx as f64),
            ("rock.ny", r.ny as f64),
            ("rock.z0", r.z0),
            ("rock.plasticFraction", r.plastic_fraction),
            ("numerics.tipSlices", n.tip_slices as f64),
            ("numerics.arcStepCells", n.arc_step_cells),
            ("numerics.ringStepCells", n.ring_step_cells),
            ("numerics.elasticDepth", n.elastic_depth),
            ("numerics.pReg", n.p_reg),
            ("numerics.sweepStep", n.sweep_step),
            ("chipping.kappa", ch.kappa),
            ("chipping.length", ch.length),
            ("chipping.lengthSpread", ch.length_spread),
            ("chipping.pressureScale", ch.pressure_scale),
        ] {
            check_bounds(name, v)?;
        }
        if c.tip_width > 2.0 * c.tip_radius {
            return Err(KerfError::BadParameter {
                name: "cutter.tipWidth",
                value: c.tip_width,
                why: "must not exceed 2 * cutter.tipRadius (the tip profile is a circle of that radius)".into(),
            });
        }
        if c.tip_radius >= c.radius {
            return Err(KerfError::BadParameter {
                name: "cutter.tipRadius",
                value: c.tip_radius,
                why: "must be smaller than cutter.radius".into(),
            });
        }
        c.check_flanks()?;
        if n.tip_slices.is_multiple_of(2) {
            return Err(KerfError::BadParameter {
                name: "numerics.tipSlices",
                value: n.tip_slices as f64,
                why: "must be odd, between 3 and 101".into(),
            });
        }
        let nodes = (r.nx as f64) * (r.ny as f64);
        if nodes > MAX_NODES {
            return Err(rule(
                "rock.nx",
                r.nx as f64,
                format!(
                    "rock.nx * rock.ny = {nodes:e} nodes exceeds the budget of {MAX_NODES:e}: coarser cells or a smaller face"
                ),
            ));
        }
        let dx = (r.x_max - r.x_min) / (r.nx - 1) as f64;
        let dy = (r.y_max - r.y_min) / (r.ny - 1) as f64;
        for (name, lo, hi, cell, count) in [
            ("rock.xMax", r.x_min, r.x_max, dx, "rock.nx"),
            ("rock.yMax", r.y_min, r.y_max, dy, "rock.ny"),
        ] {
            if hi <= lo {
                return Err(rule(name, hi, format!("must exceed the lower edge {lo}")));
            }
            if cell < MIN_CELL {
                return Err(rule(
                    name,
                    hi,
                    format!(
                        "the cells are {cell:e} m along this axis, under the smallest {MIN_CELL:e} m: fewer nodes ({count}) or a longer face"
                    ),
                ));
            }
        }
        let cell = dx.min(dy);
        let disc_nodes = ((2.0 * c.radius / dx + 3.0).min(r.nx as f64))
            * ((2.0 * c.radius / dy + 3.0).min(r.ny as f64));
        if disc_nodes > MAX_DISC_NODES {
            return Err(rule(
                "cutter.radius",
                c.radius,
                format!(
                    "the disc covers {disc_nodes:e} height-map nodes, more than the {MAX_DISC_NODES:e} one cut may scan: coarser cells or a smaller disc"
                ),
            ));
        }
        let arc_steps =
            n.tip_slices as f64 * std::f64::consts::PI * c.radius / (n.arc_step_cells * cell);
        if arc_steps > MAX_ARC_STEPS {
            return Err(rule(
                "numerics.arcStepCells",
                n.arc_step_cells,
                format!(
                    "one evaluation would walk {arc_steps:e} arc steps (numerics.tipSlices * pi * cutter.radius / (arcStepCells * cell)), more than {MAX_ARC_STEPS:e}: a larger arc step, fewer tip slices or coarser cells"
                ),
            ));
        }
        if n.sweep_step < MIN_SWEEP_STEP_CELLS * cell {
            return Err(rule(
                "numerics.sweepStep",
                n.sweep_step,
                format!(
                    "must be at least {MIN_SWEEP_STEP_CELLS} cells = {:e} m (cells are {cell:e} m)",
                    MIN_SWEEP_STEP_CELLS * cell
                ),
            ));
        }
        Ok(())
    }
}
