//! The scene family of the stress sweep (`topple stress --family scenes`):
//! random scenes for the Rapier plugin — piles, stacks and pyramids of every
//! shape the scene format supports, random sizes, masses from 10⁻² to
//! 10² kg, length units from metres to pixels, time steps from 1/240 to
//! 1/30 s, both Rapier builds — each run twice and checked frame by frame.
//!
//! | item | file | role |
//! | --- | --- | --- |
//! | [`draw_scene`], [`SceneCombo`], [`SHAPES`] | `draw.rs` | the seeded draw of one scene |
//! | [`run_scene_combo`], [`SceneObservation`], [`SoftSag`], [`native_as_topple`] | `run.rs` | one scene through its engine, watched, and again for its bits; the soft contact's sag and native Rapier as topple steps it, the baselines of its depth |
//! | [`scene_sweep`], [`scene_table`], [`scene_violations`] | `mod.rs` | many scenes in parallel; the violations and the table |
//!
//! ```no_run
//! use topple::stress::scene::{scene_sweep, scene_table, SceneSpec};
//! let spec = SceneSpec::quick(1);
//! let r = scene_sweep(&spec, None, |_, _| {});
//! println!("{}", scene_table(&spec, &r));
//! ```

mod draw;
pub(super) mod run;

use std::collections::BTreeMap;

use crate::par::prelude::*;

pub use draw::{draw_scene, SceneCombo, SceneEngine, SceneKind, StressShape, SHAPES};
pub use run::{
    native_as_topple, run_scene_combo, NearbyRuns, SceneObservation, SoftSag, NEARBY_RUNS,
    NEARBY_STEP,
};

use super::sweep::{Kind, Violation};
use super::StressEngine;

/// The size of a scene sweep.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneSpec {
    /// Seed of every draw.
    pub seed: u64,
    /// Scenes.
    pub scenes: usize,
    /// Scenes have `n_lo..=n_hi` bodies.
    pub n_lo: usize,
    /// See `n_lo`.
    pub n_hi: usize,
    /// Simulated time of a scene (s).
    pub duration: f64,
    /// Budget of one run (s of CPU time of the thread that runs it).
    pub budget: f64,
    /// The full sweep (for the reproduce line).
    pub full: bool,
}

impl SceneSpec {
    /// `topple stress --family scenes --quick` (CI): 36 scenes of 3 to 8
    /// bodies, 1 s each — every engine, kind, half of the unit range and
    /// half of the time-step range together (the draw is stratified).
    pub fn quick(seed: u64) -> Self {
        SceneSpec {
            seed,
            scenes: 36,
            n_lo: 3,
            n_hi: 8,
            duration: 1.0,
            budget: 60.0,
            full: false,
        }
    }

    /// `topple stress --family scenes --full`: 1,200 scenes of 3 to 40
    /// bodies, 4 s each.
    pub fn full(seed: u64) -> Self {
        SceneSpec {
            seed,
            scenes: 1200,
            n_lo: 3,
            n_hi: 40,
            duration: 4.0,
            budget: 120.0,
            full: true,
        }
    }

    /// Draws scene `index` of this sweep.
    pub fn draw(&self, index: usize) -> SceneCombo {
        draw_scene(self.seed, index, self.n_lo, self.n_hi, self.duration)
    }
}

/// Tolerances of the scene invariants (see `docs/stress.md`).
pub mod tolerance {
    /// Relative energy an impact may gain: round-off of the sums, the bound
    /// the fallback policy applies.
    pub const ENERGY_GAIN: f64 = 1e-9;
    /// Applied against recomputed velocities, over the speed scale.
    pub const IMPULSES: f64 = 1e-6;
    /// Largest overlap of two bodies beyond one step's closing and the soft
    /// contact's sag under its load ([`super::SoftSag`]), over the smaller
    /// one's least width (`SceneObservation::penetration_excess`): Rapier's
    /// soft contacts let a heavy body sink into a light one under load (mass
    /// ratios up to 10⁴ here), by the sag; 0.1 is twice the rows' 0.05 h.
    pub const PENETRATION: f64 = 0.1;
    /// Impact work of one frame at most for the soak (impulse steps ×
    /// contact points, summed over the frame's impacts); the scene family
    /// checks each scene against its own budget (`SolverSpec::max_work`).
    pub const FRAME_WORK: u64 = 200_000;
}

