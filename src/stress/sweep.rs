//! The sweep: many combinations in parallel, every invariant checked, a
//! table of what was found.

use std::collections::BTreeMap;

use crate::par::prelude::*;

use super::combo::{draw, reproduce, Combo, StressEngine};
use super::engines::{explained_by_native, explained_by_reference, run_combo};
use super::observe::Observation;

/// The size of a sweep.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SweepSpec {
    /// Seed of every draw.
    pub seed: u64,
    /// Combinations.
    pub combos: usize,
    /// Rows have `n_lo..=n_hi` blocks.
    pub n_lo: usize,
    /// See `n_lo`.
    pub n_hi: usize,
    /// Budget of one run (s of CPU time of the thread that runs it, so that
    /// the verdict does not depend on the machine's load).
    pub budget: f64,
    /// The full sweep (for the reproduce line).
    pub full: bool,
    /// Only the combinations of this engine (all if `None`).
    pub engine: Option<StressEngine>,
}

impl SweepSpec {
    /// `topple stress --quick`: 400 combinations of 3 to 8 blocks.
    pub fn quick(seed: u64) -> Self {
        SweepSpec {
            seed,
            combos: 400,
            n_lo: 3,
            n_hi: 8,
            budget: 60.0,
            full: false,
            engine: None,
        }
    }

    /// `topple stress --full`: 3,000 combinations of 3 to 20 blocks.
    pub fn full(seed: u64) -> Self {
        SweepSpec {
            seed,
            combos: 3000,
            n_lo: 3,
            n_hi: 20,
            budget: 120.0,
            full: true,
            engine: None,
        }
    }
}

/// Kinds of violation, in the order of the table.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Kind {
    /// A state or report value became NaN or infinite.
    NonFinite,
    /// An impact created kinetic energy.
    EnergyGain,
    /// An elastic frictionless impact did not keep its energy.
    ElasticEnergy,
    /// An elastic frictionless free impact did not keep its momentum.
    Momentum,
    /// Applied velocities differ from those the impulses give.
    Impulses,
    /// Two blocks (or a block and the ground) overlapped beyond tolerance.
    Penetration,
    /// The count of fallen blocks went down.
    FallenDrop,
    /// A body went through the ground (scenes).
    ThroughGround,
    /// A frame's impact work went over the frame budget (scenes).
    FrameWork,
    /// A second run of the same input gave other bits (scenes).
    Repeat,
    /// The run did not end within its budget.
    Budget,
    /// The engine returned an error.
    Error,
}

impl Kind {
    /// Its name in the table.
    pub fn name(self) -> &'static str {
        match self {
            Kind::NonFinite => "non-finite state",
            Kind::EnergyGain => "impact created energy",
            Kind::ElasticEnergy => "e = 1 energy not kept",
            Kind::Momentum => "e = 1 momentum not kept",
            Kind::Impulses => "velocities ≠ impulses",
            Kind::Penetration => "penetration",
            Kind::FallenDrop => "fallen count dropped",
            Kind::ThroughGround => "through the ground",
            Kind::FrameWork => "over the frame budget",
            Kind::Repeat => "other bits on a rerun",
            Kind::Budget => "over budget",
            Kind::Error => "engine error",
        }
    }
}

/// Tolerances of the invariants (see `docs/stress.md` for the reasons).
pub mod tolerance {
    /// Relative energy an impact may gain: summation round-off; the same
    /// bound the fallback policy applies (`coupling::fallback`).
    pub const ENERGY_GAIN: f64 = 1e-9;
    /// Relative energy an elastic frictionless impact may lose or gain:
    /// the resolver's fixed impulse step ΔP = 10⁻⁴ P₀ integrates the stored
    /// energy with a first-order error in ΔP/P₀ per release; 10⁻³ is ten
    /// times that.
    pub const ELASTIC_ENERGY: f64 = 1e-3;
    /// Relative momentum a free impact may change: round-off (internal
    /// impulses cancel exactly in pairs).
    pub const MOMENTUM: f64 = 1e-9;
    /// Applied against recomputed velocities, over the speed scale.
    pub const IMPULSES: f64 = 1e-6;
    /// Largest overlap over the block height, reference engine (heel
    /// contacts on): its gap tolerance 10⁻⁶ h plus the overshoot of an
    /// event located within a step.
    pub const PENETRATION_REFERENCE: f64 = 0.01;
    /// Rapier keeps resting contacts soft: its allowed linear error is
    /// 0.005 of the length unit (the block height in a row), and its contact
    /// springs give under the blocks leaning on a block; 0.05 h for both.
    pub const PENETRATION_RAPIER: f64 = 0.05;
    /// Rapier engines, over h. Native Rapier has no continuous collision
    /// detection here: a body moves a whole step before its contacts are
    /// seen, so two blocks can overlap by what they close in one step.
    /// topple splits a step at most `max_splits` (4) times at predicted
    /// impact instants; an impact beyond those in the same step is resolved
    /// where Rapier left the pair, as deep as one step's closing too. The
    /// fastest closing in a row is a block's top corner, at most
    /// max(push, √3) √(gh) (√(3gh): a block falling flat from upright); 1.1
    /// of it over one step, plus [`PENETRATION_RAPIER`].
    pub fn penetration_rapier(push: f64, dt: f64, h: f64, g: f64) -> f64 {
        PENETRATION_RAPIER + 1.1 * push.max(3f64.sqrt()) * (g * h).sqrt() * dt / h
    }

