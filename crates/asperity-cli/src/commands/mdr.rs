//! `asperity mdr`: force, stiffness and contacts of a rough line or an axisymmetric
//! indenter on the MDR spring foundation (linear, Hertz 15.2 or fractal 15.7 springs).

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use asperity::io::{read_npy_1d, sidecar_path, StagedOutputs};
use serde_json::json;

use super::measured::{has_import_sidecar, is_npy, load, record, MeasuredArgs};
use asperity::mdr::{
    log_spaced, Axisymmetric, CurvePoint, Foundation, LinearCurve, RadialProfile, Spring, SpringLaw,
};
use asperity::memory::{array_bytes, ensure_fits};
use asperity::surface::stats::rms_height;

use crate::output::{format_number, Table};
use crate::plot::{stage_charts, thin_log, Chart, ImageFormat, Series, Style};

/// Closed-form axisymmetric indenters.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ProfileKind {
    /// Sphere of radius --radius: g = x²/R (book eq. 15.1).
    Hertz,
    /// Cone of flank slope --slope (tan θ): g = (π/2) tan θ |x|.
    Cone,
    /// Flat cylindrical punch of radius --radius.
    Punch,
    /// Power law f = c rⁿ (--coefficient, --exponent): g = κ(n) c |x|ⁿ.
    Power,
}

/// Spring laws.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum SpringKind {
    /// Linear springs of stiffness E*·Δx.
    Linear,
    /// Hertz microscale law (15.2); radius from --asperity-radius (or --radius for --profile hertz).
    Hertz,
    /// Fractal microscale law (15.7) with critical depth (15.6); needs --hurst.
    Fractal,
}

/// Arguments of `asperity mdr`.
#[derive(Debug, clap::Args)]
#[command(after_help = "Examples:\n  \
    asperity line --n 32768 --hurst 0.5 --seed 1 --out line.npy\n  \
    asperity mdr --line line.npy --nloads 40 --out curve.csv\n  \
    asperity mdr --line line.npy --breakpoints --out breakpoints.csv\n  \
    asperity mdr --line line.npy --spring fractal --hurst 0.5 --nloads 60 --dmin 1e-6 --out nl.csv\n  \
    asperity mdr --profile hertz --radius 1 --n 2001 --dx 0.01 --spring hertz --indentations 1e-8,1e-6,1e-4\n  \
    asperity mdr --profile cone --slope 0.2 --n 4001 --dx 1e-3 --nloads 20 --out cone.csv\n  \
    asperity mdr --radial tip.npy --radial-step 1e-3 --n 1001 --dx 1e-3 --nloads 30\n  \
    asperity mdr --line line.npy --nloads 40 --out curve.csv --plot curve.svg\n  \
    asperity mdr --line profile.csv --detrend mean --modulus 1e9 --nloads 20 --out curve.csv\n\n\
    Output columns: indentation, force, stiffness, contacts. Indentation is measured from \
    first contact (the highest point of a line, the tip of an indenter). With --out, \
    OUT.csv.json records the inputs.")]
