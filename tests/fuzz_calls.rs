//! The FMI fuzzer of issue 11: deterministic random call sequences through
//! the exported `fmi2...` functions, in process, on stable Rust.
//!
//! Each sequence instantiates Model Exchange or Co-Simulation of one of
//! three targets (a [`Target`]: the single-disc kerf.fmu, or, one sequence
//! in four, a small cutterhead FMU, head drive and disc drive in turn), mostly walks
//! the state machine the way a host does (so that it cuts rock), and mixes
//! in everything a host may get wrong: calls out of order, bad and extreme
//! values, odd parameters, NULL pointers, value references that do not
//! exist, FMU states that were freed, corrupt or forged (checksum
//! recomputed), files that are FIFOs, devices or directories.
//!
//! Asserted for every call:
//! * no panic reaches the boundary (the FMU logs "internal error" when its
//!   guard catches one: counted as a failure);
//! * no abort, no hang: a watchdog thread aborts the process with the
//!   sequence and call when one call takes longer than a minute (a generous
//!   bound, not a performance assertion);
//! * every fmi2Error comes with a logged message;
//! * after every fmi2Error the instance is unchanged: its serialized FMU
//!   state and its outputs read back bit for bit as before the call.
//!
//! A head sequence mostly sets plausible boring motion (turning about +z,
//! advancing along -z a few mm per revolution; per disc: each disc's pose
//! and twist on that head), mixed with the extreme values, and sets the
//! head's own parameters (per-disc `cutter[i].*`, `head.steadyPenetration`).
//!
//! `KERF_FUZZ_SEQUENCES=N` sets the number of sequences (default: 1000 in
//! release builds, as CI runs them, 30 in debug builds), `KERF_FUZZ_SEED=S`
//! the first seed; `KERF_FUZZ_TRACE=1` prints every call, its status and
//! the errors it logged. The long soak is the ignored test:
//! `cargo test --release --test fuzz_calls -- --ignored` (20 000 sequences).

use std::cell::RefCell;
use std::collections::BTreeMap;
use std::ffi::{c_char, CString};
use std::path::Path;
use std::ptr;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, Once};
use std::time::{Duration, Instant};

use fmi_sys::fmi2::*;
use kerf::core::head::{place_all, DiscSpec, Drive};
use kerf::core::{layout, params, Pose, Twist};
use kerf::fmi2 as f;
use kerf::fmi2::head_md::{self, Slot, Ty};
use kerf::fmi2::md::{self, vr, Causality};

const OK: fmi2Status = fmi2Status_fmi2OK;
const ERROR: fmi2Status = fmi2Status_fmi2Error;
const R: f64 = 0.2159;

// ---- logger: counts messages per thread, keeps none ----------------------

#[derive(Default)]
struct Tally {
    errors: u64,
    internal: u64,
    last_internal: String,
}

thread_local! {
    /// The arguments of the next traced call (KERF_FUZZ_TRACE).
    static CALL_ARGS: RefCell<String> = const { RefCell::new(String::new()) };
    static TALLY: RefCell<Tally> = RefCell::new(Tally::default());
    /// Set while the host reads the instance back (its errors are not the
    /// call's: KERF_FUZZ_TRACE does not print them).
    static OBSERVING: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

struct FuzzLog;

impl log::Log for FuzzLog {
    fn enabled(&self, _: &log::Metadata) -> bool {
        true
    }
    fn log(&self, r: &log::Record) {
        if r.module_path() != Some("logger") || r.level() != log::Level::Error {
            return;
        }
        TALLY.with(|t| {
            let mut t = t.borrow_mut();
            t.errors += 1;
            let text = r.args().to_string();
            if std::env::var_os("KERF_FUZZ_TRACE").is_some() && !OBSERVING.get() {
                eprintln!("  error: {text}");
            }
            if text.contains("internal error") {
                t.internal += 1;
                t.last_internal = text;
            }
        });
    }
    fn flush(&self) {}
}

static LOG: FuzzLog = FuzzLog;
static INIT: Once = Once::new();

// ---- watchdog ------------------------------------------------------------

/// Milliseconds since `EPOCH` at which the running call started (0: none).
static CALL_START: AtomicU64 = AtomicU64::new(0);
static CALL_WHAT: Mutex<String> = Mutex::new(String::new());
static EPOCH: Mutex<Option<Instant>> = Mutex::new(None);
/// One call may take this long (debug builds run the physics ~30x slower).
const CALL_LIMIT: Duration = Duration::from_secs(if cfg!(debug_assertions) { 600 } else { 60 });

fn now_ms() -> u64 {
    let e = EPOCH.lock().unwrap().expect("epoch");
    e.elapsed().as_millis() as u64 + 1
}

fn setup() {
    INIT.call_once(|| {
        log::set_logger(&LOG).expect("logger");
        log::set_max_level(log::LevelFilter::Trace);
        *EPOCH.lock().unwrap() = Some(Instant::now());
        std::thread::spawn(|| loop {
            std::thread::sleep(Duration::from_millis(500));
            let s = CALL_START.load(Ordering::SeqCst);
            if s != 0 && now_ms().saturating_sub(s) > CALL_LIMIT.as_millis() as u64 {
                eprintln!(
                    "fuzz watchdog: one call ran over {CALL_LIMIT:?}: {}",
                    CALL_WHAT.lock().unwrap()
                );
                std::process::abort();
            }
        });
    });
}

// ---- deterministic random numbers (SplitMix64) ---------------------------

struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    fn chance(&mut self, p: f64) -> bool {
        self.unit() < p
    }
    fn pick<T: Copy>(&mut self, xs: &[T]) -> T {
        xs[self.below(xs.len())]
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
}

const EXTREME: &[f64] = &[
    0.0,
    -0.0,
    -1.0,
    1e-300,
    -1e-300,
    1e-9,
    1e9,
    1e308,
    -1e308,
    f64::MAX,
    f64::MIN_POSITIVE,
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
];

// ---- what the host drives ---------------------------------------------

/// A Real variable as the host sees it.
struct Real {
    name: String,
    vr: u32,
    causality: Causality,
    /// What a careful host sets: the start value, or a plausible one where
    /// the start is an off switch (`head.steadyPenetration`).
    typical: Option<f64>,
    /// The parameter's range (min/max of its row).
    bounds: Option<(f64, f64)>,
    /// A head input: (disc, component) into [`Target::motion_at`] (disc 0
    /// for the head drive); components x y z yaw pitch roll vx vy vz wx wy wz.
    input: Option<(usize, usize)>,
}

/// An Integer or Enumeration variable.
struct Int {
    vr: u32,
    typical: Option<i32>,
}

/// Which FMU a sequence drives.
#[derive(Clone, Copy, PartialEq)]
enum Model {
    /// kerf.fmu: one disc.
    Disc,
    /// A cutterhead FMU of [`Target::head`]'s layout.
    Head(Drive),
}

/// One FMU the fuzzer drives: how to instantiate it, its variables, the
/// small face a host gives it, and how its inputs move.
struct Target {
    label: &'static str,
    model: Model,
    guid: CString,
    /// `file://` URI of the resources folder.
    resources: Option<CString>,
    reals: Vec<Real>,
    integers: Vec<Int>,
    booleans: Vec<u32>,
    strings: Vec<u32>,
    /// The Real outputs, read back before every call and after an fmi2Error.
    outputs: Vec<u32>,
    /// The head's discs (head targets), to place them for the disc drive.
    specs: Vec<DiscSpec>,
    /// A cheap face: rock.xMin/xMax/yMin/yMax and rock.nx/ny.
    small_face: ([u32; 4], [f64; 4], [u32; 2], [i32; 2]),
}

/// The head of the head sequences: three discs on tracks 50-190 mm, the
/// outermost tilted 20 deg (default face 0.58 m square at 1 mm cells).
fn layout_json() -> String {
    r#"{"name": "fuzz", "description": "three discs, the outer one tilted",
  "disc": {"radius": 0.2159, "tipWidth": 0.013, "tipRadius": 0.0127},
  "cutters": [
    {"track": 0.05, "angleDeg": 0, "tiltDeg": 0, "setback": 0, "spacing": 0.07},
    {"track": 0.12, "angleDeg": 137.508, "tiltDeg": 0, "setback": 0, "spacing": 0.07},
    {"track": 0.19, "angleDeg": 275.016, "tiltDeg": 20, "setback": 0, "spacing": 0.07}
  ]}"#
    .into()
}

