//! Session recordings: the file (`record::file::parse`, what `record::read` does with a
//! file's text), its entries read back as session events, then re-simulated in a symbolic
//! world (`Resimulation`).
//!
//! Properties: a line that does not read is an error naming a line after the header,
//! except a cut last line, which is left out and named; the header and every entry
//! written again read back the same, and write the same text again.

use crate::fuzz::Material;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::{Rng, Target, Violation, ensure, strings, text_of};
use crate::bt::{self, NodeId, NodeKind, Status, TickRecord};
use crate::domain::Condition;
use crate::fuzz::Corpus;
use crate::fuzz::mutate::random_char;
use crate::llm::usage::UsageTotals;
use crate::record::{Entry, FORMAT, Header, RecordError, Resimulation, Source, VERSION};
use crate::scenario::Scenario;
use crate::session::{BreakReason, Event, Proposal};

/// Entries past this many are not decoded (a long recording is many short ones).
const DECODED_AT_MOST: usize = 200;

pub struct RecordingTarget {
    material: Material,
    /// Scenario path (relative), scenario, planned tree text.
    scenes: Vec<(String, Arc<Scenario>, String)>,
}

impl RecordingTarget {
    pub fn new(corpus: &Corpus) -> RecordingTarget {
        let scenes: Vec<(String, Arc<Scenario>, String)> = corpus
            .scenarios
            .iter()
            .filter_map(|s| {
                let text = bt::to_text(s.planned.as_ref()?);
                Some((s.rel.clone(), s.scenario.clone(), text))
            })
            .collect();
        let seeds = (0..scenes.len() as u64)
            .map(|k| recording(&mut Rng::new(k), &scenes[k as usize]).into_bytes())
            .collect();
        RecordingTarget {
            material: Material {
                seeds,
                tokens: strings(&[
                    "{\"kind\":\"event\",\"ms\":1,\"event\":",
                    "{\"kind\":\"command\",\"ms\":1,\"command\":\"run\"}\n",
                    "{\"event\":\"ticked\",\"record\":",
                    "{\"event\":\"tree_changed\",\"tree\":{\"text\":\"sequence\\n  Sweep!\\n\",\"ids\":[0,1],\"capacity\":2},\"new_nodes\":[0,1],\"learned\":[],\"why\":\"\"}",
                    "{\"event\":\"approved\"}",
                    "\"statuses\":\"",
                    "\"root\":\"",
                    "\"node\":",
                    "\"visited\":[",
                    "\"failures\":[[",
                    "\"forced\":[[0,\"Success\"]]",
                    "{\"Conditions\":",
                    "{\"Value\":",
                    "RSFH-",
                    "18446744073709551615",
                    "18446744073709551616",
                    "\"version\":2",
                    "\\n",
                    "\\u0000",
                ]),
                brackets: super::pairs(&[("[", "]"), ("{\"a\":", "}")]),
            },
            scenes,
        }
    }

    /// Re-simulate the events of `rec` on `scenario` (a symbolic world's only).
    fn resimulate(&self, rec: &crate::record::Recording, scenario: &Arc<Scenario>) {
        if scenario.world_kind != "symbolic" {
            return;
        }
        let variant = match &rec.header.source {
            Source::Session { variant, .. } => variant.clone(),
            Source::Watched { .. } => return,
        };
        let mut sim = Resimulation::new(scenario.clone(), variant);
        for (_, entry) in rec.entries.iter().take(DECODED_AT_MOST) {
            if let Entry::Event { event, .. } = entry {
                let _ = sim.follow(event);
            }
        }
    }
}

/// A recording of a session on `scene`: its planned tree, ticks, a failure, a proposal,
/// and the other entries, with random values where the format allows any.
fn recording(rng: &mut Rng, scene: &(String, Arc<Scenario>, String)) -> String {
    let (rel, scenario, tree_text) = scene;
    let header = Header {
        format: FORMAT.into(),
        version: VERSION,
        source: Source::Session {
            scenario: PathBuf::from(rel),
            name: scenario.name.clone(),
            variant: None,
        },
        betr: "0.1.0".into(),
        started: "2026-05-01T09:30:00Z".into(),
    };
    let Ok(tree) = bt::parse(tree_text) else {
        return serde_json::to_string(&header).unwrap_or_default();
    };
    let order = tree.preorder();
    let (node, action) = order
        .iter()
        .find_map(|id| match tree.kind(*id) {
            Ok(NodeKind::Action(a)) => Some((*id, a.clone())),
            _ => None,
        })
        .unwrap_or((
            tree.root(),
            crate::domain::ActionCall::new("Sweep", [""; 0]),
        ));
    let goal = scenario.goal.clone();
    let fact: Option<Condition> = goal.as_ref().and_then(|g| match g {
        crate::goal::Formula::Atom(a) => Some(Condition {
            atom: a.clone(),
            negated: false,
        }),
        _ => None,
    });
    let mut events = vec![Event::TreeChanged {
        tree: Arc::new(tree.clone()),
        new_nodes: order.clone(),
        learned: Vec::new(),
        why: "planned".into(),
    }];
    if let Some(goal) = goal {
        events.push(Event::Goal {
            goal,
            reasoning: Some("because".into()),
            matches_expected: Some(true),
            author: "model".into(),
            first_answer: None,
            doubt: None,
        });
    }
    let near = Near {
        tree: &tree,
        node,
        action: &action,
        fact: fact.as_ref(),
    };
    for _ in 0..1 + rng.small(6) {
        events.push(random_event(rng, &near));
    }
    let mut lines = vec![serde_json::to_string(&header).unwrap_or_default()];
    for (ms, event) in events.into_iter().enumerate() {
        let entry = if rng.chance(15) {
            Entry::Command {
                ms: ms as u64,
                command: "approve".into(),
            }
        } else {
            Entry::Event {
                ms: ms as u64,
                event,
            }
        };
        lines.push(serde_json::to_string(&entry).unwrap_or_default());
    }
    let mut text = lines.join("\n");
    if rng.chance(80) {
        text.push('\n');
    }
    text
}

