//! Plain misreadings of a request, each a detector behind one trait and registered in one
//! list ([`MISREADINGS`]), as a behavior-tree library registers its node kinds. A detector
//! says how a goal has plainly misread the request (`find`), and gives the goal with the
//! misreading undone, with what was undone (`undo`). The session's judge asks every
//! registered detector, in the list's order, and an evaluation can leave any of them out
//! by name to measure what it earns.
//!
//! | name | finds | undoes it by |
//! |---|---|---|
//! | `reversed-relation` | a relation with its objects the other way round from the request ("the blue cube on the green cube" read as green on blue) | turning it round |
//! | `swapped-object` | an object no word names in the place of one a word names alone ("fries" read as coffee) | putting the named object back, when the request names one of that kind |
//! | `turned-around` | a condition the other way round from the request's words ("do not open the curtain" read as open) | turning it back |
//! | `left-unanswered` | a condition the request asks for in its own words, left out where the request offers no choice | putting it beside the goal |
//! | `relation-as-said` | a relation other than the one the request says before the place ("in the crib" read as on) | the relation said |
//! | `convention` | an item a convention's words name left elsewhere ("bring me the kit" read as held) | the condition the convention asks for |
//! | `fewer-than-every` | a condition asked of every object of a kind ("both vents", "all the tables") held for some of them only | the same condition for the others beside it |
//! | `left-out` | one of two things named side by side left out ("fries or a dessert" read as the dessert) | the one left out put beside the other, joined as the request joins them |
//! | `not-put` | an item the request sends to a place with no condition relating them | the item at the place (made and the robot there becomes the item there; an item at a place nobody named is moved there) |

use crate::goal::Formula;

use super::kinds::{fewer_than_every, with_every};
use super::names::{swapped_back, swapped_object};
use super::order::{reversed, turned_round};
use super::placement::{moved_there, not_put, put_there};
use super::polarity::{left_unanswered, turned_around, turned_back, with_unanswered};
use super::relation_words::{convention_followed, relation_as_said};
use super::request::Request;
use super::side_by_side::{left_out, with_left_out};

/// One kind of plain misreading; see the module.
pub trait Misreading: Sync {
    /// The name an evaluation leaves it out by.
    fn name(&self) -> &'static str;
    /// How `goal` has plainly misread `request` in this way, if it has.
    fn find(&self, goal: &Formula, request: &Request) -> Option<String>;
    /// `goal` with this misreading undone, each with what was undone (none when it cannot
    /// be, or there is none).
    fn undo(&self, goal: &Formula, request: &Request) -> Vec<(Formula, String)>;
}

/// Every detector, in the order their findings are told and their undoing tried.
pub const MISREADINGS: &[&dyn Misreading] = &[
    &ReversedRelation,
    &SwappedObject,
    &TurnedAround,
    &LeftUnanswered,
    &RelationAsSaid,
    &Convention,
    &FewerThanEvery,
    &NotPut,
    &LeftOut,
];

/// A misreading named that no detector has.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("no misreading is called {name:?}; the misreadings are {known}")]
pub struct UnknownMisreading {
    pub name: String,
    pub known: String,
}

/// The registered detectors but those named in `without`; a name no detector has is an
/// error naming the ones there are.
pub fn misreadings_without(
    without: &[String],
) -> Result<Vec<&'static dyn Misreading>, UnknownMisreading> {
    if let Some(unknown) = without
        .iter()
        .find(|n| !MISREADINGS.iter().any(|m| m.name() == n.as_str()))
    {
        let known: Vec<&str> = MISREADINGS.iter().map(|m| m.name()).collect();
        return Err(UnknownMisreading {
            name: unknown.clone(),
            known: known.join(", "),
        });
    }
    Ok(MISREADINGS
        .iter()
        .copied()
        .filter(|m| !without.iter().any(|n| n == m.name()))
        .collect())
}

struct ReversedRelation;
impl Misreading for ReversedRelation {
    fn name(&self) -> &'static str {
        "reversed-relation"
    }
    fn find(&self, goal: &Formula, request: &Request) -> Option<String> {
        reversed(goal, request)
            .map(|atom| format!("{goal} has {atom} the other way round from the request"))
    }
    fn undo(&self, goal: &Formula, request: &Request) -> Vec<(Formula, String)> {
        turned_round(goal, request)
            .map(|g| {
                (
                    g,
                    format!("the request relates the objects of {goal} the other way round"),
                )
            })
            .into_iter()
            .collect()
    }
}

struct SwappedObject;
impl Misreading for SwappedObject {
    fn name(&self) -> &'static str {
        "swapped-object"
    }
    fn find(&self, goal: &Formula, request: &Request) -> Option<String> {
        swapped_object(goal, request).map(|(object, words)| {
            format!(
                "the request says {}, which no condition of {goal} answers, and never names {object}",
                words.join(", ")
            )
        })
    }
    fn undo(&self, goal: &Formula, request: &Request) -> Vec<(Formula, String)> {
        swapped_back(goal, request)
            .map(|(g, from, to)| {
                (
                    g,
                    format!(
                        "the request names {to} where the answer has {from}, which it never names"
                    ),
                )
            })
            .into_iter()
            .collect()
    }
}

struct TurnedAround;
impl Misreading for TurnedAround {
    fn name(&self) -> &'static str {
        "turned-around"
    }
    fn find(&self, goal: &Formula, request: &Request) -> Option<String> {
        turned_around(goal, request).map(|t| t.to_string())
    }
    fn undo(&self, goal: &Formula, request: &Request) -> Vec<(Formula, String)> {
        let Some(why) = self.find(goal, request) else {
            return Vec::new();
        };
        turned_back(goal, request)
            .map(|g| (g, why))
            .into_iter()
            .collect()
    }
}

