//! A first example pool made from the domain itself, for a scenario file that writes none.
//!
//! A user's new scenario usually has no worked examples, and a prompt without any shows
//! the model neither the answer format nor how the domain's words map to its conditions.
//! The made pool says plainly, in the scene's own words, goals its planner can reach from
//! the scene's first state: each condition of the vocabulary that does not hold yet (or its
//! opposite, where the scene lists words for it), with its objects called as the scene
//! calls them, the conditions taken in turn so every predicate shows; then two of them
//! joined by "and" and by "or" for the formula's shape. Made examples are marked as such,
//! and each written or kept example takes one made example's place.

use std::collections::{HashMap, HashSet};

use crate::domain::{Atom, Vocabulary};
use crate::goal::Formula;
use crate::planner::{Outcome, Planner};
use crate::scenario::{Example, ExampleSource, Scenario};

/// How many examples a domain's pool holds when made examples fill it.
pub const MADE_POOL: usize = 12;

/// How many undoings (a condition that holds asked to stop) a made pool shows.
const UNDOINGS: usize = 2;

/// How many conditions of one predicate are tried, at most, to find reachable ones.
const TRIED_PER_PREDICATE: usize = 8;

/// Fill `scenario`'s pool with made examples when it has no written ones, up to
/// [`MADE_POOL`] with its kept examples; made examples it held before are taken out first.
/// The number made.
pub fn fill(scenario: &mut Scenario) -> usize {
    scenario
        .examples
        .retain(|e| e.source != ExampleSource::Made);
    if scenario
        .examples
        .iter()
        .any(|e| e.source == ExampleSource::Written)
    {
        return 0;
    }
    let room = MADE_POOL.saturating_sub(scenario.examples.len());
    if room == 0 {
        return 0;
    }
    let made = made_pool(scenario, room);
    let count = made.len();
    scenario.examples.extend(made);
    count
}

/// At most `most` examples made from `scenario`'s domain (see the module); none when its
/// world cannot be built.
pub fn made_pool(scenario: &Scenario, most: usize) -> Vec<Example> {
    let Ok(world) = crate::world::load(scenario) else {
        return Vec::new();
    };
    let vocabulary = &scenario.domain.vocabulary;
    let planner = Planner::new(&scenario.domain);
    let reachable = |goal: &Formula| {
        planner
            .plan(&goal.to_dnf(), world.as_ref())
            .is_ok_and(|p| matches!(p.outcome, Outcome::Success | Outcome::ActionFailed { .. }))
    };
    // Every ground atom, formed once for all predicates, each with whether it holds now
    // (the scene's facts, computed once, as the prompt lists them).
    let ground = vocabulary.ground_atoms();
    let holding: HashSet<Atom> = world.facts().into_iter().map(|c| c.atom).collect();
    let mut untried: Vec<Vec<(Atom, bool)>> = vocabulary
        .predicates
        .iter()
        .map(|p| {
            atoms_of(&ground, &p.name)
                .map(|atom| {
                    let holds = holding.contains(&atom);
                    (atom, holds)
                })
                .collect()
        })
        .collect();
    // Room for the two joined examples when the pool is large enough to show them.
    let wanted_singles = if most >= 4 { most - 2 } else { most };
    let mut said_of: HashMap<String, usize> = HashMap::new();
    let mut singles: Vec<(Formula, String)> = Vec::new();
    // The predicates in turn, so each shows before any shows twice, room kept for
    // [`UNDOINGS`] undoings (`~`) after the first round; then more changes.
    let mut take_round = |undoing: bool, room: usize, singles: &mut Vec<(Formula, String)>| {
        let goal_count = singles.len() + room;
        for candidates in untried.iter_mut() {
            if singles.len() >= goal_count {
                break;
            }
            let Some(found) = next_single(candidates, undoing, &said_of, vocabulary, &reachable)
            else {
                continue;
            };
            for object in objects_of(&found.0) {
                *said_of.entry(object.clone()).or_default() += 1;
            }
            singles.push(found);
        }
    };
    take_round(false, wanted_singles.saturating_sub(UNDOINGS), &mut singles);
    take_round(
        true,
        UNDOINGS.min(wanted_singles - singles.len()),
        &mut singles,
    );
    let mut before = usize::MAX;
    while singles.len() < wanted_singles && singles.len() != before {
        before = singles.len();
        take_round(false, wanted_singles - singles.len(), &mut singles);
    }
    let mut out: Vec<Example> = singles.iter().map(|(g, said)| example(said, g)).collect();
    if most >= 4 {
        out.extend(joined(&singles, &reachable));
    }
    out.truncate(most);
    out
}

