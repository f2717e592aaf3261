//! Physics-core behaviour against exact references (issue: physics core).
//! Tolerances are stated at each assertion; geometry and numbers come from
//! thesis Table 2 and interface.md.

use kerf::core::{Model, Params, Pose, Twist};

const R: f64 = 0.2159;

/// CSM closed form (thesis eqs 13-17) for the reference rock at depth `p`.
fn csm(p: f64) -> (f64, f64) {
    let phi = ((R - p) / R).acos();
    let pp = 2.12 * ((158e6f64).powi(2) * 6.78e6 * 0.051 / (R * 0.013).sqrt()).cbrt();
    let ft = 0.013 * R * phi * pp;
    (ft * (phi / 2.0).cos(), ft * (phi / 2.0).sin())
}

struct Run {
    normal: f64,
    rolling: f64,
    side: f64,
    /// Volume removed while the cutter's centre crossed the averaging window.
    window_volume: f64,
    model: Model,
}

/// Rolls the cutter along +x at depth `p` from x = 0 to `length` in steps of
/// `step` (Co-Simulation advance), averaging outputs whose pose lies in
/// `[lo, hi]`.
fn roll(params: Params, y: f64, p: f64, step: f64, length: f64, lo: f64, hi: f64) -> Run {
    let mut m = Model::new(params).unwrap();
    let tw = Twist::new([1.0, 0.0, 0.0], [0.0, 1.0 / R, 0.0]);
    let mut pose = Pose::new(0.0, y, R - p, 0.0, 0.0, 0.0);
    let n = (length / step).round() as usize;
    let (mut sn, mut sr, mut ss, mut k) = (0.0, 0.0, 0.0, 0);
    let (mut v_lo, mut v_hi) = (None, 0.0);
    for _ in 0..n {
        pose = m.advance(&pose, &tw, step).unwrap();
        let o = m.evaluate(&pose, &tw).unwrap();
        let x = pose.position.x;
        if x >= lo - 1e-9 && x <= hi + 1e-9 {
            sn += o.normal_force;
            sr += o.rolling_force;
            ss += o.side_force;
            k += 1;
            v_lo.get_or_insert(o.excavated_volume);
            v_hi = o.excavated_volume;
        }
    }
    assert!(k > 0);
    let k = k as f64;
    Run {
        normal: sn / k,
        rolling: sr / k,
        side: ss / k,
        window_volume: v_hi - v_lo.unwrap(),
        model: m,
    }
}

/// Analytic groove cross-section of the tip profile at depth `p`, with the
/// flat side faces at |y| = T/2: integral of max(0, p - (R - rho(y))).
fn groove_area(p: f64) -> f64 {
    let (t, r) = (0.013, 0.0127);
    let n = 200_000;
    (0..n)
        .map(|k| {
            let y = -t / 2.0 + t * (k as f64 + 0.5) / n as f64;
            (p - (r - (r * r - y * y).sqrt())).max(0.0) * t / n as f64
        })
        .sum()
}

fn rel(a: f64, b: f64) -> f64 {
    ((a - b) / b).abs()
}

#[test]
fn steady_rolling_on_a_flat_face_reproduces_csm_at_every_depth() {
    for p_mm in [1.0, 2.0, 3.8, 6.0, 8.0] {
        let p = p_mm * 1e-3;
        let run = roll(Params::default(), 0.0, p, 1e-3, 1.0, 0.2, 0.8);
        let (fnn, fr) = csm(p);
        // interface: within 0.1 % of the closed form, side below 0.1 % of normal
        assert!(
            rel(run.normal, fnn) < 1e-3,
            "p={p_mm} mm: normal {} vs {}",
            run.normal,
            fnn
        );
        assert!(
            rel(run.rolling, fr) < 1e-3,
            "p={p_mm} mm: rolling {} vs {}",
            run.rolling,
            fr
        );
        assert!(
            run.side.abs() < 1e-3 * fnn,
            "p={p_mm} mm: side {}",
            run.side
        );
        // removed volume: the analytic groove over the 0.6 m window, within 1 %
        let expect = groove_area(p) * 0.6;
        assert!(
            rel(run.window_volume, expect) < 1e-2,
            "p={p_mm} mm: volume {} vs {}",
            run.window_volume,
            expect
        );
    }
}

