//! The model: parameters, the rock and the bookkeeping, and the three
//! operations the FMI layer needs (evaluate, commit, advance).

use nalgebra::Vector3;

use super::contact_cutter_heightmap::Contact;
use super::csm::CsmLaw;
use super::disc::{commit_paths, sub_steps, sweep, Disc, DiscState};
use super::error::{KerfError, Result};
use super::face::{grid_of, Face};
use super::heightmap::HeightMap;
use super::params::Params;
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
    /// The disc's own state: last cut, chips.
    disc: DiscState,
}

const MAGIC: &[u8; 8] = b"KERFCORE";
const VERSION: u32 = 3;

/// Little-endian writers and a checked reader for the state blobs of the
/// model and the head.
pub(crate) mod blob {
    use super::super::chip_heightmap::ChipState;
    use super::super::disc::DiscState;
    use super::super::error::{KerfError, Result};
    use super::super::face::Face;
    use super::super::heightmap::{Grid, HeightMap, TILE};
    use super::super::pose::Pose;

    pub fn bad(why: &str) -> KerfError {
        KerfError::BadState(why.to_string())
    }

    pub fn f64s(v: &mut Vec<u8>, xs: &[f64]) {
        for x in xs {
            v.extend_from_slice(&x.to_le_bytes());
        }
    }

    pub fn u64s(v: &mut Vec<u8>, xs: &[u64]) {
        for x in xs {
            v.extend_from_slice(&x.to_le_bytes());
        }
    }

    /// Grid, base height, excavated volume and cutting energy.
    pub fn face_header(v: &mut Vec<u8>, face: &Face) {
        let g = face.map.grid();
        u64s(v, &[g.nx as u64, g.ny as u64]);
        f64s(
            v,
            &[
                g.x_min,
                g.y_min,
                g.dx,
                g.dy,
                face.map.base_height(),
                face.excavated_volume,
                face.cutting_energy,
            ],
        );
    }

    /// Last cut and chips of one disc.
    pub fn disc_state(v: &mut Vec<u8>, s: &DiscState) {
        match s.last_cut {
            Some(p) => {
                v.push(1);
                f64s(
                    v,
                    &[
                        p.position.x,
                        p.position.y,
                        p.position.z,
                        p.yaw,
                        p.pitch,
                        p.roll,
                    ],
                );
            }
            None => v.push(0),
        }
        let c = &s.chips;
        f64s(v, &[c.travel, c.next, c.volume]);
        u64s(v, &[c.index, c.count]);
        match c.last_low {
            Some(p) => {
                v.push(1);
                f64s(v, &p);
            }
            None => v.push(0),
        }
    }

    /// The touched tiles only.
    pub fn tiles(v: &mut Vec<u8>, map: &HeightMap) {
        let tiles: Vec<(usize, &[f64])> = map.touched_tiles().collect();
        v.reserve(8 + tiles.len() * (8 + TILE * TILE * 8));
        u64s(v, &[tiles.len() as u64]);
        for (k, z) in tiles {
            u64s(v, &[k as u64]);
            f64s(v, z);
        }
    }

