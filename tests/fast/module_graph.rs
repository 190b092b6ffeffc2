//! The shape of the code, checked from its source: the top-level modules depend on each
//! other one way (no cycle), the command line reaches the planner and the world only
//! through the session layer, library code returns typed errors, not strings, and the
//! product never imports the lab (evaluations, benchmarks, fuzzing).
//!
//! Test code (`tests.rs`, `*_tests.rs`, and everything after a file's `#[cfg(test)]`) is
//! left out: tests may reach anywhere.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Every `.rs` file under `dir`.
fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let entries = std::fs::read_dir(&d).unwrap_or_else(|e| panic!("{}: {e}", d.display()));
        for entry in entries {
            let path = entry.expect("a directory entry").path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                files.push(path);
            }
        }
    }
    files.sort();
    files
}

/// The product code of a file: nothing for test files, the part before `#[cfg(test)]`
/// otherwise.
fn product_code(path: &Path) -> String {
    let name = path
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or_default();
    if name == "tests.rs" || name.ends_with("_tests.rs") {
        return String::new();
    }
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    match text.find("#[cfg(test)]") {
        Some(at) => text[..at].to_string(),
        None => text,
    }
}

/// Code lines only: comments and doc comments dropped (they may name anything).
fn code_lines(text: &str) -> impl Iterator<Item = &str> {
    text.lines().filter(|l| !l.trim_start().starts_with("//"))
}

/// The top-level module a file belongs to (`src/session/engine/flow.rs` → `session`).
fn top_module(src: &Path, file: &Path) -> Option<String> {
    let rel = file.strip_prefix(src).ok()?;
    let first = rel.components().next()?.as_os_str().to_str()?;
    Some(first.trim_end_matches(".rs").to_string())
}

/// Which top-level modules each module's product code names (`crate::X` or `betr::X`).
fn dependencies(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let modules: BTreeSet<String> = rust_files(src)
        .iter()
        .filter_map(|f| top_module(src, f))
        .filter(|m| m != "lib" && m != "main")
        .collect();
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for file in rust_files(src) {
        let Some(from) = top_module(src, &file) else {
            continue;
        };
        let code = product_code(&file);
        let entry = graph.entry(from.clone()).or_default();
        for line in code_lines(&code) {
            for prefix in ["crate::", "betr::"] {
                for (at, _) in line.match_indices(prefix) {
                    let rest = &line[at + prefix.len()..];
                    let name: String = rest
                        .chars()
                        .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                        .collect();
                    if name != from && modules.contains(&name) {
                        entry.insert(name);
                    }
                }
            }
        }
    }
    graph
}

/// A cycle through `start`, if there is one.
fn cycle_from(graph: &BTreeMap<String, BTreeSet<String>>, start: &str) -> Option<Vec<String>> {
    let mut stack = vec![(start.to_string(), vec![start.to_string()])];
    let mut seen = BTreeSet::new();
    while let Some((node, path)) = stack.pop() {
        for next in graph.get(&node).into_iter().flatten() {
            if next == start {
                let mut cycle = path.clone();
                cycle.push(start.to_string());
                return Some(cycle);
            }
            if seen.insert(next.clone()) {
                let mut longer = path.clone();
                longer.push(next.clone());
                stack.push((next.clone(), longer));
            }
        }
    }
    None
}

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

#[test]
fn top_level_modules_depend_one_way() {
    let graph = dependencies(&src());
    assert!(graph.len() > 10, "the graph was not read: {graph:?}");
    assert!(
        graph["session"].contains("planner"),
        "the reader misses imports: {graph:?}"
    );
    let cycles: Vec<String> = graph
        .keys()
        .filter_map(|m| cycle_from(&graph, m))
        .map(|c| c.join(" → "))
        .collect();
    assert!(cycles.is_empty(), "import cycles: {cycles:#?}");
}

#[test]
fn the_command_line_reaches_planner_and_world_through_the_session() {
    let graph = dependencies(&src());
    let cli = &graph["cli"];
    assert!(
        cli.contains("session"),
        "the reader misses imports: {cli:?}"
    );
    for forbidden in ["planner", "world"] {
        assert!(
            !cli.contains(forbidden),
            "src/cli imports {forbidden} directly: {cli:?}"
        );
    }
}

