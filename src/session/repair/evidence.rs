//! What betr itself established about a failure before a change for it is offered: the
//! failure, what stood in the way, the conditions tried in simulation and which fixed it,
//! what the changes tried before did, and what the offered change did in simulation. A
//! person approves on this evidence; the model's reasoning comes after it, labelled as the
//! model's, and is checked against it: a reasoning that states a condition of the scene
//! the facts at the failure contradict, names as missing a condition that holds or the
//! opposite of its own proposal, names none of the failure's objects, or blames objects
//! while the simulation found others in the way, is doubtful and never shown as the reason.

use crate::domain::{ANY_OBJECT, Atom, Condition, Object, Vocabulary};
use crate::reading::claims::claims;

use super::super::types::Shortlist;
use super::super::types::{Evidence, Proposal};
use super::ask::Tried;
use super::screen::{FailureAt, Verdict};

/// What went into a question about a failure and what came out of it.
pub struct Found<'a> {
    pub failure: &'a FailureAt,
    /// The execution world's facts when the action failed.
    pub facts: &'a [Condition],
    /// The conditions tried in simulation before the model was asked, if they were.
    pub shortlist: Option<&'a Shortlist>,
    /// Changes tried for this failure before, that did not fix it.
    pub tried: &'a [Tried],
    pub proposal: &'a Proposal,
    /// What the offered change did in simulation, when it was tried there.
    pub verdict: Option<Verdict>,
}

impl Evidence {
    /// The evidence of `found`, with `reasoning` (the model's, if any) checked against it
    /// and against the scene's `vocabulary`.
    pub fn of(found: &Found<'_>, reasoning: Option<&str>, vocabulary: &Vocabulary) -> Evidence {
        let scene = &vocabulary.objects;
        let failure = found.failure;
        let mut findings = vec![format!("{}! failed: {}", failure.action, failure.error)];
        let mut objects: Vec<String> = failure.action.args.clone();
        let error = failure.error.to_lowercase();
        for o in scene {
            if names(&error, o) {
                push_new(&mut objects, &o.name);
            }
        }
        let in_the_way = in_the_way(found);
        let mut blockers: Vec<String> = Vec::new();
        if !in_the_way.is_empty() {
            let facts: Vec<String> = in_the_way.iter().map(ToString::to_string).collect();
            findings.push(format!("in the way: {} (true now)", facts.join(", ")));
            for atom in &in_the_way {
                for a in &atom.args {
                    if !failure.action.args.contains(a) {
                        push_new(&mut blockers, a);
                    }
                    push_new(&mut objects, a);
                }
            }
        }
        if let Some(list) = found.shortlist {
            findings.push(list.finding());
        }
        for t in found.tried {
            findings.push(format!("proposed before and turned down: {t}"));
        }
        if let Proposal::Conditions { conditions, .. } = found.proposal {
            for c in conditions {
                for a in &c.atom.args {
                    if a != ANY_OBJECT {
                        push_new(&mut objects, a);
                    }
                }
            }
        }
        findings.push(match found.verdict {
            Some(v) => format!("this change, tried in simulation: {}", verdict_text(v)),
            None => "this change was not tried in simulation before it was offered".into(),
        });
        let doubt = reasoning.and_then(|r| {
            contradicted(r, found, vocabulary).or_else(|| doubt(r, &objects, &blockers, scene))
        });
        Evidence {
            findings,
            objects,
            doubt,
        }
    }
}

/// What a verdict says, in words.
fn verdict_text(v: Verdict) -> &'static str {
    match v {
        Verdict::Succeeds => "the whole task then succeeds",
        Verdict::MovesOn => {
            "the failure is gone; the tree then stops at a later action it had before"
        }
        Verdict::FailsItself => "the failure is gone; an action the change brings in then fails",
    }
}

/// The facts true at the failure that a fix found in simulation makes false: a negated
/// condition of the shortlist or of the change, with "any object" standing for any.
fn in_the_way(found: &Found<'_>) -> Vec<Atom> {
    let mut negations: Vec<&Condition> = Vec::new();
    if let Some(list) = found.shortlist {
        negations.extend(list.fixes.iter().filter(|c| c.negated));
    }
    if let Proposal::Conditions { conditions, .. } = found.proposal {
        negations.extend(conditions.iter().filter(|c| c.negated));
    }
    let mut atoms: Vec<Atom> = Vec::new();
    for fact in found.facts.iter().filter(|f| !f.negated) {
        if negations.iter().any(|n| covers(&n.atom, &fact.atom)) && !atoms.contains(&fact.atom) {
            atoms.push(fact.atom.clone());
        }
    }
    atoms
}

