//! Persson's contact mechanics theory, computed from a surface's own power spectrum: the
//! relative contact area, the mean interfacial separation and the contact stiffness against
//! the mean pressure, to set beside the boundary-element results ([`crate::bem`]).
//!
//! ## The spectrum it starts from
//! The input is the radially averaged PSD of [`crate::surface::stats::radial_psd_2d`], whose
//! normalisation is `Σ_q C2D(q) (2π)²/A = h_rms²` over all Fourier modes `q` of the grid
//! (`A` the nominal area). That is Persson's convention `h_rms² = ∫ d²q C(q)`, with the
//! sum over modes standing for the integral (each mode covers `(2π)²/A` of the q-plane).
//! A ring of `m` modes at mean wavenumber `q` with averaged PSD `C` adds
//! `m C (2π)²/A · q²` to the second moment `m₂(q) = ∫_{|q'|<q} d²q' q'² C(q')`, the mean
//! square gradient of the roughness resolved up to `q`; `ḡ² = m₂(q₁)` over every ring is
//! the rms gradient of the whole surface (spectral, not by finite differences; modes in
//! the corners of the grid beyond the ring of the Nyquist wavenumber are not in the
//! radial PSD, and so not in `ḡ`).
//!
//! ## The equations
//! With `E*` the effective modulus and `p` the mean (nominal) pressure:
//! * **Contact area**, Persson, J. Chem. Phys. 115, 3840 (2001), eqs. (21)–(22) there, with
//!   `G(q) = (π/4)(E*/p)² ∫_{q₀}^{q} dq' q'³ C(q') = (E*/p)² m₂(q)/8`:
//!   `A/A₀ = P(q₁) = erf(1/(2√G(q₁))) = erf(√2 p/(E* ḡ))`, whose small-load limit is
//!   `A/A₀ = κ p/(E* ḡ)` with `κ = √(8/π) ≈ 1.596`. Numerical contact mechanics finds κ
//!   about 2, weakly dependent on H (Hyun, Pei, Molinari & Robbins, PRE 70, 026117 (2004);
//!   Prodanov, Dapp & Müser, Tribol. Lett. 53, 433 (2014)). The literature's correction
//!   keeps the error-function form and rescales its argument so that the small-load slope
//!   is a given κ: `A/A₀ = erf(√π κ p/(2 E* ḡ))` ([`PerssonParams::kappa`]; κ = √(8/π) is
//!   the uncorrected theory).
//! * **Mean separation**, Persson, PRL 99, 125502 (2007), eq. (4) there, with the elastic
//!   energy `U_el/A₀ = (π E*/2) ∫ dq q² C(q) P(q) S(q)` and the correction factor
//!   `S(q) = γ + (1−γ) P²(q)` of Yang & Persson, J. Phys.: Condens. Matter 20, 215214 (2008)
//!   (γ ≈ 0.4–0.5 there; default here 0.45, [`PerssonParams::gamma`]). From
//!   `p = −dU_el/(A₀ dū)`:
//!   `ū(p) = √π ∫_{q₀}^{q₁} dq q² C(q) w(q) ∫_p^∞ (dp'/p') [γ + 3(1−γ) P²(q, p')]
//!   exp(−(w(q) p'/E*)²)`, `w(q) = (π ∫_{q₀}^{q} dq' q'³ C(q'))^(−1/2) = √(2/m₂(q))`.
//!   Because `P(q, p') = erf(w(q) p'/E*)`, the inner integral is a function of one
//!   variable, `J(x₀) = ∫_{x₀}^∞ dx/x [γ + 3(1−γ) erf²x] e^(−x²)` at `x₀ = w(q) p/E*`:
//!   `(γ/2) E₁(x₀²)` plus `3(1−γ)` times a tabulated smooth integral. (Persson 2007 writes
//!   the bracket as `γ + (1−γ)P²`; the factor 3 is what `dU_el/dp` gives for
//!   `S = γ + (1−γ)P²`, and it is what [`Persson::mean_gap`] and [`Persson::stiffness`]
//!   both use, so that one is the derivative of the other.)
//! * **Stiffness** per unit nominal area, `K = −dp/dū`, in closed form from the same
//!   integrand: `K(p) = p / (√π ∫ dq q² C w [γ + 3(1−γ) erf²(w p/E*)] e^(−(w p/E*)²))`.
//!   Times the nominal area it is the contact stiffness `k` of the BEM.
//!
//! ## Limits (the tests check them)
//! * small load: `A/A₀ → κ p/(E* ḡ)`; `ū = −u₀ ln p + const`, i.e. `p ∝ exp(−ū/u₀)` with
//!   `u₀ = γ √π ∫ dq q² C(q) w(q)` (Persson 2007), and so `K → p/u₀`: the stiffness is
//!   linear in the load;
//! * high load: `1 − A/A₀ → exp(−x²)/(x √π)`, `x = √2 p/(E* ḡ)`, and `ū → ((3 − 2γ)/2)
//!   √π ∫ dq q² C w E₁((w p/E*)²)` (every P = 1).
//!
//! ## Discretisation
//! Within a ring of the PSD `q` is its mean wavenumber (over its modes, not weighted by
//! their power: at ring `κ = qL/2π` this can be off by up to `1/(2κ)` of q for a ring whose
//! power sits in a few modes, a bias only the lowest rings feel) and `m₂` grows linearly from the
//! rings below to the ring's top. With `s = √m₂` the q-integrals become
//! `∫ dq q² C w F(w) = Σ_rings (√2/(π q)) ∫ ds F(√2/s)`, integrated by Gauss–Legendre on
//! pieces of each ring no wider than a ratio of 1.2 in `s` (the first ring, which starts
//! at `s = 0`, down to `10⁻⁹` of its top).
//!
//! ```
//! use asperity::persson::{Persson, PerssonParams};
//! use asperity::spectrum::{LongWavelength, Psd};
//! use asperity::surface::{Normalisation, SurfaceGenerator, SurfaceSpec};
//! let psd = Psd::new(0.8, LongWavelength::RollOff { q0: 6.0 }, None)?;
//! let spec = SurfaceSpec::new(128, 128, 1.0, psd, Normalisation::RmsSlope(1.0))?;
//! let surface = SurfaceGenerator::new(&spec)?.generate(1);
//! let theory = Persson::from_surface(&surface, PerssonParams::default())?;
//! let low = theory.predict(1e-6)?;
//! // Small load: A/A0 = κ p/(E* ḡ) with κ = √(8/π), and K = p/u0.
//! let kappa = low.area_fraction * theory.rms_gradient() / 1e-6;
//! assert!((kappa - (8.0 / std::f64::consts::PI).sqrt()).abs() < 1e-6);
//! assert!((low.stiffness * theory.u0() / 1e-6 - 1.0).abs() < 1e-4);
//! # Ok::<(), asperity::Error>(())
//! ```