/// The frame budget a scene carries: its `max_work` (impulse steps ×
/// contact points per step), `None` if it sets none (then unchecked).
pub fn frame_budget(c: &SceneCombo) -> Option<u64> {
    c.scene.solver.max_work.max_work()
}

/// A topple run beyond the overlap tolerance or through the ground, but no
/// worse than native Rapier on the same scene: reported, not counted. For
/// the overlap, "no worse" reads [`SceneObservation::topple_depth`] against
/// [`SceneObservation::native_depth`] (a scene run again from nearby starts,
/// and by native Rapier as topple configures and steps it, when topple's run
/// was deeper: topple's shallowest against native's deepest).
pub fn within_native(c: &SceneCombo, o: &SceneObservation) -> bool {
    !c.engine.is_baseline()
        && o.native.is_some_and(|(_, through)| {
            (o.penetration_excess > tolerance::PENETRATION && !deeper_than_native(o))
                || (o.through_ground.is_some() && through)
        })
}

/// topple's overlap beyond the soft contact's sag is deeper than native
/// Rapier's on the same scene (from every nearby start, and than native
/// as topple configures and steps it, when the scene was run again); false
/// without a native run.
fn deeper_than_native(o: &SceneObservation) -> bool {
    o.native_depth().is_some_and(|n| o.topple_depth() > n)
}

/// The violations of one observed scene run.
pub fn scene_violations(c: &SceneCombo, o: &SceneObservation) -> Vec<Violation> {
    use tolerance::*;
    let a = &o.audit;
    let checks = [
        (
            Kind::NonFinite,
            (o.non_finite || a.non_finite > 0) as u8 as f64,
            0.0,
        ),
        (Kind::EnergyGain, a.energy_gain, ENERGY_GAIN),
        (Kind::Impulses, a.consistency, IMPULSES),
        // beyond the tolerance, and for topple deeper than native on the
        // same scene (from every nearby start tried)
        (
            Kind::Penetration,
            if o.native.is_some() && !deeper_than_native(o) {
                0.0
            } else {
                o.penetration_excess
            },
            PENETRATION,
        ),
        (
            Kind::ThroughGround,
            (o.through_ground.is_some() && !o.native.is_some_and(|n| n.1)) as u8 as f64,
            0.0,
        ),
        (
            Kind::FrameWork,
            o.worst_frame_work as f64,
            frame_budget(c).map_or(f64::INFINITY, |b| b as f64),
        ),
        (
            Kind::Repeat,
            o.repeat_hash.is_some_and(|h| h != o.hash) as u8 as f64,
            0.0,
        ),
        (Kind::Budget, o.over_budget as u8 as f64, 0.0),
        (Kind::Error, o.error.is_some() as u8 as f64, 0.0),
    ];
    checks
        .into_iter()
        .filter(|(_, v, tol)| v.is_nan() || *v > *tol)
        .map(|(kind, value, _)| Violation {
            combo: c.index,
            engine: match c.engine {
                SceneEngine::RapierF64 => StressEngine::RapierF64,
                SceneEngine::RapierF32 => StressEngine::RapierF32,
                SceneEngine::Native => StressEngine::Native,
            },
            kind,
            value,
            detail: describe(c, o),
        })
        .collect()
}

