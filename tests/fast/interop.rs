//! Trees in BehaviorTree.CPP v4 XML and Graphviz DOT: betr text → XML → betr text is
//! exact for the trees of every scenario (planned, repaired with the expected fix, with
//! values set) and of the 100 cafe gold goals; a BT.CPP file written by hand imports; one
//! file per refusal reason is refused through the real binary with exit 2, the file, the
//! line and the element; and a DOT export is rendered to PNG by Graphviz.

#![allow(clippy::unwrap_used)] // tests may panic on what they check
use crate::support;

use std::path::Path;
use std::process::Command;

use betr::bt::{self, NodeKind, Tree};
use betr::dataset;
use betr::domain::Value;
use betr::goal::Formula;
use betr::interop::{self, TreeFormat};
use betr::planner::Planner;
use betr::scenario::Scenario;
use betr::world;
use support::cli::{betr, text, tmp};
use support::spread;
use support::verify::{planned, repaired, root, scenario_files};

/// The tree survives BT.CPP XML and back, node for node.
fn assert_round_trip(tree: &Tree, scenario: &Scenario, what: &str) {
    let xml = interop::to_btcpp(tree, &scenario.domain, "Main")
        .unwrap_or_else(|e| panic!("{what}: export: {e}"));
    let back = interop::read_tree(&xml, TreeFormat::BtCpp, &scenario.domain, what)
        .unwrap_or_else(|e| panic!("{what}: import: {e}\n{xml}"));
    assert_eq!(bt::to_text(&back.tree), bt::to_text(tree), "{what}:\n{xml}");
    assert!(back.notes.is_empty(), "{what}: {:?}", back.notes);
}

/// Every action with value parameters gets a value of the right kind (a number in its
/// unit, or its first category), so value ports are exercised.
fn with_values(mut tree: Tree, scenario: &Scenario) -> Tree {
    for id in tree.preorder() {
        let Ok(NodeKind::Action(call)) = tree.kind(id) else {
            continue;
        };
        let Some(skill) = scenario.domain.skill_for(call) else {
            continue;
        };
        let values: Vec<(String, Value)> = skill
            .values
            .iter()
            .map(|v| {
                let value = match &v.unit {
                    Some(unit) => Value::Number {
                        value: 2.5,
                        unit: unit.clone(),
                    },
                    None => Value::Category(v.categories.first().cloned().unwrap()),
                };
                (v.name.clone(), value)
            })
            .collect();
        if let Ok(NodeKind::Action(call)) = tree.kind_mut(id) {
            for (name, value) in values {
                call.set_value(&name, value);
            }
        }
    }
    tree
}

#[test]
fn the_trees_of_every_scenario_round_trip_through_btcpp_xml() {
    let files = scenario_files(&root().join("scenarios"));
    // Each scenario's trees round-trip on their own, so the scenarios run on every core;
    // per scenario: whether it has a goal, and whether its trees carry values.
    let trips = spread::each(
        &files,
        |f| f.display().to_string(),
        |file| {
            let s = Scenario::load(file).unwrap();
            let Some(planned) = planned(&s) else {
                return (false, false);
            };
            let name = file.display().to_string();
            assert_round_trip(&planned, &s, &name);
            if !s.expected_fix.is_empty() {
                assert_round_trip(&repaired(&s), &s, &format!("{name}, repaired"));
            }
            let valued = s.domain.skills.iter().any(|k| !k.values.is_empty());
            if valued {
                let with = with_values(planned, &s);
                assert!(bt::to_text(&with).contains(" {"), "{name}: no value set");
                assert_round_trip(&with, &s, &format!("{name}, with values"));
            }
            (true, valued)
        },
    );
    let checked = trips.iter().filter(|(goal, _)| *goal).count();
    let with_value_ports = trips.iter().filter(|(_, valued)| *valued).count();
    // 10 failure scenarios, 7 parameter scenarios, the cafe of the dataset, the 7 new
    // tasks of cell/tasks, the greenhouse, the lab, the warehouse, the hospital, and the 2
    // scenarios only real arms fail.
    assert_eq!(checked, 31, "{files:?}");
    assert_eq!(with_value_ports, 7);
}

