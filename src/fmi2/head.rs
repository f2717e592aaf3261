//! The cutterhead model behind the generic FMI instance of `generic.rs`
//! (the same state machine, modes, masks and rules as kerf.fmu's): a
//! [`Head`] instead of a single-disc model, with the variable table of
//! [`super::head_md`] generated from the layout packed in the FMU.
//!
//! Safe Rust only, like `instance.rs`.

use rustc_hash::FxHashMap;
use std::ffi::{CStr, CString};
use std::path::{Path, PathBuf};

use crate::core::head::{place_all, DiscSpec, Drive, Head, HeadOutputs, HeadState, Mount};
use crate::core::layout::Layout;
use crate::core::params::CutterParams;
use crate::core::{rim_speed, rim_spin_speed, Params, Pose, RimReach, Twist};

use super::generic::{restore_core, Class, Ctx, Fmi, FmuModel, Snapshot, StepError, VarInfo};
use super::head_md::{self, HeadVar, Slot, Ty};
use super::instance::{Files, Kind, Mode, Res, Values};
use super::log::Logger;
use super::md::{self, vr};
use super::state::{frame, put_header, read_header, unframe, Reader};

/// Values of everything settable: kerf's table for the shared parameters,
/// the head inputs, the per-disc parameters and inputs.
#[derive(Debug, Clone, PartialEq)]
pub struct HeadValues {
    pub kerf: Values,
    pub head_in: [f64; 12],
    /// Head-only parameters (`head_md::HEAD_PARAMS`).
    pub head_par: [f64; 1],
    pub disc_par: Vec<[f64; 8]>,
    pub disc_in: Vec<[f64; 12]>,
}

fn pose_of(a: &[f64; 12]) -> Pose {
    Pose::new(a[0], a[1], a[2], a[3], a[4], a[5])
}

fn twist_of(a: &[f64; 12]) -> Twist {
    Twist::new([a[6], a[7], a[8]], [a[9], a[10], a[11]])
}

impl HeadValues {
    fn specs(&self) -> Vec<DiscSpec> {
        self.disc_par
            .iter()
            .map(|p| DiscSpec {
                mount: Mount {
                    track: p[0],
                    angle: p[1],
                    tilt: p[2],
                    setback: p[3],
                },
                spacing: p[4],
                cutter: CutterParams {
                    radius: p[5],
                    tip_width: p[6],
                    tip_radius: p[7],
                    // the flanks are shared by every disc of the head
                    flank_angle: self.kerf.real(super::md::vr::CUTTER_FLANK_ANGLE),
                    hub_width: self.kerf.real(super::md::vr::CUTTER_HUB_WIDTH),
                },
            })
            .collect()
    }
}

/// The head's part of a captured FMU state.
pub struct HeadSnap {
    pub values: HeadValues,
    /// Co-Simulation: head pose (head drive) or disc poses (disc drive)
    /// reached at the end of the last step.
    pub cs_head: Pose,
    pub cs_discs: Vec<Pose>,
    pub pose_set: Vec<bool>,
    pub head: Option<HeadState>,
}

/// A captured head FMU state.
pub type HeadSnapshot = Snapshot<HeadSnap>;

/// The cutterhead model: many discs on one face, behind the generic
/// [`Fmi`] instance.
pub struct HeadModel {
    resources: Option<PathBuf>,
    guid: String,
    drive: Drive,
    vars: Vec<HeadVar>,
    /// (type class, value reference) -> index in `vars`.
    lookup: FxHashMap<(Class, u32), usize>,
    /// The per-disc value references ([`head_md::disc_vr`]) as a table:
    /// `dense[vr - disc_vr(0, 0)]` is the index in `vars` plus one (0: no
    /// variable). A host reading every disc's outputs each step made two
    /// hash look-ups a value: 40 % of the reference head's 571-output read.
    dense: Vec<u32>,
    start_values: HeadValues,
    values: HeadValues,
    head: Option<Head>,
    head_key: Option<(Params, Vec<DiscSpec>, [f64; 1])>,
    cs_head: Pose,
    cs_discs: Vec<Pose>,
    /// Co-Simulation: pose inputs set since the last step (head drive: one
    /// flag; disc drive: one per disc).
    pose_set: Vec<bool>,
    cache: Option<HeadOutputs>,
}

/// A cutterhead FMU instance.
pub type HeadInstance = Fmi<HeadModel>;

