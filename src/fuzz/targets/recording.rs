//! Session recordings: the file (`record::file::parse`, what `record::read` does with a
//! file's text) and its entries decoded into session events over the recorded scenario
//! (`record::Decoder`), then re-simulated in a symbolic world (`Resimulation`).
//!
//! Properties: a line that does not read is an error naming a line after the header,
//! except a cut last line, which is left out and named; the header and every entry
//! written again read back the same; an event decoded from an entry is encoded
//! (`Encoder`) to an entry that decodes and encodes to itself again; a decoding error
//! names the entry's line.

use crate::fuzz::Material;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::{Rng, Target, Violation, ensure, strings, text_of};
use crate::bt::{self, NodeKind};
use crate::fuzz::Corpus;
use crate::fuzz::mutate::random_char;
use crate::llm::usage::UsageTotals;
use crate::record::{
    Decoder, Encoder, Entry, FORMAT, Header, RecordError, Recorded, RecordedProposal, Replay,
    Resimulation, Step, VERSION,
};
use crate::scenario::Scenario;

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
                    "{\"event\":\"tick\",",
                    "{\"event\":\"tree\",\"text\":\"sequence\\n  Sweep!\\n\",\"new_nodes\":[0,1],\"why\":\"\"}",
                    "{\"event\":\"approved\"}",
                    "\"statuses\":\"",
                    "\"root\":\"",
                    "\"node\":",
                    "\"visited\":[",
                    "\"failures\":[[",
                    "\"forced\":[[0,\"S\"]]",
                    "\"type\":\"conditions\"",
                    "\"type\":\"value\"",
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

    fn decode(
        &self,
        rec: &crate::record::Recording,
        scenario: &Arc<Scenario>,
    ) -> Result<(), Violation> {
        let (mut first, mut again) = (
            Decoder::new(scenario.clone()),
            Decoder::new(scenario.clone()),
        );
        let (mut encoder, mut encoder_again) = (Encoder::new(), Encoder::new());
        let mut steps = Vec::new();
        for (line, entry) in rec.entries.iter().take(DECODED_AT_MOST) {
            let Entry::Event { event, ms } = entry else {
                continue;
            };
            let decoded = match first.decode(event, *line) {
                Ok(e) => e,
                Err(e) => {
                    return ensure(
                        matches!(e, RecordError::Decode { line: l, .. } if l == *line),
                        "a decoding error names the entry's line",
                        || format!("line {line}: {e}"),
                    );
                }
            };
            if let Some(encoded) = encoder.encode(&decoded) {
                let back = again.decode(&encoded, *line);
                let Ok(back) = back else {
                    return ensure(false, "a decoded event encoded again decodes", || {
                        format!("{event:?} encoded as {encoded:?}: {back:?}")
                    });
                };
                let twice = encoder_again.encode(&back);
                ensure(
                    twice.as_ref() == Some(&encoded),
                    "a decoded event encodes to an entry that decodes and encodes the same",
                    || format!("{event:?} encoded as {encoded:?}, then {twice:?}"),
                )?;
            }
            steps.push((*ms, Step::Event(decoded)));
        }
        if scenario.world_kind == "symbolic" {
            let replay = Replay {
                path: PathBuf::from("fuzz.jsonl"),
                header: rec.header.clone(),
                scenario: scenario.clone(),
                steps: Vec::new(),
                cut_at: None,
            };
            let mut sim = Resimulation::new(&replay);
            for (_, step) in &steps {
                if let Step::Event(e) = step {
                    let _ = sim.follow(e);
                }
            }
        }
        Ok(())
    }
}

