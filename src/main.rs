//! The `topple` command: runs the resolver, the theory, the reference engine,
//! the Rapier plugin and the benchmarks from scripts.

mod cli;

fn main() {
    std::process::exit(cli::run());
}
