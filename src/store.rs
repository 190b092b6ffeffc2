//! Writing files so that a reader never sees half of one: trees and policies are written
//! to a temporary file beside the target, flushed to disk, then renamed over it (a device,
//! FIFO or socket is written through instead, never replaced); logs of
//! JSON lines (cassettes, the usage log) grow by whole lines, each appended with one
//! write under a lock of the file, and are read back leaving out a cut last line.

use std::fs::{self, File};
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

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
    let path = &follow_links(path).map_err(named)?;
    match fs::metadata(path) {
        Ok(m) if m.is_dir() => {
            return Err(named(std::io::Error::new(
                std::io::ErrorKind::IsADirectory,
                "it is a directory",
            )));
        }
        // Written through when the time comes (`write_atomic`); a FIFO cannot be opened
        // to try without waiting for its reader.
        Ok(m) if !m.is_file() => return Ok(()),
        _ => {}
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

/// Write `bytes` to `path` so that no reader sees half of them (and no secret betr holds,
/// `http_text::without_secrets`). A regular file, or a path
/// where nothing is yet, is replaced atomically: after a crash it holds either its old
/// content or the new one, never a mix or nothing. A symbolic link is followed, and what it
/// points to is written by the same rules (the link stays). A device, FIFO or socket
/// (`/dev/null`, a pipe someone reads) is written through, never replaced. A directory is
/// refused.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let text = std::str::from_utf8(bytes).map(crate::http_text::without_secrets);
    let bytes = match &text {
        Ok(text) => text.as_bytes(),
        Err(_) => bytes,
    };
    let target = follow_links(path)?;
    match fs::metadata(&target) {
        Ok(m) if m.is_dir() => Err(std::io::Error::new(
            std::io::ErrorKind::IsADirectory,
            format!("{} is a directory", target.display()),
        )),
        Ok(m) if !m.is_file() => File::options().write(true).open(&target)?.write_all(bytes),
        _ => replace(&target, bytes),
    }
}

/// Replace the regular file (or nothing) at `path` by way of a temporary file beside it.
fn replace(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let dir = parent(path);
    fs::create_dir_all(dir)?;
    remove_orphaned_temporaries(dir, &file_name(path));
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

/// The path `path`'s symbolic links lead to (itself when it is none); a link to nothing
/// leads to the path it names, where the file will be made.
fn follow_links(path: &Path) -> std::io::Result<PathBuf> {
    // As many links as Linux follows in one path.
    const MOST_LINKS: usize = 40;
    let mut at = path.to_path_buf();
    for _ in 0..MOST_LINKS {
        match fs::symlink_metadata(&at) {
            Ok(m) if m.file_type().is_symlink() => {
                let to = fs::read_link(&at)?;
                at = if to.is_absolute() {
                    to
                } else {
                    parent(&at).join(to)
                };
            }
            _ => return Ok(at),
        }
    }
    Err(std::io::Error::new(
        std::io::ErrorKind::InvalidInput,
        format!(
            "{}: more than {MOST_LINKS} symbolic links in a row",
            path.display()
        ),
    ))
}

/// The temporary files earlier saves of `name` left in `dir` when their process was killed
/// between writing and renaming (`.NAME.PID.tmp` whose process is gone), removed.
fn remove_orphaned_temporaries(dir: &Path, name: &str) {
    let prefix = format!(".{name}.");
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    for entry in entries.filter_map(Result::ok) {
        let file = entry.file_name();
        let Some(pid) = file
            .to_str()
            .and_then(|f| f.strip_prefix(&prefix))
            .and_then(|rest| rest.strip_suffix(".tmp"))
            .and_then(|pid| pid.parse::<i32>().ok())
        else {
            continue;
        };
        if !process_alive(pid) {
            let _ = fs::remove_file(entry.path());
        }
    }
}

/// Whether a process `pid` runs (signal 0 reaches it, or exists but may not be signalled).
fn process_alive(pid: i32) -> bool {
    use nix::errno::Errno;
    match nix::sys::signal::kill(nix::unistd::Pid::from_raw(pid), None) {
        Ok(()) => true,
        Err(e) => e != Errno::ESRCH,
    }
}

/// Files a writer could not write without failing the work it was part of (a cassette's
/// entry after a call that was paid for, a usage record), each with why.
static UNWRITTEN: std::sync::Mutex<Vec<String>> = std::sync::Mutex::new(Vec::new());

/// Keep, for the end of the command, that `path` could not be written: the work goes on
/// (the reply is used, the tree is saved) and the command then fails naming the file.
pub fn note_unwritten(path: &Path, error: &dyn std::fmt::Display) {
    if let Ok(mut unwritten) = UNWRITTEN.lock() {
        unwritten.push(format!("{}: {error}", path.display()));
    }
}

/// What [`note_unwritten`] kept, each once, in the order it came.
pub fn unwritten() -> Vec<String> {
    let mut seen = Vec::new();
    if let Ok(unwritten) = UNWRITTEN.lock() {
        for u in unwritten.iter() {
            if !seen.contains(u) {
                seen.push(u.clone());
            }
        }
    }
    seen
}

/// The most betr reads of a file a person writes or points it to: scenarios, settings,
/// prompts, learned rules.
pub const SMALL_FILE_BYTES: u64 = 4 << 20;
/// The most betr reads of a tree or policy file.
pub const TREE_FILE_BYTES: u64 = 32 << 20;
/// The most betr reads of a log it wrote: a recording, a cassette.
pub const LOG_FILE_BYTES: u64 = 1 << 30;

/// The text of `path`, read only up to `limit` bytes: a larger file (or a device that never
/// ends, `/dev/zero`) is an error naming the limit, not all the memory there is. Bytes
/// that are not UTF-8 are an error, as with `fs::read_to_string`.
pub fn read_text(path: &Path, limit: u64) -> std::io::Result<String> {
    let mut bytes = Vec::new();
    File::open(path)?
        .take(limit.saturating_add(1))
        .read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(std::io::Error::new(
            std::io::ErrorKind::FileTooLarge,
            format!(
                "larger than {} (the most betr reads of such a file)",
                size_text(limit)
            ),
        ));
    }
    String::from_utf8(bytes).map_err(|_| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            "stream did not contain valid UTF-8",
        )
    })
}

