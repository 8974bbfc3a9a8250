//! Persson's theory against its closed forms: special functions against tabulated values,
//! the spectrum's moments against Parseval on a sinusoid, the small-load laws (κ, u₀,
//! `K = p/u₀`), `K = −dp/dū` against finite differences of `ū`, the high-load limit, and
//! `u₀` of a continuous power-law spectrum against its closed form.

use std::f64::consts::PI;

use ndarray::Array2;

use super::*;
use crate::spectrum::{LongWavelength, Psd};
use crate::surface::{Normalisation, SurfaceGenerator, SurfaceSpec};

fn relative(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// A generated surface, H = 0.8, roll-off 6, unit rms slope.
fn rough(n: usize) -> Surface {
    let psd = Psd::new(0.8, LongWavelength::RollOff { q0: 6.0 }, None).unwrap();
    let spec = SurfaceSpec::new(n, n, 1.0, psd, Normalisation::RmsSlope(1.0)).unwrap();
    SurfaceGenerator::new(&spec).unwrap().generate(3)
}

/// `a cos(2π k x/L)` on an n×n grid of side `size`.
fn sinusoid(n: usize, size: f64, k: usize, amplitude: f64) -> Surface {
    let heights = Array2::from_shape_fn((n, n), |(_, c)| {
        amplitude * (2.0 * PI * (k * c) as f64 / n as f64).cos()
    });
    Surface::new(heights, size).unwrap()
}

#[test]
fn special_functions_match_tabulated_values() {
    // Abramowitz & Stegun, tables 7.1 and 5.1 (to the digits given there and beyond).
    for (x, value) in [
        (0.5, 0.520_499_877_813_046_5),
        (1.0, 0.842_700_792_949_714_9),
        (2.0, 0.995_322_265_018_952_7),
    ] {
        assert!(relative(erf(x), value) < 1e-14, "erf({x}) = {}", erf(x));
        assert!(relative(erf(-x), -value) < 1e-14);
    }
    for (x, value) in [
        (2.5, 4.069_520_174_449_59e-4),
        (3.0, 2.209_049_699_858_544e-5),
        (5.0, 1.537_459_794_428_035e-12),
    ] {
        assert!(relative(erfc(x), value) < 1e-13, "erfc({x}) = {}", erfc(x));
    }
    for (x, value) in [
        (0.1, 1.822_923_958_419_390_7),
        (1.0, 0.219_383_934_395_520_3),
        (2.0, 0.048_900_510_708_061_12),
        (10.0, 4.156_968_929_685_324e-6),
    ] {
        let e1 = exp_integral_e1(x);
        assert!(relative(e1, value) < 1e-13, "E1({x}) = {e1}");
    }
    // The two branches of erf meet at the switch.
    let below = erf(ERF_SWITCH - 1e-12);
    assert!((below - (1.0 - erfc(ERF_SWITCH))).abs() < 5e-15); // a few ulps of each branch
}

/// Composite Simpson with `n` (even) intervals.
fn simpson(a: f64, b: f64, n: usize, f: impl Fn(f64) -> f64) -> f64 {
    let h = (b - a) / n as f64;
    let inner: f64 = (1..n)
        .map(|i| f(a + i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 })
        .sum();
    (f(a) + f(b) + inner) * h / 3.0
}

#[test]
fn tabulated_tail_integral_matches_direct_quadrature() {
    for x0 in [0.0, 0.003, 0.1, 0.77, 1.5, 2.9, 4.0, 6.4, 7.0] {
        let direct = simpson(x0, 12.0, 200_000, tail_integrand);
        let table = erf_squared_tail(x0);
        assert!(
            (table - direct).abs() < 1e-11 * direct.max(1e-300) + 1e-22,
            "x0 = {x0}: table {table}, direct {direct}"
        );
    }
}

#[test]
fn moments_of_a_sinusoid_follow_parseval() {
    // h = a cos(qx): h_rms² = a²/2, ḡ² = a²q²/2.
    let (a, size, k) = (0.3, 2.0, 4);
    let q = 2.0 * PI * k as f64 / size;
    let surface = sinusoid(64, size, k, a);
    let theory = Persson::from_surface(&surface, PerssonParams::default()).unwrap();
    assert!(relative(theory.rms_height(), a / 2f64.sqrt()) < 1e-12);
    // The ring's mean wavenumber (over its 32 modes, not weighted by power) stands for the
    // mode's: ḡ = h_rms q̄ exactly, and q̄ within half a ring (π/L) of q.
    let bins = crate::surface::stats::radial_psd_2d(&surface).unwrap();
    let ring = bins.iter().max_by(|x, y| x.psd.total_cmp(&y.psd)).unwrap();
    assert!(relative(theory.rms_gradient(), a / 2f64.sqrt() * ring.q) < 1e-12); // FFT noise: 1e-30
    assert!((ring.q - q).abs() < PI / size);
    // One ring from s = 0 to ḡ: u0 = γ √(2/π) ḡ/q̄ = γ a/√π, whatever q̄.
    let gamma = theory.params().gamma;
    assert!(relative(theory.u0(), gamma * a / PI.sqrt()) < 1e-12);
}

#[test]
fn small_load_area_is_linear_with_kappa() {
    let surface = rough(64);
    for kappa in [PERSSON_KAPPA, 2.0] {
        let params = PerssonParams {
            kappa,
            ..PerssonParams::default()
        };
        let theory = Persson::from_surface(&surface, params).unwrap();
        let p = 1e-7 * theory.rms_gradient();
        let measured = theory.area_fraction(p) * theory.rms_gradient() / p;
        assert!(relative(measured, kappa) < 1e-9, "κ {kappa}: {measured}");
    }
    assert!(relative(PERSSON_KAPPA, (8.0 / PI).sqrt()) < 1e-15);
}

#[test]
fn low_load_separation_is_exponential_with_the_closed_form_u0() {
    let theory = Persson::from_surface(&rough(64), PerssonParams::default()).unwrap();
    let g = theory.rms_gradient();
    // The rings with s below about p/E* are already flattened (w p/E* ≫ 1) and drop out
    // of the slope: a relative deficit of order p/(E* ḡ).
    let (p1, p2) = (1e-9 * g, 1e-7 * g);
    let slope = (theory.mean_gap(p1) - theory.mean_gap(p2)) / (p2 / p1).ln();
    assert!(
        relative(slope, theory.u0()) < 1e-6,
        "{slope} vs u0 {}",
        theory.u0()
    );
    // And so K = p/u0.
    assert!(relative(theory.stiffness(p1) * theory.u0() / p1, 1.0) < 1e-6);
    // A low-load law: at p = 0.1 E* ḡ the slope is another.
    let p3 = 0.1 * g;
    let slope3 = (theory.mean_gap(p3 / 1.01) - theory.mean_gap(p3 * 1.01)) / 1.01f64.powi(2).ln();
    assert!(
        relative(slope3, theory.u0()) > 0.05,
        "{slope3} vs {}",
        theory.u0()
    );
}

#[test]
fn stiffness_is_minus_the_derivative_of_the_separation() {
    for gamma in [0.45, 1.0] {
        let params = PerssonParams {
            gamma,
            ..PerssonParams::default()
        };
        let theory = Persson::from_surface(&rough(64), params).unwrap();
        let g = theory.rms_gradient();
        for p in [1e-4 * g, 1e-2 * g, 0.1 * g, 0.5 * g] {
            let h = 1e-4 * p;
            let derivative = (theory.mean_gap(p - h) - theory.mean_gap(p + h)) / (2.0 * h);
            let k = theory.stiffness(p);
            assert!(
                relative(1.0 / derivative, k) < 1e-6,
                "γ {gamma} p {p}: {} vs {k}",
                1.0 / derivative
            );
        }
    }
}

#[test]
fn high_load_limit_has_every_ring_in_contact() {
    let theory = Persson::from_surface(&rough(64), PerssonParams::default()).unwrap();
    let gamma = theory.params().gamma;
    let p = 3.0 * theory.rms_gradient(); // x ≥ 3√2 in every ring: erf² = 1 − 1e-9
    let limit = PI.sqrt()
        * theory.ring_integral(|w| 0.5 * (3.0 - 2.0 * gamma) * exp_integral_e1((w * p).powi(2)));
    assert!(relative(theory.mean_gap(p), limit) < 1e-7);
    let x = 2f64.sqrt() * p / theory.rms_gradient();
    let asymptote = (-x * x).exp() / (x * PI.sqrt()) * (1.0 - 0.5 / (x * x));
    assert!(relative(1.0 - theory.area_fraction(p), asymptote) < 0.02);
}

#[test]
fn u0_of_a_continuous_power_law_matches_its_closed_form() {
    // C = C0 q^(-3) (H = 1/2) on [q0, q1]: m2(q) = 2π C0 (q − q0) and
    // u0 = γ √C0 (2/√q0) atan(√((q1 − q0)/q0)).
    let (c0, q0, area): (f64, f64, f64) = (2.5e-3, 1.0, 1.0);
    let mode_area = (2.0 * PI).powi(2) / area;
    let ratio: f64 = 1.0005;
    let count = (400f64.ln() / ratio.ln()).round() as usize;
    let q1 = q0 * ratio.powi(count as i32); // the bins' own top
    let bins: Vec<PsdBin> = (0..count)
        .map(|i| {
            let (a, b) = (q0 * ratio.powi(i as i32), q0 * ratio.powi(i as i32 + 1));
            let q = 0.5 * (a + b);
            let power = 2.0 * PI * c0 * (b - a) / (q * q); // ∫ 2π q C dq over the bin
            PsdBin {
                q,
                psd: power / mode_area,
                modes: 1,
            }
        })
        .collect();
    let theory = Persson::from_psd(&bins, area, PerssonParams::default()).unwrap();
    let expected = 0.45 * c0.sqrt() * 2.0 / q0.sqrt() * ((q1 - q0) / q0).sqrt().atan();
    assert!(
        relative(theory.u0(), expected) < 1e-3,
        "{} vs {expected}",
        theory.u0()
    );
    let g_expected = (2.0 * PI * c0 * (q1 - q0)).sqrt();
    assert!(relative(theory.rms_gradient(), g_expected) < 1e-6);
}

#[test]
fn refuses_meaningless_inputs() {
    let flat = Surface::new(Array2::zeros((8, 8)), 1.0).unwrap();
    assert!(Persson::from_surface(&flat, PerssonParams::default()).is_err());
    let surface = rough(32);
    for params in [
        PerssonParams {
            gamma: 0.0,
            ..PerssonParams::default()
        },
        PerssonParams {
            gamma: 1.5,
            ..PerssonParams::default()
        },
        PerssonParams {
            modulus: -1.0,
            ..PerssonParams::default()
        },
        PerssonParams {
            kappa: f64::NAN,
            ..PerssonParams::default()
        },
    ] {
        assert!(Persson::from_surface(&surface, params).is_err());
    }
    let theory = Persson::from_surface(&surface, PerssonParams::default()).unwrap();
    for p in [0.0, -1.0, f64::INFINITY, f64::NAN] {
        assert!(theory.predict(p).is_err());
    }
    let point = theory.predict(0.01).unwrap();
    assert!(point.area_fraction > 0.0 && point.mean_gap > 0.0 && point.stiffness > 0.0);
    assert_eq!(
        point.contact_stiffness,
        point.stiffness * theory.nominal_area()
    );
}