/// What the random events of a recording name: its tree, an action of it and a fact.
struct Near<'a> {
    tree: &'a bt::Tree,
    node: NodeId,
    action: &'a crate::domain::ActionCall,
    fact: Option<&'a Condition>,
}

/// One event about `near`, with random values where the format allows any (node ids
/// past the tree included).
fn random_event(rng: &mut Rng, near: &Near<'_>) -> Event {
    let statuses = [
        Status::Idle,
        Status::Running,
        Status::Success,
        Status::Failure,
    ];
    let (tree, node) = (near.tree, near.node);
    let any = |rng: &mut Rng| NodeId(rng.below(tree.capacity() + 1) as u32);
    let action = near.action;
    let fact = near.fact;
    match rng.below(12) {
        0..=2 => Event::Ticked {
            record: Arc::new(TickRecord {
                tick: rng.below(100) as u64,
                root: bt::Outcome::Running,
                statuses: (0..tree.capacity())
                    .map(|_| *rng.pick(&statuses).unwrap_or(&Status::Idle))
                    .collect(),
                visited: (0..rng.small(tree.len())).map(|_| any(rng)).collect(),
                halted: vec![any(rng)],
                failures: vec![(node, "No collision free path found".into())],
                completed: vec![],
                forced: vec![],
            }),
        },
        3 => Event::ActionFailed {
            action: action.clone(),
            node,
            node_path: tree.path(node).unwrap_or_default(),
            error: "it failed".into(),
            executor: (rng.below(2) == 0).then(|| "mujoco".to_string()),
        },
        4 => Event::Proposal {
            proposal: Proposal::Conditions {
                action: action.clone(),
                node,
                conditions: fact.into_iter().cloned().collect(),
            },
            reasoning: Some((0..rng.small(20)).map(|_| random_char(rng)).collect()),
            author: "model".into(),
            evidence: Some(Box::new(crate::session::Evidence {
                findings: vec![(0..rng.small(20)).map(|_| random_char(rng)).collect()],
                objects: vec!["egg".into()],
                doubt: None,
            })),
        },
        5 => Event::WorldChanged {
            facts: fact.into_iter().cloned().collect(),
            reset: rng.chance(50),
        },
        6 => Event::Forced {
            forced: vec![(any(rng), bt::Forced::Failure)],
        },
        7 => Event::Breakpoints {
            nodes: vec![any(rng)],
            on_failure: rng.chance(50),
        },
        8 => Event::BreakpointHit {
            node,
            node_path: tree.path(node).unwrap_or_default(),
            tick: 3,
            reason: BreakReason::Failure,
        },
        9 => Event::Usage {
            totals: UsageTotals::default(),
        },
        10 => Event::Diverged {
            executor: (0..rng.small(12)).map(|_| random_char(rng)).collect(),
            action: action.clone(),
            reality: (0..rng.small(40)).map(|_| random_char(rng)).collect(),
            predicted: None,
        },
        _ => Event::Success {
            ticks: 4,
            executor: None,
        },
    }
}

impl Target for RecordingTarget {
    fn name(&self) -> &'static str {
        "recording"
    }

    fn material(&self) -> &Material {
        &self.material
    }

    fn generate(&self, rng: &mut Rng) -> Vec<u8> {
        match rng.pick(&self.scenes) {
            Some(scene) => recording(rng, scene).into_bytes(),
            None => Vec::new(),
        }
    }

    fn check(&self, input: &[u8]) -> Result<(), Violation> {
        let text = text_of(input);
        let lines = text.split_inclusive('\n').count();
        let rec = match crate::record::file::parse(Path::new("fuzz.jsonl"), &text) {
            Ok(r) => r,
            Err(RecordError::Line { line, .. }) => {
                return ensure(
                    (2..=lines).contains(&line),
                    "a recording error names a line after the header",
                    || format!("line {line} of {lines}"),
                );
            }
            Err(_) => return Ok(()),
        };
        if let Some(cut) = rec.cut_at {
            ensure(
                cut == lines && !text.ends_with('\n'),
                "only a last line without a newline is left out as cut",
                || format!("cut at {cut} of {lines}"),
            )?;
        }
        let header = serde_json::to_string(&rec.header).ok();
        let back: Option<Header> = header.as_deref().and_then(|h| serde_json::from_str(h).ok());
        ensure(
            back.as_ref() == Some(&rec.header),
            "a recording's header written again reads back the same",
            || format!("{:?} wrote {header:?}", rec.header),
        )?;
        for (line, entry) in rec.entries.iter().take(DECODED_AT_MOST) {
            let written = serde_json::to_string(entry).ok();
            let back: Option<Entry> = written
                .as_deref()
                .and_then(|w| serde_json::from_str(w).ok());
            let again = back.as_ref().and_then(|b| serde_json::to_string(b).ok());
            ensure(
                written.is_some() && again == written,
                "a recording's entry written again reads back and writes the same",
                || format!("line {line}: {entry:?} wrote {written:?}, then {again:?}"),
            )?;
        }
        if let Some(scene) = self
            .scenes
            .iter()
            .find(|(rel, ..)| {
                matches!(&rec.header.source, Source::Session { scenario, .. } if scenario == Path::new(rel))
            })
            .or_else(|| self.scenes.first())
        {
            self.resimulate(&rec, &scene.1);
        }
        Ok(())
    }
}