    pub struct Reader<'a> {
        pub bytes: &'a [u8],
        pub pos: usize,
    }

    impl<'a> Reader<'a> {
        pub fn new(bytes: &'a [u8]) -> Self {
            Self { bytes, pos: 0 }
        }

        pub fn take(&mut self, n: usize) -> Result<&'a [u8]> {
            let s = self
                .bytes
                .get(self.pos..self.pos + n)
                .ok_or_else(|| bad("the blob is truncated"))?;
            self.pos += n;
            Ok(s)
        }

        pub fn u8(&mut self) -> Result<u8> {
            Ok(self.take(1)?[0])
        }

        pub fn u32(&mut self) -> Result<u32> {
            Ok(u32::from_le_bytes(self.take(4)?.try_into().unwrap()))
        }

        pub fn u64(&mut self) -> Result<u64> {
            Ok(u64::from_le_bytes(self.take(8)?.try_into().unwrap()))
        }

        pub fn f64(&mut self) -> Result<f64> {
            Ok(f64::from_le_bytes(self.take(8)?.try_into().unwrap()))
        }

        pub fn end(&self) -> Result<()> {
            if self.pos != self.bytes.len() {
                return Err(bad("trailing bytes"));
            }
            Ok(())
        }

        /// Reads what [`face_header`] wrote and checks it against `grid`
        /// and `z0`; returns (excavated volume, cutting energy).
        pub fn face_header(&mut self, grid: &Grid, z0: f64) -> Result<(f64, f64)> {
            let (nx, ny) = (self.u64()?, self.u64()?);
            let mut f = [0f64; 7];
            for x in &mut f {
                *x = self.f64()?;
            }
            let same = nx == grid.nx as u64
                && ny == grid.ny as u64
                && f[0] == grid.x_min
                && f[1] == grid.y_min
                && f[2] == grid.dx
                && f[3] == grid.dy
                && f[4] == z0;
            if !same {
                return Err(bad("the state was saved for another rock grid"));
            }
            if !(f[5].is_finite() && f[6].is_finite()) {
                return Err(bad("non-finite bookkeeping"));
            }
            Ok((f[5], f[6]))
        }

        /// Reads what [`disc_state`] wrote.
        pub fn disc_state(&mut self) -> Result<DiscState> {
            let last_cut = match self.u8()? {
                0 => None,
                1 => {
                    let mut q = [0f64; 6];
                    for x in &mut q {
                        *x = self.f64()?;
                    }
                    let pose = Pose::new(q[0], q[1], q[2], q[3], q[4], q[5]);
                    pose.validate()
                        .map_err(|_| bad("non-finite last cut pose"))?;
                    Some(pose)
                }
                _ => return Err(bad("bad last-cut flag")),
            };
            let mut cf = [0f64; 3];
            for x in &mut cf {
                *x = self.f64()?;
            }
            let index = self.u64()?;
            let count = self.u64()?;
            let last_low = match self.u8()? {
                0 => None,
                1 => {
                    let mut q = [0f64; 3];
                    for x in &mut q {
                        *x = self.f64()?;
                    }
                    Some(q)
                }
                _ => return Err(bad("bad chip flag")),
            };
            if !cf
                .iter()
                .chain(last_low.iter().flatten())
                .all(|x| x.is_finite())
            {
                return Err(bad("non-finite chip state"));
            }
            let [travel, next, volume] = cf;
            Ok(DiscState {
                last_cut,
                chips: ChipState {
                    travel,
                    index,
                    next,
                    last_low,
                    count,
                    volume,
                },
            })
        }

        /// Reads what [`tiles`] wrote onto a flat map of `grid` at `z0`.
        pub fn tiles(&mut self, grid: Grid, z0: f64) -> Result<HeightMap> {
            let mut map = HeightMap::flat(grid, z0);
            let n = self.u64()?;
            if n > map.tile_count() as u64 {
                return Err(bad("more tiles than the grid has"));
            }
            let mut z = vec![0.0; TILE * TILE];
            for _ in 0..n {
                let k = self.u64()? as usize;
                for x in z.iter_mut() {
                    *x = self.f64()?;
                    if !x.is_finite() {
                        return Err(bad("non-finite height"));
                    }
                }
                map.load_tile(k, &z)
                    .ok_or_else(|| bad("tile index out of range"))?;
            }
            Ok(map)
        }
    }
}

impl ModelState {
    /// Versioned little-endian binary form: magic, version, grid, bookkeeping,
    /// then the touched tiles only.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut v = Vec::with_capacity(96);
        v.extend_from_slice(MAGIC);
        v.extend_from_slice(&VERSION.to_le_bytes());
        blob::face_header(&mut v, &self.face);
        blob::disc_state(&mut v, &self.disc);
        blob::tiles(&mut v, &self.face.map);
        v
    }

    /// Inverse of [`ModelState::to_bytes`]; rejects corrupt or foreign blobs
    /// and blobs made for another height-map grid.
    pub fn from_bytes(bytes: &[u8], params: &Params) -> Result<Self> {
        let mut r = blob::Reader::new(bytes);
        if r.take(8)? != MAGIC {
            return Err(blob::bad("not a kerf state (wrong magic)"));
        }
        let version = r.u32()?;
        if version != VERSION {
            return Err(KerfError::BadState(format!(
                "state version {version}, this build reads {VERSION}"
            )));
        }
        let grid = grid_of(&params.rock);
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
        let f = Vector3::from(self.force);
        let m = Vector3::from(self.moment);
        -(f.dot(&twist.velocity) + m.dot(&twist.omega)) * dt
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
        })
    }
}