    /// The reference engine's penetration is checked for rows with e1 ≤
    /// this. Its contacts are the corners of a block on the faces of its
    /// neighbours as a row falls forward (Sec. 2.1, and the heel with
    /// `heel_contacts`); a block that rebounds off an elastic neighbour and
    /// tilts back onto its heel brings its front bottom corner onto the next
    /// block's back face, a pair it does not have. The sweep found such
    /// overlaps of 0.06 h at e1 = 1 (Domino X, s/h 0.12, every time step):
    /// a limit of the reference's model, reported in `docs/stress.md`.
    pub const REFERENCE_E1_SCOPE: f64 = 0.85;

    /// The fallen count can only drop if an impact gives a fallen block back
    /// enough energy to stand it up past π/4: it is checked for rows whose
    /// impacts dissipate, e1 ≤ this and e2 ≤ [`FALLEN_E2`] (Table 1's
    /// materials are inside). With e = 1 a block landing on the ground or on
    /// its neighbour can bounce back up, as the sweep shows.
    pub const FALLEN_E1: f64 = 0.85;
    /// See [`FALLEN_E1`].
    pub const FALLEN_E2: f64 = 0.5;
}

/// One violation: the combination, what, by how much.
#[derive(Clone, Debug)]
pub struct Violation {
    /// The combination.
    pub combo: usize,
    /// Its engine.
    pub engine: StressEngine,
    /// What was violated.
    pub kind: Kind,
    /// By how much (the measure; its tolerance is in [`tolerance`]).
    pub value: f64,
    /// A line of detail.
    pub detail: String,
}

/// The violations of one observed run.
pub fn violations(c: &Combo, o: &Observation) -> Vec<Violation> {
    use tolerance::*;
    let a = &o.audit;
    let p = &c.row.params;
    let pen_tol = match c.engine {
        StressEngine::Reference => PENETRATION_REFERENCE,
        _ => penetration_rapier(c.row.push, c.dt, p.block.height, p.gravity),
    };
    let dissipative = p.e1 <= FALLEN_E1 && p.e2 <= FALLEN_E2;
    // the reference's contact set has no block tilting back into the one
    // behind (see REFERENCE_E1_SCOPE)
    let pen_tol = if c.engine == StressEngine::Reference && p.e1 > REFERENCE_E1_SCOPE {
        f64::INFINITY
    } else {
        pen_tol
    };
    // a drop the reference shows on the same row too is physics, and so is
    // a block rocking back across π/4 by no more than a fallen block rocks
    // back in the reference on the same row; a rock-back native Rapier
    // makes at least as large on the same row and step, from nearby starts,
    // is the baseline's (see `run_combo`)
    let explained = explained_by_reference(o) || explained_by_native(o);
    let fallen_drop = if dissipative && !explained {
        o.fallen_drop as f64
    } else {
        0.0
    };
    let checks = [
        (
            Kind::NonFinite,
            (o.non_finite || a.non_finite > 0) as u8 as f64,
            0.0,
        ),
        (Kind::EnergyGain, a.energy_gain, ENERGY_GAIN),
        (Kind::ElasticEnergy, a.elastic_energy, ELASTIC_ENERGY),
        (Kind::Momentum, a.momentum, MOMENTUM),
        (Kind::Impulses, a.consistency, IMPULSES),
        (Kind::Penetration, o.penetration, pen_tol),
        (Kind::FallenDrop, fallen_drop, 0.0),
        (Kind::Budget, o.over_budget as u8 as f64, 0.0),
        (Kind::Error, o.error.is_some() as u8 as f64, 0.0),
    ];
    checks
        .into_iter()
        .filter(|(_, v, tol)| v.is_nan() || *v > *tol)
        .map(|(kind, value, _)| Violation {
            combo: c.index,
            engine: c.engine,
            kind,
            value,
            detail: describe(c, o),
        })
        .collect()
}