/// Cells of the head's small face [m] (its default face has 1 mm cells).
const HEAD_CELL: f64 = 0.004;
/// `head.steadyPenetration` is 0 (off) by default; a host that uses it
/// sets a few mm per revolution.
const STEADY: f64 = 0.005;

impl Target {
    /// kerf.fmu, the single-disc FMU (no resources).
    fn disc() -> Self {
        let real = |v: &md::RealVar| Real {
            name: v.name.into(),
            vr: v.vr,
            causality: v.causality,
            typical: v.start,
            bounds: params::bounds(v.name),
            input: None,
        };
        Self {
            label: "disc",
            model: Model::Disc,
            guid: CString::new(md::GUID).unwrap(),
            resources: None,
            reals: md::REALS.iter().map(real).collect(),
            integers: md::INTEGERS
                .iter()
                .map(|v| Int {
                    vr: v.vr,
                    typical: v.start,
                })
                .collect(),
            booleans: md::BOOLEANS.iter().map(|v| v.vr).collect(),
            strings: md::STRINGS.iter().map(|v| v.vr).collect(),
            outputs: md::REALS
                .iter()
                .filter(|v| v.causality == Causality::Output)
                .map(|v| v.vr)
                .collect(),
            specs: Vec::new(),
            small_face: (
                [
                    vr::ROCK_X_MIN,
                    vr::ROCK_X_MAX,
                    vr::ROCK_Y_MIN,
                    vr::ROCK_Y_MAX,
                ],
                [-0.1, 0.3, -0.05, 0.05],
                [vr::ROCK_NX, vr::ROCK_NY],
                [201, 51],
            ),
        }
    }

