//! The model: parameters, the rock and the bookkeeping, and the three
//! operations the FMI layer needs (evaluate, commit, advance).

use nalgebra::{UnitQuaternion, Vector3};

use super::contact_cutter_heightmap::Contact;
use super::csm::CsmLaw;
use super::cut_cutter_heightmap::window_nodes;
use super::cutter::PosedDisc;
use super::disc::{
    along_path, commit_checked, path_since, path_travel, sweep_checked, time_groups, Disc,
    DiscState,
};
use super::error::{KerfError, Result};
use super::face::{self, blob, Face};
use super::heightmap::HeightMap;
use super::params::{Params, MAX_NODE_VISITS_PER_CALL, MAX_SUBSTEPS_PER_CALL, TILTED_NODE_WEIGHT};
use super::pose::{advance_pose, Pose, Twist};
use super::rsf;

/// Everything the FMU reports, for one pose.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Outputs {
    /// Force of the rock on the cutter, at the disc centre, rock frame \[N\].
    pub force: [f64; 3],
    /// Moment of the rock on the cutter about the disc centre, rock frame \[N m\].
    pub moment: [f64; 3],
    /// Force along cutter +z \[N\].
    pub normal_force: f64,
    /// Force along cutter -x \[N\].
    pub rolling_force: f64,
    /// Force along cutter +y \[N\].
    pub side_force: f64,
    /// Depth of the contact zone (thesis eq. 54) \[m\].
    pub penetration: f64,
    /// Angle `phi` of the contact arc \[rad\].
    pub contact_angle: f64,
    pub in_contact: bool,
    /// Committed rock removed so far \[m3\].
    pub excavated_volume: f64,
    /// Work of the cutter on the rock so far \[J\].
    pub cutting_energy: f64,
    /// `cutting_energy / excavated_volume`, 0 while nothing was removed \[J/m3\].
    pub specific_energy: f64,
    /// The part of `excavated_volume` that left as chips \[m3\].
    pub chipped_volume: f64,
    /// Chips broken out so far.
    pub chip_count: u64,
}

/// The discrete state: what `fmi2GetFMUstate` captures.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelState {
    /// The rock and its bookkeeping.
    face: Face,
    /// Where the disc last cut and where its chips are.
    disc: DiscState,
}

const MAGIC: &[u8; 8] = b"KERFCORE";
/// 4: tiles carry their cut masks; 5: and the height bound the map keeps;
/// 6: the disc's state carries the chip boundaries since its pass's last
/// chip (`ChipState::quiet`); 7: and the power after its last cut
/// (`DiscState::last_power`).
const VERSION: u32 = 7;

impl ModelState {
    /// Versioned little-endian binary form: magic, version, grid, bookkeeping,
    /// last cut and chips, then the touched tiles only (the layout of
    /// `face::blob`, which the cutterhead's state shares).
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut v = Vec::new();
        v.extend_from_slice(MAGIC);
        v.extend_from_slice(&VERSION.to_le_bytes());
        blob::face_header(&mut v, &self.face);
        blob::disc_state(&mut v, &self.disc);
        blob::tiles(&mut v, &self.face.map);
        v
    }

    /// Inverse of [`ModelState::to_bytes`]; rejects corrupt or foreign blobs
    /// and blobs made for another height-map grid, checking the sizes
    /// against the blob and the grid before anything is built.
    pub fn from_bytes(bytes: &[u8], params: &Params) -> Result<Self> {
        let bad = |why: &str| KerfError::BadState(why.to_string());
        params.validate()?;
        let mut r = blob::Reader::new(bytes);
        if r.take(8)? != MAGIC {
            return Err(bad("not a kerf state (wrong magic)"));
        }
        let version = r.u32()?;
        if version != VERSION {
            return Err(KerfError::BadState(format!(
                "state version {version}, this build reads {VERSION}"
            )));
        }
        let grid = face::grid_of(&params.rock);
        let (excavated_volume, cutting_energy) = r.face_header(&grid, params.rock.z0)?;
        let disc = r.disc_state()?;
        let map = r.tiles(grid, params.rock.z0)?;
        r.end()?;
        Ok(Self {
            face: Face {
                map,
                excavated_volume,
                cutting_energy,
            },
            disc,
        })
    }

    pub fn map(&self) -> &HeightMap {
        &self.face.map
    }

    /// The disc's own state (its last cut, its chips).
    pub fn disc(&self) -> &DiscState {
        &self.disc
    }
}

/// Friction coefficient at slip speed `v >= 0`: Adams' cubic STEP from `-mu`
/// at `-vs` to `mu` at `vs` (thesis App. A), read at `|v|`. It is 0 at zero
/// slip with a finite slope, so `mu(v) v / |v|` stays finite and smooth.
pub fn friction_coefficient(mu: f64, vs: f64, v: f64) -> f64 {
    let s = ((v + vs) / (2.0 * vs)).clamp(0.0, 1.0);
    -mu + 2.0 * mu * s * s * (3.0 - 2.0 * s)
}