struct LeftUnanswered;
impl Misreading for LeftUnanswered {
    fn name(&self) -> &'static str {
        "left-unanswered"
    }
    fn find(&self, goal: &Formula, request: &Request) -> Option<String> {
        let (atom, wanted, word) = left_unanswered(goal, request)?;
        let asked = if wanted {
            atom.to_string()
        } else {
            format!("~{atom}")
        };
        Some(format!(
            "the request says \"{word}\", which asks for {asked}, and {goal} has no condition about it"
        ))
    }
    fn undo(&self, goal: &Formula, request: &Request) -> Vec<(Formula, String)> {
        with_unanswered(goal, request)
            .map(|g| {
                (
                    g,
                    format!("the request asks in its own words for a condition {goal} leaves out"),
                )
            })
            .into_iter()
            .collect()
    }
}

struct RelationAsSaid;
impl Misreading for RelationAsSaid {
    fn name(&self) -> &'static str {
        "relation-as-said"
    }
    fn find(&self, goal: &Formula, request: &Request) -> Option<String> {
        relation_as_said(goal, request).map(|(said, word)| {
            format!(
                "the request says \"{word}\" before the place, which asks for {said}, not {goal}"
            )
        })
    }
    fn undo(&self, goal: &Formula, request: &Request) -> Vec<(Formula, String)> {
        relation_as_said(goal, request)
            .map(|(g, word)| {
                (
                    g,
                    format!("the request says \"{word}\" before the place, which {goal} reads as another relation"),
                )
            })
            .into_iter()
            .collect()
    }
}

struct Convention;
impl Misreading for Convention {
    fn name(&self) -> &'static str {
        "convention"
    }
    fn find(&self, goal: &Formula, request: &Request) -> Option<String> {
        convention_followed(goal, request).map(|(put, word)| {
            format!("the request says \"{word}\", which here asks for {put}, not {goal}")
        })
    }
    fn undo(&self, goal: &Formula, request: &Request) -> Vec<(Formula, String)> {
        convention_followed(goal, request)
            .map(|(g, word)| {
                (
                    g,
                    format!("the request says \"{word}\", which by this scene's conventions asks for where {goal} does not put it"),
                )
            })
            .into_iter()
            .collect()
    }
}

struct FewerThanEvery;
impl Misreading for FewerThanEvery {
    fn name(&self) -> &'static str {
        "fewer-than-every"
    }
    fn find(&self, goal: &Formula, request: &Request) -> Option<String> {
        fewer_than_every(goal, request)
    }
    fn undo(&self, goal: &Formula, request: &Request) -> Vec<(Formula, String)> {
        let Some(why) = fewer_than_every(goal, request) else {
            return Vec::new();
        };
        with_every(goal, request)
            .map(|g| (g, why))
            .into_iter()
            .collect()
    }
}

struct NotPut;
impl Misreading for NotPut {
    fn name(&self) -> &'static str {
        "not-put"
    }
    fn find(&self, goal: &Formula, request: &Request) -> Option<String> {
        not_put(goal, request).map(|sent| {
            format!(
                "the request sends {} to {}, and no condition of {goal} puts it there",
                sent.item, sent.place
            )
        })
    }
    fn undo(&self, goal: &Formula, request: &Request) -> Vec<(Formula, String)> {
        let put = put_there(goal, request).map(|g| {
            (
                g,
                format!("the request sends an item to a place that {goal} only has apart"),
            )
        });
        let moved = moved_there(goal, request).map(|g| {
            (
                g,
                format!("the request sends an item to a place that {goal} has it at another place, one the request never names or names as where it comes from"),
            )
        });
        put.into_iter().chain(moved).collect()
    }
}

struct LeftOut;
impl Misreading for LeftOut {
    fn name(&self) -> &'static str {
        "left-out"
    }
    fn find(&self, goal: &Formula, request: &Request) -> Option<String> {
        left_out(goal, request).map(|gap| {
            format!(
                "the request names {} beside {}, and {goal} leaves {} out",
                gap.left_out, gap.kept, gap.left_out
            )
        })
    }
    fn undo(&self, goal: &Formula, request: &Request) -> Vec<(Formula, String)> {
        with_left_out(goal, request)
            .map(|g| {
                (
                    g,
                    format!("the request names things side by side that {goal} has only one of"),
                )
            })
            .into_iter()
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_each_documented_in_the_table() {
        let source = include_str!("misreading.rs");
        let mut names: Vec<&str> = MISREADINGS.iter().map(|m| m.name()).collect();
        for n in &names {
            assert!(
                source.contains(&format!("//! | `{n}` |")),
                "{n} is not in the module's table"
            );
        }
        let count = names.len();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), count, "two detectors share a name");
    }

    #[test]
    fn leaving_out_an_unknown_misreading_names_the_known_ones() {
        let err = misreadings_without(&["polarity".into()])
            .err()
            .expect("an unknown name is refused")
            .to_string();
        assert!(
            err.contains("\"polarity\"") && err.contains("turned-around"),
            "{err}"
        );
        let kept = misreadings_without(&["convention".into()]).expect("a known name");
        assert_eq!(kept.len(), MISREADINGS.len() - 1);
        assert!(!kept.iter().any(|m| m.name() == "convention"));
    }
}
