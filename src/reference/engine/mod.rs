//! The reference engine's driver, in named stages: the smooth phase
//! integrated with the contact mode held fixed, events located inside steps
//! (contact closing, lift-off, stick ↔ slip, slip reversal), impacts resolved
//! through the coupling layer's LZB → held → plastic policy, and the
//! time-varying set of moving blocks (the paper's κ, Sec. 2.1): blocks ahead
//! of the wave stand frozen until struck, blocks at rest behind it are frozen
//! until touched.
//!
//! [`Engine`]'s state is private to this folder; each file extends its impl
//! with one stage, in the order a step runs them:
//!
//! | file | stage |
//! | --- | --- |
//! | `integrate.rs` | one step of the smooth phase (Heun or Dormand–Prince), shortened to the first event by bisection |
//! | `events.rs` | what happened in a step (contacts closing, lift-off, stick ↔ slip, slip reversal) and the response: impacts, then the contact mode |
//! | `impacts.rs` | one impact: the approaching contacts, the group they start, the LZB solve through [`crate::coupling::GroupSolver`] |
//! | `active.rs` | the active set: the mode search among closed contacts and the projection onto the active constraints |
//! | `window.rs` | the moving blocks lo..hi: their state vector, the candidate slots, waking and freezing |
//! | `scan.rs` | lower bounds on the candidates' gaps, so that the event scan measures only those that can have closed |
//! | `record.rs` | hits, rebounds, series, snapshots and the final report |
//!
//! The stage files import from this file and the leaf modules of
//! `reference` (geometry, dynamics, modes, stepper), never from each other.

use std::cell::RefCell;
use std::time::Instant;

use super::dynamics::{Active, Dynamics, Mode, RowConst};
use super::geometry::{slots_per_block, Geom};
use super::modes::{Candidate, ModeTol};
use super::settings::Settings;
use super::snapshot::Snapshot;
use super::stepper::Stages;
use crate::coupling::{FallbackPolicy, GroupSolver};
use crate::domino::{BlockSeries, ChainReport, EnergyReport, RowSpec};
use crate::impact::{Body, Contact, ImpactOutcome, ImpactSettings, StepControl};

mod active;
mod events;
mod impacts;
mod integrate;
mod record;
mod scan;
mod window;

/// Why a run failed.
#[derive(Debug, thiserror::Error)]
pub enum EngineError {
    /// The row is not usable: the field, its value and the allowed range.
    #[error("invalid row: {0}")]
    InvalidRow(crate::input::InputError),
    /// The impact resolver refused an impact's input (a non-finite state).
    #[error("impact at t = {time} s: {source}")]
    Impact {
        /// Time (s).
        time: f64,
        /// The resolver's error.
        source: crate::impact::ImpactError,
    },
    /// The contact equations became singular or the state non-finite.
    #[error("the smooth phase failed at t = {0} s (singular contact system)")]
    Singular(f64),
    /// A start state ([`run_from`]) without one finite pose and velocity
    /// per block of the row.
    #[error(
        "start state: {poses} poses and {velocities} velocities for {blocks} blocks, or not finite"
    )]
    InvalidStart {
        /// Blocks in the row.
        blocks: usize,
        /// Poses given.
        poses: usize,
        /// Velocities given.
        velocities: usize,
    },
}

/// The result of a run.
#[derive(Clone, Debug)]
pub struct RunResult {
    /// The engine-independent report (hit times, speeds, energy, …).
    pub report: ChainReport,
    /// The snapshots asked for.
    pub snapshots: Vec<Snapshot>,
    /// Accepted time steps.
    pub steps: usize,
    /// Right-hand-side evaluations (contact-force solves).
    pub evaluations: usize,
}

