//! A relation with its two objects the other way round from the request: "put the blue
//! cube on the green cube" read as the green cube on the blue one. The request names the
//! first object, then a word that sends it ("on", "onto", "in", "into", "to", "at"), then
//! the second, in one clause; a goal that relates them the other way, and never this way,
//! has them reversed.

use crate::domain::Atom;
use crate::goal::Formula;
use crate::goal::rewrite::map_atoms;

use super::english::TOWARDS;
use super::request::Request;
use super::request::sent::PLACE_WITHIN;

/// The pairs (first, second) the request relates: the first named, then within a few
/// words a word that sends it, then the second.
fn said_pairs(request: &Request) -> Vec<(String, String)> {
    let mut out = Vec::new();
    for (words, named) in request.clauses.iter().zip(request.clause_mentions()) {
        for (i, (at, len, first)) in named.iter().enumerate() {
            let Some((next_at, _, second)) = named.get(i + 1) else {
                continue;
            };
            let between = &words[at + len..*next_at];
            if first != second
                && between.len() <= PLACE_WITHIN
                && between.iter().any(|w| TOWARDS.contains(&w.as_str()))
            {
                out.push((first.clone(), second.clone()));
            }
        }
    }
    out
}

/// The first positive two-object condition of `goal` that relates a pair the request
/// says the other way round, when no condition of `goal` relates it as said: the atom.
pub fn reversed(goal: &Formula, request: &Request) -> Option<Atom> {
    let pairs = said_pairs(request);
    let atoms = goal.atoms_in_order();
    let relates =
        |a: &Atom, x: &str, y: &str| a.args.len() == 2 && a.args[0] == x && a.args[1] == y;
    atoms.iter().find_map(|a| {
        pairs
            .iter()
            .find(|(x, y)| relates(a, y, x) && !atoms.iter().any(|b| relates(b, x, y)))
            .map(|_| a.clone())
    })
}

/// `goal` with every reversed relation ([`reversed`]) turned the way the request says.
pub fn turned_round(goal: &Formula, request: &Request) -> Option<Formula> {
    let atom = reversed(goal, request)?;
    let swapped = Atom::new(
        atom.predicate.clone(),
        vec![atom.args[1].clone(), atom.args[0].clone()],
    );
    Some(map_atoms(goal, &|a| {
        if *a == atom {
            swapped.clone()
        } else {
            a.clone()
        }
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::Scenario;
    use std::path::Path;

    fn load(path: &str) -> Scenario {
        Scenario::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(path)).expect("scenario")
    }

    #[test]
    fn a_relation_the_other_way_round_is_found_and_turned() {
        let cell = load("scenarios/cell/red_on_blue.toml");
        let v = &cell.domain.vocabulary;
        let request = "Put the blue cube on the green cube";
        let reversed_goal = cell
            .parse_goal(r#""green cube" on "blue cube""#)
            .expect("goal");
        let as_said = cell
            .parse_goal(r#""blue cube" on "green cube""#)
            .expect("goal");
        assert_eq!(
            reversed(&reversed_goal, &Request::among(request, v)).map(|a| a.to_string()),
            Some(r#""green cube" on "blue cube""#.to_string())
        );
        assert_eq!(
            turned_round(&reversed_goal, &Request::among(request, v)),
            Some(as_said.clone())
        );
        assert_eq!(reversed(&as_said, &Request::among(request, v)), None);
    }

    #[test]
    fn relations_the_request_does_not_order_are_left_alone() {
        let cafe = load("scenarios/cafe/cafe.toml");
        let v = &cafe.domain.vocabulary;
        // Two places, no object sent between them.
        let goal = cafe.parse_goal("On_Coffee_Table1").expect("goal");
        assert_eq!(
            reversed(&goal, &Request::among("Bring coffee to table 1", v)),
            None
        );
        assert_eq!(
            reversed(
                &goal,
                &Request::among("Is the coffee at table 1 or the bar?", v)
            ),
            None
        );
    }
}
