//! The model asked in a small step before the goal: which of the scene's objects and
//! places the request names. A small model picks names out of a list well and writes a
//! whole formula over a large scene less well, so the goal's first answer is then typed by
//! a grammar over the named objects only (every predicate that can still be written); the
//! candidates drawn after it are typed over the whole scene again, so a name the first
//! step missed costs only the first answer.

use crate::domain::Vocabulary;
use crate::llm::prompt::Context;
use crate::llm::{LanguageModel, grammar, schema};

use super::ask::ask;
use super::types::{Event, Options, SessionError};

/// The most names one answer lists.
const MOST_NAMED: usize = 8;

/// The objects and places of the scene the request names, as the model lists them (in
/// the scene's order, each once); `None` when the model cannot be held to a grammar
/// (then the step would only cost a call) or names nothing the scene has.
pub(super) async fn named_objects(
    ctx: &Context<'_>,
    model: &dyn LanguageModel,
    options: &Options,
    emit: &mut (dyn FnMut(&Event) + Send),
) -> Result<Option<Vec<String>>, SessionError> {
    if !(options.grammar && model.supports_grammar()) {
        return Ok(None);
    }
    let vocabulary = &ctx.scenario.domain.vocabulary;
    let names: Vec<&str> = vocabulary.objects.iter().map(|o| o.name.as_str()).collect();
    if names.is_empty() {
        return Ok(None);
    }
    let messages = ctx.names(&options.templates)?;
    let names_grammar = || grammar::names_grammar(&names, MOST_NAMED);
    emit(&Event::Asking {
        what: crate::session::Question::NamedObjects,
    });
    let mut opts = options.clone();
    // One greedy answer: the runners-up of a list of names are not candidates of a goal.
    opts.beams = 1;
    let reply = ask(
        model,
        messages,
        (schema::goal(vocabulary), &names_grammar),
        &opts,
        None,
        None,
        emit,
    )
    .await?;
    let named = read_named(&reply.text, vocabulary);
    Ok((!named.is_empty()).then_some(named))
}

/// The scene's objects a `Named: a, b` answer lists, in the scene's order; other words
/// are left out.
fn read_named(text: &str, vocabulary: &Vocabulary) -> Vec<String> {
    let listed = text
        .lines()
        .find_map(|l| l.trim().strip_prefix("Named:"))
        .unwrap_or("");
    let listed: Vec<&str> = listed.split(',').map(str::trim).collect();
    vocabulary
        .objects
        .iter()
        .filter(|o| listed.contains(&o.name.as_str()))
        .map(|o| o.name.clone())
        .collect()
}

/// The vocabulary over `named` objects only: predicates with a slot no named object fits
/// are left out. `None` when no predicate is left that takes an object (the narrowed
/// grammar would then only allow what the whole one does with fewer choices of meaning).
pub(super) fn narrowed(vocabulary: &Vocabulary, named: &[String]) -> Option<Vocabulary> {
    let objects: Vec<_> = vocabulary
        .objects
        .iter()
        .filter(|o| named.contains(&o.name))
        .cloned()
        .collect();
    let predicates: Vec<_> = vocabulary
        .predicates
        .iter()
        .filter(|p| {
            p.arg_types
                .iter()
                .all(|t| objects.iter().any(|o| o.fits(t)))
        })
        .cloned()
        .collect();
    predicates
        .iter()
        .any(|p| !p.arg_types.is_empty())
        .then_some(Vocabulary {
            objects,
            predicates,
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::{Object, Predicate};

    fn vocabulary() -> Vocabulary {
        let o = |n: &str, t: &str| Object {
            name: n.into(),
            types: vec![t.into()],
            called: Vec::new(),
        };
        let p = |n: &str, args: &[&str]| Predicate {
            name: n.into(),
            arg_types: args.iter().map(|a| vec![a.to_string()]).collect(),
            description: String::new(),
            words: Default::default(),
        };
        Vocabulary {
            objects: vec![o("Coffee", "item"), o("Table1", "place"), o("Tea", "item")],
            predicates: vec![
                p("On", &["item", "place"]),
                p("Clean", &["place"]),
                p("Holding", &["item"]),
                p("Tidy", &[]),
            ],
        }
    }

    #[test]
    fn the_listed_names_the_scene_has_in_its_order() {
        let v = vocabulary();
        assert_eq!(
            read_named("Named: Table1, Coffee, Cake", &v),
            ["Coffee", "Table1"]
        );
        assert!(read_named("Goal: On_Coffee_Table1", &v).is_empty());
    }

    #[test]
    fn narrowing_keeps_the_predicates_the_named_objects_can_fill() {
        let v = vocabulary();
        let only_table = narrowed(&v, &["Table1".to_string()]).unwrap();
        let kept: Vec<&str> = only_table
            .predicates
            .iter()
            .map(|p| p.name.as_str())
            .collect();
        assert_eq!(kept, ["Clean", "Tidy"]);
        assert_eq!(only_table.objects.len(), 1);
        let both = narrowed(&v, &["Coffee".to_string(), "Table1".to_string()]).unwrap();
        assert_eq!(both.predicates.len(), 4);
        // Nothing named that a predicate takes: no narrowing.
        assert!(narrowed(&v, &[]).is_none());
    }
}
