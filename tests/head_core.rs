//! The cutterhead core: placement and free rolling, totals, both drives,
//! discs sharing one face, thread-count independence, state replay.

use kerf::core::head::{advance_rigid, DiscSpec, Drive, Head, HeadOutputs, Mount};
use kerf::core::params::CutterParams;
use kerf::core::{Model, Params, Pose, Twist};
use nalgebra::Vector3;

fn disc(track: f64, angle_deg: f64, tilt_deg: f64) -> DiscSpec {
    DiscSpec {
        mount: Mount {
            track,
            angle: angle_deg.to_radians(),
            tilt: tilt_deg.to_radians(),
            setback: 0.0,
        },
        cutter: CutterParams::default(),
        spacing: 0.08,
    }
}

/// A face square of half side `half` m at 1 mm cells.
fn params(half: f64) -> Params {
    let mut p = Params::default();
    let n = (2.0 * half * 1000.0).round() as usize + 1;
    p.rock.x_min = -half;
    p.rock.x_max = half;
    p.rock.y_min = -half;
    p.rock.y_max = half;
    p.rock.nx = n;
    p.rock.ny = n;
    p
}

/// Runs a head at `rpm`-like angular speed `w` [rad/s], advancing `p_rev`
/// per revolution, for `revs` revolutions in CS steps of `h`; returns the
/// outputs after every step.
fn bore(head: &mut Head, w: f64, p_rev: f64, revs: f64, h: f64) -> (Vec<HeadOutputs>, Pose) {
    let twist = Twist::boring(w, p_rev);
    let mut pose = Pose::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let steps = (revs * 2.0 * std::f64::consts::PI / w / h).round() as usize;
    let mut out = Vec::with_capacity(steps);
    for _ in 0..steps {
        pose = head.advance_head(&pose, &twist, h).unwrap();
        out.push(head.evaluate_head(&pose, &twist).unwrap());
    }
    (out, pose)
}

#[test]
fn mounts_follow_the_contract_frame() {
    // a disc at angle 90 deg, tilted 30 deg: tip at (0, t, 0); cutter x =
    // e_t = (-1, 0, 0); cutter z = cos g z - sin g e_r
    let s = disc(1.0, 90.0, 30.0);
    let f = s.mount.frame();
    let g = 30f64.to_radians();
    let ex = Vector3::new(-1.0, 0.0, 0.0);
    let ez = Vector3::new(0.0, -g.sin(), g.cos());
    assert!((f.column(0) - ex).norm() < 1e-15);
    assert!((f.column(2) - ez).norm() < 1e-15);
    assert!((f.column(1) - ez.cross(&ex)).norm() < 1e-15);
    assert!((s.mount.tip() - Vector3::new(0.0, 1.0, 0.0)).norm() < 1e-15);
    let c = s.centre();
    assert!((c - (Vector3::new(0.0, 1.0, 0.0) + ez * 0.2159)).norm() < 1e-15);
}

#[test]
fn discs_roll_freely_their_tips_do_not_slip() {
    let head = Head::new(
        params(1.0),
        vec![
            disc(0.5, 0.0, 0.0),
            disc(0.7, 120.0, 20.0),
            disc(0.3, 250.0, -10.0),
        ],
    )
    .unwrap();
    let pose = Pose::new(0.01, -0.02, 0.003, 0.3, 0.01, -0.02);
    let twist = Twist::new([0.01, 0.02, -0.003], [0.001, -0.002, 0.4]);
    for ((p, t), s) in head.place(&pose, &twist).iter().zip(head.specs()) {
        let rot = p.rotation();
        let tip = p.position - rot * Vector3::z() * s.cutter.radius;
        // velocity of the disc's material point at the tip: no slip along cutter x
        let v_tip = t.velocity + t.omega.cross(&(tip - p.position));
        assert!(v_tip.dot(&(rot * Vector3::x())).abs() < 1e-14, "{v_tip}");
        // the centre moves with the head as a rigid body
        let v_c = twist.velocity + twist.omega.cross(&(p.position - pose.position));
        assert!((t.velocity - v_c).norm() < 1e-15);
    }
    // rolling straight at v: spin v / R about +y, as kerf.fmu's convention
    let one = Head::new(params(1.0), vec![disc(0.5, 0.0, 0.0)]).unwrap();
    let (_, t) = one.place(
        &Pose::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
        &Twist::new([0.0, 1.0, 0.0], [0.0; 3]),
    )[0];
    // disc at angle 0 rolls along e_t = +y: cutter y = z x x = -x (rock)
    assert!(
        (t.omega - Vector3::new(-1.0 / 0.2159, 0.0, 0.0)).norm() < 1e-12,
        "{}",
        t.omega
    );
}

