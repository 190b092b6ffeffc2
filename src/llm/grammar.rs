//! GBNF grammars (llama.cpp's grammar format) built from a scenario's vocabulary, so that a
//! constrained model can only write well-formed answers whose atoms are the scenario's
//! predicates over objects of the right types: an object outside the scene cannot occur.
//!
//! Atoms are generated per predicate with one rule per argument slot (the objects whose
//! type fits), not as a list of every ground atom, which keeps the grammar small for the
//! cafe's 1,300 atoms.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use crate::domain::condition::is_word_predicate;
use crate::domain::{ANY_OBJECT, Condition, Vocabulary};

/// A GBNF string literal.
fn lit(text: &str) -> String {
    let mut out = String::from("\"");
    for c in text.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// Rules for `atom` (any condition of the vocabulary) and `literal` (`~`-prefixed or not).
/// `wildcard`: whether `"any object"` may stand in object slots (tabletop conditions).
pub fn atom_rules(vocabulary: &Vocabulary, wildcard: bool) -> String {
    // One rule per distinct slot type list, shared by the predicates that use it.
    let mut slots: BTreeMap<String, String> = BTreeMap::new();
    let mut slot_rule = |types: &[String], quoted: bool| -> String {
        let key = format!("{}{}", if quoted { "q-" } else { "i-" }, types.join("-")).to_lowercase();
        let name: String = key
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
            .collect();
        slots.entry(name.clone()).or_insert_with(|| {
            let mut objects: Vec<String> = vocabulary
                .objects_fitting(types)
                .map(str::to_string)
                .collect();
            if quoted && wildcard {
                objects.push(ANY_OBJECT.to_string());
            }
            // Longest first: GBNF alternatives are tried as written by some engines.
            objects.sort_by(|a, b| b.len().cmp(&a.len()).then(a.cmp(b)));
            objects
                .iter()
                .map(|o| {
                    if quoted {
                        lit(&format!("\"{o}\""))
                    } else {
                        lit(o)
                    }
                })
                .collect::<Vec<_>>()
                .join(" | ")
        });
        name
    };
    let mut alternatives = Vec::new();
    for p in &vocabulary.predicates {
        if p.arg_types.is_empty() {
            alternatives.push(lit(&p.name));
            continue;
        }
        if is_word_predicate(&p.name) {
            // "a" on "b": first argument, the words, then the other arguments.
            let mut parts = vec![
                slot_rule(&p.arg_types[0], true),
                lit(&format!(" {}", p.name)),
            ];
            for t in &p.arg_types[1..] {
                parts.push(lit(" "));
                parts.push(slot_rule(t, true));
            }
            alternatives.push(format!("( {} )", parts.join(" ")));
        } else {
            let mut parts = vec![lit(&p.name)];
            for t in &p.arg_types {
                parts.push(lit("_"));
                parts.push(slot_rule(t, false));
            }
            alternatives.push(format!("( {} )", parts.join(" ")));
        }
    }
    let mut out = String::new();
    let _ = writeln!(out, "atom ::= {}", alternatives.join(" | "));
    let _ = writeln!(out, "literal ::= \"~\"? atom");
    for (name, body) in slots {
        let _ = writeln!(out, "{name} ::= {body}");
    }
    out
}

/// `Goal: <formula>` with `&`, `|`, `~` and parentheses over the vocabulary's atoms;
/// with `reasoning`, a free `Reasoning:` line comes first (the chain-of-thought prompt).
pub fn goal_grammar(vocabulary: &Vocabulary, wildcard: bool, reasoning: bool) -> String {
    let mut g = String::new();
    if reasoning {
        g.push_str("root ::= \"Reasoning: \" reasoning \"\\nGoal: \" formula\n");
        g.push_str(REASONING_RULE);
    } else {
        g.push_str("root ::= \"Goal: \" formula\n");
    }
    g.push_str(&formula_rules(vocabulary, wildcard));
    g
}

/// An answer that is exactly one of `words`.
pub fn one_of_grammar(words: &[&str]) -> String {
    let alternatives: Vec<String> = words.iter().map(|w| lit(w)).collect();
    format!("root ::= {}\n", alternatives.join(" | "))
}

/// The formula's rules, below the root.
fn formula_rules(vocabulary: &Vocabulary, wildcard: bool) -> String {
    let mut g = String::new();
    // One operator per level: `A | B & C` cannot be written, only `A | (B & C)` or
    // `(A | B) & C`, so the model has to decide how the parts group (small models write
    // the first meaning the second) and the reader never needs precedence rules.
    // Bounded repetition: a small model can otherwise loop `& A & A & ...` until the
    // token limit. Eight conjuncts and four alternatives cover every goal of the dataset.
    g.push_str("formula ::= factor ( ( \" & \" factor ){1,7} | ( \" | \" factor ){1,3} )?\n");
    g.push_str("factor ::= \"~\"? ( atom | \"(\" formula \")\" )\n");
    g.push_str(&atom_rules(vocabulary, wildcard));
    g
}

/// `Named: ` and one to `most` of `names`, separated by commas: the objects and places a
/// request names, each once at most by the model's choice (repeats are read as one).
pub fn names_grammar(names: &[&str], most: usize) -> String {
    let mut sorted: Vec<&str> = names.to_vec();
    // Longest first: GBNF alternatives are tried as written by some engines.
    sorted.sort_by(|a, b| b.len().cmp(&a.len()).then(a.cmp(b)));
    sorted.dedup();
    let alternatives: Vec<String> = sorted.iter().map(|n| lit(n)).collect();
    let mut g = String::new();
    let _ = writeln!(
        g,
        "root ::= \"Named: \" name ( \", \" name ){{0,{}}}",
        most.saturating_sub(1)
    );
    let _ = writeln!(g, "name ::= {}", alternatives.join(" | "));
    g
}

/// One line of free text (the model's reasoning), bounded so it cannot run away.
const REASONING_RULE: &str = "reasoning ::= [^\\n]{1,600}\n";

/// A `Reasoning:` line, then `Conditions:` and one literal per line.
pub fn conditions_grammar(vocabulary: &Vocabulary, wildcard: bool) -> String {
    let mut g = String::new();
    g.push_str(
        "root ::= \"Reasoning: \" reasoning \"\\nConditions:\\n\" literal ( \"\\n\" literal )?\n",
    );
    g.push_str(REASONING_RULE);
    g.push_str(&atom_rules(vocabulary, wildcard));
    g
}

/// As [`conditions_grammar`], with one condition, one of `choices` (the conditions found
/// to fix a failure alone in simulation: a second would only add what is not needed).
pub fn chosen_conditions_grammar(choices: &[Condition]) -> String {
    let mut g = String::new();
    g.push_str("root ::= \"Reasoning: \" reasoning \"\\nConditions:\\n\" literal\n");
    g.push_str(REASONING_RULE);
    let alternatives: Vec<String> = choices.iter().map(|c| lit(&c.to_string())).collect();
    let _ = writeln!(g, "literal ::= {}", alternatives.join(" | "));
    g
}

/// A `Reasoning:` line, then `Parameter value: ` and a number with `unit`, or one of
/// `categories`.
pub fn value_grammar(unit: Option<&str>, categories: &[String]) -> String {
    let mut g = String::new();
    g.push_str("root ::= \"Reasoning: \" reasoning \"\\nParameter value: \" value\n");
    g.push_str(REASONING_RULE);
    if categories.is_empty() {
        let unit = unit
            .map(|u| format!(" {}", lit(&format!(" {u}"))))
            .unwrap_or_default();
        let _ = writeln!(g, "value ::= [0-9]{{1,4}} ( \".\" [0-9]{{1,3}} )?{unit}");
    } else {
        let alts: Vec<String> = categories.iter().map(|c| lit(c)).collect();
        let _ = writeln!(g, "value ::= {}", alts.join(" | "));
    }
    g
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::{Object, Predicate};

    fn vocab() -> Vocabulary {
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
            objects: vec![
                o("blue cube", "object"),
                o("red cup", "object"),
                o("Coffee", "item"),
                o("Table1", "place"),
            ],
            predicates: vec![
                p("on", &["object", "object"]),
                p("upright", &["object"]),
                p("On", &["item", "place"]),
            ],
        }
    }

    #[test]
    fn atoms_are_typed_per_slot() {
        let g = atom_rules(&vocab(), true);
        assert!(g.contains(r#"( q-object " on" " " q-object )"#), "{g}");
        assert!(g.contains(r#"( "On" "_" i-item "_" i-place )"#), "{g}");
        assert!(
            g.contains(r#"q-object ::= "\"any object\"" | "\"blue cube\"" | "\"red cup\"""#),
            "{g}"
        );
        assert!(g.contains(r#"i-item ::= "Coffee""#), "{g}");
    }

    #[test]
    fn answer_grammars_have_their_prefix() {
        let g = goal_grammar(&vocab(), false, false);
        assert!(g.starts_with("root ::= \"Goal: \" formula"));
        // `&` and `|` never share a level: mixing them needs parentheses.
        assert!(
            g.contains("formula ::= factor ( ( \" & \" factor ){1,7} | ( \" | \" factor ){1,3} )?"),
            "{g}"
        );
        assert!(
            goal_grammar(&vocab(), false, true)
                .starts_with("root ::= \"Reasoning: \" reasoning \"\\nGoal: \"")
        );
        assert!(conditions_grammar(&vocab(), true).contains("\\nConditions:\\n\" literal"));
        let v = value_grammar(Some("N"), &[]);
        assert!(
            v.contains("value ::= [0-9]{1,4} ( \".\" [0-9]{1,3} )? \" N\""),
            "{v}"
        );
        let v = value_grammar(None, &["shovel".into(), "spoon".into()]);
        assert!(v.contains("value ::= \"shovel\" | \"spoon\""), "{v}");
        let n = names_grammar(&["Table1", "Coffee", "Table10", "Coffee"], 4);
        assert!(
            n.starts_with("root ::= \"Named: \" name ( \", \" name ){0,3}"),
            "{n}"
        );
        assert!(
            n.contains("name ::= \"Table10\" | \"Coffee\" | \"Table1\"\n"),
            "{n}"
        );
    }
}
