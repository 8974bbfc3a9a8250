//! `asperity mdr`: force, stiffness and contacts of a rough line or an axisymmetric
//! indenter on the MDR spring foundation (linear, Hertz 15.2 or fractal 15.7 springs).

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use asperity::io::{read_npy_1d, sidecar_path, StagedOutputs};
use serde_json::json;

use super::measured::{open_argument, record, MeasuredArgs};
use asperity::mdr::{CurvePoint, PullOffs, Spring, SpringLaw};
use asperity::reference::Jkr;
use asperity::topography::Heights;
use asperity_app::argument::{Arrays, Dims};
use asperity_app::mdr::{params, Branch, Indenter, MdrRequest, ADHESIVE_COLUMNS, COLUMNS};
use asperity_app::refusal::count;

use crate::request::refused;

use crate::output::{format_number, pull_off_line, Table};
use crate::plot::{stage_charts, Chart, ImageFormat};
use asperity_app::figure::adhesion::{LoopFigure, LoopPoint, LoopPullOffs};
use asperity_app::figure::mdr::{mdr_charts, MdrColumns, MdrFigure};

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
    asperity mdr --line profile.csv --detrend mean --modulus 1e9 --nloads 20 --out curve.csv\n  \
    asperity mdr --profile hertz --radius 1 --n 1001 --dx 1e-3 --work-of-adhesion 1e-3 --indentations 0.09 --out jkr.csv --plot jkr.svg\n\n\
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
    #[arg(long, allow_hyphen_values = true)]
    pub n: Option<i128>,
    /// Spring spacing Δx for --profile / --radial (a line's is size / n).
    #[arg(long, allow_hyphen_values = true)]
    pub dx: Option<f64>,
    /// Line length L (--line: default the sidecar's, else 1; fractal law with a profile:
    /// default n·Δx).
    #[arg(long, allow_hyphen_values = true)]
    pub size: Option<f64>,
    /// Effective modulus E*.
    #[arg(long, default_value_t = MdrRequest::default().modulus, allow_hyphen_values = true)]
    pub modulus: f64,
    /// Spring law: linear (stiffness E*·Δx), hertz (the microscale law 15.2; radius from
    /// --asperity-radius, or --radius with --profile hertz) or fractal (15.7, with the
    /// critical depth 15.6; needs --hurst).
    #[arg(long, default_value_t = MdrRequest::default().spring)]
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
    #[arg(long, allow_hyphen_values = true)]
    pub nloads: Option<i128>,
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
    /// Work of adhesion Δγ (energy per area, in the units of E*·length; J/m² with E* in Pa
    /// and lengths in m): springs stick once pressed and let go from the edges of each
    /// contact at the elongation √(2πaΔγ/E*) (Heß's rule; JKR for a sphere, Kendall for a
    /// punch). Linear springs only. The indentations become a load path (in their order,
    /// negative allowed), after which the indenter retracts until the last spring lets go;
    /// the retraction's exact curve is written (a row just before and after each release)
    /// with a fifth column, branch (approach|retract), and both pull-off forces (force
    /// and displacement control) go to standard error and OUT.csv.json.
    #[arg(long, value_name = "DGAMMA", allow_hyphen_values = true)]
    pub work_of_adhesion: Option<f64>,
    /// Output CSV (default: standard output). Its inputs go to OUT.csv.json beside it
    /// (indenter and where it came from, springs, E*, spring law, indentations, columns).
    #[arg(long, value_name = "OUT.csv")]
    pub out: Option<PathBuf>,
    /// Also plot the curve (needs at least 2 indentations), .png or .svg by the extension:
    /// log–log force F vs indentation d (left) and stiffness k vs F (right), with F and k
    /// divided by E* (length² and length); points at d = 0 or F = 0 are left out.
    #[arg(long, value_name = "FILE.png|FILE.svg")]
    pub plot: Option<PathBuf>,
    /// Partial slip instead of the normal curve: the tangential force amplitude Q* (same
    /// force units as F, at most μF) of a cycle at the one indentation of --indentations:
    /// loading from rest to Q*, unloading to −Q*, reloading to Q* (Ciavarella–Jäger on the
    /// springs; Cattaneo–Mindlin for a sphere). Columns: branch, tangential_displacement,
    /// tangential_force, stick_springs, and stick_radius for axisymmetric indenters.
    #[arg(long, allow_hyphen_values = true, value_name = "Q")]
    pub tangential_force: Option<f64>,
    /// Friction coefficient μ of --tangential-force.
    #[arg(long, allow_hyphen_values = true)]
    pub friction: Option<f64>,
    /// Poisson's ratio ν in [0, 0.5] of --tangential-force (both bodies, or the elastic one
    /// on a rigid one): tangential springs G*/E* = 2(1−ν)/(2−ν) times the normal ones.
    #[arg(long, allow_hyphen_values = true, default_value_t = asperity_app::slip::DEFAULT_POISSON)]
    pub poisson: f64,
    /// Points per branch of the --tangential-force cycle (default 50).
    #[arg(long, allow_hyphen_values = true)]
    pub cycle_points: Option<i128>,
    /// Overwrite existing outputs.
    #[arg(long)]
    pub force: bool,
}