fn small_head() -> Head {
    Head::new(
        params(0.75),
        vec![
            disc(0.10, 0.0, 0.0),
            disc(0.25, 100.0, 0.0),
            disc(0.40, 200.0, 0.0),
            disc(0.55, 300.0, 15.0),
        ],
    )
    .unwrap()
}

#[test]
fn totals_are_the_sums_over_the_discs() {
    let mut head = small_head();
    let (out, pose) = bore(&mut head, 1.0, 0.004, 0.3, 0.01);
    let twist = Twist::new(
        [0.0, 0.0, -0.004 / (2.0 * std::f64::consts::PI)],
        [0.0, 0.0, 1.0],
    );
    let o = head.evaluate_head(&pose, &twist).unwrap();
    assert_eq!(&o, out.last().unwrap());
    let motions = head.place(&pose, &twist);
    let mut f = Vector3::zeros();
    let mut m = Vector3::zeros();
    let mut loaded = 0;
    for (d, (p, _)) in o.discs.iter().zip(&motions) {
        let fd = Vector3::from(d.force);
        f += fd;
        m += Vector3::from(d.moment) + (p.position - pose.position).cross(&fd);
        loaded += (d.normal_force > 1e3) as usize;
    }
    assert!(loaded >= 3, "only {loaded} discs carry load");
    let tol = 1e-9 * f.norm().max(1.0);
    assert!((Vector3::from(o.force) - f).norm() < tol);
    assert!((Vector3::from(o.moment) - m).norm() < tol * 10.0);
    let axis = pose.rotation() * Vector3::z();
    assert!((o.thrust - f.dot(&axis)).abs() < tol);
    assert!((o.torque + m.dot(&axis)).abs() < tol * 10.0);
    // boring: the rock pushes the head back and resists its turning
    assert!(
        o.thrust > 0.0 && o.torque > 0.0,
        "{} {}",
        o.thrust,
        o.torque
    );
    assert!(o.excavated_volume > 0.0 && o.cutting_energy > 0.0);
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut head = small_head();
            let (out, _) = bore(&mut head, 1.0, 0.004, 0.1, 0.01);
            (out, head.state().to_bytes())
        })
    };
    let (a, sa) = run(1);
    let (b, sb) = run(4);
    assert_eq!(sa, sb, "faces differ");
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(&b) {
        for (p, q) in x.discs.iter().zip(&y.discs) {
            for k in 0..3 {
                assert_eq!(p.force[k].to_bits(), q.force[k].to_bits());
                assert_eq!(p.moment[k].to_bits(), q.moment[k].to_bits());
            }
        }
        assert_eq!(x.thrust.to_bits(), y.thrust.to_bits());
        assert_eq!(x.torque.to_bits(), y.torque.to_bits());
    }
}

#[test]
fn head_drive_and_disc_drive_agree() {
    // the same motion: the disc drive is fed the placed discs at the start
    // of every step; Model Exchange commits are then identical, and swept
    // steps differ only by chord against arc over one step
    let w = 1.0;
    let twist = Twist::new(
        [0.0, 0.0, -0.004 / (2.0 * std::f64::consts::PI)],
        [0.0, 0.0, w],
    );
    let (mut a, mut b) = (small_head(), small_head());
    let mut pose = Pose::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let h = 0.01;
    for _ in 0..40 {
        let m = a.place(&pose, &twist);
        a.commit(&m, h).unwrap();
        b.commit(&m, h).unwrap();
        pose = advance_rigid(&pose, &twist, h);
    }
    let m = a.place(&pose, &twist);
    let oa = a.evaluate_head(&pose, &twist).unwrap();
    let ob = b.evaluate_discs(&m).unwrap();
    for (x, y) in oa.discs.iter().zip(&ob.discs) {
        assert_eq!(x, y);
    }
    assert_eq!(oa.thrust.to_bits(), ob.thrust.to_bits()); // head z = rock z here
    assert_eq!(oa.excavated_volume, ob.excavated_volume);

    let (mut a, mut b) = (small_head(), small_head());
    let mut pose = Pose::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    for _ in 0..60 {
        let m = a.place(&pose, &twist);
        a.advance_head(&pose, &twist, h).unwrap();
        b.advance_discs(&m, h).unwrap();
        pose = advance_rigid(&pose, &twist, h);
    }
    let m = a.place(&pose, &twist);
    let oa = a.evaluate_head(&pose, &twist).unwrap();
    let ob = b.evaluate_discs(&m).unwrap();
    let rel = (oa.thrust - ob.thrust).abs() / oa.thrust;
    assert!(
        oa.thrust > 1e4 && rel < 0.02,
        "{} vs {}",
        oa.thrust,
        ob.thrust
    );
    let rel = (oa.excavated_volume - ob.excavated_volume).abs() / oa.excavated_volume;
    assert!(
        rel < 0.02,
        "{} vs {}",
        oa.excavated_volume,
        ob.excavated_volume
    );
}

