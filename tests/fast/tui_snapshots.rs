//! Whole-screen snapshots of the workbench (ratatui `TestBackend` + insta), reached the
//! way a person reaches them: key events into the app, its commands into a real session
//! engine on scenario 1, the engine's events back into the app. The model is in-process
//! and answers from the hand-written fixtures. A recording of such a session is replayed
//! too, with the replay's keys.

#![allow(clippy::unwrap_used)] // test helpers outside #[test] functions

use crate::support;

use std::time::Duration;

use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
use ratatui::Terminal;
use ratatui::backend::TestBackend;

use betr::session::{Command, Event};
use betr::tui::dictation::DictationEvent;
use betr::tui::{KeyBindings, KeyMode, Theme, ui};
use betr::voice::Audio16k;
use support::microphone::{AudioMicrophone, tone};
use support::workbench::{Bench, fixed_words};

use support::repo::runtime as rt;

#[test]
fn planned_tree() {
    rt().block_on(async {
        let mut b = Bench::start();
        b.key(KeyCode::Char('i'));
        b.type_text("Put the blue cube on the green cube");
        b.key(KeyCode::Enter);
        b.until(|e| matches!(e, Event::TreeChanged { .. })).await;
        insta::assert_snapshot!("planned_tree", b.screen(120, 40));
    });
}

#[test]
fn failure_with_a_pending_proposal_then_approval() {
    rt().block_on(async {
        let mut b = Bench::start();
        b.step_to_failure().await;
        let screen = b.screen(120, 40);
        assert!(screen.contains("◀ failed"), "{screen}");
        assert!(
            screen.contains("Proposal for grasp \"blue cube\"!"),
            "{screen}"
        );
        insta::assert_snapshot!("failure_with_pending_proposal", screen);

        b.key(KeyCode::Char('a'));
        // The changed tree is verified before it runs: the screen after its verdict.
        b.until(|e| matches!(e, Event::Notice { message } if message == "the changed tree verifies in the model"))
            .await;
        assert_eq!(b.app.summary.unsaved_fixes, 1);
        let screen = b.screen(120, 40);
        assert!(
            screen.contains("+[ ] ~\"any object\" on \"blue cube\"?"),
            "{screen}"
        );
        insta::assert_snapshot!("after_approval", screen);
        // Quitting now would lose the approved fix: q asks first, another key stays.
        b.key(KeyCode::Char('q'));
        let screen = b.screen(120, 40);
        assert!(screen.contains("not saved as a policy"), "{screen}");
        insta::assert_snapshot!("quit_asks_when_a_fix_is_unsaved", screen);
        b.key(KeyCode::Esc);
        assert!(!b.app.should_quit());

        b.key(KeyCode::Char('r'));
        b.until(|e| matches!(e, Event::Success { .. })).await;
        let screen = b.screen(120, 40);
        assert!(screen.contains("SUCCESS"), "{screen}");
        insta::assert_snapshot!("after_run_to_success", screen);
    });
}

