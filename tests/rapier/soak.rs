//! The soak: a domino show that puts itself back every 10 s, run for 10⁵
//! frames at 60 Hz (27.8 min of game time) through topple's Rapier adapter
//! on the f32 build (a game's), twice side by side. Checked every frame, by
//! measures independent of the adapter's own counters: finite states, no
//! impact creating energy (`impact::audit`), no overlap beyond the row
//! sweep's Rapier tolerance (0.05 h + one step's closing of a block falling
//! flat, `stress::tolerance::penetration_rapier`), no block through the
//! ground, the impact work of a
//! frame within the scene family's bound, the same bits on both runs, and a
//! flat resident set from the end of the second cycle to the end.
//!
//! Long: run it with `cargo test --release --test rapier -- soak:: --ignored
//! --nocapture`; `docs/stress.md` gives its figures.

use topple::domino::Preset;
use topple::rapier::scene::Scene;
use topple::stress::scene::tolerance;
use topple::stress::soak::{resident_bytes, soak, SoakSpec};
use topple::stress::tolerance::penetration_rapier;

/// The show: 30 Domino T blocks at s/h 0.35, the first pushed.
const SHOW: &str = r#"
    duration = 10.0
    [solver]
    dt = 0.016666666666666666
    [row]
    preset = "T"
    n = 30
    spacing = 0.35
"#;

/// Resident-set growth allowed from the end of the second cycle to the end
/// (bytes): the allocator's own slack, far below what a leak of one small
/// allocation per frame would show over 10⁵ frames (≥ 1.6 MB at 16 bytes).
const MEMORY_GROWTH: i64 = 512 * 1024;

#[test]
#[ignore = "long (minutes): cargo test --release --test rapier -- soak:: --ignored --nocapture"]
fn a_domino_show_runs_1e5_frames_clean_with_flat_memory() {
    let scene: Scene = toml::from_str(SHOW).expect("the show parses");
    let spec = SoakSpec::default();
    assert_eq!(spec.frames, 100_000);
    let r = soak(&scene, &spec, resident_bytes);
    let s = &r.seen;
    println!(
        "soak: {} frames in {} cycles, {:.0} s wall (both runs), {} impacts ({} fallbacks), \
         worst frame work {}, longest frame {:.2} ms, penetration {:.4} of the thickness ({}), \
         created energy {:.2e}, memory {:?} KiB at cycle ends, growth {:?} B",
        s.frames,
        r.cycles,
        r.wall,
        s.impacts,
        s.fallbacks,
        s.worst_frame_work,
        1e3 * s.worst_frame_seconds,
        s.penetration,
        s.penetration_at,
        s.audit.energy_gain,
        r.memory.iter().map(|m| m / 1024).collect::<Vec<_>>(),
        r.memory_growth(),
    );
    assert!(s.error.is_none(), "{:?}", s.error);
    assert_eq!(
        s.frames, spec.frames,
        "every frame ran (budget {} s)",
        spec.budget
    );
    assert!(!s.over_budget);
    assert!(!s.non_finite && s.audit.non_finite == 0);
    assert!(s.impacts > 0, "the show resolves impacts every cycle");
    assert!(
        s.audit.energy_gain <= tolerance::ENERGY_GAIN,
        "{:?}",
        s.audit
    );
    assert!(s.audit.consistency <= tolerance::IMPULSES, "{:?}", s.audit);
    // the watcher measures overlaps over the least width (the thickness d)
    let p = Preset::T.params();
    let (h, d) = (p.block.height, p.block.thickness);
    let over_h = s.penetration * d / h;
    let allowed = penetration_rapier(0.0, scene.solver.dt, h, p.gravity);
    println!("soak: penetration {over_h:.4} h, tolerance {allowed:.4} h");
    assert!(over_h <= allowed, "{over_h} h: {}", s.penetration_at);
    assert!(s.through_ground.is_none(), "{:?}", s.through_ground);
    assert!(s.worst_frame_work <= tolerance::FRAME_WORK);
    assert_eq!(r.repeat_hash, Some(s.hash), "both runs give the same bits");
    // the reset happens every 600 frames: 10⁵ / 600 = 166 full cycles
    assert_eq!(r.cycles, spec.frames / 600 + 1);
    if let Some(growth) = r.memory_growth() {
        assert!(growth <= MEMORY_GROWTH, "resident set grew {growth} B");
    }
}
