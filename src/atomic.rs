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
use std::sync::atomic::{AtomicU64, Ordering};

/// Writes begun by this process so far: part of each temporary name.
static WRITES: AtomicU64 = AtomicU64::new(0);

/// A temporary name for `path` while it is written: `.NAME.PID.N.tmp` in
/// the same directory (hidden, and never taken for a finished file), N
/// new at every call, so that two threads writing the same file at once
/// (two equal jobs of `topple paper`) each rename their own whole file.
///
/// ```
/// use std::path::Path;
/// let p = Path::new("out/a.csv");
/// assert_ne!(topple::atomic::temp_path(p), topple::atomic::temp_path(p));
/// ```
pub fn temp_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let n = WRITES.fetch_add(1, Ordering::Relaxed);
    path.with_file_name(format!(".{name}.{}.{n}.tmp", std::process::id()))
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

#[cfg(test)]
mod tests {
    /// Two threads writing the same file at once both succeed, and the
    /// file is one of the two writes, whole (before the temporary names
    /// were unique, the second rename found its temporary file gone).
    #[test]
    fn two_threads_writing_one_file_both_succeed() {
        let dir = std::env::temp_dir().join(format!("topple-atomic-race-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("same.csv");
        let (a, b) = (vec![b'a'; 1 << 16], vec![b'b'; 1 << 16]);
        for _ in 0..20 {
            std::thread::scope(|s| {
                let first = s.spawn(|| super::write(&path, &a));
                let second = s.spawn(|| super::write(&path, &b));
                first.join().unwrap().unwrap();
                second.join().unwrap().unwrap();
            });
            let got = std::fs::read(&path).unwrap();
            assert!(got == a || got == b);
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
