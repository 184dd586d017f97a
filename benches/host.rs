//! Host speed: nanoseconds per estimate for the f64 reference, the f32 core,
//! the fixed-point core and the Hamrock & Brewe baseline on the same few hundred samples
//! over the practical domain, and estimates per second for a batch through the CSV
//! estimator. `cargo bench --bench host`.

use misalign_cli::estimate as cli;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use misalign::fixed::{FixedEllipticScene, exact_lsb};
use misalign::float::EllipticScene;
use misalign::{Scene, reference};
use misalign_workload::{hamrock_brewe::HamrockBrewe, samples};
use std::hint::black_box;

fn estimate(c: &mut Criterion) {
    let scene = Scene::DEMO;
    let inputs: Vec<(f64, f64)> = samples::practical(256).collect();
    let core = EllipticScene::new(&scene).unwrap();
    let (load_lsb, _) = exact_lsb(samples::LOAD_MAX, 1 << 30, 0.0);
    let angle_lsb = 1e-8;
    let fixed = FixedEllipticScene::new(&scene, load_lsb, angle_lsb).unwrap();
    let counts: Vec<(u32, i32)> = inputs
        .iter()
        .map(|&(p, phi)| ((p / load_lsb) as u32, (phi / angle_lsb) as i32))
        .collect();
    let baseline = HamrockBrewe::of(&scene);
    let mut group = c.benchmark_group("estimate");
    group.throughput(Throughput::Elements(inputs.len() as u64));
    group.bench_function("reference", |b| {
        b.iter(|| {
            for &(p, phi) in &inputs {
                black_box(reference::elliptic(&scene, black_box(p), black_box(phi)).unwrap());
            }
        })
    });
    group.bench_function("f32", |b| {
        b.iter(|| {
            for &(p, phi) in &inputs {
                black_box(
                    core.estimate(black_box(p as f32), black_box(phi as f32))
                        .unwrap(),
                );
            }
        })
    });
    group.bench_function("fixed", |b| {
        b.iter(|| {
            for &(p, a) in &counts {
                black_box(fixed.estimate(black_box(p), black_box(a)).unwrap());
            }
        })
    });
    // Section 9 per sample: the same samples on rollers 0.3 m long, where
    // about half of them take line contact; the choice costs one table read.
    let short = scene.with_length(0.3).unwrap();
    let auto = misalign::float::Auto::new(&short).unwrap();
    let fixed_auto = misalign::fixed::FixedAuto::new(&short, load_lsb, angle_lsb).unwrap();
    group.bench_function("f32-auto", |b| {
        b.iter(|| {
            for &(p, phi) in &inputs {
                black_box(
                    auto.estimate(black_box(p as f32), black_box(phi as f32))
                        .unwrap(),
                );
            }
        })
    });
    group.bench_function("fixed-auto", |b| {
        b.iter(|| {
            for &(p, a) in &counts {
                black_box(fixed_auto.estimate(black_box(p), black_box(a)).unwrap());
            }
        })
    });
    group.bench_function("hamrock-brewe", |b| {
        b.iter(|| {
            for &(p, phi) in &inputs {
                black_box(baseline.estimate(black_box(p as f32), black_box(phi as f32)));
            }
        })
    });
    group.finish();
}

fn csv_batch(c: &mut Criterion) {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/vectors_scene.csv");
    let Ok(input) = std::fs::read(&path) else {
        eprintln!("{} not found: CSV batch skipped", path.display());
        return;
    };
    let rows = input.iter().filter(|&&b| b == b'\n').count() as u64 - 1;
    let mut group = c.benchmark_group("csv_estimator");
    group.throughput(Throughput::Elements(rows));
    group.sample_size(10);
    for model in ["reference", "f32", "fixed"] {
        // The reference files have no length: every row is elliptic under --contact auto.
        let args: Vec<String> = ["--model", model].iter().map(|s| s.to_string()).collect();
        group.bench_function(model, |b| {
            b.iter(|| {
                let mut out = Vec::with_capacity(1 << 20);
                black_box(cli::run(&args, &input[..], &mut out, &mut std::io::sink()));
            })
        });
    }
    group.finish();
}

criterion_group!(benches, estimate, csv_batch);
criterion_main!(benches);
