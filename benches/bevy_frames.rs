//! Frame time of scenes a Bevy game builds, native bevy_rapier against
//! topple, measured in one run (headless apps, 1/60 s per frame, topple's
//! default settings):
//!
//! - a box pyramid standing at rest (pixel units, `TopplePlugin::default()`);
//! - a pile of boxes dropped in layers (pixel units);
//! - balls, boxes, capsules and convex polygons dropped in a bin (pixels);
//! - the ideal Domino T row of 1,000 blocks at s/h 0.45 (metres);
//! - `domino_show` with 16 fronts at once (pixel units).
//!
//! ```text
//! cargo bench --features bevy --bench bevy_frames
//! cargo bench --features bevy --bench bevy_frames -- pyramid pile   # some scenes
//! cargo bench --features bevy --bench bevy_frames -- --tolerance=1e-4 # time-domain resolver at 10⁻⁴
//! cargo bench --features bevy --bench bevy_frames -- --impulse=1e-4   # adaptive impulse stepping
//! ```
//!
//! Prints per scene and engine the mean and worst frame (whole `update()`)
//! and how many frames took longer than 1/60 s, topple's share, topple's
//! Rapier steps per frame (sub-steps and splits; native takes one), and
//! what topple did (impacts, of them solved side by side with others of
//! their step, fallbacks, steps whose
//! work budget ran out, pairs left to Rapier), and per scene whether any
//! body's state became NaN and how far the lowest body reached below the
//! ground's top face. A second table gives the CPU time of the process per
//! frame (`CLOCK_PROCESS_CPUTIME_ID`, all of Bevy's threads), mean and
//! worst, for both engines: on a loaded machine wall-clock frames stretch
//! with the load, CPU time much less; and the wall time of the physics step
//! alone per frame (`ToppleFrameStats::step_seconds`: bevy_rapier's step in
//! the native app, topple's whole step with its Rapier pieces in topple's),
//! which leaves out Bevy's schedule around it. On an idle virtual machine a
//! frame's wall time holds the wake-ups of Bevy's executor threads, which
//! cost more than a small scene's physics (docs/bevy.md, "The merged code
//! of round thirteen, and what a frame ratio measures"); the physics
//! step's ratio does not.

#[path = "../examples/common/scenes.rs"]
mod scenes;

use std::time::Instant;

use bevy::prelude::*;
use bevy_rapier2d::prelude::*;
use scenes::Target;
use topple::bevy::{headless_row_app, DominoRow, ImpactResponse, ToppleFrameStats, ToppleImpact};
use topple::coupling::Resolution;
use topple::domino::{Preset, RowSpec};

#[path = "../examples/common/show.rs"]
mod show;

struct Run {
    mean_ms: f64,
    worst_ms: f64,
    /// CPU time of the process per frame, mean and worst (ms).
    cpu_mean_ms: f64,
    cpu_worst_ms: f64,
    /// Frames longer than 1/60 s.
    slow: usize,
    topple_ms: f64,
    /// Wall time of the physics step system per frame (ms): bevy_rapier's
    /// step for native, topple's whole step (Rapier's pieces included) for
    /// topple; Bevy's schedule around it is left out.
    step_ms: f64,
    /// Rapier steps per frame (topple's sub-steps and splits; native's
    /// bevy_rapier step is not counted here: one a frame at `Fixed`).
    rapier_steps: f64,
    impacts: u64,
    fallbacks: u64,
    /// Of the fallbacks, large groups (`FallbackPolicy::large_group`).
    large_fallbacks: u64,
    /// Impacts solved side by side with others of the same physics step.
    batched: u64,
    budget_spent: u64,
    native_impacts: u64,
    nan: bool,
    /// Lowest point of a body's bounding box below the ground's top (px or m).
    below_ground: f32,
}