/// Friction on the cutter for a slip velocity `slip` of the rim over the
/// rock at a contact whose unit normal is `normal`, under a normal `load`:
/// along the slip's tangential part, against it, `mu(|v_t|)` times the load.
pub fn friction_force(
    load: f64,
    slip: Vector3<f64>,
    normal: Vector3<f64>,
    mu: f64,
    vs: f64,
) -> Vector3<f64> {
    let v_t = slip - normal * normal.dot(&slip);
    let speed = v_t.norm();
    if speed > 0.0 {
        -v_t * (load * friction_coefficient(mu, vs, speed) / speed)
    } else {
        Vector3::zeros()
    }
}

impl Outputs {
    /// The outputs of a force and moment (rock frame) on a cutter whose
    /// frame is `rot`, with the contact's penetration and angle; the
    /// bookkeeping fields are left at zero.
    pub fn from_force(
        force: Vector3<f64>,
        moment: Vector3<f64>,
        rot: &nalgebra::Rotation3<f64>,
        penetration: f64,
        contact_angle: f64,
        in_contact: bool,
    ) -> Self {
        Outputs {
            force: force.into(),
            moment: moment.into(),
            normal_force: force.dot(&(rot * Vector3::z())),
            rolling_force: -force.dot(&(rot * Vector3::x())),
            side_force: force.dot(&(rot * Vector3::y())),
            penetration,
            contact_angle,
            in_contact,
            ..Outputs::default()
        }
    }
}

impl Outputs {
    /// Work of the cutter on the rock over `dt` at these outputs: the rock's
    /// force and moment on the cutter, negated, times the cutter's velocities.
    pub fn work_on_rock(&self, twist: &Twist, dt: f64) -> f64 {
        self.power_into_rock(twist) * dt
    }

    /// Power of the cutter into the rock at these outputs \[W\]: the rock's
    /// force and moment on the cutter, negated, times the cutter's velocities.
    pub fn power_into_rock(&self, twist: &Twist) -> f64 {
        let f = Vector3::from(self.force);
        let m = Vector3::from(self.moment);
        -(f.dot(&twist.velocity) + m.dot(&twist.omega))
    }
}

/// Checks a Co-Simulation step length.
pub(crate) fn check_step(h: f64) -> Result<()> {
    if h.is_finite() && h >= 0.0 {
        Ok(())
    } else {
        Err(KerfError::BadInput {
            name: "communicationStepSize",
            value: h,
            allowed: "finite and >= 0 s".into(),
        })
    }
}

/// Checks the time since the previous commit.
pub(crate) fn check_interval(dt: f64) -> Result<()> {
    if dt.is_finite() && dt >= 0.0 {
        Ok(())
    } else {
        Err(KerfError::BadInput {
            name: "time since last event",
            value: dt,
            allowed: "finite and >= 0 s".into(),
        })
    }
}

/// The part of a disc's rim whose travel the cut sub-steps and Model
/// Exchange's events count: the rim of radius `radius` where it can meet
/// rock. No rock lies above `top` (the face's [`HeightMap::top`]) and no
/// point of the disc's solid lies further than `reach` from its centre. So
/// with the centre `h` above the top, the solid's points in the rock lie
/// within `sqrt(reach^2 - h^2)` of the vertical through the centre, and a
/// turn about the vertical (a disc steering round a tight track, a head
/// turning its discs about the tunnel axis) moves them that far from it,
/// not a radius: the footprint's half-length, some 40 mm for a 17 in disc
/// 3.8 mm deep, against 216 mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RimReach {
    pub radius: f64,
    pub reach: f64,
    pub top: f64,
}

impl RimReach {
    /// A disc of `cutter` over `map`.
    pub fn new(cutter: &super::params::CutterParams, map: &HeightMap) -> Self {
        Self {
            radius: cutter.radius,
            reach: solid_reach(cutter),
            top: map.top(),
        }
    }

    /// The whole rim, as if rock stood everywhere up to the centre.
    pub fn whole(radius: f64) -> Self {
        Self {
            radius,
            reach: radius,
            top: f64::INFINITY,
        }
    }

    /// The largest travel of a rim point in the rock under a turn of the
    /// disc's frame about its centre by the rotation vector `phi` (world
    /// frame), the centre no lower than `z` meanwhile: `|phi| radius`, or
    /// less, `|phi_z| lever + |phi_xy| radius`, where the lever of the turn
    /// about the vertical is the reach of the part in the rock (each point
    /// moves by at most `|phi x r| <= |phi_z| |r_xy| + |phi_xy| |r|`).
    pub fn turn(&self, phi: &Vector3<f64>, z: f64) -> f64 {
        let h = z - self.top;
        let whole = phi.norm() * self.radius;
        if h > 0.0 {
            // (0 once no point of the solid reaches below the top; the
            // count stays continuous in the pose, as the event indicator
            // must)
            let lever = (self.reach * self.reach - h * h).max(0.0).sqrt();
            whole.min(phi.z.abs() * lever + phi.x.hypot(phi.y) * self.radius)
        } else {
            whole
        }
    }
}

/// How far the solid of a disc of `cutter` reaches from its centre, at
/// most: the rim's corner, or the hub's with flanks (an upper bound).
pub(crate) fn solid_reach(cutter: &super::params::CutterParams) -> f64 {
    let half = if cutter.has_flanks() {
        cutter.hub_width
    } else {
        cutter.tip_width
    } * 0.5;
    cutter.radius.hypot(half)
}

