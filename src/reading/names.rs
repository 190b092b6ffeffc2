//! What a goal's objects and conjuncts have to do with the request's words: a condition
//! pasted from a shown example, conjuncts no word asks for, object words no condition
//! answers, an object put in the place of one the request names, a place numbered other
//! than the request says, and more alternatives than the request offers.

use crate::goal::Formula;
use crate::goal::rewrite::rename;

use super::english::{ARTICLES, is_generic, is_phrasing};
use super::kinds::asked_of_every;
use super::placement::named_in;
use super::request::Request;
use super::words::{is_number, same_word, terms};

/// A condition of `goal` that one of the `shown` examples' goals holds and that shares no
/// word with the request: pasted from the example rather than asked for (small models
/// copy an example's place, or its extra "hand empty", into unrelated answers).
pub fn copied_from_example(
    goal: &Formula,
    shown: &[&crate::scenario::Example],
    request: &Request,
) -> Option<String> {
    goal.atoms()
        .into_iter()
        .find(|atom| is_copied(atom, shown, &request.terms))
        .map(|atom| format!("{atom} comes from an example, and the request says nothing about it"))
}

fn is_copied(
    atom: &crate::domain::Atom,
    shown: &[&crate::scenario::Example],
    asked: &[String],
) -> bool {
    let in_example = shown
        .iter()
        .any(|e| Formula::parse(&e.goal).is_ok_and(|f| f.atoms().contains(atom)));
    // Pasted when what it is about (its first object) is one the request never names: an
    // example's saucer at the table the request does name is still the example's saucer,
    // while the bowl a named sponge is taken out of may come from the scene.
    in_example
        && atom.args.first().is_none_or(|arg| {
            !terms(arg)
                .iter()
                .any(|w| asked.iter().any(|a| same_word(a, w)))
        })
}

/// The conjuncts of `goal` (a conjunction of two or more) that nothing in the request asks
/// for: every word of the request they answer to is claimed by more conjuncts than the
/// request says it. Small models append a condition the request never mentions ("robot
/// near table 2" after "coffee on table 2": "table" and "2" are said once and claimed
/// twice, and the second conjunct has no word of its own); a request that says "bar" twice
/// ("not on the bar and bar 2, the milk to the bar") asks for every conjunct about a bar.
pub fn unasked(goal: &Formula, request: &Request) -> Vec<Formula> {
    let Formula::And(items) = factored(goal) else {
        return Vec::new();
    };
    let (asked, lexicon) = (&request.terms, request.lexicon);
    let covered: Vec<Vec<String>> = items.iter().map(|i| lexicon.covered(i, asked)).collect();
    // Each condition claims the words it answers to: alternatives "chips to table 1 or
    // juice to table 2" claim "table" twice, so a third condition about a table is one
    // more than the request says.
    let by_atom: Vec<Vec<String>> = items
        .iter()
        .flat_map(|i| i.atoms())
        .map(|a| lexicon.covered(&Formula::Atom(a), asked))
        .collect();
    let said = |w: &String| asked.iter().filter(|a| same_word(a, w)).count();
    let claimed = |w: &String| by_atom.iter().filter(|c| c.contains(w)).count();
    // "Both benches" asks for each bench's condition with one word for the kind.
    let every = request.every_of_kind();
    items
        .iter()
        .zip(&covered)
        .filter(|(item, _)| !asked_of_every(item, every))
        .filter(|(_, words)| words.iter().all(|w| claimed(w) > said(w)))
        .map(|(item, _)| item.clone())
        .collect()
}

/// Words of the request that name an object ("six" of window table 6, "juice") and that
/// no condition of `goal` answers to: the goal leaves out, or misplaces, something asked.
pub fn unanswered_names(goal: &Formula, request: &Request) -> Vec<String> {
    let lexicon = request.lexicon;
    let covered = lexicon.covered(goal, &request.terms);
    let mut out: Vec<String> = request
        .terms
        .iter()
        .filter(|w| lexicon.names_an_object(w) && !covered.contains(w))
        .cloned()
        .collect();
    out.dedup();
    out
}

/// An object of `goal` that no word of the request names, when a word of the request
/// that names an object by itself ("fries", not the "area" of a lounge area, nor a
/// number) is answered by no condition: the goal has put one thing in
/// another's place ("fries" read as coffee).
/// Returns that object and the words left unanswered. A goal whose objects are all named
/// ("a glass of milk" read as the milk) or that leaves no object word out ("it's hot"
/// read as the AC on) is no swap. Predicates are not judged this way: the words a pool
/// teaches them are too loose ("also", "sure") to say one was put in another's place.
pub fn swapped_object(goal: &Formula, request: &Request) -> Option<(String, Vec<String>)> {
    let unanswered: Vec<String> = unanswered_names(goal, request)
        .into_iter()
        .filter(|w| !is_number(w) && request.lexicon.names_an_object_alone(w))
        .collect();
    if unanswered.is_empty() {
        return None;
    }
    unnamed_object(goal.atoms(), request).map(|object| (object, unanswered))
}