#[test]
fn the_trees_of_the_hundred_cafe_gold_goals_round_trip() {
    let s = Scenario::load(&root().join("scenarios/cafe/cafe.toml")).unwrap();
    let world = world::load(&s).unwrap();
    let planner = Planner::new(&s.domain);
    let cases = dataset::load(&root().join("../shared/datasets/llm-obtea")).unwrap();
    assert_eq!(cases.len(), 100);
    for case in cases {
        let goal = Formula::parse(&case.gold).unwrap();
        let tree = planner.plan(&goal.to_dnf(), world.as_ref()).unwrap().tree;
        assert_round_trip(&tree, &s, &case.gold);
    }
}

#[test]
fn a_btcpp_file_written_by_hand_imports_as_scenario_ones_repaired_tree() {
    let s = Scenario::load(&root().join("scenarios/cell/red_on_blue.toml")).unwrap();
    let loaded = interop::load_tree_file(
        &root().join("tests/fixtures/btcpp/handwritten.xml"),
        &s.domain,
    )
    .unwrap();
    assert_eq!(loaded.format, TreeFormat::BtCpp);
    assert_eq!(bt::to_text(&loaded.tree), bt::to_text(&repaired(&s)));

    // A memory Sequence whose later children cannot be running reads as reactive, said.
    let memory = interop::load_tree_file(
        &root().join("tests/fixtures/btcpp/memory_first_only.xml"),
        &s.domain,
    )
    .unwrap();
    assert_eq!(
        bt::to_text(&memory.tree),
        "sequence\n  fallback\n    \"green cube\" grasped?\n    grasp \"green cube\"!\n  \"green cube\" grasped?\n"
    );
    assert_eq!(memory.notes.len(), 1);
    assert!(
        memory.notes[0].starts_with("line 4: <Sequence> read as <ReactiveSequence>"),
        "{:?}",
        memory.notes
    );
}

/// Scenario 1 repaired on the command line, saved as the policy `repaired.bt` in `dir`,
/// and exported in `format` (`btcpp`, `dot`) to `repaired.EXTENSION`; the exported text.
fn repair_and_export(dir: &Path, format: &str, extension: &str) -> String {
    let scenario = root().join("scenarios/cell/red_on_blue.toml");
    let add = betr(
        dir,
        &[
            "repair",
            scenario.to_str().unwrap(),
            "--add",
            "~\"any object\" on \"blue cube\"",
            "--save",
            "repaired.bt",
        ],
    );
    assert!(add.status.success(), "{}", text(&add));
    let out = format!("repaired.{extension}");
    let export = betr(
        dir,
        &["export", "repaired.bt", "--format", format, "--out", &out],
    );
    assert!(export.status.success(), "{}", text(&export));
    std::fs::read_to_string(dir.join(out)).unwrap()
}

#[test]
fn the_binary_runs_verifies_and_exports_a_btcpp_tree() {
    let dir = tmp("btcpp-run");
    let scenario = root().join("scenarios/cell/red_on_blue.toml");
    let scenario = scenario.to_str().unwrap();
    let xml = root().join("tests/fixtures/btcpp/handwritten.xml");
    let xml = xml.to_str().unwrap();

    let run = betr(&dir, &["run", scenario, "--tree", xml]);
    assert!(run.status.success(), "{}", text(&run));
    assert!(
        text(&run).contains("SUCCESS after 10 tick(s)"),
        "{}",
        text(&run)
    );

    let verify = betr(&dir, &["verify", scenario, "--tree", xml]);
    assert!(verify.status.success(), "{}", text(&verify));
    assert!(
        text(&verify).contains("loaded from") && text(&verify).contains("(BT.CPP XML)"),
        "{}",
        text(&verify)
    );

    // The memory note reaches stderr.
    let memory = root().join("tests/fixtures/btcpp/memory_first_only.xml");
    let noted = betr(&dir, &["run", scenario, "--tree", memory.to_str().unwrap()]);
    assert!(noted.status.success(), "{}", text(&noted));
    assert!(
        String::from_utf8_lossy(&noted.stderr).contains("note: ")
            && String::from_utf8_lossy(&noted.stderr).contains("memory changes nothing"),
        "{}",
        text(&noted)
    );

    // Repaired on the command line, saved as a policy, exported as XML, read back.
    let written = repair_and_export(&dir, "btcpp", "xml");
    assert!(written.contains("<root BTCPP_format=\"4\" main_tree_to_execute=\"red_on_blue\">"));
    assert!(written.contains("<TreeNodesModel>") && written.contains("<Action ID=\"grasp\">"));
    let back = betr(&dir, &["run", scenario, "--tree", "repaired.xml"]);
    assert!(
        text(&back).contains("SUCCESS after 10 tick(s)"),
        "{}",
        text(&back)
    );
}

