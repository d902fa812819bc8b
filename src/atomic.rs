//! Whole files or none: a file is written under a temporary name in its own
//! directory, flushed to disk, then renamed over its final name (a rename
//! within one directory is atomic on POSIX file systems). An interrupted
//! `topple paper` or sweep leaves every file it finished whole, and no file
//! half written under its final name.
//!
//! ```
//! let dir = std::env::temp_dir().join(format!("topple-atomic-doc-{}", std::process::id()));
//! std::fs::create_dir_all(&dir).unwrap();
//! let path = dir.join("a.csv");
//! topple::atomic::write(&path, b"x,y\n1,2\n").unwrap();
//! assert_eq!(std::fs::read(&path).unwrap(), b"x,y\n1,2\n");
//! std::fs::remove_dir_all(&dir).unwrap();
//! ```

use std::io::Write;
use std::path::{Path, PathBuf};

/// The temporary name of `path` while it is written: `.NAME.PID.tmp` in the
/// same directory (hidden, and never taken for a finished file).
pub fn temp_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!(".{name}.{}.tmp", std::process::id()))
}

/// Writes `bytes` to `path` atomically (see the module docs).
pub fn write(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let tmp = temp_path(path);
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}
