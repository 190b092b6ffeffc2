//! Writing files so that a reader never sees half of one: trees and policies are written
//! to a temporary file beside the target, flushed to disk, then renamed over it; logs of
//! JSON lines (cassettes, the usage log) grow by whole lines, each appended with one
//! write under a lock of the file, and are read back leaving out a cut last line.

use std::fs::{self, File};
use std::io::{Read, Seek, SeekFrom, Write};
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

/// Append `line` and its newline to `path` (made with its directory if missing) with one
/// write, holding an exclusive lock of the file, so writers in several processes never
/// interleave and a kill leaves whole lines and at most one cut last line. A cut last
/// line an earlier writer left is taken off first (it was never a whole entry), so a
/// new line is never glued to it.
pub fn append_line(path: &Path, line: &str) -> std::io::Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        fs::create_dir_all(dir)?;
    }
    let mut file = File::options()
        .create(true)
        .read(true)
        .append(true)
        .open(path)?;
    file.lock()?;
    let len = file.metadata()?.len();
    let whole = whole_lines_len(&mut file, len)?;
    if whole < len {
        tracing::warn!(
            path = %path.display(),
            bytes = len - whole,
            "a cut last line (a writer stopped midway) is taken off before appending"
        );
        file.set_len(whole)?;
    }
    let mut bytes = Vec::with_capacity(line.len() + 1);
    bytes.extend_from_slice(line.as_bytes());
    bytes.push(b'\n');
    file.write_all(&bytes)?;
    file.unlock()
}

/// The length of `file`'s whole lines: up to and including its last newline.
fn whole_lines_len(file: &mut File, len: u64) -> std::io::Result<u64> {
    const CHUNK: u64 = 8192;
    let mut end = len;
    let mut buf = vec![0u8; 8192];
    while end > 0 {
        let start = end.saturating_sub(CHUNK);
        let n = usize::try_from(end - start).unwrap_or(buf.len());
        file.seek(SeekFrom::Start(start))?;
        file.read_exact(&mut buf[..n])?;
        if let Some(i) = buf[..n].iter().rposition(|&b| b == b'\n') {
            return Ok(start + i as u64 + 1);
        }
        end = start;
    }
    Ok(0)
}

/// The lines of a JSON Lines text read back.
#[derive(Debug, Clone, PartialEq)]
pub struct Lines<T> {
    /// Each line read, with its 1-based number.
    pub items: Vec<(usize, T)>,
    /// The number of a last line without its newline that did not read: a writer was
    /// stopped midway through it, and it is left out.
    pub cut_at: Option<usize>,
}

/// The lines of `text` from line `first` (1-based) on, each read with `parse`; blank
/// lines are skipped. A line that does not read is an error with its number, except a
/// last line without its newline, which is left out and reported in `cut_at`.
pub fn read_lines<T, E>(
    text: &str,
    first: usize,
    mut parse: impl FnMut(&str) -> Result<T, E>,
) -> Result<Lines<T>, (usize, E)> {
    let lines: Vec<&str> = text.split_inclusive('\n').collect();
    let last = lines.len();
    let mut read = Lines {
        items: Vec::new(),
        cut_at: None,
    };
    for (i, raw) in lines.iter().enumerate().skip(first.saturating_sub(1)) {
        let number = i + 1;
        let line = raw.trim_end_matches(['\n', '\r']);
        if line.trim().is_empty() {
            continue;
        }
        match parse(line) {
            Ok(item) => read.items.push((number, item)),
            Err(_) if !raw.ends_with('\n') && number == last => read.cut_at = Some(number),
            Err(e) => return Err((number, e)),
        }
    }
    Ok(read)
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
    fn appended_lines_are_whole_and_a_cut_last_line_is_taken_off_first() {
        let dir = std::env::temp_dir().join(format!("betr-store-lines-{}", std::process::id()));
        let path = dir.join("sub/log.jsonl");
        append_line(&path, "1").unwrap();
        // A writer killed midway left half an entry.
        fs::OpenOptions::new()
            .append(true)
            .open(&path)
            .unwrap()
            .write_all(b"{\"half")
            .unwrap();
        let read =
            read_lines(&fs::read_to_string(&path).unwrap(), 1, |l| l.parse::<u32>()).unwrap();
        assert_eq!((read.items, read.cut_at), (vec![(1, 1)], Some(2)));
        append_line(&path, "2").unwrap();
        assert_eq!(fs::read_to_string(&path).unwrap(), "1\n2\n");
        // A line longer than the chunk the tail is searched in.
        let long = "3".repeat(20_000);
        append_line(&path, &long).unwrap();
        fs::OpenOptions::new()
            .append(true)
            .open(&path)
            .unwrap()
            .write_all(&[b'4'; 9000])
            .unwrap();
        append_line(&path, "5").unwrap();
        assert_eq!(
            fs::read_to_string(&path).unwrap(),
            format!("1\n2\n{long}\n5\n")
        );
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_broken_line_is_an_error_unless_it_is_a_cut_last_line() {
        let parse = |l: &str| l.parse::<u32>();
        let read = read_lines("h\n1\n\n2\nx", 2, parse).unwrap();
        assert_eq!(read.items, vec![(2, 1), (4, 2)]);
        assert_eq!(read.cut_at, Some(5));
        assert_eq!(read_lines("1\nx\n2\n", 1, parse).unwrap_err().0, 2);
        assert_eq!(read_lines("1\nx\n", 1, parse).unwrap_err().0, 2);
        assert_eq!(read_lines("", 1, parse).unwrap().items, vec![]);
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
