//! End to end, as a person would: the real `betr` binary in tmux, the model answered by
//! the fake OpenAI server from hand-written fixtures. Type the instruction of scenario 1,
//! step ticks until the grasp fails, see the proposal, approve it, run to success, save
//! the policy, quit; the screen is checked at each step (polling `capture-pane` with a
//! timeout), then the restored terminal, the exit status and the saved policy. A second
//! session rejects, edits, undoes, verifies and saves, and a fresh workbench reuses the
//! saved policy without asking the model. Two more use the debugger: a run stopped at a
//! breakpoint, and a condition forced to fail. One more replays a recorded session with
//! no server running, stepping back to the failure and on to the proposal.

#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use crate::support;

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use betr::scenario::Scenario;
use support::cli::{KEY, KEY_VAR, tmp};
use support::fake_openai::{Behavior, FakeServer};
use support::fixtures;
use support::tmux::{Tmux, quote};

/// The shell command that opens the workbench on scenario 1 in `dir`, with the model
/// answered by `server`, then says how it exited.
fn workbench_command(dir: &Path, server: &FakeServer, env: &str, extra: &str) -> String {
    support::tmux::workbench_command_on(
        "scenarios/cell/red_on_blue.toml",
        dir,
        server,
        (env, extra),
    )
}

#[test]
fn a_person_resolves_scenario_1_in_the_workbench() {
    let started = Instant::now();
    let server = FakeServer::start(vec![], Behavior::Fixtures(fixtures::every_reply()));
    let dir = tmp("tmux");
    let policies = dir.join("policies");
    let scenario = fixtures::root().join("scenarios/cell/red_on_blue.toml");
    let tmux = Tmux::start(&workbench_command(&dir, &server, "", ""));

    // The workbench opens on scenario 1 with the configured model.
    tmux.wait_for(
        &[
            "Behavior tree",
            "press i to type an instruction",
            "red_on_blue",
            "openai fake-model",
        ],
        20,
    );

    // Push-to-talk. Without a sound card (as here) the status bar says there is no
    // microphone and nothing a native library printed reaches the screen; with one, the
    // recording starts and Esc discards it. Either way the session goes on.
    tmux.keys(&["d"]);
    let screen = tmux.wait_for_any(&["dictation: no microphone", "● REC"], 10);
    if screen.contains("● REC") {
        tmux.keys(&["Escape"]);
        tmux.wait_for(&["recording discarded"], 10);
    }
    assert!(
        !screen.contains("ALSA"),
        "stderr reached the screen:\n{screen}"
    );

    // Type the instruction.
    tmux.keys(&["i"]);
    tmux.wait_for(&["Instruction or goal"], 10);
    tmux.text("Put the blue cube on the green cube");
    tmux.wait_for(&["> Put the blue cube on the green cube"], 10);
    tmux.keys(&["Enter"]);
    // The usage count reaches the status bar in its own event, possibly a frame after the
    // tree: wait for it too rather than racing it.
    let screen = tmux.wait_for(
        &[
            "Goal: \"blue cube\" on \"green cube\"",
            "grasp \"blue cube\"!",
            "[o] Fallback",
            "1 call(s)",
        ],
        20,
    );
    assert!(screen.contains("1 call(s)"), "{screen}");

    // Step until the grasp fails.
    let mut failed = false;
    for n in 1..=10 {
        tmux.keys(&["Space"]);
        let screen = tmux.wait_for(&[&format!("tick {n}")], 10);
        if screen.contains("◀ failed") {
            failed = true;
            break;
        }
    }
    assert!(failed, "the grasp never failed:\n{}", tmux.screen());
    let screen = tmux.wait_for(
        &[
            "grasp \"blue cube\"! ◀ failed",
            "No collision free path",
            "Proposal for grasp \"blue cube\"!",
            "~\"any object\" on \"blue cube\"",
            "a approve · x reject · e edit",
        ],
        20,
    );
    assert!(screen.contains("hand-written fixture"), "{screen}");

    // Approve: the tree grows, the new nodes marked; the fix is offered as a rule.
    tmux.keys(&["a"]);
    tmux.wait_for(
        &[
            "+[ ] ~\"any object\" on \"blue cube\"?",
            "place \"red cube\"",
            "Keep as a rule for later tasks: grasp {x} needs",
        ],
        20,
    );
    // Keep it: the condition is marked as learned.
    tmux.keys(&["m"]);
    tmux.wait_for(
        &[
            "kept as rule r1",
            "~\"any object\" on \"blue cube\"? ◆ learned r1",
        ],
        20,
    );

    // Run to success.
    tmux.keys(&["r"]);
    tmux.wait_for(&["SUCCESS", "\"blue cube\" on \"green cube\""], 30);

    // Save the policy, then quit.
    tmux.keys(&["s"]);
    tmux.wait_for(&["saved policy"], 10);
    tmux.keys(&["q"]);
    // Nothing is lost: it quits at once.
    let screen = tmux.wait_for(&["betr exited with status 0"], 10);
    assert!(
        !screen.contains("Behavior tree"),
        "the alternate screen was left:\n{screen}"
    );

    // The policy parses and says where its fix came from; the rule kept beside it too.
    let files: Vec<PathBuf> = std::fs::read_dir(&policies)
        .unwrap()
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "bt"))
        .collect();
    assert_eq!(files.len(), 1, "{files:?}");
    let knowledge = betr::session::Knowledge::open(&policies.join("knowledge.toml")).unwrap();
    assert_eq!(knowledge.rules.len(), 1);
    assert_eq!(knowledge.rules[0].kept_by, "a person (workbench)");
    let domain = Scenario::load(&scenario).unwrap().domain;
    let policy = betr::session::policy::load(&files[0], &domain).unwrap();
    assert_eq!(policy.fixes.len(), 1);
    assert!(
        policy.fixes[0]
            .change
            .contains("~\"any object\" on \"blue cube\"")
    );
    assert!(policy.fixes[0].model.contains("hand-written fixture"));
    assert_eq!(policy.goal, "\"blue cube\" on \"green cube\"");
    // The key never reaches a written file.
    for f in support::cli::files_under(&dir) {
        let bytes = std::fs::read(&f).unwrap_or_default();
        assert!(
            !String::from_utf8_lossy(&bytes).contains(KEY),
            "{}",
            f.display()
        );
    }
    assert!(
        started.elapsed() < Duration::from_secs(60),
        "{:?}",
        started.elapsed()
    );
    drop(tmux);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The rest of the loop: reject the proposal, type the condition instead (edit), undo
