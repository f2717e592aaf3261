//! Rock chips on a cutterhead (issue 9): cracks from one disc's groove reach
//! the neighbouring tracks' grooves on the shared face, so the ridges
//! between tracks break out and stay bounded while the head bores on.

use kerf::core::head::{default_rock, DiscSpec, Head};
use kerf::core::layout::load;
use kerf::core::{Params, Pose, Twist};

const TAU: f64 = std::f64::consts::TAU;

/// The demo head (layouts/demo-1.2m.json) on its default rock.
fn demo(chipping: bool, seed: i32) -> Head {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("layouts");
    let l = load(&dir.join("demo-1.2m.json")).unwrap();
    let (half, n) = default_rock(&l);
    let mut p = Params::default();
    (p.rock.x_min, p.rock.x_max, p.rock.y_min, p.rock.y_max) = (-half, half, -half, half);
    (p.rock.nx, p.rock.ny) = (n, n);
    p.chipping.enabled = chipping;
    p.chipping.seed = seed;
    Head::new(p, l.cutters.iter().map(DiscSpec::from_layout).collect()).unwrap()
}

/// Crest of every ridge between neighbouring tracks: per ridge, the highest
/// rock across the annulus between the two grooves (1 mm clear of each
/// tip's edge), at `m` angles, as height above the tips' plane `z_tip`.
fn crests(head: &Head, z_tip: f64, m: usize) -> Vec<Vec<f64>> {
    let mut tracks: Vec<(f64, f64)> = head
        .specs()
        .iter()
        .map(|s| (s.mount.track, 0.5 * s.cutter.tip_width))
        .collect();
    tracks.sort_by(|a, b| a.0.total_cmp(&b.0));
    tracks
        .windows(2)
        .map(|w| {
            let (r0, r1) = (w[0].0 + w[0].1 + 0.001, w[1].0 - w[1].1 - 0.001);
            (0..m)
                .map(|k| {
                    let a = TAU * k as f64 / m as f64;
                    let mut top = f64::NEG_INFINITY;
                    let mut r = r0;
                    while r <= r1 {
                        top = top.max(head.map().height(r * a.cos(), r * a.sin()));
                        r += 0.001;
                    }
                    top - z_tip
                })
                .collect()
        })
        .collect()
}

fn stats(v: &[f64]) -> (f64, f64) {
    let mean = v.iter().sum::<f64>() / v.len() as f64;
    let max = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    (mean, max)
}

/// Bores `revs` revolutions from flat rock at 10 rpm and `p_rev` per
/// revolution, `per_rev` steps a revolution; after each revolution, the
/// ridge crests (see [`crests`]).
fn bore(head: &mut Head, p_rev: f64, revs: usize, per_rev: usize) -> Vec<Vec<Vec<f64>>> {
    let w = 10.0 * TAU / 60.0;
    let twist = Twist::new([0.0, 0.0, -p_rev * w / TAU], [0.0, 0.0, w]);
    let h = TAU / w / per_rev as f64;
    let mut pose = Pose::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let mut out = vec![];
    for _ in 0..revs {
        for _ in 0..per_rev {
            pose = head.advance_head(&pose, &twist, h).unwrap();
        }
        out.push(crests(head, pose.position.z, 720));
    }
    out
}

#[test]
#[ignore]
fn explore() {
    for chipping in [true] {
        let mut head = demo(chipping, 1);
        let t0 = std::time::Instant::now();
        let c = bore(&mut head, 0.006, 5, 180);
        eprintln!("chipping {chipping}: {:.1} s", t0.elapsed().as_secs_f64());
        for (k, rev) in c.iter().enumerate() {
            let s: Vec<String> = rev
                .iter()
                .map(|r| {
                    let (m, x) = stats(r);
                    format!("{:.1}/{:.1}", m * 1e3, x * 1e3)
                })
                .collect();
            eprintln!("  rev {}: {}", k + 1, s.join("  "));
        }
        let o = head.state();
        let chips: u64 = o.discs().iter().map(|d| d.chips().count).sum();
        eprintln!(
            "  chips {chips}, excavated {:.4e}",
            o.face().excavated_volume()
        );
    }
}