pub struct MdrArgs {
    /// A rough line, heights positive up: a 1D .npy (float64; spacing = size / n), or a
    /// measured profile (x z text, Dektak CSV, ...; length and units from the file, see
    /// --detrend, --fill).
    #[arg(long, value_name = "FILE", group = "indenter")]
    pub line: Option<PathBuf>,
    #[command(flatten)]
    pub measured: MeasuredArgs,
    /// A closed-form axisymmetric indenter, mapped to 1D by the MDR transform.
    #[arg(long, value_enum, group = "indenter")]
    pub profile: Option<ProfileKind>,
    /// A user's axisymmetric profile f(r) sampled at r = 0, DR, 2DR, … (1D .npy), mapped to
    /// 1D numerically.
    #[arg(
        long,
        value_name = "FILE.npy",
        group = "indenter",
        requires = "radial_step"
    )]
    pub radial: Option<PathBuf>,
    /// Sample step DR of --radial.
    #[arg(long, value_name = "DR")]
    pub radial_step: Option<f64>,
    /// Sphere or punch radius R (--profile hertz|punch).
    #[arg(long)]
    pub radius: Option<f64>,
    /// Cone flank slope tan θ (--profile cone).
    #[arg(long)]
    pub slope: Option<f64>,
    /// Prefactor c of f = c rⁿ (--profile power).
    #[arg(long)]
    pub coefficient: Option<f64>,
    /// Exponent n of f = c rⁿ (--profile power).
    #[arg(long)]
    pub exponent: Option<f64>,
    /// Number of springs for --profile / --radial (symmetric about the axis; odd puts one on it).
    #[arg(long, conflicts_with = "line")]
    pub n: Option<usize>,
    /// Spring spacing Δx for --profile / --radial (a line's is size / n).
    #[arg(long, allow_hyphen_values = true, conflicts_with = "line")]
    pub dx: Option<f64>,
    /// Line length L (--line: default the sidecar's, else 1; fractal law with a profile:
    /// default n·Δx).
    #[arg(long, allow_hyphen_values = true)]
    pub size: Option<f64>,
    /// Effective modulus E*.
    #[arg(long, default_value_t = 1.0, allow_hyphen_values = true)]
    pub modulus: f64,
    /// Spring law.
    #[arg(long, value_enum, default_value_t = SpringKind::Linear)]
    pub spring: SpringKind,
    /// Hurst exponent H of the fractal law (15.7), 0 < H < 2.
    #[arg(long, allow_hyphen_values = true)]
    pub hurst: Option<f64>,
    /// rms height h of the fractal law (default: the line's own rms height).
    #[arg(long, allow_hyphen_values = true)]
    pub rms_height: Option<f64>,
    /// Asperity radius R of the Hertz law (15.2) (default --radius with --profile hertz).
    #[arg(long)]
    pub asperity_radius: Option<f64>,
    /// Indentations to evaluate, comma separated.
    #[arg(long, value_delimiter = ',', num_args = 1.., conflicts_with_all = ["nloads", "breakpoints"], allow_negative_numbers = true)]
    pub indentations: Option<Vec<f64>>,
    /// Number of log-spaced indentations from --dmin to --dmax (default 50).
    #[arg(long, conflicts_with = "breakpoints")]
    pub nloads: Option<usize>,
    /// Smallest indentation for --nloads (default --dmax · 1e-6).
    #[arg(long, allow_hyphen_values = true)]
    pub dmin: Option<f64>,
    /// Largest indentation for --nloads (default: full contact, the largest finite gap).
    #[arg(long, allow_hyphen_values = true)]
    pub dmax: Option<f64>,
    /// Linear springs on a line: write the exact curve, one row per contact count j = 1..N
    /// (the breakpoints d_j where the j-th spring first touches). Here `stiffness` and
    /// `contacts` are those just after the breakpoint: contacts = j counts the spring that
    /// is just touching (k = E*·Δx·j), so the first row is d = 0, F = 0, contacts = 1. With
    /// --indentations/--nloads `contacts` counts springs compressed at d (u > 0): at d = 0
    /// that is 0, and k = 0.
    #[arg(long)]
    pub breakpoints: bool,
    /// Output CSV (default: standard output). Its inputs go to OUT.csv.json beside it
    /// (indenter and where it came from, springs, E*, spring law, indentations, columns).
    #[arg(long, value_name = "OUT.csv")]
    pub out: Option<PathBuf>,
    /// Also plot the curve (needs at least 2 indentations), .png or .svg by the extension:
    /// log–log force F vs indentation d (left) and stiffness k vs F (right), with F and k
    /// divided by E* (length² and length); points at d = 0 or F = 0 are left out.
    #[arg(long, value_name = "FILE.png|FILE.svg")]
    pub plot: Option<PathBuf>,
    /// Overwrite existing outputs.
    #[arg(long)]
    pub force: bool,
}

fn need(value: Option<f64>, flag: &str, what: &str) -> Result<f64> {
    value.with_context(|| format!("{what} needs {flag}"))
}

