//! Standard output and error of the commands. A reader that goes away early
//! (`betr plan S | head -1`) ends the printing, never the command: what is left to print is
//! dropped, the command finishes its work (saves included) and exits with the status it
//! would have had. `outln!`, `out!` and `errln!` stand for `println!`, `print!` and
//! `eprintln!`, which panic when the stream is closed.

use std::fmt;
use std::io::{self, Write};
use std::sync::atomic::{AtomicBool, Ordering};

/// Set once standard output could not be written: nothing more is tried.
static STDOUT_GONE: AtomicBool = AtomicBool::new(false);
/// The same for standard error.
static STDERR_GONE: AtomicBool = AtomicBool::new(false);

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
    put(&STDOUT_GONE, &mut io::stdout().lock(), args);
}

/// Write to standard error unless it has gone.
pub fn stderr(args: fmt::Arguments) {
    put(&STDERR_GONE, &mut io::stderr().lock(), args);
}

fn put(gone: &AtomicBool, stream: &mut impl Write, args: fmt::Arguments) {
    if gone.load(Ordering::Relaxed) {
        return;
    }
    if let Err(e) = stream.write_fmt(args) {
        closed(gone, &e);
    }
}

/// A stream that failed is left alone from now on; anything but a reader that went away
/// (a full disk behind a redirection) is said in the log.
fn closed(gone: &AtomicBool, error: &io::Error) {
    if !gone.swap(true, Ordering::Relaxed) && error.kind() != io::ErrorKind::BrokenPipe {
        tracing::warn!(%error, "standard output or error cannot be written; printing stops");
    }
}

/// Standard output as an `io::Write` for code that writes reports: once it has gone,
/// every write succeeds without writing, so a report's writer never fails the command.
pub struct Stdout;

impl Write for Stdout {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        if !STDOUT_GONE.load(Ordering::Relaxed)
            && let Err(e) = io::stdout().lock().write_all(buf)
        {
            closed(&STDOUT_GONE, &e);
        }
        Ok(buf.len())
    }

    fn flush(&mut self) -> io::Result<()> {
        if !STDOUT_GONE.load(Ordering::Relaxed)
            && let Err(e) = io::stdout().lock().flush()
        {
            closed(&STDOUT_GONE, &e);
        }
        Ok(())
    }
}

/// Flush standard output (a prompt without a newline), quietly when it has gone.
pub fn flush() {
    let _ = Stdout.flush();
}
