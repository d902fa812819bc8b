//! The `topple` command: runs the resolver, the theory, the reference engine,
//! the Rapier plugin and the benchmarks from scripts.

mod cli;

fn main() {
    // Die quietly on a closed pipe (`topple chain … | head`) as Unix tools do,
    // instead of Rust's default of ignoring SIGPIPE and panicking in println!.
    #[cfg(unix)]
    // SAFETY: restores the default disposition before any thread starts.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    std::process::exit(cli::run());
}