/// Scratch of the impact stage (`impacts.rs`), kept between impacts so that
/// a long row allocates nothing per impact once it has grown.
#[derive(Debug, Default)]
struct ImpactBuffers {
    /// Closed contacts approaching faster than the approach tolerance.
    approaching: Vec<(usize, usize)>,
    /// Every closed contact of the window: (block, slot) and its geometry,
    /// in the order of `for_each_slot`.
    closed: Vec<(usize, usize, Geom)>,
    /// `closed` holds the closed contacts at the present positions and
    /// window: an impact changes velocities only, so the scans after it
    /// (the next impact's search, its group) need not measure every slot
    /// again. Cleared by `handle_events` (the positions have moved since)
    /// and when the window grows.
    closed_known: bool,
    /// Window block b linked to b + 1 by a closed contact.
    linked: Vec<bool>,
    /// Window blocks (a, b), not neighbours, linked by a closed contact.
    far_links: Vec<(usize, usize)>,
    /// Window block b takes part in the impact.
    in_group: Vec<bool>,
    /// Window block b → its index among `bodies`.
    index: Vec<Option<usize>>,
    bodies: Vec<Body>,
    /// Row index of each of `bodies`.
    members: Vec<usize>,
    contacts: Vec<Contact>,
    outcome: ImpactOutcome,
}

/// Which contacts (block, slot) are active: a flag per slot of the
/// neighbour pairs and the ground, and the few slots between blocks that
/// are not neighbours (`geometry::far_slot`) in a list.
#[derive(Debug, Default)]
struct ActiveSlots {
    /// Slots per block with a flag ([`slots_per_block`]).
    k_slots: usize,
    near: Vec<bool>,
    far: Vec<(usize, usize)>,
}

impl ActiveSlots {
    fn new(n: usize, k_slots: usize) -> Self {
        ActiveSlots {
            k_slots,
            near: vec![false; n * k_slots],
            far: Vec::new(),
        }
    }

    #[inline]
    fn contains(&self, block: usize, slot: usize) -> bool {
        if slot < self.k_slots {
            self.near[block * self.k_slots + slot]
        } else {
            self.far.contains(&(block, slot))
        }
    }

    fn set(&mut self, block: usize, slot: usize, on: bool) {
        if slot < self.k_slots {
            self.near[block * self.k_slots + slot] = on;
        } else if on {
            self.far.push((block, slot));
        } else {
            self.far.retain(|&e| e != (block, slot));
        }
    }
}

/// One event condition of a step (`events.rs`), followed while the step is
/// shortened to the event (`integrate.rs`): lift-off, stick → slip or slip
/// reversal of active contact c, or candidate (block, slot) closing.
#[derive(Clone, Copy, Debug, PartialEq)]
enum EventKey {
    Lift(usize),
    Stick(usize),
    Slide(usize),
    Close(usize, usize),
}

/// What `events_at` tells the event location besides whether an event
/// happened: the first condition it found violated, with its margin, and
/// the margin of the condition being followed (`watch`), if it could be
/// measured. A margin is the condition's value past its threshold in units
/// of its tolerance (force, velocity or gap): > 0 exactly where the
/// condition calls an event.
#[derive(Debug, Default)]
struct EventProbe {
    watch: Option<EventKey>,
    first: Option<(EventKey, f64)>,
    watched: Option<f64>,
}

/// The broad phase of the pairs of blocks that are not neighbours
/// (`window.rs`): blocks are sorted along the row, and a block can only
/// touch one whose extent along x overlaps its own.
#[derive(Debug, Default)]
struct Reach {
    /// The frozen blocks k < lo behind the window: the x extent (left,
    /// right) of each and the running maximum of the right ends over
    /// 0..=k (m), which says how far back a moving block can reach.
    behind: Vec<[f64; 3]>,
    /// Scratch of `for_each_slot`: per block from lo on (the window and
    /// the untouched blocks ahead it can reach), the x extent (left,
    /// right) and the least left end from that block on (m).
    extents: RefCell<Vec<[f64; 3]>>,
}

