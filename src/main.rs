//! The `betr` command line. Exit status: 0 when the tree succeeds, 1 when it fails in the
//! world, 2 for bad input or a result that could not be written, standard output included
//! (with the reason on stderr).
#![forbid(unsafe_code)]

mod cli;

use std::process::ExitCode;

use betr::http_text::WithoutSecrets;

fn main() -> ExitCode {
    let args = cli::Cli::parse_checked();
    let filter =
        tracing_subscriber::EnvFilter::try_from_env("BETR_LOG").unwrap_or_else(|_| "warn".into());
    let workbench = match &args.command {
        None | Some(cli::Command::Tui(_)) => true,
        Some(cli::Command::Replay(r)) => !r.print && r.to_rrd.is_none(),
        Some(cli::Command::Monitor(m)) => !m.print,
        _ => false,
    };
    if workbench {
        // The terminal belongs to the screen: log to a file (or nowhere).
        let file = cli::tui_cmd::log_path().and_then(|p| {
            std::fs::create_dir_all(p.parent()?).ok()?;
            std::fs::OpenOptions::new()
                .create(true)
                .append(true)
                .open(p)
                .ok()
        });
        let builder = tracing_subscriber::fmt()
            .with_env_filter(filter)
            .with_ansi(false);
        match file {
            Some(f) => builder
                .with_writer(std::sync::Mutex::new(WithoutSecrets(f)))
                .init(),
            None => builder.with_writer(std::io::sink).init(),
        }
    } else {
        // Colours only for a person at a terminal; a file or a pipe gets plain text.
        tracing_subscriber::fmt()
            .with_env_filter(filter)
            .with_ansi(std::io::IsTerminal::is_terminal(&std::io::stderr()))
            .with_writer(|| WithoutSecrets(std::io::stderr()))
            .init();
    }
    let code = match cli::run(args) {
        Ok(code) => code,
        Err(e) => {
            cli::out::stderr(format_args!("error: {e:#}\n"));
            return ExitCode::from(2);
        }
    };
    // What was printed is part of the result: a redirection that could not take it all
    // is a failed command, and so is a file a writer could not write midway.
    let mut failed = false;
    if let Err(e) = cli::out::finish() {
        cli::out::stderr(format_args!("error: {e}\n"));
        failed = true;
    }
    for unwritten in betr::store::unwritten() {
        cli::out::stderr(format_args!("error: could not write {unwritten}\n"));
        failed = true;
    }
    if failed { ExitCode::from(2) } else { code }
}