/// The indenter as a 1D profile on its spring grid.
struct Indenter {
    /// Line heights (positive up) or indenter profile g (lowest point touches first).
    values: Vec<f64>,
    /// True for a rough line (gaps from the highest point).
    is_line: bool,
    /// Spring spacing Δx.
    spacing: f64,
    /// Length L (used by the fractal law).
    size: f64,
    /// One line for the summary printed after writing.
    description: String,
    /// Where it came from, for the record OUT.csv.json.
    source: serde_json::Value,
}

/// Estimated bytes of one output row while the table is built and written: the row's
/// `Vec` of 4 `String`s (24 + 4·24 bytes), their text (up to 24 characters each, 32 bytes as
/// allocated) and its share of the CSV text (about 4·24 characters).
const ROW_BYTES: usize = 24 + 4 * 24 + 4 * 32 + 4 * 24;

/// Refuses an output of `rows` rows (plus `extra_per_row` bytes each of other buffers)
/// that would not fit in memory, before anything is allocated.
fn ensure_rows_fit(rows: usize, extra_per_row: usize, what: &str) -> Result<()> {
    let per_row = ROW_BYTES + extra_per_row;
    ensure_fits(
        &format!("{what} ({rows} rows of about {per_row} bytes)"),
        array_bytes(&[rows], per_row),
    )?;
    Ok(())
}

fn spring_grid(args: &MdrArgs, what: &str) -> Result<(usize, f64)> {
    let n = args
        .n
        .with_context(|| format!("{what} needs --n (number of springs)"))?;
    let dx = need(args.dx, "--dx", what)?;
    if !(dx.is_finite() && dx > 0.0) {
        bail!("invalid dx: the spring spacing Δx must be positive and finite, got {dx}");
    }
    if n == 0 {
        bail!("invalid n: need at least one spring");
    }
    // The profile g(x_i) and the foundation's sorted copy of it live together: two f64
    // per spring (the sort is in place).
    ensure_fits(
        &format!("--n {n} springs (profile and sorted gaps, 16 bytes each)"),
        array_bytes(&[n, 2], std::mem::size_of::<f64>()),
    )?;
    Ok((n, dx))
}

/// A measured profile (any readable format, or a `.npy` with an import sidecar).
fn measured_line(args: &MdrArgs, path: &Path) -> Result<Indenter> {
    let size = args.size.map(|x| x.to_string());
    let t = load(path, &args.measured, size.as_deref())?;
    let line = t.to_line().with_context(|| format!("{}", path.display()))?;
    let size = line.size();
    Ok(Indenter {
        description: format!(
            "measured line {} ({} points, L = {size} m, {})",
            path.display(),
            line.len(),
            t.provenance.format
        ),
        source: json!({ "kind": "measured line", "file": record(&t) }),
        spacing: line.spacing(),
        values: line.into_heights().to_vec(),
        is_line: true,
        size,
    })
}

/// A line from a 1D `.npy`: L from `--size`, else its sidecar, else 1.
fn npy_line(args: &MdrArgs, path: &Path) -> Result<Indenter> {
    let heights = read_npy_1d(path)?.to_vec();
    let (size, size_source) = match args.size {
        Some(size) => (size, "--size"),
        None => match asperity::io::sidecar_size(path)? {
            Some(size) => (size, "sidecar"),
            None => (1.0, "default"),
        },
    };
    if !(size.is_finite() && size > 0.0) {
        bail!("invalid size: the line length must be positive and finite, got {size}");
    }
    let spacing = size / heights.len() as f64;
    Ok(Indenter {
        description: format!(
            "line {} ({} points, L = {size})",
            path.display(),
            heights.len()
        ),
        source: json!({
            "kind": "line", "file": path, "points": heights.len(), "size_source": size_source,
        }),
        values: heights,
        is_line: true,
        spacing,
        size,
    })
}