/// A head of one disc at the head origin and kerf.fmu's Model of the same
/// disc, rock and parameters.
fn one_disc_head_and_model() -> (Head, Model) {
    let p = params(0.4);
    let mut spec = disc(0.0, 0.0, 0.0);
    spec.cutter = p.cutter;
    spec.spacing = p.csm.spacing;
    (
        Head::new(p.clone(), vec![spec]).unwrap(),
        Model::new(p).unwrap(),
    )
}

#[test]
fn one_disc_head_is_kerf_model() {
    // a one-disc head in the disc drive is kerf.fmu's Model, bit for bit
    let (mut head, mut model) = one_disc_head_and_model();
    let mut pose = Pose::new(-0.2, 0.0, 0.2121, 0.0, 0.0, 0.0);
    let twist = Twist::new([1.0, 0.0, 0.0], [0.0, 1.0 / 0.2159, 0.0]);
    for _ in 0..50 {
        let end = model.advance(&pose, &twist, 0.002).unwrap();
        let ends = head.advance_discs(&[(pose, twist)], 0.002).unwrap();
        assert_eq!(end, ends[0]);
        let om = model.evaluate(&end, &twist).unwrap();
        let oh = head.evaluate_discs(&[(end, twist)]).unwrap();
        assert_eq!(om.force, oh.discs[0].force);
        assert_eq!(om.cutting_energy, oh.cutting_energy);
        assert_eq!(om.excavated_volume, oh.excavated_volume);
        pose = end;
    }
}

/// A braked disc (spinning at half its rolling speed) in the disc drive
/// ([`Head::spun_by_host`]) is kerf.fmu's Model bit for bit, friction along
/// its path included: the host's spin counts, as the contract's per-disc
/// inputs say. The head drive's freely turning disc takes up that slip
/// itself and feels less rolling force by the friction of it (mu 0.3 of
/// the rim force, near full sliding at 50 % slip).
#[test]
fn a_braked_disc_in_the_disc_drive_feels_the_friction_kerf_fmu_gives_it() {
    let (head, mut model) = one_disc_head_and_model();
    let mut head = head.spun_by_host();
    let (mut free, _) = one_disc_head_and_model();
    let mut pose = Pose::new(-0.2, 0.0, 0.2121, 0.0, 0.0, 0.0);
    let twist = Twist::new([1.0, 0.0, 0.0], [0.0, 0.5 / 0.2159, 0.0]);
    for _ in 0..30 {
        let end = model.advance(&pose, &twist, 0.002).unwrap();
        let ends = head.advance_discs(&[(pose, twist)], 0.002).unwrap();
        free.advance_discs(&[(pose, twist)], 0.002).unwrap();
        assert_eq!(end, ends[0]);
        let om = model.evaluate(&end, &twist).unwrap();
        let oh = head.evaluate_discs(&[(end, twist)]).unwrap();
        assert_eq!(om.force, oh.discs[0].force);
        assert_eq!(om.moment, oh.discs[0].moment);
        assert_eq!(om.cutting_energy, oh.cutting_energy);
        let of = free.evaluate_discs(&[(end, twist)]).unwrap();
        let (braked, rolled) = (oh.discs[0].rolling_force, of.discs[0].rolling_force);
        let rim = of.discs[0].normal_force.hypot(rolled);
        assert!(
            (braked - rolled - 0.3 * rim).abs() < 0.02 * rim,
            "braked {braked}, turning freely {rolled}, rim force {rim}"
        );
        pose = end;
    }
}

/// The same in Model Exchange: a one-disc head's commits are kerf.fmu's,
/// the cutting energy included (the trapezoid between the outputs after the
/// last commit and after this one), with the host evaluating other poses
/// between the events as an integrator does.
#[test]
fn one_disc_head_commits_as_kerf_model() {
    let (mut head, mut model) = one_disc_head_and_model();
    let twist = Twist::new([1.0, 0.0, 0.0], [0.0, 1.0 / 0.2159, 0.0]);
    let at = |x: f64| Pose::new(x, 0.0, 0.2121, 0.0, 0.0, 0.0);
    let mut x = -0.2;
    for k in 0..40 {
        // events 1.5 to 3.4 mm apart: one to four sub-steps
        let dx = 1.5e-3 + 5e-5 * k as f64;
        for probe in [0.3, 0.7] {
            let q = at(x + probe * dx);
            model.evaluate(&q, &twist).unwrap();
            head.evaluate_discs(&[(q, twist)]).unwrap();
        }
        x += dx;
        let cm = model.commit(&at(x), &twist, dx).unwrap();
        let ch = head.commit(&[(at(x), twist)], dx).unwrap();
        assert_eq!(cm, ch);
        let om = model.evaluate(&at(x), &twist).unwrap();
        let oh = head.evaluate_discs(&[(at(x), twist)]).unwrap();
        assert_eq!(om.force, oh.discs[0].force);
        assert_eq!(om.excavated_volume, oh.excavated_volume);
        assert_eq!(om.cutting_energy.to_bits(), oh.cutting_energy.to_bits());
    }
    assert!(model.evaluate(&at(x), &twist).unwrap().cutting_energy > 0.0);
}

