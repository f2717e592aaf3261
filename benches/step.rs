//! Cost of one evaluation: one Co-Simulation `advance` of 1 mm of travel plus
//! one `evaluate`, on the reference cut (R 0.2159 m, p 3.8 mm, 1 m/s,
//! wy = 1/R) at 1 mm cells, for a 1 m^2 face (1001 x 1001 nodes) and a
//! 100 m^2 face (10001 x 10001 nodes): kerf's defaults against the
//! thesis-faithful baseline (`src/core/baseline.rs`).
//!
//! `cargo bench --bench step` (add `-- --quick` for a fast pass). The
//! baseline on 100 m^2 visits 10^8 nodes a step: its group takes few samples.
//! Timings are wall-clock, never pass/fail; `scripts/speed-vs-error` gives
//! the same numbers next to the errors.

use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use kerf::core::baseline::{BaselineModel, BaselineResolution};
use kerf::core::{Model, Params, Pose, Twist};

const R: f64 = 0.2159;
const P: f64 = 3.8e-3;
const H: f64 = 1e-3;

/// A square face of `side` metres at 1 mm cells, x from -0.25 m, centred on y = 0.
fn face(side: f64) -> Params {
    let mut p = Params::default();
    let r = &mut p.rock;
    (r.x_min, r.x_max, r.y_min, r.y_max) = (-0.25, side - 0.25, -0.5 * side, 0.5 * side);
    r.nx = (side / 1e-3).round() as usize + 1;
    r.ny = r.nx;
    p
}

trait Sim {
    fn step(&mut self, pose: &Pose, tw: &Twist) -> Pose;
}

impl Sim for Model {
    fn step(&mut self, pose: &Pose, tw: &Twist) -> Pose {
        let end = self.advance(pose, tw, H).unwrap();
        std::hint::black_box(self.evaluate(&end, tw).unwrap());
        end
    }
}

impl Sim for BaselineModel {
    fn step(&mut self, pose: &Pose, tw: &Twist) -> Pose {
        let end = self.advance(pose, tw, H).unwrap();
        std::hint::black_box(self.evaluate(&end, tw).unwrap());
        end
    }
}

/// Rolls lanes of 0.5 m along +x, 20 mm apart, starting a new lane (and,
/// when the face is used up, a new model) outside the timed region.
struct Run<S: Sim> {
    make: Box<dyn Fn() -> S>,
    sim: S,
    pose: Pose,
    lane: usize,
    lanes: usize,
    lead_in: usize,
    tw: Twist,
}

impl<S: Sim> Run<S> {
    fn new(side: f64, lead_in: usize, make: Box<dyn Fn() -> S>) -> Self {
        let sim = make();
        let lanes = (((side.min(1.0) - 0.05) / 0.02) as usize).max(1);
        let mut r = Self {
            make,
            sim,
            pose: Pose::new(0.0, 0.0, R - P, 0.0, 0.0, 0.0),
            lane: 0,
            lanes,
            lead_in,
            tw: Twist::new([1.0, 0.0, 0.0], [0.0, 1.0 / R, 0.0]),
        };
        r.start_lane();
        r
    }

    fn lane_y(&self) -> f64 {
        -0.01 * (self.lanes as f64 - 1.0) + 0.02 * self.lane as f64
    }

    /// Starts the lane and rolls its lead-in (not timed).
    fn start_lane(&mut self) {
        self.pose = Pose::new(0.0, self.lane_y(), R - P, 0.0, 0.0, 0.0);
        for _ in 0..self.lead_in {
            self.pose = self.sim.step(&self.pose, &self.tw);
        }
    }

    fn timed(&mut self, iters: u64) -> Duration {
        let mut total = Duration::ZERO;
        for _ in 0..iters {
            if self.pose.position.x > 0.5 {
                self.lane += 1;
                if self.lane >= self.lanes {
                    self.lane = 0;
                    self.sim = (self.make)();
                }
                self.start_lane();
            }
            let t = Instant::now();
            self.pose = self.sim.step(&self.pose, &self.tw);
            total += t.elapsed();
        }
        total
    }
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("advance_1mm_plus_evaluate");
    for (side, label) in [(1.0, "1m2"), (10.0, "100m2")] {
        let mut run = Run::new(side, 50, Box::new(move || Model::new(face(side)).unwrap()));
        g.bench_function(BenchmarkId::new("kerf_defaults", label), |b| {
            b.iter_custom(|iters| run.timed(iters))
        });
    }
    g.finish();

    let res = BaselineResolution {
        n_alpha: 361,
        n_y: 9,
    };
    let mut g = c.benchmark_group("advance_1mm_plus_evaluate_baseline");
    g.sample_size(10);
    // 50 mm lead-in on 1 m^2; 3 steps on 100 m^2, where a step takes ~0.5 s
    // (the cost is the node loop, not the contact)
    for (side, label, secs, lead_in) in [(1.0, "1m2", 5, 50), (10.0, "100m2", 10, 3)] {
        g.measurement_time(Duration::from_secs(secs));
        g.warm_up_time(Duration::from_millis(500));
        let mut run = Run::new(
            side,
            lead_in,
            Box::new(move || BaselineModel::new(face(side), res).unwrap()),
        );
        g.bench_function(BenchmarkId::new("thesis_baseline_361x9", label), |b| {
            b.iter_custom(|iters| run.timed(iters))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