/// A user's axisymmetric profile f(r), mapped to 1D numerically.
fn radial_indenter(args: &MdrArgs, path: &Path) -> Result<Indenter> {
    let step = need(args.radial_step, "--radial-step", "--radial")?;
    let samples = read_npy_1d(path)?;
    let profile = RadialProfile::new(samples.as_slice().expect("contiguous"), step)?;
    let (n, dx) = spring_grid(args, "--radial")?;
    let description = format!(
        "radial profile {} ({} samples, Δr = {step}), n = {n}, Δx = {dx}",
        path.display(),
        samples.len()
    );
    let source = json!({
        "kind": "radial profile", "file": path, "samples": samples.len(), "radial_step": step,
    });
    Ok(axisymmetric(
        args,
        profile.sample(n, dx)?,
        dx,
        description,
        source,
    ))
}

/// An axisymmetric indenter mapped to `values` on springs `dx` apart (L: `--size`, else
/// the grid's n·Δx).
fn axisymmetric(
    args: &MdrArgs,
    values: Vec<f64>,
    dx: f64,
    description: String,
    source: serde_json::Value,
) -> Indenter {
    Indenter {
        size: args.size.unwrap_or(values.len() as f64 * dx),
        values,
        is_line: false,
        spacing: dx,
        description,
        source,
    }
}

/// A closed-form axisymmetric indenter (`--profile`).
fn closed_form_indenter(args: &MdrArgs, kind: ProfileKind) -> Result<Indenter> {
    let shape = match kind {
        ProfileKind::Hertz => Axisymmetric::Sphere {
            radius: need(args.radius, "--radius", "--profile hertz")?,
        },
        ProfileKind::Punch => Axisymmetric::FlatPunch {
            radius: need(args.radius, "--radius", "--profile punch")?,
        },
        ProfileKind::Cone => Axisymmetric::Cone {
            slope: need(args.slope, "--slope", "--profile cone")?,
        },
        ProfileKind::Power => Axisymmetric::PowerLaw {
            coefficient: need(args.coefficient, "--coefficient", "--profile power")?,
            exponent: need(args.exponent, "--exponent", "--profile power")?,
        },
    };
    shape.validate()?;
    let (n, dx) = spring_grid(args, "--profile")?;
    let description = format!("{shape}, n = {n}, Δx = {dx}");
    let source = json!({ "kind": "profile", "shape": shape });
    Ok(axisymmetric(
        args,
        shape.sample(n, dx)?,
        dx,
        description,
        source,
    ))
}

fn load_indenter(args: &MdrArgs) -> Result<Indenter> {
    if let Some(path) = &args.line {
        return if !is_npy(path) || has_import_sidecar(path) {
            measured_line(args, path)
        } else {
            npy_line(args, path)
        };
    }
    if let Some(path) = &args.radial {
        return radial_indenter(args, path);
    }
    match args.profile {
        Some(kind) => closed_form_indenter(args, kind),
        None => bail!(
            "give an indenter: --line FILE.npy, --profile hertz|cone|punch|power or --radial FILE.npy"
        ),
    }
}

fn spring_law(args: &MdrArgs, indenter: &Indenter) -> Result<SpringLaw> {
    Ok(match args.spring {
        SpringKind::Linear => SpringLaw::Linear,
        SpringKind::Hertz => {
            let radius = match (args.asperity_radius, args.profile) {
                (Some(r), _) => r,
                (None, Some(ProfileKind::Hertz)) => {
                    need(args.radius, "--radius", "--profile hertz")?
                }
                _ => bail!("the hertz spring law (15.2) needs --asperity-radius"),
            };
            SpringLaw::Hertz { radius }
        }
        SpringKind::Fractal => {
            let hurst = args
                .hurst
                .context("the fractal spring law (15.7) needs --hurst")?;
            let rms = match (args.rms_height, indenter.is_line) {
                (Some(h), _) => h,
                (None, true) => rms_height(indenter.values.iter().copied()),
                (None, false) => {
                    bail!("the fractal spring law (15.7) on a profile needs --rms-height")
                }
            };
            SpringLaw::Fractal {
                hurst,
                rms_height: rms,
                size: indenter.size,
            }
        }
    })
}