    /// The head FMU of [`layout_json`] with `drive`, its `head.json`
    /// written to a resources folder in `dir`.
    fn head(drive: Drive, dir: &Path) -> Self {
        let json = layout_json();
        let lay = layout::parse(&json, "fuzz.json").unwrap();
        let (label, guid) = match drive {
            Drive::Head => ("head", "{kerf-fuzz-head-drive}"),
            Drive::Discs => ("discs", "{kerf-fuzz-disc-drive}"),
        };
        let res = dir.join(format!("resources-{label}"));
        std::fs::create_dir_all(&res).unwrap();
        std::fs::write(res.join("head.json"), head_md::manifest(&json, drive, guid)).unwrap();
        let mut t = Self {
            label,
            model: Model::Head(drive),
            guid: CString::new(guid).unwrap(),
            resources: Some(CString::new(format!("file://{}", res.display())).unwrap()),
            reals: Vec::new(),
            integers: Vec::new(),
            booleans: Vec::new(),
            strings: Vec::new(),
            outputs: Vec::new(),
            specs: lay.cutters.iter().map(DiscSpec::from_layout).collect(),
            small_face: ([0; 4], [0.0; 4], [0; 2], [0; 2]),
        };
        for v in head_md::variables(&lay, drive) {
            // the shared parameters' starts are kerf's unless the layout
            // sets them (the rock's extent)
            let md_real = || {
                md::REALS
                    .iter()
                    .find(|x| x.vr == v.vr)
                    .and_then(|x| x.start)
            };
            let md_int = || {
                md::INTEGERS
                    .iter()
                    .find(|x| x.vr == v.vr)
                    .and_then(|x| x.start)
            };
            match v.ty {
                Ty::Real => {
                    if v.causality == Causality::Output {
                        t.outputs.push(v.vr);
                    }
                    let typical = match (v.slot, v.start.as_deref()) {
                        (Slot::HeadParam(_), _) => Some(STEADY),
                        (Slot::Kerf, None) => md_real(),
                        (_, s) => s.map(|s| s.parse().unwrap()),
                    };
                    t.reals.push(Real {
                        bounds: v.min.zip(v.max).or_else(|| params::bounds(&v.name)),
                        input: match v.slot {
                            Slot::HeadInput(k) => Some((0, k)),
                            Slot::DiscInput(i, k) => Some((i, k)),
                            _ => None,
                        },
                        name: v.name,
                        vr: v.vr,
                        causality: v.causality,
                        typical,
                    });
                }
                Ty::Integer | Ty::Enumeration => t.integers.push(Int {
                    vr: v.vr,
                    typical: match v.start.as_deref() {
                        Some(s) => Some(s.parse().unwrap()),
                        None => md_int(),
                    },
                }),
                Ty::Boolean => t.booleans.push(v.vr),
                Ty::String => t.strings.push(v.vr),
            }
        }
        // the default face's extent at coarse cells
        let half = t.real("rock.xMax").typical.unwrap();
        let n = (2.0 * half / HEAD_CELL).round() as i32 + 1;
        t.small_face = (
            [
                vr::ROCK_X_MIN,
                vr::ROCK_X_MAX,
                vr::ROCK_Y_MIN,
                vr::ROCK_Y_MAX,
            ],
            [-half, half, -half, half],
            [vr::ROCK_NX, vr::ROCK_NY],
            [n, n],
        );
        t
    }

    fn real(&self, name: &str) -> &Real {
        self.reals.iter().find(|v| v.name == name).unwrap()
    }

    /// The head's inputs: (value reference, disc, component).
    fn inputs(&self) -> impl Iterator<Item = (u32, usize, usize)> + '_ {
        self.reals
            .iter()
            .filter_map(|v| v.input.map(|(i, k)| (v.vr, i, k)))
    }

    /// The inputs of plausible boring at time `t`: the head turning at `w`
    /// about +z, advancing `p_rev` per revolution along -z from the face
    /// (z = 0); for the disc drive, every disc's pose and twist on that
    /// head. One row per disc (one for the head drive).
    fn motion_at(&self, m: &Motion, t: f64) -> Vec<[f64; 12]> {
        let vz = -m.p_rev * m.w / std::f64::consts::TAU;
        let head = Pose::new(0.0, 0.0, vz * t, m.w * t, 0.0, 0.0);
        let twist = Twist::new([0.0, 0.0, vz], [0.0, 0.0, m.w]);
        let row = |p: &Pose, v: &Twist| {
            let (x, u, w) = (p.position, v.velocity, v.omega);
            [
                x.x, x.y, x.z, p.yaw, p.pitch, p.roll, u.x, u.y, u.z, w.x, w.y, w.z,
            ]
        };
        match self.model {
            Model::Disc => Vec::new(),
            Model::Head(Drive::Head) => vec![row(&head, &twist)],
            Model::Head(Drive::Discs) => place_all(&self.specs, &head, &twist)
                .iter()
                .map(|(p, v)| row(p, v))
                .collect(),
        }
    }
}

/// A head sequence's boring motion: turn rate [rad/s] and advance per
/// revolution [m].
#[derive(Default)]
struct Motion {
    w: f64,
    p_rev: f64,
}

// ---- the host ------------------------------------------------------------

/// Sequences, calls and fmi2Errors of one target, and the sequences in
/// which its rock was cut (excavatedVolume > 0 read back).
#[derive(Default, Debug)]
struct TargetStats {
    sequences: u64,
    calls: u64,
    errors: u64,
    cut: u64,
}

#[derive(Default)]
struct Stats {
    sequences: u64,
    calls: u64,
    errors: u64,
    checked_unchanged: u64,
    max_call: Duration,
    max_call_what: String,
    failures: Vec<String>,
    by_target: BTreeMap<&'static str, TargetStats>,
}

struct Host<'a> {
    c: fmi2Component,
    me: bool,
    seq: u64,
    rng: Rng,
    target: &'a Target,
    motion: Motion,
    states: Vec<fmi2FMUstate>,
    blobs: Vec<Vec<u8>>,
    t: f64,
    /// The largest excavatedVolume read back.
    cut: f64,
    dir: &'a Path,
    stats: &'a mut Stats,
}

extern "C" fn step_finished(_: fmi2ComponentEnvironment, _: fmi2Status) {}

fn instantiate(name: &str, me: bool, target: &Target) -> fmi2Component {
    let cb = Box::leak(Box::new(fmi2CallbackFunctions {
        logger: Some(fmi_sys::fmi2::logger::callback_logger_handler),
        allocateMemory: None,
        freeMemory: None,
        stepFinished: Some(step_finished),
        componentEnvironment: ptr::null_mut(),
    }));
    let name = CString::new(name).unwrap();
    let kind = if me {
        fmi2Type_fmi2ModelExchange
    } else {
        fmi2Type_fmi2CoSimulation
    };
    let res = target
        .resources
        .as_ref()
        .map_or(ptr::null(), |r| r.as_ptr());
    unsafe { f::fmi2Instantiate(name.as_ptr(), kind, target.guid.as_ptr(), res, cb, 0, 0) }
}

fn tally() -> (u64, u64) {
    TALLY.with(|t| {
        let t = t.borrow();
        (t.errors, t.internal)
    })
}

