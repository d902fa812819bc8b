//! The impulse stepping allocates nothing once its buffers are sized: after a
//! warm-up resolve of an impact (which sizes the solver's buffers and the
//! outcome's vectors), resolving the same impact again performs no heap
//! allocation at all, whatever the number of steps. Counted by a global
//! allocator that wraps the system one and counts the calls of each thread
//! (tests run on several threads).

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use topple::impact::capture::CapturedImpact;
use topple::impact::{ImpactOutcome, ImpactSettings, ImpactSolver};

/// The system allocator, counting allocations per thread.
struct Counting;

thread_local! {
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

fn count() {
    // `try_with`: the slot is gone while a thread is torn down.
    let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
}

// SAFETY: every call forwards to `System` with the same arguments; counting
// touches only a const-initialised thread-local `Cell` (no allocation).
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        unsafe { System.realloc(ptr, layout, new_size) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Allocations made by this thread while `f` runs.
fn allocations_in(f: impl FnOnce()) -> usize {
    let before = ALLOCATIONS.with(Cell::get);
    f();
    ALLOCATIONS.with(Cell::get) - before
}

/// Impacts captured from Rapier scenes at 1/60 s (benches/data/): the largest
/// of the box pile (47 contacts, 24 bodies, friction, e = 0.3) and one of the
/// Domino X row (λ points, e = 0 chatter).
fn impacts() -> Vec<CapturedImpact> {
    let pile = include_str!("../../benches/data/pile.jsonl");
    let x_row = include_str!("../../benches/data/x-row-1-60.jsonl");
    let parse = |line: &str| serde_json::from_str::<CapturedImpact>(line).unwrap();
    let largest = pile
        .lines()
        .filter(|l| !l.trim().is_empty())
        .map(parse)
        .max_by_key(|c| c.contacts.len())
        .unwrap();
    let x = x_row.lines().find(|l| !l.trim().is_empty()).map(parse);
    std::iter::once(largest).chain(x).collect()
}

/// The counter sees an allocation (so the zero below can fail).
#[test]
fn the_counter_counts() {
    let n = allocations_in(|| {
        std::hint::black_box(Vec::<u64>::with_capacity(16));
    });
    assert!(n >= 1, "{n}");
}

/// The paper's fixed step and the adaptive impulse step, with and without
/// held e = 0 contacts: a second resolve allocates nothing.
#[test]
fn impulse_stepping_does_not_allocate() {
    let mut solver = ImpactSolver::new();
    let mut out = ImpactOutcome::default();
    for impact in impacts() {
        for step in [
            ImpactSettings::fixed(1e-3),
            ImpactSettings::adaptive_impulse(1e-4),
        ] {
            for e0_hold in [false, true] {
                let settings = ImpactSettings {
                    e0_hold,
                    max_steps: 1_000_000,
                    ..step
                };
                let (bodies, contacts) = (&impact.bodies, &impact.contacts);
                solver
                    .solve_into(bodies, contacts, &settings, &mut out)
                    .unwrap();
                let warm_steps = out.steps;
                let n = allocations_in(|| {
                    solver
                        .solve_into(bodies, contacts, &settings, &mut out)
                        .unwrap();
                });
                assert_eq!(out.steps, warm_steps, "the same impact, the same steps");
                assert!(out.steps > 10, "{} steps: too few to test", out.steps);
                assert_eq!(
                    n,
                    0,
                    "{n} allocations in {} steps ({} contacts, {:?}, e0_hold {e0_hold})",
                    out.steps,
                    contacts.len(),
                    settings.step_control
                );
            }
        }
    }
}
