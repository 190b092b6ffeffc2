//! Standard output and error of the commands. A reader that goes away early
//! (`betr plan S | head -1`) ends the printing, never the command: what is left to print is
//! dropped, the command finishes its work (saves included) and exits with the status it
//! would have had. Any other failure to write standard output (a full disk behind a
//! redirection) makes the command fail at its end (`finish`), so nobody takes a cut file
//! for a whole one. `outln!`, `out!` and `errln!` stand for `println!`, `print!` and
//! `eprintln!`, which panic when the stream is closed.

use std::fmt;
use std::io::{self, Write};
use std::sync::OnceLock;
use std::sync::atomic::{AtomicBool, Ordering};

/// Set once standard output could not be written: nothing more is tried.
static STDOUT_GONE: AtomicBool = AtomicBool::new(false);
/// The same for standard error.
static STDERR_GONE: AtomicBool = AtomicBool::new(false);
/// Why standard output could not be written, unless its reader went away.
static STDOUT_FAILED: OnceLock<String> = OnceLock::new();

/// `println!` that stops printing, quietly, once standard output is closed.
macro_rules! outln {
    () => {
        $crate::cli::out::stdout(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        $crate::cli::out::stdout(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// `print!` that stops printing, quietly, once standard output is closed.
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::cli::out::stdout(format_args!($($arg)*))
    };
}

/// `eprintln!` that stops printing, quietly, once standard error is closed.
macro_rules! errln {
    ($($arg:tt)*) => {
        $crate::cli::out::stderr(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// Write to standard output unless it has gone.
pub fn stdout(args: fmt::Arguments) {
    if !STDOUT_GONE.load(Ordering::Relaxed)
        && let Err(e) = io::stdout().lock().write_all(shown(args).as_bytes())
    {
        stdout_failed(&e);
    }
}

/// Write to standard error unless it has gone.
pub fn stderr(args: fmt::Arguments) {
    if !STDERR_GONE.load(Ordering::Relaxed)
        && io::stderr()
            .lock()
            .write_all(shown(args).as_bytes())
            .is_err()
    {
        // Nowhere left to say it.
        STDERR_GONE.store(true, Ordering::Relaxed);
    }
}

/// What is printed, with the escape sequences and reordering marks that text from outside
/// (a scenario's names, a model's reply, a file's line in an error) may carry written out,
/// so they show instead of acting on the terminal (betr's own output has none), and
/// without the secrets betr holds.
fn shown(args: fmt::Arguments) -> String {
    let text = args.to_string();
    betr::http_text::printable(&betr::http_text::without_secrets(&text)).into_owned()
}

/// Standard output is left alone from now on; a failure other than a reader that went
/// away is kept for `finish`.
fn stdout_failed(error: &io::Error) {
    if !STDOUT_GONE.swap(true, Ordering::Relaxed) && error.kind() != io::ErrorKind::BrokenPipe {
        tracing::warn!(%error, "standard output cannot be written; printing stops");
        let _ = STDOUT_FAILED.set(error.to_string());
    }
}

/// At the end of a command: what is left of standard output written out, and an error if
/// any of it could not be written for a reason other than its reader going away.
pub fn finish() -> Result<(), String> {
    flush();
    match STDOUT_FAILED.get() {
        Some(e) => Err(format!("standard output could not be written: {e}")),
        None => Ok(()),
    }
}

/// Standard output as an `io::Write` for code that writes reports: once it has gone,
/// every write succeeds without writing, so a report's writer never stops midway (the
/// command fails at its end instead, `finish`).
pub struct Stdout;

impl Write for Stdout {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        // Formatting writes whole `str` pieces, so a piece is text unless it was bytes.
        let text = String::from_utf8_lossy(buf);
        if !STDOUT_GONE.load(Ordering::Relaxed)
            && let Err(e) = io::stdout().lock().write_all(
                betr::http_text::printable(&betr::http_text::without_secrets(&text)).as_bytes(),
            )
        {
            stdout_failed(&e);
        }
        Ok(buf.len())
    }

    fn flush(&mut self) -> io::Result<()> {
        if !STDOUT_GONE.load(Ordering::Relaxed)
            && let Err(e) = io::stdout().lock().flush()
        {
            stdout_failed(&e);
        }
        Ok(())
    }
}

/// Flush standard output (a prompt without a newline), quietly when it has gone.
pub fn flush() {
    let _ = Stdout.flush();
}