use std::f64::consts::PI;
use std::sync::OnceLock;

use crate::surface::stats::{radial_psd_2d, PsdBin};
use crate::surface::Surface;
use crate::{Error, Result};

/// Persson's own small-load coefficient, `κ = √(8/π)` in `A/A₀ = κ p/(E* ḡ)`.
pub const PERSSON_KAPPA: f64 = 1.595_769_121_605_730_7;

/// The parameters of the theory besides the spectrum.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PerssonParams {
    /// Effective modulus `E*` (the unit of the pressures).
    pub modulus: f64,
    /// Yang & Persson's elastic-energy factor γ in `S = γ + (1−γ)P²`, in `(0, 1]`
    /// (γ = 1: no correction).
    pub gamma: f64,
    /// Small-load coefficient κ of the contact area, `A/A₀ → κ p/(E* ḡ)`:
    /// [`PERSSON_KAPPA`] is Persson 2001; about 2 is what simulations find.
    pub kappa: f64,
}

impl Default for PerssonParams {
    /// `E* = 1`, γ = 0.45, κ = √(8/π) (the uncorrected area).
    fn default() -> Self {
        PerssonParams {
            modulus: 1.0,
            gamma: 0.45,
            kappa: PERSSON_KAPPA,
        }
    }
}

impl PerssonParams {
    /// Checks `E* > 0`, `γ ∈ (0, 1]`, `κ > 0`, all finite.
    pub fn validate(&self) -> Result<()> {
        if !crate::is_positive_finite(self.modulus) {
            return Err(Error::invalid(
                "modulus",
                format!(
                    "E* must be positive and finite, got {}",
                    crate::input::short_number(self.modulus)
                ),
            ));
        }
        if !(self.gamma > 0.0 && self.gamma <= 1.0) {
            return Err(Error::invalid(
                "gamma",
                format!(
                    "Persson's γ must lie in (0, 1], got {}",
                    crate::input::short_number(self.gamma)
                ),
            ));
        }
        if !crate::is_positive_finite(self.kappa) {
            return Err(Error::invalid(
                "kappa",
                format!(
                    "κ must be positive and finite, got {}",
                    crate::input::short_number(self.kappa)
                ),
            ));
        }
        Ok(())
    }
}