fn indentation_levels(args: &MdrArgs, foundation: &Foundation) -> Result<Vec<f64>> {
    if let Some(list) = &args.indentations {
        if let Some(bad) = list.iter().find(|d| !d.is_finite() || **d < 0.0) {
            bail!("invalid indentations: each must be finite and >= 0, got {bad}");
        }
        return Ok(list.clone());
    }
    let count = args.nloads.unwrap_or(50);
    ensure_rows_fit(
        count,
        std::mem::size_of::<f64>() + plot_row_bytes(args),
        "--nloads",
    )?;
    let dmax = match args.dmax {
        Some(d) => d,
        None => {
            let full = foundation.full_contact_indentation();
            if full <= 0.0 {
                bail!(
                    "every spring touches at the first contact (all gaps are equal, e.g. a \
                     flat punch, or a profile sampled by one or two springs), so there is no \
                     range of indentations to sweep: give --dmax, or --indentations"
                );
            }
            full
        }
    };
    let dmin = args.dmin.unwrap_or(dmax * 1e-6);
    log_spaced(dmin, dmax, count).map_err(|e| anyhow::anyhow!("--dmin/--dmax/--nloads: {e}"))
}

/// Extra bytes per output row with --plot: the kept curve point and its two plotted
/// `(x, y)` pairs.
fn plot_row_bytes(args: &MdrArgs) -> usize {
    if args.plot.is_some() {
        std::mem::size_of::<CurvePoint>() + 2 * std::mem::size_of::<(f64, f64)>()
    } else {
        0
    }
}

/// The `--plot` panels: F/E* vs d and k/E* vs F/E*, log–log (points at zero left out).
fn curve_charts(points: &[CurvePoint], modulus: f64, description: &str, law: &str) -> [Chart; 2] {
    // Markers for a readable number of points; a line alone for dense curves (breakpoints),
    // thinned to what a figure shows.
    let style = if points.len() <= 200 {
        Style::LinePoints
    } else {
        Style::Line
    };
    let force = |p: &CurvePoint| p.force / modulus;
    let title = format!("{description}, {law} springs");
    let force_chart = Chart {
        title: title.clone(),
        x_label: "indentation d  [length]".into(),
        y_label: "normal force F / E*  [length²]".into(),
        log_x: true,
        log_y: true,
        series: vec![Series::new(
            "",
            thin_log(points.iter().map(|p| (p.indentation, force(p))), 4000),
            style,
        )],
    };
    let stiffness_chart = Chart {
        title: format!("E* = {modulus}"),
        x_label: "normal force F / E*  [length²]".into(),
        y_label: "contact stiffness k / E*  [length]".into(),
        log_x: true,
        log_y: true,
        series: vec![Series::new(
            "",
            thin_log(
                points.iter().map(|p| (force(p), p.stiffness / modulus)),
                4000,
            ),
            style,
        )],
    };
    [force_chart, stiffness_chart]
}

/// Step 1: `--plot` needs a curve (at least 2 indentations); checked before any work.
fn check_plot(args: &MdrArgs) -> Result<()> {
    let Some(plot) = &args.plot else {
        return Ok(());
    };
    ImageFormat::from_path(plot, "--plot")?;
    let count = match (&args.indentations, args.nloads) {
        (Some(list), _) => list.len(),
        (None, Some(n)) if !args.breakpoints => n,
        _ => 2,
    };
    if count < 2 {
        bail!("--plot needs at least 2 indentations (a curve), got {count}");
    }
    Ok(())
}

/// Step 2: the curve, one point at a time (`emit`): the exact breakpoints of linear springs
/// on a line, or the foundation at every indentation asked for. Returns the indentations
/// as evaluated (none for the breakpoints), for the record.
fn compute(
    args: &MdrArgs,
    indenter: &Indenter,
    spring: Spring,
    emit: &mut dyn FnMut(CurvePoint),
) -> Result<Option<Vec<f64>>> {
    if args.breakpoints {
        if !(spring.is_linear() && indenter.is_line) {
            bail!(
                "--breakpoints needs --line with linear springs (the exact piecewise-linear curve)"
            );
        }
        // One row per spring, besides the curve's breakpoints and forces (two f64 each).
        ensure_rows_fit(
            indenter.values.len(),
            2 * std::mem::size_of::<f64>() + plot_row_bytes(args),
            "--breakpoints",
        )?;
        let curve = LinearCurve::from_heights(&indenter.values, spring.spacing(), args.modulus)?;
        (1..=curve.len()).for_each(|j| emit(curve.breakpoint(j)));
        return Ok(None);
    }
    let foundation = if indenter.is_line {
        Foundation::from_heights(&indenter.values, spring)?
    } else {
        Foundation::from_profile(&indenter.values, spring)?
    };
    let levels = indentation_levels(args, &foundation)?;
    levels.iter().for_each(|&d| emit(foundation.evaluate(d)));
    Ok(Some(levels))
}

