//! Instances are independent: different parameters side by side, and many
//! instances on many threads giving the results of a lone instance.

#[path = "fmi_support.rs"]
mod support;

use support::*;

/// Hosts move instances between threads: the core model must be `Send`.
#[allow(dead_code)]
fn model_is_send() {
    fn send<T: Send>() {}
    send::<kerf::core::Model>();
    send::<kerf::core::ModelState>();
}

#[test]
fn two_instances_with_different_parameters_are_independent() {
    let a = Fmu::new("inst-a", Kind::Cs);
    let b = Fmu::new("inst-b", Kind::Cs);
    a.small_rock();
    b.small_rock();
    // b's rock face is 2 mm lower: the same pose presses 2 mm less.
    assert_eq!(b.set_real(vr::ROCK_Z0, -0.002), OK);
    a.init();
    b.init();
    let (pa, pb) = (a.real(vr::PENETRATION), b.real(vr::PENETRATION));
    assert!(pa > pb && pb > 0.0, "{pa} {pb}");
    assert!(a.real(vr::NORMAL_FORCE) > b.real(vr::NORMAL_FORCE));
    assert_eq!(a.real(vr::ROCK_Z0), 0.0);
    // Stepping and lifting one leaves the other alone.
    assert_eq!(a.set_reals(&[vr::VX, vr::WY], &[1.0, 1.0 / R]), OK);
    for k in 0..10 {
        assert_eq!(a.do_step(k as f64 * 0.002, 0.002), OK);
    }
    assert_eq!(b.real(vr::EXCAVATED_VOLUME), 0.0);
    assert_eq!(b.real(vr::PENETRATION), pb);
    assert_eq!(b.set_real(vr::Z, 1.0), OK);
    assert!(a.real(vr::NORMAL_FORCE) > 0.0);
    // Freeing one leaves the other usable.
    drop(b);
    assert_eq!(a.do_step(0.02, 0.002), OK);
}

fn run(name: &str, kind: Kind, speed: f64) -> Vec<u64> {
    let fmu = Fmu::new(name, kind);
    fmu.small_rock();
    fmu.init();
    let h = 0.002;
    let mut out = Vec::new();
    match kind {
        Kind::Cs => {
            assert_eq!(fmu.set_reals(&[vr::VX, vr::WY], &[speed, speed / R]), OK);
            for k in 0..40 {
                assert_eq!(fmu.do_step(k as f64 * h, h), OK, "{:?}", fmu.errors());
                out.extend(fmu.get_reals(&real_outputs()).1.iter().map(|v| v.to_bits()));
            }
        }
        Kind::Me => {
            fmu.event_iteration();
            for k in 1..=40 {
                let t = k as f64 * h;
                assert_eq!(fmu.set_time(t), OK);
                assert_eq!(
                    fmu.set_reals(&[vr::X, vr::VX, vr::WY], &[speed * t, speed, speed / R]),
                    OK
                );
                let (s, enter, _) = fmu.completed_integrator_step();
                assert_eq!(s, OK);
                if enter {
                    assert_eq!(fmu.enter_event_mode(), OK);
                    fmu.event_iteration();
                }
                out.extend(fmu.get_reals(&real_outputs()).1.iter().map(|v| v.to_bits()));
            }
        }
    }
    assert_eq!(fmu.terminate(), OK);
    out
}

#[test]
fn many_instances_on_many_threads_match_a_lone_instance() {
    let cases: Vec<(Kind, f64)> = (0..8)
        .map(|i| {
            (
                if i % 2 == 0 { Kind::Cs } else { Kind::Me },
                0.5 + 0.25 * (i / 2) as f64,
            )
        })
        .collect();
    let alone: Vec<Vec<u64>> = cases
        .iter()
        .enumerate()
        .map(|(i, (k, v))| run(&format!("inst-alone-{i}"), *k, *v))
        .collect();
    let threads: Vec<_> = cases
        .iter()
        .enumerate()
        .map(|(i, &(k, v))| std::thread::spawn(move || run(&format!("inst-thread-{i}"), k, v)))
        .collect();
    for (i, t) in threads.into_iter().enumerate() {
        assert_eq!(
            t.join().unwrap(),
            alone[i],
            "case {i} differs when run in parallel"
        );
    }
    // The cases differ from each other, so the comparison means something.
    assert_ne!(alone[0], alone[2]);
}

#[test]
fn an_instance_can_move_between_threads() {
    let fmu = Fmu::new("inst-moved", Kind::Cs);
    fmu.small_rock();
    fmu.init();
    let fmu = std::thread::spawn(move || {
        assert_eq!(fmu.do_step(0.0, 0.01), OK);
        fmu
    })
    .join()
    .unwrap();
    assert_eq!(fmu.do_step(0.01, 0.01), OK);
}