/// it, let the model propose again and approve, verify, run to success, save; then a
/// fresh workbench reads the same instruction from the saved policy with no model call.
#[test]
fn a_person_rejects_edits_undoes_verifies_and_reuses_the_saved_policy() {
    let server = FakeServer::start(vec![], Behavior::Fixtures(fixtures::every_reply()));
    let dir = tmp("tmux-loop");
    let tmux = Tmux::start(&workbench_command(&dir, &server, "", ""));
    tmux.wait_for(&["press i to type an instruction"], 20);
    let instruct = |tmux: &Tmux| {
        tmux.keys(&["i"]);
        tmux.wait_for(&["Instruction or goal"], 10);
        tmux.text("Put the blue cube on the green cube");
        tmux.keys(&["Enter"]);
        tmux.wait_for(
            &[
                "Goal: \"blue cube\" on \"green cube\"",
                "grasp \"blue cube\"!",
            ],
            20,
        );
    };
    let step_to_proposal = |tmux: &Tmux| {
        for _ in 0..10 {
            let before = tmux.screen();
            tmux.keys(&["Space"]);
            // The next key only once the screen shows this tick: on a loaded machine a
            // key sent before it caught up ticks past the failure.
            let deadline = Instant::now() + Duration::from_secs(5);
            while tmux.screen() == before && Instant::now() < deadline {
                std::thread::sleep(Duration::from_millis(50));
            }
            if tmux.screen().contains("◀ failed") {
                break;
            }
        }
        tmux.wait_for(
            &["Proposal for grasp \"blue cube\"!", "awaiting approval"],
            20,
        )
    };
    instruct(&tmux);
    step_to_proposal(&tmux);

    // Reject: the tree stays as planned.
    tmux.keys(&["x"]);
    let screen = tmux.wait_for(&["rejected: the tree is unchanged"], 10);
    assert!(!screen.contains("+["), "{screen}");

    // Edit: the person types the condition; it is applied like an approved proposal.
    tmux.keys(&["e"]);
    tmux.wait_for(&[strings_edit_title()], 10);
    // The line opens with betr's first shortlisted fix; Ctrl-U clears it.
    tmux.keys(&["C-u"]);
    tmux.text("~\"any object\" on \"blue cube\"");
    tmux.keys(&["Enter"]);
    tmux.wait_for(&["+[ ] ~\"any object\" on \"blue cube\"?"], 20);

    // Undo: the planned tree is back.
    tmux.keys(&["u"]);
    let screen = tmux.wait_for(&["undid the last change (1 fix(es) removed)"], 10);
    assert!(!screen.contains("+["), "{screen}");

    // The failure again: the model proposes, the person approves.
    step_to_proposal(&tmux);
    tmux.keys(&["a"]);
    tmux.wait_for(
        &[
            "+[ ] ~\"any object\" on \"blue cube\"?",
            "Keep as a rule for later tasks",
        ],
        20,
    );
    // Not kept as a rule: the offer goes, the repair's steps are in the log.
    tmux.keys(&["n"]);
    tmux.wait_for(&["not kept as a rule", "repaired:"], 10);

    // Verify: the report opens over the screen; any key closes it.
    tmux.keys(&["v"]);
    tmux.wait_for(&["Verification (any key closes)"], 30);
    tmux.keys(&["Escape"]);
    tmux.wait_for(&["verified"], 10);

    tmux.keys(&["r"]);
    tmux.wait_for(&["SUCCESS"], 30);
    tmux.keys(&["s"]);
    tmux.wait_for(&["saved policy"], 10);
    tmux.keys(&["q"]);
    tmux.wait_for(&["betr exited with status 0"], 10);
    drop(tmux);
    let calls = server.received().len();

    // A fresh workbench: the same instruction is known from the saved policy.
    let tmux = Tmux::start(&workbench_command(&dir, &server, "", ""));
    tmux.wait_for(&["press i to type an instruction"], 20);
    instruct(&tmux);
    tmux.wait_for(
        &[
            "no LLM call needed",
            "[ ] ~\"any object\" on \"blue cube\"?",
        ],
        20,
    );
    tmux.keys(&["r"]);
    let screen = tmux.wait_for(&["SUCCESS"], 30);
    assert!(screen.contains("0 call(s)"), "{screen}");
    assert!(!screen.contains("◀ failed"), "{screen}");
    tmux.keys(&["q"]);
    tmux.wait_for(&["betr exited with status 0"], 10);
    assert_eq!(server.received().len(), calls, "the model was asked again");
    drop(tmux);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The title of the input line while a proposal is edited.
fn strings_edit_title() -> &'static str {
    betr::tui::strings::INPUT_TITLE_EDIT.trim()
}