#[test]
fn each_refusal_names_the_file_the_line_and_the_element_with_exit_2() {
    let dir = tmp("btcpp-refused");
    let scenario = root().join("scenarios/cell/red_on_blue.toml");
    let cases = [
        (
            "unknown_id.xml",
            5,
            "<Action ID=\"Fly\" to=\"green cube\"/>",
            "unknown action ID \"Fly\"",
        ),
        (
            "subtree.xml",
            4,
            "<SubTree ID=\"Stack\"/>",
            "<SubTree> is not read",
        ),
        (
            "unmapped_port.xml",
            4,
            "<Action ID=\"grasp\" x=\"blue cube\" speed_factor=\"2\"/>",
            "port speed_factor=\"2\" has no mapping: grasp takes x",
        ),
        (
            "blackboard.xml",
            4,
            "<Condition ID=\"grasped\" arg1=\"{target}\"/>",
            "is a blackboard reference",
        ),
        ("malformed.xml", 5, "", "malformed XML"),
        (
            "memory_sequence.xml",
            3,
            "<Sequence>",
            "<Sequence> has memory",
        ),
        (
            "every_kind.xml",
            8,
            "<Script code=\"attempts := 0\"/>",
            "Script is a BehaviorTree.CPP action that betr's engine does not run",
        ),
    ];
    for (file, line, element, reason) in cases {
        let path = root().join("tests/fixtures/btcpp").join(file);
        // The workbench refuses the file before its screen opens.
        for command in ["run", "verify", "repair", "tui"] {
            let mut args = vec![
                command,
                scenario.to_str().unwrap(),
                "--tree",
                path.to_str().unwrap(),
            ];
            if command == "repair" {
                args.extend(["--add", "~\"any object\" on \"blue cube\""]);
            }
            let out = betr(&dir, &args);
            let err = String::from_utf8_lossy(&out.stderr);
            assert_eq!(
                out.status.code(),
                Some(2),
                "{command} {file}: {}",
                text(&out)
            );
            let located = format!("{}: line {line}, column ", path.display());
            assert!(err.contains(&located), "{command} {file}: {err}");
            assert!(err.contains(element), "{command} {file}: {err}");
            assert!(err.contains(reason), "{command} {file}: {err}");
        }
    }
}