#[test]
fn reading_knows_no_model_session_planner_or_world() {
    let graph = dependencies(&src());
    let reading = &graph["reading"];
    assert!(
        reading.contains("domain"),
        "the reader misses imports: {reading:?}"
    );
    for forbidden in ["llm", "session", "planner", "world"] {
        assert!(
            !reading.contains(forbidden),
            "src/reading imports {forbidden}: {reading:?}"
        );
    }
    // The model's side asks reading how requests are read, never the other way round.
    assert!(
        graph["session"].contains("reading"),
        "the session does not read requests through reading: {:?}",
        graph["session"]
    );
}

#[test]
fn library_code_returns_typed_errors() {
    let src = src();
    let mut found = Vec::new();
    for file in rust_files(&src) {
        if top_module(&src, &file).as_deref() == Some("cli") {
            // The binary's edge phrases errors for people (anyhow).
            continue;
        }
        let code = product_code(&file);
        for (n, line) in code.lines().enumerate() {
            if line.trim_start().starts_with("//") {
                continue;
            }
            let compact: String = line.split_whitespace().collect();
            if compact.contains("Result<") && compact.contains(",String>") {
                found.push(format!("{}:{}: {}", file.display(), n + 1, line.trim()));
            }
        }
    }
    assert!(
        found.is_empty(),
        "Result<_, String> in library code:\n{}",
        found.join("\n")
    );
}

/// The lab's library modules: evaluations, benchmarks and fuzzing, behind the `lab`
/// feature.
const LAB_MODULES: [&str; 3] = ["eval", "bench", "fuzz"];

/// The command line's files that belong to the lab (its commands and their flags).
const LAB_COMMANDS: [&str; 5] = [
    "bench_cmd",
    "eval_cmd",
    "eval_setup",
    "fuzz_cmd",
    "lab_flags",
];

/// Whether `file` is the lab's: under one of its modules, or one of its commands.
fn is_lab(src: &Path, file: &Path) -> bool {
    let top = top_module(src, file).unwrap_or_default();
    if LAB_MODULES.contains(&top.as_str()) {
        return true;
    }
    let stem = file
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or_default();
    top == "cli" && LAB_COMMANDS.contains(&stem)
}

#[test]
fn no_product_module_imports_the_lab() {
    let src = src();
    let mut found = Vec::new();
    let mut lab_files = 0;
    for file in rust_files(&src) {
        if is_lab(&src, &file) {
            lab_files += 1;
            continue;
        }
        let code = product_code(&file);
        let in_cli = top_module(&src, &file).as_deref() == Some("cli");
        // `cli/mod.rs` declares the lab's commands, each behind the feature (checked by
        // building without it); its other lines are held to the rule like any file's.
        let declares_commands = in_cli && file.ends_with("cli/mod.rs");
        for (n, line) in code.lines().enumerate() {
            if line.trim_start().starts_with("//") {
                continue;
            }
            let mut named: Vec<String> = Vec::new();
            for prefix in ["crate::", "betr::"] {
                for m in LAB_MODULES {
                    if line.contains(&format!("{prefix}{m}::"))
                        || line.contains(&format!("{prefix}{m};"))
                    {
                        named.push(format!("{prefix}{m}"));
                    }
                }
            }
            if in_cli && !declares_commands {
                for c in LAB_COMMANDS {
                    if line.contains(&format!("super::{c}"))
                        || line.contains(&format!("crate::cli::{c}"))
                    {
                        named.push(c.to_string());
                    }
                }
            }
            if !named.is_empty() {
                found.push(format!("{}:{}: {}", file.display(), n + 1, line.trim()));
            }
        }
    }
    assert!(
        lab_files > 10,
        "the lab's files were not found under {}",
        src.display()
    );
    assert!(
        found.is_empty(),
        "product code imports the lab:\n{}",
        found.join("\n")
    );
}

#[test]
fn the_lab_modules_are_declared_behind_the_lab_feature() {
    let lib = std::fs::read_to_string(src().join("lib.rs")).expect("src/lib.rs");
    let lines: Vec<&str> = lib.lines().map(str::trim).collect();
    for m in LAB_MODULES {
        let at = lines
            .iter()
            .position(|l| *l == format!("pub mod {m};"))
            .unwrap_or_else(|| panic!("src/lib.rs does not declare {m}"));
        assert!(
            at > 0 && lines[at - 1] == "#[cfg(feature = \"lab\")]",
            "src/lib.rs declares {m} without #[cfg(feature = \"lab\")]"
        );
    }
}

