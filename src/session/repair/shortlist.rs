//! Before the model is asked about a failed action, the conditions that could be its
//! missing precondition are tried in simulation: every literal over the action's objects
//! (and the objects its error names) that is false now, in the words of the scene's
//! vocabulary. Those that make the failure go away are shown to the model, which picks the
//! one that names the cause; a small model chooses among a handful of working fixes far
//! more reliably than it names one out of the whole vocabulary. The list is told to the
//! person as well, so what the model chose from is never hidden.

use super::super::types::{Proposal, Shortlist};
use super::screen::{Screen, Verdict};
use crate::domain::{ANY_OBJECT, Atom, Condition, GroundSkill};

/// Bound on the conditions tried in each pass, so a huge scene stays quick to screen.
const MAX_TRIED: usize = 3000;

/// Bound on the fixes compared pairwise for working only through another.
const MAX_PAIRED: usize = 64;

/// Try every condition related to the failure in `screen`'s copy of the world.
pub fn shortlist(screen: &Screen) -> Shortlist {
    let domain = &screen.scenario.domain;
    let vocabulary = &domain.vocabulary;
    let failure = &screen.failure;
    let error = failure.error.to_lowercase();
    let mut objects: Vec<String> = failure.action.args.clone();
    for o in &vocabulary.objects {
        if !objects.contains(&o.name) && names_word(&error, &o.name.to_lowercase()) {
            objects.push(o.name.clone());
        }
    }
    let ground = domain.resolve(&failure.action);
    // Conditions over the failure's objects first, then over the rest of the scene (a
    // sweep that leaves the floor dirty needs a mop the action never names).
    let mut all = vocabulary.ground_atoms();
    all.retain(|a| {
        // An object in two slots of one condition ("the cube on the cube") is never meant.
        a.args
            .iter()
            .enumerate()
            .all(|(i, x)| !a.args[..i].contains(x))
    });
    let (related, rest): (Vec<Atom>, Vec<Atom>) = all
        .into_iter()
        .partition(|a| a.args.iter().any(|x| objects.contains(x)));
    let mut found = screen_all(screen, ground.as_ref(), &objects, related);
    let mut tried = found.tried;
    if found.fixes.is_empty() {
        found = screen_all(screen, ground.as_ref(), &objects, rest);
        tried += found.tried;
    }
    Shortlist {
        fixes: found.fixes,
        tried,
        objects,
        refused: 0,
        breaking: Vec::new(),
    }
}

/// Screen the literals over `atoms` that are false now and may be missing.
fn screen_all(
    screen: &Screen,
    ground: Option<&GroundSkill>,
    objects: &[String],
    candidates_from: Vec<Atom>,
) -> Shortlist {
    let failure = &screen.failure;
    let mut atoms: Vec<Atom> = Vec::new();
    for atom in candidates_from {
        // The same condition with the other objects left open: `"any object" on "x"`.
        if atom.is_quoted_form() && atom.args.len() > 1 {
            for (slot, arg) in atom.args.iter().enumerate() {
                if !objects.contains(arg) {
                    let mut args = atom.args.clone();
                    args[slot] = ANY_OBJECT.to_string();
                    push_new(&mut atoms, Atom::new(atom.predicate.clone(), args));
                }
            }
        }
        push_new(&mut atoms, atom);
    }
    let mut candidates: Vec<Condition> = Vec::new();
    for atom in atoms {
        for literal in [Condition::pos(atom.clone()), Condition::neg(atom.clone())] {
            let excluded = ground.is_some_and(|g| {
                // Already required, contradicting what is required, or what the action
                // itself is for: none of these can be what is missing.
                g.pre.contains(&literal)
                    || g.pre.contains(&literal.negate())
                    || (!literal.negated && g.add.contains(&literal.atom))
            });
            if !excluded && !screen.world.check(&literal) {
                candidates.push(literal);
            }
        }
    }
    candidates.truncate(MAX_TRIED);
    let tried = candidates.len();
    let mut succeeding = Vec::new();
    let mut moving_on = Vec::new();
    for c in candidates {
        let proposal = Proposal::Conditions {
            action: failure.action.clone(),
            node: failure.node,
            conditions: vec![c.clone()],
        };
        match screen.try_change(&proposal) {
            Ok(Verdict::Succeeds) => succeeding.push(c),
            Ok(Verdict::MovesOn) => moving_on.push(c),
            // A change whose own actions fail only trades one failure for another.
            Ok(Verdict::FailsItself) | Err(_) => {}
        }
    }
    // Conditions about any object first (they keep helping whatever object is in the
    // way next time), then what must hold (the tool held, the lid open), then the other
    // things that must not hold: a negation often works only through how the planner
    // happens to achieve it (the mop is off the entrance because the robot holds it).
    let general_first = |list: &mut Vec<Condition>| {
        list.sort_by_key(|c| match (c.atom.has_wildcard(), c.negated) {
            (true, _) => 0,
            (false, false) => 1,
            (false, true) => 2,
        });
    };
    general_first(&mut succeeding);
    general_first(&mut moving_on);
    // A change after which the whole task succeeds beats one that only gets further;
    // the latter are offered when nothing does more.
    if succeeding.is_empty() {
        succeeding = moving_on;
    }
    Shortlist {
        fixes: without_indirect(screen, succeeding),
        tried,
        objects: objects.to_vec(),
        refused: 0,
        breaking: Vec::new(),
    }
}