/// Whether `pattern` (which may say "any object") stands for `atom`.
fn covers(pattern: &Atom, atom: &Atom) -> bool {
    pattern.predicate == atom.predicate
        && pattern.args.len() == atom.args.len()
        && pattern
            .args
            .iter()
            .zip(&atom.args)
            .all(|(p, a)| p == ANY_OBJECT || p == a)
}

/// The first claim of `reasoning` about the scene's conditions that the facts at the
/// failure or the proposal contradict, quoted with what contradicts it: a condition said to
/// hold (or not) that does not (or does); one named as missing that holds already; one
/// said to be needed whose opposite is proposed.
fn contradicted(reasoning: &str, found: &Found<'_>, vocabulary: &Vocabulary) -> Option<String> {
    let true_now = |atom: &Atom| found.facts.iter().any(|f| !f.negated && f.atom == *atom);
    let proposed: &[Condition] = match found.proposal {
        Proposal::Conditions { conditions, .. } => conditions,
        _ => &[],
    };
    for claim in claims(reasoning, vocabulary) {
        let atom = &claim.condition.atom;
        if vocabulary.check_atom(atom).is_err() {
            continue;
        }
        let holds = true_now(atom) != claim.condition.negated;
        let said = &claim.said;
        if !claim.needed && !holds {
            let truth = if claim.condition.negated {
                "true"
            } else {
                "false"
            };
            return Some(format!(
                "it says \"{said}\", but {atom} is {truth} at the failure"
            ));
        }
        if claim.as_missing && holds {
            return Some(format!(
                "it says \"{said}\", but {} holds already at the failure",
                claim.condition
            ));
        }
        let opposite = proposed
            .iter()
            .any(|p| p.negated != claim.condition.negated && covers(&p.atom, atom));
        if claim.needed && opposite {
            return Some(format!(
                "it says \"{said}\", the opposite of its own proposal"
            ));
        }
    }
    None
}

/// Why `reasoning` is not to be taken as the reason: it names none of `objects` (the
/// failure's); or the simulation found `blockers` in the way and the reasoning names none
/// of them but blames other objects of the scene; or it stops mid-sentence.
pub fn doubt(
    reasoning: &str,
    objects: &[String],
    blockers: &[String],
    scene: &[Object],
) -> Option<String> {
    let text = reasoning.to_lowercase();
    let named: Vec<&Object> = scene.iter().filter(|o| names(&text, o)).collect();
    let quoted = |list: &[&str]| {
        list.iter()
            .map(|o| format!("\"{o}\""))
            .collect::<Vec<_>>()
            .join(", ")
    };
    if !named.iter().any(|o| objects.contains(&o.name)) {
        let objects: Vec<&str> = objects.iter().map(String::as_str).collect();
        return Some(format!(
            "it names none of the failure's objects ({})",
            quoted(&objects)
        ));
    }
    let others: Vec<&str> = named
        .iter()
        .filter(|o| !objects.contains(&o.name))
        .map(|o| o.name.as_str())
        .collect();
    if !blockers.is_empty() && !named.iter().any(|o| blockers.contains(&o.name)) {
        let blockers: Vec<&str> = blockers.iter().map(String::as_str).collect();
        if !others.is_empty() {
            return Some(format!(
                "it blames {}, while the simulation found {} in the way",
                quoted(&others),
                quoted(&blockers)
            ));
        }
    }
    let trimmed = reasoning.trim_end();
    if !trimmed.is_empty() && !trimmed.ends_with(['.', '!', '?', ')', '"']) {
        return Some("it stops mid-sentence".into());
    }
    None
}

/// Whether lower-cased `text` names `object` (its name or what it is called), as whole
/// words (a plural's `s` allowed).
fn names(text: &str, object: &Object) -> bool {
    std::iter::once(&object.name)
        .chain(&object.called)
        .any(|n| has_words(text, &n.to_lowercase()))
}

fn has_words(text: &str, words: &str) -> bool {
    if words.is_empty() {
        return false;
    }
    let boundary = |c: Option<char>| c.is_none_or(|c| !c.is_alphanumeric());
    text.match_indices(words).any(|(at, _)| {
        let before = text[..at].chars().next_back();
        let rest = &text[at + words.len()..];
        let mut after = rest.chars();
        let next = after.next();
        boundary(before) && (boundary(next) || (next == Some('s') && boundary(after.next())))
    })
}

