//! Surface and line generation throughput (criterion). `cargo bench -p asperity --bench generate`
use asperity::spectrum::{LongWavelength, Psd};
use asperity::surface::{LineGenerator, LineSpec, Normalisation, SurfaceGenerator, SurfaceSpec};
use criterion::{criterion_group, criterion_main, Criterion};

fn surfaces(c: &mut Criterion) {
    let mut group = c.benchmark_group("surface");
    group.sample_size(10);
    for n in [1024usize, 4096] {
        let psd = Psd::new(0.8, LongWavelength::RollOff { q0: 6.0 }, None).unwrap();
        let spec = SurfaceSpec::new(n, n, 1.0, psd, Normalisation::RmsSlope(1.0)).unwrap();
        let mut generator = SurfaceGenerator::new(&spec).unwrap();
        let mut heights = vec![0.0; n * n];
        let mut seed = 0;
        group.bench_function(format!("{n}x{n}"), |b| {
            b.iter(|| {
                seed += 1;
                generator.generate_into(seed, &mut heights).unwrap()
            })
        });
    }
    group.finish();
}

fn lines(c: &mut Criterion) {
    let spec = LineSpec::new(
        1 << 15,
        1.0,
        Psd::power_law(0.5).unwrap(),
        Normalisation::RmsHeight(1.0),
    )
    .unwrap();
    let mut generator = LineGenerator::new(&spec).unwrap();
    let mut heights = vec![0.0; 1 << 15];
    let mut seed = 0;
    c.bench_function("line 2^15", |b| {
        b.iter(|| {
            seed += 1;
            generator.generate_into(seed, &mut heights).unwrap()
        })
    });
}

criterion_group!(benches, surfaces, lines);
criterion_main!(benches);