/// `bytes` in the largest whole unit (`4 MiB`).
fn size_text(bytes: u64) -> String {
    match bytes {
        b if b >= 1 << 30 && b % (1 << 30) == 0 => format!("{} GiB", b >> 30),
        b if b >= 1 << 20 && b % (1 << 20) == 0 => format!("{} MiB", b >> 20),
        b if b >= 1 << 10 && b % (1 << 10) == 0 => format!("{} KiB", b >> 10),
        b => format!("{b} bytes"),
    }
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
    let line = crate::http_text::without_secrets(line);
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

    #[test]
    fn special_files_are_written_through_and_links_followed_never_replaced() {
        use std::os::unix::fs::{FileTypeExt, symlink};
        let dir = std::env::temp_dir().join(format!("betr-store-special-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap();

        // A FIFO: its reader gets the bytes, and it is still a FIFO.
        let fifo = dir.join("pipe.bt");
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap();
        assert!(made.success());
        let reader = {
            let fifo = fifo.clone();
            std::thread::spawn(move || fs::read_to_string(fifo).unwrap())
        };
        check_writable(&fifo).unwrap();
        write_atomic(&fifo, b"tree").unwrap();
        assert_eq!(reader.join().unwrap(), "tree");
        assert!(fs::symlink_metadata(&fifo).unwrap().file_type().is_fifo());

        // A link to a file: the file gets the bytes, the link stays a link.
        let real = dir.join("real.bt");
        fs::write(&real, "old").unwrap();
        let link = dir.join("link.bt");
        symlink("real.bt", &link).unwrap();
        write_atomic(&link, b"new").unwrap();
        assert!(
            fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(fs::read_to_string(&real).unwrap(), "new");

        // A link to nothing yet: the file it names is made.
        let dangling = dir.join("later.bt");
        symlink("made-later.bt", &dangling).unwrap();
        write_atomic(&dangling, b"made").unwrap();
        assert!(
            fs::symlink_metadata(&dangling)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(
            fs::read_to_string(dir.join("made-later.bt")).unwrap(),
            "made"
        );

        // A directory is refused, by name.
        let e = write_atomic(&dir, b"x").unwrap_err().to_string();
        assert!(e.contains("is a directory"), "{e}");
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_killed_saves_temporary_is_removed_by_the_next_save() {
        let dir = std::env::temp_dir().join(format!("betr-store-orphan-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap();
        // Above Linux's largest pid (2^22), so no process has it.
        let orphan = dir.join(".tree.bt.99999999.tmp");
        fs::write(&orphan, "half").unwrap();
        // Another file's temporary, and one whose process runs (init), stay.
        let other = dir.join(".other.bt.99999999.tmp");
        fs::write(&other, "x").unwrap();
        let live = dir.join(".tree.bt.1.tmp");
        fs::write(&live, "x").unwrap();
        write_atomic(&dir.join("tree.bt"), b"whole").unwrap();
        assert!(!orphan.exists());
        assert!(other.exists() && live.exists());
        assert_eq!(fs::read_to_string(dir.join("tree.bt")).unwrap(), "whole");
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn reading_stops_at_the_limit_and_says_it() {
        let dir = std::env::temp_dir().join(format!("betr-store-read-{}", std::process::id()));
        fs::create_dir_all(&dir).unwrap();
        let path = dir.join("s.toml");
        fs::write(&path, "12345").unwrap();
        assert_eq!(read_text(&path, 5).unwrap(), "12345");
        let e = read_text(&path, 4).unwrap_err();
        assert_eq!(e.kind(), std::io::ErrorKind::FileTooLarge);
        assert!(e.to_string().contains("larger than 4 bytes"), "{e}");
        // A device without end is read only to the limit.
        let e = read_text(Path::new("/dev/zero"), SMALL_FILE_BYTES).unwrap_err();
        assert!(e.to_string().contains("larger than 4 MiB"), "{e}");
        fs::write(&path, [0xff, 0xfe]).unwrap();
        assert_eq!(
            read_text(&path, 5).unwrap_err().kind(),
            std::io::ErrorKind::InvalidData
        );
        fs::remove_dir_all(&dir).unwrap();
    }
}