/// The FMI type class of a head variable's type.
fn class(ty: Ty) -> Class {
    match ty {
        Ty::Real => Class::Real,
        Ty::Integer | Ty::Enumeration => Class::Integer,
        Ty::Boolean => Class::Boolean,
        Ty::String => Class::String,
    }
}

/// Model Exchange: the motions are the inputs' (no Co-Simulation poses).
const ME: Ctx = Ctx {
    kind: Kind::ModelExchange,
    mode: Mode::EventMode,
};

impl HeadInstance {
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        name: CString,
        kind: Kind,
        logger: Logger,
        resources: Option<PathBuf>,
        logging_on: bool,
        guid: String,
        layout: &Layout,
        drive: Drive,
    ) -> Res<Self> {
        let model = HeadModel::new(resources, guid, layout, drive)?;
        Ok(Fmi::with_model(name, kind, logger, logging_on, model))
    }
}

impl HeadModel {
    fn new(resources: Option<PathBuf>, guid: String, layout: &Layout, drive: Drive) -> Res<Self> {
        let vars = head_md::variables(layout, drive);
        let lookup = vars
            .iter()
            .enumerate()
            .map(|(k, v)| ((class(v.ty), v.vr), k))
            .collect();
        let base = head_md::disc_vr(0, 0);
        let mut dense = vec![0u32; 100 * layout.cutters.len()];
        for (k, v) in vars.iter().enumerate() {
            if let Some(d) =
                v.vr.checked_sub(base)
                    .and_then(|d| dense.get_mut(d as usize))
            {
                *d = k as u32 + 1;
            }
        }
        let n = layout.cutters.len();
        let mut values = HeadValues {
            kerf: Values::start(),
            head_in: [0.0; 12],
            head_par: [0.0; 1],
            disc_par: vec![[0.0; 8]; n],
            disc_in: vec![[0.0; 12]; n],
        };
        for v in &vars {
            let Some(s) = &v.start else { continue };
            match v.slot {
                Slot::Kerf => match v.ty {
                    Ty::Real => {
                        let i = md::position(md::REALS, v.vr, |x| x.vr).unwrap();
                        values.kerf.real[i] = s.parse().map_err(|_| format!("bad start {s}"))?;
                    }
                    Ty::Integer | Ty::Enumeration => {
                        let i = md::position(md::INTEGERS, v.vr, |x| x.vr).unwrap();
                        values.kerf.int[i] = s.parse().map_err(|_| format!("bad start {s}"))?;
                    }
                    _ => {}
                },
                Slot::HeadInput(k) => values.head_in[k] = s.parse().unwrap_or(0.0),
                Slot::HeadParam(k) => values.head_par[k] = s.parse().unwrap_or(0.0),
                Slot::DiscParam(i, k) => values.disc_par[i][k] = s.parse().unwrap_or(0.0),
                Slot::DiscInput(i, k) => values.disc_in[i][k] = s.parse().unwrap_or(0.0),
                _ => {}
            }
        }
        let pose_flags = match drive {
            Drive::Head => 1,
            Drive::Discs => n,
        };
        let mut m = Self {
            resources,
            guid,
            drive,
            vars,
            lookup,
            dense,
            start_values: values.clone(),
            values,
            head: None,
            head_key: None,
            cs_head: Pose::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
            cs_discs: Vec::new(),
            pose_set: vec![false; pose_flags],
            cache: None,
        };
        m.reset_cs_poses();
        Ok(m)
    }

    fn reset_cs_poses(&mut self) {
        self.cs_head = pose_of(&self.values.head_in);
        self.cs_discs = self.values.disc_in.iter().map(pose_of).collect();
        self.pose_set.iter_mut().for_each(|b| *b = false);
    }

    fn params(&self, files: Files) -> Res<(Params, Vec<DiscSpec>, [f64; 1])> {
        let params = self.values.kerf.params(self.resources.as_deref(), files)?;
        Ok((params, self.values.specs(), self.values.head_par))
    }

    fn slot(&self, c: Class, r: u32) -> Slot {
        self.vars[self.index(c, r).expect("a known variable")].slot
    }

    /// The index in `vars` of the variable of class `c` with value
    /// reference `r`, if there is one.
    #[inline]
    fn index(&self, c: Class, r: u32) -> Option<usize> {
        let d = r.wrapping_sub(head_md::disc_vr(0, 0)) as usize;
        match self.dense.get(d) {
            Some(&k) => {
                (k != 0 && class(self.vars[k as usize - 1].ty) == c).then(|| k as usize - 1)
            }
            None => self.lookup.get(&(c, r)).copied(),
        }
    }

