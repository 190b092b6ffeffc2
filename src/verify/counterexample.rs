//! Counterexamples: the sequence of states, ticks and actions that leads from the initial
//! state to a violation, rebuilt from the explored graph and printable as a numbered list
//! (what each step did and which facts it changed).

use std::fmt;

use super::abstraction::{Model, State};
use super::explore::Edge;
use crate::bt::path_text;
use crate::bt::{NodeId, Outcome};
use crate::domain::{ActionCall, Atom, Condition};

/// An action node as a counterexample names it.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ActionRef {
    pub node: NodeId,
    pub path: Vec<usize>,
    pub call: ActionCall,
}

/// What happened in one step.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Event {
    /// One tick of the tree (numbered from 1 among the ticks of the counterexample).
    Tick {
        tick: u64,
        root: Outcome,
        executed: Option<ActionRef>,
        failed: Vec<ActionRef>,
        /// Actions that started while a declared precondition did not hold.
        unmet: Vec<(ActionRef, Condition)>,
    },
    /// A disturbance between ticks.
    Disturbance {
        description: String,
        grounding: String,
    },
}

/// One step and the facts it changed.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Step {
    pub event: Event,
    pub added: Vec<Atom>,
    pub removed: Vec<Atom>,
    /// Every relevant fact true after the step.
    pub state: Vec<Atom>,
}

/// A run from the initial state to a violation.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Counterexample {
    /// Relevant facts true in the initial state.
    pub initial: Vec<Atom>,
    pub steps: Vec<Step>,
    /// For runs that repeat forever: the step where the repeated part starts.
    pub loop_from: Option<usize>,
    /// What is wrong at the end, in one line.
    pub violation: String,
}

impl Counterexample {
    /// Rebuild the steps of `transitions` (each from a state by an edge) from the model.
    pub fn build(
        model: &Model,
        states: &[State],
        transitions: &[(u32, Edge)],
        loop_from: Option<usize>,
        violation: String,
    ) -> Counterexample {
        let fact_list = |s: &State| model.facts(s).into_iter().cloned().collect::<Vec<_>>();
        let initial = fact_list(&model.initial);
        let mut steps = Vec::new();
        let mut tick = 0;
        for &(from, edge) in transitions {
            let Some(before) = states.get(from as usize) else {
                continue;
            };
            let (event, after) = match edge {
                Edge::Tick { fail } => {
                    tick += 1;
                    let r = model.tick(before, usize::from(fail));
                    let aref = |a: usize| {
                        let act = &model.actions[a];
                        ActionRef {
                            node: act.node,
                            path: act.path.clone(),
                            call: act.call.clone(),
                        }
                    };
                    let after = match r.executed {
                        Some(a) => {
                            model.apply(before, &model.actions[a].add, &model.actions[a].del)
                        }
                        None => before.clone(),
                    };
                    let event = Event::Tick {
                        tick,
                        root: r.root,
                        executed: r.executed.map(aref),
                        failed: r.failed.iter().map(|&a| aref(a)).collect(),
                        unmet: r
                            .unmet
                            .iter()
                            .map(|&(a, c)| (aref(a), model.conditions[c].condition.clone()))
                            .collect(),
                    };
                    (event, after)
                }
                Edge::Disturb(j) => {
                    let Some(d) = model.disturbances.get(j as usize) else {
                        continue;
                    };
                    (
                        Event::Disturbance {
                            description: d.description.clone(),
                            grounding: d.grounding.clone(),
                        },
                        model.apply(before, &d.add, &d.del),
                    )
                }
            };
            let was = fact_list(before);
            let now = fact_list(&after);
            steps.push(Step {
                event,
                added: now.iter().filter(|a| !was.contains(a)).cloned().collect(),
                removed: was.iter().filter(|a| !now.contains(a)).cloned().collect(),
                state: now,
            });
        }
        Counterexample {
            initial,
            steps,
            loop_from,
            violation,
        }
    }

    /// The relevant facts of the last state.
    pub fn last_state(&self) -> &[Atom] {
        self.steps.last().map_or(&self.initial, |s| &s.state)
    }
}

fn list(atoms: &[Atom]) -> String {
    if atoms.is_empty() {
        "(none)".to_string()
    } else {
        atoms
            .iter()
            .map(ToString::to_string)
            .collect::<Vec<_>>()
            .join(", ")
    }
}

impl fmt::Display for ActionRef {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}! (node {})", self.call, path_text(&self.path))
    }
}

impl fmt::Display for Counterexample {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "0. initial state: {}", list(&self.initial))?;
        for (i, step) in self.steps.iter().enumerate() {
            if self.loop_from == Some(i) {
                writeln!(f, "   -- from here the run repeats forever --")?;
            }
            let what = match &step.event {
                Event::Tick {
                    tick,
                    root,
                    executed,
                    failed,
                    unmet,
                } => {
                    let mut s = format!("tick {tick}: ");
                    for a in failed {
                        s.push_str(&format!("{a} fails (state unchanged); "));
                    }
                    match executed {
                        Some(a) => s.push_str(&format!("{a} runs")),
                        None => s.push_str(&format!("no action runs, the root returns {root}")),
                    }
                    for (a, c) in unmet {
                        s.push_str(&format!(
                            "; {} starts although its precondition {c} does not hold",
                            a.call
                        ));
                    }
                    s
                }
                Event::Disturbance {
                    description,
                    grounding,
                } if grounding.is_empty() => format!("disturbance: {description}"),
                Event::Disturbance {
                    description,
                    grounding,
                } => format!("disturbance: {description} ({grounding})"),
            };
            let mut changes: Vec<String> = step.added.iter().map(|a| format!("+{a}")).collect();
            changes.extend(step.removed.iter().map(|a| format!("-{a}")));
            if changes.is_empty() {
                writeln!(f, "{}. {what}", i + 1)?;
            } else {
                writeln!(f, "{}. {what}  [{}]", i + 1, changes.join(" "))?;
            }
        }
        writeln!(f, "   state: {}", list(self.last_state()))?;
        write!(f, "   violation: {}", self.violation)
    }
}
