//! Paper Fig. 1: the exponent α of k ∝ F^α versus the Hurst exponent H, from MDR and BEM
//! studies, beside the paper's eq. (6) and eq. (24).

use std::fmt::Write as _;
use std::path::Path;

use anyhow::Result;
use asperity::study::theory::alpha_theory;
use asperity::study::{Method, TaskResult};
use asperity_app::range::parse_range;
use asperity_app::study::report::{write as write_comparison, Results};

use super::super::setting::Setting;
use super::{announce, describe_hursts, figure_study, study_spec};
use crate::request::report_error;
use crate::studies::{write_alpha, Kind};

fn alpha_rows_md(results: &[TaskResult]) -> String {
    let mut md = String::from("| method | N | H | α (ensemble fit) | 95 % of samples | theory |\n|---|---|---|---|---|---|\n");
    for r in results {
        let (lo, hi) = r.alpha_sample_interval().unwrap_or((f64::NAN, f64::NAN));
        let _ = writeln!(
            md,
            "| {} | {} | {} | {:.3} | {:.3} – {:.3} | {:.3} |",
            r.method.name(),
            r.task.n,
            r.task.hurst,
            r.alpha_ensemble.map_or(f64::NAN, |f| f.exponent),
            lo,
            hi,
            alpha_theory(r.task.hurst, r.task.n)
        );
    }
    md
}

/// Paper Fig. 1: α(H) from MDR (N = 2^9, 2^11, 2^15) and BEM (N = 2^7 … 2^10).
pub fn fig1(dir: &Path, setting: Setting, force: bool, discard: bool) -> Result<()> {
    let hursts = parse_range("-1:3:0.25")?;
    // MDR is cheap (the paper's 25 500 lines take seconds): every setting keeps it.
    let (mdr_sizes, mdr_samples) = setting.fig1_mdr();
    let mdr = study_spec(Method::Mdr, mdr_sizes, hursts, mdr_samples, None);
    let plan = setting.fig1_bem()?;
    let bem =
        study_spec(Method::Bem, plan.sizes, plan.hursts, plan.samples, None).with_alpha_sweep();
    let bem = crate::studies::resumable(bem, &dir.join("bem"), discard, false);
    announce("fig1", setting, dir, &[&bem])?;
    let mdr_results = figure_study(dir, "mdr", &mdr, Kind::Alpha, setting, discard)?;
    let bem_results = figure_study(dir, "bem", &bem, Kind::Alpha, setting, discard)?;
    let all: Vec<TaskResult> = mdr_results.iter().chain(&bem_results).cloned().collect();
    write_alpha(dir, &all, force, Some(setting.name()))?;
    let report = format!(
        "# Fig. 1: exponent α of k ∝ F^α versus H\n\n{}\n\n\
         - MDR: N = {:?}, {} samples per (N, H), H = {}.\n\
         - BEM: free boundaries, N = {:?}, {} samples per (N, H), H = {}.\n\
         - α window: {}; α is fitted on the ensemble-mean k(F) (column `alpha`), and per sample\n  \
           (`alpha_low`, `alpha_high`: 2.5 % and 97.5 % of the per-sample values).\n\n\
         Files: `alpha.csv`, `alpha.png`, `alpha.svg` (both methods with the theory curves);\n\
         `mdr/` and `bem/` hold each method's table, plot and checkpoint.\n\n\
         ## The paper's values beside ours\n\
         The paper: α = 1/3 for H > 2 (Hertz), α = 1/(1+H) for 0 < H < 2 (eq. 6), and for H ≤ 0 an\n\
         N-dependent α ≈ 0.9 given by eq. (24), α = (1 + log2 N)/(3 + log2 N), derived for H = 0 and\n\
         \"valid not only for H = 0, but also for smaller values\". Column *theory* is that value\n\
         for each row (eq. 24 at H = 0, not 1/(1+0) = 1).\n\n{}\n",
        setting.describe(),
        mdr.sizes,
        mdr.samples,
        describe_hursts(&mdr.hursts),
        bem.sizes,
        bem.samples,
        describe_hursts(&bem.hursts),
        mdr.window.describe(),
        alpha_rows_md(&all)
    );
    write_comparison(dir, Results::Fig1(&all), &report, force).map_err(report_error)
}
