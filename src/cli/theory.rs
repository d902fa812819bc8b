//! `topple theory`: natural speed of the domino wave by the cooperative,
//! extended and single collision models, at one spacing or over a sweep.

use anyhow::{bail, Context};
use serde_json::json;
use std::path::PathBuf;
use topple::theory::{self, Geometry, Model, Outcome};

/// Arguments of `topple theory`.
#[derive(clap::Args)]
pub struct Args {
    /// Model: cooperative (mu = 0), extended (needs --mu) or single (needs --mu and --e).
    /// In a sweep, all three unless given.
    #[arg(long, value_enum)]
    pub model: Option<ModelName>,
    /// Block thickness over height, d/h, in (0, 1).
    #[arg(
        long,
        allow_hyphen_values = true,
        value_name = "D_OVER_H",
        allow_negative_numbers = true
    )]
    pub thickness_ratio: f64,
    /// Gap over height, s/h (> 0), or a sweep A:B:STEP (writes a CSV table and an SVG plot).
    #[arg(long, value_name = "S_OVER_H|A:B:STEP", allow_hyphen_values = true)]
    pub spacing_ratio: String,
    /// Friction coefficient between blocks (extended and single models).
    #[arg(long, allow_hyphen_values = true, allow_negative_numbers = true)]
    pub mu: Option<f64>,
    /// Coefficient of restitution between blocks (single collision model).
    #[arg(long, allow_hyphen_values = true, allow_negative_numbers = true)]
    pub e: Option<f64>,
    /// Print JSON (key "natural_speed" holds v/sqrt(gh), null without a wave).
    #[arg(long)]
    pub json: bool,
    /// Directory for the sweep's CSV and SVG (created if missing).
    #[arg(long, value_name = "DIR", default_value = ".")]
    pub out: PathBuf,
    /// File name (without extension) of the sweep's CSV and SVG.
    #[arg(long, value_name = "NAME", default_value = "theory_sweep")]
    pub name: String,
}

/// The models on the command line.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum ModelName {
    /// Cooperative group model, mu = 0.
    Cooperative,
    /// Extended group model, friction mu between blocks.
    Extended,
    /// Single collision model, friction mu and restitution e.
    Single,
}

pub fn run(args: Args) -> anyhow::Result<()> {
    if args.spacing_ratio.contains(':') {
        return run_sweep(&args);
    }
    let s: f64 = parse_number(&args.spacing_ratio, "--spacing-ratio")?;
    let Some(name) = args.model else {
        bail!("--model is required for a single spacing (cooperative, extended or single)");
    };
    let model = build_model(name, args.mu, args.e, false)?;
    let geom = Geometry::new(args.thickness_ratio, s)?;
    let outcome = theory::solve(&model, &geom)?;
    if args.json {
        let mut obj = json!({
            "model": model.name(),
            "thickness_ratio": args.thickness_ratio,
            "spacing_ratio": s,
            "mu": model.mu(),
            "e": match model { Model::Single { e, .. } => Some(e), _ => None },
            "units": "speed over sqrt(g h), angular velocity over sqrt(g/h), time over sqrt(h/g), angles in rad",
        });
        let map = obj.as_object_mut().expect("object");
        match &outcome {
            Outcome::Wave(w) => {
                map.insert("wave".into(), json!(true));
                for (k, v) in serde_json::to_value(w)?.as_object().expect("object") {
                    map.insert(k.clone(), v.clone());
                }
            }
            Outcome::NoWave(r) => {
                map.insert("wave".into(), json!(false));
                map.insert("natural_speed".into(), serde_json::Value::Null);
                map.insert("no_wave".into(), serde_json::to_value(r)?);
                map.insert("reason".into(), json!(r.to_string()));
            }
        }
        println!("{}", serde_json::to_string_pretty(&obj)?);
        return Ok(());
    }
    println!("model            {}", describe(&model));
    println!("d/h, s/h         {}, {}", args.thickness_ratio, s);
    match outcome {
        Outcome::Wave(w) => {
            println!("natural speed    v/sqrt(gh) = {:.6}", w.natural_speed);
            println!(
                "omega after      {:.6} sqrt(g/h)  (leader, just after a collision)",
                w.omega_after
            );
            println!(
                "omega before     {:.6} sqrt(g/h)  (leader, just before a collision)",
                w.omega_before
            );
            println!("period           {:.6} sqrt(h/g)", w.period);
            println!("theta_c          {:.6} rad", w.theta_c);
            println!("theta_inf        {:.6} rad", w.theta_inf);
        }
        Outcome::NoWave(r) => println!("no wave          {r}"),
    }
    Ok(())
}

