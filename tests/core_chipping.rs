//! Rock chips between grooves (issue 9): a virtual LCM block cut by
//! sequential passes, through the core model. Tolerances at each assertion.
//!
//! The scene: thesis Table 2's disc and rock, 1 mm cells, p = 3.8 mm; a first
//! pass at y = 0 (unrelieved) and a second at y = -S beside it.

use kerf::core::csm::{contact_angle, CsmLaw};
use kerf::core::{Model, Outputs, Params, Pose, Twist};

const R: f64 = 0.2159;
const P: f64 = 0.0038;

fn block(chipping: bool, seed: i32) -> Params {
    let mut p = Params::default();
    p.rock.x_min = -0.25;
    p.rock.x_max = 0.75;
    p.rock.y_min = -0.3;
    p.rock.y_max = 0.15;
    p.rock.nx = 1001;
    p.rock.ny = 451;
    p.chipping.enabled = chipping;
    p.chipping.seed = seed;
    p
}

/// One pass along +x at `y`, depth P, from x = 0 to 0.5 at `v` m/s in CS
/// steps of about `h` s (rounded so the pass ends at 0.5); returns the
/// outputs after each step whose centre lies in the window 0.1..0.4, and the
/// volume removed over the pass.
fn pass(m: &mut Model, y: f64, v: f64, h: f64) -> (Vec<Outputs>, f64) {
    let tw = Twist::new([v, 0.0, 0.0], [0.0, v / R, 0.0]);
    let mut pose = Pose::new(0.0, y, R - P, 0.0, 0.0, 0.0);
    let v0 = m.evaluate(&pose, &tw).unwrap().excavated_volume;
    let mut out = vec![];
    let n = (0.5 / (v * h)).round() as usize;
    for _ in 0..n {
        pose = m.advance(&pose, &tw, 0.5 / (v * n as f64)).unwrap();
        let o = m.evaluate(&pose, &tw).unwrap();
        if (0.1..=0.4).contains(&pose.position.x) {
            out.push(o);
        }
    }
    let v1 = m.evaluate(&pose, &tw).unwrap().excavated_volume;
    (out, v1 - v0)
}

fn two_passes(s: f64, chipping: bool, seed: i32, v: f64, h: f64) -> (Model, Vec<Outputs>, f64) {
    two_passes_of(block(chipping, seed), s, v, h)
}

fn two_passes_of(p: Params, s: f64, v: f64, h: f64) -> (Model, Vec<Outputs>, f64) {
    let mut m = Model::new(p).unwrap();
    pass(&mut m, 0.0, v, h);
    let (o, vol) = pass(&mut m, -s, v, h);
    (m, o, vol)
}

fn mean(o: &[Outputs], f: impl Fn(&Outputs) -> f64) -> f64 {
    o.iter().map(f).sum::<f64>() / o.len() as f64
}

#[test]
fn off_is_exactly_the_model_without_chips() {
    // the default has chipping off; a disabled chip model never touches the rock
    assert!(!Params::default().chipping.enabled);
    let (a, oa, va) = two_passes(0.051, false, 1, 1.0, 0.002);
    let (b, ob, vb) = two_passes(0.051, false, 99, 1.0, 0.002);
    assert!(a.state() == b.state(), "the states differ");
    assert_eq!(oa, ob);
    assert_eq!(va, vb);
    assert!(oa
        .iter()
        .all(|o| o.chip_count == 0 && o.chipped_volume == 0.0));
}

#[test]
fn a_relieved_pass_below_the_critical_spacing_removes_the_ridge() {
    // S = 51 mm, p = 3.8 mm: S/p = 13.4, ridge 38 mm < kappa p = 57 mm
    let s = 0.051;
    let (_, o, vol) = two_passes(s, true, 1, 1.0, 0.002);
    let (_, _, vol_off) = two_passes(s, false, 1, 1.0, 0.002);
    let last = o.last().unwrap();
    assert!(last.chip_count > 0);
    // volume per metre of the second pass: the groove plus the ridge, S x p
    // (the chips run from this groove's bottom to the old groove's, so
    // within the shape of the groove ends: 20 %)
    let per_m = vol / 0.5;
    assert!(
        (per_m - s * P).abs() < 0.2 * s * P,
        "{per_m:.3e} m3/m vs S p = {:.3e}",
        s * P
    );
    // without chips the pass removes only its groove, a third of that
    assert!(vol_off / 0.5 < 0.45 * s * P, "{vol_off}");
    // the chips' volume is the difference, and is counted in both outputs
    assert!(last.chipped_volume > 0.0 && last.chipped_volume < last.excavated_volume);
}

