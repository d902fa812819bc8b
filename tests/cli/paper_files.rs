//! `topple paper --figs 3,8 --n 10`, run once for the tests that compare
//! against a clean call (determinism over thread counts, resume after a
//! kill), and the figure files of a directory.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

/// The arguments of the small `topple paper` call the tests share.
pub const PAPER_ARGS: [&str; 4] = ["--figs", "3,8", "--n", "10"];

/// Every file of a directory, by name, as bytes. Subdirectories are skipped:
/// `runs/` is the resume cache, whose records carry each run's wall time.
pub fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .map(|p| {
            (
                p.file_name().unwrap().to_string_lossy().into_owned(),
                std::fs::read(&p).unwrap(),
            )
        })
        .collect();
    v.sort();
    v
}

/// The finished runs saved (not the temporary file of a write in flight).
pub fn saved_runs(dir: &Path) -> Vec<PathBuf> {
    match std::fs::read_dir(dir.join("runs")) {
        Ok(r) => r
            .map(|e| e.unwrap().path())
            .filter(|p| !p.file_name().unwrap().to_string_lossy().starts_with('.'))
            .collect(),
        Err(_) => Vec::new(),
    }
}

/// What a clean call on one thread leaves: the figure files and the number
/// of saved runs.
pub struct CleanPaper {
    /// The figure files, by name.
    pub files: Vec<(String, Vec<u8>)>,
    /// Runs saved under `runs/`.
    pub saved_runs: usize,
}

/// `topple paper --out DIR` with [`PAPER_ARGS`] and `RAYON_NUM_THREADS=1`,
/// in a fresh temporary directory, run once per test binary.
pub fn clean_paper() -> &'static CleanPaper {
    static CLEAN: OnceLock<CleanPaper> = OnceLock::new();
    CLEAN.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("topple-paper-clean-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let out = Command::new(env!("CARGO_BIN_EXE_topple"))
            .args(["paper", "--out", dir.to_str().unwrap()])
            .args(PAPER_ARGS)
            .env("RAYON_NUM_THREADS", "1")
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let clean = CleanPaper {
            files: files(&dir),
            saved_runs: saved_runs(&dir).len(),
        };
        std::fs::remove_dir_all(&dir).unwrap();
        clean
    })
}