/// The depths of a scene's nearby runs, as a range per engine.
fn describe_nearby(n: &NearbyRuns) -> String {
    let range = |v: &[f64]| {
        let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        if v.is_empty() {
            "none ran".to_string()
        } else {
            format!("{lo:.3}–{hi:.3}")
        }
    };
    format!(
        "; from {} nearby starts: topple {}, native {}; native as topple configures and steps it {}",
        NEARBY_RUNS,
        range(&n.topple),
        range(&n.native),
        range(&n.native_as_topple)
    )
}

fn describe(c: &SceneCombo, o: &SceneObservation) -> String {
    format!(
        "{} {} {:?} of {} bodies, {:.3} units/m, dt 1/{:.0} s: {} frames, {} impacts ({} fallbacks), worst frame work {}, overlap beyond one step's closing {:.3} ({}){}{}{}{}",
        c.engine.name(),
        c.kind.name(),
        c.precision,
        c.scene.bodies.len(),
        c.unit,
        1.0 / c.scene.solver.dt,
        o.frames,
        o.impacts,
        o.fallbacks,
        o.worst_frame_work,
        o.penetration_excess,
        o.penetration_excess_at,
        o.native
            .map(|(p, t)| format!(", native: {p:.3}{}", if t { " and a centre below the ground" } else { "" }))
            .unwrap_or_default(),
        o.nearby.as_ref().map(describe_nearby).unwrap_or_default(),
        o.through_ground
            .as_deref()
            .map(|t| format!(", through the ground: {t}"))
            .unwrap_or_default(),
        o.error.as_deref().map(|e| format!(", error: {e}")).unwrap_or_default(),
    )
}

/// What a scene sweep found.
#[derive(Clone, Debug, Default)]
pub struct SceneSweepReport {
    /// Runs per engine.
    pub runs: BTreeMap<SceneEngine, usize>,
    /// Impacts checked.
    pub impacts: usize,
    /// Frames taken (first runs).
    pub frames: usize,
    /// Worst measures over all runs of topple's engines, per kind.
    pub worst: BTreeMap<Kind, f64>,
    /// Worst penetration, worst frame work and longest frame (s), per engine.
    pub per_engine: BTreeMap<SceneEngine, (f64, u64, f64)>,
    /// Every violation.
    pub violations: Vec<Violation>,
    /// CPU time of the longest scene (both runs, s).
    pub longest_run: f64,
    /// The scene and what it showed, when one alone was run.
    pub single: Option<(SceneCombo, SceneObservation)>,
    /// Topple runs beyond the overlap tolerance or through the ground but
    /// no worse than native Rapier on the same scene (not counted).
    pub within_native: usize,
    /// Bodies that tunnelled through the ground in one step's closing
    /// (reported, not counted), per engine.
    pub tunnelled: BTreeMap<SceneEngine, usize>,
    /// What the scenes covered: kinds, shapes, precisions, and the unit
    /// and time step ranges (min, max).
    pub coverage: Coverage,
}

/// What a sweep's scenes covered.
#[derive(Clone, Debug, Default)]
pub struct Coverage {
    /// Kinds drawn.
    pub kinds: Vec<SceneKind>,
    /// Shapes drawn (free bodies).
    pub shapes: Vec<&'static str>,
    /// Precisions drawn, per engine.
    pub precisions: Vec<(SceneEngine, crate::rapier::Precision)>,
    /// Units per metre, least and most.
    pub unit: Option<(f64, f64)>,
    /// Time steps (s), least and most.
    pub dt: Option<(f64, f64)>,
}

impl Coverage {
    fn add(&mut self, c: &SceneCombo) {
        if !self.kinds.contains(&c.kind) {
            self.kinds.push(c.kind);
        }
        for b in c.scene.bodies.iter().filter(|b| !b.fixed) {
            let name = match b.shape {
                crate::rapier::scene::ShapeKind::Ball => StressShape::Ball.name(),
                crate::rapier::scene::ShapeKind::Box => StressShape::Box.name(),
            };
            if !self.shapes.contains(&name) {
                self.shapes.push(name);
            }
        }
        if !self.precisions.contains(&(c.engine, c.precision)) {
            self.precisions.push((c.engine, c.precision));
        }
        let widen =
            |r: Option<(f64, f64)>, x: f64| Some(r.map_or((x, x), |r| (r.0.min(x), r.1.max(x))));
        self.unit = widen(self.unit, c.unit);
        self.dt = widen(self.dt, c.scene.solver.dt);
    }
}

