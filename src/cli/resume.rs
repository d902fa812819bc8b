//! Finished runs kept on disk so that an interrupted sweep can resume:
//! each run's report is written whole (temporary file, then rename) to
//! `DIR/runs/` as soon as it finishes, with the row and settings it came
//! from; `--resume` reuses a saved report only when those match exactly.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use topple::domino::{ChainReport, RowSpec};
use topple::reference::Settings;

/// One saved run.
#[derive(Serialize, Deserialize)]
struct Saved {
    row: RowSpec,
    settings: Settings,
    report: ChainReport,
}

/// FNV-1a (64 bits) of the text: a stable file name for a run's inputs.
fn fnv1a(text: &str) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in text.bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// The store of finished runs under `out/runs`.
pub struct RunStore {
    dir: PathBuf,
}

impl RunStore {
    /// The store of `out` (its directory is created on the first save).
    pub fn new(out: &Path) -> Self {
        RunStore {
            dir: out.join("runs"),
        }
    }

    /// The directory the runs are saved in.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    fn path(&self, row: &RowSpec, settings: &Settings) -> PathBuf {
        let key = serde_json::to_string(&(row, settings)).unwrap_or_default();
        self.dir.join(format!("{:016x}.json", fnv1a(&key)))
    }

    /// The saved report of this run, if its inputs match exactly.
    pub fn load(&self, row: &RowSpec, settings: &Settings) -> Option<ChainReport> {
        let text = std::fs::read_to_string(self.path(row, settings)).ok()?;
        let saved: Saved = serde_json::from_str(&text).ok()?;
        (saved.row == *row && saved.settings == *settings).then_some(saved.report)
    }

    /// Saves a finished run (whole or not at all).
    pub fn save(
        &self,
        row: &RowSpec,
        settings: &Settings,
        report: &ChainReport,
    ) -> anyhow::Result<()> {
        std::fs::create_dir_all(&self.dir)?;
        let saved = Saved {
            row: *row,
            settings: settings.clone(),
            report: report.clone(),
        };
        let text = serde_json::to_string(&saved)?;
        topple::atomic::write(&self.path(row, settings), text.as_bytes())?;
        Ok(())
    }
}