/// Which of the session's own modules (its rooms and files: `engine`, `interpret`,
/// `repair`, `types`, …) each one's product code names, by `crate::session::X` or by as
/// many `super::` as lead back to the session. `session/mod.rs`, which declares them all,
/// is left out.
fn session_dependencies(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let session = src.join("session");
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for file in rust_files(&session) {
        let Ok(rel) = file.strip_prefix(&session) else {
            continue;
        };
        let mut path: Vec<String> = rel
            .iter()
            .map(|c| c.to_string_lossy().trim_end_matches(".rs").to_string())
            .collect();
        if path.last().is_some_and(|l| l == "mod") {
            path.pop();
        }
        let Some(from) = path.first().cloned() else {
            continue;
        };
        let code = product_code(&file);
        let entry = graph.entry(from.clone()).or_default();
        for line in code_lines(&code) {
            for name in session_names(line, path.len()) {
                if name != from {
                    entry.insert(name);
                }
            }
        }
    }
    let modules: BTreeSet<String> = graph.keys().cloned().collect();
    for deps in graph.values_mut() {
        deps.retain(|d| modules.contains(d));
    }
    graph
}

/// The session modules `line` names from a file `depth` modules below the session.
fn session_names(line: &str, depth: usize) -> Vec<String> {
    let ident = |s: &str| -> String {
        s.chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .collect()
    };
    let mut names = Vec::new();
    for (at, _) in line.match_indices("crate::session::") {
        names.push(ident(&line[at + "crate::session::".len()..]));
    }
    let ups = "super::".repeat(depth);
    for (at, _) in line.match_indices(&ups) {
        let before = &line[..at];
        let rest = &line[at + ups.len()..];
        // `super::super::x` seen from one level deeper is not this many `super::`.
        if before.ends_with("super::") || before.ends_with(|c: char| c.is_alphanumeric()) {
            continue;
        }
        if rest.starts_with("super::") {
            continue;
        }
        if let Some(group) = rest.strip_prefix('{') {
            let group = group.split('}').next().unwrap_or_default();
            names.extend(group.split(',').map(|p| ident(p.trim())));
        } else {
            names.push(ident(rest));
        }
    }
    names
}

#[test]
fn the_session_rooms_depend_one_way() {
    let graph = session_dependencies(&src());
    for room in ["engine", "interpret", "repair", "types"] {
        assert!(
            graph.contains_key(room),
            "no session module {room}: {graph:?}"
        );
    }
    assert!(
        graph["engine"].contains("repair") && graph["engine"].contains("interpret"),
        "the reader misses the engine's imports: {graph:?}"
    );
    let cycles: Vec<String> = graph
        .keys()
        .filter_map(|m| cycle_from(&graph, m))
        .map(|c| c.join(" → "))
        .collect();
    assert!(
        cycles.is_empty(),
        "import cycles inside the session: {cycles:#?}"
    );
    // The vocabulary is plain data: it names no room of the session.
    let types = &graph["types"];
    for room in [
        "engine",
        "interpret",
        "repair",
        "policy",
        "knowledge",
        "resolve",
    ] {
        assert!(
            !types.contains(room),
            "session/types.rs imports {room}: {types:?}"
        );
    }
    // Reading an instruction and repairing a failure are separate jobs.
    assert!(
        !graph["interpret"].contains("repair") && !graph["repair"].contains("interpret"),
        "interpret and repair import each other: {graph:?}"
    );
}

/// The test command builds no unit-test harness of the binary (a second compile of the
/// whole command line at the test profile's optimisation): what the binary does is tested
/// by running it, and what can be tested alone lives in the library.
#[test]
fn the_binary_has_no_unit_tests() {
    let main = src().join("main.rs");
    let mut files = rust_files(&src().join("cli"));
    files.push(main);
    let with_tests: Vec<String> = files
        .iter()
        .filter(|f| {
            let text = std::fs::read_to_string(f).unwrap();
            text.contains("#[test]") || text.contains("#[cfg(test)]")
        })
        .map(|f| f.display().to_string())
        .collect();
    assert!(with_tests.is_empty(), "{with_tests:?}");
}
