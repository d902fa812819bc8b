//! The soak (`topple stress --family soak`): one scene run for a long time
//! in one Rapier world through topple, put back to its start every cycle as
//! a game's domino show would be, with the scene family's invariants every
//! frame, twice side by side for the bits, and the memory sampled at the end
//! of every cycle.

use crate::rapier::scene::{ImpactResponse, Scene};
use crate::rapier::Precision;

use super::scene::run::{run_with, Hooks};
use super::scene::SceneObservation;

/// How a soak runs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SoakSpec {
    /// Frames (steps of the scene's `solver.dt`).
    pub frames: usize,
    /// The scene is put back to its start every this many seconds of
    /// simulated time.
    pub cycle: f64,
    /// The Rapier build.
    pub precision: Precision,
    /// Budget of each run (s of CPU time of the thread that runs it).
    pub budget: f64,
}

impl Default for SoakSpec {
    /// 10⁵ frames, a reset every 10 s, the f32 build (a game's), an hour.
    fn default() -> Self {
        SoakSpec {
            frames: 100_000,
            cycle: 10.0,
            precision: Precision::F32,
            budget: 3600.0,
        }
    }
}

/// What a soak showed.
#[derive(Clone, Debug, Default)]
pub struct SoakReport {
    /// The first run, watched (the scene family's measures).
    pub seen: SceneObservation,
    /// The hash of the second run (equal to `seen.hash` when deterministic).
    pub repeat_hash: Option<u64>,
    /// Cycles run (resets + 1).
    pub cycles: usize,
    /// Memory at the end of each cycle (bytes, from `memory`), first run.
    pub memory: Vec<u64>,
    /// Wall-clock time of the two runs side by side (s).
    pub wall: f64,
}

impl SoakReport {
    /// Growth of the memory from the end of the second cycle (the buffers
    /// have grown to their size by then) to the end of the last (bytes);
    /// `None` with fewer than three samples.
    pub fn memory_growth(&self) -> Option<i64> {
        let (first, last) = (self.memory.get(1)?, self.memory.last()?);
        (self.memory.len() >= 3).then(|| *last as i64 - *first as i64)
    }
}

/// Runs `scene` with topple for `spec.frames` frames, twice at once; the
/// first run samples `memory()` (bytes, e.g. the resident set or the live
/// heap) at the end of every cycle.
///
/// ```no_run
/// use topple::rapier::scene::Scene;
/// use topple::stress::soak::{soak, SoakSpec};
/// let scene: Scene = toml::from_str(r#"
///     duration = 1.0
///     [solver]
///     dt = 0.0166667
///     [row]
///     preset = "T"
///     n = 20
///     spacing = 0.35
/// "#).unwrap();
/// let r = soak(&scene, &SoakSpec { frames: 6000, ..SoakSpec::default() }, || None);
/// assert!(!r.seen.non_finite && r.repeat_hash == Some(r.seen.hash));
/// ```
pub fn soak(scene: &Scene, spec: &SoakSpec, memory: impl Fn() -> Option<u64> + Sync) -> SoakReport {
    let start = std::time::Instant::now();
    let per_cycle = ((spec.cycle / scene.solver.dt).round() as usize).max(1);
    let one = |sample: bool| {
        let mut samples = Vec::new();
        let mut cycles = 1;
        let mut reset = |frame: usize, _energy: f64| {
            let end = (frame + 1).is_multiple_of(per_cycle);
            if end {
                if sample && let Some(m) = memory() {
                    samples.push(m);
                }
                cycles += 1;
            }
            end
        };
        let mut hooks = Hooks {
            watch: sample,
            budget: spec.budget,
            frames: spec.frames,
            reset: Some(&mut reset),
        };
        let seen = run_with(scene, ImpactResponse::Topple, spec.precision, &mut hooks);
        (seen, samples, cycles)
    };
    let ((seen, memory, cycles), (again, _, _)) = crate::par::join(|| one(true), || one(false));
    SoakReport {
        repeat_hash: (!again.over_budget && again.error.is_none()).then_some(again.hash),
        seen,
        cycles,
        memory,
        wall: start.elapsed().as_secs_f64(),
    }
}

/// The resident set of this process (bytes), from `/proc/self/statm`
/// (Linux); `None` elsewhere.
pub fn resident_bytes() -> Option<u64> {
    let statm = std::fs::read_to_string("/proc/self/statm").ok()?;
    let pages: u64 = statm.split_whitespace().nth(1)?.parse().ok()?;
    Some(pages * 4096)
}
