//! A recording asked for and not made is a failed command: `--record` on a disk that
//! fills up during the run ends it with an error (exit 2), and what was written stays
//! readable. The disk is a 64 KiB tmpfs filled to its last page, which needs root (in a
//! container, one allowed to mount) to mount. Where it cannot be mounted the test fails
//! under CI saying so, and elsewhere prints why it checks nothing.

#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use crate::support;

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;

use support::cli::{betr, text, tmp};
use support::fixtures;

/// A mounted tmpfs, unmounted when dropped.
struct Tmpfs(PathBuf);

impl Tmpfs {
    /// The tmpfs mounted at `dir`, or what `mount` said when it could not be.
    fn mount(dir: &Path) -> Result<Tmpfs, String> {
        std::fs::create_dir_all(dir).unwrap();
        let out = Command::new("mount")
            .args(["-t", "tmpfs", "-o", "size=64k", "tmpfs"])
            .arg(dir)
            .output()
            .map_err(|e| format!("`mount` could not be run: {e}"))?;
        if !out.status.success() {
            return Err(format!(
                "`mount -t tmpfs` failed ({}): {}",
                out.status,
                String::from_utf8_lossy(&out.stderr).trim()
            ));
        }
        Ok(Tmpfs(dir.to_path_buf()))
    }

    /// Fill the disk, leaving one page free.
    fn fill_but_a_page(&self) {
        std::fs::write(self.0.join("slack"), [0u8; 4096]).unwrap();
        let mut filler = std::fs::File::create(self.0.join("filler")).unwrap();
        while filler.write_all(&[0u8; 4096]).is_ok() {}
        drop(filler);
        std::fs::remove_file(self.0.join("slack")).unwrap();
    }
}

impl Drop for Tmpfs {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(&self.0).status();
    }
}

#[test]
fn a_disk_that_fills_during_a_recorded_repair_fails_it() {
    let dir = tmp("full-disk");
    let disk = match Tmpfs::mount(&dir.join("disk")) {
        Ok(disk) => disk,
        Err(why) => {
            support::check::cannot_check(
                "the full-disk test",
                &format!(
                    "it could not make a full filesystem: a 64 KiB tmpfs at {} needs root \
                     (in a container, one allowed to mount); {why}",
                    dir.join("disk").display()
                ),
            );
            return;
        }
    };
    disk.fill_but_a_page();
    let scenario = fixtures::root()
        .join("scenarios/cell/red_on_blue.toml")
        .to_string_lossy()
        .into_owned();
    // A repair records its plan, runs and change: more than a page.
    let out = betr(
        &dir,
        &[
            "repair",
            &scenario,
            "--add",
            "~\"any object\" on \"blue cube\"",
            "--record",
            "disk/r.jsonl",
        ],
    );
    let log = text(&out);
    assert_eq!(out.status.code(), Some(2), "{log}");
    assert!(log.contains("--record"), "{log}");
    assert!(log.contains("No space left on device"), "{log}");
    // What was written before the disk filled reads back.
    let recording = betr::record::read(&dir.join("disk/r.jsonl")).unwrap();
    assert_eq!(
        recording.header.scenario_name(),
        Some("Red cube on the blue cube")
    );
    drop(disk);
    std::fs::remove_dir_all(&dir).unwrap();
}
