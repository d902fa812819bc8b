//! `topple impact FILE`: one multiple impact, JSON in, JSON out.
//!
//! Input (keys exactly as here; `null` in a contact's `bodies` is the fixed
//! world; a number in `tolerance` selects adaptive stepping):
//!
//! ```json
//! {"bodies": [{"mass": 1.0, "inertia": 0.1, "position": [0.0, 0.0], "angle": 0.0,
//!              "velocity": [1.0, 0.0], "angular_velocity": 0.0, "fixed": false}],
//!  "contacts": [{"bodies": [0, null], "point": [0.5, 0.0], "normal": [1.0, 0.0],
//!                "stiffness": 1e9, "exponent": 1.5, "restitution": 1.0,
//!                "friction": 0.0, "stick_friction": 0.0}],
//!  "impulse_step": 1e-4, "tolerance": null}
//! ```

use std::io::Read;
use std::path::PathBuf;

use anyhow::Context;
use serde::{Deserialize, Serialize};
use topple::impact::{Body, Contact, ContactMaterial, ImpactSettings, ImpactSolver, StepControl};

/// Arguments of `topple impact`.
#[derive(clap::Args)]
pub struct Args {
    /// JSON file with bodies and contacts, or - for stdin.
    pub file: PathBuf,
    /// Largest number of impulse steps before giving up.
    #[arg(long, default_value_t = 10_000_000)]
    pub max_steps: usize,
    /// Hold e = 0 contacts closed once their compression ends (a plastic
    /// constraint) instead of the paper's release-and-reload law.
    #[arg(long)]
    pub e0_hold: bool,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct InputBody {
    mass: f64,
    inertia: f64,
    position: [f64; 2],
    angle: f64,
    velocity: [f64; 2],
    angular_velocity: f64,
    fixed: bool,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct InputContact {
    bodies: [Option<usize>; 2],
    point: [f64; 2],
    normal: [f64; 2],
    stiffness: f64,
    exponent: f64,
    restitution: f64,
    friction: f64,
    stick_friction: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Input {
    bodies: Vec<InputBody>,
    contacts: Vec<InputContact>,
    impulse_step: f64,
    tolerance: Option<f64>,
}

#[derive(Serialize)]
struct OutputBody {
    velocity: [f64; 2],
    angular_velocity: f64,
}

#[derive(Serialize)]
struct OutputContact {
    normal_impulse: f64,
    tangent_impulse: f64,
    peak_energy: f64,
}

#[derive(Serialize)]
struct Output {
    bodies: Vec<OutputBody>,
    contacts: Vec<OutputContact>,
    kinetic_energy_before: f64,
    kinetic_energy_after: f64,
    steps: usize,
    rejected_steps: usize,
    duration: f64,
}

/// Reads FILE (or stdin for `-`), resolves the impact, prints the result.
pub fn run(args: Args) -> anyhow::Result<()> {
    let text = if args.file.as_os_str() == "-" {
        let mut s = String::new();
        std::io::stdin()
            .read_to_string(&mut s)
            .context("reading stdin")?;
        s
    } else {
        std::fs::read_to_string(&args.file)
            .with_context(|| format!("reading {}", args.file.display()))?
    };
    let output = resolve_json(&text, args.max_steps, args.e0_hold)?;
    println!("{output}");
    Ok(())
}

/// The whole command as a function of the input text.
fn resolve_json(text: &str, max_steps: usize, e0_hold: bool) -> anyhow::Result<String> {
    // serde_json rejects NaN and infinities in JSON text already; the resolver
    // re-checks every value.
    let input: Input = serde_json::from_str(text).map_err(|e| topple::validate::SyntaxError {
        file: "input JSON".into(),
        line: e.line(),
        column: e.column(),
        message: e.to_string(),
    })?;
    let bodies: Vec<Body> = input
        .bodies
        .iter()
        .map(|b| Body {
            mass: b.mass,
            inertia: b.inertia,
            position: b.position,
            angle: b.angle,
            velocity: b.velocity,
            angular_velocity: b.angular_velocity,
            fixed: b.fixed,
        })
        .collect();
    let contacts: Vec<Contact> = input
        .contacts
        .iter()
        .map(|c| Contact {
            bodies: c.bodies,
            point: c.point,
            normal: c.normal,
            material: ContactMaterial {
                stiffness: c.stiffness,
                exponent: c.exponent,
                restitution: c.restitution,
                friction: c.friction,
                stick_friction: c.stick_friction,
            },
        })
        .collect();
    topple::validate::impact(&bodies, &contacts)?;
    topple::validate::check_count("--max-steps", max_steps, 1, 1_000_000_000)?;
    match input.tolerance {
        Some(t) => topple::validate::check_range("tolerance", t, 1e-12, 0.1)?,
        None => topple::validate::check_open_low("impulse_step", input.impulse_step, 0.0, 1.0)?,
    };
    let step_control = match input.tolerance {
        Some(tolerance) => StepControl::Adaptive { tolerance },
        None => StepControl::Fixed {
            impulse_step: input.impulse_step,
        },
    };
    let settings = ImpactSettings {
        step_control,
        max_steps,
        e0_hold,
        ..ImpactSettings::default()
    };
    let out = ImpactSolver::new().solve(&bodies, &contacts, &settings)?;
    let output = Output {
        bodies: out
            .bodies
            .iter()
            .map(|b| OutputBody {
                velocity: b.velocity,
                angular_velocity: b.angular_velocity,
            })
            .collect(),
        contacts: out
            .contacts
            .iter()
            .map(|c| OutputContact {
                normal_impulse: c.normal_impulse,
                tangent_impulse: c.tangent_impulse,
                peak_energy: c.peak_energy,
            })
            .collect(),
        kinetic_energy_before: out.kinetic_energy_before,
        kinetic_energy_after: out.kinetic_energy_after,
        steps: out.steps,
        rejected_steps: out.rejected_steps,
        duration: out.duration,
    };
    Ok(serde_json::to_string_pretty(&output)?)
}
