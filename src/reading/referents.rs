//! What "it" and "them" stand for: the object named last before them. "Prune the basil,
//! then water it" asks for the basil watered; a goal that waters another plant, one no
//! word of the request names, has taken "it" for it.

use crate::domain::Atom;
use crate::goal::Formula;
use crate::goal::rewrite::map_atoms;

use super::english::BACK_REFERENCES;
use super::request::Request;
use super::words::same_word;

/// A condition of `goal` about an object no word of the request names, in place of the
/// object a back reference stands for: the atom, and the object meant.
pub fn referent_swapped(goal: &Formula, request: &Request) -> Option<(Atom, String)> {
    let lexicon = request.lexicon;
    let vocabulary = request.vocabulary;
    let named: Vec<&String> = request.mentions().iter().map(|(_, _, n)| n).collect();
    let mentions = request.clause_mentions();
    let slot_of = |predicate: &str| {
        vocabulary
            .predicates
            .iter()
            .find(|p| p.name == predicate && p.arg_types.len() == 1)
            .and_then(|p| p.arg_types.first())
    };
    for (at, words) in request.clauses.iter().enumerate() {
        if !words.iter().any(|w| BACK_REFERENCES.contains(&w.as_str())) {
            continue;
        }
        let said_here = |predicate: &str| {
            lexicon
                .words(predicate)
                .iter()
                .any(|w| words.iter().any(|c| same_word(c, w)))
        };
        let here = mentions.get(at).map_or(&[][..], Vec::as_slice);
        let found = goal.atoms().into_iter().find_map(|a| {
            let [object] = a.args.as_slice() else {
                return None;
            };
            let slot = slot_of(&a.predicate)?;
            // The clause names what the condition is about itself ("water the can").
            let names_its_own = here.iter().any(|(_, _, n)| vocabulary.fits(n, slot));
            if named.contains(&object) || names_its_own || !said_here(&a.predicate) {
                return None;
            }
            // The object named last before the clause that the condition can be about.
            let referent = mentions[..at]
                .iter()
                .rev()
                .flat_map(|m| m.iter().rev())
                .map(|(_, _, name)| name)
                .find(|name| vocabulary.fits(name, slot))?;
            (referent != object).then(|| (a.clone(), referent.clone()))
        });
        if found.is_some() {
            return found;
        }
    }
    None
}

/// `goal` with the object [`referent_swapped`] finds replaced, in that condition, by the
/// object the back reference stands for.
pub fn referent_back(goal: &Formula, request: &Request) -> Option<Formula> {
    let (atom, referent) = referent_swapped(goal, request)?;
    let back = map_atoms(goal, &|a| {
        if *a == atom {
            Atom::new(a.predicate.clone(), vec![referent.clone()])
        } else {
            a.clone()
        }
    });
    (back != *goal).then_some(back)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reading::Lexicon;
    use crate::scenario::Scenario;
    use std::path::Path;

    fn greenhouse() -> Scenario {
        Scenario::load(
            &Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/greenhouse/greenhouse.toml"),
        )
        .expect("greenhouse scenario")
    }

    #[test]
    fn it_is_the_plant_named_before() {
        let scene = greenhouse();
        let lexicon = Lexicon::new(&scene.domain.vocabulary, &scene.examples);
        let request = Request::new("Prune the basil, then water it.", &scene, &lexicon);
        let goal = Formula::parse("Pruned_Basil & Watered_Mint").expect("parses");
        let (atom, referent) = referent_swapped(&goal, &request).expect("a swap");
        assert_eq!(
            (atom.to_string(), referent.as_str()),
            ("Watered_Mint".to_string(), "Basil")
        );
        assert_eq!(
            referent_back(&goal, &request).map(|g| g.to_string()),
            Some("Pruned_Basil & Watered_Basil".to_string())
        );
        // Read right, or about a plant the request names: nothing to find.
        let right = Formula::parse("Pruned_Basil & Watered_Basil").expect("parses");
        assert_eq!(referent_swapped(&right, &request), None);
        let request = Request::new("Prune the basil, then water the mint.", &scene, &lexicon);
        assert_eq!(referent_swapped(&goal, &request), None);
    }
}