impl Host<'_> {
    /// Runs one FMI call under the watchdog and the checks.
    fn call(&mut self, what: &str, f: impl FnOnce(&mut Self) -> fmi2Status) -> fmi2Status {
        if std::env::var_os("KERF_FUZZ_TRACE").is_some() {
            eprintln!(
                "sequence {} ({}) {what} {:?}",
                self.seq,
                self.target.label,
                CALL_ARGS.with(|a| std::mem::take(&mut *a.borrow_mut()))
            );
        }
        let before = self.observe();
        let (errors0, internal0) = tally();
        *CALL_WHAT.lock().unwrap() =
            format!("sequence {} ({}) call {what}", self.seq, self.target.label);
        CALL_START.store(now_ms(), Ordering::SeqCst);
        let t0 = Instant::now();
        let s = f(self);
        let dt = t0.elapsed();
        CALL_START.store(0, Ordering::SeqCst);
        self.stats.calls += 1;
        let by = self.stats.by_target.entry(self.target.label).or_default();
        by.calls += 1;
        by.errors += u64::from(s == ERROR);
        if std::env::var_os("KERF_FUZZ_TRACE").is_some() {
            eprintln!("  -> {s} in {dt:?}");
        }
        if dt > self.stats.max_call {
            self.stats.max_call = dt;
            self.stats.max_call_what =
                format!("sequence {} ({}) {what}", self.seq, self.target.label);
        }
        let (errors1, internal1) = tally();
        if internal1 != internal0 {
            let msg = TALLY.with(|t| t.borrow().last_internal.clone());
            self.fail(format!("{what}: a panic reached the guard: {msg}"));
        }
        if s == ERROR {
            self.stats.errors += 1;
            if errors1 == errors0 && !self.c.is_null() {
                self.fail(format!("{what}: fmi2Error without a message"));
            }
            let after = self.observe();
            if before != after {
                self.fail(format!("{what}: fmi2Error changed the instance"));
            }
            self.stats.checked_unchanged += 1;
        }
        s
    }

    fn fail(&mut self, msg: String) {
        if self.stats.failures.len() < 50 {
            self.stats.failures.push(format!(
                "sequence {} ({}): {msg}",
                self.seq, self.target.label
            ));
        }
    }

    /// The serialized FMU state and the outputs' bits (when readable).
    fn observe(&mut self) -> (Vec<u8>, Vec<u64>) {
        OBSERVING.set(true);
        let c = self.c;
        let mut s: fmi2FMUstate = ptr::null_mut();
        let mut bytes = Vec::new();
        unsafe {
            if f::fmi2GetFMUstate(c, &mut s) == OK {
                let mut n = 0usize;
                if f::fmi2SerializedFMUstateSize(c, s, &mut n) == OK {
                    bytes = vec![0u8; n];
                    let _ = f::fmi2SerializeFMUstate(c, s, bytes.as_mut_ptr().cast(), n);
                }
                let _ = f::fmi2FreeFMUstate(c, &mut s);
            }
        }
        let outs = &self.target.outputs;
        let mut vals = vec![0.0; outs.len()];
        let st = unsafe { f::fmi2GetReal(c, outs.as_ptr(), outs.len(), vals.as_mut_ptr()) };
        let bits = if st == OK {
            if let Some(k) = outs.iter().position(|&r| r == vr::EXCAVATED_VOLUME) {
                self.cut = self.cut.max(vals[k]);
            }
            vals.iter().map(|v| v.to_bits()).collect()
        } else {
            Vec::new()
        };
        OBSERVING.set(false);
        (bytes, bits)
    }

    /// A value for a parameter (or an output: the host is careless).
    fn real_value(&mut self, v: &Real) -> f64 {
        let start = v.typical.unwrap_or(1.0);
        let r = &mut self.rng;
        match r.below(10) {
            0..=5 => start * r.pick(&[1.0, 1.0, 0.5, 2.0, 0.9, 1.1]),
            6 => r.pick(EXTREME),
            7 => start * r.pick(&[10.0, 0.1, 100.0, 0.01, -1.0]),
            _ => {
                // near the bounds of its row
                match v.bounds {
                    Some((lo, hi)) => r.pick(&[lo, hi, lo * 0.999, hi * 1.001, lo - 1.0]),
                    None => r.range(-2.0, 2.0),
                }
            }
        }
    }

    fn input_value(&mut self, v: &Real) -> f64 {
        match (self.target.model, v.input) {
            (Model::Head(_), Some((i, k))) => self.head_input_value(i, k),
            _ => self.disc_input_value(v.vr),
        }
    }

    /// kerf.fmu's inputs: a disc about to cut, rolling along x, and odd ones.
    fn disc_input_value(&mut self, r: u32) -> f64 {
        let g = &mut self.rng;
        if g.chance(0.05) {
            return g.pick(EXTREME);
        }
        match r {
            vr::X => g.range(-0.3, 0.4),
            vr::Y => g.range(-0.06, 0.06),
            vr::Z => R + g.range(-0.01, 0.01),
            vr::YAW | vr::PITCH | vr::ROLL => g.pick(&[0.0, 0.0, 0.1, -0.3, 1.0, 1e3]),
            vr::VX | vr::VY | vr::VZ => g.pick(&[0.0, 1.0, -1.0, 0.1, 10.0, 1e4]),
            _ => g.pick(&[0.0, 1.0 / R, -1.0 / R, 5.0, 1e4]),
        }
    }

    /// A head input (component `k` of disc `i`): mostly the boring motion
    /// at the host's time, else a little or far off.
    fn head_input_value(&mut self, i: usize, k: usize) -> f64 {
        let m = self.target.motion_at(&self.motion, self.t)[i][k];
        let g = &mut self.rng;
        if g.chance(0.05) {
            return g.pick(EXTREME);
        }
        match g.below(10) {
            0..=5 => m,
            6 => m + g.range(-0.002, 0.002),
            7 => m * g.pick(&[0.0, -1.0, 2.0, 10.0]),
            8 => g.pick(&[0.0, 0.1, -0.3, 1.0, 1e3]),
            _ => m + g.pick(&[1e-9, -1e-9, 0.05, -0.05]),
        }
    }

    /// A head host's SetReal of its inputs: the boring motion at its time
    /// (now and then at a time a little off), all inputs, the poses or the
    /// velocities, one of them extreme now and then.
    fn set_motion(&mut self) {
        let dt = if self.rng.chance(0.1) {
            self.rng.range(-0.01, 0.01)
        } else {
            0.0
        };
        let rows = self.target.motion_at(&self.motion, self.t + dt);
        let part = self.rng.below(4);
        let (mut vrs, mut vals) = (Vec::new(), Vec::new());
        for (r, i, k) in self.target.inputs() {
            if part < 2 || (part == 2) == (k < 6) {
                vrs.push(r);
                vals.push(rows[i][k]);
            }
        }
        if self.rng.chance(0.1) {
            let k = self.rng.below(vals.len());
            vals[k] = self.rng.pick(EXTREME);
        }
        let c = self.c;
        CALL_ARGS.with(|a| *a.borrow_mut() = format!("{vrs:?} = {vals:?}"));
        self.call("fmi2SetReal(motion)", |_| unsafe {
            f::fmi2SetReal(c, vrs.as_ptr(), vrs.len(), vals.as_ptr())
        });
    }

    fn set_reals(&mut self) {
        let head = matches!(self.target.model, Model::Head(_));
        if head && self.rng.chance(0.4) {
            return self.set_motion();
        }
        let target = self.target;
        let n = 1 + self.rng.below(3);
        let mut vrs = Vec::new();
        let mut vals = Vec::new();
        for _ in 0..n {
            if self.rng.chance(0.05) {
                vrs.push(self.rng.pick(&[0u32, 9999, u32::MAX]));
                vals.push(1.0);
                continue;
            }
            // a head has many outputs (per disc): an input, a parameter or
            // any Real
            let class = if head { self.rng.below(10) } else { 9 };
            let some: Vec<&Real> = target
                .reals
                .iter()
                .filter(|v| match class {
                    0..=2 => v.causality == Causality::Input,
                    3..=6 => v.causality == Causality::Parameter,
                    _ => true,
                })
                .collect();
            let v = some[self.rng.below(some.len())];
            let x = match v.causality {
                Causality::Input => self.input_value(v),
                _ => self.real_value(v),
            };
            vrs.push(v.vr);
            vals.push(x);
        }
        let c = self.c;
        CALL_ARGS.with(|a| *a.borrow_mut() = format!("{vrs:?} = {vals:?}"));
        self.call("fmi2SetReal", |_| unsafe {
            f::fmi2SetReal(c, vrs.as_ptr(), vrs.len(), vals.as_ptr())
        });
    }

    fn set_integer(&mut self) {
        let ints = &self.target.integers;
        let v = &ints[self.rng.below(ints.len())];
        let start = v.typical.unwrap_or(1);
        let x = self.rng.pick(&[
            start,
            start,
            start / 2,
            start * 2,
            0,
            1,
            2,
            3,
            -1,
            i32::MAX,
            i32::MIN,
            713_261_102,
            30_001,
        ]);
        let c = self.c;
        let r = v.vr;
        CALL_ARGS.with(|a| *a.borrow_mut() = format!("{r} = {x}"));
        self.call("fmi2SetInteger", |_| unsafe {
            f::fmi2SetInteger(c, &r, 1, &x)
        });
    }

    fn set_string(&mut self) {
        let r = self
            .rng
            .pick(&[vr::ROCK_INITIAL_SURFACE, vr::ROCK_FINAL_SURFACE, 99]);
        let dir = self.dir.display().to_string();
        let s = match self.rng.below(9) {
            0 | 1 => String::new(),
            2 => "/dev/zero".into(),
            3 => "/dev/full".into(),
            4 => format!("{dir}/fifo"),
            5 => dir.clone(),
            6 => format!("{dir}/missing/none.rsf"),
            7 => format!("file://{dir}/out-{}.rsf", self.seq % 4),
            _ => format!("{dir}/out-{}.rsf", self.seq % 4),
        };
        let null = self.rng.chance(0.03);
        CALL_ARGS.with(|a| *a.borrow_mut() = format!("{r} = {}", if null { "NULL" } else { &s }));
        let cs = CString::new(s).unwrap();
        let p: *const c_char = if null { ptr::null() } else { cs.as_ptr() };
        let c = self.c;
        self.call("fmi2SetString", |_| unsafe {
            f::fmi2SetString(c, &r, 1, &p)
        });
    }

    fn get_any(&mut self) {
        let c = self.c;
        match self.rng.below(5) {
            0 => {
                let reals = &self.target.reals;
                let v = &reals[self.rng.below(reals.len())];
                let r = if self.rng.chance(0.05) { 12345 } else { v.vr };
                let mut x = 0.0;
                let null = self.rng.chance(0.03);
                self.call("fmi2GetReal", |_| unsafe {
                    let out = if null {
                        ptr::null_mut()
                    } else {
                        &mut x as *mut f64
                    };
                    f::fmi2GetReal(c, &r, 1, out)
                });
            }
            1 => {
                let ints = &self.target.integers;
                let r = ints[self.rng.below(ints.len())].vr;
                let mut x = 0;
                self.call("fmi2GetInteger", |_| unsafe {
                    f::fmi2GetInteger(c, &r, 1, &mut x)
                });
            }
            2 => {
                let r = self.rng.pick(&self.target.booleans);
                let mut x = 0;
                self.call("fmi2GetBoolean", |_| unsafe {
                    f::fmi2GetBoolean(c, &r, 1, &mut x)
                });
            }
            3 => {
                let r = self.rng.pick(&self.target.strings);
                let mut x: fmi2String = ptr::null();
                self.call("fmi2GetString", |_| unsafe {
                    f::fmi2GetString(c, &r, 1, &mut x)
                });
            }
            _ => {
                let mut x = 0.0;
                self.call("fmi2GetRealStatus", |_| unsafe {
                    f::fmi2GetRealStatus(c, fmi2StatusKind_fmi2LastSuccessfulTime, &mut x)
                });
            }
        }
    }

    fn do_step(&mut self) {
        let c = self.c;
        let mut t = self.t;
        if self.rng.chance(0.05) {
            t = self.rng.pick(EXTREME);
        }
        let h = match self.rng.below(12) {
            0..=5 => self.rng.pick(&[1e-3, 2e-3, 5e-3, 1e-2]),
            6 => 0.0,
            7 => self.rng.pick(&[0.1, 1.0]),
            8 => self.rng.pick(&[1e2, 1e4, 1e6]),
            9 => self.rng.pick(EXTREME),
            _ => self.rng.range(0.0, 0.05),
        };
        let what = format!("fmi2DoStep(t = {t}, h = {h})");
        let s = self.call(&what, |_| unsafe { f::fmi2DoStep(c, t, h, 0) });
        if s == OK {
            self.t = t + h;
        }
    }

    fn me_call(&mut self) {
        let c = self.c;
        match self.rng.below(7) {
            0 => {
                let dt = self.rng.pick(&[1e-3, 1e-2, 0.1, 10.0, -1e-3]);
                let t = if self.rng.chance(0.03) {
                    self.rng.pick(EXTREME)
                } else {
                    self.t + dt
                };
                if self.call("fmi2SetTime", |_| unsafe { f::fmi2SetTime(c, t) }) == OK {
                    self.t = t;
                }
            }
            1 => {
                self.call("fmi2EnterEventMode", |_| unsafe {
                    f::fmi2EnterEventMode(c)
                });
            }
            2 => {
                let mut e: fmi2EventInfo = unsafe { std::mem::zeroed() };
                let null = self.rng.chance(0.03);
                self.call("fmi2NewDiscreteStates", |_| unsafe {
                    let p = if null {
                        ptr::null_mut()
                    } else {
                        &mut e as *mut _
                    };
                    f::fmi2NewDiscreteStates(c, p)
                });
            }
            3 => {
                self.call("fmi2EnterContinuousTimeMode", |_| unsafe {
                    f::fmi2EnterContinuousTimeMode(c)
                });
            }
            4 => {
                let (mut a, mut b) = (0, 0);
                self.call("fmi2CompletedIntegratorStep", |_| unsafe {
                    f::fmi2CompletedIntegratorStep(c, 1, &mut a, &mut b)
                });
            }
            5 => {
                let mut x = [0.0; 4];
                let n = self.rng.pick(&[0usize, 0, 1, 4]);
                self.call("fmi2GetEventIndicators", |_| unsafe {
                    f::fmi2GetEventIndicators(c, x.as_mut_ptr(), n)
                });
            }
            _ => {
                let mut x = [0.0; 4];
                let n = self.rng.pick(&[0usize, 0, 1]);
                self.call("fmi2GetDerivatives", |_| unsafe {
                    f::fmi2GetDerivatives(c, x.as_mut_ptr(), n)
                });
            }
        }
    }

    fn state_call(&mut self) {
        let c = self.c;
        match self.rng.below(6) {
            0 => {
                let mut s: fmi2FMUstate = ptr::null_mut();
                if self.call("fmi2GetFMUstate", |_| unsafe {
                    f::fmi2GetFMUstate(c, &mut s)
                }) == OK
                    && self.states.len() < 6
                {
                    self.states.push(s);
                } else if !s.is_null() {
                    unsafe { f::fmi2FreeFMUstate(c, &mut s) };
                }
            }
            1 if !self.states.is_empty() => {
                let s = self.states[self.rng.below(self.states.len())];
                self.call("fmi2SetFMUstate", |_| unsafe { f::fmi2SetFMUstate(c, s) });
                self.sync_time();
            }
            2 if !self.states.is_empty() => {
                let k = self.rng.below(self.states.len());
                let mut s = self.states.swap_remove(k);
                let keep = s;
                self.call("fmi2FreeFMUstate", |_| unsafe {
                    f::fmi2FreeFMUstate(c, &mut s)
                });
                // a freed state, used again (undefined in FMI 2.0; kerf
                // recognises it)
                if self.rng.chance(0.2) {
                    self.call("fmi2SetFMUstate(freed)", |_| unsafe {
                        f::fmi2SetFMUstate(c, keep)
                    });
                }
            }
            3 if !self.states.is_empty() => {
                let s = self.states[self.rng.below(self.states.len())];
                let mut n = 0usize;
                if unsafe { f::fmi2SerializedFMUstateSize(c, s, &mut n) } == OK {
                    let mut b = vec![0u8; n];
                    if self.call("fmi2SerializeFMUstate", |_| unsafe {
                        f::fmi2SerializeFMUstate(c, s, b.as_mut_ptr().cast(), n)
                    }) == OK
                        && self.blobs.len() < 4
                    {
                        self.blobs.push(b);
                    }
                }
            }
            4 if !self.blobs.is_empty() => {
                let mut b = self.blobs[self.rng.below(self.blobs.len())].clone();
                self.corrupt(&mut b);
                let mut s: fmi2FMUstate = ptr::null_mut();
                if self.call("fmi2DeSerializeFMUstate", |_| unsafe {
                    f::fmi2DeSerializeFMUstate(c, b.as_ptr().cast(), b.len(), &mut s)
                }) == OK
                {
                    if self.rng.chance(0.7) {
                        self.call("fmi2SetFMUstate(deserialized)", |_| unsafe {
                            f::fmi2SetFMUstate(c, s)
                        });
                        self.sync_time();
                    }
                    if self.states.len() < 6 {
                        self.states.push(s);
                    } else {
                        unsafe { f::fmi2FreeFMUstate(c, &mut s) };
                    }
                }
            }
            _ => {
                // NULL and foreign pointers
                let mut junk = [0u64; 8];
                let p = junk.as_mut_ptr().cast::<std::ffi::c_void>();
                match self.rng.below(3) {
                    0 => self.call("fmi2SetFMUstate(NULL)", |_| unsafe {
                        f::fmi2SetFMUstate(c, ptr::null_mut())
                    }),
                    1 => self.call("fmi2SetFMUstate(junk)", |_| unsafe {
                        f::fmi2SetFMUstate(c, p)
                    }),
                    _ => self.call("fmi2GetFMUstate(NULL)", |_| unsafe {
                        f::fmi2GetFMUstate(c, ptr::null_mut())
                    }),
                };
            }
        }
    }

    /// Bit flips, truncation, extension, and forgeries with the checksum
    /// recomputed.
    fn corrupt(&mut self, b: &mut Vec<u8>) {
        match self.rng.below(6) {
            0 => {}
            1 => {
                let k = self.rng.below(b.len());
                b[k] ^= 1 << self.rng.below(8);
            }
            2 => b.truncate(self.rng.below(b.len())),
            3 => b.extend_from_slice(&[0u8; 9]),
            _ => {
                // forged: change bytes in the payload, reseal
                for _ in 0..1 + self.rng.below(3) {
                    let k = 20 + self.rng.below(b.len() - 28);
                    b[k] = self.rng.pick(&[0x00, 0xff, 0x7f, 0x80, 0x01]);
                }
                let n = b.len() - 8;
                let mut h: u64 = 0xcbf2_9ce4_8422_2325;
                for &x in &b[..n] {
                    h ^= u64::from(x);
                    h = h.wrapping_mul(0x0000_0100_0000_01b3);
                }
                b[n..].copy_from_slice(&h.to_le_bytes());
            }
        }
    }

    fn sync_time(&mut self) {
        let mut x = 0.0;
        if unsafe { f::fmi2GetRealStatus(self.c, fmi2StatusKind_fmi2LastSuccessfulTime, &mut x) }
            == OK
        {
            self.t = x;
        }
    }

    fn lifecycle(&mut self) {
        let c = self.c;
        match self.rng.below(6) {
            0 => {
                let t0 = self.rng.pick(&[0.0, 0.0, 1.0, -1.0, f64::NAN]);
                if self.call("fmi2SetupExperiment", |_| unsafe {
                    f::fmi2SetupExperiment(c, 0, 0.0, t0, 0, 0.0)
                }) == OK
                {
                    self.t = t0;
                }
            }
            1 => {
                self.call("fmi2EnterInitializationMode", |_| unsafe {
                    f::fmi2EnterInitializationMode(c)
                });
            }
            2 => {
                self.call("fmi2ExitInitializationMode", |_| unsafe {
                    f::fmi2ExitInitializationMode(c)
                });
            }
            3 => {
                self.call("fmi2Terminate", |_| unsafe { f::fmi2Terminate(c) });
            }
            4 => {
                if self.call("fmi2Reset", |_| unsafe { f::fmi2Reset(c) }) == OK {
                    self.t = 0.0;
                }
            }
            _ => {
                let cats = [c"logEvents".as_ptr(), c"noSuchCategory".as_ptr()];
                let n = self.rng.below(3);
                self.call("fmi2SetDebugLogging", |_| unsafe {
                    f::fmi2SetDebugLogging(c, 1, n, cats.as_ptr())
                });
            }
        }
    }

    /// A host's start: small face, a cutting pose (the head: boring
    /// motion, a steady start now and then), initialized.
    fn start(&mut self) {
        let c = self.c;
        let target = self.target;
        let small = self.rng.chance(0.9);
        let s = unsafe { f::fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0) };
        assert_eq!(s, OK);
        assert_eq!(unsafe { f::fmi2EnterInitializationMode(c) }, OK);
        if small {
            let (vrs, vals, ivrs, ivals) = &target.small_face;
            assert_eq!(
                unsafe { f::fmi2SetReal(c, vrs.as_ptr(), 4, vals.as_ptr()) },
                OK
            );
            assert_eq!(
                unsafe { f::fmi2SetInteger(c, ivrs.as_ptr(), 2, ivals.as_ptr()) },
                OK
            );
        }
        if self.rng.chance(0.3) {
            let (r, v) = (vr::CHIPPING_ENABLED, 1);
            assert_eq!(unsafe { f::fmi2SetBoolean(c, &r, 1, &v) }, OK);
        }
        let (vrs, vals): (Vec<u32>, Vec<f64>) = match target.model {
            Model::Disc => (
                vec![vr::X, vr::Z, vr::VX, vr::WY],
                vec![self.rng.range(-0.05, 0.1), R - 0.004, 1.0, 1.0 / R],
            ),
            Model::Head(_) => {
                if self.rng.chance(0.4) {
                    let (r, p) = (target.real("head.steadyPenetration").vr, self.motion.p_rev);
                    assert_eq!(unsafe { f::fmi2SetReal(c, &r, 1, &p) }, OK);
                }
                let rows = target.motion_at(&self.motion, 0.0);
                target.inputs().map(|(r, i, k)| (r, rows[i][k])).unzip()
            }
        };
        assert_eq!(
            unsafe { f::fmi2SetReal(c, vrs.as_ptr(), vrs.len(), vals.as_ptr()) },
            OK
        );
        // a random parameter or two before exit, as a careless host sets them
        for _ in 0..self.rng.below(3) {
            match self.rng.below(3) {
                0 => self.set_reals(),
                1 => self.set_integer(),
                _ => self.set_string(),
            }
        }
        self.call("fmi2ExitInitializationMode", |_| unsafe {
            f::fmi2ExitInitializationMode(c)
        });
        self.t = 0.0;
    }

    fn run(&mut self, calls: usize) {
        if self.rng.chance(0.85) {
            self.start();
        }
        for _ in 0..calls {
            match self.rng.below(100) {
                0..=29 => {
                    if self.me {
                        self.me_call()
                    } else {
                        self.do_step()
                    }
                }
                30..=39 => self.me_call(), // wrong interface half the time
                40..=44 => self.do_step(),
                45..=59 => self.get_any(),
                60..=71 => self.set_reals(),
                72..=75 => self.set_integer(),
                76..=78 => self.set_string(),
                79..=91 => self.state_call(),
                _ => self.lifecycle(),
            }
        }
        // a NULL component, now and then (no instance, so no logger to
        // tell: fmi2Error is all it can say)
        if self.rng.chance(0.1) {
            let s = unsafe { f::fmi2DoStep(ptr::null_mut(), 0.0, 1e-3, 0) };
            if s != ERROR {
                self.fail(format!("fmi2DoStep(NULL) returned {s}"));
            }
        }
        // the host leaves some states for fmi2FreeInstance to free
        let n = self.rng.below(self.states.len() + 1);
        for mut s in self.states.drain(..n) {
            unsafe { f::fmi2FreeFMUstate(self.c, &mut s) };
        }
        unsafe { f::fmi2FreeInstance(self.c) };
        self.stats.sequences += 1;
        let by = self.stats.by_target.entry(self.target.label).or_default();
        by.sequences += 1;
        by.cut += u64::from(self.cut > 0.0);
    }
}