/// The inputs of a run, for OUT.csv.json (the same style as `asperity bem`'s record).
fn record_of(
    args: &MdrArgs,
    indenter: &Indenter,
    law: SpringLaw,
    levels: Option<&[f64]>,
) -> serde_json::Value {
    let indentations = match (levels, &args.indentations) {
        (None, _) => json!({ "breakpoints": true }),
        (Some(values), Some(_)) => json!({ "values": values }),
        (Some(values), None) => json!({
            "count": values.len(), "min": values.first(), "max": values.last(),
            "spacing": "logarithmic", "values": values,
        }),
    };
    json!({
        "command": "asperity mdr",
        "version": env!("CARGO_PKG_VERSION"),
        "indenter": indenter.source,
        "springs": indenter.values.len(),
        "spacing": indenter.spacing,
        "size": indenter.size,
        "modulus": args.modulus,
        "spring_law": law,
        "indentations": indentations,
        "columns": COLUMNS,
    })
}

/// The CSV columns.
const COLUMNS: [&str; 4] = ["indentation", "force", "stiffness", "contacts"];

/// Runs `asperity mdr`: check, compute, then write every output together.
pub fn run(args: &MdrArgs) -> Result<()> {
    // Every output is checked before any work, and all are written together at the end.
    check_plot(args)?;
    let record_path = args.out.as_deref().map(sidecar_path);
    let outputs = args.out.iter().chain(&record_path).chain(&args.plot);
    let mut staged = StagedOutputs::new(outputs, args.force)?;
    for input in args.line.iter().chain(&args.radial) {
        staged.ensure_not_input(input)?;
    }
    let indenter = load_indenter(args)?;
    let law = spring_law(args, &indenter)?;
    let spring = Spring::new(law, indenter.spacing, args.modulus)?;
    let mut table = Table::new(&COLUMNS);
    let mut plotted: Option<Vec<CurvePoint>> = args.plot.as_ref().map(|_| Vec::new());
    let levels = compute(args, &indenter, spring, &mut |p| {
        table.push(&[
            format_number(p.indentation),
            format_number(p.force),
            format_number(p.stiffness),
            p.contacts.to_string(),
        ]);
        if let Some(points) = plotted.as_mut() {
            points.push(p);
        }
    })?;
    if let (Some(plot), Some(points)) = (&args.plot, &plotted) {
        let charts = curve_charts(points, args.modulus, &indenter.description, law.name());
        stage_charts(&mut staged, plot, &charts)
            .with_context(|| format!("writing {}", plot.display()))?;
    }
    if let (Some(out), Some(record_path)) = (&args.out, &record_path) {
        table
            .stage(&mut staged, out)
            .with_context(|| format!("writing {}", out.display()))?;
        staged
            .write_json(
                record_path,
                &record_of(args, &indenter, law, levels.as_deref()),
            )
            .with_context(|| format!("writing {}", record_path.display()))?;
    }
    staged.commit()?;
    if let Some(plot) = &args.plot {
        eprintln!("wrote {}", plot.display());
    }
    match &args.out {
        Some(out) => eprintln!(
            "wrote {} and {} ({} rows): {}, {} springs (u0 = {:.4e})",
            out.display(),
            sidecar_path(out).display(),
            table.len(),
            indenter.description,
            law.name(),
            spring.critical_depth()
        ),
        None => match std::io::stdout().write_all(&table.to_csv()?) {
            // A closed pipe (`| head`) is not an error of ours.
            Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => {}
            other => other?,
        },
    }
    Ok(())
}
