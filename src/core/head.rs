//! A cutterhead: many discs on mounts, cutting one [`Face`] together
//! (interface.md, "Many discs on one rock face").
//!
//! **Head frame**: origin on the tunnel axis in the plane of the face-cutter
//! tips, `z` along the axis out of the rock. **Disc `i`** sits on a mount:
//! its tip at `track (cos a, sin a, 0) + setback z`; with
//! `e_r = (cos a, sin a, 0)`, `e_t = (-sin a, cos a, 0)` and tilt `g`, the
//! cutter frame is `x = e_t`, `z = cos g z - sin g e_r`, `y = z x x`, and the
//! disc centre is the tip plus `R` along cutter `z`.
//!
//! Each disc turns freely on its axle: [`Head::place`] gives it the spin
//! that rolls its tip without slip (along cutter `x`) for the head's motion.
//!
//! Two drives: the head's pose and velocities (rock frame), or every disc's
//! own pose and velocities (`--drive discs`, a multibody host with flexible
//! mounts). Totals are the sums over the discs, moments about the head
//! origin (head drive) or the rock origin (disc drive).

use nalgebra::{Matrix3, Rotation3, Vector3};
use rayon::prelude::*;

use super::disc::{commit_paths, sub_steps, sweep, Disc, DiscState};
use super::error::{KerfError, Result};
use super::face::blob;
use super::face::{grid_of, Face};
use super::heightmap::{HeightMap, TileRect, TILE};
use super::layout::{CutterSpec, Layout};
use super::model::{check_step, Outputs, RimReach};
use super::params::{CutterParams, Params};
use super::pose::{advance_pose, Pose, Twist};
use super::rsf;

/// Where a disc sits on the head (head frame; angles in radians).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mount {
    /// Distance of the tip from the axis \[m\].
    pub track: f64,
    /// Angle of the tip about the axis, from head +x towards +y \[rad\].
    pub angle: f64,
    /// Tilt, tip leaning outwards \[rad\].
    pub tilt: f64,
    /// Tip set back along head +z \[m\].
    pub setback: f64,
}

impl Mount {
    /// Columns: cutter x, y, z in the head frame.
    pub fn frame(&self) -> Matrix3<f64> {
        let (s, c) = self.angle.sin_cos();
        let e_r = Vector3::new(c, s, 0.0);
        let e_t = Vector3::new(-s, c, 0.0);
        let (sg, cg) = self.tilt.sin_cos();
        let z = Vector3::z() * cg - e_r * sg;
        let x = e_t;
        let y = z.cross(&x);
        Matrix3::from_columns(&[x, y, z])
    }

    /// The tip (the rim's lowest point), head frame.
    pub fn tip(&self) -> Vector3<f64> {
        let (s, c) = self.angle.sin_cos();
        Vector3::new(self.track * c, self.track * s, self.setback)
    }
}

/// One disc of a head: its mount, geometry and CSM spacing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DiscSpec {
    pub mount: Mount,
    pub cutter: CutterParams,
    pub spacing: f64,
}

impl DiscSpec {
    /// The disc of a layout entry (degrees to radians).
    pub fn from_layout(c: &CutterSpec) -> Self {
        Self {
            mount: Mount {
                track: c.track,
                angle: c.angle_deg.to_radians(),
                tilt: c.tilt_deg.to_radians(),
                setback: c.setback,
            },
            cutter: c.disc,
            spacing: c.spacing,
        }
    }

    /// Disc centre, head frame.
    pub fn centre(&self) -> Vector3<f64> {
        self.mount.tip() + self.mount.frame().column(2) * self.cutter.radius
    }
}

/// Which inputs move the discs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Drive {
    /// The head's pose and velocities; every disc follows its mount.
    Head,
    /// Every disc's own pose and velocities (spin included).
    Discs,
}

