//! A domino row and the run of an engine over it: every parameter in its
//! documented range (`docs/input-limits.md`), the run bounded in steps,
//! memory and time before it starts.

use super::{
    check_count, check_memory, check_open_low, check_range, fmt_value, EngineKind, InputError,
};
use crate::domino::RowSpec;

/// Largest row (blocks) any engine takes, whatever the memory: a wave over
/// it would take days on the reference engine (about 10⁴ blocks a minute).
pub const MAX_BLOCKS: usize = 10_000_000;

/// Most Rapier steps a run may take (`max_time / dt`).
pub const MAX_RAPIER_STEPS: f64 = 1e7;

/// How an engine runs a row: what bounds its time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RunBudget {
    /// The engine.
    pub engine: EngineKind,
    /// Fixed time step (s) if the run uses one.
    pub dt: Option<f64>,
    /// Integration tolerance if the run is adaptive (dimensionless).
    pub tolerance: Option<f64>,
    /// Simulated time limit (s) (Rapier engines).
    pub max_time: Option<f64>,
    /// Wall-clock limit (s).
    pub wall_limit: Option<f64>,
}

/// How the fields of a row are named to the user: CLI flags or scene keys.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Naming {
    /// `--spacing-ratio`, `--mu1`, …
    Flags,
    /// `row.spacing`, `row.mu1`, …
    Scene,
}

impl Naming {
    fn name(self, key: &str) -> String {
        match self {
            Naming::Flags => match key {
                "spacing" => "--spacing-ratio".into(),
                "lambda_points" => "--lambda".into(),
                "dt" | "tolerance" | "max_time" | "wall_limit" | "n" | "push" => {
                    format!("--{}", key.replace('_', "-"))
                }
                k => format!("--{}", k.replace('_', "-")),
            },
            Naming::Scene => match key {
                "dt" | "tolerance" => format!("solver.{key}"),
                "max_time" => "duration".into(),
                "lambda_points" => "solver.lambda".into(),
                k => format!("row.{k}"),
            },
        }
    }
}

/// Checks a row and its run; `naming` says how to name a bad field.
///
/// Ranges (see `docs/input-limits.md` for why): 0 < s/h < 1, 2 ≤ n ≤ 10⁷
/// and within memory, 0 < push ≤ 10, μ in [0, 5] with μ_s ≥ μ, e in [0, 1],
/// 0 < k ≤ 10¹⁵, 1 ≤ α ≤ 3, 2 ≤ λ ≤ 100, impact friction factor in [0, 1],
/// 10⁻⁴ m ≤ h ≤ 10 m, 0 < d < h; the reference engine's step
/// 10⁻⁷ s ≤ Δt ≤ 0.05 t̄, Rapier's 10⁻⁶ s ≤ Δt ≤ 1/30 s; a tolerance in
/// [10⁻¹², 10⁻³]; at most 10⁷ Rapier steps.
///
/// ```
/// use topple::domino::{Preset, RowSpec};
/// use topple::validate::{row, EngineKind, Naming, RunBudget};
/// let p = Preset::X.params();
/// let budget = RunBudget { engine: EngineKind::Reference, dt: Some(0.0), tolerance: None, max_time: None, wall_limit: None };
/// let e = row(&RowSpec::new(p, 0.3 * p.block.height, 10, 1.0), &budget, Naming::Flags).unwrap_err();
/// assert_eq!(e.to_string(), "--dt = 0: allowed 1e-7 ≤ --dt ≤ 0.0033");
/// ```
pub fn row(spec: &RowSpec, budget: &RunBudget, naming: Naming) -> Result<(), InputError> {
    let f = |k: &str| naming.name(k);
    let p = &spec.params;
    let b = &p.block;
    check_range(&f("height"), b.height, 1e-4, 10.0)?;
    if !(b.thickness.is_finite() && b.thickness > 0.0 && b.thickness < b.height) {
        return Err(InputError::new(
            f("thickness"),
            fmt_value(b.thickness),
            format!("0 < {} < the height {}", f("thickness"), b.height),
        ));
    }
    if !(b.mass.is_finite() && b.mass > 0.0 && b.mass <= 1e6) {
        return Err(InputError::new(
            f("mass"),
            fmt_value(b.mass),
            "0 < mass ≤ 1e6 kg",
        ));
    }
    let ratio = spec.spacing / b.height;
    if !(ratio.is_finite() && ratio > 0.0 && ratio < 1.0) {
        return Err(InputError::new(
            f("spacing"),
            fmt_value(ratio),
            format!("0 < {} < 1 (a gap shorter than the block)", f("spacing")),
        ));
    }
    check_memory(&f("n"), spec.n, budget.engine, None)?;
    check_count(&f("n"), spec.n, 2, MAX_BLOCKS)?;
    check_open_low(&f("push"), spec.push, 0.0, 10.0)?;
    for (k, v) in [("mu1", p.mu1), ("mu2", p.mu2)] {
        check_range(&f(k), v, 0.0, 5.0)?;
    }
    for (k, v, slide) in [
        ("mu1_stick", p.mu1_stick, p.mu1),
        ("mu2_stick", p.mu2_stick, p.mu2),
    ] {
        check_range(&f(k), v, slide, 5.0)?;
    }
    for (k, v) in [("e1", p.e1), ("e2", p.e2)] {
        check_range(&f(k), v, 0.0, 1.0)?;
    }
    for (k, v) in [("k1", p.k1), ("k2", p.k2)] {
        check_open_low(&f(k), v, 0.0, 1e15)?;
    }
    check_range(&f("alpha"), p.alpha, 1.0, 3.0)?;
    check_count(&f("lambda_points"), p.lambda_points, 2, 100)?;
    check_range(
        &f("impact_friction_factor"),
        p.impact_friction_factor,
        0.0,
        1.0,
    )?;
    check_open_low(&f("gravity"), p.gravity, 0.0, 1e3)?;
    budget_checks(spec, budget, naming)
}

/// The time step, tolerance and limits of the run.
fn budget_checks(spec: &RowSpec, budget: &RunBudget, naming: Naming) -> Result<(), InputError> {
    let f = |k: &str| naming.name(k);
    if let Some(tol) = budget.tolerance {
        check_range(&f("tolerance"), tol, 1e-12, 1e-3)?;
    }
    if let Some(limit) = budget.wall_limit {
        check_open_low(&f("wall_limit"), limit, 0.0, 1e7)?;
    }
    match budget.engine {
        EngineKind::Reference => {
            if let (Some(dt), None) = (budget.dt, budget.tolerance) {
                // the paper's improved Euler: 0.05 t̄ is where v̂_na still
                // agrees with 1e-4 s to 1 % (Domino X, s/h 0.3; 0.15 t̄ stops
                // the wave)
                let hi = 0.05 * spec.params.time_scale();
                check_range(&f("dt"), dt, 1e-7, hi)?;
            }
        }
        EngineKind::Rapier => {
            let dt = budget.dt.unwrap_or(1e-3);
            check_range(&f("dt"), dt, 1e-6, 1.0 / 30.0)?;
            if let Some(t) = budget.max_time {
                check_open_low(&f("max_time"), t, 0.0, 1e4)?;
                let steps = (t / dt).ceil();
                if steps > MAX_RAPIER_STEPS {
                    return Err(InputError::new(
                        f("max_time"),
                        fmt_value(t),
                        format!(
                            "{} / {} ≤ 1e7 Rapier steps (this run would take {steps:.3e})",
                            f("max_time"),
                            f("dt")
                        ),
                    ));
                }
            }
        }
    }
    Ok(())
}
