//! Nothing lost: `topple paper` writes every file whole (temporary name,
//! then rename) and saves each finished run; killed in the middle, it leaves
//! only whole files, and `--resume` finishes the job with the files a
//! clean call writes.

use std::path::Path;
use std::process::{Command, Stdio};

use super::paper_files::{clean_paper, files as figures, saved_runs, PAPER_ARGS as ARGS};

fn paper(out: &Path, resume: bool) -> String {
    let mut args = vec!["paper", "--out", out.to_str().unwrap()];
    args.extend_from_slice(&ARGS);
    if resume {
        args.push("--resume");
    }
    let o = Command::new(env!("CARGO_BIN_EXE_topple"))
        .args(&args)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8(o.stderr).unwrap()
}

#[test]
fn a_killed_paper_leaves_whole_files_and_resumes_to_the_same_figures() {
    let root = std::env::temp_dir().join(format!("topple-resume-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    let clean = clean_paper();
    let want = &clean.files;
    assert_eq!(
        want.len(),
        4,
        "{:?}",
        want.iter().map(|f| &f.0).collect::<Vec<_>>()
    );
    assert_eq!(clean.saved_runs, 8, "2 runs of Fig. 3, 6 of Fig. 8");

    // kill a second call once it has saved a run
    let cut = root.join("cut");
    let mut args = vec!["paper", "--out", cut.to_str().unwrap()];
    args.extend_from_slice(&ARGS);
    let mut child = Command::new(env!("CARGO_BIN_EXE_topple"))
        .args(&args)
        .env("RAYON_NUM_THREADS", "1")
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    while saved_runs(&cut).is_empty() && child.try_wait().unwrap().is_none() {
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let _ = child.kill();
    child.wait().unwrap();
    // whatever is there under a final name is whole
    for p in saved_runs(&cut) {
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        let text = std::fs::read_to_string(&p).unwrap();
        serde_json::from_str::<serde_json::Value>(&text)
            .unwrap_or_else(|e| panic!("{name} is not whole: {e}"));
    }
    let done_before = saved_runs(&cut).len();
    let stderr = paper(&cut, true);
    assert!(
        stderr.contains(&format!("reused {done_before} of 8 runs")) || done_before == 0,
        "{stderr}"
    );
    assert!(
        figures(&cut) == *want,
        "resumed figures differ from a clean call"
    );

    // a saved run whose inputs do not match is not reused
    let runs = saved_runs(&cut);
    let first = &runs[0];
    let text = std::fs::read_to_string(first).unwrap();
    std::fs::write(first, text.replacen("\"push\":", "\"push\":9", 1)).unwrap();
    let stderr = paper(&cut, true);
    assert!(stderr.contains("reused 7 of 8 runs"), "{stderr}");
    assert!(figures(&cut) == *want);
    std::fs::remove_dir_all(&root).unwrap();
}