/// What the head FMU reports.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct HeadOutputs {
    /// Per disc, in layout order (no bookkeeping fields).
    pub discs: Vec<Outputs>,
    /// Total force of the rock on the head, rock frame \[N\].
    pub force: [f64; 3],
    /// Total moment about the head origin (disc drive: the rock origin) \[N m\].
    pub moment: [f64; 3],
    /// Force along head +z \[N\].
    pub thrust: f64,
    /// Moment about head -z \[N m\].
    pub torque: f64,
    pub excavated_volume: f64,
    pub cutting_energy: f64,
    pub specific_energy: f64,
    pub chipped_volume: f64,
    pub chip_count: u64,
}

/// The head's discrete state: the face and every disc's own state.
#[derive(Debug, Clone, PartialEq)]
pub struct HeadState {
    face: Face,
    discs: Vec<DiscState>,
}

const MAGIC: &[u8; 8] = b"KERFHEAD";
/// 2: tiles carry the height bound the map keeps; 3: every disc's state
/// carries the chip boundaries since its pass's last chip; 4: and the
/// power after its last cut.
const VERSION: u32 = 4;

impl HeadState {
    pub fn face(&self) -> &Face {
        &self.face
    }

    pub fn discs(&self) -> &[DiscState] {
        &self.discs
    }

    /// Versioned little-endian form: magic, version, grid and bookkeeping,
    /// the discs' states, then the touched tiles only.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut v = Vec::with_capacity(96 + 100 * self.discs.len());
        v.extend_from_slice(MAGIC);
        v.extend_from_slice(&VERSION.to_le_bytes());
        blob::face_header(&mut v, &self.face);
        blob::u64s(&mut v, &[self.discs.len() as u64]);
        for d in &self.discs {
            blob::disc_state(&mut v, d);
        }
        blob::tiles(&mut v, &self.face.map);
        v
    }

    /// Inverse of [`HeadState::to_bytes`] for a head of `n` discs on the
    /// rock of `params`.
    pub fn from_bytes(bytes: &[u8], params: &Params, n: usize) -> Result<Self> {
        let mut r = blob::Reader::new(bytes);
        if r.take(8)? != MAGIC {
            return Err(blob::bad("not a kerf head state (wrong magic)"));
        }
        let version = r.u32()?;
        if version != VERSION {
            return Err(KerfError::BadState(format!(
                "head state version {version}, this build reads {VERSION}"
            )));
        }
        let grid = grid_of(&params.rock);
        let (excavated_volume, cutting_energy) = r.face_header(&grid, params.rock.z0)?;
        let count = r.u64()?;
        if count != n as u64 {
            return Err(KerfError::BadState(format!(
                "the state holds {count} discs, this head has {n}"
            )));
        }
        let discs = (0..n).map(|_| r.disc_state()).collect::<Result<Vec<_>>>()?;
        let map = r.tiles(grid, params.rock.z0)?;
        r.end()?;
        Ok(Self {
            face: Face {
                map,
                excavated_volume,
                cutting_energy,
            },
            discs,
        })
    }
}

/// Moves a rigid body (the head) along a twist for `t`: the whole angular
/// velocity turns it (unlike a disc's frame, which does not spin).
pub fn advance_rigid(pose: &Pose, twist: &Twist, t: f64) -> Pose {
    let dr = Rotation3::from_scaled_axis(twist.omega * t);
    Pose::from_rotation(pose.position + twist.velocity * t, &(dr * pose.rotation()))
}

/// The discs of a head on one face.
pub struct Head {
    /// The parameters every disc shares (rock, friction, numerics,
    /// chipping); `cutter` and `csm.spacing` are each disc's own.
    params: Params,
    specs: Vec<DiscSpec>,
    discs: Vec<Disc>,
    state: HeadState,
    /// The discs' placement ([`place_all`], a function of the head's pose
    /// and twist alone) at the last head pose and twist placed: a step
    /// ends where the host's reading of the outputs and the next step
    /// begin. Placing the reference head's 56 discs costs 42 k
    /// instructions, on one thread; a step placed them five times. Not
    /// part of the state.
    placed: Option<(Pose, Twist, Motions)>,
}

/// Every disc's pose and twist, in layout order.
type Motions = Vec<(Pose, Twist)>;

