//! The serialized form of an FMU state (fmi2SerializeFMUstate).
//!
//! ```text
//! "KERFFMU\0"            8 bytes  magic
//! version                u32 LE   (1)
//! payload length         u64 LE
//! payload                         fields below, each written explicitly
//! checksum               u64 LE   FNV-1a 64 of everything before it
//! ```
//!
//! Payload: GUID (u32 length + bytes), kind u8, mode u8, startTime,
//! time, lastCommitTime (f64), eventCommitted u8, poseInputsSet u8, the
//! Co-Simulation pose (6 f64: x y z yaw pitch roll), the values (u32 count +
//! f64 each for Reals, u32 count + i32 each for Integers, u32 count + u8 each
//! for Booleans, u32 count + (u32 length + bytes) for Strings, all in
//! value-reference order), then u8 hasModel and, if 1, u64 length + the
//! core's `ModelState::to_bytes`. All numbers little-endian.

use std::ffi::CString;
use std::path::Path;

use crate::core::{ModelState, Pose};

use super::generic;
use super::instance::{DiscSnap, Files, Kind, Mode, Res, Snapshot, Values};
use super::md;

const MAGIC: &[u8; 8] = b"KERFFMU\0";
const VERSION: u32 = 1;
const HEADER: usize = 8 + 4 + 8;

/// FNV-1a, 64 bit.
pub fn fnv1a64(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

pub fn encode(s: &Snapshot) -> Vec<u8> {
    let mut p = Vec::new();
    put_bytes(&mut p, md::GUID.as_bytes());
    put_header(&mut p, &s.header);
    p.push(u8::from(s.model.pose_inputs_set));
    for v in s.model.cs_pose.to_array() {
        p.extend_from_slice(&v.to_le_bytes());
    }
    put_u32(&mut p, s.model.values.real.len());
    s.model
        .values
        .real
        .iter()
        .for_each(|v| p.extend_from_slice(&v.to_le_bytes()));
    put_u32(&mut p, s.model.values.int.len());
    s.model
        .values
        .int
        .iter()
        .for_each(|v| p.extend_from_slice(&v.to_le_bytes()));
    put_u32(&mut p, s.model.values.boolean.len());
    s.model
        .values
        .boolean
        .iter()
        .for_each(|v| p.push(u8::from(*v)));
    put_u32(&mut p, s.model.values.string.len());
    s.model
        .values
        .string
        .iter()
        .for_each(|v| put_bytes(&mut p, v.as_bytes()));
    match &s.model.model {
        None => p.push(0),
        Some(m) => {
            p.push(1);
            let b = m.to_bytes();
            p.extend_from_slice(&(b.len() as u64).to_le_bytes());
            p.extend_from_slice(&b);
        }
    }

    frame(MAGIC, VERSION, &p)
}

/// The instance's part of a state (after the GUID): interface type, mode,
/// start time, time, last commit time, event committed.
pub fn put_header(p: &mut Vec<u8>, s: &generic::Header) {
    p.push(match s.kind {
        Kind::ModelExchange => 0,
        Kind::CoSimulation => 1,
    });
    p.push(s.mode.to_u8());
    for v in [s.start_time, s.time, s.last_commit_time] {
        p.extend_from_slice(&v.to_le_bytes());
    }
    p.push(u8::from(s.event_committed));
}

/// Inverse of [`put_header`].
pub fn read_header(r: &mut Reader) -> Res<generic::Header> {
    let kind = match r.u8()? {
        0 => Kind::ModelExchange,
        1 => Kind::CoSimulation,
        v => return Err(format!("unknown interface type {v}")),
    };
    let mode = Mode::from_u8(r.u8()?)
        .filter(|m| m.fits(kind))
        .ok_or("invalid mode")?;
    Ok(generic::Header {
        kind,
        mode,
        start_time: r.f64()?,
        time: r.f64()?,
        last_commit_time: r.f64()?,
        event_committed: r.flag("eventCommitted")?,
    })
}

/// The frame of every kerf FMU state (single disc or head): magic, format
/// version, payload length, payload, FNV-1a checksum of all before it.
pub fn frame(magic: &[u8; 8], version: u32, payload: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(HEADER + payload.len() + 8);
    out.extend_from_slice(magic);
    out.extend_from_slice(&version.to_le_bytes());
    out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    out.extend_from_slice(payload);
    let sum = fnv1a64(&out);
    out.extend_from_slice(&sum.to_le_bytes());
    out
}

/// The payload of a [`frame`]d state, after checking its size, magic,
/// version, length and checksum; `what` names the state in the errors
/// ("kerf FMU state").
pub fn unframe<'a>(bytes: &'a [u8], magic: &[u8; 8], version: u32, what: &str) -> Res<&'a [u8]> {
    if bytes.len() < HEADER + 8 {
        return Err(format!("{} bytes is too short for a {what}", bytes.len()));
    }
    if &bytes[..8] != magic {
        return Err(format!("not a {what} (wrong magic)"));
    }
    let v = u32::from_le_bytes(bytes[8..12].try_into().unwrap());
    if v != version {
        return Err(format!(
            "{what} version {v}; this FMU reads version {version}"
        ));
    }
    let len = u64::from_le_bytes(bytes[12..20].try_into().unwrap());
    if len != (bytes.len() - HEADER - 8) as u64 {
        return Err(format!(
            "the state's payload length {len} does not match its size ({} bytes): truncated or padded",
            bytes.len()
        ));
    }
    let body = &bytes[..bytes.len() - 8];
    let sum = u64::from_le_bytes(bytes[bytes.len() - 8..].try_into().unwrap());
    if fnv1a64(body) != sum {
        return Err("checksum mismatch: the state is corrupt".into());
    }
    Ok(&body[HEADER..])
}