fn describe(c: &Combo, o: &Observation) -> String {
    let p = &c.row.params;
    format!(
        "{} {} s/h {:.3} n {} push {:.2} μ1 {:.2} μ2 {:.2} e1 {} e2 {} dt {:.2e}: {} hits, {} impacts, {:.1} s of CPU, penetration {}{}{}",
        c.engine.name(),
        c.preset,
        c.row.spacing_ratio(),
        c.row.n,
        c.row.push,
        p.mu1,
        p.mu2,
        p.e1,
        p.e2,
        c.dt,
        o.hits,
        o.audit.impacts,
        o.cpu,
        o.penetration_at,
        if o.fallen_drop > 0 {
            format!(
                ", fallen count dropped by {} (stood up: blocks {:?}; rock-back {:.2}°{}{})",
                o.fallen_drop,
                o.stood_up,
                o.stood_up_rock_back.to_degrees(),
                o.reference_rock_back
                    .map(|r| format!(", reference's {:.2}°", r.to_degrees()))
                    .unwrap_or_default(),
                o.native_rock_back
                    .map(|r| format!(
                        "; from its start and {} nearby at the same step: topple stands one up by at least {:.2}°, native Rapier rocks one back by at most {:.2}° and drops up to {}",
                        super::observe::NEARBY_RUNS,
                        r.topple_least.to_degrees(),
                        r.native_most.to_degrees(),
                        r.native_drop
                    ))
                    .unwrap_or_default(),
            )
        } else {
            String::new()
        },
        o.error.as_deref().map(|e| format!(", error: {e}")).unwrap_or_default()
    )
}

/// What a sweep found.
#[derive(Clone, Debug, Default)]
pub struct SweepResult {
    /// Combinations run, per engine.
    pub runs: BTreeMap<StressEngine, usize>,
    /// Impacts checked.
    pub impacts: usize,
    /// Elastic frictionless free impacts checked.
    pub elastic_impacts: usize,
    /// Worst measures over all runs, per kind.
    pub worst: BTreeMap<Kind, f64>,
    /// Every violation.
    pub violations: Vec<Violation>,
    /// CPU time of the longest run (s).
    pub longest_run: f64,
    /// The combination of the longest run.
    pub longest_combo: usize,
    /// Worst penetration (over h) per engine and time step (µs).
    pub penetration: BTreeMap<(StressEngine, u64), f64>,
    /// The combination and what it showed, when one alone was run.
    pub single: Option<(Combo, Observation)>,
}

impl SweepResult {
    /// The violations of topple's engines: what the exit status counts
    /// (native Rapier's are the baseline, see [`StressEngine::is_baseline`]).
    pub fn counted(&self) -> impl Iterator<Item = &Violation> {
        self.violations.iter().filter(|v| !v.engine.is_baseline())
    }

    /// The violations of the baseline (native Rapier).
    pub fn baseline(&self) -> impl Iterator<Item = &Violation> {
        self.violations.iter().filter(|v| v.engine.is_baseline())
    }
}

/// The combinations a sweep runs: `which` alone, or all of the spec's (of
/// its engine, if it names one).
pub fn combos_of(spec: &SweepSpec, which: Option<usize>) -> Vec<usize> {
    match which {
        Some(i) => vec![i],
        None => (0..spec.combos)
            .filter(|&i| spec.engine.is_none_or(|e| StressEngine::of_combo(i) == e))
            .collect(),
    }
}

/// Runs combinations `which` (all of the spec's if `None`) and gathers the
/// result; `progress` is called after each run with what it observed.
pub fn sweep(
    spec: &SweepSpec,
    which: Option<usize>,
    progress: impl Fn(&Combo, &Observation) + Sync,
) -> SweepResult {
    let indices = combos_of(spec, which);
    let observed: Vec<(Combo, Observation)> = indices
        .par_iter()
        .map(|&i| {
            let c = draw(spec.seed, i, spec.n_lo, spec.n_hi);
            let o = run_combo(&c, spec.budget);
            progress(&c, &o);
            (c, o)
        })
        .collect();
    let mut r = SweepResult::default();
    for (c, o) in &observed {
        *r.runs.entry(c.engine).or_default() += 1;
        r.impacts += o.audit.impacts;
        r.elastic_impacts += o.audit.elastic_impacts;
        if o.cpu > r.longest_run {
            r.longest_run = o.cpu;
            r.longest_combo = c.index;
        }
        if c.engine != StressEngine::Impact {
            let w = r
                .penetration
                .entry((c.engine, (c.dt * 1e6).round() as u64))
                .or_insert(0.0);
            *w = w.max(o.penetration);
        }
        let a = &o.audit;
        for (k, v) in [
            (Kind::EnergyGain, a.energy_gain),
            (Kind::ElasticEnergy, a.elastic_energy),
            (Kind::Momentum, a.momentum),
            (Kind::Impulses, a.consistency),
            (Kind::Penetration, o.penetration),
        ] {
            let w = r.worst.entry(k).or_insert(0.0);
            *w = w.max(v);
        }
        r.violations.extend(violations(c, o));
    }
    if which.is_some() {
        r.single = observed.into_iter().next();
    }
    r
}