/// An edit the app cannot read is shown where the engine's errors are (above the log and
/// in it) and never sent; one the engine refuses is shown the same way.
#[test]
fn an_edit_that_cannot_be_read_is_shown_like_the_engines_errors() {
    rt().block_on(async {
        let mut b = Bench::start();
        b.step_to_failure().await;
        b.key(KeyCode::Char('x'));
        b.until(|e| matches!(e, Event::Rejected)).await;
        // The model is asked again without the rejected fix; every answer of these
        // fixtures names it again, so the questions end with the rounds.
        b.until(|e| matches!(e, Event::GaveUp { .. })).await;
        // The fix line opens with the first fix betr's simulation found; Ctrl-U clears it.
        b.key(KeyCode::Char('e'));
        b.app
            .on_key(KeyEvent::new(KeyCode::Char('u'), KeyModifiers::CONTROL));
        b.type_text("\"purple cube\" on \"blue cube\"");
        b.key(KeyCode::Enter);
        assert!(
            !b.sent.iter().any(|c| matches!(c, Command::Edit(_))),
            "{:?}",
            b.sent
        );
        let shown = b.app.llm.error.clone().unwrap_or_default();
        assert!(shown.contains("unknown object \"purple cube\""), "{shown}");
        assert_eq!(
            b.app.llm.log_lines().last(),
            Some(&format!("error: {shown}"))
        );
        // The line stays as typed, the error under it, for the person to correct.
        let screen = b.screen(120, 40);
        assert!(
            screen.contains("> \"purple cube\" on \"blue cube\""),
            "{screen}"
        );
        insta::assert_snapshot!("a_mistyped_edit_kept_with_its_error", screen);
        b.key(KeyCode::Esc);

        b.key(KeyCode::Char('e'));
        b.app
            .on_key(KeyEvent::new(KeyCode::Char('u'), KeyModifiers::CONTROL));
        b.type_text("5 N");
        b.key(KeyCode::Enter);
        b.until(|e| matches!(e, Event::Error { .. })).await;
        let shown = b.app.llm.error.clone().unwrap_or_default();
        assert!(shown.contains("calls for conditions"), "{shown}");
        assert!(
            b.app.llm.log_lines().contains(&format!("error: {shown}")),
            "{:?}",
            b.app.llm.log_lines()
        );
    });
}

/// A goal formula the scene cannot hold stays in the instruction line with the whole
/// error wrapped under it (80 columns), never reaches the engine, and is one ↑ away after
/// the line is closed; Tab completes a condition without its opening quote.
#[test]
fn a_refused_goal_stays_typed_with_its_error_wrapped_and_in_the_history() {
    rt().block_on(async {
        let mut b = Bench::start();
        let goal = "\"blue cube\" on \"gren cube\" & ~\"red cube\" on \"blue cube\"";
        b.key(KeyCode::Char('i'));
        b.type_text(goal);
        b.key(KeyCode::Enter);
        assert!(
            !b.sent.iter().any(|c| matches!(c, Command::Submit(_))),
            "{:?}",
            b.sent
        );
        let screen = b.screen(80, 24);
        assert!(screen.contains("did you mean"), "{screen}");
        assert!(screen.contains("on \"green"), "{screen}");
        insta::assert_snapshot!("a_refused_goal_kept_with_its_error_wrapped", screen);
        b.key(KeyCode::Esc);
        b.key(KeyCode::Char('i'));
        b.key(KeyCode::Up);
        assert_eq!(b.app.input.text(), goal);
        // Corrected where the error pointed, the goal goes to the engine.
        b.key(KeyCode::Esc);
        b.key(KeyCode::Char('i'));
        b.type_text("blue cube\" on \"gre");
        b.key(KeyCode::Tab);
        assert_eq!(b.app.input.text(), "\"blue cube\" on \"green cube\"");
        b.key(KeyCode::Enter);
        assert!(
            b.sent.iter().any(|c| matches!(c, Command::Submit(_))),
            "{:?}",
            b.sent
        );
    });
}

