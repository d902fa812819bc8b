//! One interface for every engine that runs a domino row: the reference
//! engine of the paper's model, Rapier with topple's impacts and native
//! Rapier, in either Rapier build. `topple chain`, `topple bench` and the
//! stress sweep dispatch through it, and a library user can compare engines
//! the same way.
//!
//! | item | role |
//! | --- | --- |
//! | [`RowEngine`] | runs a [`RowSpec`] and fills a [`ChainReport`] |
//! | [`ReferenceRow`] | the reference engine ([`crate::reference`]) with its settings |
//! | [`RapierRow`] | Rapier with topple or natively ([`crate::rapier::scene::run_row`]) |
//! | [`RowError`] | why a run could not finish |
//!
//! ```
//! use topple::domino::{Preset, RowSpec};
//! use topple::engines::{RapierRow, ReferenceRow, RowEngine};
//! use topple::rapier::scene::ImpactResponse;
//! let p = Preset::T.params().ideal();
//! let row = RowSpec::new(p, 0.5 * p.block.height, 4, 1.0);
//! let engines: Vec<Box<dyn RowEngine>> = vec![
//!     Box::new(ReferenceRow::default()),
//!     Box::new(RapierRow::new(ImpactResponse::Topple, 1.0 / 240.0)),
//! ];
//! for engine in &engines {
//!     let report = engine.run(&row, &mut |_| {}).unwrap();
//!     assert_eq!(report.hit_times.len(), 4, "{}", engine.name());
//! }
//! ```

use crate::domino::{ChainReport, RowSpec};
use crate::rapier::scene::{ImpactResponse, SceneError, SolverSpec};
use crate::rapier::Precision;
use crate::reference::{EngineError, Settings};

/// Why a row could not be run to its end.
#[derive(Debug, thiserror::Error)]
pub enum RowError {
    /// The reference engine failed.
    #[error(transparent)]
    Reference(#[from] EngineError),
    /// The Rapier world could not be built or run.
    #[error(transparent)]
    Rapier(#[from] SceneError),
}

/// An engine that runs a domino row and reports its wave.
pub trait RowEngine {
    /// The engine's name in reports ("reference", "rapier", "rapier-native").
    fn name(&self) -> &'static str;

    /// Runs `row` to its end (the last block hit, the wave stopped, or the
    /// engine's own budget); `progress` gets the number of blocks hit so far.
    fn run(&self, row: &RowSpec, progress: &mut dyn FnMut(usize)) -> Result<ChainReport, RowError>;
}

/// The reference engine of the paper's model with its settings.
#[derive(Clone, Debug, Default)]
pub struct ReferenceRow {
    /// Integrator, tolerances, budgets.
    pub settings: Settings,
}

impl RowEngine for ReferenceRow {
    fn name(&self) -> &'static str {
        "reference"
    }

    fn run(&self, row: &RowSpec, progress: &mut dyn FnMut(usize)) -> Result<ChainReport, RowError> {
        Ok(crate::reference::run_with_progress(row, &self.settings, progress)?.report)
    }
}

/// A row in Rapier, with topple's impacts or natively, on one Rapier build.
#[derive(Clone, Debug)]
pub struct RapierRow {
    /// Who resolves impacts.
    pub engine: ImpactResponse,
    /// Which Rapier build.
    pub precision: Precision,
    /// Rapier's and topple's settings (its `dt` is Rapier's step, s).
    pub solver: SolverSpec,
    /// Simulated time (s) after which the run stops.
    pub max_time: f64,
}

impl RapierRow {
    /// `engine` on the f64 build (the f32 one when only it is compiled) at
    /// time step `dt` (s), default settings otherwise, stopping after 600 s
    /// of simulated time.
    pub fn new(engine: ImpactResponse, dt: f64) -> Self {
        RapierRow {
            engine,
            precision: Precision::default(),
            solver: SolverSpec {
                dt,
                ..SolverSpec::default()
            },
            max_time: 600.0,
        }
    }
}

impl RowEngine for RapierRow {
    fn name(&self) -> &'static str {
        self.engine.name()
    }

    fn run(&self, row: &RowSpec, progress: &mut dyn FnMut(usize)) -> Result<ChainReport, RowError> {
        Ok(crate::rapier::scene::run_row(
            row,
            self.engine,
            self.precision,
            self.solver.clone(),
            self.max_time,
            progress,
        )?)
    }
}
