//! The command line's definition, checked through the binary: every command's help,
//! down to the subcommands of subcommands, is built by clap, whose debug builds assert
//! the definition (conflicting names, a default outside its values, a missing value
//! name) as each command is built. The binary has no unit tests of its own, so this is
//! where the definition is checked.

#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use crate::support;

use support::cli::{betr, text, tmp};

/// The subcommands a help text lists under "Commands:" (clap's `help` left out).
fn subcommands(help: &str) -> Vec<String> {
    help.lines()
        .skip_while(|l| l.trim() != "Commands:")
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|name| *name != "help")
        .map(str::to_string)
        .collect()
}

#[test]
fn every_command_and_subcommand_builds_its_help() {
    let dir = tmp("command-line");
    let mut pending: Vec<Vec<String>> = vec![Vec::new()];
    let mut seen = 0;
    while let Some(path) = pending.pop() {
        let mut args: Vec<&str> = path.iter().map(String::as_str).collect();
        args.push("--help");
        let out = betr(&dir, &args);
        let help = String::from_utf8_lossy(&out.stdout).into_owned();
        assert_eq!(out.status.code(), Some(0), "{args:?}: {}", text(&out));
        assert!(help.contains("Usage: betr"), "{args:?}: {help}");
        seen += 1;
        for sub in subcommands(&help) {
            let mut deeper = path.clone();
            deeper.push(sub);
            pending.push(deeper);
        }
    }
    // betr, its commands, and the subcommands of eval, knowledge and model.
    assert!(seen > 20, "{seen} helps built");
}

/// A first word that is neither a command nor a scenario, but close to a command's name,
/// is answered with that command; one close to nothing names only the scenario it could
/// not find.
#[test]
fn a_mistyped_command_gets_the_command_it_was_likely_meant_as() {
    let dir = tmp("command-line-typo");
    let out = betr(&dir, &["tiu"]);
    let log = text(&out);
    assert_eq!(out.status.code(), Some(2), "{log}");
    assert!(
        log.contains("did you mean the command `betr tui`?"),
        "{log}"
    );
    let out = betr(&dir, &["verfy"]);
    assert!(text(&out).contains("`betr verify`"), "{}", text(&out));
    let out = betr(&dir, &["zzzzzz"]);
    let log = text(&out);
    assert_eq!(out.status.code(), Some(2), "{log}");
    assert!(
        log.contains("zzzzzz") && !log.contains("did you mean the command"),
        "{log}"
    );
}

/// `export` takes a scenario by its name, as the other commands do.
#[test]
fn export_takes_a_scenario_by_name() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_betr"))
        .args(["export", "cell/red_on_blue", "--format", "btcpp"])
        .current_dir(support::fixtures::root())
        .env("BETR_OFFLINE", "1")
        .env("XDG_CACHE_HOME", tmp("command-line-export").join("cache"))
        .output()
        .unwrap();
    let xml = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    assert!(xml.contains("<root BTCPP_format=\"4\""), "{xml}");
}

/// Options before a command are the workbench's: given with a command they are refused,
/// naming them, instead of ignored; the global flags are taken anywhere.
#[test]
fn workbench_options_before_a_command_are_refused_not_ignored() {
    let dir = tmp("command-line-before");
    let scenario = support::fixtures::root()
        .join("scenarios/cell/red_on_blue.toml")
        .to_string_lossy()
        .into_owned();
    let out = betr(&dir, &["--viewer", "web", "plan", &scenario]);
    let log = text(&out);
    assert_eq!(out.status.code(), Some(2), "{log}");
    assert!(log.contains("--viewer before the command `plan`"), "{log}");
    // Planned (and predicted to fail in simulation: exit 1), the flag taken.
    let out = betr(&dir, &["--ascii", "plan", &scenario]);
    let log = text(&out);
    assert_eq!(out.status.code(), Some(1), "{log}");
    assert!(log.contains("Planned in") && !log.contains('▸'), "{log}");
}
