//! The same scene run twice gives the same bits.

use topple::rapier::scene::{load_scene, run_scene, ImpactResponse, RunOptions};
use topple::rapier::Precision;

#[test]
fn same_scene_twice_gives_identical_results() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/scenes/domino-row-x.toml");
    let mut scene = load_scene(&path).unwrap();
    scene.row.as_mut().unwrap().n = 12;
    scene.duration = 0.6;
    for engine in [ImpactResponse::Topple, ImpactResponse::Native] {
        let a = serde_json::to_string(
            &run_scene(&scene, engine, Precision::F64, RunOptions::default()).unwrap(),
        )
        .unwrap();
        let b = serde_json::to_string(
            &run_scene(&scene, engine, Precision::F64, RunOptions::default()).unwrap(),
        )
        .unwrap();
        assert_eq!(a, b, "{engine:?} is not deterministic");
    }
}
