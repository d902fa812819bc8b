//! The paper's own model of a domino row (Sec. 2), the project's accuracy
//! oracle.
//!
//! Each moving block has reduced coordinates q_i = (x_i, y_i, φ_i) (φ = −θ, the
//! paper's θ being clockwise). Contacts are corners against faces
//! ([`geometry`](self)): the λ points of the bottom face on the ground (the
//! paper's A_i is the front one; all λ carry the line contact of a standing
//! block, docs/model.md §5), the front top corner on the ground (a block lying on its
//! face), the front top corner B_i on the next block's back face, and, for the
//! last pair only, the last block's heel on the front face of the one behind
//! (inside the row that pair is not a contact unless `heel_contacts` is set).
//!
//! - Smooth phase (Eqs. 17–20): unilateral contacts with Coulomb friction, the
//!   mode (pressing / lifting off, sticking with μ_s / sliding with μ) found by
//!   an active-set search and held fixed during a step; every transition is an
//!   event located inside the step by bisection: a contact closing (gap below
//!   −`gap_tolerance`·h while approaching), lift-off (F_n < 0), stick → slip
//!   (|F_t| > μ_s F_n), slip reversal (v_t through 0). Persistent contacts are
//!   kept exactly closed by projection.
//! - Two integrators ([`Integrator`]): the paper's improved Euler at Δt = 10⁻⁴ s,
//!   and Dormand–Prince 5(4) with error control.
//! - Impacts (Sec. 2.3): by [`crate::impact::ImpactSolver`], one group of
//!   closed contacts at a time, impact friction 0.5 × Table 1 (docs/model.md §4); an
//!   impact the resolver cannot finish within its step limit is solved again
//!   with its e = 0 contacts held closed (`held_impacts`), and if that fails
//!   too, as a plastic impact (`impact_fallbacks`).
//! - Only what moves is integrated: a window of blocks lo..hi; the block in
//!   front of the wave joins when struck, blocks at rest behind it are frozen.
//!   The cost per step depends on the window, not on the row.
//!
//! ```no_run
//! use topple::domino::{Preset, RowSpec};
//! use topple::reference::{run, Settings};
//! let p = Preset::X.params();
//! let row = RowSpec::new(p, 0.18 * p.block.height, 40, 1.8);
//! let r = run(&row, &Settings::accurate(1e-8)).unwrap().report;
//! println!("{:?} {:?}", r.natural_speed, r.energy);
//! ```

// Small fixed-size numeric loops read best with indices, and the inner
// routines take the row state as separate borrowed slices on purpose.
#![allow(clippy::needless_range_loop, clippy::too_many_arguments)]

mod band;
mod dynamics;
mod engine;
mod geometry;
mod modes;
mod settings;
mod snapshot;
mod stepper;

pub use engine::{run, run_from, run_with_progress, EngineError, RunResult};
pub use settings::{Integrator, Settings};
#[cfg(feature = "plots")]
pub use snapshot::snapshot_png;
pub use snapshot::{snapshot_svg, Snapshot, PNG_BLOCK};