/// The default rock of a layout: a square about the axis that holds every
/// disc's reach (plus 2 cm), at 1 mm cells, flat at 0.
pub fn default_rock(layout: &Layout) -> (f64, usize) {
    let half = ((layout.reach() + 0.02) * 1000.0).ceil() / 1000.0;
    let nodes = (2.0 * half * 1000.0).round() as usize + 1;
    (half, nodes)
}

/// Default parameters on the layout's default rock ([`default_rock`]'s
/// square) at cells of `cell` (1 mm: that rock exactly; a cell that divides
/// its side, such as 0.5 or 2 mm, keeps the square).
pub fn default_params(layout: &Layout, cell: f64) -> Params {
    let (half, _) = default_rock(layout);
    let nodes = (2.0 * half / cell).round() as usize + 1;
    let mut p = Params::default();
    (p.rock.x_min, p.rock.x_max, p.rock.y_min, p.rock.y_max) = (-half, half, -half, half);
    (p.rock.nx, p.rock.ny) = (nodes, nodes);
    p
}

impl Head {
    /// Checks the shared parameters and every disc (messages name
    /// `cutter[i].key`), and builds the face. The discs turn freely on
    /// their bearings ([`Disc::turning_freely`]): the head drive gives each
    /// the spin that rolls its nominal tip, and a tilted disc touching near
    /// its tip's low edge takes up the rest itself.
    pub fn new(params: Params, specs: Vec<DiscSpec>) -> Result<Self> {
        if specs.is_empty() {
            return Err(KerfError::Layout("a head needs at least one disc".into()));
        }
        for (k, s) in specs.iter().enumerate() {
            Self::disc_params(&params, s)
                .validate()
                .map_err(|e| match e {
                    KerfError::BadParameter { name, value, why } => {
                        let key = match name {
                            "csm.spacing" => "spacing",
                            n => n.strip_prefix("cutter.").unwrap_or(n),
                        };
                        if name.starts_with("cutter.") || name == "csm.spacing" {
                            KerfError::Layout(format!(
                                "parameter cutter[{}].{key} = {}: {why}",
                                k + 1,
                                crate::core::error::Compact(value)
                            ))
                        } else {
                            KerfError::BadParameter { name, value, why }
                        }
                    }
                    other => other,
                })?;
            let m = &s.mount;
            let bad = |key: &str, v: f64, why: &str| {
                Err(KerfError::Layout(format!(
                    "parameter cutter[{}].{key} = {v}: {why}",
                    k + 1
                )))
            };
            if !(m.track.is_finite() && m.track >= 0.0 && m.track <= 10.0) {
                return bad("track", m.track, "must lie in [0, 10] m");
            }
            if !(m.angle.is_finite() && m.angle.abs() <= 4.0 * std::f64::consts::PI) {
                return bad("angle", m.angle, "must be finite, within +-4 pi");
            }
            if !(m.tilt.is_finite() && m.tilt.abs() <= 75f64.to_radians()) {
                return bad("tilt", m.tilt, "must lie within +-75 deg");
            }
            if !(m.setback.is_finite() && m.setback.abs() <= 0.5) {
                return bad("setback", m.setback, "must lie in [-0.5, 0.5] m");
            }
        }
        params.validate()?;
        let face = Face::new(&params.rock)?;
        let discs = specs
            .iter()
            .map(|s| {
                let p = Self::disc_params(&params, s);
                Disc::new(
                    p.cutter,
                    p.csm,
                    p.numerics.p_reg,
                    p.chipping.pressure_scale_in_use(),
                )
                .turning_freely()
            })
            .collect();
        let state = HeadState {
            face,
            discs: specs.iter().map(|_| DiscState::new(&params)).collect(),
        };
        Ok(Self {
            params,
            specs,
            discs,
            state,
            placed: None,
        })
    }

