//! Seeking in a long recording, through the replay workbench's own seek
//! (`tui::replay::Player::seek`, which every key of a replay calls): a session of 10,000
//! ticks on a tree of about 500 nodes is made in memory — the tree built with `bt` as the
//! tick benchmark builds its tree, the ticks ticked by the real `Ticker`, and every tenth of
//! them a failure, a model call, a proposal, its approval and the tree again, as a resolve
//! session records them — then the app is rebuilt at random steps.

use std::path::Path;
use std::sync::Arc;
use std::time::{Duration, Instant};

use super::{BenchError, Better, Row, Target};
use crate::bt::{ActionStep, Leaves, NodeId, NodeKind, Ticker};
use crate::domain::{ActionCall, Atom, Condition};
use crate::llm::usage::UsageTotals;
use crate::record::Step;
use crate::scenario::Scenario;
use crate::session::{Event, Proposal};
use crate::tui::replay::Player;
use crate::tui::{Info, KeyBindings, Theme};

/// What seeking is measured on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Sizes {
    pub nodes: usize,
    pub ticks: usize,
    pub seeks: usize,
}

impl Sizes {
    pub const FULL: Sizes = Sizes {
        nodes: 500,
        ticks: 10_000,
        seeks: 100,
    };
    pub const QUICK: Sizes = Sizes {
        nodes: 100,
        ticks: 1_000,
        seeks: 20,
    };
}

/// A session's ticks over the failures in it (each followed by a model call and a repair).
const EPISODES: usize = 10;
/// Ticks between two changes of the world's facts.
const FACTS_EVERY: usize = 10;
/// Milliseconds between ticks, as `betr tui --tick-ms` would space them.
const TICK_MS: u64 = 50;

/// The seeks' times on one synthetic recording.
#[derive(Debug, Clone, PartialEq)]
pub struct SeekTimes {
    pub nodes: usize,
    pub ticks: usize,
    pub steps: usize,
    pub seeks: usize,
    pub mean: Duration,
    pub max: Duration,
    /// A seek and the screen drawn (120 × 40), as a key in the replay costs.
    pub shown_mean: Duration,
    pub shown_max: Duration,
    /// The same positions reached by feeding every step from the start.
    pub every_step_mean: Duration,
    pub every_step_max: Duration,
    /// Steps fed per seek, on average (the rest are ticks the screen no longer shows).
    pub fed: f64,
}

/// Conditions hold by their name; every third step of an action completes it, so the
/// statuses move from tick to tick.
struct Stepping(u64);

impl Leaves for Stepping {
    fn check(&mut self, condition: &Condition) -> bool {
        condition.atom.predicate.starts_with("Ok")
    }
    fn step(&mut self, _: NodeId, _: &ActionCall, _: bool) -> ActionStep {
        self.0 += 1;
        if self.0.is_multiple_of(3) {
            ActionStep::Success
        } else {
            ActionStep::Running
        }
    }
    fn halt(&mut self, _: NodeId, _: &ActionCall) {}
}

fn fact(n: usize) -> Condition {
    Condition::pos(Atom {
        predicate: format!("Moved_{}", n % 7),
        args: Vec::new(),
    })
}