/// The theory's predictions at one mean pressure.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PerssonPoint {
    /// Mean (nominal) pressure `p`.
    pub pressure: f64,
    /// Relative contact area `A/A₀`.
    pub area_fraction: f64,
    /// Mean interfacial separation `ū` (length).
    pub mean_gap: f64,
    /// Stiffness per unit nominal area, `K = −dp/dū` (pressure per length).
    pub stiffness: f64,
    /// Contact stiffness `k = K A₀` (force per length), comparable to the BEM's.
    pub contact_stiffness: f64,
}

/// One ring of the spectrum: its wavenumber and the range of `s = √m₂` it spans.
#[derive(Debug, Clone, Copy)]
struct Ring {
    q: f64,
    s_low: f64,
    s_high: f64,
}

/// Persson's theory for one surface spectrum; see the module docs.
#[derive(Debug, Clone)]
pub struct Persson {
    rings: Vec<Ring>,
    params: PerssonParams,
    area: f64,
    rms_height: f64,
}

impl Persson {
    /// From a radially averaged PSD in the normalisation of
    /// [`radial_psd_2d`] (`Σ C (2π)²/A = h_rms²`) over the nominal area `area`. Bins
    /// without power are skipped; at least one must carry some.
    pub fn from_psd(bins: &[PsdBin], area: f64, params: PerssonParams) -> Result<Self> {
        params.validate()?;
        if !crate::is_positive_finite(area) {
            return Err(Error::invalid(
                "area",
                format!(
                    "the nominal area must be positive and finite, got {}",
                    crate::input::short_number(area)
                ),
            ));
        }
        let mode_area = (2.0 * PI).powi(2) / area;
        let (mut m2, mut h2) = (0.0f64, 0.0f64);
        let mut rings = Vec::with_capacity(bins.len());
        for bin in bins {
            if !(crate::is_positive_finite(bin.q) && bin.psd.is_finite() && bin.psd >= 0.0) {
                return Err(Error::invalid(
                    "psd",
                    format!(
                        "a bin needs q > 0 and C >= 0, finite; got q = {}, C = {}",
                        bin.q, bin.psd
                    ),
                ));
            }
            let power = bin.modes as f64 * bin.psd * mode_area;
            if power == 0.0 {
                continue;
            }
            let s_low = m2.sqrt();
            m2 += power * bin.q * bin.q;
            h2 += power;
            rings.push(Ring {
                q: bin.q,
                s_low,
                s_high: m2.sqrt(),
            });
        }
        if rings.is_empty() {
            return Err(Error::invalid(
                "psd",
                "the spectrum carries no power (a flat surface has no rough contact)",
            ));
        }
        Ok(Persson {
            rings,
            params,
            area,
            rms_height: h2.sqrt(),
        })
    }