#[test]
fn off_node_track_gives_the_same_forces_and_no_side_force() {
    // the cut need not run along a node row: a track 0.3 mm off still gives CSM
    let p = 3.8e-3;
    let run = roll(Params::default(), 0.0003, p, 1e-3, 0.5, 0.15, 0.4);
    let (fnn, fr) = csm(p);
    assert!(rel(run.normal, fnn) < 1e-3 && rel(run.rolling, fr) < 1e-3);
    assert!(run.side.abs() < 1e-3 * fnn, "side {}", run.side);
}

#[test]
fn step_length_does_not_change_forces_or_groove() {
    let p = 3.8e-3;
    let runs: Vec<(f64, Run)> = [0.1e-3, 1e-3, 10e-3, 50e-3]
        .iter()
        .map(|&h| (h, roll(Params::default(), 0.0, p, h, 0.3, 0.1, 0.25)))
        .collect();
    let base = &runs[1].1;
    let v_base = base
        .model
        .evaluate(
            &Pose::new(0.3, 0.0, R - p, 0.0, 0.0, 0.0),
            &Twist::default(),
        )
        .unwrap()
        .excavated_volume;
    for (h, r) in &runs {
        assert!(
            rel(r.normal, base.normal) < 5e-3,
            "step {h}: normal {} vs {}",
            r.normal,
            base.normal
        );
        assert!(
            rel(r.rolling, base.rolling) < 5e-3,
            "step {h}: rolling {} vs {}",
            r.rolling,
            base.rolling
        );
        let v = r
            .model
            .evaluate(
                &Pose::new(0.3, 0.0, R - p, 0.0, 0.0, 0.0),
                &Twist::default(),
            )
            .unwrap()
            .excavated_volume;
        assert!(rel(v, v_base) < 5e-3, "step {h}: volume {v} vs {v_base}");
    }
}

#[test]
fn heading_along_y_gives_the_same_cutter_frame_forces() {
    let p = 3.8e-3;
    let mut params = Params::default();
    (
        params.rock.x_min,
        params.rock.x_max,
        params.rock.y_min,
        params.rock.y_max,
    ) = (-0.1, 0.1, -0.25, 0.45);
    (params.rock.nx, params.rock.ny) = (201, 701);
    let mut m = Model::new(params).unwrap();
    let yaw = std::f64::consts::FRAC_PI_2;
    // rolling towards +y: velocity +y, spin about the axle (rock -x) gives wx = -v/R
    let tw = Twist::new([0.0, 1.0, 0.0], [-1.0 / R, 0.0, 0.0]);
    let mut pose = Pose::new(0.0, 0.0, R - p, yaw, 0.0, 0.0);
    let (mut sn, mut sr, mut ss, mut fx, mut fy, mut k) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    for _ in 0..400 {
        pose = m.advance(&pose, &tw, 1e-3).unwrap();
        let o = m.evaluate(&pose, &tw).unwrap();
        if pose.position.y > 0.1 && pose.position.y < 0.35 {
            sn += o.normal_force;
            sr += o.rolling_force;
            ss += o.side_force;
            fx += o.force[0];
            fy += o.force[1];
            k += 1.0;
        }
    }
    let (fnn, fr) = csm(p);
    assert!(rel(sn / k, fnn) < 1e-3 && rel(sr / k, fr) < 1e-3 && (ss / k).abs() < 1e-3 * fnn);
    // the rolling force resists motion along +y: rock-frame Fy = -rolling, Fx = side (cutter y is rock -x)
    assert!(rel(-fy / k, fr) < 1e-3, "Fy {}", fy / k);
    assert!((fx / k).abs() < 1e-3 * fnn);
}