/// The state of a running simulation. Private to the stage files of this
/// folder; the rest of the crate runs it through [`run`].
struct Engine {
    rc: RowConst,
    row: RowSpec,
    s: Settings,
    // --- window (`window.rs`)
    /// Configuration and velocity of every block (window blocks: see `y`).
    pos: Vec<[f64; 3]>,
    vel: Vec<[f64; 3]>,
    /// Moving blocks lo..hi.
    lo: usize,
    hi: usize,
    /// Window state (6 per block) + the contact work accumulator.
    y: Vec<f64>,
    // --- integration (`integrate.rs`)
    /// Time (s).
    t: f64,
    k0: Vec<f64>,
    y1: Vec<f64>,
    ybest: Vec<f64>,
    stages: Stages,
    h_adapt: f64,
    steps: usize,
    evaluations: usize,
    // --- active set (`active.rs`)
    dynamics: Dynamics,
    active: Vec<Active>,
    is_active: ActiveSlots,
    candidates: Vec<Candidate>,
    mode_state: Vec<Option<Mode>>,
    new_active: Vec<Active>,
    // --- events (`events.rs`): references per active contact at the step start
    ref_fn: Vec<f64>,
    ref_stick: Vec<f64>,
    ref_slide: Vec<f64>,
    /// Time (s) of the last impact, and how many `handle_events` calls in a
    /// row have found an impact at that same instant.
    last_impact_time: f64,
    impacts_at_this_instant: usize,
    /// The last mode search let a sliding contact press without friction
    /// (`modes::Search::Frictionless`): the search runs again after every
    /// step until it ends otherwise.
    mode_unsettled: bool,
    probe: EventProbe,
    /// Bounds on the gaps of the window's candidate slots (`scan.rs`).
    gap_bounds: scan::GapBounds,
    /// F_n, F_t (N) and v_t (m/s) of each active contact at the step start
    /// (`eval_k0`): the event margins there, for the event location.
    start_forces: Vec<[f64; 3]>,
    // --- impacts (`impacts.rs`)
    solver: GroupSolver,
    /// The resolver's settings: `Settings::impact` with its rest speed
    /// raised to the approach that starts an impact (`v_app`).
    impact: ImpactSettings,
    policy: FallbackPolicy,
    impact_buffers: ImpactBuffers,
    // --- broad phase of the far pairs (`window.rs`)
    reach: Reach,
    // --- tolerances in SI
    eps_gap: f64,
    v_tol: f64,
    v_app: f64,
    tol: ModeTol,
    // --- records (`record.rs`)
    hit: Vec<Option<f64>>,
    energy: EnergyReport,
    max_penetration: f64,
    impacts: usize,
    impact_fallbacks: usize,
    held_impacts: usize,
    reversed: Vec<bool>,
    series: Vec<BlockSeries>,
    next_sample: f64,
    snapshots: Vec<Snapshot>,
    next_snapshot: usize,
}

impl Engine {
    fn new(row: &RowSpec, settings: &Settings) -> Result<Engine, EngineError> {
        row.validate().map_err(EngineError::InvalidRow)?;
        let p = row.params;
        let n = row.n;
        let rc = RowConst::new(p, n);
        let k_slots = slots_per_block(p.lambda_points);
        let mut pos = Vec::with_capacity(n);
        for i in 0..n {
            let c = row.centre(i);
            pos.push([c[0], c[1], 0.0]);
        }
        let mut vel = vec![[0.0; 3]; n];
        let (v0, w0) = row.initial_velocity();
        vel[0] = [v0[0], v0[1], w0];
        let vbar = p.speed_scale();
        let m = p.block.mass;
        let mut e = Engine {
            rc,
            row: *row,
            s: settings.clone(),
            pos,
            vel,
            lo: 0,
            hi: 1,
            y: Vec::new(),
            k0: Vec::new(),
            y1: Vec::new(),
            ybest: Vec::new(),
            t: 0.0,
            active: Vec::new(),
            is_active: ActiveSlots::new(n, k_slots),
            reach: Reach::default(),
            dynamics: Dynamics::default(),
            stages: Stages::default(),
            solver: GroupSolver::default(),
            impact: impact_settings(settings, vbar),
            policy: impact_policy(settings),
            impact_buffers: ImpactBuffers::default(),
            hit: vec![None; n],
            energy: EnergyReport::default(),
            max_penetration: 0.0,
            impacts: 0,
            impact_fallbacks: 0,
            held_impacts: 0,
            reversed: vec![false; n],
            last_impact_time: f64::NEG_INFINITY,
            impacts_at_this_instant: 0,
            mode_unsettled: false,
            probe: EventProbe::default(),
            gap_bounds: scan::GapBounds::new(k_slots, p.block.height, p.block.thickness),
            start_forces: Vec::new(),
            steps: 0,
            evaluations: 0,
            ref_fn: Vec::new(),
            ref_stick: Vec::new(),
            ref_slide: Vec::new(),
            candidates: Vec::new(),
            mode_state: Vec::new(),
            new_active: Vec::new(),
            eps_gap: settings.gap_tolerance * p.block.height,
            v_tol: settings.velocity_tolerance * vbar,
            v_app: settings.approach_tolerance * vbar,
            tol: ModeTol {
                force: 1e-9 * m * p.gravity,
                accel: 1e-9 * p.gravity,
                velocity: settings.velocity_tolerance * vbar,
            },
            series: settings
                .series_blocks
                .iter()
                .map(|&b| BlockSeries {
                    block: b,
                    ..Default::default()
                })
                .collect(),
            next_sample: 0.0,
            snapshots: Vec::new(),
            next_snapshot: 0,
            h_adapt: 1e-4,
        };
        e.hit[0] = Some(0.0);
        e.sync_in();
        e.energy.initial = e.total_energy();
        Ok(e)
    }
}