/// Travel of a rim point in the rock ([`RimReach`]) along a straight move
/// from `a` to `b`, as the cut sub-steps and Model Exchange's event
/// indicator count it: the move of the disc centre plus the turn between
/// the two orientations ([`RimReach::turn`]), leaving out the turn about
/// the disc's own axle, which moves no point of its surface (a body of
/// revolution): a host that gives the disc the orientation it spins to gets
/// the sub-steps and events of one that does not, as `rim_speed` counts a
/// Co-Simulation step.
pub fn rim_travel(a: &Pose, b: &Pose, reach: &RimReach) -> f64 {
    let q0 = UnitQuaternion::from_rotation_matrix(&a.rotation());
    let q1 = UnitQuaternion::from_rotation_matrix(&b.rotation());
    rim_travel_between((&a.position, &b.position), &q0, &q1, reach)
}

/// [`rim_travel`] for a straight move of the centre from `p0` to `p1`, from
/// the orientation `q0` to `q1`.
pub(crate) fn rim_travel_between(
    (p0, p1): (&Vector3<f64>, &Vector3<f64>),
    q0: &UnitQuaternion<f64>,
    q1: &UnitQuaternion<f64>,
    reach: &RimReach,
) -> f64 {
    // the turn in the disc's frame as a swing after a twist about the axle
    // (body y): q1 = q0 swing twist, and the surface at q1 is the one at
    // q0 swing, whatever the twist
    let qb = (q0.inverse() * q1).into_inner();
    let twist = nalgebra::Quaternion::new(qb.w, 0.0, qb.j, 0.0);
    let swing = if twist.norm() > 1e-12 {
        qb * UnitQuaternion::from_quaternion(twist)
            .inverse()
            .into_inner()
    } else {
        // a half turn about an axis across the axle: all swing
        qb
    };
    // the swing in the rock frame: the surface at q0 turned about the
    // centre by q0 swing q0^-1
    let phi = q0 * UnitQuaternion::from_quaternion(swing).scaled_axis();
    (p1 - p0).norm() + reach.turn(&phi, p0.z.min(p1.z))
}

/// The most nodes one cut of a disc of `cutter` can scan on a map of
/// `grid`: every node a cut scans lies within the solid's reach of its
/// centre (`sqrt(R^2 + (W/2)^2)`).
pub(crate) fn reach_nodes(
    cutter: &super::params::CutterParams,
    grid: &super::heightmap::Grid,
) -> f64 {
    let reach = solid_reach(cutter);
    (2.0 * reach / grid.dx + 2.0) * (2.0 * reach / grid.dy + 2.0)
}

/// The most weighted node visits one cut of a disc of `cutter` can make on
/// a map of `grid`, whatever its pose: [`reach_nodes`], each counted as a
/// tilted disc's.
pub(crate) fn most_visits_per_cut(
    cutter: &super::params::CutterParams,
    grid: &super::heightmap::Grid,
) -> f64 {
    reach_nodes(cutter, grid) * TILTED_NODE_WEIGHT
}

/// What one node of a cut of the posed disc counts in the budget:
/// `TILTED_NODE_WEIGHT` under a tilted axle (its lower boundary takes
/// Newton steps), else 1.
pub(crate) fn visit_weight(disc: &PosedDisc) -> f64 {
    if disc.rot[(2, 1)].abs() > 1e-12 {
        TILTED_NODE_WEIGHT
    } else {
        1.0
    }
}

/// The weighted node visits of a cut at the posed disc: the nodes of its
/// window, each counting [`visit_weight`].
pub(crate) fn cut_visits(map: &HeightMap, disc: &PosedDisc) -> f64 {
    visit_weight(disc) * window_nodes(map, disc) as f64
}

/// Refuses cuts at the posed discs `cuts` (each with [`reach_nodes`] of its
/// cutter) that would make more than `budget` weighted node visits, for a
/// call whose cheaper bound (every node counted as a tilted disc's,
/// [`most_visits_per_cut`]) did not fit: each cut's reach weighed by its
/// pose ([`visit_weight`]) first, and the windows themselves
/// ([`cut_visits`]) only where that does not fit either. (A long commit of
/// an upright disc, e.g. a lap of a 0.1 m track in 333 sub-steps, found
/// every window twice while its nodes counted as a tilted disc's.)
pub(crate) fn check_posed_visits(
    map: &HeightMap,
    cuts: &[(f64, PosedDisc)],
    budget: f64,
    what: &str,
    span: f64,
) -> Result<()> {
    let bound: f64 = cuts.iter().map(|(r, d)| r * visit_weight(d)).sum();
    if bound <= budget {
        return Ok(());
    }
    let visits = cuts.iter().map(|(_, d)| cut_visits(map, d)).sum();
    bound_visits(visits, budget, what, span)
}

