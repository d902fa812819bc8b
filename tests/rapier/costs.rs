//! What topple costs on top of Rapier: sleeping bodies are never queried, and once its buffers have grown
//! to the largest impact group, the impact pass allocates nothing.
//!
//! Allocations are counted by a global allocator that counts only while the
//! current thread has switched counting on, so Rapier's own step (and any
//! other test thread) is left out. One Rapier cost remains inside the count:
//! writing a velocity through `RigidBodySet`'s `IndexMut` records the body in
//! Rapier's modified-bodies list, which Rapier's step takes away
//! (`mem::take`), so after each impact step that list grows again from empty.
//! The steady-state check tells those allocations apart (by a backtrace) and
//! allows no other. With the `parallel` feature one more: a batch of
//! independent impacts handed to rayon's pool from outside it is pushed on
//! the pool's injector queue (crossbeam-deque's `Injector`), which allocates
//! a block for every 63 jobs; those are told apart the same way and bounded.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use topple::rapier::f64::{build, SceneWorld};
use topple::rapier::scene::{load_scene, ImpactResponse};

struct Counting;

thread_local! {
    static COUNTING: Cell<bool> = const { Cell::new(false) };
    static ATTRIBUTE: Cell<bool> = const { Cell::new(false) };
    /// Allocations counted on this thread (per thread, so that tests running
    /// in parallel do not see each other's).
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
    /// Of those, the ones made inside Rapier's `RigidBodySet` (its modified
    /// list), told apart by a backtrace when `ATTRIBUTE` is on.
    static RAPIER_ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
    /// Of those, the blocks of rayon's injector queue.
    static RAYON_ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

fn rayon_allocations() -> usize {
    RAYON_ALLOCATIONS.with(|c| c.get())
}

fn allocations() -> usize {
    ALLOCATIONS.with(|c| c.get())
}

fn rapier_allocations() -> usize {
    RAPIER_ALLOCATIONS.with(|c| c.get())
}

fn count_one() {
    if !COUNTING.with(|c| c.get()) {
        return;
    }
    ALLOCATIONS.with(|c| c.set(c.get() + 1));
    if ATTRIBUTE.with(|c| c.get()) {
        // the backtrace allocates too: stop counting while it is taken
        COUNTING.with(|c| c.set(false));
        let trace = std::backtrace::Backtrace::force_capture().to_string();
        if trace.contains("RigidBodySet") {
            RAPIER_ALLOCATIONS.with(|c| c.set(c.get() + 1));
        } else if trace.contains("Injector") {
            RAYON_ALLOCATIONS.with(|c| c.set(c.get() + 1));
        }
        COUNTING.with(|c| c.set(true));
    }
}

// SAFETY: forwards every call to the system allocator unchanged.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count_one();
        // SAFETY: the caller's contract of `alloc`, passed on.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: the caller's contract of `dealloc`, passed on.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count_one();
        // SAFETY: the caller's contract of `realloc`, passed on.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Allocations a `Vec` makes growing from empty to `len` elements: the first
/// allocation holds 4 (the standard library's smallest non-zero capacity for
/// small elements), then the capacity doubles.
fn growth_allocations(len: usize) -> usize {
    let (mut capacity, mut allocations) = (0usize, 0usize);
    while capacity < len {
        capacity = if capacity == 0 { 4 } else { 2 * capacity };
        allocations += 1;
    }
    allocations
}

/// One step as `ToppleRapier::step` does it, with topple's part counted.
/// Returns (impacts, allocations inside `begin_step` and `end_step`).
fn counted_step(sw: &mut SceneWorld) -> (usize, usize) {
    let before = allocations();
    let w = &mut sw.world;
    COUNTING.with(|c| c.set(true));
    sw.topple
        .begin_step(w.gravity, &w.integration_parameters, &w.islands, &w.bodies);
    COUNTING.with(|c| c.set(false));
    w.step_with_events(sw.topple.hooks(), &());
    COUNTING.with(|c| c.set(true));
    let impacts = sw.topple.end_step(
        &mut w.bodies,
        &w.colliders,
        &w.narrow_phase,
        &w.broad_phase,
        &w.integration_parameters,
    );
    COUNTING.with(|c| c.set(false));
    (impacts, allocations() - before)
}

fn scene(name: &str) -> topple::rapier::scene::Scene {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("assets/scenes")
        .join(name);
    load_scene(&path).unwrap()
}

#[test]
fn a_domino_wave_allocates_nothing_once_its_buffers_have_grown() {
    // Domino X with Table 1's material, 30 blocks. The first run grows
    // topple's buffers to the largest group of this wave; the same wave run
    // again in a fresh world with that warmed-up `ToppleRapier` is the steady
    // state, where topple must not allocate at all.
    let mut s = scene("domino-row-x.toml");
    s.row.as_mut().unwrap().n = 30;
    s.solver.max_group_hops = Some(8);
    let mut warm = build(&s, ImpactResponse::Topple).unwrap();
    let steps = (1.2 / warm.world.integration_parameters.dt) as usize;
    let mut first = (0, 0);
    for _ in 0..steps {
        let (n, a) = counted_step(&mut warm);
        first.0 += n;
        first.1 += a;
    }
    let mut sw = build(&s, ImpactResponse::Topple).unwrap();
    // same construction, so the same collider handles and materials
    sw.topple = warm.topple;
    let (mut impacts, mut allocations, mut rapier_share) = (0, 0, 0);
    ATTRIBUTE.with(|c| c.set(true));
    let (rapier_before, rayon_before) = (rapier_allocations(), rayon_allocations());
    for _ in 0..steps {
        let (n, a) = counted_step(&mut sw);
        // at most every body of every group had its velocity written
        let written: usize = sw.topple.last_impacts().iter().map(|r| r.bodies).sum();
        impacts += n;
        allocations += a;
        rapier_share += growth_allocations(written);
    }
    ATTRIBUTE.with(|c| c.set(false));
    let in_rapier = rapier_allocations() - rapier_before;
    let in_rayon = rayon_allocations() - rayon_before;
    println!(
        "first run: {} impacts, {} allocations; second run: {impacts} impacts, \
         {allocations} allocations, {in_rapier} of them in Rapier's RigidBodySet \
         (its growth from empty after each impact step allows {rapier_share}), \
         {in_rayon} in rayon's injector queue",
        first.0, first.1
    );
    // The test means something only if the second run resolves impacts.
    assert!(impacts > 100, "too few impacts: {impacts}");
    assert_eq!(
        allocations - in_rapier - in_rayon,
        0,
        "topple's own code allocated in steady state"
    );
    // a block per 63 batches at most (each batch is at least one impact)
    assert!(
        in_rayon <= 1 + impacts / 63,
        "rayon's queue allocated {in_rayon} times"
    );
    assert!(
        in_rapier <= rapier_share,
        "Rapier's list grew more than expected"
    );
}

#[test]
fn sleeping_bodies_are_not_queried() {
    // A box dropped flat comes to rest and falls asleep; from then on topple
    // queries no pair.
    let s = scene("box-drop-flat.toml");
    let mut sw = build(&s, ImpactResponse::Topple).unwrap();
    let dt = sw.world.integration_parameters.dt;
    let mut asleep_at = None;
    for k in 0..(10.0 / dt) as usize {
        counted_step(&mut sw);
        if sw
            .world
            .bodies
            .iter()
            .all(|(_, b)| !b.is_dynamic() || b.is_sleeping())
        {
            asleep_at = Some(k);
            break;
        }
    }
    assert!(asleep_at.is_some(), "the box never fell asleep in 10 s");
    let queried = sw.topple.stats().pairs_queried;
    assert!(
        queried > 0,
        "the box's contact with the ground was queried while awake"
    );
    let mut allocations = 0;
    for _ in 0..200 {
        allocations += counted_step(&mut sw).1;
    }
    assert_eq!(sw.topple.stats().pairs_queried, queried);
    assert_eq!(allocations, 0);
}