/// Estimated bytes of one output row while the table is built and written: the row's
/// `Vec` of 4 `String`s (24 + 4·24 bytes), their text (up to 24 characters each, 32 bytes as
/// allocated) and its share of the CSV text (about 4·24 characters).
const ROW_BYTES: usize = 24 + 4 * 24 + 4 * 32 + 4 * 24;

/// The request of the arguments (the line or radial samples themselves are read apart).
fn request(args: &MdrArgs) -> Result<MdrRequest> {
    Ok(MdrRequest {
        line: args.line.is_some(),
        profile: args.profile.clone(),
        radial: args.radial.is_some(),
        radial_step: args.radial_step,
        radius: args.radius,
        slope: args.slope,
        coefficient: args.coefficient,
        exponent: args.exponent,
        n: args.n.map(|n| count(params::N, n)).transpose()?,
        dx: args.dx,
        size: args.size,
        modulus: args.modulus,
        spring: args.spring.clone(),
        hurst: args.hurst,
        rms_height: args.rms_height,
        asperity_radius: args.asperity_radius,
        indentations: args.indentations.clone(),
        nloads: args.nloads.map(|n| count(params::NLOADS, n)).transpose()?,
        dmin: args.dmin,
        dmax: args.dmax,
        breakpoints: args.breakpoints,
        work_of_adhesion: args.work_of_adhesion,
    })
}

