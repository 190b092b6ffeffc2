//! While the screen is up, the process's standard error goes to a file: native libraries
//! write there directly (ALSA when a microphone is opened on a machine without one,
//! llama.cpp and CTranslate2 while loading), which would scribble over the screen. The
//! original is put back on every exit path, before a panic message is printed.

use std::fs::OpenOptions;
use std::os::fd::{AsFd, OwnedFd};
use std::path::Path;
use std::sync::Mutex;

/// The terminal's standard error while it is redirected.
static SAVED: Mutex<Option<OwnedFd>> = Mutex::new(None);

/// Send standard error to `file` (appended) until [`restore`].
pub fn redirect(file: &Path) -> std::io::Result<()> {
    let target = OpenOptions::new().create(true).append(true).open(file)?;
    let mut saved = SAVED
        .lock()
        .map_err(|_| std::io::Error::other("the saved standard error is poisoned"))?;
    if saved.is_none() {
        *saved = Some(std::io::stderr().as_fd().try_clone_to_owned()?);
    }
    nix::unistd::dup2_stderr(&target)?;
    Ok(())
}

/// Put the terminal's standard error back (nothing when it was not redirected).
pub fn restore() {
    let saved = match SAVED.lock() {
        Ok(mut s) => s.take(),
        Err(poisoned) => poisoned.into_inner().take(),
    };
    if let Some(fd) = saved {
        // Nothing better can be done on the way out than to leave it as it is.
        let _ = nix::unistd::dup2_stderr(&fd);
    }
}