/// Depth each disc cut on its last pass: the groove bottom (at the track)
/// just ahead of the disc less just behind it, `delta` rad either side.
fn cut_depths(head: &Head, pose: &Pose, delta: f64) -> Vec<f64> {
    let yaw = pose.yaw;
    head.specs()
        .iter()
        .map(|s| {
            let at = |a: f64| {
                let (x, y) = (s.mount.track * a.cos(), s.mount.track * a.sin());
                head.map().height(x, y)
            };
            let a = s.mount.angle + yaw;
            at(a + delta) - at(a - delta)
        })
        .collect()
}

#[test]
fn two_discs_on_one_track_share_the_depth() {
    let p_rev = 0.006;
    let (w, h) = (2.0, 0.005);
    let mut one = Head::new(params(0.6), vec![disc(0.35, 0.0, 0.0)]).unwrap();
    let mut two = Head::new(
        params(0.6),
        vec![disc(0.35, 0.0, 0.0), disc(0.35, 180.0, 0.0)],
    )
    .unwrap();
    let (o1, pose1) = bore(&mut one, w, p_rev, 2.5, h);
    let (o2, pose2) = bore(&mut two, w, p_rev, 2.5, h);
    // on the helical groove, one disc cuts p per revolution: p (1 - d / pi)
    // between d ahead and d behind it; two discs each cut p / 2:
    // p / 2 (1 - 2 d / pi)
    let d = 0.15;
    let pi = std::f64::consts::PI;
    let c1 = cut_depths(&one, &pose1, d);
    let c2 = cut_depths(&two, &pose2, d);
    let want1 = p_rev * (1.0 - d / pi);
    let want2 = 0.5 * p_rev * (1.0 - 2.0 * d / pi);
    assert!(
        (c1[0] - want1).abs() < 0.05 * want1,
        "single disc cut {c1:?}, want {want1}"
    );
    for c in &c2 {
        assert!(
            (c - want2).abs() < 0.05 * want2,
            "shared track cut {c2:?}, want {want2}"
        );
    }
    // (their forces are not compared: on the current contact a disc in its
    // own groove also loads on the groove walls, see docs/head.md)
    assert!(o1.last().unwrap().thrust > 0.0 && o2.last().unwrap().thrust > 0.0);
}

#[test]
fn a_disc_meeting_a_neighbours_groove_feels_it() {
    // disc 1 alone cuts a groove 4 mm deep round its track; disc 2, on the
    // same track half a turn behind and set 2 mm deeper, then meets that
    // groove: at the same pose it cuts 2 mm instead of 6 mm of rock
    let mut specs = vec![disc(0.30, 0.0, 0.0), disc(0.30, 180.0, 0.0)];
    specs[1].mount.setback = -0.002;
    let mut head = Head::new(params(0.6), specs.clone()).unwrap();
    let w = 2.0;
    let twist = Twist::new([0.0, 0.0, 0.0], [0.0, 0.0, w]);
    let pressed = Pose::new(0.0, 0.0, -0.004, 0.0, 0.0, 0.0);
    let flat = head.evaluate_head(&pressed, &twist).unwrap();
    let mut solo = Head::new(params(0.6), vec![specs[0]]).unwrap();
    let mut pose = pressed;
    for _ in 0..((2.0 * std::f64::consts::PI / w / 0.01) as usize + 1) {
        pose = solo.advance_head(&pose, &twist, 0.01).unwrap();
    }
    head.set_face(solo.face().clone()).unwrap();
    let grooved = head.evaluate_head(&pressed, &twist).unwrap();
    let (f_flat, f_groove) = (flat.discs[1].normal_force, grooved.discs[1].normal_force);
    assert!(f_flat > 1e4, "{f_flat}");
    // 2 mm instead of 6 mm of rock under the tip; the current contact also
    // loads the groove walls, so the drop is smaller than the CSM law of the
    // depths would give (docs/head.md)
    assert!(
        f_groove < 0.95 * f_flat,
        "flat {f_flat}, grooved {f_groove}"
    );
    let (p_flat, p_groove) = (flat.discs[1].penetration, grooved.discs[1].penetration);
    assert!((p_flat - 0.006).abs() < 1e-4, "{p_flat}");
    assert!(p_groove < 0.95 * p_flat, "{p_groove}");
}