fn fuzz(first_seed: u64, sequences: u64) -> Stats {
    setup();
    let dir = std::env::temp_dir().join(format!("kerf-fuzz-{}-{first_seed}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let fifo = dir.join("fifo");
    if !fifo.exists() {
        let ok = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .map(|s| s.success())
            .unwrap_or(false);
        assert!(ok, "mkfifo");
    }
    let targets = [
        Target::disc(),
        Target::head(Drive::Head, &dir),
        Target::head(Drive::Discs, &dir),
    ];
    let mut stats = Stats::default();
    let t0 = Instant::now();
    for seq in first_seed..first_seed + sequences {
        // one sequence in four drives a head, the head and the disc drive
        // in turn
        let target = match (seq % 4, seq / 4 % 2) {
            (0, 0) => &targets[1],
            (0, _) => &targets[2],
            _ => &targets[0],
        };
        let mut rng = Rng(seq.wrapping_mul(0x2545_f491_4f6c_dd1d) ^ 0x6b65_7266);
        let me = rng.chance(0.5);
        let calls = 20 + rng.below(120);
        let motion = match target.model {
            Model::Disc => Motion::default(),
            Model::Head(_) => Motion {
                w: rng.range(0.3, 3.0),
                p_rev: rng.range(0.002, 0.01),
            },
        };
        let c = instantiate(&format!("fuzz-{seq}"), me, target);
        assert!(!c.is_null(), "fmi2Instantiate failed");
        let mut host = Host {
            c,
            me,
            seq,
            rng,
            target,
            motion,
            states: Vec::new(),
            blobs: Vec::new(),
            t: 0.0,
            cut: 0.0,
            dir: &dir,
            stats: &mut stats,
        };
        host.run(calls);
        assert_eq!(
            f::fmu_states_of(c),
            0,
            "sequence {seq}: states left after FreeInstance"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
    eprintln!(
        "fuzz: seeds {first_seed}..{}: {} sequences, {} calls ({} fmi2Error, each checked unchanged), \
         {} failures, longest call {:?} ({}), total {:?}",
        first_seed + sequences,
        stats.sequences,
        stats.calls,
        stats.checked_unchanged,
        stats.failures.len(),
        stats.max_call,
        stats.max_call_what,
        t0.elapsed()
    );
    for (label, t) in &stats.by_target {
        eprintln!(
            "fuzz: {label}: {} sequences ({} cut rock), {} calls, {} fmi2Error",
            t.sequences, t.cut, t.calls, t.errors
        );
    }
    stats
}

fn env_u64(name: &str) -> Option<u64> {
    std::env::var(name).ok().and_then(|s| s.parse().ok())
}

#[test]
fn random_call_sequences_never_crash_hang_or_half_change() {
    let default = if cfg!(debug_assertions) { 30 } else { 1000 };
    let n = env_u64("KERF_FUZZ_SEQUENCES").unwrap_or(default);
    let seed = env_u64("KERF_FUZZ_SEED").unwrap_or(1);
    let stats = fuzz(seed, n);
    assert!(stats.failures.is_empty(), "{:#?}", stats.failures);
    // the fuzzer reached what it is for: errors, and rock cut by every
    // target (each sequence in four is a head, in turn by head and by disc
    // drive)
    assert!(stats.errors > stats.sequences, "too few errors exercised");
    if n >= 200 {
        for label in ["disc", "head", "discs"] {
            let t = &stats.by_target[label];
            assert!(t.cut * 4 > t.sequences, "{label}: too few cut rock: {t:?}");
        }
    }
}

/// The long soak: 20 000 sequences (about 3 million calls with the checks).
#[test]
#[ignore = "slow (the long soak, 20 000 sequences): cargo test --release --test fuzz_calls -- --ignored"]
fn soak() {
    let n = env_u64("KERF_FUZZ_SEQUENCES").unwrap_or(20_000);
    let seed = env_u64("KERF_FUZZ_SEED").unwrap_or(1_000_000);
    let stats = fuzz(seed, n);
    assert!(stats.failures.is_empty(), "{:#?}", stats.failures);
}
