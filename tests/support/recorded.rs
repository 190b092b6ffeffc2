//! A recording of scenario 1 resolved in the session engine as a person resolves it in the
//! workbench (the instruction, a run to the failure, the fixture's proposal approved, a run
//! to success), every command and event written by a `SessionRecorder`, then read back.
//! The steps' times are rewritten to 10 ms apiece and its events made steady as the live
//! bench's are (`workbench::steady`), so screens that show them are the same in every run.

use std::path::Path;
use std::sync::Arc;
use std::time::Duration;

use betr::record::{Replay, SessionRecorder, Step};
use betr::session::{Command, Engine, Event};

use super::engine::{INSTRUCTION, model, scenario_path, setup};

pub fn scenario_1(file: &Path) -> Replay {
    let path = scenario_path();
    let name = betr::scenario::Scenario::load(&path).unwrap().name;
    let mut recorder = SessionRecorder::create(file, &path, &name, None).unwrap();
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .unwrap();
    runtime.block_on(async {
        let (engine, mut events) =
            Engine::spawn(setup(Ok(Arc::new(model(Duration::ZERO))), None)).unwrap();
        let send = |recorder: &mut SessionRecorder, command: Command| {
            recorder.command(&command);
            assert!(engine.send(command));
        };
        send(&mut recorder, Command::Submit(INSTRUCTION.into()));
        loop {
            let event = tokio::time::timeout(Duration::from_secs(30), events.recv())
                .await
                .expect("the session went on")
                .expect("the engine is there");
            recorder.event(&event);
            match event {
                Event::TreeChanged { .. } => send(&mut recorder, Command::Run),
                Event::Proposal { .. } => send(&mut recorder, Command::Approve),
                Event::Success { .. } => break,
                Event::ChangeViolates { .. } | Event::GaveUp { .. } | Event::Failed { .. } => {
                    panic!("scenario 1 did not resolve: {event:?}")
                }
                _ => {}
            }
        }
        send(&mut recorder, Command::Shutdown);
    });
    let mut replay = Replay::load(file, None).unwrap();
    for (i, (ms, step)) in replay.steps.iter_mut().enumerate() {
        *ms = 10 * i as u64;
        if let Step::Event(event) = step {
            super::workbench::steady(event);
        }
    }
    replay
}
