//! Sessions, headless, in three rooms: reading an instruction as a goal ([`interpret`]),
//! repairing a failure ([`repair`]: the question, the shortlist screened in simulation,
//! the evidence, values), and the [`Engine`] (a state machine that owns a task from
//! instruction to saved policy; commands in, events out), which starts a reading or a
//! repair and takes its answer. Beside them: the resolve loop that drives the engine
//! unattended, policies and the knowledge kept from approved fixes. Front ends (CLI, TUI)
//! show the events; nothing here prints or reads a terminal.

mod call;
pub mod engine;
pub mod interpret;
pub mod knowledge;
pub mod planned;
pub mod policy;
pub mod repair;
pub mod resolve;
pub mod types;

pub use crate::planner::RunLimits;
/// The robot description a scenario's arms need and the cache lacks: what a front end
/// fetches before the session's world can move the arms ([`Command::RobotArrived`]).
pub use crate::world::missing_description;
pub use engine::{Command, Engine, EngineHandle, Setup};
pub use interpret::goal_checks::check_goal;
pub use interpret::{Interpretation, interpret};
pub use knowledge::{KeptRule, Knowledge, KnowledgeError, Refusal};
pub use planned::{PlanSummary, Prediction};
pub use policy::{Policy, PolicyStore};
pub use repair::ask::missing_value;
pub use repair::edit::{Edit, EditError, parse_edit, vocabulary_words};
pub use resolve::{Execution, resolve, resolve_with_scenes};
pub use types::{
    BreakReason, Ending, Event, Evidence, FixCounts, NoModel, Options, PhaseKind, Proposal,
    Question, Reading, Resolved, SessionError, Shortlist, Steps,
};

/// Calls `check` with each worked example of the shipped scenes (the cafe and the cell),
/// its scene's path and scenario, and its goal: the misreading checks must find nothing in
/// what the scenes themselves teach.
#[cfg(test)]
pub(crate) fn for_each_worked_example(
    mut check: impl FnMut(
        &str,
        &crate::scenario::Scenario,
        &crate::scenario::Example,
        &crate::goal::Formula,
    ),
) {
    for scene in [
        "scenarios/cafe/cafe.toml",
        "scenarios/cell/red_on_blue.toml",
    ] {
        let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(scene);
        let scenario = crate::scenario::Scenario::load(&path).expect("scene loads");
        assert!(!scenario.examples.is_empty(), "{scene} has worked examples");
        for example in &scenario.examples {
            let goal = crate::goal::Formula::parse(&example.goal).expect("example goal parses");
            check(scene, &scenario, example, &goal);
        }
    }
}