/// Presses a cutter rolled by `roll` straight down until its lowest point is
/// `depth` into the flat face, that point at (0.3, 0), and commits there.
fn press(params: Params, roll: f64, depth: f64) -> (Model, Pose) {
    let mut m = Model::new(params).unwrap();
    let probe = Pose::new(0.0, 0.0, 1.0, 0.0, 0.0, roll);
    let low = kerf::core::cutter::PosedDisc::new(&m.params().cutter, &probe).lowest_point();
    let pose = Pose::new(0.3 - low.x, -low.y, 1.0 - low.z - depth, 0.0, 0.0, roll);
    m.commit(&pose, &Twist::default(), 0.0).unwrap();
    (m, pose)
}

#[test]
fn tilted_cutter_touching_with_its_corner_and_side_face_is_pushed_sideways() {
    for roll_deg in [30.0f64, 60.0] {
        let (m, pose) = press(Params::default(), roll_deg.to_radians(), 3e-3);
        let o = m.evaluate(&pose, &Twist::default()).unwrap();
        assert!(o.in_contact, "roll {roll_deg}");
        assert!(o.force.iter().all(|f| f.is_finite()));
        // with roll > 0 the edge y_local = -T/2 is lowest: the rock pushes the
        // cutter towards its +y (away from the buried corner), and up
        assert!(
            o.side_force > 0.05 * o.normal_force.abs(),
            "roll {roll_deg}: side {} normal {}",
            o.side_force,
            o.normal_force
        );
        assert!(o.force[2] > 0.0, "roll {roll_deg}: Fz {}", o.force[2]);
    }
    // the side face itself carries load at 60 deg (node-based face contact)
    let (m, pose) = press(Params::default(), 60f64.to_radians(), 6e-3);
    let c = m.contact(&pose, &Twist::new([0.0; 3], [0.0; 3]));
    assert!(c.side_force.norm() > 0.0, "side face carries no load");
}

#[test]
fn cut_beside_an_existing_groove_is_pushed_towards_the_free_side() {
    let p = 3.8e-3;
    // first groove along y = 0
    let first = roll(Params::default(), 0.0, p, 1e-3, 0.6, 0.2, 0.4);
    let mut m = first.model;
    // second cut 10 mm to +y: its -y edge overlaps the first groove
    let tw = Twist::new([1.0, 0.0, 0.0], [0.0, 1.0 / R, 0.0]);
    let mut pose = Pose::new(0.0, 0.010, R - p, 0.0, 0.0, 0.0);
    let (mut ss, mut sn, mut k) = (0.0, 0.0, 0.0);
    for _ in 0..500 {
        pose = m.advance(&pose, &tw, 1e-3).unwrap();
        let o = m.evaluate(&pose, &tw).unwrap();
        if pose.position.x > 0.15 && pose.position.x < 0.45 {
            ss += o.side_force;
            sn += o.normal_force;
            k += 1.0;
        }
    }
    // free side is -y: the side force (along cutter +y) is negative and clear
    assert!(ss / k < -0.01 * sn / k, "side {} normal {}", ss / k, sn / k);
}

#[test]
fn a_cutter_pressed_in_and_held_keeps_its_load() {
    let p = 3.8e-3;
    let (mut m, pose) = press(Params::default(), 0.0, p);
    let o0 = m.evaluate(&pose, &Twist::default()).unwrap();
    for _ in 0..100 {
        m.commit(&pose, &Twist::default(), 1e-3).unwrap();
    }
    let o1 = m.evaluate(&pose, &Twist::default()).unwrap();
    let (fnn, _) = csm(p);
    // same order as the rolling force, vertical, and unchanged by holding
    assert!(
        o1.normal_force > 0.5 * fnn && o1.normal_force < 2.0 * fnn,
        "{}",
        o1.normal_force
    );
    assert!(rel(o1.normal_force, o0.normal_force) < 1e-9);
    assert!(o1.rolling_force.abs() < 1e-6 * fnn, "{}", o1.rolling_force);
    // lifting it off its pit unloads it monotonically, in steps no larger than
    // a fifth of the load per 0.1 um, to zero within 40 um (the elastic layer
    // plus the interpolation noise of the cut groove, about 14 um at 1 mm cells)
    let mut last = o1.normal_force;
    for k in 1..=400 {
        let up = Pose::new(
            pose.position.x,
            0.0,
            pose.position.z + k as f64 * 0.1e-6,
            0.0,
            0.0,
            0.0,
        );
        let f = m.evaluate(&up, &Twist::default()).unwrap().normal_force;
        assert!(
            f <= last + 1e-9 && last - f < 0.2 * fnn,
            "jump at lift {k}: {last} -> {f}"
        );
        last = f;
    }
    assert_eq!(last, 0.0);
}