#[test]
fn far_apart_the_ridge_stays() {
    // S = 100 mm: ridge 87 mm > kappa p = 57 mm
    let (m, o, vol) = two_passes(0.1, true, 1, 1.0, 0.002);
    let (_, _, vol_off) = two_passes(0.1, false, 1, 1.0, 0.002);
    assert_eq!(o.last().unwrap().chip_count, 0);
    assert!((vol - vol_off).abs() < 1e-12);
    // the ridge between the grooves is intact at full height
    assert_eq!(m.map().height(0.3, -0.05), 0.0);
}

/// `chipping.pressureScale` belongs to relieved passes: a pass whose cracks
/// reach no free surface breaks out nothing, so its rock is the rock without
/// chips, and so is its force, bit for bit (the factor used to apply to
/// every pass with chipping on: 1.5 times the closed form here). A relieved
/// pass takes the factor from its first chip boundary on.
#[test]
fn only_a_relieved_pass_takes_the_pressure_scale() {
    let p = block(true, 1);
    let plain = CsmLaw::new(p.cutter, p.csm, p.numerics.p_reg);
    // far apart (S = 100 mm > T + kappa p): neither pass is relieved
    let (m_on, on, _) = two_passes(0.1, true, 1, 1.0, 0.002);
    let (_, off, _) = two_passes(0.1, false, 1, 1.0, 0.002);
    assert!(!m_on.state().disc().chips().relieved());
    assert_eq!(*m_on.law(), plain);
    assert_eq!(on.len(), off.len());
    for (a, b) in on.iter().zip(&off) {
        assert_eq!(a.force, b.force);
        assert_eq!(a.normal_force.to_bits(), b.normal_force.to_bits());
    }
    // beside a groove at 51 mm: relieved, and the law is the scaled one
    let (m, rel, _) = two_passes(0.051, true, 1, 1.0, 0.002);
    assert!(m.state().disc().chips().relieved());
    assert_eq!(m.law().pressure_scale(), p.chipping.pressure_scale);
    assert!(rel.last().unwrap().chip_count > 0);
}

#[test]
fn chips_do_not_depend_on_speed_or_step_and_replay_bit_for_bit() {
    let (a, oa, _) = two_passes(0.051, true, 7, 1.0, 0.002);
    let (b, ob, _) = two_passes(0.051, true, 7, 1.0, 0.002);
    assert!(a.state() == b.state(), "the states differ");
    assert_eq!(oa, ob);
    let n = oa.last().unwrap().chip_count;
    // slower, with other steps: the same chips. Their volume follows the
    // grooves, whose bottoms differ by the sub-step scallops of the cut
    // itself ((s/2)^2 / 2R < 0.6 um at 1 mm sub-steps): 0.1 %
    for (v, h) in [(0.2, 0.013), (2.0, 0.0007)] {
        let (_, oc, _) = two_passes(0.051, true, 7, v, h);
        let c = oc.last().unwrap();
        assert_eq!(c.chip_count, n, "v = {v}, h = {h}");
        let va = oa.last().unwrap().chipped_volume;
        assert!(
            (c.chipped_volume - va).abs() < 1e-3 * va,
            "{} vs {va}",
            c.chipped_volume
        );
    }
}

#[test]
fn another_seed_scatters_the_chips_but_keeps_the_mean() {
    // a 3 m relieved pass (about 60 chips a side); means over its middle 2 m
    let run = |seed| {
        let mut p = block(true, seed);
        p.rock.x_max = 3.25;
        p.rock.nx = 3501;
        let mut m = Model::new(p).unwrap();
        let tw = Twist::new([1.0, 0.0, 0.0], [0.0, 1.0 / R, 0.0]);
        let mut out = vec![];
        for y in [0.0, -0.051] {
            out.clear();
            let mut pose = Pose::new(0.0, y, R - P, 0.0, 0.0, 0.0);
            for _ in 0..1500 {
                pose = m.advance(&pose, &tw, 0.002).unwrap();
                if (0.5..=2.5).contains(&pose.position.x) {
                    out.push(m.evaluate(&pose, &tw).unwrap());
                }
            }
        }
        out
    };
    let (a, b) = (run(1), run(2));
    assert_ne!(a, b);
    let vol = |o: &[Outputs]| o.last().unwrap().excavated_volume - o[0].excavated_volume;
    assert!(
        (vol(&a) - vol(&b)).abs() < 0.03 * vol(&a),
        "{} vs {}",
        vol(&a),
        vol(&b)
    );
    // the force drops after each chip (less rock ahead) and rises again, so
    // its mean follows where the chips fall in the window (40 +- 1.2 chips
    // for a uniform spread of +-50 %): 5 % on both
    type Field = fn(&Outputs) -> f64;
    let tol: [(Field, f64); 2] = [(|o| o.normal_force, 0.05), (|o| o.rolling_force, 0.05)];
    for (f, t) in tol {
        let (ma, mb) = (mean(&a, f), mean(&b, f));
        assert!((ma - mb).abs() < t * ma, "{ma} vs {mb}");
    }
}

