//! `betr bench PARTS --quick` run from the repository, its JSON report read back: shared by
//! the fast tier's bench tests and the slow tier's (those whose parts need the model or
//! the Python anchors).

use std::path::Path;
use std::process::{Command, Output};

pub fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// `betr bench PARTS --quick` in the repository (it reads scenarios/ and ../shared), the
/// JSON written to a scratch file.
pub fn bench(parts: &[&str], extra: &[&str]) -> (Output, serde_json::Value) {
    let scratch = super::cli::tmp(&format!("bench-{}", parts.join("-")));
    let json = scratch.join("bench.json");
    let out = Command::new(env!("CARGO_BIN_EXE_betr"))
        .arg("bench")
        .args(parts)
        .arg("--quick")
        .arg("--json")
        .arg(&json)
        .args(extra)
        .current_dir(repo())
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", super::cli::text(&out));
    let report: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    (out, report)
}

pub fn rows_of<'a>(report: &'a serde_json::Value, part: &str) -> Vec<&'a serde_json::Value> {
    report["rows"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|r| r["part"] == part)
        .collect()
}