/// Runs `frames` updates, timing each.
fn measure(app: &mut App, frames: usize, ground_y: f32) -> Run {
    let mut run = Run {
        mean_ms: 0.0,
        worst_ms: 0.0,
        cpu_mean_ms: 0.0,
        cpu_worst_ms: 0.0,
        slow: 0,
        topple_ms: 0.0,
        step_ms: 0.0,
        rapier_steps: 0.0,
        impacts: 0,
        fallbacks: 0,
        large_fallbacks: 0,
        batched: 0,
        budget_spent: 0,
        native_impacts: 0,
        nan: false,
        below_ground: 0.0,
    };
    let start = Instant::now();
    let cpu_start = process_cpu_ms();
    for frame in 0..frames {
        let t = Instant::now();
        let cpu = process_cpu_ms();
        app.update();
        let ms = 1e3 * t.elapsed().as_secs_f64();
        run.cpu_worst_ms = run.cpu_worst_ms.max(process_cpu_ms() - cpu);
        if std::env::var("FRAMES_VERBOSE").is_ok() {
            let s = app.world().resource::<ToppleFrameStats>();
            eprintln!(
                "frame {frame}: {ms:.2} ms, topple {:.2} ms, rapier steps {}, impacts {} (batched {}), fallbacks {} (large {}), work {}, spent {}: {}",
                1e3 * s.topple_seconds,
                s.rapier_steps,
                s.impacts,
                s.batched_impacts,
                s.fallbacks,
                s.large_group_fallbacks,
                s.work,
                s.budget_spent,
                impacts_of_frame(app)
            );
        }
        run.worst_ms = run.worst_ms.max(ms);
        run.slow += usize::from(ms > 1e3 / 60.0);
        let s = app.world().resource::<ToppleFrameStats>();
        run.topple_ms += 1e3 * s.topple_seconds;
        run.step_ms += 1e3 * s.step_seconds;
        run.rapier_steps += s.rapier_steps as f64;
        run.impacts += s.impacts;
        run.fallbacks += s.fallbacks;
        run.large_fallbacks += s.large_group_fallbacks;
        run.batched += s.batched_impacts;
        run.budget_spent += s.budget_spent;
        run.native_impacts += s.native_impacts;
    }
    run.mean_ms = 1e3 * start.elapsed().as_secs_f64() / frames as f64;
    run.cpu_mean_ms = (process_cpu_ms() - cpu_start) / frames as f64;
    run.topple_ms /= frames as f64;
    run.step_ms /= frames as f64;
    run.rapier_steps /= frames as f64;
    let world = app.world_mut();
    let mut q = world.query_filtered::<(&Transform, &Velocity, &Collider), With<RigidBody>>();
    for (t, v, c) in q.iter(world) {
        run.nan |= !(t.translation.is_finite() && v.linear.is_finite() && v.angular.is_finite());
        let aabb = c.raw.compute_aabb(&bevy_rapier2d::rapier::math::Pose::new(
            t.translation.truncate(),
            t.rotation.to_euler(EulerRot::ZYX).0,
        ));
        run.below_ground = run.below_ground.max(ground_y - aabb.mins.y);
    }
    run
}

/// The impacts of the last frame, one word each: free bodies `b`, contact
/// points `c`, resolver steps `s` and how it ended (`L` the law, `H` held,
/// `P` plastic, `R` rejected), e.g. `4b12c180sL`.
fn impacts_of_frame(app: &App) -> String {
    let Some(messages) = app.world().get_resource::<Messages<ToppleImpact>>() else {
        return String::new();
    };
    let mut words = Vec::new();
    for m in messages.iter_current_update_messages() {
        let r = &m.report;
        let how = match r.resolution {
            Resolution::Lzb => 'L',
            Resolution::Held => 'H',
            Resolution::Plastic => 'P',
            Resolution::Rejected => 'R',
        };
        words.push(format!("{}b{}c{}s{how}", r.bodies, r.contacts, r.steps));
    }
    words.join(" ")
}

/// CPU time the process has used (ms), every thread's (NaN where there
/// is no such clock).
#[cfg(not(unix))]
fn process_cpu_ms() -> f64 {
    f64::NAN
}

