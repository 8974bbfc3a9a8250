//! The settings of `asperity reproduce`: how far each figure follows the paper's grids and
//! samples. The MDR parts are cheap and follow the paper in every setting but the quick one's
//! Fig. 15.2 and Fig. 6; the BEM parts set the run time:
//!
//! | setting | Fig. 1 BEM | Fig. 2 | Fig. 5 BEM | time on 2 cores |
//! |---|---|---|---|---|
//! | quick | N = 64, 128; H step 0.5; 20 samples | 128², 20 samples | N = 64, 128; 20 | minutes |
//! | medium | N = 256, 512; H step 0.5; 20 samples | 512², 20 samples | N = 64 … 512; 20 | hours |
//! | paper | N = 128 … 1024; H step 0.25; 60 samples | 1024², 60 samples, H step 0.5 | N = 128 … 1024; 60 | about 10 hours in all |
//!
//! A hidden `test` setting runs the medium setting's code path on tiny grids for the tests.

use anyhow::Result;
use asperity_app::range::parse_range;

/// How closely `reproduce` follows the paper (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Setting {
    /// Small grids and few samples: minutes.
    Quick,
    /// BEM on 256² and 512² with 20 samples: hours on 2 cores, checkpointed.
    Medium,
    /// The paper's grids (up to 1024²) and 60 samples: about 10 hours for all the figures on 2
    /// cores (estimated), checkpointed.
    Paper,
    /// Tiny grids through the medium setting's code path (tests only).
    #[value(hide = true)]
    Test,
}

/// The BEM studies of a setting: grids, samples per (N, H) and H values.
pub struct BemPlan {
    pub sizes: Vec<usize>,
    pub samples: usize,
    pub hursts: Vec<f64>,
}

impl Setting {
    /// The name on the command line and in each folder's stamp.
    pub fn name(self) -> &'static str {
        match self {
            Setting::Quick => "quick",
            Setting::Medium => "medium",
            Setting::Paper => "paper",
            Setting::Test => "test",
        }
    }

    /// Whether the cheap figures (Fig. 6, 15.2) are cut down too.
    pub fn is_quick(self) -> bool {
        matches!(self, Setting::Quick | Setting::Test)
    }

    /// Fig. 1, MDR: sizes and samples (the paper's: N = 2^9, 2^11, 2^15, 500 lines).
    pub fn fig1_mdr(self) -> (Vec<usize>, usize) {
        match self {
            Setting::Test => (vec![1 << 9], 20),
            _ => (vec![1 << 9, 1 << 11, 1 << 15], 500),
        }
    }

    /// Fig. 1, BEM.
    pub fn fig1_bem(self) -> Result<BemPlan> {
        let (sizes, samples, hursts) = match self {
            Setting::Quick => (vec![64, 128], 20, "-1:3:0.5"),
            Setting::Medium => (vec![256, 512], 20, "-1:3:0.5"),
            Setting::Paper => (vec![1 << 7, 1 << 8, 1 << 9, 1 << 10], 60, "-1:3:0.25"),
            Setting::Test => (vec![16, 32], 3, "-1:3:2"),
        };
        Ok(BemPlan {
            sizes,
            samples,
            hursts: parse_range(hursts)?,
        })
    }

    /// Fig. 2 (BEM, roll-off 6): one grid.
    pub fn fig2(self) -> Result<BemPlan> {
        let five = vec![-1.0, 0.0, 1.0, 2.0, 3.0];
        let (n, samples, hursts) = match self {
            Setting::Quick => (128, 20, five),
            Setting::Medium => (512, 20, five),
            Setting::Paper => (1024, 60, parse_range("-1:3:0.5")?),
            Setting::Test => (32, 3, vec![-1.0, 1.0]),
        };
        Ok(BemPlan {
            sizes: vec![n],
            samples,
            hursts,
        })
    }

    /// Fig. 5, MDR sizes and samples (the paper's: N = 2^6 … 2^16, 500 lines).
    pub fn fig5_mdr(self) -> (Vec<usize>, usize) {
        match self {
            Setting::Test => ((6..=9).map(|m| 1usize << m).collect(), 20),
            _ => ((6..=16).map(|m| 1usize << m).collect(), 500),
        }
    }

    /// Fig. 5, BEM (H = −0.5).
    pub fn fig5_bem(self) -> BemPlan {
        let (sizes, samples) = match self {
            Setting::Quick => (vec![64, 128], 20),
            Setting::Medium => (vec![64, 128, 256, 512], 20),
            Setting::Paper => (vec![1 << 7, 1 << 8, 1 << 9, 1 << 10], 60),
            Setting::Test => (vec![16, 32], 3),
        };
        BemPlan {
            sizes,
            samples,
            hursts: vec![-0.5],
        }
    }

    /// The sentence each report opens with.
    pub fn describe(self) -> &'static str {
        match self {
            Setting::Quick => {
                "**Setting: quick** (`--quick`): BEM on small grids (N ≤ 128) with 20 samples \
                 instead of the paper's N up to 1024 with 60; MDR as in the paper. \
                 `--setting medium` (hours) and `--setting paper` (about 10 hours in all) follow the \
                 paper closer."
            }
            Setting::Medium => {
                "**Setting: medium** (`--setting medium`): BEM on 256² and 512² (Fig. 5: 64² … \
                 512²) with 20 samples, between the quick setting and the paper's N up to 1024 \
                 with 60 samples; MDR as in the paper."
            }
            Setting::Paper => "**Setting: paper** — the paper's grids and samples.",
            Setting::Test => "**Setting: test** — tiny grids for the test suite; not a result.",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_plans_grow_with_the_setting() {
        let names: std::collections::BTreeSet<_> = [
            Setting::Quick,
            Setting::Medium,
            Setting::Paper,
            Setting::Test,
        ]
        .map(|s| s.name())
        .into();
        assert_eq!(names.len(), 4);
        let largest = |s: Setting| *s.fig1_bem().unwrap().sizes.iter().max().unwrap();
        assert!(largest(Setting::Test) < largest(Setting::Quick));
        assert!(largest(Setting::Quick) < largest(Setting::Medium));
        assert!(largest(Setting::Medium) < largest(Setting::Paper));
        assert_eq!(Setting::Medium.fig1_bem().unwrap().hursts.len(), 9);
        assert_eq!(Setting::Medium.fig2().unwrap().sizes, vec![512]);
    }
}
