//! `asperity`: the command-line front end as a library. Parsing and error reporting only;
//! the work is in `commands::*` and the `asperity` library. [`main_with_args`] runs one
//! command line and returns its exit status: the `asperity` binary (`src/main.rs`) calls
//! it with the process's arguments, and the Python package's `asperity` command calls it
//! from its extension module, so that one Rust build serves both.

mod cli;
mod commands;
#[cfg(feature = "mpi")]
mod distributed;
mod estimate;
mod interrupt;
mod output;
mod plot;
mod progress;
mod request;
mod rerun;
mod studies;

use std::ffi::OsString;

use clap::Parser;

/// Runs the command line `args` (the program's name first, as `std::env::args_os`
/// gives it) and returns the exit status, with standard output and error flushed. Under
/// MPI (the `mpi` feature), rank 0 runs the command and the other ranks compute samples
/// for its studies (see `distributed`).
pub fn main_with_args(args: Vec<OsString>) -> i32 {
    #[cfg(feature = "mpi")]
    let code = distributed::main(|| run(&args));
    #[cfg(not(feature = "mpi"))]
    let code = run(&args);
    use std::io::Write;
    let _ = std::io::stdout().flush();
    let _ = std::io::stderr().flush();
    code
}

/// Parses the command line and runs it; returns the exit status.
fn run(args: &[OsString]) -> i32 {
    if let Some(message) = non_utf8_argument(args) {
        eprintln!("error: {message}");
        return 2;
    }
    stdout_errors_exit();
    let cli = match cli::Cli::try_parse_from(args) {
        Ok(cli) => cli,
        // --help, --version; and `asperity` or `asperity study` alone: the help (on
        // stderr, status 2) says what to give.
        Err(err)
            if !err.use_stderr()
                || err.kind()
                    == clap::error::ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand =>
        {
            let _ = err.print();
            return err.exit_code();
        }
        Err(err) => {
            eprintln!("error: {} (see --help)", one_line(&err.to_string()));
            return 2;
        }
    };
    // Room for the threads first: a thread whose stack was mapped but whose signal stack
    // then finds no address space aborts the process (issue 33, item 11).
    let threads = match threads_that_fit() {
        Ok(threads) => threads,
        Err(message) => {
            eprintln!("error: {message}");
            return 2;
        }
    };
    // Ctrl-C, SIGTERM or SIGHUP: unfinished outputs are removed, status 130.
    interrupt::install();
    // The command runs on a thread of a rayon pool, so that its parallel loops (FFT
    // passes, the solvers' chunked passes, a study's lanes) run there directly: called from
    // the main thread, every one of them would be handed to the pool and waited for (two
    // thread switches per loop; measured: a one-thread BEM study ran 3.9× slower than on
    // two threads).
    let pool = match worker_pool(threads) {
        Ok(pool) => pool,
        Err(message) => {
            eprintln!("error: {message}");
            return 2;
        }
    };
    if let Err(err) = pool.install(|| commands::run(cli)) {
        eprintln!("error: {}", in_one_line(&err));
        return 2;
    }
    0
}

/// An error in one line: the chain of causes joined, as a user reads it; a cause that its
/// parent's message already ends with (library errors print their source) is skipped.
fn in_one_line(err: &anyhow::Error) -> String {
    let mut line = String::new();
    for cause in err.chain().map(in_cli_words) {
        if line.is_empty() {
            line = cause;
        } else if !line.ends_with(&cause) {
            line = format!("{line}: {cause}");
        }
    }
    shorten_numbers(&asperity::input::one_line(&line))
}

/// The pool the command runs on: one worker per core (or `RAYON_NUM_THREADS`). Where its
/// threads cannot all start (an address-space limit, `ulimit -v`, leaves no room for their
/// stacks) the command runs on one thread, with a warning, instead of panicking in rayon's
/// global pool (issue 33, item 11); if even that fails, a one-line error. Under such a
/// limit the C allocator shares one arena between threads first (`asperity::memory`).
fn worker_pool(threads: Option<usize>) -> Result<rayon::ThreadPool, String> {
    let named = |i: usize| format!("asperity-{i}");
    let mut builder = rayon::ThreadPoolBuilder::new().thread_name(named);
    if let Some(threads) = threads {
        builder = builder.num_threads(threads);
    }
    match builder.build() {
        Ok(pool) => Ok(pool),
        Err(first) => {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(1)
                .thread_name(named)
                .build()
                .map_err(|e| {
                    format!("cannot start a worker thread: {e} (is ulimit -v too low?)")
                })?;
            eprintln!(
                "warning: running on 1 thread: the worker threads could not all start ({first}; \
                 is ulimit -v too low?)"
            );
            Ok(pool)
        }
    }
}

/// The address space one started thread may take: its 2 MiB stack, the guard page, its
/// signal stack and thread-local storage, with room to spare.
const THREAD_SPACE: u64 = 4 << 20;