/// Refuses a call whose cuts would make `visits` weighted node visits, more
/// than `budget`, naming the split that would fit; `what` and `span` (its
/// duration) name the call.
pub(crate) fn bound_visits(visits: f64, budget: f64, what: &str, span: f64) -> Result<()> {
    if visits <= budget {
        return Ok(());
    }
    let parts = (visits / budget).ceil();
    Err(KerfError::TooMuchWork(format!(
        "{what} ({span} s) would scan {visits:e} height-map nodes, more than the \
         {budget:e} one call may: split it into at least {parts} steps \
         of at most {:e} s",
        span / parts
    )))
}

/// How many sub-steps of at most `step` a path of `travel` takes (at least
/// one). A part in 1e12 of the travel is forgiven: the frame turn of a disc
/// spinning about its own tilted axle comes out as ~1e-17 rad/s instead of
/// zero, and a 1 mm step at 1 m/s then took two cuts instead of one.
pub fn steps_for(travel: f64, step: f64) -> f64 {
    (travel / step * (1.0 - 1e-12)).ceil().max(1.0)
}

/// Refuses a call (`what`, lasting `span`) that would take `n` sub-steps of
/// `sweep_step`, more than [`MAX_SUBSTEPS_PER_CALL`], naming the split that
/// fits; `moving` says what travels that far, built only for the error
/// (formatted at every step, it cost a straight cut some 2 k of its 126 k
/// instructions a step). The one-disc model and the head check with it
/// before anything changes.
pub(crate) fn bound_sub_steps(
    n: f64,
    sweep_step: f64,
    what: &str,
    span: f64,
    moving: impl FnOnce() -> String,
) -> Result<()> {
    if n <= MAX_SUBSTEPS_PER_CALL {
        return Ok(());
    }
    let moving = moving();
    let parts = (n / MAX_SUBSTEPS_PER_CALL).ceil();
    Err(KerfError::TooMuchWork(format!(
        "{what} ({span} s) {moving} {n:e} sub-steps of numerics.sweepStep = {sweep_step} m, \
         more than the {MAX_SUBSTEPS_PER_CALL:e} one call may take: split it into at least \
         {parts} steps of at most {:e} s",
        span / parts
    )))
}

/// Travel of a rim point in the rock ([`RimReach`]) of a disc at `pose`
/// moving with `twist` for `h` seconds, as a Co-Simulation step counts it:
/// the centre's travel plus the turn of the disc's frame (the spin about the
/// axle left out), the centre no lower than where it ends.
pub fn step_travel(pose: &Pose, twist: &Twist, reach: &RimReach, h: f64) -> f64 {
    let z = pose.position.z + (twist.velocity.z * h).min(0.0);
    travel_over(pose, twist, reach, h, z)
}

/// Speed of a rim point in the rock ([`RimReach`]) of a disc at `pose`
/// moving with `twist`: [`step_travel`] per second, for an instant.
pub fn rim_speed(pose: &Pose, twist: &Twist, reach: &RimReach) -> f64 {
    travel_over(pose, twist, reach, 1.0, pose.position.z)
}

/// [`step_travel`] over `h` seconds with the centre no lower than `z`.
fn travel_over(pose: &Pose, twist: &Twist, reach: &RimReach, h: f64, z: f64) -> f64 {
    let w_frame = twist.frame_rate(&(pose.rotation() * Vector3::y()));
    twist.velocity.norm() * h + reach.turn(&(w_frame * h), z)
}

/// Speed of a rim point about the disc centre from the spin about the axle
/// (`|w . axle| radius`): the rim's motion that the pose does not show (a
/// disc spinning in place skids its rim over the rock at this speed).
pub fn rim_spin_speed(pose: &Pose, twist: &Twist, radius: f64) -> f64 {
    let axle = pose.rotation() * Vector3::y();
    twist.omega.dot(&axle).abs() * radius
}

/// One disc on its own face: the cutterhead's [`Disc`] and [`Face`] with
/// the single-disc FMU's rules on top (all-or-nothing changes, bounds on the
/// work of one call, the trapezoidal work between commits).
pub struct Model {
    params: Params,
    /// The disc: geometry, law and the cache of its last evaluation (which
    /// the disc clears when it cuts; the model when the rock changes
    /// otherwise).
    disc: Disc,
    state: ModelState,
}

impl Model {
    /// Validates the parameters and builds the rock (flat, or from
    /// `rock.initial_surface`).
    pub fn new(params: Params) -> Result<Self> {
        params.validate()?;
        let face = Face::new(&params.rock)?;
        let disc = Disc::new(
            params.cutter,
            params.csm,
            params.numerics.p_reg,
            params.chipping.pressure_scale_in_use(),
        );
        let state = ModelState {
            face,
            disc: DiscState::new(&params),
        };
        Ok(Self {
            params,
            disc,
            state,
        })
    }

    pub fn params(&self) -> &Params {
        &self.params
    }

    /// The law the disc cuts with now: with chipping on, its pressure is
    /// scaled while the pass is relieved (`ChipState::relieved`).
    pub fn law(&self) -> &CsmLaw {
        self.disc.law_in(&self.state.disc)
    }

    /// The committed rock.
    pub fn map(&self) -> &HeightMap {
        &self.state.face.map
    }