fn put_u32(p: &mut Vec<u8>, n: usize) {
    p.extend_from_slice(&(n as u32).to_le_bytes());
}

fn put_bytes(p: &mut Vec<u8>, b: &[u8]) {
    put_u32(p, b.len());
    p.extend_from_slice(b);
}

/// Little-endian reader of a state blob, for the single-disc and the head
/// FMU's states alike.
pub(crate) struct Reader<'a> {
    pub(crate) b: &'a [u8],
    pub(crate) at: usize,
}

impl<'a> Reader<'a> {
    pub(crate) fn take(&mut self, n: usize) -> Res<&'a [u8]> {
        let end = self
            .at
            .checked_add(n)
            .filter(|&e| e <= self.b.len())
            .ok_or("the state is truncated")?;
        let s = &self.b[self.at..end];
        self.at = end;
        Ok(s)
    }
    pub(crate) fn u8(&mut self) -> Res<u8> {
        Ok(self.take(1)?[0])
    }
    pub(crate) fn flag(&mut self, what: &str) -> Res<bool> {
        match self.u8()? {
            0 => Ok(false),
            1 => Ok(true),
            v => Err(format!("{what} = {v} is not a boolean")),
        }
    }
    pub(crate) fn u32(&mut self) -> Res<u32> {
        Ok(u32::from_le_bytes(self.take(4)?.try_into().unwrap()))
    }
    pub(crate) fn u64(&mut self) -> Res<u64> {
        Ok(u64::from_le_bytes(self.take(8)?.try_into().unwrap()))
    }
    pub(crate) fn f64(&mut self) -> Res<f64> {
        Ok(f64::from_le_bytes(self.take(8)?.try_into().unwrap()))
    }
    pub(crate) fn i32(&mut self) -> Res<i32> {
        Ok(i32::from_le_bytes(self.take(4)?.try_into().unwrap()))
    }
    pub(crate) fn bytes(&mut self) -> Res<&'a [u8]> {
        let n = self.u32()? as usize;
        self.take(n)
    }
    pub(crate) fn count(&mut self, what: &str, want: usize) -> Res<()> {
        let n = self.u32()? as usize;
        if n == want {
            Ok(())
        } else {
            Err(format!("the state has {n} {what} values, this FMU {want}"))
        }
    }
}

/// Parses and checks a serialized state completely; `resources` resolves the
/// surface paths of the parameters it holds (the core checks its own blob
/// against them).
pub fn decode(bytes: &[u8], resources: Option<&Path>) -> Res<Snapshot> {
    let mut r = Reader {
        b: unframe(bytes, MAGIC, VERSION, "kerf FMU state")?,
        at: 0,
    };
    if r.bytes()? != md::GUID.as_bytes() {
        return Err("the state belongs to another FMU (GUID differs)".into());
    }
    let header = read_header(&mut r)?;
    let pose_inputs_set = r.flag("poseInputsSet")?;
    let mut q = [0.0; 6];
    for v in &mut q {
        *v = r.f64()?;
    }
    let cs_pose = Pose::new(q[0], q[1], q[2], q[3], q[4], q[5]);
    if ![header.start_time, header.time, header.last_commit_time]
        .iter()
        .chain(q.iter())
        .all(|v| v.is_finite())
    {
        return Err("non-finite time or pose".into());
    }

    let mut values = Values::start();
    r.count("Real", values.real.len())?;
    for v in &mut values.real {
        *v = r.f64()?;
        if !v.is_finite() {
            return Err("a non-finite Real value".into());
        }
    }
    r.count("Integer", values.int.len())?;
    for (v, var) in values.int.iter_mut().zip(md::INTEGERS) {
        *v = r.i32()?;
        if var.items.is_some_and(|items| !items.contains(v)) {
            return Err(format!(
                "{} = {v} is not an item of its enumeration",
                var.name
            ));
        }
    }
    r.count("Boolean", values.boolean.len())?;
    for v in &mut values.boolean {
        *v = r.flag("a Boolean value")?;
    }
    r.count("String", values.string.len())?;
    for (v, var) in values.string.iter_mut().zip(md::STRINGS) {
        let b = r.bytes()?;
        if std::str::from_utf8(b).is_err() {
            return Err(format!("the value of {} is not UTF-8", var.name));
        }
        *v = CString::new(b).map_err(|_| format!("the value of {} holds a NUL", var.name))?;
    }
    let model = if r.flag("hasModel")? {
        let n = usize::try_from(r.u64()?).map_err(|_| "model state too large")?;
        let blob = r.take(n)?;
        let params = values.params(resources, Files::MayBeMissing)?;
        // the parameters bound the grid the blob may describe: checked
        // before anything is built from them
        params.validate().map_err(|e| e.to_string())?;
        Some(ModelState::from_bytes(blob, &params).map_err(|e| e.to_string())?)
    } else {
        if !matches!(header.mode, Mode::Instantiated | Mode::InitializationMode) {
            return Err("an initialized state without the model's state".into());
        }
        None
    };
    if r.at != r.b.len() {
        return Err(format!(
            "{} unexpected bytes after the state",
            r.b.len() - r.at
        ));
    }
    Ok(header.with(DiscSnap {
        values,
        cs_pose,
        pose_inputs_set,
        model,
    }))
}
