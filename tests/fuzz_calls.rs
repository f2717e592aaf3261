//! The FMI fuzzer of issue 11: deterministic random call sequences through
//! the exported `fmi2...` functions, in process, on stable Rust.
//!
//! Each sequence instantiates Model Exchange or Co-Simulation, mostly walks
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
//! `KERF_FUZZ_SEQUENCES=N` sets the number of sequences (default: 1000 in
//! release builds, as CI runs them, 30 in debug builds), `KERF_FUZZ_SEED=S`
//! the first seed. The long soak is the ignored test:
//! `cargo test --release --test fuzz_calls -- --ignored` (20 000 sequences).

use std::cell::RefCell;
use std::ffi::{c_char, CString};
use std::ptr;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, Once};
use std::time::{Duration, Instant};

use fmi_sys::fmi2::*;
use kerf::fmi2 as f;
use kerf::fmi2::md::{self, vr};

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

// ---- the host ------------------------------------------------------------

#[derive(Default)]
struct Stats {
    sequences: u64,
    calls: u64,
    errors: u64,
    checked_unchanged: u64,
    max_call: Duration,
    max_call_what: String,
    failures: Vec<String>,
}

struct Host<'a> {
    c: fmi2Component,
    me: bool,
    seq: u64,
    rng: Rng,
    states: Vec<fmi2FMUstate>,
    blobs: Vec<Vec<u8>>,
    t: f64,
    dir: &'a std::path::Path,
    stats: &'a mut Stats,
}

extern "C" fn step_finished(_: fmi2ComponentEnvironment, _: fmi2Status) {}