/// When nothing more is asked about the failure, the pane says every way on with its key;
/// `p` then asks whether planning again keeps the refused fixes, and keeping them plans
/// again without forgetting them.
#[test]
fn when_nothing_more_is_asked_the_ways_on_are_shown_and_plan_asks() {
    rt().block_on(async {
        let mut b = Bench::start();
        b.step_to_failure().await;
        b.key(KeyCode::Char('x'));
        b.until(|e| matches!(e, Event::PersonDecides { .. })).await;
        let refused = b.app.refused_fixes;
        assert!(refused > 0);
        let screen = b.screen(120, 40);
        assert!(screen.contains("What now:"), "{screen}");
        assert!(
            screen.contains(&format!("keeping the {refused} refused")),
            "{screen}"
        );
        insta::assert_snapshot!("nothing_more_is_asked_the_ways_on", screen);

        b.key(KeyCode::Char('p'));
        assert!(!b.sent.contains(&Command::Plan), "{:?}", b.sent);
        let screen = b.screen(120, 40);
        assert!(screen.contains("Plan again?"), "{screen}");
        insta::assert_snapshot!("plan_asks_about_the_refused_fixes", screen);
        // Any other key plans nothing.
        b.key(KeyCode::Char('z'));
        assert!(!b.screen(120, 40).contains("Plan again?"));
        assert_eq!(b.sent.last(), Some(&Command::Reject));

        b.key(KeyCode::Char('p'));
        b.key(KeyCode::Char('k'));
        assert_eq!(b.sent.last(), Some(&Command::PlanKeepingRefused));
        b.until(|e| matches!(e, Event::TreeChanged { .. })).await;
        assert_eq!(b.app.refused_fixes, refused, "kept");
        assert!(!b.screen(120, 40).contains("What now:"));

        b.key(KeyCode::Char('p'));
        b.key(KeyCode::Char('f'));
        assert_eq!(b.sent.last(), Some(&Command::Plan));
        b.until(|e| matches!(e, Event::FixCounts(c) if c.refused == 0))
            .await;
        assert_eq!(b.app.refused_fixes, 0, "forgotten");
        // With none refused, p plans at once.
        b.key(KeyCode::Char('p'));
        assert_eq!(b.sent.last(), Some(&Command::Plan));
    });
}

/// A reasoning that states what the world contradicts is marked doubtful with the claim
/// quoted, after betr's own findings.
#[test]
fn a_false_claim_in_the_reasoning_is_marked_doubtful_with_the_claim_quoted() {
    rt().block_on(async {
        let mut replies = vec![support::fixtures::false_claim_reply()];
        replies.extend(support::fixtures::every_reply());
        let mut b = Bench::answering(replies);
        b.step_to_failure().await;
        let doubt = b
            .app
            .llm
            .proposal
            .as_ref()
            .and_then(|p| p.doubt.clone())
            .unwrap_or_default();
        assert_eq!(
            doubt,
            "it says \"The red cube is on the table\", but \"red cube\" on \"table\" is false at the failure"
        );
        let screen = b.screen(160, 50);
        assert!(screen.contains("DOUBTFUL"), "{screen}");
        insta::assert_snapshot!("a_false_claim_marked_doubtful", screen);
    });
}

