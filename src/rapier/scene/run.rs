//! Running a scene or a domino row on the Rapier build the caller picks:
//! the dispatch to [`crate::rapier::f64`] or [`crate::rapier::f32`] (each
//! compiled only with its cargo feature). Kept apart from `setup.rs`, whose
//! settings and outputs the builds themselves use, so that no file imports
//! one that imports it.

use super::{RunOptions, Scene, SceneOutput, SceneResult, SolverSpec};
use crate::domino::{ChainReport, RowSpec as DominoRow};
use crate::rapier::ImpactResponse;
use crate::rapier::Precision;

/// Runs a scene with an engine on the Rapier build of `precision`.
///
/// ```
/// use topple::rapier::scene::{run_scene, ImpactResponse, RunOptions, Scene};
/// use topple::rapier::Precision;
/// let scene: Scene = toml::from_str(r#"
///     duration = 0.01
///     gravity = [0.0, 0.0]
///     [[materials]]
///     name = "steel"
///     stiffness = 1e10
///     [[bodies]]
///     shape = "ball"
///     radius = 0.05
///     position = [0.0, 0.0]
///     velocity = [1.0, 0.0]
///     mass = 1.0
///     material = "steel"
///     [[bodies]]
///     shape = "ball"
///     radius = 0.05
///     position = [0.1, 0.0]
///     mass = 1.0
///     material = "steel"
/// "#).unwrap();
/// for precision in [Precision::F64, Precision::F32] {
///     let out = run_scene(&scene, ImpactResponse::Topple, precision, RunOptions::default()).unwrap();
///     assert_eq!(out.impacts.len(), 1);
///     assert!((out.bodies[1].velocity[0] - 1.0).abs() < 1e-3);
/// }
/// ```
pub fn run_scene(
    scene: &Scene,
    engine: ImpactResponse,
    precision: Precision,
    options: RunOptions,
) -> SceneResult<SceneOutput> {
    match precision {
        #[cfg(feature = "f64")]
        Precision::F64 => crate::rapier::f64::run_scene(scene, engine, options),
        #[cfg(feature = "f32")]
        Precision::F32 => crate::rapier::f32::run_scene(scene, engine, options),
        #[allow(unreachable_patterns)]
        _ => {
            let _ = (scene, engine, options);
            Err(super::SceneError::NotBuilt(precision))
        }
    }
}

/// Runs a domino row of [`crate::domino`] through Rapier (topple or native,
/// either build) until its last block is hit, nothing was hit for 2 s, or
/// `max_time` (s) passed; `progress` gets the number of blocks hit so far.
///
/// ```
/// use topple::domino::{Preset, RowSpec};
/// use topple::rapier::scene::{run_row, ImpactResponse, SolverSpec};
/// use topple::rapier::Precision;
/// let p = Preset::T.params().ideal();
/// let row = RowSpec::new(p, 0.45 * p.block.height, 4, 1.0);
/// let solver = SolverSpec { dt: 1.0 / 240.0, ..SolverSpec::default() };
/// let r = run_row(&row, ImpactResponse::Topple, Precision::F64, solver, 2.0, |_| {}).unwrap();
/// assert_eq!(r.hit_times.len(), 4); // the wave reached the last block
/// ```
pub fn run_row(
    row: &DominoRow,
    engine: ImpactResponse,
    precision: Precision,
    solver: SolverSpec,
    max_time: f64,
    progress: impl FnMut(usize),
) -> SceneResult<ChainReport> {
    match precision {
        #[cfg(feature = "f64")]
        Precision::F64 => {
            crate::rapier::f64::chain::run_row(row, engine, solver, max_time, progress)
        }
        #[cfg(feature = "f32")]
        Precision::F32 => {
            crate::rapier::f32::chain::run_row(row, engine, solver, max_time, progress)
        }
        #[allow(unreachable_patterns)]
        _ => {
            let _ = (row, engine, solver, max_time, progress);
            Err(super::SceneError::NotBuilt(precision))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domino::Preset;
    use crate::rapier::scene::SceneError;

    /// Each precision runs when its cargo feature compiles it and is
    /// refused with [`SceneError::NotBuilt`] otherwise (checked under each
    /// feature set by .ci/run).
    #[test]
    fn a_precision_runs_exactly_when_it_is_built() {
        let scene: Scene = toml::from_str("duration = 0.05").unwrap();
        let p = Preset::T.params().ideal();
        let row = DominoRow::new(p, 0.45 * p.block.height, 2, 1.0);
        let solver = SolverSpec::default();
        for precision in [Precision::F32, Precision::F64] {
            let s = run_scene(
                &scene,
                ImpactResponse::Topple,
                precision,
                RunOptions::default(),
            );
            let r = run_row(
                &row,
                ImpactResponse::Native,
                precision,
                solver.clone(),
                0.05,
                |_| {},
            );
            if precision.is_built() {
                assert!(s.is_ok() && r.is_ok(), "{precision:?}");
            } else {
                for e in [s.map(|_| ()), r.map(|_| ())] {
                    let e = e.unwrap_err();
                    assert!(
                        matches!(e, SceneError::NotBuilt(q) if q == precision),
                        "{e}"
                    );
                    assert!(e.to_string().contains(&format!("`{}`", precision.name())));
                }
            }
        }
        assert_eq!(
            Precision::default().is_built(),
            cfg!(any(feature = "f32", feature = "f64"))
        );
    }
}