/// The next condition of one predicate to make an example of, taken out of `candidates`,
/// of the objects said least so far, that the scene can say and the planner can reach:
/// one asked to become true, or, when `undoing`, one that holds now asked to stop
/// holding, of objects the scene says how people call (not a stand-in such as the
/// `Nothing` of an empty gripper). At most [`TRIED_PER_PREDICATE`] are tried.
fn next_single(
    candidates: &mut Vec<(Atom, bool)>,
    undoing: bool,
    said_of: &HashMap<String, usize>,
    vocabulary: &Vocabulary,
    reachable: &dyn Fn(&Formula) -> bool,
) -> Option<(Formula, String)> {
    let used = |atom: &Atom| {
        atom.args
            .iter()
            .map(|a| said_of.get(a).copied().unwrap_or(0))
            .sum::<usize>()
    };
    let called = |atom: &Atom| {
        atom.args
            .iter()
            .all(|a| vocabulary.object(a).is_some_and(|o| !o.called.is_empty()))
    };
    let fits = |(atom, holds): &(Atom, bool)| *holds == undoing && (!undoing || called(atom));
    candidates.sort_by_key(|c| (!fits(c), used(&c.0)));
    for _ in 0..TRIED_PER_PREDICATE.min(candidates.len()) {
        if !candidates.first().is_some_and(fits) {
            break;
        }
        let (atom, holds) = candidates.remove(0);
        let Some(said) = plainly(&atom, !holds, vocabulary) else {
            continue;
        };
        let goal = if holds {
            Formula::Not(Box::new(Formula::Atom(atom)))
        } else {
            Formula::Atom(atom)
        };
        if reachable(&goal) {
            return Some((goal, said));
        }
    }
    None
}

/// Two of `singles` of different predicates and different objects, joined by "and" (when
/// the planner reaches both) and by "or": the shape of goals of several wishes.
fn joined(singles: &[(Formula, String)], reachable: &dyn Fn(&Formula) -> bool) -> Vec<Example> {
    let Some((a, said_a)) = singles.first() else {
        return Vec::new();
    };
    let Some((b, said_b)) = singles.iter().skip(1).find(|(b, _)| {
        predicate_of(b) != predicate_of(a)
            && objects_of(a).iter().all(|o| !objects_of(b).contains(o))
    }) else {
        return Vec::new();
    };
    let mut made = Vec::new();
    let both = Formula::and(vec![a.clone(), b.clone()]);
    if reachable(&both) {
        made.push(example(&format!("{said_a} and {}", lower(said_b)), &both));
    }
    let either = Formula::or(vec![a.clone(), b.clone()]);
    made.push(example(&format!("{said_a} or {}", lower(said_b)), &either));
    made
}

fn example(said: &str, goal: &Formula) -> Example {
    Example {
        instruction: format!("{said}."),
        goal: goal.to_string(),
        source: ExampleSource::Made,
    }
}

/// The one atom of a single condition, held or negated.
fn atom_of(goal: &Formula) -> Option<&Atom> {
    match goal {
        Formula::Atom(a) => Some(a),
        Formula::Not(inner) => atom_of(inner),
        _ => None,
    }
}

fn predicate_of(goal: &Formula) -> Option<&str> {
    atom_of(goal).map(|a| a.predicate.as_str())
}

fn objects_of(goal: &Formula) -> &[String] {
    atom_of(goal).map_or(&[], |a| a.args.as_slice())
}

/// `text` with its first letter lower case.
fn lower(text: &str) -> String {
    first_letter(text, char::to_lowercase)
}

/// `text` with its first letter as `case` makes it.
fn first_letter<I: Iterator<Item = char>>(text: &str, case: impl Fn(char) -> I) -> String {
    let mut chars = text.chars();
    chars
        .next()
        .map(|c| case(c).chain(chars).collect())
        .unwrap_or_default()
}

/// The ground atoms of `predicate`, an object never twice in one.
fn atoms_of<'a>(ground: &'a [Atom], predicate: &'a str) -> impl Iterator<Item = Atom> + 'a {
    ground
        .iter()
        .filter(move |a| a.predicate == predicate)
        .filter(|a| {
            let mut args = a.args.clone();
            args.sort_unstable();
            args.windows(2).all(|w| w[0] != w[1])
        })
        .cloned()
}

/// `atom` (or, when not `wanted`, its opposite) said plainly: the scene's first phrase for
/// the condition or its opposite with the objects as the scene calls them ("Close the
/// curtain"); a wanted relation with no phrase as an item to a place ("Coffee to Table2");
/// else the predicate's description with its objects put in, for a wanted condition
/// ("Make sure "Coffee" has been made"). `None` for an opposite the scene lists no words
/// for.
pub fn plainly(atom: &Atom, wanted: bool, vocabulary: &Vocabulary) -> Option<String> {
    let predicate = vocabulary.predicate(&atom.predicate)?;
    let (says, opposite) = (&predicate.words.says, &predicate.words.opposite);
    let called = |name: &String| {
        vocabulary
            .object(name)
            .and_then(|o| o.called.first())
            .map_or_else(|| name.clone(), |c| format!("the {c}"))
    };
    let phrase = if wanted {
        says.first()
    } else {
        opposite.first()
    };
    let said = match (phrase, atom.args.as_slice()) {
        (Some(p), [one]) => format!("{p} {}", called(one)),
        (Some(p), [item, place]) => format!("{} {p} {}", called(item), called(place)),
        // A relation of an item and a place with no phrase, as the scene's own words
        // for a request's items say it ("coffee to table 2").
        (None, [item, place]) if wanted => format!("{} to {}", called(item), called(place)),
        (None, _) if wanted => {
            let words = super::readings::in_words(&Formula::Atom(atom.clone()), vocabulary);
            format!("make sure {words}")
        }
        _ => return None,
    };
    Some(capitalised(&said))
}