#[test]
fn an_approved_fix_kept_as_a_rule_is_marked_in_the_tree() {
    let dir = std::env::temp_dir().join(format!("betr-tui-knowledge-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("knowledge.toml");
    rt().block_on(async {
        let knowledge = betr::session::Knowledge::open(&file).unwrap();
        let mut b = Bench::with_knowledge(
            AudioMicrophone::missing(),
            fixed_words("unused"),
            Some(knowledge),
        );
        b.step_to_failure().await;
        b.key(KeyCode::Char('a'));
        b.until(|e| matches!(e, Event::RuleOffered { .. })).await;
        let screen = b.screen(120, 40);
        assert!(
            screen.contains("Keep as a rule for later tasks: grasp {x} needs"),
            "{screen}"
        );
        b.key(KeyCode::Char('m'));
        b.until(|e| matches!(e, Event::TreeChanged { learned, .. } if !learned.is_empty()))
            .await;
        let screen = b.screen(120, 40);
        assert!(
            screen.contains("~\"any object\" on \"blue cube\"? ◆ learned r1"),
            "{screen}"
        );
        // (No snapshot: the screen shows the knowledge file's temporary path.)
        assert!(screen.contains("kept as rule r1"), "{screen}");
        b.key(KeyCode::Char('g'));
        b.until(|e| matches!(e, Event::Knowledge { .. })).await;
        let screen = b.screen(120, 40);
        assert!(
            screen.contains("Rules learned from approved fixes (1"),
            "{screen}"
        );
        assert!(screen.contains("r1: grasp {x} needs"), "{screen}");
    });
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The debugger's keys on scenario 1's planned tree: `b` puts a breakpoint on the
/// selected grasp, `f` forces the selected goal condition to fail; both are marked. Run
/// stops before the first tick, which would enter the grasp: it is highlighted and the
/// status bar says why.
#[test]
fn a_breakpoint_and_a_forced_node_are_marked_and_the_run_stops_there() {
    rt().block_on(async {
        let mut b = Bench::start();
        b.key(KeyCode::Char('p'));
        b.until(|e| matches!(e, Event::TreeChanged { .. })).await;
        // Nothing selected yet: the keys say so and send nothing.
        b.key(KeyCode::Char('b'));
        assert!(
            b.screen(120, 40)
                .contains("select a node in the tree first")
        );
        assert!(b.sent.iter().all(|c| *c == Command::Plan), "{:?}", b.sent);
        // The grasp is the eighth row: root, goal, sequence, fallback, grasped?,
        // sequence, hand empty?, grasp.
        for _ in 0..8 {
            b.key(KeyCode::Down);
        }
        b.key(KeyCode::Char('b'));
        b.until(|e| matches!(e, Event::Breakpoints { .. })).await;
        b.key(KeyCode::Home);
        b.key(KeyCode::Down);
        b.key(KeyCode::Char('f'));
        b.until(|e| matches!(e, Event::Forced { .. })).await;
        let screen = b.screen(120, 40);
        assert!(screen.contains("grasp \"blue cube\"! ● break"), "{screen}");
        assert!(
            screen.contains("\"blue cube\" on \"green cube\"? ⚑ forced failure"),
            "{screen}"
        );
        insta::assert_snapshot!("breakpoint_and_forced_node", screen);

        b.key(KeyCode::Char('r'));
        b.until(|e| matches!(e, Event::BreakpointHit { .. })).await;
        let screen = b.screen(120, 40);
        assert!(screen.contains("◀ stopped here"), "{screen}");
        assert!(
            screen.contains(
                "stopped at a breakpoint: grasp \"blue cube\"! (node 1.0.1.1) before tick 1"
            ),
            "{screen}"
        );
        insta::assert_snapshot!("stopped_at_breakpoint", screen);

        // The next key takes the message away; the status bar still says the run stopped,
        // and that break on failure is on once B turns it on. With the goal selected again
        // (the stop selected the grasp), f cycles its forced status on to success,
        // running, and off.
        b.key(KeyCode::Char('B'));
        b.until(|e| {
            matches!(
                e,
                Event::Breakpoints {
                    on_failure: true,
                    ..
                }
            )
        })
        .await;
        let screen = b.screen(120, 40);
        let status_bar = screen.lines().last().unwrap();
        assert!(status_bar.contains("STOPPED"), "{screen}");
        assert!(status_bar.contains("break on failure"), "{screen}");
        b.key(KeyCode::Home);
        b.key(KeyCode::Down);
        for want in ["⚑ forced success", "⚑ forced running"] {
            b.key(KeyCode::Char('f'));
            b.until(|e| matches!(e, Event::Forced { .. })).await;
            assert!(b.screen(120, 40).contains(want), "{want}");
        }
        b.key(KeyCode::Char('f'));
        b.until(|e| matches!(e, Event::Forced { forced } if forced.is_empty()))
            .await;
        assert!(!b.screen(120, 40).contains("⚑ forced"));
    });
}

#[test]
fn help_overlay_lists_every_binding() {
    rt().block_on(async {
        let mut b = Bench::start();
        b.key(KeyCode::Char('?'));
        // Too many keys for one column in 40 rows: two columns.
        let screen = b.screen(160, 40);
        for (key, what) in KeyBindings::default().help_lines(KeyMode::Workbench) {
            assert!(screen.contains(&key), "{key} missing:\n{screen}");
            assert!(screen.contains(what), "{what} missing:\n{screen}");
        }
        insta::assert_snapshot!("help_overlay", screen);
        // Any key closes it.
        b.key(KeyCode::Esc);
        assert!(!b.screen(120, 40).contains("Press any key to close"));
    });
}

#[test]
fn small_terminal_stays_usable() {
    rt().block_on(async {
        let mut b = Bench::start();
        b.step_to_failure().await;
        let screen = b.screen(80, 24);
        // The proposal and its keys stay on the pane's border; its findings lead inside.
        assert!(screen.contains("proposed: ~\"any object\" on"), "{screen}");
        assert!(screen.contains("a approve · x reject"), "{screen}");
        assert!(screen.contains("Found by betr:"), "{screen}");
        assert!(screen.contains("tick"), "{screen}");
        insta::assert_snapshot!("small_terminal_80x24", screen);
        // Even tinier terminals draw without panicking.
        for (w, h) in [(40, 12), (20, 6), (1, 1)] {
            b.screen(w, h);
        }
    });
}

/// Push-to-talk as a person uses it: d records (a level meter, the elapsed time), d again
/// stops and transcribes, and the words land in the input line, not submitted; Enter
/// submits them, as typed words would be.
#[test]
fn dictation_records_then_puts_the_transcript_in_the_input_line() {
    rt().block_on(async {
        let mut b = Bench::with_microphone(
            AudioMicrophone::playing(tone(2.0)),
            fixed_words("Put the blue cube on the green cube"),
        );
        b.key(KeyCode::Char('d'));
        b.until_heard(|e| matches!(e, DictationEvent::Recording { .. }))
            .await;
        // A level (every 50 ms window of the tone has the same), then a fixed clock for
        // the snapshot.
        b.until_heard(|e| matches!(e, DictationEvent::Level(_)))
            .await;
        if let betr::tui::components::dictation::Dictation::Recording { elapsed, .. } =
            &mut b.app.dictation.state
        {
            *elapsed = Duration::from_millis(2_040);
        }
        let screen = b.screen(120, 40);
        assert!(screen.contains("● REC 0:02.0"), "{screen}");
        assert!(screen.contains("test microphone"), "{screen}");
        assert!(screen.contains("d stops and transcribes"), "{screen}");
        insta::assert_snapshot!("dictation_recording", screen);

        b.key(KeyCode::Char('d'));
        b.until_heard(|e| matches!(e, DictationEvent::Transcribing { .. }))
            .await;
        let screen = b.screen(120, 40);
        assert!(screen.contains("transcribing 2.0 s of audio"), "{screen}");
        insta::assert_snapshot!("dictation_transcribing", screen);

        b.until_heard(|e| matches!(e, DictationEvent::Heard(_)))
            .await;
        let screen = b.screen(120, 40);
        assert!(
            screen.contains("> Put the blue cube on the green cube"),
            "{screen}"
        );
        assert!(screen.contains("dictated 2.0 s in 0.3 s"), "{screen}");
        insta::assert_snapshot!("dictation_transcript_in_input_line", screen);
        assert!(b.sent.is_empty(), "submitted unseen: {:?}", b.sent);

        // The person corrects the transcript, then submits it.
        for _ in 0.."green cube".len() {
            b.key(KeyCode::Backspace);
        }
        b.type_text("red cube");
        b.key(KeyCode::Enter);
        assert_eq!(
            b.sent,
            [Command::Submit("Put the blue cube on the red cube".into())]
        );
    });
}

#[test]
fn dictation_without_a_microphone_says_so_and_the_session_goes_on() {
    rt().block_on(async {
        let mut b = Bench::start();
        b.key(KeyCode::Char('d'));
        b.until_heard(|e| matches!(e, DictationEvent::Failed(_)))
            .await;
        let screen = b.screen(120, 40);
        assert!(screen.contains("dictation: no microphone"), "{screen}");
        insta::assert_snapshot!("dictation_no_microphone", screen);
        // The next key clears the message (the log keeps it) and works as usual.
        b.key(KeyCode::Char('i'));
        let screen = b.screen(120, 40);
        let status_bar = screen.lines().last().unwrap();
        assert!(!status_bar.contains("no microphone"), "{screen}");
        assert!(screen.contains("dictation: no microphone"), "{screen}");
        assert!(screen.contains("Instruction or goal"), "{screen}");
    });
}

#[test]
fn a_recording_can_be_discarded_and_a_silent_one_is_refused() {
    rt().block_on(async {
        let mut b = Bench::with_microphone(
            AudioMicrophone::playing(Audio16k::new(vec![0.0; 32_000])),
            fixed_words("never heard"),
        );
        b.key(KeyCode::Char('d'));
        b.until_heard(|e| matches!(e, DictationEvent::Recording { .. }))
            .await;
        b.key(KeyCode::Esc);
        b.until_heard(|e| matches!(e, DictationEvent::Cancelled))
            .await;
        let screen = b.screen(120, 40);
        assert!(screen.contains("recording discarded"), "{screen}");
        assert!(
            screen.contains("press i to type an instruction"),
            "{screen}"
        );

        b.key(KeyCode::Char('d'));
        b.until_heard(|e| matches!(e, DictationEvent::Recording { .. }))
            .await;
        b.key(KeyCode::Char('d'));
        b.until_heard(|e| matches!(e, DictationEvent::Failed(_)))
            .await;
        let screen = b.screen(120, 40);
        assert!(screen.contains("the recording is silent"), "{screen}");
        assert!(!screen.contains("never heard"), "{screen}");
        assert!(b.sent.is_empty(), "{:?}", b.sent);
    });
}

/// A recorded session replayed: from the end, back to the failure, then on to the
/// proposal, with the replay's keys; the help lists them and none that edits or runs.
#[test]
fn a_replay_steps_back_to_the_failure_and_on_to_the_proposal() {
    use betr::tui::replay::{Player, ReplayScreen};
    let scratch = support::cli::tmp("snapshot-replay");
    let file = scratch.join("session.jsonl");
    let replay = support::recorded::scenario_1(&file);
    let player = Player::of(replay, KeyBindings::default(), Theme::default());
    let mut s = ReplayScreen::open(player, usize::MAX);
    let screen = |s: &mut ReplayScreen| {
        let mut terminal = Terminal::new(TestBackend::new(120, 40)).unwrap();
        terminal.draw(|f| ui::draw(f, &mut s.app)).unwrap();
        // How many steps follow the proposal depends on how the engine's events after it
        // interleaved with the commands the recording sent; the screen at the proposal
        // is what is compared.
        let drawn = terminal.backend().to_string();
        let Some((head, rest)) = drawn.split_once("REPLAY  step ") else {
            return drawn;
        };
        let Some((at, after)) = rest.split_once('/') else {
            return drawn;
        };
        let total_digits = after.chars().take_while(char::is_ascii_digit).count();
        let total: usize = after[..total_digits].parse().unwrap();
        let at: usize = at.parse().unwrap();
        assert!(at <= total, "step {at} of {total}");
        format!("{head}REPLAY  step {at}/…{}", &after[total_digits..])
    };
    let key = |s: &mut ReplayScreen, code: KeyCode| s.key(KeyEvent::new(code, KeyModifiers::NONE));
    key(&mut s, KeyCode::Char('N'));
    key(&mut s, KeyCode::Char('m'));
    key(&mut s, KeyCode::Char('m'));
    while s.app.llm.proposal.is_none() {
        key(&mut s, KeyCode::Right);
    }
    let at_proposal = screen(&mut s);
    assert!(at_proposal.contains("◀ failed"), "{at_proposal}");
    assert!(at_proposal.contains("REPLAY  step"), "{at_proposal}");
    insta::assert_snapshot!("replay_at_the_proposal", at_proposal);
    key(&mut s, KeyCode::Char('?'));
    let help = screen(&mut s);
    for (key, what) in KeyBindings::default().help_lines(KeyMode::Replay) {
        assert!(help.contains(&key), "{key} missing:\n{help}");
        assert!(help.contains(what), "{what} missing:\n{help}");
    }
    assert!(!help.contains("approve the proposal"), "{help}");
    insta::assert_snapshot!("replay_help", help);
}

/// While the model is asked about the grasp that failed, what betr's simulation found is
/// already on screen with how many fixes the model chooses among, the call under way is
/// counted, and `Esc` leaves the shortlist to the person: the fix line opens with its
/// first fix.
#[test]
fn the_wait_for_the_model_shows_the_shortlist_and_esc_leaves_it_to_the_person() {
    rt().block_on(async {
        let mut b = Bench::slow_to_propose(Duration::from_secs(30));
        b.step_to_question().await;
        // The elapsed time is the clock's: fixed for the snapshot.
        b.app.llm.asking_since = Some(std::time::Instant::now());
        let screen = b.screen(120, 40);
        assert!(
            screen.contains("Found by betr: grasp \"blue cube\"!"),
            "{screen}"
        );
        assert!(
            screen.contains("the model is choosing among these"),
            "{screen}"
        );
        assert!(screen.contains("0 s · call 1 · esc cancels"), "{screen}");
        assert!(screen.contains("asking the model"), "{screen}");
        insta::assert_snapshot!("waiting_for_the_model", screen);
        b.key(KeyCode::Esc);
        b.until(|e| matches!(e, Event::PersonDecides { .. })).await;
        let screen = b.screen(120, 40);
        assert!(!screen.contains("asking the model"), "{screen}");
        assert!(screen.contains("choose one yourself"), "{screen}");
        assert!(screen.contains("waits for you"), "{screen}");
        let first = b.app.llm.screened.as_ref().unwrap().1.fixes[0].to_string();
        b.key(KeyCode::Char('e'));
        assert!(b.screen(120, 40).contains(&first), "{first}");
    });
}

/// A tree that fails because a person forced its root to fail (no action failed) ends
/// FAILED in the status bar, as a failed action does.
#[test]
fn a_tree_failed_on_a_forced_status_is_marked_failed() {
    rt().block_on(async {
        let mut b = Bench::start();
        b.key(KeyCode::Char('p'));
        b.until(|e| matches!(e, Event::TreeChanged { .. })).await;
        // The first row is the root (selected in the tree as drawn).
        b.screen(120, 40);
        b.key(KeyCode::Home);
        let root = b.app.tree.selected().unwrap();
        assert!(b.engine.send(Command::Force {
            node: root,
            status: Some(betr::bt::Forced::Failure),
        }));
        b.key(KeyCode::Char(' '));
        b.until(|e| matches!(e, Event::GaveUp { .. })).await;
        let screen = b.screen(120, 40);
        assert!(screen.contains("FAILED"), "{screen}");
        assert!(screen.contains("paused"), "{screen}");
    });
}

/// The 3D view's web page, when betr started a web viewer, is in `?` on a line of its own,
/// whole at 80 columns, so it can be copied.
#[test]
fn the_help_shows_the_viewer_page_whole() {
    rt().block_on(async {
        let page = "http://127.0.0.1:9090/?url=rerun%2Bhttp%3A%2F%2F127.0.0.1%3A9876%2Fproxy";
        let mut b = Bench::start();
        b.app.viewer_page = Some(page.to_string());
        b.key(KeyCode::Char('?'));
        for (w, h) in [(120, 40), (80, 24)] {
            let screen = b.screen(w, h);
            assert!(screen.lines().any(|l| l.contains(page)), "{screen}");
            assert!(
                screen.contains("3D view: open this address in a browser:"),
                "{screen}"
            );
        }
    });
}