#[test]
fn a_second_pass_in_the_same_groove_feels_far_less() {
    let p = 3.8e-3;
    let first = roll(Params::default(), 0.0, p, 1e-3, 0.5, 0.15, 0.35);
    let mut m = first.model;
    let tw = Twist::new([1.0, 0.0, 0.0], [0.0, 1.0 / R, 0.0]);
    let mut pose = Pose::new(0.05, 0.0, R - p, 0.0, 0.0, 0.0);
    let (mut sn, mut k) = (0.0, 0.0);
    for _ in 0..300 {
        pose = m.advance(&pose, &tw, 1e-3).unwrap();
        if pose.position.x > 0.15 && pose.position.x < 0.35 {
            sn += m.evaluate(&pose, &tw).unwrap().normal_force;
            k += 1.0;
        }
    }
    assert!(
        sn / k < 0.1 * first.normal,
        "second pass {} vs first {}",
        sn / k,
        first.normal
    );
}

#[test]
fn trial_and_committed_evaluations_agree_while_rolling() {
    // Model Exchange: outputs read before the event commit and after it must
    // be the same force (no jump at events)
    let p = 3.8e-3;
    let mut m = Model::new(Params::default()).unwrap();
    let tw = Twist::new([1.0, 0.0, 0.0], [0.0, 1.0 / R, 0.0]);
    for k in 0..300 {
        let pose = Pose::new(k as f64 * 1e-3, 0.0, R - p, 0.0, 0.0, 0.0);
        let before = m.evaluate(&pose, &tw).unwrap();
        m.commit(&pose, &tw, 1e-3).unwrap();
        let after = m.evaluate(&pose, &tw).unwrap();
        if k > 100 {
            assert!(rel(after.normal_force, before.normal_force) < 1e-6, "k={k}");
            assert!(
                rel(after.rolling_force, before.rolling_force) < 1e-6,
                "k={k}"
            );
            let (fnn, _) = csm(p);
            assert!(rel(after.normal_force, fnn) < 1e-3);
        }
    }
}

#[test]
fn rolling_backwards_mirrors_rolling_forwards() {
    let p = 3.8e-3;
    let mut m = Model::new(Params::default()).unwrap();
    let tw = Twist::new([-1.0, 0.0, 0.0], [0.0, -1.0 / R, 0.0]);
    let mut pose = Pose::new(0.9, 0.0, R - p, 0.0, 0.0, 0.0);
    let (mut sn, mut sr, mut k) = (0.0, 0.0, 0.0);
    for _ in 0..400 {
        pose = m.advance(&pose, &tw, 1e-3).unwrap();
        if pose.position.x < 0.8 && pose.position.x > 0.55 {
            let o = m.evaluate(&pose, &tw).unwrap();
            sn += o.normal_force;
            sr += o.rolling_force;
            k += 1.0;
        }
    }
    let (fnn, fr) = csm(p);
    assert!(
        rel(sn / k, fnn) < 1e-3 && rel(-sr / k, fr) < 1e-3,
        "{} {}",
        sn / k,
        sr / k
    );
}

#[test]
fn energy_and_specific_energy_follow_the_rolling_force() {
    let p = 3.8e-3;
    let run = roll(Params::default(), 0.0, p, 1e-3, 0.5, 0.1, 0.5);
    let o = run
        .model
        .evaluate(
            &Pose::new(0.5, 0.0, R - p, 0.0, 0.0, 0.0),
            &Twist::default(),
        )
        .unwrap();
    // work of the cutter on the rock over 0.5 m is the rolling force times the
    // distance (pure rolling: no friction work), within 2 % (the start-up pit)
    let (_, fr) = csm(p);
    assert!(
        rel(o.cutting_energy, fr * 0.5) < 0.02,
        "{} vs {}",
        o.cutting_energy,
        fr * 0.5
    );
    assert!(rel(o.specific_energy, o.cutting_energy / o.excavated_volume) < 1e-12);
}