    /// The discs turn as the host spins them, as kerf.fmu's disc does
    /// ([`Disc::spun_by_host`]): the disc drive, whose per-disc inputs have
    /// the single-disc contract's meaning, spin included. A multibody host
    /// that carries each disc on its own bearing gets the friction that
    /// spins it up or brakes it; fed the spin that rolls each disc's contact
    /// (upright discs: their tip) it reads as the head drive.
    pub fn spun_by_host(mut self) -> Self {
        self.discs = self.discs.into_iter().map(Disc::spun_by_host).collect();
        self
    }

    /// The parameters of disc `s` alone (what a kerf.fmu of it would have).
    pub fn disc_params(params: &Params, s: &DiscSpec) -> Params {
        let mut p = params.clone();
        p.cutter = s.cutter;
        p.csm.spacing = s.spacing;
        p
    }

    pub fn params(&self) -> &Params {
        &self.params
    }

    pub fn specs(&self) -> &[DiscSpec] {
        &self.specs
    }

    pub fn discs(&self) -> &[Disc] {
        &self.discs
    }

    pub fn len(&self) -> usize {
        self.specs.len()
    }

    pub fn is_empty(&self) -> bool {
        self.specs.is_empty()
    }

    pub fn face(&self) -> &Face {
        &self.state.face
    }

    pub fn map(&self) -> &HeightMap {
        &self.state.face.map
    }

    /// The largest rim travel ([`super::model::rim_travel`]) of any disc from
    /// its last cut to its pose in `motions` (Model Exchange's event
    /// indicator counts it); `None` before the first cut. Changes nothing.
    pub fn travel_since_cut(&self, motions: &[(Pose, Twist)]) -> Option<f64> {
        self.state
            .discs
            .iter()
            .zip(motions)
            .zip(&self.specs)
            .filter_map(|((s, (pose, _)), spec)| {
                Some(super::model::rim_travel(
                    &s.last_cut?,
                    pose,
                    &RimReach::new(&spec.cutter, &self.state.face.map),
                ))
            })
            .reduce(f64::max)
    }

    /// Every disc's pose and twist (rock frame) for the head at `head`
    /// moving with `twist`: the disc frame follows its mount; the disc spins
    /// freely about its axle so that its tip rolls without slip.
    pub fn place(&self, head: &Pose, twist: &Twist) -> Vec<(Pose, Twist)> {
        place_all(&self.specs, head, twist)
    }

    fn check_motions(&self, motions: &[(Pose, Twist)]) -> Result<()> {
        if motions.len() != self.len() {
            return Err(KerfError::BadState(format!(
                "{} disc motions for a head of {} discs",
                motions.len(),
                self.len()
            )));
        }
        for (p, t) in motions {
            p.validate()?;
            t.validate()?;
        }
        Ok(())
    }

    /// Outputs for the discs at `motions`, against the committed face;
    /// totals about `origin` with thrust along `axis`. Never changes the
    /// face. Discs are evaluated in parallel (rayon's current pool).
    pub fn evaluate(
        &mut self,
        motions: &[(Pose, Twist)],
        origin: Vector3<f64>,
        axis: Vector3<f64>,
    ) -> Result<HeadOutputs> {
        self.check_motions(motions)?;
        let discs = super::disc::evaluate_all(
            &mut self.discs,
            &self.state.discs,
            &self.state.face.map,
            motions,
            &self.params,
        );
        Ok(self.totals(discs, motions, origin, axis))
    }

    /// [`Head::evaluate`] for the head drive: discs placed from the head
    /// pose, totals about the head origin, thrust along head +z.
    pub fn evaluate_head(&mut self, head: &Pose, twist: &Twist) -> Result<HeadOutputs> {
        head.validate()?;
        twist.validate()?;
        let motions = self.placed(head, twist);
        self.evaluate(&motions, head.position, head.rotation() * Vector3::z())
    }

    /// [`Head::evaluate`] for the disc drive: totals about the rock origin,
    /// thrust along rock +z.
    pub fn evaluate_discs(&mut self, motions: &[(Pose, Twist)]) -> Result<HeadOutputs> {
        self.evaluate(motions, Vector3::zeros(), Vector3::z())
    }

