//! The real CCS disc section (issue 7, item 2): straight flanks at
//! `cutter.flankAngle` from the tip's edges to the hub width. The solid's
//! geometry against brute force, the cut against the section's area, the
//! flank element against a numerical surface integral, the fast contact
//! against the brute-force oracle on tilted and deep scenes, and flank
//! angle 0 being the thesis's disc bit for bit. Tolerances are fractions of
//! the fresh cut's normal force `FN` (60.8 kN) unless a test says otherwise.

use kerf::core::contact_bruteforce::Resolution;
use kerf::core::contact_law::{Element, Motion};
use kerf::core::cutter::{Face, PosedDisc};
use kerf::core::params::CutterParams;
use kerf::core::{Params, Pose, Twist};
use kerf::scenes::*;
use nalgebra::Vector3;

const FN: f64 = 60_795.388;

fn diff(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|i| (a[i] - b[i]).abs()).fold(0.0, f64::max) / FN
}

/// Is the cutter-frame point `q` inside the flanked solid?
fn inside(d: &PosedDisc, q: &Vector3<f64>) -> bool {
    q.y.abs() <= d.hub_half_width && (q.x * q.x + q.z * q.z).sqrt() <= d.rho_full(q.y)
}

#[test]
fn the_flanked_section_is_the_tip_then_straight_flanks_then_the_hub() {
    let c = flanked_cutter(FLANK_DEG);
    let d = PosedDisc::new(&c, &Pose::new(0.0, 0.0, 0.3, 0.0, 0.0, 0.0));
    let h = 0.5 * c.tip_width;
    let f = c.flank_angle;
    // across the tip: the tip profile itself
    for y in [-h, -0.003, 0.0, 0.004, h] {
        assert_eq!(d.rho_full(y).to_bits(), d.rho(y).to_bits());
    }
    // along the flank the radius falls 1/tan(f) per metre of axle
    let y = h + 0.01;
    assert!((d.rho_full(y) - (d.rho(h) - 0.01 / f.tan())).abs() < 1e-12);
    assert!((d.rho_full(-y) - d.rho_full(y)).abs() < 1e-15);
    let (sn, cn) = d.flank_normal();
    assert!((sn - f.sin()).abs() < 1e-15 && (cn - f.cos()).abs() < 1e-15);
    // concave across the seam (the convexity rule holds for this disc)
    let e = 1e-6;
    let slope_tip = (d.rho(h) - d.rho(h - e)) / e;
    let slope_flank = (d.rho_full(h + e) - d.rho(h)) / e;
    assert!(slope_flank < slope_tip, "{slope_tip} {slope_flank}");
}

#[test]
fn lower_boundary_of_the_flanked_solid_agrees_with_a_brute_force_scan() {
    let c = flanked_cutter(FLANK_DEG);
    let mut faces = [false; 3];
    for &(yaw, roll) in &[
        (0.0, 0.0),
        (0.3, 0.2),
        (0.0, 0.5),
        (0.7, 1.0),
        (0.0, -1.2),
        (1.0, 1.45),
    ] {
        let d = PosedDisc::new(&c, &Pose::new(0.0, 0.0, 0.2, yaw, 0.1, roll));
        let rt = d.rot.transpose();
        for a in 0..=60 {
            for b in 0..=60 {
                let x = -0.24 + 0.48 * a as f64 / 60.0;
                let y = -0.24 + 0.48 * b as f64 / 60.0;
                let local = |z: f64| rt * (Vector3::new(x, y, z) - d.centre);
                match d.lower_boundary(x, y) {
                    None => {
                        // no point of the line in the solid (0.02 mm scan)
                        for k in 0..=25_000 {
                            let z = -0.1 + 0.5 * k as f64 / 25_000.0;
                            assert!(
                                !inside(&d, &local(z)),
                                "pose {yaw} {roll}: ({x}, {y}) missed, but z = {z} is inside"
                            );
                        }
                    }
                    Some((zl, face)) => {
                        // on the surface, with nothing of the solid just below
                        // (convex: then nothing below at all)
                        let q = local(zl);
                        let g = (q.x * q.x + q.z * q.z).sqrt()
                            - d.rho_full(q.y.clamp(-d.hub_half_width, d.hub_half_width));
                        assert!(
                            g < 1e-9 && q.y.abs() <= d.hub_half_width + 1e-9,
                            "pose {yaw} {roll} at ({x}, {y}): {zl} is outside ({g}, {q})"
                        );
                        assert!(
                            !inside(&d, &local(zl - 1e-8)),
                            "pose {yaw} {roll} at ({x}, {y}): the solid reaches below {zl}"
                        );
                        match face {
                            Face::Rim { y } => {
                                faces[0] = true;
                                assert!(y.abs() <= d.half_width + 1e-12 && (q.y - y).abs() < 1e-9)
                            }
                            Face::Flank { y } => {
                                faces[1] = true;
                                assert!(y.abs() > d.half_width && (q.y - y).abs() < 1e-9)
                            }
                            Face::Side(s) => {
                                faces[2] = true;
                                assert!((q.y - f64::from(s) * d.hub_half_width).abs() < 1e-9)
                            }
                        }
                    }
                }
            }
        }
    }
    assert_eq!(faces, [true; 3], "every face met: rim, flank, hub");
}