#[test]
fn model_exchange_commits_cut_the_whole_path_between_events() {
    // events 10 mm apart leave the same groove as events 1 mm apart (a CVode
    // host takes long steps); a jump that no step can make is not a path
    let p = 3.8e-3;
    let tw = Twist::new([1.0, 0.0, 0.0], [0.0, 1.0 / R, 0.0]);
    let volume = |every: f64| {
        let mut m = Model::new(Params::default()).unwrap();
        let n = (0.3 / every).round() as usize;
        for k in 0..=n {
            let pose = Pose::new(k as f64 * every, 0.0, R - p, 0.0, 0.0, 0.0);
            m.commit(&pose, &tw, every).unwrap();
        }
        m.evaluate(&Pose::new(0.3, 0.0, R - p, 0.0, 0.0, 0.0), &tw)
            .unwrap()
            .excavated_volume
    };
    let (fine, coarse) = (volume(1e-3), volume(10e-3));
    assert!(rel(coarse, fine) < 5e-3, "{coarse} vs {fine}");
    // a host that puts the cutter 0.5 m further to start a new pass does not
    // cut a trench along the jump
    let mut m = Model::new(Params::default()).unwrap();
    m.commit(
        &Pose::new(0.0, 0.0, R - p, 0.0, 0.0, 0.0),
        &Twist::default(),
        0.0,
    )
    .unwrap();
    let pit = m
        .evaluate(&Pose::new(0.0, 0.0, R - p, 0.0, 0.0, 0.0), &tw)
        .unwrap()
        .excavated_volume;
    m.commit(
        &Pose::new(0.5, 0.0, R - p, 0.0, 0.0, 0.0),
        &Twist::default(),
        1e-3,
    )
    .unwrap();
    let two = m
        .evaluate(&Pose::new(0.5, 0.0, R - p, 0.0, 0.0, 0.0), &tw)
        .unwrap()
        .excavated_volume;
    assert!(rel(two, 2.0 * pit) < 1e-6, "{two} vs {}", 2.0 * pit);
}

#[test]
fn rolling_into_the_end_face_is_felt_at_the_first_sample_that_touches_it() {
    // the rock ends at x = -0.25: rolling in at 3.8 mm, the first contact is
    // a short arc at the face's top edge; it must be found when the rim is
    // first inside the rock, not a few samples later
    let p = 3.8e-3;
    let mut m = Model::new(Params::default()).unwrap();
    let tw = Twist::new([1.0, 0.0, 0.0], [0.0, 1.0 / R, 0.0]);
    let mut pose = Pose::new(-0.30, 0.0, R - p, 0.0, 0.0, 0.0);
    let mut first = None;
    for _ in 0..60 {
        let next = kerf::core::pose::advance_pose(&pose, &tw, 1e-3);
        let o = m.evaluate(&next, &tw).unwrap();
        // the rim's exit from z = 0 lies at x_c + R sin(phi); it touches rock
        // once that passes the face
        let reach = next.position.x + R * ((R - p) / R).acos().sin();
        if reach > -0.25 && first.is_none() {
            first = Some(o.normal_force);
        }
        if reach <= -0.25 {
            assert_eq!(o.normal_force, 0.0);
        }
        pose = m.advance(&pose, &tw, 1e-3).unwrap();
    }
    assert!(
        first.unwrap() > 0.0,
        "contact missed at the first touching sample"
    );
}