    fn totals(
        &self,
        discs: Vec<Outputs>,
        motions: &[(Pose, Twist)],
        origin: Vector3<f64>,
        axis: Vector3<f64>,
    ) -> HeadOutputs {
        let mut force = Vector3::zeros();
        let mut moment = Vector3::zeros();
        for (o, (p, _)) in discs.iter().zip(motions) {
            let f = Vector3::from(o.force);
            force += f;
            moment += Vector3::from(o.moment) + (p.position - origin).cross(&f);
        }
        let face = &self.state.face;
        HeadOutputs {
            force: force.into(),
            moment: moment.into(),
            thrust: force.dot(&axis),
            torque: -moment.dot(&axis),
            excavated_volume: face.excavated_volume,
            cutting_energy: face.cutting_energy,
            specific_energy: face.specific_energy(),
            chipped_volume: self.state.discs.iter().map(|d| d.chips.volume).sum(),
            chip_count: self.state.discs.iter().map(|d| d.chips.count).sum(),
            discs,
        }
    }

    /// Would a commit at `motions` change the face?
    pub fn cuts(&self, motions: &[(Pose, Twist)]) -> Result<bool> {
        self.check_motions(motions)?;
        Ok(self
            .discs
            .iter()
            .zip(motions)
            .any(|(d, (p, _))| d.would_cut(&self.state.face.map, p, &self.params)))
    }

    /// Cuts the face at `motions` (a Model Exchange event; see
    /// [`commit_paths`]): every disc along its path from its last cut, in
    /// disc order. Returns whether the face changed. All or nothing, as
    /// [`Head::advance_head`].
    pub fn commit(&mut self, motions: &[(Pose, Twist)], dt: f64) -> Result<bool> {
        super::model::check_interval(dt)?;
        self.check_motions(motions)?;
        commit_paths(
            &mut self.state.face,
            &mut self.discs,
            &mut self.state.discs,
            motions,
            dt,
            &self.params,
        )
    }

    /// Moves the head from `start` with `twist` (rigidly: the head turns with
    /// the whole angular velocity) for `h` seconds, every disc cutting the
    /// face along its whole path. Returns the end pose of the head. All or
    /// nothing: a step that returns an error has changed nothing (every
    /// check, every pose it would cut at included, comes first).
    pub fn advance_head(&mut self, start: &Pose, twist: &Twist, h: f64) -> Result<Pose> {
        check_step(h)?;
        start.validate()?;
        twist.validate()?;
        let motions0 = self.placed(start, twist);
        self.check_motions(&motions0)?;
        let counts = self.sub_step_counts(&motions0, h);
        // (the checks and the cuts ask for the same times)
        let at = std::cell::RefCell::new(Vec::<(f64, Pose, Motions)>::new());
        let path = |t: f64| {
            let mut at = at.borrow_mut();
            if let Some((_, _, m)) = at.iter().find(|a| a.0 == t) {
                return Ok(m.clone());
            }
            let head = advance_rigid(start, twist, t);
            let m = place_all(&self.specs, &head, twist);
            at.push((t, head, m.clone()));
            Ok(m)
        };
        sweep(
            &mut self.state.face,
            &mut self.discs,
            &mut self.state.discs,
            &self.params,
            &motions0,
            h,
            &counts,
            path,
        )?;
        // the placement at the step's last time, for the outputs after it
        self.placed = at
            .into_inner()
            .into_iter()
            .max_by(|a, b| a.0.total_cmp(&b.0))
            .map(|(_, head, m)| (head, *twist, m));
        Ok(advance_rigid(start, twist, h))
    }

    /// [`Head::place`], or the placement kept in the `placed` field when it
    /// is for this head pose and twist.
    fn placed(&mut self, head: &Pose, twist: &Twist) -> Vec<(Pose, Twist)> {
        if let Some((p, t, m)) = &self.placed {
            if p == head && t == twist {
                return m.clone();
            }
        }
        let m = self.place(head, twist);
        self.placed = Some((*head, *twist, m.clone()));
        m
    }