/// The line of `--line` through the front-end layer's one call: a measured profile (any
/// readable format, or a `.npy` with an import sidecar), else a 1D `.npy` with L from
/// `--size`, else its sidecar, else 1.
fn line_indenter(args: &MdrArgs, path: &Path) -> Result<Indenter> {
    let no_check = |_: &[usize]| Ok(());
    let size = args.size.map(|x| [Some(x), None]);
    let input = open_argument(
        path,
        &args.measured,
        size,
        Arrays::Plain(Dims::Line, &no_check),
    )?;
    let t = input.topography;
    if !input.measured {
        let Heights::Profile(heights) = t.heights else {
            unreachable!("a plain line is 1D")
        };
        let name = path.display().to_string();
        let mut line = Indenter::line(heights.to_vec(), t.sizes[0], &name)?;
        line.source = json!({
            "kind": "line", "file": path, "points": line.values.len(),
            "size_source": input.size_source.name(),
        });
        return Ok(line);
    }
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

/// The indenter of the request: a line or radial samples read from their file, or a
/// closed form.
pub(super) fn load_indenter(args: &MdrArgs, request: &MdrRequest) -> Result<Indenter> {
    if let Some(path) = &args.line {
        return line_indenter(args, path);
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

/// Extra bytes per output row with --plot: the kept curve point, its three columns and
/// its two plotted `(x, y)` pairs.
fn plot_row_bytes(args: &MdrArgs) -> usize {
    if args.plot.is_some() {
        std::mem::size_of::<CurvePoint>()
            + 3 * std::mem::size_of::<f64>()
            + 2 * std::mem::size_of::<(f64, f64)>()
    } else {
        0
    }
}

/// The `--plot` panels ([`asperity_app::figure::mdr`]): F/E* vs d and k/E* vs F/E*,
/// log–log (points at zero left out).
fn curve_charts(points: &[CurvePoint], modulus: f64, description: &str, law: &str) -> [Chart; 2] {
    let column = |f: fn(&CurvePoint) -> f64| -> Vec<f64> { points.iter().map(f).collect() };
    let (indentation, force, stiffness) = (
        column(|p| p.indentation),
        column(|p| p.force),
        column(|p| p.stiffness),
    );
    let columns = MdrColumns {
        indentation: &indentation,
        force: &force,
        stiffness: &stiffness,
    };
    mdr_charts(
        columns,
        MdrFigure {
            description,
            law,
            modulus,
        },
    )
}

/// Step 1: `--plot` needs a curve (at least 2 indentations); checked before any work.
fn check_plot(args: &MdrArgs) -> Result<()> {
    let Some(plot) = &args.plot else {
        return Ok(());
    };
    ImageFormat::from_path(plot, "--plot")?;
    if args.work_of_adhesion.is_some() {
        // The retraction to pull-off is a curve whatever the path.
        return Ok(());
    }
    let count = match (&args.indentations, args.nloads) {
        (Some(list), _) => list.len() as i128,
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

/// A pull-off point as the record writes it.
fn point_json(p: &CurvePoint) -> serde_json::Value {
    json!({ "force": p.force, "indentation": p.indentation, "contacts": p.contacts })
}

/// The adhesion part of OUT.csv.json.
fn adhesion_record(w: f64, pull_offs: Option<&PullOffs>) -> serde_json::Value {
    json!({
        "work_of_adhesion": w,
        "rule": "Heß: springs attach when pressed; the ends of a contact of half-width a let \
                 go at the edge elongation sqrt(2π a Δγ / E*)",
        "pull_off": pull_offs.map(|p| json!({
            "force_controlled": point_json(&p.force_controlled),
            "displacement_controlled": point_json(&p.displacement_controlled),
        })),
        "columns": ADHESIVE_COLUMNS,
    })
}

/// Runs `asperity mdr`: check, compute, then write every output together.
pub fn run(args: &MdrArgs) -> Result<()> {
    // Every output is checked before any work, and all are written together at the end.
    let request = request(args)?;
    request.check()?;
    if args.tangential_force.is_some() {
        return super::mdr_slip::run(args, &request);
    }
    check_plot(args)?;
    let record_path = args.out.as_deref().map(sidecar_path);
    let outputs = args.out.iter().chain(&record_path).chain(&args.plot);
    let mut staged = StagedOutputs::new(outputs, args.force)?;
    for input in args.line.iter().chain(&args.radial) {
        staged.ensure_not_input(input)?;
    }
    let indenter = load_indenter(args, &request)?;
    if let Some(w) = args.work_of_adhesion {
        return run_adhesive(args, &request, &indenter, w, staged, record_path.as_deref());
    }
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
        None => crate::output::print_stdout(&table.to_csv()?)?,
    }
    Ok(())
}

/// The F–d panel of an adhesive loop ([`asperity_app::figure::adhesion::loop_chart`]):
/// the path and the retraction with arrows the way they were travelled, JKR's curve for a
/// sphere (dashed), the pull-offs marked.
fn loop_chart(
    points: &[(CurvePoint, Branch)],
    pull: Option<&PullOffs>,
    jkr: Option<Jkr>,
    title: &str,
) -> Chart {
    let loop_points: Vec<LoopPoint> = points
        .iter()
        .map(|(p, b)| LoopPoint {
            indentation: p.indentation,
            force: p.force,
            retract: *b == Branch::Retract,
        })
        .collect();
    let theory = jkr.map(|jkr| {
        // Contact radii up to beyond the deepest approach (a²/R − Δl ≤ a²/R), the curve
        // cut there.
        let largest = points
            .iter()
            .map(|(p, _)| p.indentation)
            .fold(0.0f64, f64::max);
        let a_top = 2.0 * (jkr.radius * largest).sqrt();
        let curve = (1..=800)
            .map(|i| a_top * i as f64 / 800.0)
            .map(|a| (jkr.approach(a), jkr.force(a)))
            .filter(|&(d, _)| d <= largest)
            .collect();
        ("JKR (equilibrium)".to_string(), curve)
    });
    let at = |q: &CurvePoint| (q.indentation, q.force);
    let pull = pull.map(|p| LoopPullOffs {
        force_controlled: at(&p.force_controlled),
        displacement_controlled: at(&p.displacement_controlled),
    });
    let figure = LoopFigure {
        title: title.into(),
        x_label: "indentation d  [length]".into(),
        y_label: "normal force F  [E*·length²]".into(),
        force_unit: String::new(),
        theory,
    };
    asperity_app::figure::adhesion::loop_chart(&loop_points, pull, figure)
}

/// `asperity mdr --work-of-adhesion`: the load path, then the retraction to pull-off.
fn run_adhesive(
    args: &MdrArgs,
    request: &MdrRequest,
    indenter: &Indenter,
    w: f64,
    mut staged: StagedOutputs,
    record_path: Option<&Path>,
) -> Result<()> {
    let mut table = Table::new(&ADHESIVE_COLUMNS);
    let mut rows: Vec<(CurvePoint, Branch)> = Vec::new();
    let row_bytes = ROW_BYTES + plot_row_bytes(args);
    let (levels, pull_offs) = request
        .compute_adhesive(indenter, row_bytes, &mut |p, branch| {
            table.push(&[
                format_number(p.indentation),
                format_number(p.force),
                format_number(p.stiffness),
                p.contacts.to_string(),
                branch.name().to_string(),
            ]);
            if args.plot.is_some() {
                rows.push((p, branch));
            }
        })
        .map_err(refused)?;
    if let Some(plot) = &args.plot {
        let title = format!("{}, Δγ = {w}, E* = {}", indenter.description, args.modulus);
        let jkr = match (request.profile.as_deref(), request.radius) {
            (Some("hertz"), Some(radius)) => Jkr::new(radius, args.modulus, w).ok(),
            _ => None,
        };
        let chart = loop_chart(&rows, pull_offs.as_ref(), jkr, &title);
        stage_charts(&mut staged, plot, &[chart])
            .with_context(|| format!("writing {}", plot.display()))?;
    }
    if let (Some(out), Some(record_path)) = (&args.out, record_path) {
        table
            .stage(&mut staged, out)
            .with_context(|| format!("writing {}", out.display()))?;
        let mut record = record_of(args, indenter, SpringLaw::Linear, Some(&levels));
        record["adhesion"] = adhesion_record(w, pull_offs.as_ref());
        record["columns"] = json!(ADHESIVE_COLUMNS);
        staged
            .write_json(record_path, &record)
            .with_context(|| format!("writing {}", record_path.display()))?;
    }
    staged.commit()?;
    match &pull_offs {
        Some(p) => eprintln!(
            "{}",
            pull_off_line(
                (p.force_controlled.force, p.force_controlled.indentation),
                (
                    p.displacement_controlled.force,
                    p.displacement_controlled.indentation
                ),
                ("", ""),
            )
        ),
        None => eprintln!("pull-off: nothing in contact at the end of the path"),
    }
    if let Some(plot) = &args.plot {
        eprintln!("wrote {}", plot.display());
    }
    match &args.out {
        Some(out) => eprintln!(
            "wrote {} ({} rows): {}",
            out.display(),
            table.len(),
            indenter.description
        ),
        None => crate::output::print_stdout(&table.to_csv()?)?,
    }
    Ok(())
}