    /// From a surface: its radially averaged PSD ([`radial_psd_2d`]) over its nominal area
    /// (the area that PSD is normalised with, `L² · rows/cols`).
    pub fn from_surface(surface: &Surface, params: PerssonParams) -> Result<Self> {
        let (rows, cols) = surface.dim();
        let area = surface.size() * surface.size() * rows as f64 / cols as f64;
        Persson::from_psd(&radial_psd_2d(surface)?, area, params)
    }

    /// The parameters.
    pub fn params(&self) -> PerssonParams {
        self.params
    }

    /// The nominal area `A₀`.
    pub fn nominal_area(&self) -> f64 {
        self.area
    }

    /// rms gradient `ḡ = √m₂(q₁)` from the spectrum.
    pub fn rms_gradient(&self) -> f64 {
        self.rings.last().map_or(0.0, |r| r.s_high)
    }

    /// rms height from the spectrum (the rings the PSD holds).
    pub fn rms_height(&self) -> f64 {
        self.rms_height
    }

    /// The decay length of the low-load law `p ∝ exp(−ū/u₀)`:
    /// `u₀ = γ √π ∫ dq q² C w = γ √(2/π) Σ_rings Δs/q` (exact per ring).
    pub fn u0(&self) -> f64 {
        let sum: f64 = self.rings.iter().map(|r| (r.s_high - r.s_low) / r.q).sum();
        self.params.gamma * (2.0 / PI).sqrt() * sum
    }

    /// Relative contact area `A/A₀ = erf(√π κ p/(2 E* ḡ))` (Persson 2001 for κ = √(8/π)).
    pub fn area_fraction(&self, pressure: f64) -> f64 {
        let PerssonParams { modulus, kappa, .. } = self.params;
        erf(PI.sqrt() * kappa * pressure / (2.0 * modulus * self.rms_gradient()))
    }

    /// Mean interfacial separation `ū(p)` (Persson 2007 with Yang & Persson's S).
    pub fn mean_gap(&self, pressure: f64) -> f64 {
        let gamma = self.params.gamma;
        let scale = pressure / self.params.modulus;
        PI.sqrt()
            * self.ring_integral(|w| {
                let x = w * scale;
                0.5 * gamma * exp_integral_e1(x * x) + 3.0 * (1.0 - gamma) * erf_squared_tail(x)
            })
    }

    /// Stiffness per unit nominal area `K = −dp/dū` at mean pressure `p`.
    pub fn stiffness(&self, pressure: f64) -> f64 {
        let gamma = self.params.gamma;
        let scale = pressure / self.params.modulus;
        let integral = self.ring_integral(|w| {
            let x = w * scale;
            let e = erf(x);
            (gamma + 3.0 * (1.0 - gamma) * e * e) * (-x * x).exp()
        });
        pressure / (PI.sqrt() * integral)
    }

    /// Every prediction at one mean pressure; refuses a pressure that is not positive and
    /// finite, and results that are not finite (pressures so small or large that the
    /// integrals under- or overflow).
    pub fn predict(&self, pressure: f64) -> Result<PerssonPoint> {
        if !crate::is_positive_finite(pressure) {
            return Err(Error::invalid(
                "pressure",
                format!(
                    "Persson's theory needs a positive, finite mean pressure, got {}",
                    crate::input::short_number(pressure)
                ),
            ));
        }
        let stiffness = self.stiffness(pressure);
        let point = PerssonPoint {
            pressure,
            area_fraction: self.area_fraction(pressure),
            mean_gap: self.mean_gap(pressure),
            stiffness,
            contact_stiffness: stiffness * self.area,
        };
        let values = [
            point.area_fraction,
            point.mean_gap,
            point.stiffness,
            point.contact_stiffness,
        ];
        if values.iter().any(|v| !v.is_finite()) {
            return Err(Error::invalid(
                "pressure",
                format!("p = {pressure} is out of the range where the theory's integrals are finite in double precision"),
            ));
        }
        Ok(point)
    }