/// A recording of a session on `scene`: its planned tree, ticks, a failure, a proposal,
/// and the other entries, with random values where the format allows any.
fn recording(rng: &mut Rng, scene: &(String, Arc<Scenario>, String)) -> String {
    let (rel, scenario, tree_text) = scene;
    let header = Header {
        format: FORMAT.into(),
        version: VERSION,
        scenario: PathBuf::from(rel),
        name: scenario.name.clone(),
        variant: None,
        betr: "0.1.0".into(),
        started: "2026-05-01T09:30:00Z".into(),
    };
    let tree = bt::parse(tree_text).ok();
    let nodes = tree.as_ref().map_or(1, bt::Tree::len);
    let action = tree.as_ref().and_then(|t| {
        let order = t.preorder();
        order
            .iter()
            .enumerate()
            .find_map(|(i, id)| match t.kind(*id) {
                Ok(NodeKind::Action(a)) => Some((i, a.to_string())),
                _ => None,
            })
    });
    let (node, action) = action.unwrap_or((0, "Sweep".into()));
    let goal = scenario
        .goal
        .as_ref()
        .map(ToString::to_string)
        .unwrap_or_default();
    let letters = ['-', 'R', 'S', 'F', 'H'];
    let mut events = vec![
        Recorded::Tree {
            text: tree_text.clone(),
            new_nodes: (0..nodes).collect(),
            why: "planned".into(),
        },
        Recorded::Goal {
            goal: goal.clone(),
            reasoning: Some("because".into()),
            matches_expected: Some(true),
            author: "model".into(),
        },
    ];
    for _ in 0..1 + rng.small(6) {
        let event = match rng.below(12) {
            0..=2 => Recorded::Tick {
                tick: rng.below(100) as u64,
                root: *rng.pick(&['R', 'S', 'F']).unwrap_or(&'R'),
                statuses: (0..nodes)
                    .map(|_| *rng.pick(&letters).unwrap_or(&'-'))
                    .collect(),
                visited: (0..rng.small(nodes))
                    .map(|_| rng.below(nodes + 1))
                    .collect(),
                failures: vec![(node, "No collision free path found".into())],
                completed: vec![],
                halted: vec![rng.below(nodes)],
                forced: vec![],
            },
            3 => Recorded::ActionFailed {
                action: action.clone(),
                node,
                node_path: "0.1".into(),
                error: "it failed".into(),
            },
            4 => Recorded::Proposal {
                proposal: RecordedProposal::Conditions {
                    action: action.clone(),
                    node,
                    conditions: vec![goal.clone()],
                },
                reasoning: None,
                author: "model".into(),
                evidence: None,
            },
            5 => Recorded::Proposal {
                proposal: RecordedProposal::Value {
                    skill: "grasp".into(),
                    object: "egg".into(),
                    param: "force".into(),
                    value: format!("{}.{} N", rng.below(100), rng.below(10)),
                },
                reasoning: Some((0..rng.small(20)).map(|_| random_char(rng)).collect()),
                author: "model".into(),
                evidence: Some(crate::session::Evidence {
                    findings: vec![(0..rng.small(20)).map(|_| random_char(rng)).collect()],
                    objects: vec!["egg".into()],
                    doubt: None,
                }),
            },
            6 => Recorded::WorldChanged {
                facts: vec![goal.clone()],
                reset: rng.chance(50),
            },
            7 => Recorded::Forced {
                forced: vec![(
                    rng.below(nodes),
                    *rng.pick(&['S', 'F', 'R', 'x']).unwrap_or(&'S'),
                )],
            },
            8 => Recorded::Breakpoints {
                nodes: vec![rng.below(nodes + 1)],
                on_failure: rng.chance(50),
            },
            9 => Recorded::BreakpointHit {
                node: rng.below(nodes),
                node_path: "0".into(),
                tick: 3,
                on_failure: rng.chance(50),
            },
            10 => Recorded::Usage {
                totals: UsageTotals::default(),
            },
            _ => rng
                .pick(&[
                    Recorded::Approved,
                    Recorded::Rejected,
                    Recorded::Success { ticks: 4 },
                ])
                .cloned()
                .unwrap_or(Recorded::Approved),
        };
        events.push(event);
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
        for (line, entry) in &rec.entries {
            let written = serde_json::to_string(entry).ok();
            let back: Option<Entry> = written
                .as_deref()
                .and_then(|w| serde_json::from_str(w).ok());
            ensure(
                back.as_ref() == Some(entry),
                "a recording's entry written again reads back the same",
                || format!("line {line}: {entry:?} wrote {written:?}"),
            )?;
        }
        let Some(scene) = self
            .scenes
            .iter()
            .find(|(rel, ..)| rec.header.scenario == Path::new(rel))
            .or_else(|| self.scenes.first())
        else {
            return Ok(());
        };
        self.decode(&rec, &scene.1)
    }
}