#[test]
fn the_relieved_cut_saw_tooths_and_the_unrelieved_one_does_not() {
    let cv = |o: &[Outputs]| {
        let m = mean(o, |o| o.normal_force);
        (mean(o, |o| (o.normal_force - m).powi(2))).sqrt() / m
    };
    // at the closed form's pressure (chipping.pressureScale 1), so that the
    // two runs differ only in the rock the chips took
    let mut p = block(true, 1);
    p.chipping.pressure_scale = 1.0;
    let (_, on, _) = two_passes_of(p, 0.051, 1.0, 0.001);
    let (_, off, _) = two_passes(0.051, false, 1, 1.0, 0.001);
    // with chips the force drops where the rock ahead broke out and rises
    // on intact rock; without, the relieved pass is steady to 1 %
    let (c_on, c_off) = (cv(&on), cv(&off));
    eprintln!("normal-force CV: chips {c_on:.3}, none {c_off:.4}");
    assert!(c_off < 0.01, "{c_off}");
    // no disc LCM CV was reachable (shared/research/lcm-data.md); traces of
    // relieved cuts swing between about half and twice the mean and do not
    // drop to zero between chips, a CV of roughly 0.1-0.4 (0.24 here)
    assert!(c_on > 0.05 && c_on < 0.5, "{c_on}");
    assert!(mean(&on, |o| o.normal_force) < mean(&off, |o| o.normal_force));
}

/// An LCM series at spacing `s`: four passes side by side towards -y (each
/// relieved by the one before, at +y), the last one's window outputs.
fn series(s: f64, chipping: bool) -> Vec<Outputs> {
    series_of(block(chipping, 1), s).1
}

/// [`series`] from the block `p`; also returns the model after it.
fn series_of(mut p: Params, s: f64) -> (Model, Vec<Outputs>) {
    p.csm.spacing = s;
    // rock 100 mm past the last pass on its unrelieved side (no free edge)
    p.rock.y_min = -(3.0 * s + 0.1);
    p.rock.ny = ((p.rock.y_max - p.rock.y_min) / 0.001).round() as usize + 1;
    let mut m = Model::new(p).unwrap();
    let mut last = vec![];
    for n in 0..4 {
        last = pass(&mut m, -(n as f64) * s, 1.0, 0.001).0;
    }
    (m, last)
}

/// Specific energy over a window's outputs: the cutting energy spent over the
/// volume removed \[J/m3\].
fn specific_energy(o: &[Outputs]) -> f64 {
    let (a, b) = (o.first().unwrap(), o.last().unwrap());
    (b.cutting_energy - a.cutting_energy) / (b.excavated_volume - a.excavated_volume)
}

#[test]
fn a_relieved_cut_is_pushed_towards_the_relieved_side() {
    // thesis Table 3's LCM scene: S = 51 mm beside the previous groove (at +y)
    let on = series(0.051, true);
    let off = series(0.051, false);
    let side = mean(&on, |o| o.side_force);
    let normal = mean(&on, |o| o.normal_force);
    // cutter +y is the relieved side: the chips took the rock there, the
    // intact rock at -y pushes the disc over (LCM: 11.2 kN, 14 % of Fn)
    assert!(side > 0.05 * normal, "side {side} N, normal {normal} N");
    assert!(mean(&off, |o| o.side_force).abs() < 1e-6 * normal);
}

