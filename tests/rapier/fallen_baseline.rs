//! A fallen block standing up again in a topple Rapier run is held against
//! native Rapier at the same step when the reference engine cannot judge it
//! (it runs up to the last hit only), and against topple's own run at a
//! finer step, which it must not need.

use topple::stress::{draw, run_combo, violations, Kind, Observation, StressEngine, SweepSpec};

/// Combination 896 of the full sweep, seed 1 (Domino X, s/h 0.102, 13
/// blocks, e1 0.6, e2 0.5, Rapier f64 at Δt = 1/120 s): after the last
/// block slides out ahead of the row and falls flat, the train behind it
/// settles back, and native Rapier stands fallen blocks back up past π/4
/// (docs/stress.md, "A fallen count native Rapier drops as well"; on the
/// step loop before Rapier's substep was kept native inside the pieces,
/// topple stood block 11 up by 8.1°, native blocks 11 and 12 by 12.8°).
/// Native Rapier, stepped alone, must show that drop (it is what the rule
/// holds topple's runs against); topple's run, at the drawn step and at
/// half of it, must have no violation; and where topple's run drops a
/// block, native must have been run beside it, as the rule asks.
#[test]
fn combo_896_native_rapier_stands_blocks_up_topple_does_not() {
    let spec = SweepSpec::full(1);
    let c = draw(1, 896, spec.n_lo, spec.n_hi);
    assert_eq!(c.engine, StressEngine::RapierF64);
    let mut native = c.clone();
    native.engine = StressEngine::Native;
    let n = run_combo(&native, 120.0);
    println!(
        "native: drop {} (blocks {:?}, {:.2}°)",
        n.fallen_drop,
        n.stood_up,
        n.stood_up_rock_back.to_degrees()
    );
    assert!(n.fallen_drop > 0, "native Rapier kept its blocks down");
    for div in [1.0, 2.0] {
        let mut t = c.clone();
        t.dt = c.dt / div;
        let o = run_combo(&t, 120.0);
        println!(
            "topple at Δt/{div}: drop {} (blocks {:?}, {:.2}°), native beside it {:?}",
            o.fallen_drop,
            o.stood_up,
            o.stood_up_rock_back.to_degrees(),
            o.native_drop.map(|(d, r)| (d, r.to_degrees()))
        );
        assert!(violations(&t, &o).is_empty(), "Δt/{div}");
        if o.fallen_drop > 0
            && o.reference_rock_back
                .is_some_and(|r| r < o.stood_up_rock_back)
        {
            assert!(o.native_drop.is_some(), "native not run beside the drop");
        }
    }
}

/// The rule on hand-made observations of a dissipative row (e1 0.6, e2
/// 0.5): a drop native Rapier does not make, or makes smaller, is counted.
#[test]
fn a_drop_native_rapier_does_not_make_is_counted() {
    let spec = SweepSpec::full(1);
    let c = draw(1, 896, spec.n_lo, spec.n_hi);
    let drop = |native: Option<(usize, f64)>| {
        let o = Observation {
            fallen_drop: 1,
            stood_up: vec![11],
            stood_up_rock_back: 0.14,
            fallen_rock_back: 0.16,
            reference_fallen_drop: Some(0),
            reference_rock_back: Some(0.0),
            native_drop: native,
            ..Observation::default()
        };
        violations(&c, &o)
            .iter()
            .any(|v| v.kind == Kind::FallenDrop)
    };
    assert!(drop(None), "not run");
    assert!(drop(Some((0, 0.0))), "native kept its blocks down");
    assert!(drop(Some((1, 0.10))), "native stood one up less far");
    assert!(!drop(Some((1, 0.20))), "native stood one up further");
    assert!(!drop(Some((2, 0.14))), "native stood two up as far");
}
