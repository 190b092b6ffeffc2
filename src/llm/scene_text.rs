//! The scene as a prompt writes it: the conditions the robot understands (each with its
//! description), the objects grouped
//! by type with what people call them, and the facts that hold now.

use crate::domain::{ANY_OBJECT, Condition, Vocabulary};

/// One line per predicate: its written form with argument types and its description; for
/// quoted-form vocabularies, a line on the `"any object"` wildcard.
pub fn vocabulary_text(vocabulary: &Vocabulary, descriptions: bool) -> String {
    let mut text = predicate_lines(vocabulary, descriptions);
    // Explained with a placeholder, not a real object: small models copy a concrete
    // example verbatim as their answer.
    let binary = vocabulary
        .predicates
        .iter()
        .find(|p| crate::domain::condition::is_word_predicate(&p.name) && p.arg_types.len() == 2);
    if let Some(p) = binary {
        text.push_str(&format!(
            "\n\"{ANY_OBJECT}\" stands for some object, and negated for none: ~\"{ANY_OBJECT}\" {} \"<object>\" means that no object is {} that object.",
            p.name, p.name
        ));
    }
    text
}

fn predicate_lines(vocabulary: &Vocabulary, descriptions: bool) -> String {
    vocabulary
        .predicates
        .iter()
        .map(|p| {
            let slots: Vec<String> = p.arg_types.iter().map(|t| t.join("|")).collect();
            let form = if crate::domain::condition::is_word_predicate(&p.name) {
                let mut s = String::new();
                if let Some(first) = slots.first() {
                    s.push_str(&format!("\"<{first}>\" "));
                }
                s.push_str(&p.name);
                for t in slots.iter().skip(1) {
                    s.push_str(&format!(" \"<{t}>\""));
                }
                s
            } else {
                let mut s = p.name.clone();
                for t in &slots {
                    s.push_str(&format!("_<{t}>"));
                }
                s
            };
            if descriptions && !p.description.is_empty() {
                format!("- {form}: {}", p.description)
            } else {
                format!("- {form}")
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// The objects grouped by type, types in first-seen order; an object the scene says people
/// call otherwise has those words beside its name, once (the model is told that "fries"
/// are `Chips` rather than left to guess between neighbours).
pub fn objects_text(vocabulary: &Vocabulary) -> String {
    let mut types: Vec<&str> = Vec::new();
    for o in &vocabulary.objects {
        for t in &o.types {
            if !types.contains(&t.as_str()) {
                types.push(t);
            }
        }
    }
    let mut glossed: Vec<&str> = Vec::new();
    let mut lines: Vec<String> = Vec::new();
    for t in types {
        let mut names: Vec<String> = Vec::new();
        for o in vocabulary
            .objects
            .iter()
            .filter(|o| o.types.iter().any(|ot| ot == t))
        {
            if o.called.is_empty() || glossed.contains(&o.name.as_str()) {
                names.push(o.name.clone());
            } else {
                glossed.push(&o.name);
                names.push(format!("{} ({})", o.name, o.called.join(", ")));
            }
        }
        lines.push(format!("- {t}: {}", names.join(", ")));
    }
    lines.join("\n")
}

/// The facts true now, one per line; everything else is false.
pub fn scene_text(facts: &[Condition]) -> String {
    if facts.is_empty() {
        return "No condition holds now.".into();
    }
    let lines: Vec<String> = facts.iter().map(|f| format!("- {f}")).collect();
    format!(
        "These conditions hold now; every other condition is false:\n{}",
        lines.join("\n")
    )
}