    /// `∫ dq q² C(q) w(q) F(w(q)) = Σ_rings (√2/(π q)) ∫ ds F(√2/s)`: `f` receives
    /// `w = √2/s` and returns `F(w)` (the integrand's own factor `w` is absorbed by `ds`).
    fn ring_integral(&self, f: impl Fn(f64) -> f64) -> f64 {
        let mut total = 0.0;
        for ring in &self.rings {
            let mut sum = 0.0;
            for (a, b) in ring_pieces(ring.s_low, ring.s_high) {
                sum += gauss_legendre(a, b, |s| f(std::f64::consts::SQRT_2 / s));
            }
            total += std::f64::consts::SQRT_2 / (PI * ring.q) * sum;
        }
        total
    }
}

/// Pieces `[a, b]` of `[low, high]` with `b/a ≤` [`PIECE_RATIO`]; from `low = 0`, down to
/// `10⁻⁹ high` (the rest adds less than that fraction of a bounded integrand).
fn ring_pieces(low: f64, high: f64) -> impl Iterator<Item = (f64, f64)> {
    let start = if low > 0.0 { low } else { high * 1e-9 };
    let count = ((high / start).ln() / PIECE_RATIO.ln()).ceil().max(1.0) as usize;
    let ratio = (high / start).powf(1.0 / count as f64);
    (0..count).map(move |i| {
        let a = start * ratio.powi(i as i32);
        let b = if i + 1 == count { high } else { a * ratio };
        (a, b)
    })
}

/// The widest ratio `b/a` of one Gauss–Legendre piece of a ring.
const PIECE_RATIO: f64 = 1.2;

/// Four-point Gauss–Legendre on `[a, b]`.
fn gauss_legendre(a: f64, b: f64, f: impl Fn(f64) -> f64) -> f64 {
    const NODES: [f64; 2] = [0.339_981_043_584_856_3, 0.861_136_311_594_052_6];
    const WEIGHTS: [f64; 2] = [0.652_145_154_862_546_1, 0.347_854_845_137_453_9];
    let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
    let mut sum = 0.0;
    for (x, w) in NODES.iter().zip(WEIGHTS) {
        sum += w * (f(mid - half * x) + f(mid + half * x));
    }
    sum * half
}

/// The error function, to about 1e-16 relative: the series
/// `erf x = (2/√π) e^(−x²) Σ 2ⁿ x^(2n+1)/(1·3⋯(2n+1))` below 2.5 (positive terms, no
/// cancellation), `1 − erfc x` above.
pub fn erf(x: f64) -> f64 {
    if x < 0.0 {
        return -erf(-x);
    }
    if x >= ERF_SWITCH {
        return 1.0 - erfc(x);
    }
    let (mut term, mut sum) = (x, x);
    let mut n = 0.0;
    while term > 1e-17 * sum {
        n += 1.0;
        term *= 2.0 * x * x / (2.0 * n + 1.0);
        sum += term;
    }
    2.0 / PI.sqrt() * (-x * x).exp() * sum
}

/// Where [`erf`] switches from its series to the continued fraction of [`erfc`].
const ERF_SWITCH: f64 = 2.5;

/// The complementary error function `1 − erf x`; by the continued fraction
/// `erfc x = e^(−x²)/√π / (x + (1/2)/(x + 1/(x + (3/2)/(x + …))))` from 2.5 up.
pub fn erfc(x: f64) -> f64 {
    if x < ERF_SWITCH {
        return 1.0 - erf(x);
    }
    // Modified Lentz for f = x + a₁/(x + a₂/(x + …)), a_k = k/2.
    let tiny = 1e-300;
    let (mut f, mut c, mut d) = (x, x, 0.0f64);
    for k in 1..500 {
        let a = 0.5 * k as f64;
        d = x + a * d;
        d = if d.abs() < tiny { tiny } else { d };
        d = 1.0 / d;
        c = x + a / c;
        c = if c.abs() < tiny { tiny } else { c };
        let delta = c * d;
        f *= delta;
        if (delta - 1.0).abs() < 1e-16 {
            break;
        }
    }
    (-x * x).exp() / (PI.sqrt() * f)
}