    /// The head pose the outputs are for (head drive).
    fn head_pose(&self, cx: Ctx) -> Pose {
        if cx.cs_after_step() && !self.pose_set[0] {
            self.cs_head
        } else {
            pose_of(&self.values.head_in)
        }
    }

    /// Every disc's pose and twist now.
    fn motions(&self, cx: Ctx) -> Vec<(Pose, Twist)> {
        match self.drive {
            Drive::Head => place_all(
                &self.values.specs(),
                &self.head_pose(cx),
                &twist_of(&self.values.head_in),
            ),
            Drive::Discs => self
                .values
                .disc_in
                .iter()
                .enumerate()
                .map(|(i, a)| {
                    let p = if cx.cs_after_step() && !self.pose_set[i] {
                        self.cs_discs[i]
                    } else {
                        pose_of(a)
                    };
                    (p, twist_of(a))
                })
                .collect(),
        }
    }

    fn outputs(&mut self, cx: Ctx) -> Res<&HeadOutputs> {
        if self.cache.is_none() {
            if cx.mode == Mode::InitializationMode {
                self.build()?;
            }
            let pose = self.head_pose(cx);
            let twist = twist_of(&self.values.head_in);
            let motions = match self.drive {
                Drive::Head => Vec::new(),
                Drive::Discs => self.motions(cx),
            };
            let head = self.head.as_mut().ok_or("the head was never initialized")?;
            let o = match self.drive {
                Drive::Head => head.evaluate_head(&pose, &twist),
                Drive::Discs => head.evaluate_discs(&motions),
            }
            .map_err(|e| e.to_string())?;
            self.cache = Some(o);
        }
        Ok(self.cache.as_ref().unwrap())
    }
}

impl FmuModel for HeadModel {
    type State = HeadSnap;
    const EVENT_INDICATORS: usize = head_md::NUMBER_OF_EVENT_INDICATORS;
    const COMMITTED: &'static str = "cuts committed";
    const INITIALIZED: &'static str = "head initialized";
    // the head's steps are all or nothing (`disc::sweep` checks every pose
    // it will cut before it cuts): a refused step leaves the instance as it
    // was, and a shorter one may follow
    const FATAL_STEP_FAILURE: bool = false;

