//! `toposmooth`: the command line, parsed and run by the library ([`toposmooth::commands::cli`]).

fn main() {
    std::process::exit(toposmooth::commands::cli::main(std::env::args_os()));
}