fn push_new(list: &mut Vec<String>, name: &str) {
    if !list.iter().any(|n| n == name) {
        list.push(name.to_string());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bt::NodeId;
    use crate::domain::ActionCall;

    /// Scenario 1's vocabulary: the table and three cubes.
    fn vocabulary() -> Vocabulary {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenarios/cell/red_on_blue.toml");
        crate::scenario::Scenario::load(&path)
            .unwrap()
            .domain
            .vocabulary
    }

    fn condition(text: &str) -> Condition {
        Condition::parse(text).unwrap()
    }

    /// Scenario 1's failure: the grasp of the blue cube, with the red cube on it.
    fn evidence_of(reasoning: &str) -> Evidence {
        let failure = FailureAt {
            node: NodeId(7),
            action: ActionCall::parse("grasp \"blue cube\"").unwrap(),
            error: "No collision free path found".into(),
        };
        let facts = [
            condition("\"blue cube\" on \"table\""),
            condition("\"green cube\" on \"table\""),
            condition("\"red cube\" on \"blue cube\""),
            condition("\"blue cube\" near robot"),
        ];
        let fixes = vec![
            condition("~\"any object\" on \"blue cube\""),
            condition("~\"red cube\" on \"blue cube\""),
        ];
        let list = Shortlist {
            fixes: fixes.clone(),
            tried: 19,
            objects: vec!["blue cube".into()],
            refused: 0,
            breaking: Vec::new(),
        };
        let proposal = Proposal::Conditions {
            action: failure.action.clone(),
            node: failure.node,
            conditions: vec![fixes[0].clone()],
        };
        let found = Found {
            failure: &failure,
            facts: &facts,
            shortlist: Some(&list),
            tried: &[],
            proposal: &proposal,
            verdict: Some(Verdict::Succeeds),
        };
        Evidence::of(&found, Some(reasoning), &vocabulary())
    }

    #[test]
    fn the_findings_start_with_the_failure_and_say_what_was_in_the_way() {
        let e = evidence_of("Something lies on top of the blue cube.");
        assert_eq!(
            e.findings,
            [
                "grasp \"blue cube\"! failed: No collision free path found",
                "in the way: \"red cube\" on \"blue cube\" (true now)",
                "tried 19 condition(s) about \"blue cube\" in simulation: 2 fix the failure (~\"any object\" on \"blue cube\", ~\"red cube\" on \"blue cube\")",
                "this change, tried in simulation: the whole task then succeeds",
            ]
        );
        assert_eq!(e.objects, ["blue cube", "red cube"]);
        assert_eq!(e.doubt, None);
    }

    #[test]
    fn a_reasoning_naming_none_of_the_failures_objects_is_doubtful() {
        let e = evidence_of("The gripper needs room to close.");
        assert_eq!(
            e.doubt.as_deref(),
            Some("it names none of the failure's objects (\"blue cube\", \"red cube\")")
        );
    }

    #[test]
    fn a_reasoning_blaming_another_object_than_the_one_in_the_way_is_doubtful() {
        let e = evidence_of(
            "The blue cube was resting on the table, and the green cube was also resting on the table, which blocked the path.",
        );
        assert_eq!(
            e.doubt.as_deref(),
            Some(
                "it blames \"table\", \"green cube\", while the simulation found \"red cube\" in the way"
            )
        );
        // Naming what the simulation found in the way is not doubtful.
        let e = evidence_of("The red cube on the blue cubes blocks the gripper.");
        assert_eq!(e.doubt, None);
    }

    #[test]
    fn a_reasoning_cut_mid_sentence_is_doubtful() {
        let e = evidence_of("The red cube is on the blue cube and the");
        assert_eq!(e.doubt.as_deref(), Some("it stops mid-sentence"));
    }

    /// The claims the engineer found unmarked: each contradicted, quoted.
    #[test]
    fn a_claim_the_facts_or_the_proposal_contradict_is_doubtful_with_the_claim_quoted() {
        let e = evidence_of("The blue cube was not near the robot, so the arm cannot reach it.");
        assert_eq!(
            e.doubt.as_deref(),
            Some(
                "it says \"The blue cube was not near the robot\", but \"blue cube\" near robot is true at the failure"
            )
        );
        let e = evidence_of("The missing condition is that the red cube must not be on the table.");
        assert_eq!(
            e.doubt.as_deref(),
            Some(
                "it says \"The missing condition is that the red cube must not be on the table\", but ~\"red cube\" on \"table\" holds already at the failure"
            )
        );
        let e = evidence_of("The green cube is on the blue cube.");
        assert!(
            e.doubt
                .as_deref()
                .is_some_and(|d| d.contains("\"green cube\" on \"blue cube\" is false")),
            "{:?}",
            e.doubt
        );
        let e = evidence_of("The blue cube must have something on it: nothing may be moved.");
        assert_eq!(e.doubt, None, "no claim read, none contradicted");
        // True claims, and a need the proposal answers, leave the reasoning alone.
        let e = evidence_of(
            "The red cube is on the blue cube. The blue cube needs to have nothing on it.",
        );
        assert_eq!(e.doubt, None);
    }

    #[test]
    fn names_are_matched_as_whole_words() {
        assert!(has_words("the red cubes are", "red cube"));
        assert!(!has_words("the red cubed", "red cube"));
        assert!(!has_words("hired cube", "red cube"));
    }
}