/// `fixes` without those that work only through another of them. A fix `c` works through
/// `d` when, with `c` made true and `d` kept false, the action still fails as before,
/// while `d` with `c` kept false does not: the mop is off the entrance only because the
/// robot picked it up, and sweeping needs it held, not moved. Two fixes that each need
/// the other are both kept.
fn without_indirect(screen: &Screen, fixes: Vec<Condition>) -> Vec<Condition> {
    // Every ordered pair is tried; a long list is left as it is to keep this quick.
    if !(2..=MAX_PAIRED).contains(&fixes.len()) {
        return fixes;
    }
    let fails_with = |made: &Condition, kept_false: &Condition| {
        screen.still_fails(&Proposal::Conditions {
            action: screen.failure.action.clone(),
            node: screen.failure.node,
            conditions: vec![made.clone(), kept_false.negate()],
        })
    };
    let indirect: Vec<bool> = fixes
        .iter()
        .map(|c| {
            fixes
                .iter()
                .any(|d| d != c && fails_with(c, d) && !fails_with(d, c))
        })
        .collect();
    fixes
        .into_iter()
        .zip(indirect)
        .filter_map(|(c, indirect)| (!indirect).then_some(c))
        .collect()
}

/// `conditions` without those another of them implies (`~"any object" on "x"` implies
/// `~"red cube" on "x"`; `"red cube" on "x"` implies `"any object" on "x"`) and without
/// repeats: a precondition the tree would check twice only makes it harder to read.
pub fn without_implied(conditions: Vec<Condition>) -> Vec<Condition> {
    let mut kept: Vec<Condition> = Vec::new();
    for (i, c) in conditions.iter().enumerate() {
        let redundant = kept.contains(c)
            || conditions
                .iter()
                .enumerate()
                .any(|(j, other)| j != i && other != c && implies(other, c));
        if !redundant {
            kept.push(c.clone());
        }
    }
    kept
}

/// Whether `a` implies `b` through the wildcard: same predicate and sign, and where they
/// differ, the negated one names any object in `a`, the positive one in `b`.
fn implies(a: &Condition, b: &Condition) -> bool {
    a.negated == b.negated
        && a.atom.predicate == b.atom.predicate
        && a.atom.args.len() == b.atom.args.len()
        && a.atom.args.iter().zip(&b.atom.args).all(|(x, y)| {
            x == y
                || if a.negated {
                    x == ANY_OBJECT
                } else {
                    y == ANY_OBJECT
                }
        })
}

fn push_new(atoms: &mut Vec<Atom>, atom: Atom) {
    if !atoms.contains(&atom) {
        atoms.push(atom);
    }
}

/// Whether `name` (lower case) occurs in `text` (lower case) as a whole word or phrase.
fn names_word(text: &str, name: &str) -> bool {
    text.match_indices(name).any(|(at, _)| {
        let before = text[..at].chars().next_back();
        let after = text[at + name.len()..].chars().next();
        !before.is_some_and(char::is_alphanumeric) && !after.is_some_and(char::is_alphanumeric)
    })
}

#[cfg(test)]
mod tests {
    use std::path::Path;
    use std::sync::Arc;

    use super::*;
    use crate::planner::Planner;
    use crate::scenario::Scenario;
    use crate::session::repair::screen::FailureAt;
    use crate::world::load;

    fn screen_at_first_failure(path: &str) -> Screen {
        let scenario = Arc::new(Scenario::load(Path::new(path)).expect("scenario loads"));
        let world = load(&scenario).expect("world loads");
        let goal = scenario.goal.clone().expect("a stated goal");
        let plan = Planner::new(&scenario.domain)
            .plan(&goal.to_dnf(), world.as_ref())
            .expect("plans");
        let crate::planner::Outcome::ActionFailed {
            action,
            node,
            error,
            ..
        } = plan.outcome
        else {
            panic!("the scenario's plan should fail: {:?}", plan.outcome);
        };
        Screen {
            scenario,
            tree: plan.tree,
            world,
            failure: FailureAt {
                node,
                action,
                error,
            },
        }
    }