    /// Warnings about parameters that are legal but questionable (for the
    /// FMI logger): an Ozdemir regression outside its Table 1 range.
    pub fn warnings(&self) -> Vec<String> {
        self.disc
            .law()
            .range_warnings(0.0038)
            .into_iter()
            .filter(|w| !w.contains(": penetration"))
            .collect()
    }

    fn disc(&self, pose: &Pose) -> PosedDisc {
        self.disc.posed(pose)
    }

    /// The contact geometry and cutting force (no friction) at `pose`, for a
    /// disc moving with `twist`.
    pub fn contact(&self, pose: &Pose, twist: &Twist) -> Contact {
        self.disc.contact(
            &self.state.face.map,
            &self.state.disc,
            pose,
            twist,
            &self.params,
        )
    }

    /// The contact law at `pose` by brute force (`contact_bruteforce`): the
    /// oracle the fast query is tested against.
    pub fn contact_brute(
        &self,
        pose: &Pose,
        twist: &Twist,
        res: &super::contact_bruteforce::Resolution,
    ) -> Contact {
        let n = &self.params.numerics;
        super::contact_bruteforce::contact_brute(
            &self.state.face.map,
            &self.disc(pose),
            self.disc.law_in(&self.state.disc),
            n,
            n.elastic_depth,
            twist,
            res,
        )
    }

    /// Contact force for `pose`, against the committed rock. Never changes the rock.
    pub fn evaluate(&self, pose: &Pose, twist: &Twist) -> Result<Outputs> {
        pose.validate()?;
        twist.validate()?;
        let o = self.disc.evaluate(
            &self.state.face.map,
            &self.state.disc,
            pose,
            twist,
            &self.params,
        );
        Ok(self.with_bookkeeping(o))
    }

    /// `o` with the current excavated volume, cutting energy and specific energy.
    fn with_bookkeeping(&self, mut o: Outputs) -> Outputs {
        let (f, c) = (&self.state.face, self.state.disc.chips());
        o.excavated_volume = f.excavated_volume();
        o.cutting_energy = f.cutting_energy();
        o.specific_energy = f.specific_energy();
        o.chipped_volume = c.volume;
        o.chip_count = c.count;
        o
    }

    /// Rim travel ([`rim_travel`]) from the pose of the last cut to `pose`;
    /// `None` before the first cut. Changes nothing.
    pub fn travel_since_cut(&self, pose: &Pose) -> Option<f64> {
        self.state
            .disc
            .last_cut
            .map(|prev| rim_travel(&prev, pose, &self.rim_reach()))
    }

    /// What of the disc's rim the sub-steps and events count, over this
    /// face ([`RimReach`]).
    pub fn rim_reach(&self) -> RimReach {
        RimReach::new(&self.params.cutter, &self.state.face.map)
    }

    /// Would [`Model::commit`] at `pose` change the rock?
    pub fn cuts(&self, pose: &Pose) -> Result<bool> {
        pose.validate()?;
        Ok(self
            .disc
            .would_cut(&self.state.face.map, pose, &self.params))
    }

    /// Rate of work of the cutter on the rock at `pose` \[W\]: `-(F.v + M.w)`.
    /// Non-zero whenever the contact does work (cutting, or friction on a
    /// skid), which is when the energy bookkeeping has something to add.
    pub fn power(&self, pose: &Pose, twist: &Twist) -> Result<f64> {
        let o = self.evaluate(pose, twist)?;
        Ok(o.power_into_rock(twist))
    }

    /// Cuts the rock at `pose` (a Model Exchange event). `dt` is the time since
    /// the previous commit, for the energy bookkeeping. Returns whether the rock changed.
    ///
    /// The cut follows the path from the pose of the previous cut, so a
    /// solver step longer than a cell leaves no uncut rock (the thesis cut
    /// only at the sampled poses). The path is taken as straight (positions
    /// linear, orientation by slerp) and cut in sub-steps of at most
    /// `numerics.sweep_step` of rim travel, when the move is one a step can
    /// make: shorter than the disc radius, or explained by the velocity
    /// inputs. A longer jump (a host that moves the cutter to start a new
    /// pass) is not a path: only the new pose is cut.
    ///
    /// The energy takes the trapezoidal rule between the power after the
    /// previous cut (with the twist of that time, `DiscState::last_power`)
    /// and the power after this one, as [`Model::advance`] does over a step,
    /// so that events at a Co-Simulation host's communication points book
    /// the same work. (The power at the start is the one the outputs gave
    /// then: it is not evaluated again with the new twist.)
    pub fn commit(&mut self, pose: &Pose, twist: &Twist, dt: f64) -> Result<bool> {
        check_interval(dt)?;
        pose.validate()?;
        twist.validate()?;
        // the path, checked whole before anything changes
        let radius = self.params.cutter.radius;
        let path = path_since(self.state.disc.last_cut, (pose, twist), dt, radius);
        let n = match &path {
            Some(p) => {
                let travel = path_travel(p, pose, &self.rim_reach());
                self.sub_steps(travel, "the solver step since the last event", dt)?
            }
            None => 1,
        };
        self.check_visits(
            (1..=n).map(|k| along_path(&path, pose, k, n)),
            "the solver step since the last event",
            dt,
        )?;
        // the commit is a head's commit of its one disc (`disc::commit_paths`)
        let groups = time_groups(&[n]);
        let at = |k: usize, n: usize| Ok(vec![(along_path(&path, pose, k, n), *twist)]);
        self.transaction(|m| {
            let s = &mut m.state;
            commit_checked(
                &mut s.face,
                std::slice::from_mut(&mut m.disc),
                std::slice::from_mut(&mut s.disc),
                &[(*pose, *twist)],
                dt,
                &m.params,
                &groups,
                at,
            )
        })
    }

