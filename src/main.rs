//! `toposmooth`: the command line, parsed and run by the library ([`toposmooth::commands::cli`]).

/// Running out of memory ends the tool with a message and exit 3, never an abort.
#[global_allocator]
static ALLOCATOR: toposmooth::commands::alloc::Guarded = toposmooth::commands::alloc::Guarded;

fn main() {
    std::process::exit(toposmooth::commands::cli::main(std::env::args_os()));
}