impl SceneSweepReport {
    /// The violations of topple's engines: what the exit status counts.
    pub fn counted(&self) -> impl Iterator<Item = &Violation> {
        self.violations.iter().filter(|v| !v.engine.is_baseline())
    }

    /// The violations of the baseline (native Rapier).
    pub fn baseline(&self) -> impl Iterator<Item = &Violation> {
        self.violations.iter().filter(|v| v.engine.is_baseline())
    }
}

/// Runs scene `which` (all of the spec's if `None`); `progress` is called
/// after each scene.
pub fn scene_sweep(
    spec: &SceneSpec,
    which: Option<usize>,
    progress: impl Fn(&SceneCombo, &SceneObservation) + Sync,
) -> SceneSweepReport {
    let indices: Vec<usize> = match which {
        Some(i) => vec![i],
        None => (0..spec.scenes).collect(),
    };
    let observed: Vec<(SceneCombo, SceneObservation)> = indices
        .par_iter()
        .map(|&i| {
            let c = spec.draw(i);
            let o = run_scene_combo(&c, spec.budget);
            progress(&c, &o);
            (c, o)
        })
        .collect();
    let mut r = SceneSweepReport::default();
    for (c, o) in &observed {
        *r.runs.entry(c.engine).or_default() += 1;
        r.impacts += o.audit.impacts;
        r.frames += o.frames;
        r.longest_run = r.longest_run.max(o.cpu);
        r.coverage.add(c);
        r.within_native += within_native(c, o) as usize;
        *r.tunnelled.entry(c.engine).or_default() += o.tunnelled;
        let e = r.per_engine.entry(c.engine).or_insert((0.0, 0, 0.0));
        e.0 = e.0.max(o.penetration_excess);
        e.1 = e.1.max(o.worst_frame_work);
        e.2 = e.2.max(o.worst_frame_seconds);
        if !c.engine.is_baseline() {
            for (k, v) in [
                (Kind::EnergyGain, o.audit.energy_gain),
                (Kind::Impulses, o.audit.consistency),
                (Kind::Penetration, o.penetration_excess),
                (Kind::FrameWork, o.worst_frame_work as f64),
            ] {
                let w = r.worst.entry(k).or_insert(0.0);
                *w = w.max(v);
            }
        }
        r.violations.extend(scene_violations(c, o));
    }
    if which.is_some() {
        r.single = observed.into_iter().next();
    }
    r
}

/// The kinds the scene family checks, in the order of the table.
const SCENE_KINDS: [Kind; 9] = [
    Kind::NonFinite,
    Kind::EnergyGain,
    Kind::Impulses,
    Kind::Penetration,
    Kind::ThroughGround,
    Kind::FrameWork,
    Kind::Repeat,
    Kind::Budget,
    Kind::Error,
];

