//! The paper's domain: one rectangular block, the Table 1 presets (X, T, P), the
//! row builder and the wave-speed measures (Eq. 33, natural speed).
//!
//! This layer knows nothing of how a row is simulated: an engine (the
//! [`crate::reference`] engine, or a Rapier-based one) takes a [`RowSpec`],
//! records when each block is hit and fills a [`ChainReport`].
//!
//! | item | role |
//! | --- | --- |
//! | [`Block`] | height, thickness, mass, inertia, corners in the body frame |
//! | [`Preset`], [`RowParams`] | Table 1 of the paper, every value overridable |
//! | [`Ground`] | the ground under the feet: Coulomb (the paper) or no-slip pivots |
//! | [`RowSpec`] | a row of `n` blocks at pitch s + d with a push on block 1 |
//! | [`WaveMeasures`] | t_i, v̂_i (Eq. 33), v̂_na with its spread |
//! | [`ChainReport`] | the engine-independent JSON report of `topple chain` |
//!
//! ```
//! use topple::domino::{Preset, RowSpec, WaveMeasures};
//! let params = Preset::T.params();
//! let row = RowSpec::new(params, 0.35 * params.block.height, 20, 1.0);
//! // hit times of a wave that moves at exactly one pitch per 10 ms
//! let hits: Vec<f64> = (0..20).map(|i| 0.01 * i as f64).collect();
//! let m = WaveMeasures::from_hit_times(&row, &hits);
//! let expected = row.pitch() / 0.01 / params.speed_scale();
//! assert!((m.natural_speed.unwrap().mean - expected).abs() < 1e-12);
//! ```

mod block;
mod ground;
mod measures;
mod preset;
mod report;
mod row;

pub use block::Block;
pub use ground::Ground;
pub use measures::{Spread, WaveMeasures, FIRST_STEADY_BLOCK};
pub use preset::{Preset, RowParams};
pub use report::{BlockSeries, ChainReport, EnergyReport};
pub use row::RowSpec;
