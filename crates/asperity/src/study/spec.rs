//! What a study is: its method, sizes, Hurst exponents and samples ([`StudySpec`], with
//! its rules and a documented `Default`), its tasks, the seed of every sample and the cost of
//! a sample.

use super::*;

/// Which solver produces the force–stiffness curve of a sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// 1D method of dimensionality reduction on rough lines (linear springs).
    Mdr,
    /// 3D boundary elements on rough surfaces (free boundaries, frozen-set stiffness).
    Bem,
}

impl Method {
    /// Lower-case name, as in the CLI and CSV.
    pub fn name(&self) -> &'static str {
        match self {
            Method::Mdr => "mdr",
            Method::Bem => "bem",
        }
    }
}

/// Everything that defines a study; validated by [`StudySpec::validate`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StudySpec {
    /// Solver.
    pub method: Method,
    /// Grid sizes N (points of a line, or points per side of a square surface).
    pub sizes: Vec<usize>,
    /// Hurst exponents.
    pub hursts: Vec<f64>,
    /// Realisations per (N, H).
    pub samples: usize,
    /// Long-wavelength roll-off `q0 L / 2π`, if any.
    pub rolloff: Option<f64>,
    /// Study seed.
    pub seed: u64,
    /// Low-force window of the α fits.
    pub window: FitWindow,
    /// Number of common force levels of the ensemble curves.
    pub levels: usize,
    /// BEM: the contact fraction past which a sample stops loading (its sweep ends with
    /// the first load above it); `None`: all [`samplers::BemSampler::LOADS`] loads, up to
    /// p̄ = 0.2 E*. An α study needs only the low-force end ([`StudySpec::with_alpha_sweep`]);
    /// MDR samples ignore it (their whole curve costs one pass).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sweep_end: Option<f64>,
    /// BEM: Poisson's ratio ν of the tangential (no-slip) frozen-set stiffnesses computed at
    /// every load beside the normal one ([`crate::bem::tangential`]; each point's
    /// [`CurvePoint::tangential_ratio`], the ensemble's [`EnsemblePoint::tangential_ratio`]);
    /// `None`: none. MDR studies refuse it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub poisson: Option<f64>,
    /// BEM with [`StudySpec::poisson`]: which of `k_x`, `k_y` (both by default; one for
    /// about half the cost, the ratio then `k_d/k`); absent (both) from the JSON when both.
    #[serde(default, skip_serializing_if = "Directions::is_both")]
    pub tangential: Directions,
}

/// A study of one MDR task, 64 samples of a line of N = 512 points at H = 0.5 without
/// roll-off, with the front ends' defaults for the rest: seed 1, the default α window
/// ([`FitWindow::default`]), [`DEFAULT_LEVELS`] force levels, every load of a BEM sample.
/// A front end sets `method`, `sizes`, `hursts` and `samples` (which the CLI requires) and
/// takes the rest from here: `StudySpec { samples: 40, ..StudySpec::default() }`.
///
/// ```
/// use asperity::study::{StudySpec, DEFAULT_LEVELS};
///
/// let spec = StudySpec::default();
/// assert!(spec.validate().is_ok());
/// assert_eq!((spec.seed, spec.levels, spec.sweep_end), (1, DEFAULT_LEVELS, None));
/// ```
impl Default for StudySpec {
    fn default() -> Self {
        StudySpec {
            method: Method::Mdr,
            sizes: vec![512],
            hursts: vec![0.5],
            samples: 64,
            rolloff: None,
            seed: 1,
            window: FitWindow::default(),
            levels: DEFAULT_LEVELS,
            sweep_end: None,
            poisson: None,
            tangential: Directions::Both,
        }
    }
}

/// An α study's BEM sweep ends past this many times the largest window fraction it may be
/// fitted on: each sample's curve must reach the ensemble's window end, the median over
/// samples of their window ends. Measured on `reproduce fig1 --quick` (64², 128², 9 H,
/// 20 samples each, every sensitivity window): the first load past 4× a window's end
/// carries at least 3.5 times that window's ensemble end force (docs/bem_history.md).
pub const ALPHA_SWEEP_MARGIN: f64 = 4.0;

impl StudySpec {
    /// The spec with the sweep of an α study: BEM samples stop loading past
    /// [`ALPHA_SWEEP_MARGIN`] times the largest contact fraction any of its α fits can end
    /// at (its own window and those of [`sensitivity::sensitivity_windows`], on each of its
    /// grids), or never where that is not below full contact. The fits are then those of
    /// the whole sweep, bit for bit, as long as every sample's curve reaches the ensemble's
    /// window ends, which [`TaskResult::from_samples`] checks (`samplers::tests`); at a
    /// fraction of the cost: at 128² the loads above 10 % contact are about 40 % of a
    /// sample's time.
    pub fn with_alpha_sweep(mut self) -> Self {
        let largest_end = self
            .sizes
            .iter()
            .flat_map(|&n| {
                let points = n.saturating_mul(n);
                self.fit_windows().map(move |w| w.fraction_range(points).1)
            })
            .fold(0.0, f64::max);
        let end = ALPHA_SWEEP_MARGIN * largest_end;
        self.sweep_end = (self.method == Method::Bem && end < 1.0).then_some(end);
        self
    }