/// How many workers an address-space limit (`ulimit -v`) leaves room for, where that is
/// fewer than the pool would start (`RAYON_NUM_THREADS`, else one per core): `None` for no
/// cap (the pool then runs on fewer threads silently: a refusal that follows must stay one
/// line). Every thread the command starts (the interrupt handler's and the workers) is
/// counted before any starts, so none can find the address space spent by the others while
/// it starts (a `ulimit -v` run aborted so: "failed to allocate an alternative stack").
/// Too little room for even one worker is refused in one line. Call before any thread.
fn threads_that_fit() -> Result<Option<usize>, String> {
    asperity::memory::fit_allocator_to_address_space_limit();
    let Some(available) = asperity::memory::address_space_headroom() else {
        return Ok(None);
    };
    // The interrupt handler's thread and at least one worker.
    let room = (available / THREAD_SPACE).saturating_sub(1) as usize;
    if room == 0 {
        return Err(format!(
            "only {} MiB of address space are free: too little to start (is ulimit -v too low?)",
            available >> 20
        ));
    }
    let wanted = std::env::var("RAYON_NUM_THREADS")
        .ok()
        .and_then(|n| n.parse::<usize>().ok())
        .filter(|&n| n > 0)
        .or_else(|| std::thread::available_parallelism().ok().map(|n| n.get()))
        .unwrap_or(1);
    Ok((wanted > room).then_some(room))
}

/// A refusal of the first argument that is not UTF-8 (a file name in another encoding):
/// every command records its inputs and outputs in JSON, which holds UTF-8 text only, so
/// such a name is refused up front rather than half-way (it made them panic).
fn non_utf8_argument(args: &[OsString]) -> Option<String> {
    let bad = args.iter().skip(1).find(|a| a.to_str().is_none())?;
    Some(format!(
        "argument {} is not UTF-8 text: asperity records its files' names in JSON (UTF-8); \
         rename the file or folder",
        bad.to_string_lossy()
    ))
}

/// Makes a failed write to standard output end the process the way a command-line tool
/// should instead of with a panic (Rust's `println!` panics when the write fails): a
/// closed pipe (`asperity stats s.npy | head -1`) ends it quietly with status 141 (as
/// SIGPIPE would), any other failure (`> /dev/full`) with one line and status 2. Other
/// panics keep the default report.
fn stdout_errors_exit() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let payload = info.payload();
        let text = (payload.downcast_ref::<String>().map(String::as_str))
            .or_else(|| payload.downcast_ref::<&str>().copied())
            .unwrap_or("");
        let Some(reason) = text.strip_prefix("failed printing to stdout: ") else {
            return default(info);
        };
        if reason.contains("os error 32") {
            std::process::exit(141);
        }
        eprintln!("error: writing to standard output: {reason}");
        std::process::exit(2);
    }));
}