/// The table of a scene sweep (plain text).
pub fn scene_table(spec: &SceneSpec, r: &SceneSweepReport) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let total: usize = r.runs.values().sum();
    let shapes: Vec<&str> = SHAPES.iter().map(|s| s.name()).collect();
    let _ = writeln!(
        s,
        "scenes: seed {}  scenes {total}  frames {}  impacts checked {}  shapes {}",
        spec.seed,
        r.frames,
        r.impacts,
        shapes.join(", ")
    );
    let cov = &r.coverage;
    let kinds: Vec<&str> = cov.kinds.iter().map(|k| k.name()).collect();
    let precisions: Vec<String> = cov
        .precisions
        .iter()
        .map(|(e, p)| format!("{} {p:?}", e.name()))
        .collect();
    let (u, d) = (cov.unit.unwrap_or_default(), cov.dt.unwrap_or_default());
    let _ = writeln!(
        s,
        "covered: {}; shapes {}; {}; {:.2} to {:.1} units/m; dt 1/{:.0} to 1/{:.0} s",
        kinds.join(", "),
        cov.shapes.join(", "),
        precisions.join(", "),
        u.0,
        u.1,
        1.0 / d.0.max(f64::MIN_POSITIVE),
        1.0 / d.1.max(f64::MIN_POSITIVE),
    );
    let _ = writeln!(
        s,
        "longest scene {:.1} s of CPU (budget {} s of CPU per run, two runs each and native once)",
        r.longest_run, spec.budget
    );
    let _ = writeln!(
        s,
        "{:<11} {:>5} {:>10} {:>12} {:>16} {:>14}",
        "engine", "runs", "violations", "penetration", "worst frame work", "longest frame"
    );
    for (e, n) in &r.runs {
        let count = r
            .violations
            .iter()
            .filter(|v| v.engine.name() == e.name())
            .count();
        let (pen, work, secs) = r.per_engine.get(e).copied().unwrap_or_default();
        let _ = writeln!(
            s,
            "{:<11} {n:>5} {count:>10} {pen:>12.3e} {work:>16} {:>12.1} ms{}",
            e.name(),
            1e3 * secs,
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
    for kind in SCENE_KINDS {
        let count = r.counted().filter(|v| v.kind == kind).count();
        let base = r.baseline().filter(|v| v.kind == kind).count();
        let worst = r
            .worst
            .get(&kind)
            .map(|w| format!("{w:.3e}"))
            .unwrap_or_else(|| "-".into());
        let tol = match kind {
            Kind::EnergyGain => format!("{:.0e}", tolerance::ENERGY_GAIN),
            Kind::Impulses => format!("{:.0e}", tolerance::IMPULSES),
            Kind::Penetration => format!(
                "{} of the least width beyond one step's closing and the soft contact's sag, and for topple deeper than native as drawn and as topple steps it",
                tolerance::PENETRATION
            ),
            Kind::ThroughGround => "centre below the ground unless one step's closing reaches it, and for topple not in native".into(),
            Kind::FrameWork => "the scene's max_work (steps × contacts per step)".into(),
            _ => "0".into(),
        };
        let _ = writeln!(
            s,
            "{:<24} {count:>10} {base:>10} {worst:>12}  {tol}",
            kind.name()
        );
    }
    let worst_of = |v: &mut dyn Iterator<Item = &Violation>| -> Option<Violation> {
        v.min_by(|a, b| a.kind.cmp(&b.kind).then(b.value.total_cmp(&a.value)))
            .cloned()
    };
    let tunnelled: Vec<String> = r
        .tunnelled
        .iter()
        .map(|(e, n)| format!("{} {n}", e.name()))
        .collect();
    let _ = writeln!(
        s,
        "not counted: {} topple runs beyond the overlap tolerance or through the ground but no worse than native on the same scene; body-frames below the ground within one step's closing (tunnelling): {}",
        r.within_native,
        tunnelled.join(", ")
    );
    if let Some(v) = worst_of(&mut r.counted()) {
        let _ = writeln!(
            s,
            "worst: {} = {:.3e} in scene {}: {}",
            v.kind.name(),
            v.value,
            v.combo,
            v.detail
        );
        let _ = writeln!(
            s,
            "reproduce: topple stress --family scenes --seed {} --combo {}{}",
            spec.seed,
            v.combo,
            if spec.full { " --full" } else { "" }
        );
    } else {
        let _ = writeln!(s, "no violations in topple's engines");
    }
    if let Some(v) = worst_of(&mut r.baseline()) {
        let _ = writeln!(
            s,
            "baseline worst: {} = {:.3e} in scene {}",
            v.kind.name(),
            v.value,
            v.combo
        );
    }
    s
}
