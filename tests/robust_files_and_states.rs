//! Issue 11, parts 3-5: files, forged states, host misuse. Each case the
//! issue's fuzzer found to hang or abort the host now returns fmi2Error (or
//! the core's error) promptly; each runs under a watchdog so a regression
//! fails the test instead of hanging the suite.

#[path = "fmi_support.rs"]
mod support;

use std::path::PathBuf;
use std::sync::mpsc;
use std::time::Duration;

use fmi_sys::fmi2::*;
use kerf::core::heightmap::Grid;
use kerf::core::{rsf, KerfError, Model, Params, Pose, Twist};
use kerf::fmi2 as f;
use support::*;

/// Runs `f` on a thread; fails if it takes longer than a minute (a hang).
fn within_a_minute<T: Send + 'static>(what: &str, f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(f());
    });
    rx.recv_timeout(Duration::from_secs(60))
        .unwrap_or_else(|_| panic!("{what}: no answer within 60 s (hangs)"))
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("kerf-robust-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

fn fifo(name: &str) -> PathBuf {
    let p = tmp(name);
    let _ = std::fs::remove_file(&p);
    let ok = std::process::Command::new("mkfifo")
        .arg(&p)
        .status()
        .expect("mkfifo")
        .success();
    assert!(ok, "mkfifo failed");
    p
}

#[test]
fn a_fifo_as_initial_surface_is_refused_without_blocking() {
    let p = fifo("in.fifo");
    let s = p.display().to_string();
    let (status, e) = within_a_minute("exit init with a FIFO", move || {
        let fmu = Fmu::new("robust-fifo", Kind::Cs);
        fmu.small_rock();
        assert_eq!(fmu.set_string(vr::ROCK_INITIAL_SURFACE, &s), OK);
        assert_eq!(fmu.setup(0.0), OK);
        assert_eq!(fmu.enter_init(), OK);
        let st = fmu.exit_init();
        (st, fmu.last_error())
    });
    assert_eq!(status, ERROR);
    assert!(e.contains("not a regular file"), "{e}");
    // and the core's reader on its own
    let g = Grid::new(0.0, 1.0, 0.0, 1.0, 2, 2);
    let r = within_a_minute("rsf::read of a FIFO", move || rsf::read(&p, g, 0.0));
    assert!(matches!(r, Err(KerfError::SurfaceFile { .. })), "{r:?}");
}

#[test]
fn endless_and_overlong_lines_are_refused() {
    let g = Grid::new(0.0, 1.0, 0.0, 1.0, 2, 2);
    for dev in ["/dev/zero", "/dev/urandom"] {
        let r = within_a_minute(dev, move || rsf::read(std::path::Path::new(dev), g, 0.0));
        let e = r.expect_err(dev).to_string();
        assert!(e.contains("not a regular file"), "{e}");
    }
    let p = tmp("long-line.rsf");
    std::fs::write(&p, format!("# {}\n1 1 0 0 0\n", "x".repeat(100_000))).unwrap();
    let e = rsf::read(&p, g, 0.0).unwrap_err().to_string();
    assert!(e.contains("line 1") && e.contains("longer than"), "{e}");
    // a regular file of NULs without a newline: one overlong line
    let p = tmp("zeros.rsf");
    std::fs::write(&p, vec![0u8; 1 << 20]).unwrap();
    let e = rsf::read(&p, g, 0.0).unwrap_err().to_string();
    assert!(e.contains("longer than"), "{e}");
}

/// A face larger than the dense limit is written sparse: only the nodes the
/// cut changed, the grid and the base height in comments. It reads back
/// exactly, and the lines are `L K x y z` numbers (numpy.loadtxt's form).
#[test]
fn a_large_face_is_written_sparse_and_reads_back_exactly() {
    let mut p = Params::default();
    // 2001 x 801 nodes at 0.5 mm: 1.6 million, over the dense limit
    p.rock.x_min = -0.25;
    p.rock.x_max = 0.75;
    p.rock.y_min = -0.2;
    p.rock.y_max = 0.2;
    p.rock.nx = 2001;
    p.rock.ny = 801;
    assert!(p.rock.nx * p.rock.ny > rsf::DENSE_NODES);
    let mut m = Model::new(p.clone()).unwrap();
    let r = p.cutter.radius;
    let tw = Twist::new([1.0, 0.0, 0.0], [0.0, 1.0 / r, 0.0]);
    let mut pose = Pose::new(0.0, 0.0, r - 0.003, 0.0, 0.0, 0.0);
    for _ in 0..20 {
        pose = m.advance(&pose, &tw, 2e-3).unwrap();
    }
    let path = tmp("sparse.rsf");
    m.write_surface(&path).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains("# grid nx=2001 ny=801"), "header");
    assert!(
        text.contains("# sparse: unlisted nodes are at z0 = 0"),
        "header"
    );
    let rows: Vec<Vec<f64>> = text
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| l.split_whitespace().map(|s| s.parse().unwrap()).collect())
        .collect();
    assert!(rows.iter().all(|r| r.len() == 5));
    let g = *m.map().grid();
    let mut changed = 0;
    for j in 0..g.ny {
        for i in 0..g.nx {
            changed += usize::from(m.map().node(i, j) != 0.0);
        }
    }
    assert!(changed > 1000, "the cut changed {changed} nodes");
    assert_eq!(rows.len(), changed, "sparse: one line per changed node");
    let mut p2 = p.clone();
    p2.rock.initial_surface = path.display().to_string();
    let m2 = Model::new(p2).unwrap();
    for j in 0..g.ny {
        for i in 0..g.nx {
            assert_eq!(m.map().node(i, j), m2.map().node(i, j), "node {i} {j}");
        }
    }
    // a sparse file on another base height is an error, not a wrong face
    let mut p3 = p.clone();
    p3.rock.z0 = 0.01;
    p3.rock.initial_surface = path.display().to_string();
    let e = Model::new(p3).err().expect("another z0").to_string();
    assert!(e.contains("rock.z0"), "{e}");
}