/// The resolver's settings for the row: `Settings::impact` with its rest
/// speed (m/s) raised to half the engine's own impact threshold
/// `approach_tolerance · √(gh)` (`vbar`, m/s): a contact approaching slower
/// than the threshold does not start an impact, so an impact may end once
/// nothing approaches much faster (docs/model.md §9). Without it, two
/// blocks wedged between opposite faces (a Table 1 T row at s/h 0.5)
/// bounced between those faces in ever shorter cycles (e = 0.62) until the
/// step limit, and the impact ended plastic.
///
/// Half, not all of it ([`REST_SPEED_SHARE`]): the resolver's normal rate
/// and the engine's gap rate agree only to rounding, so an impact the
/// resolver ended at the threshold could be an impact again to the engine
/// at once. In the stress sweep's combination 2800 (seed 1) two blocks
/// leaning top to top were handed the same impact 884,125 times: each
/// ended "at rest" 10⁻¹¹ m/s under the threshold and started again a
/// rounding over it.
///
/// Only for the time-domain resolver: the paper's fixed impulse step and
/// the adaptive impulse stepping follow the paper's law to its end, as
/// they did before (with the rest speed, the converged no-slip row at s/h
/// 0.6 of tests/reference/ground.rs, paper's fixed step and freeze
/// tolerance 10⁻⁴, went from 20 s to more than 6 min: the slow approaches
/// the impacts left kept the smooth phase at its smallest steps).
/// The share of the engine's impact threshold below which the resolver
/// calls an impact at rest (see [`impact_settings`]).
const REST_SPEED_SHARE: f64 = 0.5;

fn impact_settings(settings: &Settings, vbar: f64) -> ImpactSettings {
    let in_time = matches!(settings.impact.step_control, StepControl::Adaptive { .. });
    if !in_time {
        return settings.impact;
    }
    ImpactSettings {
        rest_speed: settings
            .impact
            .rest_speed
            .max(REST_SPEED_SHARE * settings.approach_tolerance * vbar),
        ..settings.impact
    }
}

/// The fallback policy with the reference's own budgets: the held retry
/// after `held_retry_after` resolver steps, every attempt within the
/// resolver's step limit.
/// Any other budget of the policy stays at its default.
#[allow(clippy::needless_update)] // the policy may gain budgets
fn impact_policy(settings: &Settings) -> FallbackPolicy {
    FallbackPolicy {
        held_retry_after: settings.held_retry_after,
        max_steps: settings.impact.max_steps,
        ..FallbackPolicy::default()
    }
}

/// Runs the reference engine on a row.
///
/// ```no_run
/// use topple::domino::{Preset, RowSpec};
/// use topple::reference::{run, Settings};
/// let p = Preset::T.params().ideal();
/// let row = RowSpec::new(p, 0.35 * p.block.height, 30, 1.0);
/// let out = run(&row, &Settings::default()).unwrap();
/// println!("v_na = {:?}", out.report.natural_speed);
/// ```
pub fn run(row: &RowSpec, settings: &Settings) -> Result<RunResult, EngineError> {
    run_with_progress(row, settings, |_| {})
}