pub struct Model {
    params: Params,
    /// The one disc, with its contact cache.
    disc: Disc,
    state: ModelState,
}

impl Model {
    /// Validates the parameters and builds the rock (flat, or from
    /// `rock.initial_surface`).
    pub fn new(params: Params) -> Result<Self> {
        params.validate()?;
        let face = Face::new(&params.rock)?;
        let disc = Disc::new(params.cutter, params.csm, params.numerics.p_reg);
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

    pub fn law(&self) -> &CsmLaw {
        self.disc.law()
    }

    /// The committed rock.
    pub fn map(&self) -> &HeightMap {
        &self.state.face.map
    }

    /// The rock and its bookkeeping.
    pub fn face(&self) -> &Face {
        &self.state.face
    }

    /// Warnings about parameters that are legal but questionable (for the
    /// FMI logger): an Ozdemir regression outside its Table 1 range.
    pub fn warnings(&self) -> Vec<String> {
        self.law()
            .range_warnings(0.0038)
            .into_iter()
            .filter(|w| !w.contains(": penetration"))
            .collect()
    }

    /// The contact geometry and cutting force (no friction) at `pose`.
    pub fn contact(&self, pose: &Pose) -> Contact {
        self.disc.contact(&self.state.face.map, pose, &self.params)
    }

    /// Contact force for `pose`, against the committed rock. Never changes the rock.
    pub fn evaluate(&self, pose: &Pose, twist: &Twist) -> Result<Outputs> {
        pose.validate()?;
        twist.validate()?;
        let o = self
            .disc
            .evaluate(&self.state.face.map, pose, twist, &self.params);
        Ok(self.with_bookkeeping(o))
    }

    /// `o` with the current excavated volume, cutting energy and specific energy.
    fn with_bookkeeping(&self, mut o: Outputs) -> Outputs {
        let s = &self.state;
        o.excavated_volume = s.face.excavated_volume;
        o.cutting_energy = s.face.cutting_energy;
        o.specific_energy = s.face.specific_energy();
        o.chipped_volume = s.disc.chips.volume;
        o.chip_count = s.disc.chips.count;
        o
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
        Ok(o.work_on_rock(twist, 1.0))
    }

    /// Cuts the rock at `pose` (a Model Exchange event). `dt` is the time since
    /// the previous commit, for the energy bookkeeping. Returns whether the rock changed.
    ///
    /// The cut follows the path from the pose of the previous cut (see
    /// [`commit_paths`], of which this is the one-disc case), so a solver step
    /// longer than a cell leaves no uncut rock (the thesis cut only at the
    /// sampled poses).
    pub fn commit(&mut self, pose: &Pose, twist: &Twist, dt: f64) -> Result<bool> {
        check_interval(dt)?;
        pose.validate()?;
        twist.validate()?;
        commit_paths(
            &mut self.state.face,
            std::slice::from_mut(&mut self.disc),
            std::slice::from_mut(&mut self.state.disc),
            &[(*pose, *twist)],
            dt,
            &self.params,
        )
    }

    /// Moves the cutter from `start` along `twist` for `h` seconds, cutting the
    /// rock along the whole path (a Co-Simulation step): the path is cut at
    /// sub-steps no longer than `numerics.sweep_step` of travel of any rim
    /// point, so no uncut rock is left however long `h`. The cutting energy
    /// takes the trapezoidal rule over the step. Returns the end pose.
    pub fn advance(&mut self, start: &Pose, twist: &Twist, h: f64) -> Result<Pose> {
        check_step(h)?;
        start.validate()?;
        twist.validate()?;
        let n = sub_steps(start, twist, self.params.cutter.radius, h, &self.params);
        let end = sweep(
            &mut self.state.face,
            std::slice::from_mut(&mut self.disc),
            std::slice::from_mut(&mut self.state.disc),
            &self.params,
            &[(*start, *twist)],
            h,
            n,
            |t| Ok(vec![(advance_pose(start, twist, t), *twist)]),
        )?;
        Ok(end[0].0)
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