    /// The windows the study's α may be fitted on: its own, and those of the sensitivity
    /// table ([`sensitivity::sensitivity_windows`], refitted from its stored curves).
    pub(super) fn fit_windows(&self) -> impl Iterator<Item = FitWindow> {
        std::iter::once(self.window).chain(sensitivity::sensitivity_windows())
    }

    /// Checks sizes, Hurst exponents, samples, roll-off and window.
    pub fn validate(&self) -> Result<()> {
        if self.sizes.is_empty() {
            return Err(Error::invalid("n", "no grid size given"));
        }
        let min_n = match self.method {
            Method::Mdr => 16,
            Method::Bem => 8,
        };
        if let Some(&n) = self.sizes.iter().find(|&&n| n < min_n) {
            return Err(Error::invalid(
                "n",
                format!("N = {n} is below the smallest useful size {min_n}"),
            ));
        }
        let mut seen = std::collections::HashSet::with_capacity(self.sizes.len());
        if let Some(n) = self.sizes.iter().find(|&&n| !seen.insert(n)) {
            return Err(Error::invalid("n", format!("N = {n} is given twice")));
        }
        if self.hursts.is_empty() {
            return Err(Error::invalid("hurst", "the range of H is empty"));
        }
        let (lo, hi) = HURST_RANGE;
        if let Some(&h) = self.hursts.iter().find(|h| !(lo..=hi).contains(*h)) {
            return Err(Error::invalid(
                "hurst",
                format!("H = {h} is outside [{lo}, {hi}]"),
            ));
        }
        check_distinct_hursts(&self.hursts)?;
        if self.samples == 0 {
            return Err(Error::invalid("samples", "need at least 1 sample"));
        }
        if let Some(q0) = self.rolloff {
            if !crate::is_positive_finite(q0) {
                return Err(Error::invalid(
                    "rolloff",
                    format!("must be positive, got {q0}"),
                ));
            }
        }
        if !(3..=MAX_LEVELS).contains(&self.levels) {
            return Err(Error::invalid(
                "levels",
                format!("need 3 to {MAX_LEVELS} force levels, got {}", self.levels),
            ));
        }
        self.window.validate()?;
        if let Some(end) = self.sweep_end {
            if !(end > 0.0 && end <= 1.0) {
                return Err(Error::invalid(
                    "sweep_end",
                    format!(
                        "the sweep's end is a contact fraction in (0, 1], got {}",
                        crate::input::short_number(end)
                    ),
                ));
            }
        }
        if let Some(poisson) = self.poisson {
            crate::mdr::check_poisson(poisson)?;
            if self.method != Method::Bem {
                let reason = "the tangential stiffness of a study is computed by BEM only";
                return Err(Error::invalid("poisson", reason));
            }
        } else if !self.tangential.is_both() {
            let reason = format!(
                "the direction {} needs a Poisson's ratio (poisson)",
                self.tangential.name()
            );
            return Err(Error::invalid("tangential", reason));
        }
        self.ensure_size()?;
        self.ensure_samplers()
    }

    /// Refuses a study whose size (tasks × samples, and the results it keeps: tasks ×
    /// levels) is beyond what can be run, before anything is created.
    pub(super) fn ensure_size(&self) -> Result<()> {
        let tasks = self.sizes.len().checked_mul(self.hursts.len());
        let samples = tasks.and_then(|t| t.checked_mul(self.samples));
        match samples {
            Some(total) if total <= MAX_STUDY_SAMPLES => {}
            _ => {
                return Err(Error::invalid(
                    "samples",
                    format!(
                        "{} sizes x {} H values x {} samples is more than the {} samples a \
                         study may hold",
                        self.sizes.len(),
                        self.hursts.len(),
                        self.samples,
                        crate::input::short_number(MAX_STUDY_SAMPLES as f64)
                    ),
                ))
            }
        }
        // The results of every task stay in memory until the tables are written.
        let per_task = array_bytes(&[self.levels], std::mem::size_of::<EnsemblePoint>())
            .zip(array_bytes(&[self.samples], 8))
            .and_then(|(a, b)| a.checked_add(b));
        crate::memory::ensure_fits(
            &format!(
                "the results of a study of {} tasks with {} force levels",
                tasks.unwrap_or(usize::MAX),
                self.levels
            ),
            per_task.and_then(|b| b.checked_mul(tasks? as u64)),
        )
    }