    /// Runs `f`, a change of the discrete state, all or nothing: on an
    /// error (or a panic, which goes on unwinding) the state and the
    /// evaluation cache are put back as they were. The height map records
    /// the tiles it writes and puts those back, so the cost is what the
    /// change touched, not the face.
    fn transaction<T>(&mut self, f: impl FnOnce(&mut Self) -> Result<T>) -> Result<T> {
        let s = &self.state;
        let saved = (
            s.face.excavated_volume,
            s.face.cutting_energy,
            s.disc.clone(),
        );
        self.state.face.map.begin_undo();
        let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| f(self)));
        if let Ok(Ok(_)) = r {
            self.state.face.map.commit_undo();
        } else {
            self.state.face.map.rollback();
            let s = &mut self.state;
            (s.face.excavated_volume, s.face.cutting_energy, s.disc) = saved;
            // the rock is as it was, the cached evaluation may not be
            self.disc.forget();
        }
        match r {
            Ok(v) => v,
            Err(panic) => std::panic::resume_unwind(panic),
        }
    }

    /// Sub-steps of a path of `travel` of rim travel, within the work one
    /// call may do; `what` and `span` (its duration) name the call's step.
    fn sub_steps(&self, travel: f64, what: &str, span: f64) -> Result<usize> {
        let s = self.params.numerics.sweep_step;
        let n = steps_for(travel, s);
        bound_sub_steps(n, s, what, span, || format!("moves the rim {travel:e} m,"))?;
        Ok(n as usize)
    }

    /// Checks every pose of a path and the nodes its cuts would scan.
    fn check_visits(&self, poses: impl Iterator<Item = Pose>, what: &str, span: f64) -> Result<()> {
        let poses: Vec<Pose> = poses.collect();
        poses.iter().try_for_each(Pose::validate)?;
        let map = &self.state.face.map;
        // when the reach bound already fits, the discs need not be posed nor
        // the windows found twice (they cost a tenth of a cut)
        if most_visits_per_cut(&self.params.cutter, map.grid()) * poses.len() as f64
            <= MAX_NODE_VISITS_PER_CALL
        {
            return Ok(());
        }
        let reach = reach_nodes(&self.params.cutter, map.grid());
        let cuts: Vec<(f64, PosedDisc)> = poses.iter().map(|p| (reach, self.disc(p))).collect();
        check_posed_visits(map, &cuts, MAX_NODE_VISITS_PER_CALL, what, span)
    }

    /// Moves the cutter from `start` along `twist` for `h` seconds, cutting the
    /// rock along the whole path (a Co-Simulation step): the path is cut at
    /// sub-steps no longer than `numerics.sweep_step` of travel of any rim
    /// point, so no uncut rock is left however long `h`. The cutting energy
    /// takes the trapezoidal rule over the step, from the power reported
    /// after the last step (`DiscState::last_power`: a start pose a host
    /// sets a round-off away from the last end is not evaluated again).
    /// Returns the end pose.
    ///
    /// At the start of the run (nothing cut yet) the start pose is cut first,
    /// as Model Exchange's initial event does: the cutter pressed into the
    /// rock at rest has made its imprint there.
    pub fn advance(&mut self, start: &Pose, twist: &Twist, h: f64) -> Result<Pose> {
        check_step(h)?;
        start.validate()?;
        twist.validate()?;
        let travel = step_travel(start, twist, &self.rim_reach(), h);
        let n = self.sub_steps(travel, "the step", h)?;
        let along = |k: usize| advance_pose(start, twist, h * k as f64 / n as f64);
        // the whole path is checked before anything changes
        self.check_visits((1..=n).map(along), "the step", h)?;
        // the step is a head's sweep of its one disc (`disc::sweep`)
        let groups = time_groups(&[n]);
        let path = |t: f64| Ok(vec![(advance_pose(start, twist, t), *twist)]);
        self.transaction(|m| {
            let s = &mut m.state;
            let end = sweep_checked(
                &mut s.face,
                std::slice::from_mut(&mut m.disc),
                std::slice::from_mut(&mut s.disc),
                &m.params,
                &[(*start, *twist)],
                h,
                &groups,
                path,
            )?;
            Ok(end[0].0)
        })
    }

    /// A copy of the discrete state.
    pub fn state(&self) -> ModelState {
        self.state.clone()
    }

    /// Restores a state taken from a model with the same grid.
    pub fn set_state(&mut self, s: &ModelState) -> Result<()> {
        if !s.face.same_grid(&self.state.face) {
            return Err(KerfError::BadState(
                "the state was taken for another rock grid".into(),
            ));
        }
        self.state = s.clone();
        self.disc.forget();
        Ok(())
    }

    /// Writes the committed surface as an `.rsf` file.
    pub fn write_surface(&self, path: &std::path::Path) -> Result<()> {
        rsf::write(path, &self.state.face.map)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rim travel leaves out the disc's turn about its own axle (a spin
    /// moves no point of the surface) and counts every other turn times the
    /// radius: spun by 0.3 rad about the axle of a disc yawed and tilted, it
    /// is the centre's move alone; tilted further by 0.01 rad it gains
    /// 0.01 R, yawed by 0.01 rad the part of that off the axle (the tilted
    /// axle has a vertical part: `2 asin(sin(0.005) sqrt(1 - a_z^2)) R`),
    /// spun as well the same. To 1e-12 m.
    #[test]
    fn rim_travel_leaves_out_the_spin_about_the_axle() {
        let r = 0.2159;
        let whole = RimReach::whole(r);
        let a = Pose::new(0.1, 0.2, 0.3, 0.7, 0.0, -0.4);
        let q0 = UnitQuaternion::from_rotation_matrix(&a.rotation());
        let at = |q: UnitQuaternion<f64>, dx: f64| {
            Pose::from_rotation(
                a.position + Vector3::new(dx, 0.0, 0.0),
                &q.to_rotation_matrix(),
            )
        };
        let spun = q0 * UnitQuaternion::from_scaled_axis(Vector3::y() * 0.3);
        assert!((rim_travel(&a, &at(spun, 1e-3), &whole) - 1e-3).abs() < 1e-12);
        let off_axle = (1.0 - (q0 * Vector3::y()).z.powi(2)).sqrt();
        assert!(off_axle < 0.95);
        let yawed = UnitQuaternion::from_scaled_axis(Vector3::z() * 0.01) * q0;
        let swing = 2.0 * (0.005f64.sin() * off_axle).asin() * r;
        assert!((rim_travel(&a, &at(yawed, 0.0), &whole) - swing).abs() < 1e-12);
        let tilted = q0 * UnitQuaternion::from_scaled_axis(Vector3::x() * 0.01);
        assert!((rim_travel(&a, &at(tilted, 0.0), &whole) - 0.01 * r).abs() < 1e-12);
        // spun and yawed: the yaw alone
        let both = UnitQuaternion::from_scaled_axis(Vector3::z() * 0.01) * spun;
        assert!((rim_travel(&a, &at(both, 0.0), &whole) - swing).abs() < 1e-12);
    }

    /// The travel counts every point of the solid in the rock: brute force
    /// over points of the tip's rim (its mid-plane circle and both edges)
    /// of a disc turned (swing and spin) and moved at random, its centre
    /// from 10 mm below the face's top to above the solid's reach. A point
    /// below the top at either end moves by at most the rim travel (the
    /// edges, `reach` from the centre where the sweep step counts the rim at
    /// `radius`, by that ratio more), and some do by more than the old
    /// whole-rim count's half whenever the disc is in the rock. Counting
    /// the turn about the vertical at the rim's own reach below the top
    /// (the tip's half width left out) fails.
    #[test]
    fn rim_travel_bounds_every_point_of_the_solid_in_the_rock() {
        let mut u = crate::core::uniforms(0x5eed_0117);
        let c = super::super::params::CutterParams::default();
        let (r, w) = (c.radius, c.tip_width * 0.5);
        let reach = solid_reach(&c);
        let mut near = 0usize;
        for case in 0..4000 {
            // every other case an upright disc cutting shallow (its tip's
            // edges lie furthest from the vertical through its centre)
            let upright = case % 2 == 0;
            let a = if upright {
                let q = UnitQuaternion::from_scaled_axis(Vector3::z() * u() * 6.0)
                    * UnitQuaternion::from_scaled_axis(Vector3::y() * u() * 6.0);
                Pose::from_rotation(Vector3::new(u(), u(), u()), &q.to_rotation_matrix())
            } else {
                Pose::new(
                    u() - 0.5,
                    u() - 0.5,
                    u(),
                    (u() - 0.5) * 1.4,
                    (u() - 0.5) * 6.0,
                    (u() - 0.5) * 6.0,
                )
            };
            let q0 = UnitQuaternion::from_rotation_matrix(&a.rotation());
            // a swing about an axis across the axle, mostly about the
            // vertical (a track's turn), and any spin
            let t = u() * std::f64::consts::TAU;
            let across = q0.inverse() * Vector3::z();
            let across = (across - Vector3::y() * across.y).normalize();
            let other = Vector3::y().cross(&across);
            let lean = if upright { 0.0 } else { t.cos() };
            let axis = (across * (1.0 + 4.0 * u()) + other * lean).normalize();
            let swing = UnitQuaternion::from_scaled_axis(axis * (u() - 0.5) * 0.1);
            let spin = UnitQuaternion::from_scaled_axis(Vector3::y() * (u() - 0.5) * 2.0);
            let dp = Vector3::new(u() - 0.5, u() - 0.5, u() - 0.5) * 2e-3;
            let b = Pose::from_rotation(a.position + dp, &(q0 * swing * spin).to_rotation_matrix());
            let h = if upright {
                r - 0.012 * u()
            } else {
                -0.01 + u() * (reach + 0.02)
            };
            let rr = RimReach {
                radius: r,
                reach,
                top: a.position.z.min(b.position.z) - h,
            };
            let travel = rim_travel(&a, &b, &rr);
            let whole = rim_travel(&a, &b, &RimReach::whole(r));
            assert!(travel <= whole + 1e-15, "case {case}");
            let mut most: f64 = 0.0;
            for k in 0..720 {
                let th = k as f64 / 720.0 * std::f64::consts::TAU;
                for (y, scale) in [(0.0, 1.0), (w, reach / r), (-w, reach / r)] {
                    let p = Vector3::new(r * th.cos(), y, r * th.sin());
                    let pa = a.position + q0 * p;
                    // the surface at b is the one at a swung (the spin
                    // moves no point of it)
                    let pb = b.position + q0 * (swing * p);
                    if pa.z.min(pb.z) <= rr.top {
                        let moved = (pb - pa).norm();
                        assert!(
                            moved <= dp.norm() + (travel - dp.norm()) * scale + 1e-12,
                            "case {case}: {moved} > {travel} (h {h}, y {y})"
                        );
                        most = most.max(moved);
                    }
                }
            }
            if most > 0.5 * whole {
                near += 1;
            }
        }
        // (the bound is not empty: it is met closely in many cases)
        assert!(near > 1000, "{near}");
        // continuous in the centre's height, as the event indicator must be:
        // where the solid leaves the rock (the lever's square root falls to
        // 0 there: 7e-9 m over these 2e-12 m) and where the centre meets
        // the top
        let rr = RimReach {
            radius: r,
            reach,
            top: 0.0,
        };
        let phi = Vector3::new(0.003, -0.002, 0.01);
        for z in [reach, 0.0] {
            let (lo, hi) = (rr.turn(&phi, z - 1e-12), rr.turn(&phi, z + 1e-12));
            assert!((lo - hi).abs() < 1e-7, "{z}: {lo} {hi}");
        }
    }

    /// The contact and the cut read the face, not how it came to be: a face
    /// lowered 20 mm node by node (its tiles' height bounds found again,
    /// `HeightMap::refresh_bounds`) bears a disc tilted 30 deg, whose side
    /// face's yield reads the highest rock near it, as the flat face at
    /// that height does, bit for bit, over a pass. (With the bounds left at
    /// the height the nodes were lowered from, the forces differ.)
    #[test]
    fn a_face_lowered_node_by_node_bears_as_a_flat_face_there() {
        use crate::scenes::{face, roll, Straight};
        let mut low = face(1e-3, -0.3, 0.5, -0.06, 0.06);
        low.rock.z0 = -0.02;
        let mut high = low.clone();
        high.rock.z0 = 0.0;
        let track = Straight {
            prm: low.clone(),
            x0: 0.0,
            y: 0.0,
            depth: 0.0238,
            roll: 30f64.to_radians(),
        };
        let mut a = Model::new(low).unwrap();
        let mut b = Model::new(high).unwrap();
        let mut map = b.state.face.map.clone();
        let g = *map.grid();
        for j in 0..g.ny {
            for i in 0..g.nx {
                map.set_node(i, j, -0.02);
            }
        }
        b.state.face = Face::from_map(map);
        let ma = roll(&mut a, &track, 0.15, 1e-3, 0.05, 0.15);
        let mb = roll(&mut b, &track, 0.15, 1e-3, 0.05, 0.15);
        assert!(
            ma.force[0] > 20e3 && ma.force[2].abs() > 1e3,
            "{:?}",
            ma.force
        );
        assert_eq!((ma.force, ma.moment), (mb.force, mb.moment));
        assert_eq!(ma.volume, mb.volume);
    }

    /// The work bound counts the windows exactly once the cheap reach bound
    /// no longer fits: a long step of a tilted disc on fine cells is refused
    /// before it cuts anything, and a short one on the same rock runs.
    #[test]
    fn a_step_that_would_scan_too_many_nodes_is_refused_untouched() {
        let mut p = Params::default();
        (p.rock.x_min, p.rock.x_max, p.rock.y_min, p.rock.y_max) = (-0.3, 0.3, -0.2, 0.2);
        (p.rock.nx, p.rock.ny) = (3001, 2001); // 0.2 mm cells
        let mut m = Model::new(p.clone()).unwrap();
        let roll = 0.5f64;
        let probe = Pose::new(0.0, 0.0, 1.0, 0.0, 0.0, roll);
        let low = PosedDisc::new(&p.cutter, &probe).lowest_point();
        let start = Pose::new(-0.2 - low.x, -low.y, 1.0 - low.z - 0.004, 0.0, 0.0, roll);
        let twist = Twist::new([1.0, 0.0, 0.0], [0.0, 0.0, 0.0]);
        let before = m.state();
        let e = m.advance(&start, &twist, 0.2).unwrap_err().to_string();
        assert!(
            e.contains("height-map nodes") && e.contains("split it into"),
            "{e}"
        );
        assert!(m.state() == before, "a refused step cut the rock");
        m.advance(&start, &twist, 2e-3).unwrap();
        assert!(m.state() != before);
    }
}
