//! The same input gives the same bits, run to run and for any number of
//! threads (RAYON_NUM_THREADS): the reference engine, the Rapier plugin in
//! both precisions, `topple paper`'s files and the stress sweep's table.
//! Wall-clock times are the only values allowed to differ.

use std::process::Command;

use super::paper_files::{clean_paper, files, PAPER_ARGS};

fn topple(args: &[&str], threads: usize) -> Vec<u8> {
    let out = Command::new(env!("CARGO_BIN_EXE_topple"))
        .args(args)
        .env("RAYON_NUM_THREADS", threads.to_string())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out.stdout
}

/// A chain report as JSON without its wall-clock time; floats are printed
/// in full (shortest round-trip form), so equal text is equal bits.
fn chain_json(extra: &[&str], threads: usize) -> serde_json::Value {
    let mut args = vec!["chain", "--spacing-ratio", "0.3", "--n", "8", "--json"];
    args.extend_from_slice(extra);
    let mut v: serde_json::Value = serde_json::from_slice(&topple(&args, threads)).unwrap();
    v.as_object_mut().unwrap().remove("run_time");
    v
}

#[test]
fn the_reference_engine_repeats_its_bits_for_any_thread_count() {
    let first = chain_json(&[], 1);
    assert!(first["hit_times"].as_array().unwrap().len() == 8);
    for threads in [1, 2, 4] {
        assert_eq!(chain_json(&[], threads), first, "{threads} threads");
    }
}

#[test]
fn the_rapier_plugin_repeats_its_bits_for_any_thread_count() {
    for precision in ["f64", "f32"] {
        let args = [
            "--engine",
            "rapier",
            "--dt",
            "0.001",
            "--precision",
            precision,
        ];
        let first = chain_json(&args, 1);
        assert!(!first["hit_times"].as_array().unwrap().is_empty());
        for threads in [1, 3] {
            assert_eq!(
                chain_json(&args, threads),
                first,
                "{precision}, {threads} threads"
            );
        }
    }
}

#[test]
fn paper_writes_the_same_files_for_any_thread_count() {
    // one thread: the clean call the resume test compares against too
    let one = &clean_paper().files;
    let dir = std::env::temp_dir().join(format!("topple-determinism-{}", std::process::id()));
    let d = dir.to_str().unwrap();
    let mut args = vec!["paper", "--out", d];
    args.extend_from_slice(&PAPER_ARGS);
    topple(&args, 3);
    let three = files(&dir);
    assert!(
        one.len() >= 4,
        "{:?}",
        one.iter().map(|f| &f.0).collect::<Vec<_>>()
    );
    assert!(*one == three, "the files differ between 1 and 3 threads");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_stress_table_is_the_same_for_any_thread_count() {
    // every line but the wall-clock one
    let table = |threads| {
        let text =
            String::from_utf8(topple(&["stress", "--seed", "3", "--combo", "7"], threads)).unwrap();
        text.lines()
            .filter(|l| !l.starts_with("longest run"))
            .collect::<Vec<_>>()
            .join("\n")
    };
    assert_eq!(table(1), table(2));
}
