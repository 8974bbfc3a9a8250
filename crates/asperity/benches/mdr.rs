//! MDR throughput: 500 rough lines of N = 2^15 — generation (FFT synthesis) plus the whole
//! linear-spring curve (sort + cumulative sums) — in parallel over lines with rayon.
//! Deterministic: line `i` is seed `i` whatever the thread count. Also the two parts
//! alone, to name the limit (sorting vs FFT).
//!
//! Run: `cargo bench -p asperity --bench mdr` (`RAYON_NUM_THREADS=2` for the 2-core figure).

use std::hint::black_box;

use asperity::mdr::LinearCurve;
use asperity::spectrum::Psd;
use asperity::surface::{LineGenerator, LineSpec, Normalisation};
use criterion::{criterion_group, criterion_main, Criterion};
use rayon::prelude::*;

const LINES: u64 = 500;
const N: usize = 1 << 15;

fn spec() -> LineSpec {
    LineSpec::new(
        N,
        1.0,
        Psd::power_law(0.5).expect("valid H"),
        Normalisation::RmsHeight(1.0),
    )
    .expect("valid spec")
}

/// Generation + full curve for `LINES` lines; returns the sum of the final forces so that
/// nothing is optimised away.
fn lines_and_curves(spec: &LineSpec) -> f64 {
    (0..LINES)
        .into_par_iter()
        .map_init(
            || {
                (
                    LineGenerator::new(spec).expect("plan"),
                    vec![0.0; N],
                    LinearCurve::with_capacity(N),
                )
            },
            |(generator, heights, curve), seed| {
                generator.generate_into(seed, heights).expect("power");
                curve
                    .recompute(heights, 1.0 / N as f64, 1.0)
                    .expect("finite");
                curve.forces()[N - 1]
            },
        )
        .sum()
}

fn lines_only(spec: &LineSpec) -> f64 {
    (0..LINES)
        .into_par_iter()
        .map_init(
            || (LineGenerator::new(spec).expect("plan"), vec![0.0; N]),
            |(generator, heights), seed| {
                generator.generate_into(seed, heights).expect("power");
                heights[0]
            },
        )
        .sum()
}

fn curves_only(lines: &[Vec<f64>]) -> f64 {
    lines
        .par_iter()
        .map_init(
            || LinearCurve::with_capacity(N),
            |curve, heights| {
                curve
                    .recompute(heights, 1.0 / N as f64, 1.0)
                    .expect("finite");
                curve.forces()[N - 1]
            },
        )
        .sum()
}

fn bench(c: &mut Criterion) {
    let spec = spec();
    let mut group = c.benchmark_group("mdr_500_lines_2^15");
    group.sample_size(10);
    group.bench_function("generate_and_curve", |b| {
        b.iter(|| black_box(lines_and_curves(&spec)))
    });
    group.bench_function("generate_only", |b| b.iter(|| black_box(lines_only(&spec))));
    let mut generator = LineGenerator::new(&spec).expect("plan");
    let lines: Vec<Vec<f64>> = (0..LINES)
        .map(|seed| generator.generate(seed).into_heights().to_vec())
        .collect();
    group.bench_function("curve_only", |b| b.iter(|| black_box(curves_only(&lines))));
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
