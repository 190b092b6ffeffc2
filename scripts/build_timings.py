#!/usr/bin/env python3
"""Where a build's time goes, per crate, from `cargo build --timings`.

Usage: python3 scripts/build_timings.py TIMINGS.html [--top N] [--repo DIR]

Reads the unit list cargo writes into its timings page, adds up each crate's units
(compiling it, and running its build script: for the -sys crates that is where cmake
builds the C++ library), and names the direct dependency of betr that pulls each crate in
(from `cargo tree`, run in --repo). Prints a Markdown table, slowest first.
"""

import argparse
import json
import re
import subprocess
import sys
from collections import defaultdict

# What each of betr's direct dependencies is for (the comments in Cargo.toml, short).
PURPOSE = {
    "anyhow": "errors at the binary's edge",
    "clap": "the command line",
    "crossterm": "the terminal",
    "cpal": "the microphone (dictation)",
    "ct2rs": "speech-to-text (Whisper through CTranslate2)",
    "futures-util": "streams of the model's replies",
    "hound": "WAV files (dictation)",
    "indexmap": "ordered maps in scenario files",
    "indicatif": "progress bars (fetches)",
    "plotters": "charts (eval, bench)",
    "ratatui": "the workbench's panes",
    "reqwest": "OpenAI-compatible servers, fetches",
    "rustfft": "speech features (dictation)",
    "rustls": "TLS for fetches and servers",
    "nalgebra": "kinematics and geometry",
    "nix": "signals, stderr redirection",
    "parry3d": "collision tests",
    "serde": "every file format",
    "serde_json": "journals, cassettes, recordings",
    "sha2": "checksums of fetched files",
    "strsim": "suggestions for mistyped names",
    "thiserror": "library errors",
    "tokio": "the async runtime",
    "toml": "scenario files",
    "tracing": "logging",
    "tracing-subscriber": "logging",
    "tui-tree-widget": "the tree pane",
    "zip": "archives",
    "llama-cpp-2": "the embedded LLM (llama.cpp)",
    "rerun": "the 3D view and recordings",
    "roxmltree": "reading BT.CPP XML",
    "quick-xml": "writing BT.CPP XML",
    "urdf-rs": "the robot description",
    "tar": "the robot description's archive",
    "flate2": "the robot description's archive",
    "stl_io": "the robot's meshes",
}

UNIT_DATA = re.compile(r"const UNIT_DATA = (\[.*?\]);", re.S)


def units(html: str) -> list[dict]:
    found = UNIT_DATA.search(html)
    if not found:
        sys.exit("error: no UNIT_DATA in the timings page (was it written by `cargo build --timings`?)")
    return json.loads(found.group(1))


def pulled_in_by(repo: str) -> dict[str, set[str]]:
    """For every crate in betr's dependency graph, the direct dependencies that reach it."""
    tree = subprocess.run(
        ["cargo", "tree", "--locked", "-e", "normal,build", "--prefix", "depth"],
        cwd=repo,
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    by: dict[str, set[str]] = defaultdict(set)
    direct = None
    for line in tree.splitlines():
        m = re.match(r"(\d+)(\S+) v", line)
        if not m:
            continue
        depth, name = int(m.group(1)), m.group(2)
        if depth == 1:
            direct = name
        if depth >= 1 and direct is not None:
            by[name].add(direct)
    return by


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("timings")
    parser.add_argument("--top", type=int, default=25)
    parser.add_argument("--repo", default=".")
    args = parser.parse_args()
    with open(args.timings, encoding="utf-8") as f:
        data = units(f.read())
    compile_s: dict[str, float] = defaultdict(float)
    script_s: dict[str, float] = defaultdict(float)
    for unit in data:
        name = unit["name"]
        if unit.get("mode") == "run-custom-build":
            script_s[name] += unit["duration"]
        else:
            compile_s[name] += unit["duration"]
    end = max(u["start"] + u["duration"] for u in data)
    total = sum(compile_s.values()) + sum(script_s.values())
    by = pulled_in_by(args.repo)
    crates = sorted(set(compile_s) | set(script_s), key=lambda n: -(compile_s[n] + script_s[n]))
    print(f"wall time {end:.0f} s; units added up {total:.0f} s over {len(data)} units, {len(crates)} crates")
    print()
    print("| crate | seconds | of which build script (C++) | pulled in by | for |")
    print("|---|---:|---:|---|---|")
    shown = 0.0
    for name in crates[: args.top]:
        seconds = compile_s[name] + script_s[name]
        shown += seconds
        if name == "betr":
            roots, purpose = "—", "betr itself (library, binary)"
        else:
            direct = sorted(by.get(name, set()))
            roots = ", ".join(direct[:4]) + (f" and {len(direct) - 4} more" if len(direct) > 4 else "")
            roots = roots or "(build tool)"
            purpose = "; ".join(sorted({PURPOSE[r] for r in direct if r in PURPOSE})) if len(direct) <= 4 else "shared"
        script = f"{script_s[name]:.0f}" if script_s[name] >= 1 else ""
        print(f"| {name} | {seconds:.0f} | {script} | {roots} | {purpose} |")
    rest = len(crates) - args.top
    if rest > 0:
        print(f"| {rest} more crates | {total - shown:.0f} | | | |")


if __name__ == "__main__":
    main()