    /// Each disc's sub-steps over a step of `h` from `motions` (its twist is
    /// constant over the step, on the rigid head as in the disc drive).
    fn sub_step_counts(&self, motions: &[(Pose, Twist)], h: f64) -> Vec<usize> {
        motions
            .iter()
            .zip(&self.specs)
            .map(|((p, t), s)| {
                let reach = RimReach::new(&s.cutter, &self.state.face.map);
                sub_steps(p, t, &reach, h, &self.params)
            })
            .collect()
    }

    /// Moves every disc from its own start with its own twist for `h`
    /// seconds (the disc drive; each disc as kerf.fmu's Co-Simulation step),
    /// cutting the face along every path. Returns the end poses. All or
    /// nothing, as [`Head::advance_head`].
    pub fn advance_discs(&mut self, starts: &[(Pose, Twist)], h: f64) -> Result<Vec<Pose>> {
        check_step(h)?;
        self.check_motions(starts)?;
        let counts = self.sub_step_counts(starts, h);
        let end = sweep(
            &mut self.state.face,
            &mut self.discs,
            &mut self.state.discs,
            &self.params,
            starts,
            h,
            &counts,
            |t| {
                Ok(starts
                    .iter()
                    .map(|(p, tw)| (advance_pose(p, tw, t), *tw))
                    .collect())
            },
        )?;
        Ok(end.into_iter().map(|(p, _)| p).collect())
    }

    /// A copy of the discrete state (shares the face's tiles).
    pub fn state(&self) -> HeadState {
        self.state.clone()
    }

    /// Restores a state taken from a head on the same grid with as many discs.
    pub fn set_state(&mut self, s: &HeadState) -> Result<()> {
        if !s.face.same_grid(&self.state.face) || s.discs.len() != self.discs.len() {
            return Err(KerfError::BadState(
                "the state was taken for another rock grid or head".into(),
            ));
        }
        self.state = s.clone();
        self.discs.iter().for_each(Disc::forget);
        Ok(())
    }

