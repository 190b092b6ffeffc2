//! Sessions, headless: the [`Engine`] (a state machine that owns a task from instruction
//! to saved policy; commands in, events out), the resolve loop that drives it unattended,
//! the questions asked of a model, and policies that last. Front ends (CLI, TUI) drive
//! them and show the events they emit; nothing here prints or reads a terminal.

pub mod ask;
mod confirm;
pub mod edit;
pub mod engine;
pub mod evidence;
pub mod goal_checks;
pub mod interpret;
mod interpret_parts;
mod judge;
pub mod knowledge;
mod named_first;
pub mod planned;
pub mod policy;
pub mod readings;
pub mod resolve;
pub mod screen;
pub mod shortlist;
pub mod submitted;
pub mod types;
pub mod value_bounds;
mod value_levels;
pub mod values;

pub use crate::planner::RunLimits;
/// The robot description a scenario's arms need and the cache lacks: what a front end
/// fetches before the session's world can move the arms ([`Command::RobotArrived`]).
pub use crate::world::missing_description;
pub use ask::missing_value;
pub use edit::{Edit, EditError, parse_edit, vocabulary_words};
pub use engine::{Command, Engine, EngineHandle, Setup};
pub use evidence::Evidence;
pub use goal_checks::check_goal;
pub use interpret::{Interpretation, interpret};
pub use knowledge::{KeptRule, Knowledge, KnowledgeError, Refusal};
pub use planned::{PlanSummary, Prediction};
pub use policy::{Policy, PolicyStore};
pub use readings::Reading;
pub use resolve::{resolve, resolve_with_scenes};
pub use types::{
    BreakReason, Ending, Event, NoModel, Options, Proposal, Question, Resolved, SessionError,
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