#[test]
fn footprint_and_lowest_point_hold_the_flanks() {
    let c = flanked_cutter(FLANK_DEG);
    for &(yaw, pitch, roll) in &[
        (0.0, 0.0, 0.0),
        (0.3, 0.1, 0.6),
        (0.0, 0.0, 1.2),
        (0.7, -0.2, -1.4),
        (0.0, 0.0, 60f64.to_radians()),
        (0.2, 0.0, -0.3),
    ] {
        let d = PosedDisc::new(&c, &Pose::new(0.0, 0.0, 0.2, yaw, pitch, roll));
        // the lowest point: the lowest of a fine sampling of the section's
        // circles (the flanks' lowest points are at their ends)
        let low = d.lowest_point();
        let mut best = f64::INFINITY;
        let n = 4000;
        let ys = (0..=n)
            .map(|k| -d.hub_half_width + 2.0 * d.hub_half_width * k as f64 / n as f64)
            .chain([-d.half_width, d.half_width]);
        for y in ys {
            let rho = d.rho_full(y);
            let (t0, _) = d.arc_below(y, rho, f64::MAX).unwrap();
            let p = d.to_world(&Vector3::new(rho * t0.sin(), y, -rho * t0.cos()));
            best = best.min(p.z);
        }
        assert!(
            // lowest_point samples 201 slices of the tip: (T/200)^2 / r
            low.z <= best + (c.tip_width / 200.0).powi(2) / c.tip_radius && low.z > best - 1e-7,
            "{yaw} {pitch} {roll}: {} vs {best}",
            low.z
        );
        // every point of the solid below z_top lies in the footprint: the
        // extremes of a convex solid cut by a plane are on its section
        // circles, sampled densely (400 x 3000)
        for dz in [0.0005, 0.002, 0.01, 0.05] {
            let z_top = low.z + dz;
            let bb = d.footprint_below(z_top).unwrap();
            let mut ext = [
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::INFINITY,
                f64::NEG_INFINITY,
            ];
            for k in 0..=400 {
                let y = -d.hub_half_width + 2.0 * d.hub_half_width * k as f64 / 400.0;
                let rho = d.rho_full(y);
                for i in 0..3000 {
                    let t = std::f64::consts::TAU * i as f64 / 3000.0;
                    let p = d.to_world(&Vector3::new(rho * t.sin(), y, -rho * t.cos()));
                    if p.z < z_top {
                        assert!(
                            p.x >= bb[0] && p.x <= bb[1] && p.y >= bb[2] && p.y <= bb[3],
                            "{yaw} {pitch} {roll} dz {dz}: {p} outside {bb:?}"
                        );
                        ext = [
                            ext[0].min(p.x),
                            ext[1].max(p.x),
                            ext[2].min(p.y),
                            ext[3].max(p.y),
                        ];
                    }
                }
            }
            eprintln!(
                "{yaw} {pitch} {roll} dz {dz}: box {:.1} x {:.1} mm, solid {:.1} x {:.1} mm",
                (bb[1] - bb[0]) * 1e3,
                (bb[3] - bb[2]) * 1e3,
                (ext[1] - ext[0]) * 1e3,
                (ext[3] - ext[2]) * 1e3
            );
        }
        // and the vertical lines that meet the solid below z_top
        let z_top = low.z + 0.03;
        let bb = d.footprint_below(z_top).unwrap();
        let n = 200;
        for a in 0..=n {
            for b in 0..=n {
                let x = -0.25 + 0.5 * a as f64 / n as f64;
                let y = -0.25 + 0.5 * b as f64 / n as f64;
                if let Some((zl, _)) = d.lower_boundary(x, y) {
                    if zl < z_top {
                        assert!(
                            x >= bb[0] && x <= bb[1] && y >= bb[2] && y <= bb[3],
                            "{yaw} {pitch} {roll}: ({x}, {y}) outside {bb:?}"
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn the_flank_element_is_the_pressure_integral_over_the_cone() {
    // -n dA summed over a patch of the cone, with n and dA from the
    // surface's own parametrisation, against the element's closed form;
    // and v_n against (v + w x q) . n
    let c = flanked_cutter(FLANK_DEG);
    let d = PosedDisc::new(&c, &Pose::new(0.0, 0.0, 0.3, 0.0, 0.0, 0.0));
    let m = Motion::new(&d, &Twist::new([1.0, 0.3, -0.2], [0.4, 4.6, -0.7]), 0.0);
    let (sn, cn) = d.flank_normal();
    for side in [1.0f64, -1.0] {
        let (s0, ds) = (0.004, 1e-4);
        let y = side * (d.half_width + (s0 + 0.5 * ds) * sn);
        let e = Element::flank(&d, y, ds, &m);
        let (t0, t1) = (-0.3, 0.5);
        let (nt, ns) = (4000, 8);
        let (mut f, mut mo) = (Vector3::zeros(), Vector3::zeros());
        let point = |t: f64, s: f64| {
            let (yy, rho) = (side * (d.half_width + s * sn), d.rho(d.half_width) - s * cn);
            Vector3::new(rho * t.sin(), yy, -rho * t.cos())
        };
        for i in 0..nt {
            for j in 0..ns {
                let t = t0 + (t1 - t0) * (i as f64 + 0.5) / nt as f64;
                let s = s0 + ds * (j as f64 + 0.5) / ns as f64;
                let (ht, hs) = (1e-7, 1e-9);
                let pt = (point(t + ht, s) - point(t - ht, s)) / (2.0 * ht);
                let ps = (point(t, s + hs) - point(t, s - hs)) / (2.0 * hs);
                let mut n = pt.cross(&ps);
                let q = point(t, s);
                // outward: away from the axle and the mid-plane
                if n.dot(&Vector3::new(q.x, side, q.z)) < 0.0 {
                    n = -n;
                }
                let w = (t1 - t0) / nt as f64 * ds / ns as f64;
                f -= n * w;
                mo -= q.cross(&n) * w;
                if j == 0 && i % 500 == 0 {
                    // at the band's middle, where the element sits
                    let s = s0 + 0.5 * ds;
                    let q = point(t, s);
                    let pt = (point(t + ht, s) - point(t - ht, s)) / (2.0 * ht);
                    let ps = (point(t, s + hs) - point(t, s - hs)) / (2.0 * hs);
                    let mut n = pt.cross(&ps).normalize();
                    if n.dot(&Vector3::new(q.x, side, q.z)) < 0.0 {
                        n = -n;
                    }
                    let direct = (m.v + m.w.cross(&q)).dot(&n);
                    assert!(
                        (direct - e.vn_at(t)).abs() < 1e-6,
                        "{direct} {}",
                        e.vn_at(t)
                    );
                }
            }
        }
        let fi = e.force.integral(t0, t1);
        let mi = e.moment.integral(t0, t1);
        assert!((f - fi).norm() < 1e-5 * fi.norm(), "{f} {fi}");
        assert!((mo - mi).norm() < 1e-5 * mi.norm(), "{mo} {mi}");
    }
}

#[test]
fn a_deep_cut_removes_the_flanked_section() {
    // the rock removed per metre of a fresh upright cut is the section's
    // area below the face, the flanks' wedges included
    for flank in [0.0, FLANK_DEG] {
        let c = flanked_cutter(flank);
        let d = PosedDisc::new(&c, &Pose::new(0.0, 0.0, 0.3, 0.0, 0.0, 0.0));
        let p = 12e-3;
        let n = 100_000;
        let hw = d.hub_half_width;
        let area: f64 = (0..n)
            .map(|k| {
                let y = -hw + 2.0 * hw * (k as f64 + 0.5) / n as f64;
                (p - (c.radius - d.rho_full(y))).max(0.0) * 2.0 * hw / n as f64
            })
            .sum();
        let m = fresh_disc(&c, 1e-3, p, 0.0);
        let got = m.volume / m.length;
        // 1 mm cells: the groove's edges are resolved to a cell
        assert!(
            (got / area - 1.0).abs() < 0.03,
            "flank {flank}: {got} vs {area}"
        );
    }
}

#[test]
fn the_fast_contact_matches_the_oracle_with_flanks() {
    // the oracle samples the surface every 0.05 mm: 101 tip slices, 60
    // hub-face rings, 200 bands along each flank. Held to 1.5 % of FN per
    // component (measured: at most 0.85 %, the side force tilted 60 deg)
    let c = flanked_cutter(FLANK_DEG);
    let flat = flank_scenes(&CutterParams::default(), 1e-3);
    for ((name, m, pose, tw), (_, m0, pose0, tw0)) in flank_scenes(&c, 1e-3).iter().zip(&flat) {
        let fast = cutting_force(pose, &m.contact(pose, tw));
        let brute = cutting_force(pose, &m.contact_brute(pose, tw, &Resolution::default()));
        let e = diff(fast, brute);
        assert!(e < 0.015, "{name}: fast {fast:?} brute {brute:?} ({e})");
        // the flanks bear: the flanked disc feels more than the flat one
        let b0 = cutting_force(pose0, &m0.contact_brute(pose0, tw0, &Resolution::default()));
        assert!(
            brute[0] > b0[0] + 0.02 * FN,
            "{name}: {brute:?} vs flat {b0:?}"
        );
    }
}

#[test]
fn flank_angle_zero_is_the_thesis_disc_bit_for_bit() {
    // the hub width is ignored without flanks, and a hub no wider than the
    // tip has no flanks whatever the angle: same forces, same rock, to the bit
    let thesis = CutterParams::default();
    let others = [
        CutterParams {
            hub_width: 0.05,
            ..thesis
        },
        CutterParams {
            flank_angle: 0.3,
            hub_width: thesis.tip_width,
            ..thesis
        },
    ];
    for (depth, roll) in [(P_REF, 0.0), (P_REF, 30f64.to_radians()), (12e-3, 0.0)] {
        let a = fresh_disc(&thesis, 1e-3, depth, roll);
        for c in &others {
            let b = fresh_disc(c, 1e-3, depth, roll);
            assert_eq!(
                a,
                Mean {
                    us_median: a.us_median,
                    ..b
                },
                "{c:?} {depth} {roll}"
            );
        }
    }
}

#[test]
fn flank_parameters_are_checked() {
    let ok = |c: CutterParams| {
        let p = Params {
            cutter: c,
            ..Params::default()
        };
        p.validate().map_err(|e| e.to_string())
    };
    let base = CutterParams::default();
    assert!(ok(flanked_cutter(FLANK_DEG)).is_ok());
    // the steepest convex flank for the thesis's tip: pi/2 - asin(T/2r) = 59.2 deg
    let max = base.max_flank_angle();
    assert!(
        (max.to_degrees() - 59.218).abs() < 1e-2,
        "{}",
        max.to_degrees()
    );
    assert!(ok(CutterParams {
        flank_angle: max,
        ..flanked_cutter(0.0)
    })
    .is_ok());
    let e = ok(CutterParams {
        flank_angle: max + 1e-3,
        ..flanked_cutter(0.0)
    })
    .unwrap_err();
    assert!(
        e.starts_with("parameter cutter.flankAngle") && e.contains("non-convex"),
        "{e}"
    );
    let e = ok(CutterParams {
        flank_angle: 0.3,
        hub_width: 0.01,
        ..base
    })
    .unwrap_err();
    assert!(
        e.starts_with("parameter cutter.hubWidth") && e.contains("tipWidth"),
        "{e}"
    );
    // a flank so steep it meets the axle before the hub width
    let e = ok(CutterParams {
        flank_angle: 0.01,
        hub_width: 0.4,
        ..base
    })
    .unwrap_err();
    assert!(
        e.starts_with("parameter cutter.hubWidth") && e.contains("axle"),
        "{e}"
    );
    // out of bounds
    assert!(ok(CutterParams {
        flank_angle: -0.1,
        ..base
    })
    .is_err());
    // without flanks the hub width only has to be in its bounds
    assert!(ok(CutterParams {
        hub_width: 0.001,
        ..base
    })
    .is_ok());
}