/// FNV-1a 64, the serialized state's checksum (an attacker can recompute it).
fn fnv(b: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &x in b {
        h ^= u64::from(x);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

fn reseal(b: &mut [u8]) {
    let n = b.len() - 8;
    let s = fnv(&b[..n]);
    b[n..].copy_from_slice(&s.to_le_bytes());
}

/// Offset of the i32 value of Integer `vr` in a serialized state (the
/// layout of src/fmi2/state.rs).
fn int_offset(vr: u32) -> usize {
    let guid = md_guid_len();
    let reals = kerf::fmi2::md::REALS.len();
    let k = kerf::fmi2::md::INTEGERS
        .iter()
        .position(|v| v.vr == vr)
        .unwrap();
    20 + 4 + guid + 2 + 24 + 2 + 48 + 4 + 8 * reals + 4 + 4 * k
}

fn md_guid_len() -> usize {
    kerf::fmi2::md::GUID.len()
}

#[test]
fn forged_states_are_refused_before_anything_is_built() {
    let fmu = Fmu::new("robust-forged", Kind::Cs);
    fmu.small_rock();
    fmu.init();
    assert_eq!(fmu.do_step(0.0, 0.01), OK);
    let st = fmu.get_state();
    let good = fmu.serialize(st);
    fmu.free_state(st);
    let nx = int_offset(vr::ROCK_NX);
    assert_eq!(&good[nx..nx + 4], &201i32.to_le_bytes(), "layout");
    // a 2^31 x 2^31 grid with a valid checksum
    let mut forged = good.clone();
    let ny = int_offset(vr::ROCK_NY);
    forged[nx..nx + 4].copy_from_slice(&i32::MAX.to_le_bytes());
    forged[ny..ny + 4].copy_from_slice(&i32::MAX.to_le_bytes());
    reseal(&mut forged);
    let c = fmu.c as usize;
    let (s, _) = within_a_minute("deserialize a 2^31 x 2^31 grid", move || {
        let fmu = Fmu {
            c: c as fmi2Component,
            name: "robust-forged".into(),
            kind: Kind::Cs,
        };
        let r = fmu.deserialize(&forged);
        std::mem::forget(fmu);
        (r.0, r.1 as usize)
    });
    assert_eq!(s, ERROR);
    let e = fmu.last_error();
    assert!(e.contains("rock.nx") || e.contains("rock.ny"), "{e}");
    // the good one still restores
    let (s, st) = fmu.deserialize(&good);
    assert_eq!(s, OK, "{:?}", fmu.errors());
    assert_eq!(fmu.set_state(st), OK);
    fmu.free_state(st);
}

/// A state whose rock.initialSurface names /dev/zero restores from the state
/// alone: the file is never opened.
#[test]
fn a_forged_surface_path_in_a_state_is_never_read() {
    let path = tmp("s.rsf");
    {
        let fmu = Fmu::new("robust-devzero-src", Kind::Cs);
        fmu.small_rock();
        assert_eq!(
            fmu.set_string(vr::ROCK_FINAL_SURFACE, path.to_str().unwrap()),
            OK
        );
        fmu.init();
        assert_eq!(fmu.terminate(), OK);
    }
    let fmu = Fmu::new("robust-devzero", Kind::Cs);
    fmu.small_rock();
    let name = path.to_str().unwrap().to_string();
    assert_eq!(fmu.set_string(vr::ROCK_INITIAL_SURFACE, &name), OK);
    fmu.init();
    let st = fmu.get_state();
    let good = fmu.serialize(st);
    fmu.free_state(st);
    // the same length, so the layout holds: "/dev/zero" padded with '/'
    let forged_name = format!("{:/<w$}dev/zero", "/", w = name.len() - 8);
    assert_eq!(forged_name.len(), name.len());
    let mut forged = good.clone();
    let at = good
        .windows(name.len())
        .position(|w| w == name.as_bytes())
        .unwrap();
    forged[at..at + name.len()].copy_from_slice(forged_name.as_bytes());
    reseal(&mut forged);
    let c = fmu.c as usize;
    let s = within_a_minute("restore a state naming /dev/zero", move || {
        let fmu = Fmu {
            c: c as fmi2Component,
            name: "robust-devzero".into(),
            kind: Kind::Cs,
        };
        let (s, st) = fmu.deserialize(&forged);
        let r = if s == OK { fmu.set_state(st) } else { s };
        if s == OK {
            fmu.free_state(st);
        }
        std::mem::forget(fmu);
        r
    });
    assert_eq!(s, OK, "{:?}", fmu.errors());
    assert_eq!(fmu.do_step(0.0, 0.01), OK, "{:?}", fmu.errors());
}

/// nvr far beyond the arrays: the FMU reads the value references one by one
/// and stops at the first bad one, allocating nothing from nvr.
#[test]
fn a_huge_nvr_is_processed_without_allocating_from_it() {
    let fmu = Fmu::new("robust-nvr", Kind::Cs);
    fmu.small_rock();
    fmu.init();
    let huge = 1usize << 40;
    let vrs = [vr::FX, 999_999, 0, 0];
    let mut out = [0.0f64; 4];
    let s = within_a_minute("GetReal nvr 2^40", move || unsafe {
        let c = fmu.c;
        let r = f::fmi2GetReal(c, vrs.as_ptr(), huge, out.as_mut_ptr());
        std::mem::forget(fmu);
        r
    });
    assert_eq!(s, ERROR);
    let fmu = Fmu::new("robust-nvr2", Kind::Cs);
    fmu.small_rock();
    fmu.init();
    let vals = [0.0f64; 4];
    let ints = [0i32; 4];
    let mut bools = [0i32; 4];
    let strs: [fmi2String; 4] = [c"".as_ptr(); 4];
    unsafe {
        assert_eq!(
            f::fmi2SetReal(fmu.c, vrs.as_ptr(), huge, vals.as_ptr()),
            ERROR
        );
        assert_eq!(
            f::fmi2SetInteger(fmu.c, vrs.as_ptr(), huge, ints.as_ptr()),
            ERROR
        );
        assert_eq!(
            f::fmi2SetBoolean(fmu.c, vrs.as_ptr(), huge, ints.as_ptr()),
            ERROR
        );
        assert_eq!(
            f::fmi2GetBoolean(fmu.c, vrs.as_ptr(), huge, bools.as_mut_ptr()),
            ERROR
        );
        assert_eq!(
            f::fmi2SetString(fmu.c, vrs.as_ptr(), huge, strs.as_ptr()),
            ERROR
        );
    }
    // nothing was set
    assert_eq!(fmu.real(vr::X), 0.0);
}

#[test]
fn free_instance_frees_the_states_the_host_left() {
    let fmu = Fmu::new("robust-free", Kind::Cs);
    fmu.small_rock();
    fmu.init();
    let c = fmu.c;
    let a = fmu.get_state();
    let _b = fmu.get_state();
    let bytes = fmu.serialize(a);
    let (s, _c) = fmu.deserialize(&bytes);
    assert_eq!(s, OK);
    assert_eq!(f::fmu_states_of(c), 3);
    fmu.free_state(a);
    assert_eq!(f::fmu_states_of(c), 2);
    // a freed state is recognised, not read
    assert_eq!(fmu.set_state(a), ERROR);
    assert!(
        fmu.last_error().contains("not an FMU state"),
        "{}",
        fmu.last_error()
    );
    drop(fmu); // fmi2FreeInstance
    assert_eq!(f::fmu_states_of(c), 0);
}
