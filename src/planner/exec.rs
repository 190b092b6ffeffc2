//! Running a tree in a world: the leaf executor that connects `bt` to a `World`, and a
//! run-to-completion loop used by the planner's simulation and by `betr run`.
//!
//! The executor also monitors postconditions: an action that completes without its
//! declared effects (a mop-less sweep) is reported as a failure with the text
//! `Postcondition IsClean_Floor not met after Sweep action completion`, because a reactive
//! tree would otherwise re-run it forever.

use crate::bt::{ActionStep, Leaves, NodeId, Outcome, TickRecord, Ticker, Tree};
use crate::domain::{ActionCall, Condition, Domain};
use crate::world::{Step, World};

pub struct WorldLeaves<'a> {
    pub world: &'a mut dyn World,
    pub domain: &'a Domain,
}

impl Leaves for WorldLeaves<'_> {
    fn check(&mut self, condition: &Condition) -> bool {
        self.world.check(condition)
    }

    fn step(&mut self, _node: NodeId, action: &ActionCall, started: bool) -> ActionStep {
        match self.world.step(action, started) {
            Step::Running => ActionStep::Running,
            Step::Failure(error) => ActionStep::Failure(error),
            Step::Success => match postcondition_failure(self.domain, &*self.world, action) {
                Some(error) => ActionStep::Failure(error),
                None => ActionStep::Success,
            },
        }
    }

    fn halt(&mut self, _node: NodeId, action: &ActionCall) {
        self.world.halt(action);
    }
}

/// The error an action that completed reports when one of its declared effects does not
/// hold in `world` afterwards (the paper's words).
pub fn postcondition_failure(
    domain: &Domain,
    world: &dyn World,
    action: &ActionCall,
) -> Option<String> {
    let unmet = unmet_postcondition(domain, world, action)?;
    Some(format!(
        "Postcondition {unmet} not met after {} action completion",
        action.skill
    ))
}

/// The first declared effect of `action` that does not hold in `world`.
pub fn unmet_postcondition(
    domain: &Domain,
    world: &dyn World,
    action: &ActionCall,
) -> Option<Condition> {
    let ground = domain.resolve(action)?;
    ground
        .postconditions()
        .into_iter()
        .find(|c| !world.check(c))
}

/// How a run ended.
#[derive(Debug, Clone, PartialEq)]
pub enum RunEnd {
    Success,
    /// The tree failed; when an action failed on the last tick, which and with what text.
    Failure {
        action: Option<(NodeId, String)>,
    },
    /// Still running after the tick budget.
    TickLimit,
}

/// The result of ticking a tree until it stops running.
pub struct RunReport {
    pub end: RunEnd,
    pub ticks: u64,
    pub last: Option<TickRecord>,
}

/// How many ticks a tree may take: in the world it acts in (a run, a verified
/// execution), and in each run the planner simulates while it grows or repairs a tree.
/// One place for both, so every command and the workbench agree.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RunLimits {
    pub run_ticks: u64,
    pub plan_ticks: u64,
}

impl RunLimits {
    pub const DEFAULT: RunLimits = RunLimits {
        run_ticks: 10_000,
        plan_ticks: 2_000,
    };
}

impl Default for RunLimits {
    fn default() -> Self {
        RunLimits::DEFAULT
    }
}

/// Tick `tree` in `world` until the root returns Success or Failure, or `max_ticks` pass.
///
/// Success counts only from a tick in which no action completed: an action that completes
/// late in a tick can undo a condition the same tick already checked (moving to the cup
/// leaves the window table), so such a tick is followed by one that checks again.
/// `on_tick` sees every record and the world after that tick (for tracing and conflict
/// detection); returning `false` from it stops the run early.
pub fn run_tree(
    tree: &Tree,
    world: &mut dyn World,
    domain: &Domain,
    max_ticks: u64,
    mut on_tick: impl FnMut(&TickRecord, &dyn World) -> bool,
) -> RunReport {
    let mut ticker = Ticker::new();
    let mut leaves = WorldLeaves { world, domain };
    let mut last = None;
    for n in 1..=max_ticks {
        let record = ticker.tick(tree, &mut leaves);
        let keep_going = on_tick(&record, &*leaves.world);
        let end = match record.root {
            Outcome::Running => None,
            Outcome::Success if record.completed.is_empty() => Some(RunEnd::Success),
            Outcome::Success => None,
            Outcome::Failure => Some(RunEnd::Failure {
                action: record.failures.first().cloned(),
            }),
        };
        last = Some(record);
        if let Some(end) = end {
            return RunReport {
                end,
                ticks: n,
                last,
            };
        }
        if !keep_going {
            break;
        }
    }
    ticker.halt_all(tree, &mut leaves);
    RunReport {
        end: RunEnd::TickLimit,
        ticks: ticker.tick_count(),
        last,
    }
}
