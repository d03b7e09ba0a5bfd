//! Criterion benchmark: host nanoseconds per step of every reduced-model variant (format ×
//! integrator) at 10 kHz, on the reverse-load braking after the cut. `cargo xtask bench` runs it
//! and reads `target/criterion/reduced_step/<format>/<integrator>/new/estimates.json`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use fixed::types::{I16F16, I32F32};
use noback::mechanism::TABLE2;
use noback_study::reduced::num::{Real, Widen};
use noback_study::reduced::{BrakingScene, Method, Params, Reduced};
use std::hint::black_box;
use std::time::Duration;

fn one<N: Real + Widen<A>, A: Real>(c: &mut Criterion, format: &str, method: Method) {
    let p = Params::from_mechanism(&TABLE2, TABLE2.load_torque_nm, 10_000.0);
    let mut m = Reduced::<N, A>::new(p, method);
    m.set_drive(true, BrakingScene::REVERSE.speed_ref_rad_s);
    m.step();
    m.set_drive(false, 0.0);
    c.benchmark_group("reduced_step").bench_function(
        BenchmarkId::new(format, method.name()),
        |b| {
            b.iter(|| {
                m.step();
                black_box(&m);
            })
        },
    );
}

fn all(c: &mut Criterion) {
    for method in Method::ALL {
        one::<f64, f64>(c, "f64", method);
        one::<f32, f32>(c, "f32", method);
        one::<I16F16, I16F16>(c, "I16F16", method);
        one::<I32F32, I32F32>(c, "I32F32", method);
        one::<I16F16, I32F32>(c, "mixed", method);
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .warm_up_time(Duration::from_millis(200))
        .measurement_time(Duration::from_millis(600))
        .sample_size(20);
    targets = all
}
criterion_main!(benches);