/// The exponential integral `E₁(x) = ∫_x^∞ e^(−t)/t dt` for `x > 0`: its series up to 1,
/// the continued fraction (modified Lentz) above.
pub fn exp_integral_e1(x: f64) -> f64 {
    const EULER: f64 = 0.577_215_664_901_532_9;
    if x <= 1.0 {
        let (mut term, mut sum) = (1.0f64, 0.0f64);
        for k in 1..100 {
            term *= -x / k as f64;
            let add = term / k as f64;
            sum += add;
            if add.abs() <= 1e-17 * sum.abs() {
                break;
            }
        }
        return -EULER - x.ln() - sum;
    }
    let tiny = 1e-300;
    let mut b = x + 1.0;
    let (mut c, mut d) = (1.0 / tiny, 1.0 / b);
    let mut h = d;
    for i in 1..500 {
        let a = -((i * i) as f64);
        b += 2.0;
        d = 1.0 / (a * d + b);
        c = b + a / c;
        let delta = c * d;
        h *= delta;
        if (delta - 1.0).abs() < 1e-16 {
            break;
        }
    }
    h * (-x).exp()
}

/// `I(x₀) = ∫_{x₀}^∞ erf²(x) e^(−x²)/x dx`, by cubic Hermite interpolation in a table of
/// step [`TAIL_STEP`] on `[0, TAIL_END]` (values by Gauss–Legendre between the nodes,
/// slopes exact); beyond `TAIL_END`, `erf² = 1` to 1e-19 and `I = E₁(x₀²)/2`.
fn erf_squared_tail(x0: f64) -> f64 {
    if x0 >= TAIL_END {
        return 0.5 * exp_integral_e1(x0 * x0);
    }
    let table = tail_table();
    let t = x0 / TAIL_STEP;
    let i = (t.floor() as usize).min(table.len() - 2);
    let u = t - i as f64;
    let (y0, y1) = (table[i], table[i + 1]);
    let (d0, d1) = (
        -tail_integrand(i as f64 * TAIL_STEP) * TAIL_STEP,
        -tail_integrand((i + 1) as f64 * TAIL_STEP) * TAIL_STEP,
    );
    let (u2, u3) = (u * u, u * u * u);
    (2.0 * u3 - 3.0 * u2 + 1.0) * y0
        + (u3 - 2.0 * u2 + u) * d0
        + (-2.0 * u3 + 3.0 * u2) * y1
        + (u3 - u2) * d1
}

/// Step of the table of [`erf_squared_tail`].
const TAIL_STEP: f64 = 1.0 / 1024.0;
/// End of the table of [`erf_squared_tail`].
const TAIL_END: f64 = 6.5;

/// `erf²(x) e^(−x²)/x` (0 at x = 0, its limit).
fn tail_integrand(x: f64) -> f64 {
    if x == 0.0 {
        return 0.0;
    }
    let e = erf(x);
    e * e * (-x * x).exp() / x
}

/// The table of `I` at `k · TAIL_STEP`, built once, from the top down.
fn tail_table() -> &'static [f64] {
    static TABLE: OnceLock<Vec<f64>> = OnceLock::new();
    TABLE.get_or_init(|| {
        let n = (TAIL_END / TAIL_STEP).round() as usize;
        let mut table = vec![0.0; n + 1];
        table[n] = 0.5 * exp_integral_e1(TAIL_END * TAIL_END);
        for k in (0..n).rev() {
            let (a, b) = (k as f64 * TAIL_STEP, (k + 1) as f64 * TAIL_STEP);
            table[k] = table[k + 1] + gauss_legendre(a, b, tail_integrand);
        }
        table
    })
}

#[cfg(test)]
mod tests;

/// The code blocks of `docs/persson.md`, run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../../../docs/persson.md")]
pub struct PerssonPage;