#[test]
fn specific_energy_is_lowest_near_the_critical_spacing() {
    // p = 3.8 mm; kappa = 15 breaks ridges up to about 57 mm: S/p < ~18.5
    let ratios = [10.5, 13.4, 17.1, 21.1, 26.3];
    let se: Vec<f64> = ratios
        .iter()
        .map(|r| specific_energy(&series(r * P, true)))
        .collect();
    let best = (0..se.len())
        .min_by(|&a, &b| se[a].total_cmp(&se[b]))
        .unwrap();
    // the sources put the optimum of Colorado Red Granite at S/p 17-20
    // (thesis 2.3.5: "normally between 10 and 20"); the CSM alone has none
    assert_eq!(ratios[best], 17.1, "SE {se:?} at S/p {ratios:?}");
    // past the critical spacing the ridge stays and the SE jumps up
    assert!(se[3] > 2.0 * se[2], "{se:?}");
    // without chips the SE only rises with S (no optimum)
    let plain: Vec<f64> = [10.5, 17.1, 26.3]
        .iter()
        .map(|r| specific_energy(&series(r * P, false)))
        .collect();
    assert!(plain[0] < plain[1] && plain[1] < plain[2], "{plain:?}");
}

/// The CSM closed form's normal force at depth `p` for the block's disc and
/// rock at spacing `s`: `F_t(p) cos(phi / (2 + psi))` (thesis eqs 13-17).
fn closed_form_normal(s: f64, p: f64) -> f64 {
    let d = Params::default();
    let mut csm = d.csm;
    csm.spacing = s;
    let law = CsmLaw::new(d.cutter, csm, d.numerics.p_reg);
    law.force(p) * law.resultant_angle(contact_angle(d.cutter.radius, p)).cos()
}

/// The window's means: normal, rolling and side force \[N\] and specific
/// energy \[J/m3\].
fn means(o: &[Outputs]) -> [f64; 4] {
    [
        mean(o, |o| o.normal_force),
        mean(o, |o| o.rolling_force),
        mean(o, |o| o.side_force),
        specific_energy(o),
    ]
}

fn show_means(label: &str, m: [f64; 4], closed: f64) {
    eprintln!(
        "{label}: normal {:.1} kN ({:.3} x the closed form {:.1} kN), rolling {:.2} kN, side {:.2} kN, SE {:.1} MJ/m3",
        m[0] / 1e3,
        m[0] / closed,
        closed / 1e3,
        m[1] / 1e3,
        m[2] / 1e3,
        m[3] / 1e6
    );
}

/// Thesis Table 3's LCM scene, long: four passes `len` m long along x at
/// p = 3.8 mm, each `s` further towards -y (each relieved by the one before),
/// at 1 m/s in 1 mm steps; the last pass's outputs over `window` and the
/// model after it.
fn long_series(mut p: Params, s: f64, len: f64, window: (f64, f64)) -> (Model, Vec<Outputs>) {
    p.csm.spacing = s;
    p.rock.x_max = len + 0.25;
    p.rock.nx = ((p.rock.x_max - p.rock.x_min) / 0.001).round() as usize + 1;
    p.rock.y_min = -(3.0 * s + 0.1);
    p.rock.ny = ((p.rock.y_max - p.rock.y_min) / 0.001).round() as usize + 1;
    let mut m = Model::new(p).unwrap();
    let tw = Twist::new([1.0, 0.0, 0.0], [0.0, 1.0 / R, 0.0]);
    let mut out = vec![];
    for n in 0..4 {
        out.clear();
        let mut pose = Pose::new(0.0, -(n as f64) * s, R - P, 0.0, 0.0, 0.0);
        for _ in 0..(len / 0.001).round() as usize {
            pose = m.advance(&pose, &tw, 0.001).unwrap();
            if (window.0..=window.1).contains(&pose.position.x) {
                out.push(m.evaluate(&pose, &tw).unwrap());
            }
        }
    }
    (m, out)
}

