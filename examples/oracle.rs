//! Fast contact vs the brute-force oracle on the oracle scenes' end poses
//! (`kerf::scenes::oracle_scenes`), with the cost of each:
//! `cargo run --release --example oracle`.
use kerf::core::contact_bruteforce::Resolution;
use kerf::scenes::{cutting_force, oracle_scenes};

fn main() {
    let fresh_n = 60795.388;
    for (name, m, pose, tw) in oracle_scenes(1e-3) {
        let t0 = std::time::Instant::now();
        let fast = cutting_force(&pose, &m.contact(&pose, &tw));
        let tf = t0.elapsed().as_secs_f64() * 1e6;
        let t0 = std::time::Instant::now();
        let brute = cutting_force(&pose, &m.contact_brute(&pose, &tw, &Resolution::default()));
        let tb = t0.elapsed().as_secs_f64() * 1e3;
        let d: Vec<f64> = (0..3)
            .map(|i| (fast[i] - brute[i]) / fresh_n * 100.0)
            .collect();
        println!(
            "{name:<14} N/R/S fast {:7.0} {:7.0} {:7.0}  brute {:7.0} {:7.0} {:7.0}  diff % of Fn {:6.2} {:6.2} {:6.2}  {tf:.0} us / {tb:.0} ms",
            fast[0], fast[1], fast[2], brute[0], brute[1], brute[2], d[0], d[1], d[2]
        );
    }
}
