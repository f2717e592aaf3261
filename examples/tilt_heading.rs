//! A tilted disc's fresh straight cut against the angle between its track
//! and the grid: `scenes::TiltedArc` (radius 0) rolled by TILT_DEG, 3.8 mm
//! deep at 1 m/s through fresh rock, heading 0, 5, 15, 30 and 45 deg to the
//! grid, at 0.25, 0.5 and 1 mm cells. Prints the mean cutting force
//! (normal / rolling / side, kN, friction left out) over 0.15-0.28 m of a
//! 0.3 m pass, then the normal force of the fast contact and of the
//! brute-force oracle at the pose 0.2 m along (1 mm cells), which read the
//! same map. The physics does not know the grid: every row should read the
//! same (docs/head.md, "Tilted discs across the grid").
//! `cargo run --release --example tilt_heading -- [TILT_DEG]` (default -60).
use kerf::core::contact_bruteforce::Resolution;
use kerf::core::Model;
use kerf::scenes::*;

fn main() {
    let tilt: f64 = std::env::args()
        .nth(1)
        .map_or(-60.0, |s| s.parse().unwrap());
    println!(
        "tilt {tilt} deg; F_N / F_R / F_S kN at 0.25 | 0.5 | 1 mm cells | F_N at 0.2 m, 1 mm: fast / oracle"
    );
    // the face at cells of `cell` and the track heading `yaw` deg to the grid
    let scene = |yaw: f64, cell: f64| {
        let prm = face(cell, -0.35, 0.35, -0.35, 0.35);
        let track = TiltedArc {
            prm: prm.clone(),
            yaw: yaw.to_radians(),
            roll: tilt.to_radians(),
            depth: P_REF,
            radius: 0.0,
            speed: 1.0,
        };
        (prm, track)
    };
    for yaw in [0.0f64, 5.0, 15.0, 30.0, 45.0] {
        let mut row = format!("heading {yaw:4} deg:");
        for cell in [0.25e-3, 0.5e-3, 1e-3] {
            let (prm, track) = scene(yaw, cell);
            let mut m = Model::new(prm).unwrap();
            let mean = roll(&mut m, &track, 0.3, 1e-3, 0.15, 0.28);
            row += &format!(
                " | {:.2} / {:.2} / {:.2}",
                mean.cutting[0] / 1e3,
                mean.cutting[1] / 1e3,
                mean.cutting[2] / 1e3
            );
        }
        let (prm, track) = scene(yaw, 1e-3);
        let (m, pose, tw) = rolled(&prm, &[(&track as &dyn Track, 0.2)]);
        let fast = cutting_force(&pose, &m.contact(&pose, &tw));
        let brute = cutting_force(&pose, &m.contact_brute(&pose, &tw, &Resolution::default()));
        row += &format!(" | {:.2} / {:.2}", fast[0] / 1e3, brute[0] / 1e3);
        println!("{row}");
    }
}