#[test]
fn rolling_off_the_end_of_the_rock_unloads_without_a_jump() {
    // the rock ends at x = 1.25: rolling out of it at 3.8 mm, the leading
    // arc shortens to the rock that is left and the load falls with it. The
    // "rock still there" look-ahead (4 mm of travel) read the void past the
    // end as no rock and dropped its three samples one at a time: F_N fell
    // by 15.5 kN (a quarter of the steady cut) in one 1 mm step, 16 mm and
    // again 8 mm before the end, and was gone 5 mm before it
    let p = 3.8e-3;
    let mut m = Model::new(Params::default()).unwrap();
    let tw = Twist::new([1.0, 0.0, 0.0], [0.0, 1.0 / R, 0.0]);
    let mut pose = Pose::new(1.1, 0.0, R - p, 0.0, 0.0, 0.0);
    let (f_ref, _) = csm(p);
    let mut last: Option<f64> = None;
    let mut largest_step = 0.0f64;
    for _ in 0..180 {
        pose = m.advance(&pose, &tw, 1e-3).unwrap();
        let o = m.evaluate(&pose, &tw).unwrap();
        let x = pose.position.x;
        if x >= 1.2 {
            if let Some(f) = last {
                largest_step = largest_step.max((o.normal_force - f).abs());
            }
            last = Some(o.normal_force);
        }
        // 2-3.5 mm before the end there is still a lump of rock 3.6 mm high
        if (1.2465..=1.248).contains(&x) {
            assert!(o.normal_force > 0.02 * f_ref, "x {x}: {}", o.normal_force);
        }
        // past the end the rim is over its own groove only: no contact
        if x > 1.252 {
            assert!(!o.in_contact, "x {x}");
            assert_eq!(o.force, [0.0; 3], "x {x}");
        }
    }
    // the steepest fall is the last 2 mm of rock's (3.4 kN, 5.6 % of F_N)
    assert!(
        largest_step < 0.07 * f_ref,
        "F_N steps by {largest_step} N of {f_ref}"
    );
}

/// kerf.fmu's disc rolling at 0.157 m/s while it plunges at 1 mm/s from
/// 0.1 mm deep in flat rock (every step cuts a little deeper): each step
/// taken twice from the same state, z moved by 1e-15 m the second time,
/// moves the forces by round-off (it moved the normal force by 9e-4 of
/// itself: docs/hosts.md, K1).
#[test]
fn a_plunging_cut_moves_by_round_off_when_the_pose_does() {
    let prm = Params::default();
    let r = prm.cutter.radius;
    let (v, d0, vz) = (0.157, 1e-4, -1e-3);
    let mut m = Model::new(prm).unwrap();
    let tw = Twist::new([v, 0.0, vz], [0.0, v / r, 0.0]);
    let mut worst = 0.0f64;
    for k in 0..60 {
        let t = k as f64 * 1e-3;
        let pose = Pose::new(v * t, 0.0, r - d0 + vz * t, 0.0, 0.0, 0.0);
        let s = m.state();
        let mut moved = pose;
        moved.position.z += 1e-15;
        let e = m.advance(&moved, &tw, 1e-3).unwrap();
        let b = m.evaluate(&e, &tw).unwrap();
        m.set_state(&s).unwrap();
        let e = m.advance(&pose, &tw, 1e-3).unwrap();
        let a = m.evaluate(&e, &tw).unwrap();
        assert!(a.normal_force > 0.0, "step {k} cuts");
        for (x, y) in [
            (a.normal_force, b.normal_force),
            (a.rolling_force, b.rolling_force),
        ] {
            worst = worst.max((x - y).abs() / a.normal_force);
        }
    }
    assert!(
        worst < 1e-7,
        "the forces moved by {worst:e} of the normal force"
    );
}