#[test]
fn state_replay_is_bit_identical() {
    let mut head = small_head();
    let w = 1.0;
    let twist = Twist::new([0.0, 0.0, -0.001], [0.0, 0.0, w]);
    let mut pose = Pose::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    for _ in 0..20 {
        pose = head.advance_head(&pose, &twist, 0.01).unwrap();
    }
    let saved = head.state();
    let blob = saved.to_bytes();
    let run = |head: &mut Head, mut pose: Pose| {
        let mut v = Vec::new();
        for _ in 0..20 {
            pose = head.advance_head(&pose, &twist, 0.01).unwrap();
            v.push(head.evaluate_head(&pose, &twist).unwrap());
        }
        v
    };
    let a = run(&mut head, pose);
    head.set_state(&saved).unwrap();
    let b = run(&mut head, pose);
    let restored =
        kerf::core::head::HeadState::from_bytes(&blob, head.params(), head.len()).unwrap();
    assert_eq!(restored, saved);
    head.set_state(&restored).unwrap();
    let c = run(&mut head, pose);
    assert_eq!(a, b);
    assert_eq!(a, c);
    // a blob for another disc count is rejected
    assert!(kerf::core::head::HeadState::from_bytes(&blob, head.params(), 3).is_err());
    let _ = Drive::Head;
}

#[test]
fn steady_start_meets_each_disc_at_its_depth_per_revolution() {
    let p_rev = 0.006;
    let mut specs = vec![
        disc(0.12, 0.0, 0.0),
        disc(0.25, 100.0, 0.0),
        disc(0.25, 280.0, 0.0),
        disc(0.40, 200.0, 0.0),
    ];
    specs[3].mount.setback = 0.001;
    let mut head = Head::new(params(0.75), specs).unwrap();
    assert!(head.steady_start(-0.001).is_err());
    head.steady_start(p_rev).unwrap();
    let w = 1.0;
    let twist = Twist::boring(w, p_rev);
    let rest = Pose::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let o = head.evaluate_head(&rest, &twist).unwrap();
    // one disc on its track meets p; two share it, p / 2 each (tips on a flat
    // groove bottom; the setback does not change what a disc meets)
    let want = [p_rev, 0.5 * p_rev, 0.5 * p_rev, p_rev];
    // (within 10 %: the rim meets the ramp of the helix a little short of its step)
    let pen: Vec<f64> = o.discs.iter().map(|d| d.penetration).collect();
    for (p, w) in pen.iter().zip(want) {
        assert!((p - w).abs() < 0.1 * w, "{pen:?} vs {want:?}");
    }
    assert!((pen[1] - pen[2]).abs() < 1e-9 * pen[1], "{pen:?}");
    // the face just behind each disc is at its tip, just ahead p (or p/2) higher
    let z = |r: f64, a: f64| head.map().height(r * a.cos(), r * a.sin());
    let a = 100f64.to_radians();
    assert!((z(0.25, a - 0.01) - 0.0).abs() < 1e-4);
    assert!((z(0.25, a + 0.01) - 0.5 * p_rev).abs() < 1e-4);
    assert!((z(0.40, 200f64.to_radians() - 0.01) - 0.001).abs() < 1e-4);
    // boring on from the steady start keeps the loads steady
    let mut pose = rest;
    let n = 60;
    let mut first = 0.0;
    for k in 0..n {
        pose = head.advance_head(&pose, &twist, 0.01).unwrap();
        let f = head.evaluate_head(&pose, &twist).unwrap().discs[0].normal_force;
        if k == 0 {
            first = f;
        }
        if k == n - 1 {
            assert!((f - first).abs() < 0.1 * first, "{first} -> {f}");
        }
    }
    assert!(first > 1e4);
}

