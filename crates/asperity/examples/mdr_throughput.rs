//! MDR throughput without criterion: 500 lines of N = 2^15 (generation + whole curve),
//! parallel over lines, reporting wall time and process CPU time (Linux `/proc/self/stat`),
//! so that a figure measured on a busy machine can still be judged (CPU time / threads is
//! what the work costs when the cores are free).
//!
//! Run: `RAYON_NUM_THREADS=2 cargo run --release -p asperity --example mdr_throughput`.

use std::time::Instant;

use asperity::mdr::LinearCurve;
use asperity::spectrum::Psd;
use asperity::surface::{LineGenerator, LineSpec, Normalisation};
use rayon::prelude::*;

/// User + system CPU seconds of this process, if `/proc` is there.
fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    let after_name = &stat[stat.rfind(')')? + 2..];
    let fields: Vec<&str> = after_name.split_whitespace().collect();
    let ticks: f64 = fields.get(11)?.parse::<f64>().ok()? + fields.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0) // USER_HZ is 100 on Linux
}

fn run<F: Fn(&mut LineGenerator, &mut Vec<f64>, &mut LinearCurve, u64) + Sync>(
    name: &str,
    spec: &LineSpec,
    lines: u64,
    work: F,
) {
    let repeats = 5;
    let mut best = f64::INFINITY;
    let cpu0 = cpu_seconds();
    for _ in 0..repeats {
        let start = Instant::now();
        (0..lines).into_par_iter().for_each_init(
            || {
                (
                    LineGenerator::new(spec).expect("plan"),
                    vec![0.0; spec.n],
                    LinearCurve::with_capacity(spec.n),
                )
            },
            |(generator, heights, curve), seed| work(generator, heights, curve, seed),
        );
        best = best.min(start.elapsed().as_secs_f64());
    }
    let cpu = cpu0
        .zip(cpu_seconds())
        .map(|(a, b)| format!("{:.3} s CPU per run", (b - a) / repeats as f64))
        .unwrap_or_default();
    println!(
        "{name}: best wall {best:.3} s for {lines} lines on {} threads; {cpu}",
        rayon::current_num_threads()
    );
}

fn main() {
    let n = 1 << 15;
    let spec = LineSpec::new(
        n,
        1.0,
        Psd::power_law(0.5).unwrap(),
        Normalisation::RmsHeight(1.0),
    )
    .unwrap();
    run("generation + curve", &spec, 500, |g, h, c, seed| {
        g.generate_into(seed, h).unwrap();
        c.recompute(h, 1.0 / n as f64, 1.0).unwrap();
        std::hint::black_box(c.forces()[n - 1]);
    });
    run("generation only", &spec, 500, |g, h, _, seed| {
        g.generate_into(seed, h).unwrap();
        std::hint::black_box(h[0]);
    });
    run(
        "curve only (same line each time)",
        &spec,
        500,
        |g, h, c, _| {
            if h[0] == 0.0 {
                g.generate_into(1, h).unwrap();
            }
            c.recompute(h, 1.0 / n as f64, 1.0).unwrap();
            std::hint::black_box(c.forces()[n - 1]);
        },
    );
    // For comparison: the comparison sort the radix sort replaced, and the radix sort, each
    // on a fresh copy of the line (the radix sort here also allocates its scratch each
    // time, which `LinearCurve::recompute` reuses).
    run(
        "comparison sort only (for reference)",
        &spec,
        500,
        |g, h, c, _| {
            if h[0] == 0.0 {
                g.generate_into(1, h).unwrap();
            }
            let mut copy = h.clone();
            copy.sort_unstable_by(|a, b| b.total_cmp(a));
            std::hint::black_box((copy[0], c.len()));
        },
    );
    run("radix sort only", &spec, 500, |g, h, _, _| {
        if h[0] == 0.0 {
            g.generate_into(1, h).unwrap();
        }
        let mut copy = h.clone();
        let mut scratch = asperity::mdr::radix_sort::RadixScratch::default();
        asperity::mdr::radix_sort::sort_descending(&mut copy, &mut scratch);
        std::hint::black_box(copy[0]);
    });
}