/// [`run`], calling `progress` with the number of blocks hit so far each time
/// the wave reaches another block (for a progress bar on long rows).
///
/// ```
/// use topple::domino::{Preset, RowSpec};
/// use topple::reference::{run_with_progress, Settings};
/// let p = Preset::T.params().ideal();
/// let row = RowSpec::new(p, 0.5 * p.block.height, 4, 1.0);
/// let mut seen = Vec::new();
/// let out = run_with_progress(&row, &Settings::default(), |hit| seen.push(hit)).unwrap();
/// assert_eq!(seen, (1..=out.report.hit_times.len()).collect::<Vec<_>>());
/// ```
pub fn run_with_progress(
    row: &RowSpec,
    settings: &Settings,
    progress: impl FnMut(usize),
) -> Result<RunResult, EngineError> {
    let start = Instant::now();
    let e = Engine::new(row, settings)?;
    drive(e, row, settings, start, progress)
}

/// Runs the reference engine on the blocks of `row` from a state of one's
/// own: `poses[i]` = (x, y, φ) of block i (m, m, rad; y of its centre above
/// the ground, φ counter-clockwise, 0 standing) and `velocities[i]` =
/// (ẋ, ẏ, ω) (m/s, m/s, rad/s). Every block starts moving; `row`'s spacing
/// and push are not used. Blocks must not overlap at the start.
///
/// ```
/// use topple::domino::{Preset, RowSpec};
/// use topple::reference::{run_from, Settings};
/// let p = Preset::T.params();
/// let (h, d) = (p.block.height, p.block.thickness);
/// let row = RowSpec::new(p, 0.5 * h, 2, 1.0);
/// // a block lying on its face, and one standing 2 h away, both at rest
/// let poses = [[0.0, 0.5 * d, -std::f64::consts::FRAC_PI_2], [2.0 * h, 0.5 * h, 0.0]];
/// let settings = Settings { t_max: Some(0.05), ..Settings::default() };
/// let out = run_from(&row, &settings, &poses, &[[0.0; 3]; 2]).unwrap();
/// assert!(out.report.max_penetration.unwrap() < 1e-6 * h);
/// ```
pub fn run_from(
    row: &RowSpec,
    settings: &Settings,
    poses: &[[f64; 3]],
    velocities: &[[f64; 3]],
) -> Result<RunResult, EngineError> {
    let start = Instant::now();
    let n = row.n;
    let finite = |v: &[[f64; 3]]| v.iter().flatten().all(|x| x.is_finite());
    if poses.len() != n || velocities.len() != n || !finite(poses) || !finite(velocities) {
        return Err(EngineError::InvalidStart {
            blocks: n,
            poses: poses.len(),
            velocities: velocities.len(),
        });
    }
    let mut e = Engine::new(row, settings)?;
    e.pos.copy_from_slice(poses);
    e.vel.copy_from_slice(velocities);
    e.lo = 0;
    e.hi = n;
    e.sync_in();
    e.energy.initial = e.total_energy();
    drive(e, row, settings, start, |_| {})
}

/// The run loop: the first events, then steps until the window is empty,
/// the end time, the last hit (if asked) or a budget.
fn drive(
    mut e: Engine,
    row: &RowSpec,
    settings: &Settings,
    start: Instant,
    mut progress: impl FnMut(usize),
) -> Result<RunResult, EngineError> {
    let t_max = settings
        .t_max
        .unwrap_or(40.0 * row.params.time_scale() * (row.n as f64 + 5.0));
    e.handle_events()?;
    e.record();
    let mut stopped_early = false;
    let mut hits_seen = 0;
    let cpu = crate::clock::CpuWatch::start();
    while e.lo < e.hi && e.t < t_max {
        if settings.stop_at_last_hit
            && e.hit[row.n - 1].is_some_and(|t| e.t >= t + settings.after_last_hit)
        {
            break;
        }
        if settings.max_steps.is_some_and(|m| e.steps >= m) {
            stopped_early = true;
            break;
        }
        if let Some(limit) = settings.wall_time_limit
            && start.elapsed().as_secs_f64() > limit
        {
            stopped_early = true;
            break;
        }
        if settings.cpu_time_limit.is_some_and(|l| cpu.seconds() >= l) {
            stopped_early = true;
            break;
        }
        e.advance(t_max)?;
        while hits_seen < row.n && e.hit[hits_seen].is_some() {
            hits_seen += 1;
            progress(hits_seen);
        }
    }
    Ok(e.finish(start, stopped_early))
}
