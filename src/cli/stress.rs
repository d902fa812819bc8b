//! `topple stress [--quick | --full] [--seed S] [--combo K]`: the seeded
//! sweep of `topple::stress`; prints its table, exits non-zero on any
//! violation.

use topple::stress::{sweep, table, SweepSpec};

/// Arguments of `topple stress`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The CI sweep: 400 combinations of 3 to 8 blocks (the default).
    #[arg(long, conflicts_with = "full")]
    pub quick: bool,
    /// The full sweep: 3,000 combinations of 3 to 20 blocks.
    #[arg(long)]
    pub full: bool,
    /// Seed of the draws.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Run only this combination (as printed in a reproduce line).
    #[arg(long)]
    pub combo: Option<usize>,
    /// Print every violation, not only the worst.
    #[arg(long)]
    pub verbose: bool,
}

pub fn run(args: Args) -> anyhow::Result<()> {
    let spec = if args.full {
        SweepSpec::full(args.seed)
    } else {
        SweepSpec::quick(args.seed)
    };
    if let Some(k) = args.combo {
        topple::validate::check_count("--combo", k, 0, spec.combos - 1)?;
    }
    let n = args.combo.map_or(spec.combos, |_| 1);
    let bar = indicatif::ProgressBar::new(n as u64);
    let r = sweep(&spec, args.combo, || bar.inc(1));
    bar.finish_and_clear();
    print!("{}", table(&spec, &r));
    if args.verbose || args.combo.is_some() {
        for v in &r.violations {
            println!(
                "  combo {}: {} = {:.3e}: {}",
                v.combo,
                v.kind.name(),
                v.value,
                v.detail
            );
        }
    }
    anyhow::ensure!(
        r.violations.is_empty(),
        "{} violations in {} combinations",
        r.violations.len(),
        n
    );
    Ok(())
}