/// CPU time the process has used (ms), every thread's.
#[cfg(unix)]
fn process_cpu_ms() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid timespec for the call to write.
    let ok = unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut ts) } == 0;
    if ok {
        ts.tv_sec as f64 * 1e3 + ts.tv_nsec as f64 * 1e-6
    } else {
        f64::NAN
    }
}

/// The value of `--NAME=VALUE` on the command line, if given. Flags:
/// `--budget=WORK` (the step work budget instead of topple's default),
/// `--tolerance=TOL` (the time-domain resolver at this tolerance instead of
/// the default 10⁻⁶), `--impulse=TOL` (the adaptive impulse stepping, the
/// default before the time-domain resolver).
fn flag<T: std::str::FromStr>(name: &str) -> Option<T> {
    let prefix = format!("--{name}=");
    std::env::args().find_map(|a| {
        a.strip_prefix(&prefix).map(|v| {
            v.parse()
                .unwrap_or_else(|_| panic!("--{name}={v}: not a number"))
        })
    })
}

/// `--large=BODIES:WORK` (groups of more than BODIES free bodies may spend
/// WORK) or `--large=none` (no cap on large groups).
fn large_group(v: &str) -> Option<topple::coupling::LargeGroup> {
    if v == "none" {
        return None;
    }
    let (b, w) = v
        .split_once(':')
        .unwrap_or_else(|| panic!("--large={v}: BODIES:WORK or none"));
    let n = |x: &str| -> u64 {
        x.parse()
            .unwrap_or_else(|_| panic!("--large={v}: not a number"))
    };
    Some(topple::coupling::LargeGroup {
        bodies: n(b) as usize,
        work: n(w),
    })
}

fn with_budget(app: &mut App) {
    let mut config = app.world_mut().resource_mut::<topple::bevy::ToppleConfig>();
    let settings = &mut config.settings;
    if let Some(t) = flag("tolerance") {
        settings.impact = topple::impact::ImpactSettings::adaptive(t);
    }
    if let Some(t) = flag("impulse") {
        settings.impact = topple::impact::ImpactSettings::adaptive_impulse(t);
    }
    if let Some(w) = flag("budget") {
        settings.fallback.max_work = Some(w);
    }
    if let Some(large) = std::env::args().find_map(|a| a.strip_prefix("--large=").map(String::from))
    {
        settings.fallback.large_group = large_group(&large);
    }
}

fn pixel_scene(
    physics: ImpactResponse,
    frames: usize,
    ground_y: f32,
    spawn: impl FnOnce(&mut Commands, Target),
) -> Run {
    let mut app = scenes::headless_app(physics);
    with_budget(&mut app);
    scenes::spawn_in(&mut app, |c| {
        spawn(
            c,
            Target {
                physics,
                context: None,
            },
        )
    });
    measure(&mut app, frames, ground_y)
}

fn row(physics: ImpactResponse, n: usize, frames: usize) -> Run {
    let p = Preset::T.params().ideal();
    let row = DominoRow {
        physics,
        ..DominoRow::new(RowSpec::new(p, 0.45 * p.block.height, n, 1.0))
    };
    let (mut app, _) = headless_row_app(&row, 1.0 / 60.0).expect("a valid row");
    with_budget(&mut app);
    measure(&mut app, frames, 0.0)
}

/// The CPU-time rows, printed after the wall-clock table.
static CPU_ROWS: std::sync::Mutex<Vec<String>> = std::sync::Mutex::new(Vec::new());