#[test]
fn steady_boring_face_discs_carry_the_csm_force_of_their_depth_per_revolution() {
    // upright face discs on tracks of 0.5 m and more, 80 mm apart (the
    // spacing each disc's law is given), the middle track shared by two
    // discs half a turn apart; from the steady start (ridges relieved, as
    // chips leave them) a quarter revolution at 6 mm per revolution
    let p_rev = 0.006;
    let specs: Vec<DiscSpec> = [0.50, 0.58, 0.66, 0.66, 0.74, 0.82]
        .iter()
        .zip([0.0, 137.5, 275.0, 95.0, 52.5, 190.0])
        .map(|(&t, a)| disc(t, a, 0.0))
        .collect();
    let mut head = Head::new(params(0.85), specs).unwrap();
    head.steady_start(p_rev).unwrap();
    let w = 1.0;
    let twist = Twist::boring(w, p_rev);
    let mut pose = Pose::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let steps = 80;
    let h = 0.25 * 2.0 * std::f64::consts::PI / w / steps as f64;
    let mut sum = vec![0.0; head.len()];
    let mut pen = vec![0.0; head.len()];
    for _ in 0..steps {
        pose = head.advance_head(&pose, &twist, h).unwrap();
        let o = head.evaluate_head(&pose, &twist).unwrap();
        for ((s, q), d) in sum.iter_mut().zip(pen.iter_mut()).zip(&o.discs) {
            *s += d.normal_force / steps as f64;
            *q += d.penetration / steps as f64;
        }
    }
    // CSM (its own law, each disc's spacing): normal force F cos(phi / (2 +
    // psi)) at the depth per revolution, p / k for k discs on the track
    let csm_normal = |d: &kerf::core::Disc, p: f64| {
        let law = d.law();
        let phi = kerf::core::csm::contact_angle(d.cutter().radius, p);
        law.force(p) * law.resultant_angle(phi).cos()
    };
    let depth = [p_rev, p_rev, 0.5 * p_rev, 0.5 * p_rev, p_rev, p_rev];
    for (i, (got, p)) in sum.iter().zip(depth).enumerate() {
        let want = csm_normal(&head.discs()[i], p);
        eprintln!(
            "disc {i}: mean normal {got:.0} N, CSM {want:.0} N at p {p}; penetration {:.2} mm",
            pen[i] * 1e3
        );
        // within 3 % (the rim meets the helix's ramp a little short of its
        // step). The outermost track (disc 5) has no neighbour outside: the
        // steady start leaves the rock past the bore at the tips' plane,
        // below the face it pre-cuts, so that disc's outer flank finds less
        // rock (measured 8 % under the CSM): 15 % there. On a head its
        // outside is the gauge discs' (docs/head.md, "Steady start").
        let tol = if i == 5 { 0.15 } else { 0.03 };
        assert!(
            (got - want).abs() < tol * want,
            "disc {i}: {got} N against the CSM's {want} N at p = {p}"
        );
    }
    // the shared track: each of its two discs carries about half of the
    // depth, so less than a disc alone on its track
    assert!(sum[2] < 0.8 * sum[1] && sum[3] < 0.8 * sum[1], "{sum:?}");
}

/// Every pose a step would cut at is checked before it cuts: a step whose
/// path leaves the poses' bounds on the way (here one disc of the disc
/// drive runs past x = 1e6 m within the step, the others cut the face) is
/// refused whole, in the Co-Simulation step and the Model Exchange commit,
/// and a shorter one runs. Before, the first cuts and the start-of-run
/// imprint stood, and the head FMU went to its error state.
#[test]
fn a_step_whose_path_leaves_the_bounds_is_refused_whole() {
    let mut head = small_head();
    let start = Pose::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let w = 3.0 * std::f64::consts::TAU / 60.0;
    let twist = Twist::new([0.0, 0.0, -1e-3], [0.0, 0.0, w]);
    let mut motions = head.place(&start, &twist);
    // the last disc far away, 0.5 m short of the bound, running towards it
    let far = motions.len() - 1;
    motions[far].0.position.x = 1.0e6 - 0.5;
    motions[far].1 = Twist::new([1.0, 0.0, 0.0], [0.0, 1.0 / 0.2159, 0.0]);
    let before = head.state().to_bytes();
    // nothing cut yet: the start imprint is the first change a step makes
    let e = head.advance_discs(&motions, 1.0).unwrap_err().to_string();
    assert!(e.contains("x") && e.contains("1000000"), "{e}");
    assert_eq!(head.state().to_bytes(), before);
    assert!(head.discs().len() == 4 && head.face().excavated_volume() == 0.0);
    // a step that stays inside runs, and cuts
    head.advance_discs(&motions, 0.25).unwrap();
    assert!(head.face().excavated_volume() > 0.0);
    // Model Exchange: an event whose path runs past the bound
    let before = head.state().to_bytes();
    let mut later = motions.clone();
    for (p, t) in later.iter_mut() {
        p.position += t.velocity * 0.25;
    }
    later[far].0.position.x = 1.0e6 + 0.2;
    assert!(head.commit(&later, 0.45).is_err());
    assert_eq!(head.state().to_bytes(), before);
}

/// A call whose cuts would scan more nodes than kerf.fmu may in one call
/// for each disc (here every disc pushed 0.15 m into the rock and run 0.3 m
/// in one step, the tilted one counting each node 50 times) is refused
/// before anything changes, naming the split; so is a Model Exchange
/// commit along such paths. (Before, a head bounded only its sub-steps.)
#[test]
fn a_step_that_would_scan_too_many_nodes_is_refused_untouched() {
    let mut head = small_head();
    let start = Pose::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let mut motions = head.place(&start, &Twist::default());
    for (p, t) in motions.iter_mut() {
        p.position.z -= 0.15;
        *t = Twist::new([1.0, 0.0, 0.0], [0.0, 0.0, 0.0]);
    }
    let before = head.state().to_bytes();
    let e = head.advance_discs(&motions, 0.3).unwrap_err().to_string();
    assert!(
        e.contains("height-map nodes") && e.contains("split it into at least"),
        "{e}"
    );
    assert_eq!(head.state().to_bytes(), before);
    // the Model Exchange commit of the same paths is refused alike
    head.commit(&motions, 1e-3).unwrap();
    let before = head.state().to_bytes();
    let mut later = motions.clone();
    for (p, _) in later.iter_mut() {
        p.position.x += 0.2;
    }
    let e = head.commit(&later, 0.2).unwrap_err().to_string();
    assert!(e.contains("height-map nodes"), "{e}");
    assert_eq!(head.state().to_bytes(), before);
}