    /// Steady start: pre-cuts the face as if the head (at rest pose, all
    /// inputs zero) had been boring at `p_rev` per revolution with `wz > 0`
    /// for ever, so a run measures steady loads from its first step.
    ///
    /// Assumptions: every node within the bore (radius up to the outermost
    /// tip track + T/2) belongs to the nearest track; the ridges between
    /// tracks are fully relieved (broken out down to the groove bottoms, as
    /// chipping does at a good spacing), so the whole annulus of a track lies
    /// on its groove bottom; that bottom is where the disc of the track that
    /// passed last left it: a disc at angle `a` passed angle `phi` a turn
    /// fraction `((a - phi) mod 2 pi) / 2 pi` ago, when the head stood that
    /// fraction of `p_rev` higher, so the height is `setback + p_rev *
    /// fraction` (lowest over the discs on the track, tracks equal within
    /// 1 mm). Each disc then meets rock `p_rev / k` deep (k discs on its
    /// track). The tip's profile across the groove is ignored (flat bottom).
    /// Rock ahead of a disc stands above `rock.z0` by up to `p_rev`.
    pub fn steady_start(&mut self, p_rev: f64) -> Result<()> {
        if !(p_rev.is_finite() && (0.0..=0.05).contains(&p_rev)) {
            return Err(KerfError::BadParameter {
                name: "head.steadyPenetration",
                value: p_rev,
                why: "must lie in [0, 0.05] m".into(),
            });
        }
        if p_rev == 0.0 {
            return Ok(());
        }
        let mut tracks: Vec<(f64, Vec<(f64, f64)>)> = Vec::new();
        for s in &self.specs {
            let m = &s.mount;
            match tracks.iter_mut().find(|(t, _)| (t - m.track).abs() < 1e-3) {
                Some((_, d)) => d.push((m.angle, m.setback)),
                None => tracks.push((m.track, vec![(m.angle, m.setback)])),
            }
        }
        tracks.sort_by(|a, b| a.0.total_cmp(&b.0));
        let edge = self
            .specs
            .iter()
            .map(|s| s.mount.track + 0.5 * s.cutter.tip_width)
            .fold(0.0, f64::max);
        let map = &mut self.state.face.map;
        let g = *map.grid();
        let Some((i0, i1, j0, j1)) = g.node_range(-edge, edge, -edge, edge) else {
            return Ok(());
        };
        let two_pi = std::f64::consts::TAU;
        let z0 = map.base_height();
        let depth = |x: f64, y: f64| {
            let rho = (x * x + y * y).sqrt();
            if rho > edge {
                return None;
            }
            let phi = y.atan2(x);
            let k = tracks.partition_point(|(t, _)| *t < rho);
            let near = match (k.checked_sub(1), tracks.get(k)) {
                (Some(a), Some(b)) if rho - tracks[a].0 > b.0 - rho => k,
                (Some(a), _) => a,
                (None, _) => 0,
            };
            Some(
                tracks[near]
                    .1
                    .iter()
                    .map(|&(a, setback)| {
                        // the fraction of a turn from the disc back to phi
                        let u = (a - phi) / two_pi;
                        setback + p_rev * (u - u.floor())
                    })
                    .fold(f64::INFINITY, f64::min),
            )
        };
        // one patch a row of tiles, filled in parallel (a 10 m face holds
        // about 80 million nodes inside the gauge)
        let all = map.tile_rect(i0, i1, j0, j1);
        let rows: Vec<TileRect> = (all.tj[0]..=all.tj[1])
            .map(|tj| TileRect {
                ti: all.ti,
                tj: [tj, tj],
            })
            .collect();
        let patches = map.patches(&rows).expect("rows of tiles do not overlap");
        patches
            .into_par_iter()
            .zip(rows.par_iter())
            .for_each(|(mut patch, r)| {
                let (ja, jb) = ((r.tj[0] * TILE).max(j0), ((r.tj[0] + 1) * TILE - 1).min(j1));
                for j in ja..=jb {
                    for i in i0..=i1 {
                        let (x, y) = g.node_xy(i, j);
                        if let Some(z) = depth(x, y) {
                            patch.set_node(i, j, z0 + z);
                        }
                    }
                }
            });
        map.new_lineage();
        self.discs.iter().for_each(Disc::forget);
        Ok(())
    }

    /// Replaces the face (rock and bookkeeping), e.g. by one bored before;
    /// it must stand on the same grid.
    pub fn set_face(&mut self, face: Face) -> Result<()> {
        if !face.same_grid(&self.state.face) {
            return Err(KerfError::BadState(
                "the face is on another rock grid".into(),
            ));
        }
        self.state.face = face;
        self.discs.iter().for_each(Disc::forget);
        Ok(())
    }

    /// Writes the committed surface as an `.rsf` file.
    pub fn write_surface(&self, path: &std::path::Path) -> Result<()> {
        rsf::write(path, &self.state.face.map)
    }
}

/// Every disc's pose and twist for the head at `head` moving with `twist`.
pub fn place_all(specs: &[DiscSpec], head: &Pose, twist: &Twist) -> Vec<(Pose, Twist)> {
    let rh = head.rotation();
    specs
        .iter()
        .map(|s| {
            let r = s.cutter.radius;
            let rot = Rotation3::from_matrix_unchecked(rh.matrix() * s.mount.frame());
            let centre = head.position + rh * s.centre();
            let arm = centre - head.position;
            let v = twist.velocity + twist.omega.cross(&arm);
            let (x, y, z) = (rot * Vector3::x(), rot * Vector3::y(), rot * Vector3::z());
            // velocity of the fork-fixed tip point, then the spin that
            // cancels it along cutter x: (v + w x (-R z)) . x = spin R
            let tip_v = v + twist.omega.cross(&(-z * r));
            let spin = tip_v.dot(&x) / r;
            (
                Pose::from_rotation(centre, &rot),
                Twist {
                    velocity: v,
                    omega: twist.omega + y * spin,
                },
            )
        })
        .collect()
}