/// A file of every node kind BT.CPP 4 ships, which betr refuses to run, is shown whole:
/// one line per node, each with its kind and ports, the SubTree's tree under it.
#[test]
fn a_tree_file_of_every_kind_is_shown_whole() {
    let dir = tmp("btcpp-shown");
    let path = root().join("tests/fixtures/btcpp/every_kind.xml");
    let out = betr(
        &dir,
        &["monitor", "--file", path.to_str().unwrap(), "--print"],
    );
    assert!(out.status.success(), "{}", text(&out));
    let printed = String::from_utf8_lossy(&out.stdout);
    let lines: Vec<&str> = printed.lines().collect();
    assert!(lines[0].ends_with("tree Main, 55 nodes"), "{printed}");
    let elements = std::fs::read_to_string(&path)
        .unwrap()
        .matches("<AlwaysSuccess/>")
        .count();
    assert_eq!(
        lines
            .iter()
            .filter(|l| l.trim_end().ends_with("AlwaysSuccess (Action)"))
            .count(),
        elements,
        "{printed}"
    );
    for shown in [
        "2.0.1            SubTree \"PickPlace\" object=\"{target}\" _autoremap=\"false\"",
        "2.0.1.0            RetryUntilSuccessful (Decorator) num_attempts=\"3\"",
        "Parallel (Control) success_count=\"1\" failure_count=\"1\"",
        "Switch2 (Control) variable=\"{target}\" case_1=\"red cube\" case_2=\"blue cube\"",
        "Precondition (Decorator) if=\"attempts < 3\" else=\"FAILURE\"",
        "ScriptCondition (Condition) code=\"attempts < 3\"",
        "Grasp (Action) object=\"{object}\"",
    ] {
        assert!(printed.contains(shown), "{shown:?} in:\n{printed}");
    }
    // Drawn as written for Graphviz, with no scenario.
    let out = betr(
        &dir,
        &[
            "export",
            path.to_str().unwrap(),
            "--format",
            "dot",
            "--out",
            "every.dot",
        ],
    );
    assert!(out.status.success(), "{}", text(&out));
    let dot = std::fs::read_to_string(dir.join("every.dot")).unwrap();
    assert_eq!(dot.matches(" [label=").count(), 55, "{dot}");
    let out = betr(&dir, &["monitor", "--file", "missing.xml", "--print"]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    assert!(String::from_utf8_lossy(&out.stderr).contains("missing.xml"));
}

/// Graphviz's `dot`, or `None` (a loud skip) when it is missing outside CI.
fn graphviz() -> Option<&'static str> {
    let found = Command::new("dot").arg("-V").output().is_ok();
    if !found {
        support::check::cannot_check(
            "the DOT export rendered by Graphviz",
            "graphviz's dot is not installed (scripts/setup.sh --test installs it, or apt-get install graphviz)",
        );
        return None;
    }
    Some("dot")
}

#[test]
fn a_dot_export_renders_to_png_with_graphviz() {
    let dir = tmp("dot-png");
    let dot = repair_and_export(&dir, "dot", "dot");
    // The fix's nodes are marked; the last tick of the run succeeded at the root.
    assert!(
        dot.contains("+ ~\\\"any object\\\" on \\\"blue cube\\\""),
        "{dot}"
    );
    assert!(dot.contains("tick 10: Success"), "{dot}");
    let Some(dot_bin) = graphviz() else { return };
    let png = dir.join("repaired.png");
    let rendered = Command::new(dot_bin)
        .args(["-Tpng", "-o"])
        .arg(&png)
        .arg(dir.join("repaired.dot"))
        .output()
        .unwrap();
    assert!(
        rendered.status.success(),
        "{}",
        String::from_utf8_lossy(&rendered.stderr)
    );
    let bytes = std::fs::read(&png).unwrap();
    assert!(bytes.starts_with(b"\x89PNG\r\n\x1a\n"), "not a PNG");
    assert!(
        bytes.len() > 10_000,
        "a tree of 18 nodes draws more than {} bytes",
        bytes.len()
    );
}

#[test]
fn the_tree_files_guide_shows_the_xml_betr_writes_for_scenario_ones_repaired_tree() {
    let s = Scenario::load(&root().join("scenarios/cell/red_on_blue.toml")).unwrap();
    let xml = interop::to_btcpp(&repaired(&s), &s.domain, "red_on_blue").unwrap();
    let readme = std::fs::read_to_string(root().join("docs/TREE-FILES.md")).unwrap();
    let start = readme
        .find("```xml\n")
        .expect("an xml block in docs/TREE-FILES.md")
        + "```xml\n".len();
    let end = start + readme[start..].find("```").unwrap();
    assert_eq!(
        &readme[start..end],
        xml,
        "regenerate the XML of docs/TREE-FILES.md with betr export"
    );
    assert!(
        root()
            .join("docs/images/red_on_blue-repaired.png")
            .is_file()
    );
}
