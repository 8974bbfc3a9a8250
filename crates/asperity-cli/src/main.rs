//! `asperity`: the command-line tool (the work is in the `asperity_cli` library).

/// Large buffers (the solvers' fields, surfaces, spectra) on transparent huge pages:
/// fewer page faults and TLB misses (`asperity::huge_pages`).
#[global_allocator]
static ALLOCATOR: asperity::huge_pages::HugePageAlloc = asperity::huge_pages::HugePageAlloc;

fn main() {
    std::process::exit(asperity_cli::main_with_args(std::env::args_os().collect()));
}