/// `goal` with the object it put in another's place ([`swapped_object`]) replaced by the
/// one object of a kind with it that the request names and the goal leaves out ("fries"
/// read as `Softdrink`: `Chips`, called fries; "spring water" is `SpringWater`, not the
/// water its second word names). `None` when the request names no such object or several.
/// Returns the goal, and the object replaced and its replacement.
pub fn swapped_back(goal: &Formula, request: &Request) -> Option<(Formula, String, String)> {
    let (from, _) = swapped_object(goal, request)?;
    let of_kind = of_a_kind_with(request.vocabulary, &from)?;
    let in_goal: Vec<String> = goal.atoms().into_iter().flat_map(|a| a.args).collect();
    let mut named: Vec<String> = named_in(request, &of_kind)
        .into_iter()
        .filter(|name| !in_goal.contains(name))
        .collect();
    named.sort();
    named.dedup();
    let [to] = named.as_slice() else {
        return None;
    };
    Some((rename(goal, &from, to), from, to.clone()))
}

/// The objects that share a kind with the object called `name` (it among them); `None`
/// when the vocabulary has no such object.
fn of_a_kind_with<'a>(
    vocabulary: &'a crate::domain::Vocabulary,
    name: &str,
) -> Option<Vec<&'a crate::domain::Object>> {
    let kinds = &vocabulary.objects.iter().find(|o| o.name == name)?.types;
    Some(
        vocabulary
            .objects
            .iter()
            .filter(|o| o.types.iter().any(|t| kinds.contains(t)))
            .collect(),
    )
}

/// An object of `goal` guessed for one the scene lacks: the request says "the purple cube",
/// no symbol of the scene answers to "purple", several of its objects answer to "cube", and
/// the goal's cube is one whose own distinguishing words the request never says ("blue
/// cube"). The model chose among the cubes by itself; a person settles which, if any, was
/// meant. Only a word right after an article is read as naming which object ("grab cubes"
/// names no particular one), and an unsaid word with the modifier's first letter may be its
/// abbreviation (so "the pink cube" read as a "purple cube" passes). Returns why, in words.
pub fn guessed_for_unknown(goal: &Formula, request: &Request) -> Option<String> {
    let words = &request.unnumbered_words;
    let in_goal: Vec<String> = goal
        .atoms()
        .into_iter()
        .flat_map(|a| a.args)
        .filter(|arg| !is_placeholder(arg))
        .collect();
    words.windows(3).find_map(|w| {
        let [article, modifier, noun] = [&w[0], &w[1], &w[2]];
        if !ARTICLES.contains(&article.as_str())
            || is_generic(modifier)
            || is_number(modifier)
            || request.lexicon.knows(modifier)
            || !request.lexicon.names_an_object(noun)
        {
            return None;
        }
        let answering = |object: &str| {
            request
                .lexicon
                .words(object)
                .iter()
                .any(|x| same_word(x, noun))
        };
        let of_the_noun = request
            .vocabulary
            .objects
            .iter()
            .filter(|o| answering(&o.name))
            .count();
        if of_the_noun < 2 {
            return None;
        }
        let said = |x: &String| request.terms.iter().any(|t| same_word(t, x));
        // A word the request leaves unsaid that may shorten the modifier ("AD" of `ADMilk`
        // for "almond milk") does not make the object a guess.
        let shortens = |x: &String| x.chars().next() == modifier.chars().next();
        in_goal
            .iter()
            .find(|object| {
                let unsaid: Vec<&String> = request
                    .lexicon
                    .words(object)
                    .iter()
                    .filter(|x| !said(x))
                    .collect();
                answering(object) && !unsaid.is_empty() && !unsaid.into_iter().any(shortens)
            })
            .map(|object| {
                format!(
                    "the request says \"{modifier} {noun}\", and no object of the scene is \
                     {modifier}: the goal puts \"{object}\" in its place"
                )
            })
    })
}

/// The first object of `atoms` that no word of `request` names.
pub fn unnamed_object(
    atoms: impl IntoIterator<Item = crate::domain::Atom>,
    request: &Request,
) -> Option<String> {
    atoms
        .into_iter()
        .flat_map(|a| a.args)
        .filter(|arg| !is_placeholder(arg))
        .find(|arg| {
            !request
                .lexicon
                .words(arg)
                .iter()
                .any(|w| request.terms.iter().any(|a| same_word(a, w)))
        })
}

