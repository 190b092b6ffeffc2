//! Writing files so that a reader never sees half of one: trees and policies are written
//! to a temporary file beside the target, flushed to disk, then renamed over it.

use std::fs::{self, File};
use std::io::Write;
use std::path::Path;

/// Whether `path` can be written by `write_atomic`, found before the work that produces
/// it: `path` must not be a directory, and the nearest directory on its way that exists
/// must take a new file (a probe, removed at once), so the missing ones can be made.
/// Nothing is left behind. Errors name the path.
pub fn check_writable(path: &Path) -> std::io::Result<()> {
    let named = |e: std::io::Error| {
        std::io::Error::new(
            e.kind(),
            format!("{} cannot be written: {e}", path.display()),
        )
    };
    if path.is_dir() {
        return Err(named(std::io::Error::new(
            std::io::ErrorKind::IsADirectory,
            "it is a directory",
        )));
    }
    let mut dir = parent(path);
    while !dir.exists() && parent(dir) != dir {
        dir = parent(dir);
    }
    let probe = dir.join(format!(".{}.{}.probe", file_name(path), std::process::id()));
    File::options()
        .write(true)
        .create_new(true)
        .open(&probe)
        .map_err(named)?;
    fs::remove_file(&probe).map_err(named)
}

/// The directory a file is written in (`.` for a bare name).
fn parent(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

fn file_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "betr".into())
}

/// Replace `path` with `bytes` atomically: after a crash the file holds either its old
/// content or the new one, never a mix or nothing.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let dir = parent(path);
    fs::create_dir_all(dir)?;
    let tmp = dir.join(format!(".{}.{}.tmp", file_name(path), std::process::id()));
    let result = (|| {
        let mut f = File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        drop(f);
        fs::rename(&tmp, path)?;
        // Persist the rename itself.
        if let Ok(d) = File::open(dir) {
            let _ = d.sync_all();
        }
        Ok(())
    })();
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn replaces_content_and_leaves_no_temporary() {
        let dir = std::env::temp_dir().join(format!("betr-store-{}", std::process::id()));
        let path = dir.join("tree.bt");
        write_atomic(&path, b"one").unwrap();
        write_atomic(&path, b"two").unwrap();
        assert_eq!(fs::read_to_string(&path).unwrap(), "two");
        let leftovers: Vec<_> = fs::read_dir(&dir)
            .unwrap()
            .filter_map(Result::ok)
            .filter(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
            .collect();
        assert!(leftovers.is_empty());
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_path_that_cannot_be_written_is_found_before_any_work() {
        let dir = std::env::temp_dir().join(format!("betr-store-check-{}", std::process::id()));
        fs::create_dir_all(&dir).unwrap();
        check_writable(&dir.join("new/sub/tree.bt")).unwrap();
        assert!(!dir.join("new").exists(), "nothing is made");
        assert!(
            fs::read_dir(&dir).unwrap().next().is_none(),
            "the probe is removed"
        );
        let file = dir.join("a-file");
        fs::write(&file, "x").unwrap();
        let e = check_writable(&file.join("tree.bt"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("a-file/tree.bt cannot be written"), "{e}");
        let e = check_writable(&dir).unwrap_err().to_string();
        assert!(e.contains("is a directory"), "{e}");
        fs::remove_dir_all(&dir).unwrap();
    }
}
