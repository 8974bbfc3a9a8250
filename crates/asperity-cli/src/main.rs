//! `asperity`: the command-line front end. Parsing and error reporting only; the work is
//! in `commands::*` and the `asperity` library.

mod cli;
mod commands;
#[allow(dead_code)] // shared helpers, not all used by every command yet
mod output;
#[allow(dead_code)]
mod plot;
#[allow(dead_code)]
mod progress;

use clap::Parser;

fn main() {
    let cli = match cli::Cli::try_parse() {
        Ok(cli) => cli,
        Err(err) if !err.use_stderr() => err.exit(), // --help, --version
        Err(err) => {
            // clap's message is several lines (tip, usage); keep the first, as for every error.
            let text = err.to_string();
            let first = text
                .lines()
                .next()
                .unwrap_or("invalid arguments")
                .trim_start_matches("error: ");
            eprintln!("error: {first} (see --help)");
            std::process::exit(2);
        }
    };
    if let Err(err) = commands::run(cli) {
        // One line: the chain of causes joined, as a user reads it; a cause that its
        // parent's message already ends with (library errors print their source) is skipped.
        let mut line = String::new();
        for cause in err.chain().map(|c| c.to_string()) {
            if line.is_empty() {
                line = cause;
            } else if !line.ends_with(&cause) {
                line = format!("{line}: {cause}");
            }
        }
        eprintln!("error: {line}");
        std::process::exit(2);
    }
}