/// A host that steps a head by hours is refused before anything changes,
/// with the split that fits, in both drives and in a Model Exchange commit;
/// the step the message names then runs.
#[test]
fn a_step_too_long_for_one_call_is_refused_untouched() {
    let mut head = small_head();
    let w = 3.0 * std::f64::consts::TAU / 60.0;
    let twist = Twist::boring(w, 0.006);
    let start = Pose::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    head.advance_head(&start, &twist, 1e-3).unwrap();
    let before = head.state().to_bytes();
    let e = head
        .advance_head(&start, &twist, 3600.0)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("refused, nothing changed") && e.contains("split it into at least"),
        "{e}"
    );
    assert_eq!(head.state().to_bytes(), before);
    let motions = head.place(&start, &twist);
    let e = head
        .advance_discs(&motions, 3600.0)
        .unwrap_err()
        .to_string();
    assert!(e.contains("split it into at least"), "{e}");
    assert_eq!(head.state().to_bytes(), before);
    head.advance_head(&start, &twist, 1.0).unwrap();
    assert_ne!(head.state().to_bytes(), before);
    // Model Exchange: an event half a turn after the last commit, at a
    // sweep step of 20 um (the outer disc's path: ~1.8 m, 90 000 sub-steps)
    let mut p = params(0.75);
    p.numerics.sweep_step = 2e-5;
    let mut me = Head::new(p, small_head().specs().to_vec()).unwrap();
    me.commit(&me.place(&start, &twist), 1e-3).unwrap();
    let before = me.state().to_bytes();
    let half = advance_rigid(&start, &twist, 10.0);
    let e = me
        .commit(&me.place(&half, &twist), 10.0)
        .unwrap_err()
        .to_string();
    assert!(e.contains("split it into at least"), "{e}");
    assert_eq!(me.state().to_bytes(), before);
}

/// A head boring flat rock, its discs' cuts shallow and deepening every
/// step: each step is taken twice from the same state, the head's z
/// moved by 1e-15 m the second time. The outputs must move by round-off,
/// not jump. (They jumped by up to 1 % of the thrust and 4 % of a disc's
/// normal force: an arc's last sample, where the rim rises to the highest
/// rock, read inside or out by round-off, and a march step could hide a
/// second exit; docs/hosts.md, K1.) The demo head's layout, 10 rpm, 6 mm
/// per revolution, 1 ms steps. Since cuts stop short of the front arc
/// (`cut_cutter_heightmap::Front`) the map steps up where the uncut rock
/// begins, and in 6 of these 200 steps a disc's normal force moves by up
/// to 3.9e-6 of itself (a tilted disc, 0.09 N of 24.2 kN; a shallow upright
/// disc's side force switches between 0 and 0.58 N) and the thrust by
/// 6.7e-7; whole cuts moved nothing by more than 1e-8 (docs/head.md, "Cuts
/// stop short of the front arc"). Still three orders below the jumps this
/// test was written for.
#[test]
fn outputs_move_by_round_off_when_the_pose_does_in_a_shallow_deepening_cut() {
    let lay = kerf::core::layout::load(std::path::Path::new("layouts/demo-1.2m.json")).unwrap();
    let (half, _) = kerf::core::head::default_rock(&lay);
    let specs: Vec<DiscSpec> = lay.cutters.iter().map(DiscSpec::from_layout).collect();
    let mut head = Head::new(params(half), specs).unwrap();
    let w = 10.0 * 2.0 * std::f64::consts::PI / 60.0;
    let twist = Twist::boring(w, 0.006);
    let vz = twist.velocity.z;
    let h = 1e-3;
    let (mut thrust, mut disc) = (0.0f64, 0.0f64);
    for k in 0..200 {
        let t = k as f64 * h;
        let pose = Pose::new(0.0, 0.0, vz * t, w * t, 0.0, 0.0);
        let s = head.state();
        let mut moved = pose;
        moved.position.z += 1e-15;
        let e = head.advance_head(&moved, &twist, h).unwrap();
        let b = head.evaluate_head(&e, &twist).unwrap();
        head.set_state(&s).unwrap();
        let e = head.advance_head(&pose, &twist, h).unwrap();
        let a = head.evaluate_head(&e, &twist).unwrap();
        thrust = thrust.max((a.thrust - b.thrust).abs() / a.thrust.abs());
        for (x, y) in a.discs.iter().zip(&b.discs) {
            if x.normal_force > 0.0 {
                disc = disc.max((x.normal_force - y.normal_force).abs() / x.normal_force);
            }
        }
    }
    assert!(thrust < 3e-6, "thrust moved by {thrust:e} of itself");
    assert!(
        disc < 2e-5,
        "a disc's normal force moved by {disc:e} of itself"
    );
}

