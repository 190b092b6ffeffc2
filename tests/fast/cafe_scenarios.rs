//! Scenarios 8, 9 and 10 of BETR-XP-LLM through the real `betr` binary: `run` fails with
//! the paper's error text at the right action (exit 1); `repair` with the fixing condition
//! succeeds (exit 0) and saves the tree; the saved tree, run in a fresh world in the same
//! failing state, succeeds with no further repair.

#![allow(clippy::unwrap_used)] // tests may panic on what they check

use crate::support;
use std::path::{Path, PathBuf};
use std::process::Output;

use support::repo::betr;

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("betr-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

struct Case {
    file: &'static str,
    failing_action: &'static str,
    error: &'static str,
    fix: &'static str,
}

const CASES: [Case; 3] = [
    Case {
        file: "scenarios/cafe/no_coffee.toml",
        failing_action: "MoveTo \"Coffee\"!",
        error: "Coffee not found",
        fix: "Exists_Coffee",
    },
    Case {
        file: "scenarios/cafe/find_fries.toml",
        failing_action: "PickUp \"Chips\"!",
        error: "Position out of reach",
        fix: "RobotNear_Bar",
    },
    Case {
        file: "scenarios/cafe/sweep.toml",
        failing_action: "Sweep \"Floor\"!",
        error: "Postcondition IsClean_Floor not met after Sweep action completion",
        fix: "Holding_Mop",
    },
];

#[test]
fn run_fails_with_the_papers_error_at_the_right_action() {
    for case in &CASES {
        let out = betr(&["run", case.file]);
        let text = stdout(&out);
        assert_eq!(out.status.code(), Some(1), "{}: {text}", case.file);
        let verdict = text.lines().last().unwrap_or_default();
        assert!(verdict.starts_with("FAILED"), "{verdict}");
        assert!(
            verdict.contains(case.failing_action),
            "{}: {verdict}",
            case.file
        );
        assert!(verdict.ends_with(case.error), "{}: {verdict}", case.file);
    }
}

#[test]
fn repair_succeeds_and_the_saved_tree_needs_no_further_repair() {
    let dir = temp_dir("cafe-repair");
    for case in &CASES {
        let name = Path::new(case.file)
            .file_stem()
            .unwrap()
            .to_string_lossy()
            .into_owned();
        let saved = dir.join(format!("{name}.bt"));
        let out = betr(&[
            "repair",
            case.file,
            "--add",
            case.fix,
            "--save",
            saved.to_str().unwrap(),
        ]);
        let text = stdout(&out);
        assert_eq!(out.status.code(), Some(0), "{}: {text}", case.file);
        assert!(
            text.contains(&format!(
                "{} failed in simulation: {}",
                case.failing_action, case.error
            )),
            "{text}"
        );

        // The fix is the failing action's first precondition in the saved tree.
        let tree_text = std::fs::read_to_string(&saved).unwrap();
        let tree = betr::bt::parse(&tree_text).unwrap();
        let action = case.failing_action.trim_end_matches('!');
        let (node, _) = tree
            .actions()
            .into_iter()
            .find(|(_, a)| a.to_string() == action)
            .expect("the failing action is still in the tree");
        let seq = tree.parent(node).unwrap().unwrap();
        let first = tree.children(seq).unwrap()[0];
        let first_condition = match tree.kind(first).unwrap() {
            betr::bt::NodeKind::Condition(c) => c.to_string(),
            betr::bt::NodeKind::Fallback => {
                match tree.kind(tree.children(first).unwrap()[0]).unwrap() {
                    betr::bt::NodeKind::Condition(c) => c.to_string(),
                    other => panic!("unexpected {other:?}"),
                }
            }
            other => panic!("unexpected {other:?}"),
        };
        assert_eq!(first_condition, case.fix, "{tree_text}");

        // A fresh world in the same failing state: the saved tree succeeds as it is.
        let out = betr(&["run", case.file, "--tree", saved.to_str().unwrap()]);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{}: {}",
            case.file,
            stdout(&out)
        );
        assert!(
            stdout(&out)
                .lines()
                .last()
                .unwrap_or_default()
                .starts_with("SUCCESS")
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_input_exits_2_with_the_reason() {
    let out = betr(&["plan", "scenarios/cafe/nowhere.toml"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("not found"));

    let out = betr(&[
        "plan",
        "scenarios/cafe/cafe.toml",
        "--goal",
        "On_Coffee_Table1 &",
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--goal") && err.contains("column"), "{err}");

    let out = betr(&[
        "plan",
        "scenarios/cafe/cafe.toml",
        "--goal",
        "On_Fries_Table1",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("unknown object \"Fries\""));

    // A goal nested too deep is refused, and the message quotes only the stretch around
    // the column it is about.
    let deep = format!("{}Holding_Nothing{}", "(".repeat(5000), ")".repeat(5000));
    let out = betr(&["plan", "scenarios/cafe/cafe.toml", "--goal", &deep]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("column 257") && err.contains("nested"),
        "{err}"
    );
    assert!(err.contains("(10015 characters)"), "{err}");
    assert!(err.len() < 300, "{} bytes: {err}", err.len());

    let dir = temp_dir("bad-tree");
    let tree = dir.join("bad.bt");
    std::fs::write(
        &tree,
        "sequence\n  On_Coffee_Table1?\n   Holding_Nothing?\n",
    )
    .unwrap();
    let out = betr(&[
        "run",
        "scenarios/cafe/cafe.toml",
        "--tree",
        tree.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("line 3"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );

    std::fs::write(&tree, "sequence\n  On_Coffee_Table1?\n  Fly \"Coffee\"!\n").unwrap();
    let out = betr(&[
        "run",
        "scenarios/cafe/cafe.toml",
        "--tree",
        tree.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("Fly \"Coffee\"!"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn plan_exit_status_follows_the_outcome() {
    assert_eq!(
        betr(&["plan", "scenarios/cafe/cafe.toml"]).status.code(),
        Some(0)
    );
    assert_eq!(
        betr(&["plan", "scenarios/cafe/no_coffee.toml"])
            .status
            .code(),
        Some(1)
    );
}