/// One cause of an error as the CLI says it. The library names its parameters and
/// arguments (`rms_height`, `force`); the CLI names the flags that set them (`rms-height`,
/// `--force`, `--out`). Other causes are kept as they are.
fn in_cli_words(cause: &(dyn std::error::Error + 'static)) -> String {
    use asperity::bem::SolveError;
    if let Some(error) = cause.downcast_ref::<asperity::Error>() {
        return library_error(error);
    }
    match cause.downcast_ref::<SolveError>() {
        Some(SolveError::Input(error)) => library_error(error),
        _ => cause.to_string(),
    }
}

/// The CLI flag (without `--`) of a library parameter whose name differs from it.
fn flag(parameter: &str) -> &str {
    const FLAGS: [(&str, &str); 5] = [
        ("rms_height", "rms-height"),
        ("tangential_force", "tangential-force"),
        ("rms_slope", "rms-slope"),
        ("radial_step", "radial-step"),
        ("short_cutoff", "short-cutoff"),
    ];
    FLAGS
        .iter()
        .find(|(name, _)| *name == parameter)
        .map_or(parameter, |(_, flag)| flag)
}

fn library_error(error: &asperity::Error) -> String {
    use asperity::Error as E;
    match error {
        E::InvalidParameter { name, reason } => format!("invalid {}: {reason}", flag(name)),
        E::OutputExists(path) => format!(
            "{}: output already exists (use --force to overwrite)",
            path.display()
        ),
        E::ForeignCheckpoint { dir, reason } => format!(
            "{}: holds the checkpoint of another study ({reason}); use another --out, or \
             --force to discard it",
            dir.display()
        ),
        E::NarrowerStudy { dir, reason } => format!(
            "{}: holds results this run would leave out: {reason}; include them (the \
             folder's study grows, its checkpoints are reused), use another --out, or \
             --force to leave them out (their checkpoints are kept)",
            dir.display()
        ),
        E::DamagedStudy { path, reason } => format!(
            "{}: {reason}, or use --force to discard the folder's checkpoints",
            path.display()
        ),
        E::Solve { context, source } => {
            let source: &(dyn std::error::Error + 'static) = source.as_ref();
            format!("{context}: {}", in_cli_words(source))
        }
        other => other.to_string(),
    }
}

/// Numbers of more than 20 characters (Rust prints `1e-300` as 300 digits) in short
/// scientific form; everything else as it is.
fn shorten_numbers(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(start) = rest.find(|c: char| c.is_ascii_digit()) {
        let tail = &rest[start..];
        let len = tail
            .find(|c: char| !(c.is_ascii_digit() || c == '.'))
            .unwrap_or(tail.len());
        let number = tail[..len].trim_end_matches('.');
        out.push_str(&rest[..start]);
        match number.parse::<f64>() {
            Ok(v) if number.len() > 20 => out.push_str(&asperity::input::short_number(v)),
            _ => out.push_str(number),
        }
        rest = &tail[number.len()..];
    }
    out.push_str(rest);
    out
}

/// clap's message in one line. It is several lines (tip, usage); the first is kept, as for
/// every error, but when it ends with ':' (e.g. "the following required arguments were not
/// provided:") the indented lines that follow, up to the first blank line, are what it
/// announces (the missing arguments' names), so they are appended, trimmed and joined
/// with ", ".
fn one_line(text: &str) -> String {
    let mut lines = text.lines();
    let first = lines
        .next()
        .unwrap_or("invalid arguments")
        .trim_start_matches("error: ")
        .trim_end();
    if !first.ends_with(':') {
        return first.to_string();
    }
    let items: Vec<&str> = lines
        .take_while(|l| !l.trim().is_empty())
        .take_while(|l| l.starts_with([' ', '\t']))
        .map(str::trim)
        .collect();
    if items.is_empty() {
        first.trim_end_matches(':').to_string()
    } else {
        format!("{first} {}", items.join(", "))
    }
}

#[cfg(test)]
mod tests {
    use super::one_line;

    #[test]
    fn library_errors_are_said_with_the_cli_flags() {
        use asperity::Error;
        use std::path::PathBuf;
        let cases = [
            (
                Error::invalid("rms_height", "must be positive"),
                "invalid rms_height: must be positive",
                "invalid rms-height: must be positive",
            ),
            (
                Error::OutputExists(PathBuf::from("a.csv")),
                "a.csv: output already exists (allow overwriting to replace it)",
                "a.csv: output already exists (use --force to overwrite)",
            ),
            (
                Error::ForeignCheckpoint {
                    dir: PathBuf::from("st"),
                    reason: "seed 1 vs 2".into(),
                },
                "st: holds the checkpoint of another study (seed 1 vs 2); use another \
                 folder, or discard it (force)",
                "st: holds the checkpoint of another study (seed 1 vs 2); use another --out, \
                 or --force to discard it",
            ),
            (
                Error::DamagedStudy {
                    path: PathBuf::from("st/study.json"),
                    reason: "corrupt study file (eof); restore it".into(),
                },
                "st/study.json: corrupt study file (eof); restore it, or discard the \
                 folder's checkpoints (force)",
                "st/study.json: corrupt study file (eof); restore it, or use --force to \
                 discard the folder's checkpoints",
            ),
        ];
        for (error, library, cli) in cases {
            assert_eq!(error.to_string(), library);
            assert!(!library.contains("--"), "{library}");
            assert_eq!(super::library_error(&error), cli);
        }
        // Names that are no flag stay as they are.
        let env = Error::invalid("ASPERITY_MEMORY_LIMIT_MIB", "x");
        assert_eq!(
            super::library_error(&env),
            "invalid ASPERITY_MEMORY_LIMIT_MIB: x"
        );
        // Inside a solver error, and inside a study sample's error.
        let solve = asperity::bem::SolveError::from(Error::invalid("radial_step", "x"));
        assert_eq!(super::in_cli_words(&solve), "invalid radial-step: x");
        let sample = Error::Solve {
            context: "seed 3".into(),
            source: Box::new(solve),
        };
        assert_eq!(
            super::in_cli_words(&sample),
            "seed 3: invalid radial-step: x"
        );
    }

    #[test]
    fn missing_arguments_are_named() {
        let text = "error: the following required arguments were not provided:\n  \
                    --radial-step <DR>\n  --out <FILE>\n\nUsage: asperity mdr --radial <FILE.npy>\n\n\
                    For more information, try '--help'.\n";
        assert_eq!(
            one_line(text),
            "the following required arguments were not provided: --radial-step <DR>, --out <FILE>"
        );
    }

    #[test]
    fn long_numbers_are_shortened() {
        let tiny = format!("H = {} is outside [-1, 3]", 1e-300f64);
        assert!(tiny.len() > 300);
        assert_eq!(
            super::shorten_numbers(&tiny),
            "H = 1e-300 is outside [-1, 3]"
        );
        let huge = format!("got {} and -{}", 1e300f64, 4.5e25f64);
        assert_eq!(super::shorten_numbers(&huge), "got 1e300 and -4.5e25");
        let plain = "a/b1.npy: needs 32000000000000 bytes, v0.1.0";
        assert_eq!(super::shorten_numbers(plain), plain);
    }

    #[test]
    fn other_messages_keep_their_first_line() {
        let text = "error: unexpected argument '--x' found\n\n  tip: to pass '--x' as a value, \
                    use '-- --x'\n\nUsage: asperity mdr [OPTIONS]\n";
        assert_eq!(one_line(text), "unexpected argument '--x' found");
        assert_eq!(one_line(""), "invalid arguments");
        assert_eq!(one_line("error: a list:\n\nUsage: x\n"), "a list");
    }
}