fn run_sweep(args: &Args) -> anyhow::Result<()> {
    let spacings = parse_range(&args.spacing_ratio)?;
    let models: Vec<Model> = match args.model {
        Some(name) => vec![build_model(name, args.mu, args.e, true)?],
        None => vec![
            Model::Cooperative,
            build_model(ModelName::Extended, args.mu, None, true)?,
            build_model(ModelName::Single, args.mu, args.e, true)?,
        ],
    };
    // validate the thickness before creating files
    Geometry::new(args.thickness_ratio, spacings[0])?;
    if args.name.is_empty() || args.name.contains(['/', '\\']) {
        bail!(
            "--name must be a plain file name without a directory, got {:?}",
            args.name
        );
    }
    let rows = theory::sweep(&models, args.thickness_ratio, &spacings)?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create directory {}", args.out.display()))?;
    let csv = args.out.join(format!("{}.csv", args.name));
    let svg = args.out.join(format!("{}.svg", args.name));
    let file =
        std::fs::File::create(&csv).with_context(|| format!("cannot write {}", csv.display()))?;
    theory::write_csv(std::io::BufWriter::new(file), &models, &rows)
        .with_context(|| format!("cannot write {}", csv.display()))?;
    theory::plot_svg(&svg, args.thickness_ratio, &models, &rows)?;
    if args.json {
        let out_rows: Vec<_> = rows
            .iter()
            .map(|r| {
                let mut speeds = serde_json::Map::new();
                for (m, o) in models.iter().zip(&r.outcomes) {
                    speeds.insert(m.name().into(), json!(o.natural_speed()));
                }
                json!({ "spacing_ratio": r.spacing_ratio, "natural_speed": speeds })
            })
            .collect();
        let obj = json!({
            "thickness_ratio": args.thickness_ratio,
            "models": models,
            "csv": csv,
            "svg": svg,
            "rows": out_rows,
        });
        println!("{}", serde_json::to_string_pretty(&obj)?);
    } else {
        let with_wave = |i: usize| {
            rows.iter()
                .filter(|r| r.outcomes[i].natural_speed().is_some())
                .count()
        };
        for (i, m) in models.iter().enumerate() {
            println!(
                "{:<40} wave at {} of {} spacings",
                describe(m),
                with_wave(i),
                rows.len()
            );
        }
        println!("wrote {} and {}", csv.display(), svg.display());
    }
    Ok(())
}

fn describe(m: &Model) -> String {
    match *m {
        Model::Cooperative => "cooperative group (mu = 0)".into(),
        Model::Extended { mu } => format!("extended group (mu = {mu})"),
        Model::Single { mu, e } => format!("single collision (mu = {mu}, e = {e})"),
    }
}

fn build_model(
    name: ModelName,
    mu: Option<f64>,
    e: Option<f64>,
    sweep: bool,
) -> anyhow::Result<Model> {
    let model = match name {
        ModelName::Cooperative => {
            if mu.is_some_and(|m| m != 0.0) {
                bail!("the cooperative model has mu = 0; use --model extended for friction");
            }
            if e.is_some() && !sweep {
                bail!("--e applies to the single collision model only");
            }
            Model::Cooperative
        }
        ModelName::Extended => {
            let Some(mu) = mu else {
                bail!("--mu is required for the extended model (Domino T: 0.15)");
            };
            if e.is_some() && !sweep {
                bail!("--e applies to the single collision model only");
            }
            Model::Extended { mu }
        }
        ModelName::Single => {
            let (Some(mu), Some(e)) = (mu, e) else {
                bail!("--mu and --e are required for the single collision model (Domino T: 0.15 and 0.62)");
            };
            Model::Single { mu, e }
        }
    };
    model.validate()?;
    Ok(model)
}

fn parse_number(text: &str, what: &str) -> anyhow::Result<f64> {
    text.trim()
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite())
        .with_context(|| format!("{what}: expected a number, got {text:?}"))
}

/// `A:B:STEP` → A, A + STEP, … up to B (included when it falls on the grid).
fn parse_range(text: &str) -> anyhow::Result<Vec<f64>> {
    let parts: Vec<&str> = text.split(':').collect();
    if parts.len() != 3 {
        bail!("--spacing-ratio: a sweep is A:B:STEP, got {text:?}");
    }
    let a = parse_number(parts[0], "--spacing-ratio start")?;
    let b = parse_number(parts[1], "--spacing-ratio end")?;
    let step = parse_number(parts[2], "--spacing-ratio step")?;
    if !(a > 0.0 && b > a && step > 0.0) {
        bail!("--spacing-ratio {text}: need 0 < A < B and STEP > 0");
    }
    let count = ((b - a) / step + 1e-9).floor() + 1.0;
    if count > 1e6 {
        bail!("--spacing-ratio {text}: {count} points is too many (at most 1000000)");
    }
    Ok((0..count as usize)
        .map(|i| {
            let s = a + step * i as f64;
            (s * 1e12).round() / 1e12
        })
        .collect())
}
