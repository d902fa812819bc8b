//! Command-line front end. Each subcommand lives in its own module with its
//! `Args` and a `run` that returns `anyhow::Result<()>`; errors print as one
//! line on stderr and exit with status 2 for bad input (clap's errors and
//! [`topple::validate`]'s, refused before any work starts), 1 otherwise.

use clap::{Parser, Subcommand};

mod bench;
mod chain;
mod impact;
mod paper;
mod plot;
mod resume;
mod scene;
mod stress;
mod theory;

#[derive(Parser)]
#[command(
    name = "topple",
    version,
    about = "LZB multiple impacts for dominoes, Rapier and Bevy"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

// Parsed once per run: the size of the largest variant does not matter.
#[allow(clippy::large_enum_variant)]
#[derive(Subcommand)]
enum Command {
    /// Resolve one multiple impact given as JSON (FILE, or - for stdin).
    #[command(allow_negative_numbers = true)]
    Impact(impact::Args),
    /// Run a TOML scene in Rapier, with topple's impacts or natively.
    #[command(allow_negative_numbers = true)]
    Scene(scene::Args),
    /// Natural speed of the domino wave by the cooperative, extended and single collision models.
    #[command(allow_negative_numbers = true)]
    Theory(theory::Args),
    /// Simulate a row of dominoes (the paper's model) and report the wave.
    #[command(allow_negative_numbers = true)]
    Chain(chain::Args),
    /// Regenerate the paper's Figs. 3–10 (CSV + SVG) with the reference engine.
    #[command(allow_negative_numbers = true)]
    Paper(paper::Args),
    /// Run time against accuracy of one row over engines and settings (a table).
    #[command(allow_negative_numbers = true)]
    Bench(bench::Args),
    /// Seeded sweep over engines and parameters, invariants checked (a table; non-zero exit on a violation).
    Stress(stress::Args),
}

/// A bar on stderr counting the blocks the wave has hit; indicatif draws it
/// only when stderr is a terminal, so pipes and captured output stay clean.
fn blocks_bar(n: usize, label: &str) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(n as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{prefix} {bar:40} {pos}/{len} blocks hit, {elapsed} elapsed, eta {eta}",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    bar.set_prefix(label.to_string());
    bar
}

/// Parses the command line, runs the subcommand, returns the exit status.
pub fn run() -> i32 {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Impact(args) => impact::run(args),
        Command::Scene(args) => scene::run(args),
        Command::Theory(args) => theory::run(args),
        Command::Chain(args) => chain::run(args),
        Command::Paper(args) => paper::run_cmd(args),
        Command::Bench(args) => bench::run(args),
        Command::Stress(args) => stress::run(args),
    };
    match result {
        Ok(()) => 0,
        Err(err) => {
            // One line: the error and its causes joined by ": ".
            let line = format!("{err:#}").replace('\n', " ");
            eprintln!("error: {line}");
            let bad_input = err.chain().any(|e| {
                e.is::<topple::validate::InputError>() || e.is::<topple::validate::SyntaxError>()
            });
            if bad_input {
                2
            } else {
                1
            }
        }
    }
}