fn print(scene: &str, frames: usize, native: &Run, topple: &Run) {
    CPU_ROWS
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .push(format!(
            "| {scene} | {:.3} | {:.2} | {:.3} | {:.2} | {:.2} | {:.2} | {:.3} | {:.3} | {:.2} |",
            native.cpu_mean_ms,
            native.cpu_worst_ms,
            topple.cpu_mean_ms,
            topple.cpu_worst_ms,
            topple.cpu_mean_ms / native.cpu_mean_ms,
            topple.cpu_worst_ms / native.cpu_worst_ms,
            native.step_ms,
            topple.step_ms,
            topple.step_ms / native.step_ms,
        ));
    let sane = |r: &Run| {
        if r.nan {
            "NaN".to_string()
        } else {
            format!("{:.2}", r.below_ground)
        }
    };
    println!(
        "| {scene} | {frames} | {:.3} | {:.2} | {} | {:.3} | {:.2} | {} | {:.3} | {:.2} | {:.2} | {:.2} | {} ({}) | {} ({}) | {} | {} | {} / {} |",
        native.mean_ms,
        native.worst_ms,
        native.slow,
        topple.mean_ms,
        topple.worst_ms,
        topple.slow,
        topple.topple_ms,
        topple.rapier_steps,
        topple.mean_ms / native.mean_ms,
        topple.worst_ms / native.worst_ms,
        topple.impacts,
        topple.batched,
        topple.fallbacks,
        topple.large_fallbacks,
        topple.budget_spent,
        topple.native_impacts,
        sane(native),
        sane(topple),
    );
}

fn main() {
    let wanted: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with('-'))
        .collect();
    let want = |name: &str| wanted.is_empty() || wanted.iter().any(|w| name.contains(w.as_str()));
    println!("| scene | frames | native mean (ms) | native worst (ms) | native frames > 1/60 s | topple mean (ms) | topple worst (ms) | topple frames > 1/60 s | topple's own (ms/frame) | topple's Rapier steps per frame | mean ratio | worst ratio | impacts (solved in batches) | fallbacks (large groups) | budget ran out | left to Rapier | below ground (native / topple) |");
    println!(
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"
    );
    if want("pyramid") {
        let (f, ground) = (180, 0.0);
        let spawn = |c: &mut Commands, t: Target| {
            scenes::pyramid(c, t, 10, 40.0);
        };
        let native = pixel_scene(ImpactResponse::Native, f, ground, spawn);
        let topple = pixel_scene(ImpactResponse::Topple, f, ground, spawn);
        print("pyramid at rest, 55 boxes, px", f, &native, &topple);
    }
    if want("pile") {
        let (f, ground) = (300, 0.0);
        let spawn = |c: &mut Commands, t: Target| {
            scenes::pile_in_layers(c, t, 10, 15);
        };
        let native = pixel_scene(ImpactResponse::Native, f, ground, spawn);
        let topple = pixel_scene(ImpactResponse::Topple, f, ground, spawn);
        print(
            "pile of 150 boxes dropped in layers, px",
            f,
            &native,
            &topple,
        );
    }
    if want("bin") {
        let (f, ground) = (300, 0.0);
        let spawn = |c: &mut Commands, t: Target| {
            scenes::bin(c, t, 48);
        };
        let native = pixel_scene(ImpactResponse::Native, f, ground, spawn);
        let topple = pixel_scene(ImpactResponse::Topple, f, ground, spawn);
        print(
            "48 balls, boxes, capsules, polygons in a bin, px",
            f,
            &native,
            &topple,
        );
    }
    if want("row") {
        let f = 600;
        let native = row(ImpactResponse::Native, 1_000, f);
        let topple = row(ImpactResponse::Topple, 1_000, f);
        print("ideal Domino T row, 1,000 blocks, m", f, &native, &topple);
    }
    if want("show") {
        let f = 600;
        let (native, native_fell) = show_scene(ImpactResponse::Native, f);
        let (topple, topple_fell) = show_scene(ImpactResponse::Topple, f);
        print("domino_show, 16 fronts, px", f, &native, &topple);
        SHOW_ROWS
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .extend([native_fell.row("native"), topple_fell.row("topple")]);
    }
    println!();
    println!("| scene (CPU time of the process per frame; physics step's wall time per frame) | native mean (ms) | native worst (ms) | topple mean (ms) | topple worst (ms) | mean ratio | worst ratio | native physics step (ms) | topple physics step (ms) | physics step ratio |");
    println!("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |");
    for row in CPU_ROWS.lock().unwrap_or_else(|e| e.into_inner()).iter() {
        println!("{row}");
    }
    let show_rows = SHOW_ROWS.lock().unwrap_or_else(|e| e.into_inner());
    if !show_rows.is_empty() {
        println!();
        println!("| domino_show at the end | fronts' dominoes turned > 10° | growing turned | tower blocks moved > 6 px | steps' dominoes turned |");
        println!("| --- | --- | --- | --- | --- |");
        for row in show_rows.iter() {
            println!("{row}");
        }
    }
}