    #[test]
    fn a_blocked_grasp_is_fixed_by_clearing_the_cube_and_only_false_conditions_are_tried() {
        let screen = screen_at_first_failure("scenarios/cell/red_on_blue.toml");
        let list = shortlist(&screen);
        let clear = Condition::parse(r#"~"any object" on "blue cube""#).expect("parses");
        assert!(list.fixes.contains(&clear), "{:?}", list.fixes);
        assert_eq!(list.fixes.first(), Some(&clear), "general conditions first");
        // Something that is true already can never be the missing precondition.
        let true_now = Condition::parse(r#""red cube" on "blue cube""#).expect("parses");
        assert!(screen.world.check(&true_now));
        assert!(!list.fixes.contains(&true_now));
        assert!(list.tried > list.fixes.len());
    }

    #[test]
    fn a_missing_coffee_is_made_first() {
        let screen = screen_at_first_failure("scenarios/cafe/no_coffee.toml");
        let list = shortlist(&screen);
        let made = Condition::parse("Exists_Coffee").expect("parses");
        assert!(list.fixes.contains(&made), "{:?}", list.fixes);
    }

    #[test]
    fn a_condition_implied_by_another_is_left_out() {
        let c = |t: &str| Condition::parse(t).expect("parses");
        let kept = without_implied(vec![
            c(r#"~"any object" on "blue cube""#),
            c(r#"~"red cube" on "blue cube""#),
            c(r#""red cup" upright"#),
            c(r#""red cup" upright"#),
        ]);
        assert_eq!(
            kept,
            vec![
                c(r#"~"any object" on "blue cube""#),
                c(r#""red cup" upright"#)
            ]
        );
        // A positive wildcard is the weaker one: the named object is kept.
        let kept = without_implied(vec![
            c(r#""any object" on "tray""#),
            c(r#""banana" on "tray""#),
        ]);
        assert_eq!(kept, vec![c(r#""banana" on "tray""#)]);
        // Different objects are different conditions.
        let both = vec![
            c(r#"~"any object" on "blue cube""#),
            c(r#"~"any object" on "green cube""#),
        ];
        assert_eq!(without_implied(both.clone()), both);
    }

    #[test]
    fn a_tool_the_action_never_names_is_found_in_the_rest_of_the_scene() {
        let screen = screen_at_first_failure("scenarios/cafe/sweep.toml");
        let list = shortlist(&screen);
        let mop = Condition::parse("Holding_Mop").expect("parses");
        assert!(list.fixes.contains(&mop), "{:?}", list.fixes);
        // The mop off the entrance fixes sweeping only because picking it up holds it.
        let moved = Condition::parse("~On_Mop_Entrance").expect("parses");
        assert!(!list.fixes.contains(&moved), "{:?}", list.fixes);
    }

    #[test]
    fn a_condition_that_only_closes_the_actions_branch_is_no_fix() {
        // "Fries or a dessert": putting the chips anywhere but the bar makes the chips
        // branch impossible, so the robot brings the dessert instead; the pick-up of the
        // chips never completes.
        let screen = screen_at_first_failure("scenarios/cafe/find_fries.toml");
        let list = shortlist(&screen);
        let near = Condition::parse("RobotNear_Bar").expect("parses");
        assert!(list.fixes.contains(&near), "{:?}", list.fixes);
        assert!(
            !list
                .fixes
                .iter()
                .any(|c| c.atom.predicate == "On" && !c.negated),
            "{:?}",
            list.fixes
        );
        let around = Proposal::Conditions {
            action: screen.failure.action.clone(),
            node: screen.failure.node,
            conditions: vec![Condition::parse("On_Chips_Table1").expect("parses")],
        };
        let why = screen
            .try_change(&around)
            .expect_err("goes around the failure");
        assert!(
            matches!(
                why,
                crate::session::repair::screen::NotHelped::GoesAround(_)
            ),
            "{why}"
        );
        assert!(
            why.to_string().contains("closes the action's branch"),
            "{why}"
        );
    }

    #[test]
    fn whole_words_only() {
        assert!(names_word("coffee not found", "coffee"));
        assert!(!names_word("coffeemaker not found", "coffee"));
        assert!(names_word("\"red cup\" is upside down", "red cup"));
    }
}
