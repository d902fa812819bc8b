//! `topple scene FILE [--engine rapier|rapier-native] [--json]`.

use std::path::PathBuf;

use anyhow::Context;
use topple::rapier::scene::{run_scene, ImpactResponse, RunOptions, Scene};
use topple::rapier::Precision;

/// Arguments of `topple scene`.
#[derive(clap::Args)]
pub struct Args {
    /// TOML scene file (see assets/scenes/).
    pub file: PathBuf,
    /// Who resolves impacts.
    #[arg(long, value_enum, default_value_t = ImpactResponse::Topple)]
    pub engine: ImpactResponse,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
    /// Stop a domino-row scene once its last block has been hit.
    #[arg(long)]
    pub until_last_hit: bool,
    /// Rapier build (f32 is what bevy_rapier2d uses).
    #[arg(long, value_enum, default_value_t = Precision::F64)]
    pub precision: Precision,
    /// Write the first impact that needed the fallback policy (held e = 0
    /// contacts or a plastic impact) here, as input for `topple impact`.
    #[arg(long)]
    pub dump_fallback_impact: Option<PathBuf>,
}

/// Runs the scene and prints final body states and the impacts resolved.
pub fn run(args: Args) -> anyhow::Result<()> {
    let text = std::fs::read_to_string(&args.file)
        .with_context(|| format!("reading {}", args.file.display()))?;
    let scene: Scene = topple::validate::parse_toml(&text, &args.file.display().to_string())?;
    topple::rapier::scene::check_scene(&scene)?;
    let options = RunOptions {
        stop_after_last_hit: args.until_last_hit,
        dump_fallback_impact: args.dump_fallback_impact.clone(),
    };
    let out = run_scene(&scene, args.engine, args.precision, options)?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&out)?);
        return Ok(());
    }
    println!(
        "engine {} ({})  t = {:.6} s  steps {}  kinetic energy {:.6e} -> {:.6e} J",
        out.engine.name(),
        out.precision.name(),
        out.time,
        out.steps,
        out.kinetic_energy[0],
        out.kinetic_energy[1]
    );
    println!(
        "{:<10} {:>12} {:>12} {:>10} {:>12} {:>12} {:>12}",
        "body", "x (m)", "y (m)", "angle", "vx (m/s)", "vy (m/s)", "w (rad/s)"
    );
    for b in &out.bodies {
        println!(
            "{:<10} {:>12.6} {:>12.6} {:>10.5} {:>12.6} {:>12.6} {:>12.6}",
            b.name,
            b.position[0],
            b.position[1],
            b.angle,
            b.velocity[0],
            b.velocity[1],
            b.angular_velocity
        );
    }
    println!("impacts resolved: {}", out.impacts.len());
    const SHOWN: usize = 20;
    for i in out.impacts.iter().take(SHOWN) {
        println!(
            "  t = {:.6} s  bodies {}  contacts {}  approach {:.4} m/s  KE {:.6e} -> {:.6e} J  steps {}",
            i.time,
            i.report.bodies,
            i.report.contacts,
            i.report.approach_speed,
            i.report.kinetic_energy_before,
            i.report.kinetic_energy_after,
            i.report.steps
        );
    }
    if out.impacts.len() > SHOWN {
        println!(
            "  ... ({} more; --json lists all)",
            out.impacts.len() - SHOWN
        );
    }
    if let Some(row) = &out.row {
        match row.natural_speed_spread {
            Some(s) => println!(
                "natural speed v_na = {:.4} (std dev {:.4} over {} blocks)",
                s.mean, s.std_dev, s.count
            ),
            None => println!("natural speed: the wave did not get past block 7"),
        }
        println!(
            "blocks hit: {} of {}",
            row.hit_times.len(),
            out.bodies.len()
        );
    }
    Ok(())
}