fn instantiate(name: &str, me: bool) -> fmi2Component {
    let cb = Box::leak(Box::new(fmi2CallbackFunctions {
        logger: Some(fmi_sys::fmi2::logger::callback_logger_handler),
        allocateMemory: None,
        freeMemory: None,
        stepFinished: Some(step_finished),
        componentEnvironment: ptr::null_mut(),
    }));
    let name = CString::new(name).unwrap();
    let guid = CString::new(md::GUID).unwrap();
    let kind = if me {
        fmi2Type_fmi2ModelExchange
    } else {
        fmi2Type_fmi2CoSimulation
    };
    unsafe { f::fmi2Instantiate(name.as_ptr(), kind, guid.as_ptr(), ptr::null(), cb, 0, 0) }
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
                "sequence {} {what} {:?}",
                self.seq,
                CALL_ARGS.with(|a| a.borrow().clone())
            );
        }
        let before = self.observe();
        let (errors0, internal0) = tally();
        *CALL_WHAT.lock().unwrap() = format!("sequence {} call {what}", self.seq);
        CALL_START.store(now_ms(), Ordering::SeqCst);
        let t0 = Instant::now();
        let s = f(self);
        let dt = t0.elapsed();
        CALL_START.store(0, Ordering::SeqCst);
        self.stats.calls += 1;
        if std::env::var_os("KERF_FUZZ_TRACE").is_some() {
            eprintln!("  -> {s} in {dt:?}");
        }
        if dt > self.stats.max_call {
            self.stats.max_call = dt;
            self.stats.max_call_what = format!("sequence {} {what}", self.seq);
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
            self.stats
                .failures
                .push(format!("sequence {}: {msg}", self.seq));
        }
    }

    /// The serialized FMU state and the outputs' bits (when readable).
    fn observe(&self) -> (Vec<u8>, Vec<u64>) {
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
        let outs: Vec<u32> = md::REALS
            .iter()
            .filter(|v| v.causality == md::Causality::Output)
            .map(|v| v.vr)
            .collect();
        let mut vals = vec![0.0; outs.len()];
        let st = unsafe { f::fmi2GetReal(c, outs.as_ptr(), outs.len(), vals.as_mut_ptr()) };
        let bits = if st == OK {
            vals.iter().map(|v| v.to_bits()).collect()
        } else {
            Vec::new()
        };
        (bytes, bits)
    }

    fn real_value(&mut self, name: &str, start: f64) -> f64 {
        let r = &mut self.rng;
        match r.below(10) {
            0..=5 => start * r.pick(&[1.0, 1.0, 0.5, 2.0, 0.9, 1.1]),
            6 => r.pick(EXTREME),
            7 => start * r.pick(&[10.0, 0.1, 100.0, 0.01, -1.0]),
            _ => {
                // near the bounds of its row
                match kerf::core::params::bounds(name) {
                    Some((lo, hi)) => r.pick(&[lo, hi, lo * 0.999, hi * 1.001, lo - 1.0]),
                    None => r.range(-2.0, 2.0),
                }
            }
        }
    }

    fn input_value(&mut self, r: u32) -> f64 {
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

    fn set_reals(&mut self) {
        let n = 1 + self.rng.below(3);
        let mut vrs = Vec::new();
        let mut vals = Vec::new();
        for _ in 0..n {
            if self.rng.chance(0.05) {
                vrs.push(self.rng.pick(&[0u32, 9999, u32::MAX]));
                vals.push(1.0);
                continue;
            }
            let v = &md::REALS[self.rng.below(md::REALS.len())];
            let x = match v.causality {
                md::Causality::Input => self.input_value(v.vr),
                _ => self.real_value(v.name, v.start.unwrap_or(1.0)),
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
        let v = &md::INTEGERS[self.rng.below(md::INTEGERS.len())];
        let start = v.start.unwrap_or(1);
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
        let cs = CString::new(s).unwrap();
        let p: *const c_char = if self.rng.chance(0.03) {
            ptr::null()
        } else {
            cs.as_ptr()
        };
        let c = self.c;
        self.call("fmi2SetString", |_| unsafe {
            f::fmi2SetString(c, &r, 1, &p)
        });
    }

    fn get_any(&mut self) {
        let c = self.c;
        match self.rng.below(5) {
            0 => {
                let v = &md::REALS[self.rng.below(md::REALS.len())];
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
                let r = md::INTEGERS[self.rng.below(md::INTEGERS.len())].vr;
                let mut x = 0;
                self.call("fmi2GetInteger", |_| unsafe {
                    f::fmi2GetInteger(c, &r, 1, &mut x)
                });
            }
            2 => {
                let r = md::BOOLEANS[self.rng.below(md::BOOLEANS.len())].vr;
                let mut x = 0;
                self.call("fmi2GetBoolean", |_| unsafe {
                    f::fmi2GetBoolean(c, &r, 1, &mut x)
                });
            }
            3 => {
                let r = md::STRINGS[self.rng.below(md::STRINGS.len())].vr;
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

    /// A host's start: small face, a cutting pose, initialized.
    fn start(&mut self) {
        let c = self.c;
        let small = self.rng.chance(0.9);
        let s = unsafe { f::fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0) };
        assert_eq!(s, OK);
        assert_eq!(unsafe { f::fmi2EnterInitializationMode(c) }, OK);
        if small {
            let vrs = [
                vr::ROCK_X_MIN,
                vr::ROCK_X_MAX,
                vr::ROCK_Y_MIN,
                vr::ROCK_Y_MAX,
            ];
            let vals = [-0.1, 0.3, -0.05, 0.05];
            assert_eq!(
                unsafe { f::fmi2SetReal(c, vrs.as_ptr(), 4, vals.as_ptr()) },
                OK
            );
            let ivrs = [vr::ROCK_NX, vr::ROCK_NY];
            let ivals = [201, 51];
            assert_eq!(
                unsafe { f::fmi2SetInteger(c, ivrs.as_ptr(), 2, ivals.as_ptr()) },
                OK
            );
        }
        if self.rng.chance(0.3) {
            let (r, v) = (vr::CHIPPING_ENABLED, 1);
            assert_eq!(unsafe { f::fmi2SetBoolean(c, &r, 1, &v) }, OK);
        }
        let vrs = [vr::X, vr::Z, vr::VX, vr::WY];
        let vals = [self.rng.range(-0.05, 0.1), R - 0.004, 1.0, 1.0 / R];
        assert_eq!(
            unsafe { f::fmi2SetReal(c, vrs.as_ptr(), 4, vals.as_ptr()) },
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
    let mut stats = Stats::default();
    let t0 = Instant::now();
    for seq in first_seed..first_seed + sequences {
        let mut rng = Rng(seq.wrapping_mul(0x2545_f491_4f6c_dd1d) ^ 0x6b65_7266);
        let me = rng.chance(0.5);
        let calls = 20 + rng.below(120);
        let c = instantiate(&format!("fuzz-{seq}"), me);
        assert!(!c.is_null(), "fmi2Instantiate failed");
        let mut host = Host {
            c,
            me,
            seq,
            rng,
            states: Vec::new(),
            blobs: Vec::new(),
            t: 0.0,
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
    // the fuzzer reached what it is for
    assert!(stats.errors > stats.sequences, "too few errors exercised");
}

/// The long soak: 20 000 sequences (about 3 million calls with the checks).
#[test]
#[ignore]
fn soak() {
    let n = env_u64("KERF_FUZZ_SEQUENCES").unwrap_or(20_000);
    let seed = env_u64("KERF_FUZZ_SEED").unwrap_or(1_000_000);
    let stats = fuzz(seed, n);
    assert!(stats.failures.is_empty(), "{:#?}", stats.failures);
}