/// Push-to-talk with real speech through the real binary: `BETR_PUSH_TO_TALK_WAV` plays an espeak-ng
/// recording of scenario 1's instruction as the microphone, the embedded Whisper model
/// (fetched into the cache first when missing) transcribes it, the transcript waits in the
/// input line, and Enter sends it to the model like typed words.
#[test]
fn a_person_dictates_the_instruction_in_the_workbench() {
    let server = FakeServer::start(vec![], Behavior::Fixtures(fixtures::every_reply()));
    let dir = tmp("tmux-dictation");
    let wav = dir.join("instruction.wav");
    let out = Command::new("espeak-ng")
        .args(["-s", "140", "-g", "3", "-w"])
        .arg(&wav)
        .arg("Put the blue cube on the green cube")
        .output()
        .expect("espeak-ng is required for this test (scripts/test.sh installs it)");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let models = support::embedded::whisper_dir().parent().unwrap();
    let tmux = Tmux::start(&workbench_command(
        &dir,
        &server,
        &format!(
            "BETR_MODEL_DIR={} BETR_PUSH_TO_TALK_WAV={}",
            quote(models),
            quote(&wav)
        ),
        "",
    ));
    tmux.wait_for(&["press i to type an instruction, d to dictate one"], 20);

    // Press to record: the meter, the clock and the "device" show.
    tmux.keys(&["d"]);
    tmux.wait_for(
        &[
            "● REC 0:0",
            "instruction.wav (file)",
            "d stops and transcribes",
        ],
        10,
    );
    // Press again: the transcript waits in the input line, not submitted.
    tmux.keys(&["d"]);
    let screen = tmux.wait_for(&["> Put the blue cube on the green cube", "dictated "], 60);
    assert!(
        screen.contains("No tree yet"),
        "submitted unseen:\n{screen}"
    );

    // Enter submits it, as if typed.
    tmux.keys(&["Enter"]);
    tmux.wait_for(
        &[
            "Goal: \"blue cube\" on \"green cube\"",
            "grasp \"blue cube\"!",
            "1 call(s)",
        ],
        20,
    );
    tmux.keys(&["q"]);
    tmux.wait_for(&["betr exited with status 0"], 10);
    drop(tmux);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The debugger as a person uses it: plan scenario 1, select the grasp in the tree, put a
/// breakpoint on it, run: the run stops before the first tick, which would enter the
/// grasp, and the screen says so; a step goes past it (the grasp is ticked and fails).
#[test]
fn a_person_stops_a_run_at_a_breakpoint() {
    let server = FakeServer::start(vec![], Behavior::Fixtures(fixtures::every_reply()));
    let dir = tmp("tmux-breakpoint");
    let tmux = Tmux::start(&workbench_command(&dir, &server, "", ""));
    tmux.wait_for(&["press i to type an instruction"], 20);
    tmux.keys(&["p"]);
    tmux.wait_for(&["grasp \"blue cube\"!", "[o] Fallback"], 20);
    // The grasp is the eighth row: root, goal, sequence, fallback, grasped?, sequence,
    // hand empty?, grasp.
    for _ in 0..8 {
        tmux.keys(&["Down"]);
    }
    tmux.keys(&["b"]);
    tmux.wait_for(
        &[
            "grasp \"blue cube\"! ● break",
            "breakpoints: grasp \"blue cube\"!",
        ],
        10,
    );

    tmux.keys(&["r"]);
    let screen = tmux.wait_for(
        &[
            "stopped at a breakpoint: grasp \"blue cube\"! (node 1.0.1.1) before tick 1",
            // Not ticked yet.
            "[ ] grasp \"blue cube\"! ● break ◀ stopped here",
        ],
        20,
    );
    assert!(!screen.contains("◀ failed"), "{screen}");

    // A step performs the tick the run stopped before.
    tmux.keys(&["Space"]);
    tmux.wait_for(&["tick 1", "grasp \"blue cube\"! ◀ failed ● break"], 20);
    tmux.keys(&["q"]);
    tmux.wait_for(&["betr exited with status 0"], 10);
    drop(tmux);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Forcing a status as a person does: scenario 1 without the red cube on the blue one
/// runs to success; the goal condition, forced to fail, sends the fallback to its other
/// branch (the grasp runs again); cleared, the goal holds again and the grasp is halted.
#[test]
fn a_person_forces_the_goal_condition_to_fail() {
    let server = FakeServer::start(vec![], Behavior::Fixtures(fixtures::every_reply()));
    let dir = tmp("tmux-force");
    let tmux = Tmux::start(&workbench_command(&dir, &server, "", "--variant clear"));
    tmux.wait_for(&["press i to type an instruction"], 20);
    tmux.keys(&["p"]);
    tmux.wait_for(&["grasp \"blue cube\"!", "[o] Fallback"], 20);
    tmux.keys(&["r"]);
    tmux.wait_for(
        &[
            "SUCCESS",
            "[✓] \"blue cube\" on \"green cube\"?",
            "[ ] grasp \"blue cube\"!",
        ],
        30,
    );

    // The goal is the second row.
    tmux.keys(&["Down"]);
    tmux.keys(&["Down"]);
    tmux.keys(&["f"]);
    tmux.wait_for(&["\"blue cube\" on \"green cube\"? ⚑ forced failure"], 10);
    tmux.keys(&["Space"]);
    tmux.wait_for(
        &[
            "[✕] \"blue cube\" on \"green cube\"? ⚑ forced failure",
            "[*] grasp \"blue cube\"!",
        ],
        10,
    );

    // f cycles on to success, running, and off.
    for _ in 0..3 {
        tmux.keys(&["f"]);
    }
    tmux.wait_for(&["no status forced"], 10);
    tmux.keys(&["Space"]);
    let screen = tmux.wait_for(
        &[
            "[✓] \"blue cube\" on \"green cube\"?",
            "[‖] grasp \"blue cube\"!",
        ],
        10,
    );
    assert!(!screen.contains("⚑ forced"), "{screen}");
    tmux.keys(&["q"]);
    tmux.wait_for(&["betr exited with status 0"], 10);
    drop(tmux);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A recorded session in the workbench, read-only: `betr resolve` on scenario 1 recorded
/// against the fake server, the server stopped, then `betr replay` in tmux opens at the
/// end; the keys go back to the failure, on to the question about it and the proposal,
/// and the screen shows each; approving does nothing; q quits.
#[test]
fn a_person_replays_a_recorded_session_without_the_model() {
    let dir = tmp("tmux-replay");
    let record = dir.join("session.jsonl");
    {
        let server = FakeServer::start(vec![], Behavior::Fixtures(fixtures::every_reply()));
        let scenario = fixtures::root().join("scenarios/cell/red_on_blue.toml");
        let out = support::cli::betr(
            &dir,
            &[
                "resolve",
                &scenario.to_string_lossy(),
                "--yes",
                "--base-url",
                &server.base_url(),
                "--model",
                "fake-model",
                "--api-key-env",
                KEY_VAR,
                "--record",
                &record.to_string_lossy(),
            ],
        );
        assert_eq!(out.status.code(), Some(0), "{}", support::cli::text(&out));
    }
    // No server from here on, and no key: the replay needs neither.
    let tmux = Tmux::start(&format!(
        "cd {dir} && {isolated} {bin} replay session.jsonl; echo \"betr exited with status $?\"; \
         sleep 60",
        dir = quote(&dir),
        isolated = support::tmux::isolated_env(&dir),
        bin = quote(Path::new(env!("CARGO_BIN_EXE_betr"))),
    ));
    let end = tmux.wait_for(&["REPLAY  step", "SUCCESS", "Replay (read-only)"], 20);
    let (position, steps) = replay_position(&end);
    assert_eq!(position, steps, "it opens at the end:\n{end}");

    tmux.keys(&["N"]);
    let screen = tmux.wait_for(
        &[
            "grasp \"blue cube\"! ◀ failed",
            "FAILED",
            "No proposal pending",
            "✗ grasp \"blue cube\"! (node 1.0.1.1) failed",
        ],
        10,
    );
    assert!(replay_position(&screen).0 < position, "{screen}");
    tmux.keys(&["m"]);
    tmux.wait_for(&["asking the model for"], 10);
    tmux.keys(&["m"]);
    tmux.wait_for(&["reply from"], 10);
    let mut proposal = None;
    for _ in 0..20 {
        tmux.keys(&["Right"]);
        std::thread::sleep(Duration::from_millis(100));
        let screen = tmux.screen();
        if screen.contains("Proposal for grasp \"blue cube\"!") {
            proposal = Some(screen);
            break;
        }
    }
    let screen = proposal.unwrap_or_else(|| panic!("no proposal:\n{}", tmux.screen()));
    assert!(
        screen.contains("~\"any object\" on \"blue cube\""),
        "{screen}"
    );
    assert!(screen.contains("◀ failed"), "{screen}");
    // Approving belongs to the live workbench: nothing moves.
    let at = replay_position(&screen).0;
    tmux.keys(&["a"]);
    std::thread::sleep(Duration::from_millis(300));
    assert_eq!(replay_position(&tmux.screen()).0, at);

    tmux.keys(&["q"]);
    let screen = tmux.wait_for(&["betr exited with status 0"], 10);
    assert!(
        !screen.contains("REPLAY"),
        "the alternate screen was left:\n{screen}"
    );
    drop(tmux);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The step a replay's status bar stands on, and of how many (`step 12/45`).
fn replay_position(screen: &str) -> (usize, usize) {
    let at = screen
        .find("REPLAY  step ")
        .expect("the replay's status bar")
        + 13;
    let field = screen[at..].split_whitespace().next().unwrap();
    let (p, n) = field.split_once('/').unwrap();
    (p.parse().unwrap(), n.parse().unwrap())
}

/// `betr SCENARIO [workbench options]` without a command is the workbench, a scenario
/// given by its name as every command takes it.
#[test]
fn bare_betr_with_a_scenario_name_opens_the_workbench_on_it() {
    let server = FakeServer::start(vec![], Behavior::Fixtures(fixtures::every_reply()));
    let dir = tmp("tmux-bare");
    // The shell sleeps first: a `q` typed meanwhile waits in the terminal, as keys typed
    // while betr starts do, and must not quit the workbench when it opens.
    let command = format!(
        "cd {repo} && sleep 1 && {isolated} {key_var}={key} {bin} cafe/no_coffee --backend openai \
         --base-url {url} --model fake-model --api-key-env {key_var} --policy-dir {policies}; \
         echo \"betr exited with status $?\"; sleep 60",
        repo = quote(&fixtures::root()),
        isolated = support::tmux::isolated_env(&dir),
        key_var = KEY_VAR,
        key = KEY,
        bin = quote(Path::new(env!("CARGO_BIN_EXE_betr"))),
        url = server.base_url(),
        policies = quote(&dir.join("policies")),
    );
    let tmux = Tmux::start(&command);
    tmux.keys(&["q"]);
    tmux.wait_for(&["Behavior tree", "no_coffee", "openai fake-model"], 20);
    std::thread::sleep(std::time::Duration::from_millis(500));
    let screen = tmux.screen();
    assert!(!screen.contains("betr exited"), "{screen}");
    tmux.keys(&["q"]);
    tmux.wait_for(&["betr exited with status 0"], 10);
    drop(tmux);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The cafe with a goal of five wishes, not the scenario's own: the scenario's declared
/// property `always Holding_Nothing | Holding_Coffee` is broken by the planned tree before
/// any change (it carries the water), so the approved fix is not held for it: the log says
/// the failure is the tree's, declared for the scenario's goal, and the tree runs on.
#[test]
fn a_property_the_tree_broke_already_does_not_hold_the_approved_fix() {
    let server = FakeServer::start(
        vec![],
        Behavior::Fixtures(fixtures::replies_of("no_coffee.toml")),
    );
    let dir = tmp("tmux-cafe-property");
    let tmux = Tmux::start(&support::tmux::workbench_command_on(
        "scenarios/cafe/no_coffee.toml",
        &dir,
        &server,
        ("", ""),
    ));
    tmux.wait_for(&["Behavior tree", "no_coffee"], 20);
    tmux.keys(&["i"]);
    tmux.wait_for(&["Instruction or goal"], 10);
    tmux.text("On_Water_Table2 & On_Dessert_Table3 & Active_AC & IsClean_Floor & On_Coffee_Table1");
    tmux.keys(&["Enter"]);
    tmux.wait_for(&["planned for On_Water_Table2"], 20);
    tmux.keys(&["r"]);
    tmux.wait_for(&["Exists_Coffee", "a approve · x reject · e edit"], 30);
    tmux.keys(&["a"]);
    let screen = tmux.wait_for(&["the change breaks nothing"], 20);
    assert!(
        !screen.contains("fails verification: approve again"),
        "the fix was held:\n{screen}"
    );
    tmux.keys(&["r"]);
    tmux.wait_for(&["SUCCESS"], 60);
    drop(tmux);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A slow model's question shows how long it has waited and the key that cancels it;
/// `Esc` cancels it, and the person's own fix then resolves the failure.
#[test]
fn a_person_cancels_a_slow_question_and_writes_the_fix() {
    let server = FakeServer::start(
        vec![],
        Behavior::Slow(Duration::from_secs(600), "never read".into()),
    );
    let dir = tmp("tmux-cancel");
    let tmux = Tmux::start(&workbench_command(&dir, &server, "", ""));
    tmux.wait_for(&["Behavior tree", "red_on_blue"], 20);
    tmux.keys(&["i"]);
    tmux.wait_for(&["Instruction or goal"], 10);
    tmux.text("\"blue cube\" on \"green cube\"");
    tmux.keys(&["Enter"]);
    tmux.wait_for(&["grasp \"blue cube\"!"], 20);
    tmux.keys(&["r"]);
    tmux.wait_for(&["asking the model for", "esc cancels"], 30);
    // While the model is asked, betr's shortlist is on screen, with the call counted.
    tmux.wait_for(
        &[
            " 2 s · call 1 · esc cancels",
            "the model is choosing among these 2",
        ],
        10,
    );
    tmux.keys(&["Escape"]);
    let screen = tmux.wait_for(&["What now:", "question was cancelled"], 10);
    assert!(!screen.contains("esc cancels"), "{screen}");
    assert!(screen.contains("choose one yourself"), "{screen}");
    // The fix line opens with the shortlist's first fix: Enter applies it.
    tmux.keys(&["e"]);
    tmux.wait_for(&["~\"any object\" on \"blue cube\""], 10);
    tmux.keys(&["Enter"]);
    tmux.wait_for(&["+[ ] ~\"any object\" on \"blue cube\"?"], 20);
    tmux.keys(&["r"]);
    tmux.wait_for(&["SUCCESS"], 30);
    drop(tmux);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// With `--executor`, the workbench says what performs the actions and runs the tree in
/// it: the fixture executor process (three ticks an action) takes scenario 1's tree, in
/// its `clear` world, to success.
#[test]
fn a_person_runs_the_tree_in_an_executor_process() {
    let server = FakeServer::start(vec![], Behavior::Fixtures(fixtures::every_reply()));
    let dir = tmp("tmux-executor");
    let follower = fixtures::root().join("tests/fixtures/executor/follower.py");
    let extra = format!(
        "--variant clear --executor \"python3 {} --ticks 3\"",
        quote(&follower)
    );
    let tmux = Tmux::start(&workbench_command(&dir, &server, "", &extra));
    tmux.wait_for(
        &[
            "Performed by the python3 follower.py executor",
            "the python3 follower.py executor performs the",
        ],
        20,
    );
    tmux.keys(&["p"]);
    tmux.wait_for(&["grasp \"blue cube\"!"], 20);
    tmux.keys(&["r"]);
    // The grasp in ticks 1-3, the place in 3-5, the goal found at tick 6: the success is
    // the executor's (the log line wraps after the tick count).
    tmux.wait_for(&["SUCCESS in the python3 follower.py executor after 6"], 60);
    tmux.keys(&["q"]);
    tmux.wait_for(&["betr exited with status 0"], 10);
    drop(tmux);
    std::fs::remove_dir_all(&dir).unwrap();
}