/// The work booked over a run is the trapezoid of the power the outputs
/// reported after each commit or step, each at its own twist (the twist
/// turns on a curved track): the start of a step's trapezoid is the power
/// reported at its start, not the old pose's power re-evaluated with the new
/// twist. Model Exchange commits, and Co-Simulation steps from host-set
/// poses a round-off away from the model's own ends. Exact to 1e-12 of the
/// total.
#[test]
fn cutting_energy_is_the_trapezoid_of_the_reported_power_on_a_turning_track() {
    use kerf::scenes::{face, Circle, Track, P_REF};
    let prm = face(1e-3, -0.35, 0.35, -0.06, 0.3);
    let track = Circle {
        prm: prm.clone(),
        cx: 0.0,
        cy: 0.25,
        radius: 0.25,
        a0: -std::f64::consts::FRAC_PI_2,
        depth: P_REF,
    };
    let h = 1e-3;
    for cs in [false, true] {
        let mut m = Model::new(prm.clone()).unwrap();
        let (mut booked, mut p0) = (0.0, 0.0);
        for k in 0..=120 {
            let s = k as f64 * h;
            let (pose, tw) = (track.pose(s), track.twist(s));
            let end = if cs {
                m.advance(&pose, &tw, h).unwrap()
            } else {
                m.commit(&pose, &tw, if k == 0 { 0.0 } else { h }).unwrap();
                pose
            };
            let o = m.evaluate(&end, &tw).unwrap();
            let p1 = o.power_into_rock(&tw);
            if k == 0 {
                // (the first step's start is the start pose, cut first)
                booked = o.cutting_energy;
            } else {
                booked += 0.5 * (p0 + p1) * h;
                assert!(
                    (o.cutting_energy - booked).abs() <= 1e-12 * booked,
                    "cs {cs}, step {k}: booked {:e} J, trapezoid of the reported power {booked:e} J",
                    o.cutting_energy
                );
            }
            p0 = p1;
        }
        assert!(booked > 100.0, "the track cuts: {booked} J");
    }
}

/// A Model Exchange host that gives the disc the orientation it spins to
/// (the pose turning about the axle by s / R as it rolls, as a multibody
/// host's revolute joint does) poses the same disc as one that does not: the
/// same rock is cut (the spin adds no sub-steps to the cut path,
/// `rim_travel`) and the same forces come out, in the rock frame and in the
/// cutter frame the contract defines (`Pose::cutter_rotation`: the law's
/// rolling direction does not turn with the spin). Upright and rolled by
/// 30 deg, after 0.15 m: to 1e-9 of the normal force and the volume.
#[test]
fn a_host_that_spins_the_disc_pose_cuts_the_same_rock() {
    use kerf::scenes::{face, pose_with_lowest_point, P_REF};
    let prm = face(1e-3, -0.3, 0.4, -0.06, 0.06);
    for roll in [0.0f64, 30f64.to_radians()] {
        let run = |spin: bool| {
            let mut m = Model::new(prm.clone()).unwrap();
            let base = pose_with_lowest_point(&prm, 0.0, 0.0, P_REF, 0.0, roll);
            let axle = base.rotation() * nalgebra::Vector3::y();
            let tw = Twist::new([1.0, 0.0, 0.0], (axle / R).into());
            let mut o = None;
            for k in 0..=150 {
                let s = k as f64 * 1e-3;
                let at = base.position + nalgebra::Vector3::new(s, 0.0, 0.0);
                let turn = if spin { s / R } else { 0.0 };
                let rot = base.rotation()
                    * nalgebra::Rotation3::from_axis_angle(&nalgebra::Vector3::y_axis(), turn);
                let pose = Pose::from_rotation(at, &rot);
                m.commit(&pose, &tw, if k == 0 { 0.0 } else { 1e-3 })
                    .unwrap();
                o = Some(m.evaluate(&pose, &tw).unwrap());
            }
            o.unwrap()
        };
        let (a, b) = (run(false), run(true));
        let what = format!("roll {roll:.2}: spun {b:?}\nvs not {a:?}");
        assert!(a.normal_force > 20e3, "{what}");
        assert!(rel(b.excavated_volume, a.excavated_volume) < 1e-9, "{what}");
        let tol = 1e-9 * a.normal_force;
        for i in 0..3 {
            assert!((b.force[i] - a.force[i]).abs() < tol, "{what}");
        }
        assert!((b.normal_force - a.normal_force).abs() < tol, "{what}");
        assert!((b.rolling_force - a.rolling_force).abs() < tol, "{what}");
        assert!((b.side_force - a.side_force).abs() < tol, "{what}");
    }
}