/// A recorded session of `ticks` ticks on a tree of about `nodes` nodes, as steps.
pub fn synthetic(nodes: usize, ticks: usize) -> Result<Vec<(u64, Step)>, BenchError> {
    let tree = super::ticks::pytrees_shape(nodes)
        .map_err(|e| BenchError::Setup(format!("the tree: {e}")))?;
    let action = tree
        .preorder()
        .into_iter()
        .find(|n| matches!(tree.kind(*n), Ok(NodeKind::Action(_))))
        .ok_or_else(|| BenchError::Setup("the tree has no action".into()))?;
    let call = match tree.kind(action) {
        Ok(NodeKind::Action(a)) => a.clone(),
        _ => ActionCall::new("Act", ["a0"]),
    };
    let path = tree.path(action).unwrap_or_default();
    let mut steps: Vec<(u64, Step)> = Vec::with_capacity(ticks * 6 / 5 + 64);
    let mut ms = 0;
    let mut push = |ms: u64, step: Step| steps.push((ms, step));
    let event = |e: Event| Step::Event(e);
    let mut tree = Arc::new(tree);
    let mut usage = UsageTotals::default();
    push(ms, Step::Command("plan".into()));
    push(
        ms,
        event(Event::TreeChanged {
            tree: tree.clone(),
            new_nodes: Vec::new(),
            learned: Vec::new(),
            why: "planned".into(),
        }),
    );
    push(ms, Step::Command("run".into()));
    push(ms, event(Event::RunState { running: true }));
    let mut ticker = Ticker::new();
    let mut leaves = Stepping(0);
    let episode = episode(ticks);
    for t in 1..=ticks {
        ms += TICK_MS;
        let record = ticker.tick(&tree, &mut leaves);
        push(
            ms,
            event(Event::Ticked {
                record: Arc::new(record),
            }),
        );
        if t % FACTS_EVERY == 0 {
            push(
                ms,
                event(Event::WorldChanged {
                    facts: (0..t % 5 + 1).map(|k| fact(t + k)).collect(),
                    reset: false,
                }),
            );
        }
        if t % episode != 0 || t == ticks {
            continue;
        }
        // A failure resolved as a session records it: the question, the answer, the
        // proposal approved, the grown tree run again from a reset world.
        usage.calls += 1;
        usage.prompt_tokens += 900;
        usage.completion_tokens += 40;
        let episode = failure_resolved(&call, action, &path, fact(t), usage);
        for step in episode {
            ms += 100;
            push(ms, step);
        }
        tree = Arc::new((*tree).clone());
        push(
            ms,
            event(Event::TreeChanged {
                tree: tree.clone(),
                new_nodes: Vec::new(),
                learned: Vec::new(),
                why: "repaired".into(),
            }),
        );
        push(
            ms,
            event(Event::WorldChanged {
                facts: vec![fact(0)],
                reset: true,
            }),
        );
        push(ms, Step::Command("run".into()));
        push(ms, event(Event::RunState { running: true }));
        ticker = Ticker::new();
    }
    push(ms, event(Event::RunState { running: false }));
    push(
        ms,
        event(Event::Success {
            ticks: u64::try_from(ticks).unwrap_or(u64::MAX),
            executor: None,
        }),
    );
    Ok(steps)
}

/// A failure of `call` (node `node` at `path`) resolved as a session records it: the
/// question, the answer, the proposal of `condition` approved, the tree repaired; `usage`
/// is the model's usage after the answer.
fn failure_resolved(
    call: &ActionCall,
    node: NodeId,
    path: &[usize],
    condition: Condition,
    usage: UsageTotals,
) -> [Step; 9] {
    let event = Step::Event;
    [
        event(Event::ActionFailed {
            action: call.clone(),
            node,
            node_path: path.to_vec(),
            error: "No collision free path found".into(),
            executor: None,
        }),
        event(Event::RunState { running: false }),
        event(Event::Asking {
            what: crate::session::Question::Preconditions {
                action: call.clone(),
            },
        }),
        event(Event::Replied {
            attribution: "the benchmark".into(),
            prompt_tokens: 900,
            completion_tokens: 40,
            latency_ms: 800,
            text: "Conditions:\n~Held_0".into(),
        }),
        event(Event::Usage { totals: usage }),
        event(Event::Proposal {
            proposal: Proposal::Conditions {
                action: call.clone(),
                node,
                conditions: vec![condition],
            },
            reasoning: Some("the benchmark's".into()),
            author: "the benchmark".into(),
            evidence: None,
        }),
        Step::Command("approve".into()),
        event(Event::Approved),
        event(Event::Repaired {
            added_nodes: 0,
            valued_nodes: 0,
        }),
    ]
}

/// Ticks between two failures.
fn episode(ticks: usize) -> usize {
    (ticks / EPISODES).max(1)
}

/// A small generator of positions, the same in every run (SplitMix64).
struct Positions(u64);

impl Positions {
    fn next(&mut self, below: usize) -> usize {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        usize::try_from(z % u64::try_from(below.max(1)).unwrap_or(1)).unwrap_or(0)
    }
}

/// The total and the longest of some timed calls.
#[derive(Default)]
struct Timer {
    total: Duration,
    max: Duration,
}

impl Timer {
    fn time<T>(&mut self, f: impl FnOnce() -> T) {
        let started = Instant::now();
        let out = f();
        let took = started.elapsed();
        std::hint::black_box(out);
        self.total += took;
        self.max = self.max.max(took);
    }
}