/// A head's discs turn freely on their bearings: friction does not push a
/// tilted gauge disc along its path. Its spin rolls its nominal tip, but it
/// touches the rock near the tip's low edge, which then slid at 1-2 % of
/// the rolling speed; with the full slip, friction (mu = 0.3) made the demo
/// head's 20 deg disc's rolling force -1.3 kN instead of +1.0 kN, and the
/// head's torque negative (docs/hosts.md, K2). With friction on and off the
/// tilted discs' rolling forces now agree within 1 % of their normal force.
#[test]
fn friction_does_not_push_a_freely_turning_tilted_disc_along_its_path() {
    let lay = kerf::core::layout::load(std::path::Path::new("layouts/demo-1.2m.json")).unwrap();
    let (half, _) = kerf::core::head::default_rock(&lay);
    let specs: Vec<DiscSpec> = lay.cutters.iter().map(DiscSpec::from_layout).collect();
    let tilted: Vec<usize> = (0..specs.len())
        .filter(|&i| specs[i].mount.tilt > 0.0)
        .collect();
    assert!(tilted.len() >= 2);
    let run = |mu: f64| {
        let mut p = params(half);
        p.friction.mu = mu;
        let mut head = Head::new(p, specs.clone()).unwrap();
        let w = 10.0 * 2.0 * std::f64::consts::PI / 60.0;
        let (out, _) = bore(
            &mut head,
            w,
            0.006,
            0.05 * w / (2.0 * std::f64::consts::PI),
            1e-3,
        );
        out
    };
    let (with, without) = (run(0.3), run(0.0));
    assert_eq!(with.len(), 50);
    for (a, b) in with.iter().zip(&without) {
        for &i in &tilted {
            let (x, y) = (&a.discs[i], &b.discs[i]);
            assert!(x.normal_force > 1e4, "disc {} cuts", i + 1);
            let d = (x.rolling_force - y.rolling_force).abs() / x.normal_force;
            assert!(
                d < 0.01,
                "disc {}: rolling force {} with friction, {} without",
                i + 1,
                x.rolling_force,
                y.rolling_force
            );
        }
        assert!(a.torque > 0.0, "torque {}", a.torque);
    }
}

/// The head's cutting energy is the trapezoid, disc by disc, of the power
/// its outputs reported at the end of each step (each disc's force and
/// moment against its own twist there), also when the host sets the head's
/// pose at every step from its own clock and speeds the head up step by
/// step (as a Python host does): the start of a step's trapezoid is the
/// power reported at the end of the last, not the start pose evaluated
/// again with the new twist. To 1e-12 of the total.
#[test]
fn head_energy_is_the_trapezoid_of_the_reported_power_as_the_host_drives_it() {
    let mut head = small_head();
    let (h, p_rev) = (0.01, 0.004);
    let (mut angle, mut booked, mut p0) = (0.0f64, 0.0, Vec::new());
    for k in 0..40 {
        // the host's own integration of a head speeding up from 0.5 rad/s
        let w = 0.5 + 0.02 * k as f64;
        let twist = Twist::boring(w, p_rev);
        let pose = Pose::new(
            0.0,
            0.0,
            -p_rev * angle / std::f64::consts::TAU,
            angle,
            0.0,
            0.0,
        );
        let end = head.advance_head(&pose, &twist, h).unwrap();
        let o = head.evaluate_head(&end, &twist).unwrap();
        let p1: Vec<f64> = o
            .discs
            .iter()
            .zip(head.place(&end, &twist))
            .map(|(d, (_, tw))| d.power_into_rock(&tw))
            .collect();
        if k == 0 {
            // (the first step starts from the start poses, cut first)
            booked = o.cutting_energy;
        } else {
            for (a, b) in p0.iter().zip(&p1) {
                booked += 0.5 * (a + b) * h;
            }
            assert!(
                (o.cutting_energy - booked).abs() <= 1e-12 * booked,
                "step {k}: booked {:e} J, trapezoid of the reported power {booked:e} J",
                o.cutting_energy
            );
        }
        p0 = p1;
        angle += w * h;
    }
    assert!(booked > 10.0, "the head cuts: {booked} J");
}