/// The calibration of `chipping.pressureScale` (README, "Chips", *Means*):
/// the relieved pass of thesis Table 3's LCM scene (S = 51 mm, p = 3.8 mm,
/// the last of four), 3 m long and measured over its middle 2 m (about 40
/// chips a side), for seeds 1-4. Prints the means; asserts that the default
/// brings the mean normal force to the closed form.
#[test]
fn the_calibrated_pressure_brings_the_relieved_mean_to_the_closed_form() {
    let s = 0.051;
    let closed = closed_form_normal(s, P);
    let scale = Params::default().chipping.pressure_scale;
    let (len, window) = (3.0, (0.5, 2.5));
    let mut sum = [[0.0; 4]; 2];
    let seeds = [1, 2, 3, 4];
    for seed in seeds {
        let (m_cal, cal) = long_series(block(true, seed), s, len, window);
        let mut p = block(true, seed);
        p.chipping.pressure_scale = 1.0;
        let (m_one, one) = long_series(p, s, len, window);
        let (a, b) = (means(&cal), means(&one));
        if seed == 1 {
            // the saw-tooth and the work of the rolling force (reported)
            let f: Vec<f64> = cal.iter().map(|o| o.normal_force).collect();
            let (lo, hi) = f
                .iter()
                .fold((f64::INFINITY, 0.0f64), |(l, h), &x| (l.min(x), h.max(x)));
            let cv = (mean(&cal, |o| (o.normal_force - a[0]).powi(2))).sqrt() / a[0];
            let travel = window.1 - window.0;
            let (e0, e1) = (cal[0].cutting_energy, cal.last().unwrap().cutting_energy);
            eprintln!(
                "seed 1, pressureScale {scale}: normal force {:.1} to {:.1} kN (CV {cv:.3}); rolling force x travel {:.1} kJ vs cutting energy {:.1} kJ over {travel} m",
                lo / 1e3,
                hi / 1e3,
                a[1] * travel / 1e3,
                (e1 - e0) / 1e3
            );
        }
        show_means(
            &format!("seed {seed}, chips, pressureScale {scale}"),
            a,
            closed,
        );
        show_means(
            &format!("seed {seed}, chips, pressureScale 1   "),
            b,
            closed,
        );
        // the default: the relieved mean is the closed form (10 %), seed by seed
        assert!(
            (a[0] - closed).abs() < 0.1 * closed,
            "seed {seed}: {} vs {closed}",
            a[0]
        );
        // at the closed form's own pressure the chips leave it at about 0.6
        assert!(
            (0.55..0.70).contains(&(b[0] / closed)),
            "seed {seed}: {} vs {closed}",
            b[0]
        );
        // the factor is on the pressure: the rock, the chips and the volume
        // are the same (the cut is geometric), and every force scales with it
        assert!(m_cal.map() == m_one.map(), "seed {seed}: the rock differs");
        let (x, y) = (cal.last().unwrap(), one.last().unwrap());
        assert_eq!(x.chip_count, y.chip_count);
        assert_eq!(x.excavated_volume, y.excavated_volume);
        for k in 0..3 {
            assert!(
                (a[k] - scale * b[k]).abs() < 1e-6 * b[0],
                "seed {seed}, {k}: {} vs {}",
                a[k],
                b[k]
            );
        }
        for k in 0..4 {
            sum[0][k] += a[k] / seeds.len() as f64;
            sum[1][k] += b[k] / seeds.len() as f64;
        }
    }
    show_means(&format!("seeds 1-4, pressureScale {scale}"), sum[0], closed);
    show_means("seeds 1-4, pressureScale 1   ", sum[1], closed);
    eprintln!(
        "the factor that puts the mean at the closed form: {:.3}; LCM row (thesis Table 3): normal 81 kN ({:.2} x the closed form), rolling 7.3 kN, side 11.2 kN",
        closed / sum[1][0],
        81e3 / closed
    );
    // over the four seeds the default is the calibrated factor (2 %)
    assert!(
        (sum[0][0] - closed).abs() < 0.02 * closed,
        "{} vs {closed}",
        sum[0][0]
    );
    // without chips the same pass is the closed form (0.5 %)
    let (_, off) = long_series(block(false, 1), s, len, window);
    let c = means(&off);
    show_means("no chips", c, closed);
    assert!((c[0] - closed).abs() < 5e-3 * closed, "{}", c[0]);
}

#[test]
fn without_chips_the_pressure_scale_changes_nothing() {
    let run = |scale: f64| {
        let mut p = block(false, 1);
        p.chipping.pressure_scale = scale;
        let m = Model::new(p.clone()).unwrap();
        assert_eq!(*m.law(), CsmLaw::new(p.cutter, p.csm, p.numerics.p_reg));
        two_passes_of(p, 0.051, 1.0, 0.002)
    };
    let (a, oa, va) = run(1.0);
    for scale in [1.55, 0.1, 10.0] {
        let (b, ob, vb) = run(scale);
        assert!(a.state() == b.state(), "the states differ at {scale}");
        assert_eq!(oa, ob, "at {scale}");
        assert_eq!(va.to_bits(), vb.to_bits());
    }
}