/// The show's rows of the last table.
static SHOW_ROWS: std::sync::Mutex<Vec<String>> = std::sync::Mutex::new(Vec::new());

/// What fell in the show: per part, how many of its bodies turned or moved.
struct ShowFell {
    /// (fell, of) per part: the fronts, the growing dominoes, the tower,
    /// the steps.
    parts: [(usize, usize); 4],
    /// The tower's blocks: mean distance their centres moved, and the
    /// width of the pile they make (px, extent of their centres in x).
    tower_moved: f32,
    tower_width: f32,
}

impl ShowFell {
    fn row(&self, engine: &str) -> String {
        let p = |k: usize| format!("{} / {}", self.parts[k].0, self.parts[k].1);
        format!(
            "| {engine} | {} | {} | {} ({:.0} px on average, {:.0} px wide) | {} |",
            p(0),
            p(1),
            p(2),
            self.tower_moved,
            self.tower_width,
            p(3)
        )
    }
}

/// A body's pose: centre (px) and angle (rad).
fn pose(app: &mut App, e: Entity) -> (Vec2, f32) {
    let t = app.world().get::<Transform>(e).copied().unwrap_or_default();
    (
        t.translation.truncate(),
        t.rotation.to_euler(EulerRot::ZYX).0,
    )
}

/// The show with 16 fronts, measured, and what fell in it: a domino of a
/// front, of the growing row or of the steps fell if it turned more than
/// 10° from its start; a tower block if its centre moved more than half a
/// block's height (6 px).
fn show_scene(physics: ImpactResponse, frames: usize) -> (Run, ShowFell) {
    let mut app = scenes::headless_app(physics);
    with_budget(&mut app);
    let mut layout = show::ShowLayout::default();
    scenes::spawn_in(&mut app, |c| {
        layout = show::domino_show(
            c,
            Target {
                physics,
                context: None,
            },
            16,
        );
    });
    let fronts: Vec<Entity> = layout
        .rows
        .iter()
        .flat_map(|r| r.dominoes.clone())
        .collect();
    let parts = [&fronts, &layout.growing, &layout.tower, &layout.steps];
    let start: Vec<Vec<(Vec2, f32)>> = parts
        .iter()
        .map(|p| p.iter().map(|&e| pose(&mut app, e)).collect())
        .collect();
    let run = measure(&mut app, frames, show::FLOOR_Y);
    let mut fell = ShowFell {
        parts: [(0, 0); 4],
        tower_moved: 0.0,
        tower_width: 0.0,
    };
    let (mut x0, mut x1) = (f32::INFINITY, f32::NEG_INFINITY);
    for (k, part) in parts.iter().enumerate() {
        let mut n = 0;
        for (&e, &(c0, a0)) in part.iter().zip(&start[k]) {
            let (c, a) = pose(&mut app, e);
            if k == 2 {
                fell.tower_moved += c.distance(c0) / part.len() as f32;
                (x0, x1) = (x0.min(c.x), x1.max(c.x));
            }
            n += usize::from(if k == 2 {
                c.distance(c0) > 6.0
            } else {
                (a - a0).abs() > 10f32.to_radians()
            });
        }
        fell.parts[k] = (n, part.len());
    }
    fell.tower_width = x1 - x0;
    (run, fell)
}
