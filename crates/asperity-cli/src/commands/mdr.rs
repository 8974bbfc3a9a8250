//! `asperity mdr`: force, stiffness and contacts of a rough line or an axisymmetric
//! indenter on the MDR spring foundation (linear, Hertz 15.2 or fractal 15.7 springs).

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use asperity::io::{read_npy_1d, sidecar_path, StagedOutputs};
use serde_json::json;

use super::measured::{has_import_sidecar, is_npy, load, record, MeasuredArgs};
use asperity::mdr::{CurvePoint, Spring, SpringLaw};
use asperity_app::mdr::{Indenter, MdrRequest, COLUMNS};

use crate::request::refused;

use crate::output::{format_number, Table};
use crate::plot::{stage_charts, thin_log, Chart, ImageFormat, Series, Style};

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
    #[arg(long, value_name = "FILE")]
    pub line: Option<PathBuf>,
    #[command(flatten)]
    pub measured: MeasuredArgs,
    /// A closed-form axisymmetric indenter, mapped to 1D by the MDR transform: hertz (a
    /// sphere of radius --radius: g = x²/R, book eq. 15.1), cone (flank slope --slope,
    /// tan θ: g = (π/2) tan θ |x|), punch (a flat cylindrical punch of radius --radius) or
    /// power (f = c rⁿ, --coefficient, --exponent: g = κ(n) c |x|ⁿ).
    #[arg(long, value_name = "hertz|cone|punch|power")]
    pub profile: Option<String>,
    /// A user's axisymmetric profile f(r) sampled at r = 0, DR, 2DR, … (1D .npy), mapped to
    /// 1D numerically.
    #[arg(long, value_name = "FILE.npy")]
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
    #[arg(long)]
    pub n: Option<usize>,
    /// Spring spacing Δx for --profile / --radial (a line's is size / n).
    #[arg(long, allow_hyphen_values = true)]
    pub dx: Option<f64>,
    /// Line length L (--line: default the sidecar's, else 1; fractal law with a profile:
    /// default n·Δx).
    #[arg(long, allow_hyphen_values = true)]
    pub size: Option<f64>,
    /// Effective modulus E*.
    #[arg(long, default_value_t = 1.0, allow_hyphen_values = true)]
    pub modulus: f64,
    /// Spring law: linear (stiffness E*·Δx), hertz (the microscale law 15.2; radius from
    /// --asperity-radius, or --radius with --profile hertz) or fractal (15.7, with the
    /// critical depth 15.6; needs --hurst).
    #[arg(long, default_value = "linear")]
    pub spring: String,
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
    #[arg(long, value_delimiter = ',', num_args = 1.., allow_negative_numbers = true)]
    pub indentations: Option<Vec<f64>>,
    /// Number of log-spaced indentations from --dmin to --dmax (default 50).
    #[arg(long)]
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

/// Estimated bytes of one output row while the table is built and written: the row's
/// `Vec` of 4 `String`s (24 + 4·24 bytes), their text (up to 24 characters each, 32 bytes as
/// allocated) and its share of the CSV text (about 4·24 characters).
const ROW_BYTES: usize = 24 + 4 * 24 + 4 * 32 + 4 * 24;

/// The request of the arguments (the line or radial samples themselves are read apart).
fn request(args: &MdrArgs) -> MdrRequest {
    MdrRequest {
        line: args.line.is_some(),
        profile: args.profile.clone(),
        radial: args.radial.is_some(),
        radial_step: args.radial_step,
        radius: args.radius,
        slope: args.slope,
        coefficient: args.coefficient,
        exponent: args.exponent,
        n: args.n,
        dx: args.dx,
        size: args.size,
        modulus: args.modulus,
        spring: args.spring.clone(),
        hurst: args.hurst,
        rms_height: args.rms_height,
        asperity_radius: args.asperity_radius,
        indentations: args.indentations.clone(),
        nloads: args.nloads,
        dmin: args.dmin,
        dmax: args.dmax,
        breakpoints: args.breakpoints,
    }
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
    let mut line = Indenter::line(heights, size, &path.display().to_string())?;
    line.source = json!({
        "kind": "line", "file": path, "points": line.values.len(), "size_source": size_source,
    });
    Ok(line)
}

/// The indenter of the request: a line or radial samples read from their file, or a
/// closed form.
fn load_indenter(args: &MdrArgs, request: &MdrRequest) -> Result<Indenter> {
    if let Some(path) = &args.line {
        return if !is_npy(path) || has_import_sidecar(path) {
            measured_line(args, path)
        } else {
            npy_line(args, path)
        };
    }
    if let Some(path) = &args.radial {
        let samples = read_npy_1d(path)?;
        let samples = samples.as_slice().expect("contiguous");
        let mut radial = request
            .radial(samples, &path.display().to_string())
            .map_err(refused)?;
        radial.source["file"] = json!(path);
        return Ok(radial);
    }
    request.closed_form().map_err(refused)
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

/// Runs `asperity mdr`: check, compute, then write every output together.
pub fn run(args: &MdrArgs) -> Result<()> {
    // Every output is checked before any work, and all are written together at the end.
    let request = request(args);
    request.check()?;
    check_plot(args)?;
    let record_path = args.out.as_deref().map(sidecar_path);
    let outputs = args.out.iter().chain(&record_path).chain(&args.plot);
    let mut staged = StagedOutputs::new(outputs, args.force)?;
    for input in args.line.iter().chain(&args.radial) {
        staged.ensure_not_input(input)?;
    }
    let indenter = load_indenter(args, &request)?;
    let law = request.spring_law(&indenter)?;
    let spring = Spring::new(law, indenter.spacing, args.modulus)?;
    let mut table = Table::new(&COLUMNS);
    let mut plotted: Option<Vec<CurvePoint>> = args.plot.as_ref().map(|_| Vec::new());
    let row_bytes = ROW_BYTES + plot_row_bytes(args);
    let levels = request.compute(&indenter, spring, row_bytes, &mut |p| {
        table.push(&[
            format_number(p.indentation),
            format_number(p.force),
            format_number(p.stiffness),
            p.contacts.to_string(),
        ]);
        if let Some(points) = plotted.as_mut() {
            points.push(p);
        }
    });
    let levels = levels.map_err(refused)?;
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