fn capitalised(text: &str) -> String {
    first_letter(text, char::to_uppercase)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cafe() -> Scenario {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/cafe/cafe.toml");
        Scenario::load(&path).expect("cafe scenario")
    }

    #[test]
    fn a_made_pool_names_many_things_and_undoes_what_holds() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenarios/warehouse/warehouse.toml");
        let scenario = Scenario::load(&path).expect("warehouse scenario");
        let made = made_pool(&scenario, MADE_POOL);
        assert_eq!(made.len(), MADE_POOL);
        // The singles name many of the scene's things, not its first box each time.
        let mut objects: Vec<String> = made
            .iter()
            .filter(|e| !e.goal.contains(['&', '|']))
            .flat_map(|e| {
                let goal = scenario.parse_goal(&e.goal).expect("a goal of the scene");
                goal.atoms().into_iter().flat_map(|a| a.args)
            })
            .collect();
        objects.sort();
        objects.dedup();
        assert!(objects.len() >= 8, "{objects:?}");
        // An undoing of what holds now, of a thing people call by name: the aisle lights
        // off, never the empty gripper's stand-in put down.
        let undoings: Vec<&Example> = made.iter().filter(|e| e.goal.starts_with('~')).collect();
        assert!(!undoings.is_empty(), "{made:?}");
        assert!(
            undoings.iter().all(|e| !e.goal.contains("Nothing")),
            "{undoings:?}"
        );
        // "and" and "or" join wishes about different things.
        let both = made.iter().find(|e| e.goal.contains('&')).expect("an and");
        let goal = scenario
            .parse_goal(&both.goal)
            .expect("a goal of the scene");
        let atoms: Vec<Atom> = goal.atoms().into_iter().collect();
        assert!(
            atoms[0].args.iter().all(|o| !atoms[1].args.contains(o)),
            "{both:?}"
        );
    }

    #[test]
    fn a_pool_without_written_examples_is_made_from_the_domain() {
        let mut scenario = cafe();
        assert_eq!(fill(&mut scenario), 0, "a written pool is left as it is");
        scenario.examples.clear();
        let made = fill(&mut scenario);
        assert!(made > 4 && made <= MADE_POOL, "{made}");
        assert!(
            scenario
                .examples
                .iter()
                .all(|e| e.source == ExampleSource::Made)
        );
        // Every goal is of the scene and reachable, and the pool shows "and" and "or".
        for e in &scenario.examples {
            let goal = scenario.parse_goal(&e.goal).expect("a goal of the scene");
            let world = crate::world::load(&scenario).unwrap();
            assert!(
                Planner::new(&scenario.domain)
                    .plan(&goal.to_dnf(), world.as_ref())
                    .is_ok()
            );
        }
        assert!(scenario.examples.iter().any(|e| e.goal.contains('&')));
        assert!(scenario.examples.iter().any(|e| e.goal.contains('|')));
        // Predicates are taken in turn: the first examples name different ones.
        let firsts: Vec<&str> = scenario.examples[..3]
            .iter()
            .map(|e| e.goal.split('_').next().unwrap_or(""))
            .collect();
        assert!(
            firsts[0] != firsts[1] && firsts[1] != firsts[2],
            "{firsts:?}"
        );
        // A kept example takes a made one's place; filling again replaces the made ones.
        scenario.examples.push(Example {
            instruction: "Curtains shut".into(),
            goal: "Closed_Curtain".into(),
            source: ExampleSource::Kept("e1".into()),
        });
        let again = fill(&mut scenario);
        assert_eq!(scenario.examples.len(), again + 1);
        assert!(again < MADE_POOL, "{again}");
    }

    #[test]
    fn a_condition_is_said_with_the_scenes_words() {
        let scenario = cafe();
        let v = &scenario.domain.vocabulary;
        let atom = |p: &str, args: &[&str]| Atom {
            predicate: p.into(),
            args: args.iter().map(|a| a.to_string()).collect(),
        };
        let said = plainly(&atom("Closed", &["Curtain"]), true, v).unwrap();
        assert!(said.to_lowercase().contains("curtain"), "{said}");
        assert!(said.starts_with(char::is_uppercase), "{said}");
    }
}