/// The kinds of violation, in the order of the table.
const KINDS: [Kind; 9] = [
    Kind::NonFinite,
    Kind::EnergyGain,
    Kind::ElasticEnergy,
    Kind::Momentum,
    Kind::Impulses,
    Kind::Penetration,
    Kind::FallenDrop,
    Kind::Budget,
    Kind::Error,
];

/// The table of a sweep (plain text): topple's engines, whose violations
/// count, and native Rapier's as the baseline beside them.
pub fn table(spec: &SweepSpec, r: &SweepResult) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let total: usize = r.runs.values().sum();
    let _ = writeln!(
        s,
        "seed {}  combinations {total}  impacts checked {}  (e = 1 frictionless free impacts {})",
        spec.seed, r.impacts, r.elastic_impacts
    );
    let _ = writeln!(
        s,
        "longest run {:.1} s of CPU, combination {} (budget {} s of CPU per run)",
        r.longest_run, r.longest_combo, spec.budget
    );
    let _ = writeln!(
        s,
        "{:<11} {:>5} {:>10}  worst penetration / h",
        "engine", "runs", "violations"
    );
    for (e, n) in &r.runs {
        let count = r.violations.iter().filter(|v| v.engine == *e).count();
        let worst = r
            .penetration
            .iter()
            .filter(|((pe, _), _)| pe == e)
            .map(|(_, w)| *w)
            .fold(None, |a: Option<f64>, w| Some(a.map_or(w, |a| a.max(w))));
        let _ = writeln!(
            s,
            "{:<11} {n:>5} {count:>10}  {}{}",
            e.name(),
            worst.map_or("-".into(), |w| format!("{w:.2e}")),
            if e.is_baseline() {
                "  (baseline, not counted)"
            } else {
                ""
            }
        );
    }
    let _ = writeln!(
        s,
        "{:<24} {:>10} {:>10} {:>12}  tolerance",
        "invariant", "topple", "baseline", "worst"
    );
    for kind in KINDS {
        let count = r.counted().filter(|v| v.kind == kind).count();
        let base = r.baseline().filter(|v| v.kind == kind).count();
        let worst = r
            .worst
            .get(&kind)
            .map(|w| format!("{w:.3e}"))
            .unwrap_or_else(|| "-".into());
        let tol = match kind {
            Kind::EnergyGain => format!("{:.0e}", tolerance::ENERGY_GAIN),
            Kind::ElasticEnergy => format!("{:.0e}", tolerance::ELASTIC_ENERGY),
            Kind::Momentum => format!("{:.0e}", tolerance::MOMENTUM),
            Kind::Impulses => format!("{:.0e}", tolerance::IMPULSES),
            Kind::Penetration => format!(
                "reference {} h; Rapier {} h + one step's closing",
                tolerance::PENETRATION_REFERENCE,
                tolerance::PENETRATION_RAPIER
            ),
            _ => "0".into(),
        };
        let _ = writeln!(
            s,
            "{:<24} {count:>10} {base:>10} {worst:>12}  {tol}",
            kind.name()
        );
    }
    let _ = writeln!(s, "worst penetration / h by engine and time step:");
    for ((e, us), w) in &r.penetration {
        let _ = writeln!(s, "  {:<11} dt {:>6} µs  {w:.2e}", e.name(), us);
    }
    // the worst violation: the largest measure of the first kind violated
    let worst_of = |v: &mut dyn Iterator<Item = &Violation>| -> Option<Violation> {
        v.min_by(|a, b| a.kind.cmp(&b.kind).then(b.value.total_cmp(&a.value)))
            .cloned()
    };
    if let Some(v) = worst_of(&mut r.counted()) {
        let _ = writeln!(
            s,
            "worst: {} = {:.3e} in {}",
            v.kind.name(),
            v.value,
            v.detail
        );
        let _ = writeln!(s, "reproduce: {}", reproduce(spec.seed, v.combo, spec.full));
    } else {
        let _ = writeln!(s, "no violations in topple's engines");
    }
    if let Some(v) = worst_of(&mut r.baseline()) {
        let _ = writeln!(
            s,
            "baseline worst: {} = {:.3e} in {}",
            v.kind.name(),
            v.value,
            v.detail
        );
    }
    s
}
