//! The cut visits only a window of nodes about the disc (its heading box,
//! row by row): held here against a cut that visits every node of the map
//! and asks the solid for each one.

use kerf::core::cut_cutter_heightmap::cut;
use kerf::core::cutter::PosedDisc;
use kerf::core::heightmap::{Grid, HeightMap};
use kerf::core::params::CutterParams;
use kerf::core::Pose;

const ELASTIC: f64 = 2e-6;

/// A 0.6 m square face at 1 mm cells with a groove 3 mm deep along a
/// diagonal and a 2 mm step, so windows meet uneven rock.
fn face() -> HeightMap {
    let g = Grid::new(-0.3, 0.3, -0.3, 0.3, 601, 601);
    let mut m = HeightMap::flat(g, 0.0);
    for j in 0..601 {
        for i in 0..601 {
            let (x, y) = g.node_xy(i, j);
            let mut z = if x > 0.05 { 0.002 } else { 0.0 };
            if (x - y).abs() < 0.008 {
                z -= 0.003;
            }
            m.set_node(i, j, z);
        }
    }
    m
}

/// Every node of the map against the solid's lower boundary.
fn brute_cut(map: &mut HeightMap, disc: &PosedDisc, fraction: f64) -> usize {
    let g = *map.grid();
    let mut n = 0;
    for j in 0..g.ny {
        for i in 0..g.nx {
            let (x, y) = g.node_xy(i, j);
            let z = map.node(i, j);
            if let Some((zl, _)) = disc.lower_boundary(x, y) {
                let excess = z - (zl + ELASTIC);
                if excess > 1e-10 {
                    map.lower_node(i, j, z - fraction * excess);
                    n += 1;
                }
            }
        }
    }
    n
}

#[test]
fn the_windowed_cut_lowers_exactly_the_nodes_a_full_scan_lowers() {
    let flanked = CutterParams {
        flank_angle: 30f64.to_radians(),
        hub_width: 0.04,
        ..CutterParams::default()
    };
    let mut checked = 0;
    for c in [CutterParams::default(), flanked] {
        for heading in [0.0f64, 17.0, 45.0, 90.0, 133.0, 250.0] {
            for tilt in [0.0f64, 12.0, 35.0, 60.0] {
                for (x, y, depth) in [(0.0, 0.0, 0.004), (0.06, -0.02, 0.007), (-0.1, 0.1, 0.001)] {
                    let (yaw, roll) = (heading.to_radians(), tilt.to_radians());
                    let probe = Pose::new(0.0, 0.0, 1.0, yaw, 0.0, roll);
                    let low = PosedDisc::new(&c, &probe).lowest_point();
                    let pose = Pose::new(x - low.x, y - low.y, 1.0 - low.z - depth, yaw, 0.0, roll);
                    let disc = PosedDisc::new(&c, &pose);
                    let (mut a, mut b) = (face(), face());
                    let stats = cut(&mut a, &disc, ELASTIC, 1.0, (None, None));
                    let n = brute_cut(&mut b, &disc, 1.0);
                    assert_eq!(
                        stats.nodes, n,
                        "heading {heading} tilt {tilt} at ({x}, {y})"
                    );
                    let g = *a.grid();
                    for j in 0..g.ny {
                        for i in 0..g.nx {
                            let (za, zb) = (a.node(i, j), b.node(i, j));
                            assert!(
                                (za - zb).abs() < 1e-12,
                                "heading {heading} tilt {tilt}: node ({i}, {j}) {za} vs {zb}"
                            );
                        }
                    }
                    assert!(
                        n > 0,
                        "heading {heading} tilt {tilt}: the scene cuts nothing"
                    );
                    checked += 1;
                }
            }
        }
    }
    assert_eq!(checked, 144);
}

/// A row of nodes that keeps its axle coordinate gets a floor, the lowest
/// the solid reaches in the row's vertical plane, found once: it must lie
/// at or below the solid's lower boundary at every point of the row, and
/// equal the lowest of them (here sampled every 5 um).
#[test]
fn a_rows_floor_is_the_lowest_the_solid_reaches_along_the_row() {
    let c = CutterParams::default();
    let mut checked = 0;
    for tilt in [3.0f64, 12.0, 35.0, 60.0, 85.0] {
        for z in [0.2f64, 0.2159, 0.23] {
            let pose = Pose::new(0.01, -0.02, z, 0.0, 0.0, tilt.to_radians());
            let disc = PosedDisc::new(&c, &pose);
            let rt = disc.rot.transpose();
            let d = rt.column(2).into_owned();
            let step = rt.column(0) * 1e-3;
            assert!(step.y.abs() < 1e-15, "a row along x keeps y_local");
            for k in -40..=40 {
                let y = -0.02 + 1e-3 * k as f64;
                let x0 = -0.3;
                let a = rt
                    * nalgebra::Vector3::new(x0 - disc.centre.x, y - disc.centre.y, -disc.centre.z);
                let floor = disc.row_floor(&a, &d, &step);
                let lowest = (0..120_000)
                    .filter_map(|i| disc.lower_boundary(x0 + 5e-6 * i as f64, y))
                    .map(|(z, _)| z)
                    .fold(f64::INFINITY, f64::min);
                match floor {
                    None => assert!(
                        lowest.is_infinite(),
                        "tilt {tilt} y {y}: no floor, solid at {lowest}"
                    ),
                    Some(f) => {
                        assert!(
                            f <= lowest + 1e-12,
                            "tilt {tilt} y {y}: floor {f} above {lowest}"
                        );
                        assert!(
                            f >= lowest - 1e-9,
                            "tilt {tilt} y {y}: floor {f} far below {lowest}"
                        );
                        checked += 1;
                    }
                }
            }
        }
    }
    assert!(checked > 300, "{checked} rows met the solid");
}