/// Whether `object` is no thing a request names: `"any object"`, or a name that is a word
/// naming no symbol (the empty hand's `Nothing`: "not holding anything" asks for
/// `Holding_Nothing` without the word).
fn is_placeholder(object: &str) -> bool {
    object == crate::domain::ANY_OBJECT || is_generic(&object.to_lowercase())
}

/// `goal` with the conjuncts every alternative shares taken out of the alternatives:
/// `X & A | X & B` is `X & (A | B)`, so that what each alternative repeats is judged once
/// ("the robot near table 3" added to both "fries at table 3" and "dessert at table 3").
/// Any other goal as it is.
pub fn factored(goal: &Formula) -> Formula {
    let Formula::Or(alternatives) = goal else {
        return goal.clone();
    };
    let lists: Vec<Vec<Formula>> = alternatives.iter().map(Formula::conjuncts).collect();
    let Some((first, rest)) = lists.split_first() else {
        return goal.clone();
    };
    let common: Vec<Formula> = first
        .iter()
        .filter(|c| rest.iter().all(|l| l.contains(c)))
        .cloned()
        .collect();
    let remainders: Vec<Vec<Formula>> = lists
        .iter()
        .map(|l| l.iter().filter(|c| !common.contains(c)).cloned().collect())
        .collect();
    // An alternative that is only the shared part would absorb the others.
    if common.is_empty() || remainders.iter().any(Vec::is_empty) {
        return goal.clone();
    }
    let mut items = common;
    items.push(Formula::Or(
        remainders.into_iter().map(Formula::and).collect(),
    ));
    Formula::and(items)
}

/// `goal` without the conjuncts nothing asks for, taken out one at a time, the last
/// first (an appended condition comes last), while more than one is left.
pub fn without_unasked(goal: &Formula, request: &Request) -> Option<Formula> {
    let mut current = factored(goal);
    let mut changed = false;
    while let Some(extra) = unasked(&current, request).pop() {
        let Formula::And(items) = &current else {
            break;
        };
        let kept: Vec<Formula> = items.iter().filter(|i| **i != extra).cloned().collect();
        if kept.is_empty() || kept.len() == items.len() {
            break;
        }
        current = Formula::and(kept);
        changed = true;
    }
    changed.then_some(current)
}

/// A conjunction without its conjuncts pasted from an example, when the rest stands
/// alone: something is left, and every word of the request that asks for something is
/// covered by what is left ("put the blue cube on the green cube" read as "blue on green
/// & hand empty": the rest covers blue, green and cube, so the pasted "hand empty" goes).
/// A request with a word the rest does not cover ("it's hot, close the curtain") may
/// mean the pasted condition in other words, and keeps it.
pub fn without_copied(
    goal: &Formula,
    shown: &[&crate::scenario::Example],
    request: &Request,
) -> Option<Formula> {
    let Formula::And(items) = goal else {
        return None;
    };
    let asked = &request.terms;
    let kept: Vec<Formula> = items
        .iter()
        .filter(|item| !item.atoms().iter().any(|a| is_copied(a, shown, asked)))
        .cloned()
        .collect();
    if kept.is_empty() || kept.len() == items.len() {
        return None;
    }
    let rest = Formula::and(kept);
    let covered: Vec<String> = rest
        .atoms()
        .iter()
        .flat_map(|a| terms(&a.to_string()))
        .collect();
    let unexplained = asked
        .iter()
        .any(|w| !is_phrasing(w) && !covered.iter().any(|c| same_word(c, w)));
    (!unexplained).then_some(rest)
}

/// How many alternatives `goal` offers beyond the first where it asks for something:
/// `A | B | C` offers two; a disjunction under a negation ("neither A nor B") offers none.
fn alternatives(goal: &Formula, negated: bool) -> usize {
    match goal {
        Formula::Atom(_) => 0,
        Formula::Not(inner) => alternatives(inner, !negated),
        Formula::And(items) | Formula::Or(items) => {
            let inner: usize = items.iter().map(|i| alternatives(i, negated)).sum();
            // `~(A & B)` is `~A | ~B`: a conjunction offers alternatives under a negation.
            let offers = matches!(goal, Formula::Or(_)) != negated;
            inner + if offers { items.len() - 1 } else { 0 }
        }
    }
}

/// Why `goal` offers more alternatives than `request` does, if it does: "a banana or an
/// orange, and switch the light off" written `A | B | ~C` makes switching the light off
/// one of three alternatives, when the request asks for it in any case.
pub fn more_alternatives_than_asked(goal: &Formula, request: &Request) -> Option<String> {
    let offered = alternatives(goal, false);
    let asked = request.choices;
    (offered > asked).then(|| {
        format!(
            "it offers {} alternatives joined by |, where the request gives {} choice(s); \
             what must hold in any case is joined with &, and a choice in parentheses: (A | B) & C",
            offered + 1,
            asked + 1
        )
    })
}