    fn var(&self, c: Class, r: u32) -> Option<VarInfo<'_>> {
        let v = &self.vars[self.index(c, r)?];
        let items = match (v.slot, c) {
            (Slot::Kerf, Class::Integer) => {
                md::position(md::INTEGERS, r, |x| x.vr).and_then(|i| md::INTEGERS[i].items)
            }
            _ => None,
        };
        Some(VarInfo {
            name: &v.name,
            causality: v.causality,
            items,
        })
    }

    fn get_real(&mut self, cx: Ctx, r: u32) -> Res<f64> {
        Ok(match self.slot(Class::Real, r) {
            Slot::Kerf => self.values.kerf.real[md::position(md::REALS, r, |x| x.vr).unwrap()],
            Slot::HeadInput(j) => self.values.head_in[j],
            Slot::HeadParam(j) => self.values.head_par[j],
            Slot::DiscParam(i, j) => self.values.disc_par[i][j],
            Slot::DiscInput(i, j) => self.values.disc_in[i][j],
            Slot::Total(j) => {
                let o = self.outputs(cx)?;
                match j {
                    0..=2 => o.force[j],
                    3..=5 => o.moment[j - 3],
                    6 => o.thrust,
                    7 => o.torque,
                    8 => o.excavated_volume,
                    9 => o.cutting_energy,
                    10 => o.specific_energy,
                    _ => o.chipped_volume,
                }
            }
            Slot::DiscOutput(i, j) => {
                let o = &self.outputs(cx)?.discs[i];
                match j {
                    0..=2 => o.force[j],
                    3..=5 => o.moment[j - 3],
                    6 => o.normal_force,
                    7 => o.rolling_force,
                    8 => o.side_force,
                    9 => o.penetration,
                    _ => o.contact_angle,
                }
            }
            _ => unreachable!("a Real slot"),
        })
    }

    fn get_integer(&mut self, cx: Ctx, r: u32) -> Res<i32> {
        Ok(match self.slot(Class::Integer, r) {
            Slot::ChipCount => i32::try_from(self.outputs(cx)?.chip_count).unwrap_or(i32::MAX),
            _ => self.values.kerf.int[md::position(md::INTEGERS, r, |x| x.vr).unwrap()],
        })
    }

    fn get_boolean(&mut self, cx: Ctx, r: u32) -> Res<bool> {
        Ok(match self.slot(Class::Boolean, r) {
            Slot::DiscInContact(i) => self.outputs(cx)?.discs[i].in_contact,
            _ => self.values.kerf.boolean[md::position(md::BOOLEANS, r, |x| x.vr).unwrap()],
        })
    }

    fn get_string(&self, r: u32) -> &CStr {
        &self.values.kerf.string[md::position(md::STRINGS, r, |x| x.vr).unwrap()]
    }

    fn set_real(&mut self, r: u32, x: f64) {
        self.cache = None;
        match self.slot(Class::Real, r) {
            Slot::Kerf => {
                self.values.kerf.real[md::position(md::REALS, r, |x| x.vr).unwrap()] = x;
            }
            Slot::HeadInput(j) => {
                self.values.head_in[j] = x;
                if j < 6 {
                    self.pose_set[0] = true;
                }
            }
            Slot::DiscParam(i, j) => self.values.disc_par[i][j] = x,
            Slot::HeadParam(j) => self.values.head_par[j] = x,
            Slot::DiscInput(i, j) => {
                self.values.disc_in[i][j] = x;
                if j < 6 {
                    self.pose_set[i] = true;
                }
            }
            _ => {}
        }
    }

    fn set_integer(&mut self, r: u32, x: i32) {
        self.values.kerf.int[md::position(md::INTEGERS, r, |x| x.vr).unwrap()] = x;
        self.cache = None;
    }

    fn set_boolean(&mut self, r: u32, x: bool) {
        self.values.kerf.boolean[md::position(md::BOOLEANS, r, |x| x.vr).unwrap()] = x;
        self.cache = None;
    }

    fn set_string(&mut self, r: u32, x: CString) {
        self.values.kerf.string[md::position(md::STRINGS, r, |x| x.vr).unwrap()] = x;
        self.cache = None;
    }

    fn build(&mut self) -> Res<Vec<String>> {
        let key = self.params(Files::MustExist)?;
        if self.head.is_some() && self.head_key.as_ref() == Some(&key) {
            return Ok(Vec::new());
        }
        let mut head = Head::new(key.0.clone(), key.1.clone()).map_err(|e| e.to_string())?;
        if self.drive == Drive::Discs {
            // (the per-disc inputs are kerf.fmu's, spin included)
            head = head.spun_by_host();
        }
        head.steady_start(key.2[0]).map_err(|e| e.to_string())?;
        self.head = Some(head);
        self.head_key = Some(key);
        self.cache = None;
        Ok(Vec::new())
    }

    fn begin(&mut self) {
        self.reset_cs_poses();
        self.cache = None;
    }

    fn reset(&mut self) {
        self.values = self.start_values.clone();
        self.head = None;
        self.head_key = None;
        self.reset_cs_poses();
        self.cache = None;
    }

    fn final_surface(&self) -> String {
        match (&self.head, &self.head_key) {
            (Some(_), Some((p, _, _))) => p.rock.final_surface.clone(),
            _ => String::new(),
        }
    }

    fn write_surface(&self, path: &Path) -> Res<()> {
        let h = self.head.as_ref().ok_or("no head")?;
        h.write_surface(path).map_err(|e| e.to_string())
    }

    fn sweep_step(&self) -> f64 {
        self.values.kerf.real(vr::NUMERICS_SWEEP_STEP)
    }

    fn has_core(&self) -> bool {
        self.head.is_some()
    }

    fn travel_since_cut(&self) -> Option<f64> {
        self.head.as_ref()?.travel_since_cut(&self.motions(ME))
    }

    fn spin_speed(&self) -> f64 {
        self.motions(ME)
            .iter()
            .zip(self.values.specs())
            .map(|((p, t), s)| rim_spin_speed(p, t, s.cutter.radius))
            .fold(0.0, f64::max)
    }

    fn rim_speed(&self) -> f64 {
        self.motions(ME)
            .iter()
            .zip(self.values.specs())
            .map(|((p, t), s)| {
                let r = s.cutter.radius;
                let reach = self
                    .head
                    .as_ref()
                    .map_or(RimReach::whole(r), |h| RimReach::new(&s.cutter, h.map()));
                rim_speed(p, t, &reach).max(rim_spin_speed(p, t, r))
            })
            .fold(0.0, f64::max)
    }

    fn commit(&mut self, dt: f64) -> Res<bool> {
        let motions = self.motions(ME);
        let head = self.head.as_mut().ok_or("no head")?;
        let changed = head
            .commit(&motions, dt)
            .map_err(|e| format!("committing the cuts failed: {e}"))?;
        self.cache = None;
        Ok(changed)
    }

    fn works(&mut self, cx: Ctx) -> Res<bool> {
        let motions = self.motions(cx);
        let o = self.outputs(cx)?;
        Ok(o.discs
            .iter()
            .zip(&motions)
            .any(|(d, (_, t))| d.power_into_rock(t) != 0.0))
    }

    fn advance(&mut self, cx: Ctx, h: f64) -> Result<(), StepError> {
        let head_start = self.head_pose(cx);
        // (the head drive places the discs itself)
        let motions = match self.drive {
            Drive::Head => Vec::new(),
            Drive::Discs => self.motions(cx),
        };
        let twist = twist_of(&self.values.head_in);
        let head = self
            .head
            .as_mut()
            .ok_or(StepError::Refused("no head".into()))?;
        match self.drive {
            Drive::Head => {
                self.cs_head = head
                    .advance_head(&head_start, &twist, h)
                    .map_err(|e| StepError::Refused(e.to_string()))?
            }
            Drive::Discs => {
                self.cs_discs = head
                    .advance_discs(&motions, h)
                    .map_err(|e| StepError::Refused(e.to_string()))?
            }
        }
        self.pose_set.iter_mut().for_each(|b| *b = false);
        self.cache = None;
        Ok(())
    }

    fn state(&self, core: bool) -> HeadSnap {
        HeadSnap {
            values: self.values.clone(),
            cs_head: self.cs_head,
            cs_discs: self.cs_discs.clone(),
            pose_set: self.pose_set.clone(),
            head: if core {
                self.head.as_ref().map(Head::state)
            } else {
                None
            },
        }
    }

    fn restore(&mut self, s: &HeadSnap) -> Res<()> {
        if s.values.disc_par.len() != self.values.disc_par.len() {
            return Err("the state is for a head with another disc count".into());
        }
        let (head, key) = match &s.head {
            None => (None, None),
            Some(hs) => {
                let params = s
                    .values
                    .kerf
                    .params(self.resources.as_deref(), Files::MayBeMissing)?;
                let key = (params, s.values.specs(), s.values.head_par);
                let head = restore_core(
                    &mut self.head,
                    self.head_key.as_ref(),
                    &key,
                    || {
                        let mut p = key.0.clone();
                        p.rock.initial_surface.clear(); // the state holds the whole surface
                        Head::new(p, key.1.clone()).map_err(|e| e.to_string())
                    },
                    |h| h.set_state(hs).map_err(|e| e.to_string()),
                )?;
                (Some(head), Some(key))
            }
        };
        self.values = s.values.clone();
        self.cs_head = s.cs_head;
        self.cs_discs = s.cs_discs.clone();
        self.pose_set = s.pose_set.clone();
        self.head = head;
        self.head_key = key;
        self.cache = None;
        Ok(())
    }

    /// The serialized form of a snapshot of this head.
    fn encode(&self, s: &HeadSnapshot) -> Vec<u8> {
        let mut p = Vec::new();
        let put_f = |p: &mut Vec<u8>, x: f64| p.extend_from_slice(&x.to_le_bytes());
        let put_u = |p: &mut Vec<u8>, x: u64| p.extend_from_slice(&x.to_le_bytes());
        put_u(&mut p, self.guid.len() as u64);
        p.extend_from_slice(self.guid.as_bytes());
        put_header(&mut p, &s.header);
        let v = &s.model.values;
        put_u(&mut p, v.kerf.real.len() as u64);
        v.kerf.real.iter().for_each(|&x| put_f(&mut p, x));
        put_u(&mut p, v.kerf.int.len() as u64);
        v.kerf
            .int
            .iter()
            .for_each(|&x| put_u(&mut p, x as i64 as u64));
        put_u(&mut p, v.kerf.boolean.len() as u64);
        v.kerf.boolean.iter().for_each(|&x| p.push(u8::from(x)));
        put_u(&mut p, v.kerf.string.len() as u64);
        for x in &v.kerf.string {
            put_u(&mut p, x.as_bytes().len() as u64);
            p.extend_from_slice(x.as_bytes());
        }
        v.head_in
            .iter()
            .chain(&v.head_par)
            .for_each(|&x| put_f(&mut p, x));
        put_u(&mut p, v.disc_par.len() as u64);
        for (a, b) in v.disc_par.iter().zip(&v.disc_in) {
            a.iter().chain(b.iter()).for_each(|&x| put_f(&mut p, x));
        }
        for q in std::iter::once(&s.model.cs_head).chain(&s.model.cs_discs) {
            for x in q.to_array() {
                put_f(&mut p, x);
            }
        }
        s.model.pose_set.iter().for_each(|&b| p.push(u8::from(b)));
        match &s.model.head {
            None => p.push(0),
            Some(h) => {
                p.push(1);
                let b = h.to_bytes();
                put_u(&mut p, b.len() as u64);
                p.extend_from_slice(&b);
            }
        }
        frame(STATE_MAGIC, STATE_VERSION, &p)
    }

    /// Inverse of `encode`, for this head.
    fn decode(&self, bytes: &[u8]) -> Res<HeadSnapshot> {
        let mut r = Reader {
            b: unframe(bytes, STATE_MAGIC, STATE_VERSION, "kerf head FMU state")?,
            at: 0,
        };
        let n = r.u64()? as usize;
        let guid = r.take(n)?;
        if guid != self.guid.as_bytes() {
            return Err("the state belongs to another FMU (GUID)".into());
        }
        let header = read_header(&mut r)?;
        let mut values = self.start_values.clone();
        let expect = |r: &mut Reader, n: usize| -> Res<()> {
            if r.u64()? as usize != n {
                return Err("the state was saved by another build (value count)".into());
            }
            Ok(())
        };
        expect(&mut r, values.kerf.real.len())?;
        for x in values.kerf.real.iter_mut() {
            *x = r.f64()?;
        }
        expect(&mut r, values.kerf.int.len())?;
        for x in values.kerf.int.iter_mut() {
            *x = r.u64()? as i64 as i32;
        }
        expect(&mut r, values.kerf.boolean.len())?;
        for x in values.kerf.boolean.iter_mut() {
            *x = r.u8()? != 0;
        }
        expect(&mut r, values.kerf.string.len())?;
        for x in values.kerf.string.iter_mut() {
            let n = r.u64()? as usize;
            *x = CString::new(r.take(n)?.to_vec()).map_err(|_| "a string with NUL")?;
        }
        for x in values.head_in.iter_mut().chain(values.head_par.iter_mut()) {
            *x = r.f64()?;
        }
        expect(&mut r, values.disc_par.len())?;
        for (a, b) in values.disc_par.iter_mut().zip(values.disc_in.iter_mut()) {
            for x in a.iter_mut().chain(b.iter_mut()) {
                *x = r.f64()?;
            }
        }
        let mut poses = Vec::with_capacity(values.disc_par.len() + 1);
        for _ in 0..=values.disc_par.len() {
            let q = [r.f64()?, r.f64()?, r.f64()?, r.f64()?, r.f64()?, r.f64()?];
            poses.push(Pose::new(q[0], q[1], q[2], q[3], q[4], q[5]));
        }
        let mut pose_set = self.pose_set.clone();
        for b in pose_set.iter_mut() {
            *b = r.u8()? != 0;
        }
        let head = match r.u8()? {
            0 => None,
            1 => {
                let n = r.u64()? as usize;
                let blob = r.take(n)?;
                let params = values
                    .kerf
                    .params(self.resources.as_deref(), Files::MayBeMissing)?;
                Some(
                    HeadState::from_bytes(blob, &params, values.disc_par.len())
                        .map_err(|e| e.to_string())?,
                )
            }
            _ => return Err("bad head flag".into()),
        };
        if r.at != r.b.len() {
            return Err("trailing bytes".into());
        }
        Ok(header.with(HeadSnap {
            values,
            cs_head: poses[0],
            cs_discs: poses[1..].to_vec(),
            pose_set,
            head,
        }))
    }
}

const STATE_MAGIC: &[u8; 8] = b"KERFHFMU";
const STATE_VERSION: u32 = 1;

/// The head manifest in `resources`, if this FMU is a head: (guid, drive,
/// layout).
pub fn head_manifest(resources: Option<&Path>) -> Option<Res<(String, Drive, Layout)>> {
    let path = resources?.join("head.json");
    let text = std::fs::read_to_string(&path).ok()?;
    Some(head_md::read_manifest(&text, &path.display().to_string()))
}