/// Seek to `sizes.seeks` random steps of a synthetic recording over `scenario`.
pub fn seek_times(scenario: &Path, sizes: Sizes) -> Result<SeekTimes, BenchError> {
    let scenario = Scenario::load(scenario)
        .map_err(|e| BenchError::Setup(format!("{}: {e}", scenario.display())))?;
    let steps = synthetic(sizes.nodes, sizes.ticks)?;
    let nodes = steps
        .iter()
        .find_map(|(_, s)| match s {
            Step::Event(Event::TreeChanged { tree, .. }) => Some(tree.len()),
            _ => None,
        })
        .unwrap_or(0);
    let count = steps.len();
    let player = Player::new(
        steps,
        Arc::new(scenario),
        Info::default(),
        KeyBindings::default(),
        Theme::default(),
    );
    let mut positions = Positions(0x5eed);
    let seeks = sizes.seeks.max(1);
    let (mut seek, mut shown, mut every) = (Timer::default(), Timer::default(), Timer::default());
    let mut fed = 0usize;
    let mut terminal = ratatui::Terminal::new(ratatui::backend::TestBackend::new(120, 40))
        .map_err(|e| BenchError::Setup(format!("a test terminal: {e}")))?;
    for _ in 0..seeks {
        let p = positions.next(count + 1);
        fed += player.fed(p);
        seek.time(|| player.seek(p));
        shown.time(|| {
            let mut app = player.seek(p);
            // A draw into memory does not fail; what it would say is not what is measured.
            let _ = terminal.draw(|f| crate::tui::ui::draw(f, &mut app));
            app
        });
        // Back to back, the same position without leaving any step out.
        every.time(|| {
            let mut app = player.fresh();
            for i in 0..p {
                player.apply(&mut app, i);
            }
            player.finish(&mut app, p);
            app
        });
    }
    let n = u32::try_from(seeks).unwrap_or(u32::MAX);
    Ok(SeekTimes {
        nodes,
        ticks: sizes.ticks,
        steps: count,
        seeks,
        mean: seek.total / n,
        max: seek.max,
        shown_mean: shown.total / n,
        shown_max: shown.max,
        every_step_mean: every.total / n,
        every_step_max: every.max,
        fed: fed as f64 / seeks as f64,
    })
}

/// The table's rows: the mean and the slowest seek, each against the target of 50 ms,
/// beside the same positions reached by feeding every step.
pub fn rows(t: &SeekTimes) -> Vec<Row> {
    let note = format!(
        "{} steps ({} ticks, a {}-node tree, a failure, a model call and a repair every {} ticks); {} seeks to random steps; {:.0} steps fed per seek on average",
        t.steps,
        t.ticks,
        t.nodes,
        episode(t.ticks),
        t.seeks,
        t.fed
    );
    let ms = |d: Duration| d.as_secs_f64() * 1000.0;
    let row = |measure: &str, value: Duration, every_step: Duration| Row {
        part: "replay".into(),
        measure: measure.into(),
        unit: "ms".into(),
        better: Better::Lower,
        betr: ms(value),
        anchor: Some(("every step fed from the start".into(), ms(every_step))),
        target: Some(Target::AtMost(50.0)),
        note: note.clone(),
    };
    vec![
        row(
            "seek to a random step of a recording, mean",
            t.mean,
            t.every_step_mean,
        ),
        row(
            "seek to a random step of a recording, slowest",
            t.max,
            t.every_step_max,
        ),
        Row {
            anchor: None,
            ..row(
                "seek and draw the screen (120×40), slowest",
                t.shown_max,
                Duration::ZERO,
            )
        },
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_synthetic_session_has_its_ticks_failures_and_model_calls() -> Result<(), BenchError> {
        let steps = synthetic(100, 2_000)?;
        let count = |f: fn(&Event) -> bool| {
            steps
                .iter()
                .filter(|(_, s)| matches!(s, Step::Event(e) if f(e)))
                .count()
        };
        // A failure every 200 ticks but at the end, which succeeds.
        assert_eq!(count(|e| matches!(e, Event::Ticked { .. })), 2_000);
        assert_eq!(count(|e| matches!(e, Event::ActionFailed { .. })), 9);
        assert_eq!(count(|e| matches!(e, Event::Asking { .. })), 9);
        assert_eq!(count(|e| matches!(e, Event::TreeChanged { .. })), 10);
        assert_eq!(count(|e| matches!(e, Event::Success { .. })), 1);
        // The times only grow.
        assert!(steps.windows(2).all(|w| w[0].0 <= w[1].0));
        Ok(())
    }
}