    /// All tasks, sizes outer, H inner.
    pub fn tasks(&self) -> Vec<Task> {
        self.sizes
            .iter()
            .flat_map(|&n| self.hursts.iter().map(move |&hurst| Task { n, hurst }))
            .collect()
    }
}

/// The number of common force levels of the ensemble curves when none is asked for (the
/// CLI's `--levels`, Python's `levels`, the figures and the benchmarks).
pub const DEFAULT_LEVELS: usize = 48;

/// The most force levels of an ensemble curve.
pub const MAX_LEVELS: usize = 100_000;

/// The most samples (over all tasks) a study may hold.
pub const MAX_STUDY_SAMPLES: usize = 1_000_000_000;

/// Refuses H values given twice (`0` and `-0` are one value) or sharing a checkpoint
/// name (6 decimals), in one pass.
pub(super) fn check_distinct_hursts(hursts: &[f64]) -> Result<()> {
    let mut values = std::collections::HashMap::with_capacity(hursts.len());
    let mut keys = std::collections::HashMap::with_capacity(hursts.len());
    for &h in hursts {
        if values.insert((h + 0.0).to_bits(), h).is_some() {
            return Err(Error::invalid("hurst", format!("H = {h} is given twice")));
        }
        if let Some(earlier) = keys.insert(hurst_key(h), h) {
            return Err(Error::invalid(
                "hurst",
                format!(
                    "H = {earlier} and H = {h} would share one checkpoint (H is kept to 6 \
                     decimals in its name, {}); give values at least 1e-6 apart",
                    hurst_key(h)
                ),
            ));
        }
    }
    Ok(())
}

/// One `(N, H)` ensemble of a study.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Task {
    /// Grid size.
    pub n: usize,
    /// Hurst exponent.
    pub hurst: f64,
}

impl Task {
    /// File-name key, e.g. `mdr_n512_h-0.250000`: H rounded to 6 decimals, so
    /// [`StudySpec::validate`] refuses H values that would share a key.
    pub fn key(&self, method: Method) -> String {
        format!("{}_n{}_h{}", method.name(), self.n, hurst_key(self.hurst))
    }

    /// Same N and the same H bit for bit.
    pub fn same_as(&self, other: &Task) -> bool {
        self.n == other.n && self.hurst.to_bits() == other.hurst.to_bits()
    }
}

/// H as it appears in checkpoint names: signed, 6 decimals.
pub(super) fn hurst_key(hurst: f64) -> String {
    format!("{hurst:+.6}")
}

/// Relative cost of one sample of `method` at grid size `n`, the weight of a sample in
/// progress estimates: `N² log₂ N` for BEM (FFTs of the N×N grid in every iteration of
/// every load) and `N log₂ N` for MDR (FFT synthesis of the line, then its sort). Only
/// ratios within one method are meaningful.
pub fn sample_cost(method: Method, n: usize) -> f64 {
    let n = n.max(2) as f64;
    match method {
        Method::Bem => n * n * n.log2(),
        Method::Mdr => n * n.log2(),
    }
}

pub(crate) fn splitmix64(mut x: u64) -> u64 {
    x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    x ^ (x >> 31)
}

/// Seed of sample `index` of `(method, N, H)` in a study with seed `study_seed`.
pub fn sample_seed(study_seed: u64, method: Method, task: Task, index: usize) -> u64 {
    let mut x = splitmix64(study_seed ^ method as u64);
    x = splitmix64(x ^ task.n as u64);
    x = splitmix64(x ^ task.hurst.to_bits());
    splitmix64(x ^ index as u64)
}

/// Refuses the samples of a sweep that ended early ([`StudySpec::sweep_end`]) when one
/// of them ends below the ensemble's window end of the study's window or of a sensitivity
/// window: there the fit would average fewer samples than the whole sweep's fit does.
pub(super) fn check_sweep_reaches_windows(spec: &StudySpec, samples: &[SampleCurve]) -> Result<()> {
    let Some(end) = spec.sweep_end else {
        return Ok(());
    };
    let refs: Vec<&SampleCurve> = samples.iter().collect();
    for window in spec.fit_windows() {
        let Some((_, hi)) = curve::ensemble_window(&refs, &window) else {
            continue;
        };
        let short = samples.iter().enumerate().find_map(|(i, s)| {
            let last = s.points.last()?.force;
            (last < hi).then_some((i, last))
        });
        if let Some((i, last)) = short {
            return Err(Error::invalid(
                "sweep_end",
                format!(
                    "sample {i}, its sweep ended past contact fraction {}, reached force \
                     {last:.6e} only, below the {hi:.6e} at which the ensemble's α window ({}) \
                     ends: this study needs the whole load sweep",
                    crate::input::short_number(end),
                    window.describe()
                ),
            ));
        }
    }
    Ok(())
}
