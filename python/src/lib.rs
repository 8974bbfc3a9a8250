//! `asperity._asperity`: the compiled part of the Python package `asperity`.
//!
//! A thin layer over the `asperity` library: every number comes from the same library
//! functions the command line calls, in the same order, so results are bit-identical to
//! the CLI's. The Python package (`python/asperity/__init__.py`) adds keyword-only
//! signatures, input coercion to float64 and the progress bar; this crate does the work
//! with the GIL released ([`interrupt::run_detached`]), maps the library's errors to Python
//! exceptions ([`errors`]) and hands results back as numpy arrays without copying them.

mod adhesion;
mod arrays;
mod bem;
mod contact;
mod errors;
mod fields;
mod figure;
mod interrupt;
mod mdr;
mod persson;
mod reference;
mod slip;
mod study;
mod study_windows;
mod surface;
mod topography;

use pyo3::prelude::*;

/// Large buffers on transparent huge pages, as in the `asperity` binary
/// (`asperity::huge_pages`): the module's own allocations only (numpy keeps its own).
#[global_allocator]
static ALLOCATOR: asperity::huge_pages::HugePageAlloc = asperity::huge_pages::HugePageAlloc;

/// The compiled module.
#[pymodule]
fn _asperity(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    // Under `ulimit -v`, one malloc arena for all threads (see the function's docs).
    asperity::memory::fit_allocator_to_address_space_limit();
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add(
        "ConvergenceError",
        py.get_type::<errors::ConvergenceError>(),
    )?;
    m.add(
        "BeyondFullContactError",
        py.get_type::<errors::BeyondFullContactError>(),
    )?;
    surface::register(m)?;
    bem::register(m)?;
    adhesion::register(m)?;
    contact::register(m)?;
    fields::register(m)?;
    figure::register(m)?;
    mdr::register(m)?;
    persson::register(m)?;
    reference::register(m)?;
    slip::register(m)?;
    study::register(m)?;
    study_windows::register(m)?;
    topography::register(m)?;
    m.add_function(wrap_pyfunction!(cli, m)?)?;
    m.add_function(wrap_pyfunction!(defaults, m)?)?;
    Ok(())
}

/// The defaults of the keywords that both front ends share, from the front-end layer's
/// `Default`s (the CLI's flags read the same): Python's signatures take them from here, so
/// that each default is written once.
#[pyfunction]
fn defaults(py: Python<'_>) -> PyResult<Bound<'_, pyo3::types::PyDict>> {
    let solver = asperity_app::bem::SolverRequest::default();
    let persson = asperity::persson::PerssonParams::default();
    let surface = asperity_app::surface::SurfaceRequest::default();
    let d = pyo3::types::PyDict::new(py);
    d.set_item("modulus", solver.modulus)?;
    d.set_item("boundary", solver.boundary)?;
    d.set_item("solver", solver.solver)?;
    d.set_item("tolerance", solver.tolerance)?;
    d.set_item("max_iterations", solver.max_iterations)?;
    d.set_item("fd_step", asperity_app::bem::FD_STEP)?;
    d.set_item("gamma", persson.gamma)?;
    d.set_item("kappa", persson.kappa)?;
    d.set_item("size", surface.size)?;
    let seed = asperity_app::surface::parse_seed(&surface.seed).expect("the default seed parses");
    d.set_item("seed", seed)?;
    d.set_item("window", asperity_app::stats::DEFAULT_WINDOW)?;
    d.set_item("convention", asperity_app::stats::DEFAULT_CONVENTION)?;
    Ok(d)
}

/// The `asperity` command line (the `asperity_cli` library the binary runs): runs `argv`
/// (the program's name first) with the GIL released and returns the exit status. The
/// package's `asperity` command (`asperity._cli`) calls it in a process of its own; the
/// command installs its own Ctrl-C handling there.
#[pyfunction]
fn cli(py: Python<'_>, argv: Vec<std::ffi::OsString>) -> i32 {
    py.detach(|| asperity_cli::main_with_args(argv))
}
