//! Building a scenario from the files of its `extends` chain, base first: the vocabulary
//! (objects, then predicates), the skills, the goals, and the rest of the tables. Every
//! error points into the file and string it is about.

use std::collections::HashMap;

use toml::Spanned;

use super::file::{RawFile, RawPuts};
use super::{
    Convention, ConventionPuts, Example, Scenario, ScenarioError, SourceFile, goal_in, split_types,
};
use crate::domain::skill::Domain;
use crate::domain::vocabulary::{Object, Predicate, StateWords, Vocabulary};
use crate::goal::Formula;

impl Scenario {
    /// The scenario of a chain of files, base first; the last file is the one loaded and
    /// holds the `[scenario]` table.
    pub(super) fn build(
        files: Vec<SourceFile>,
        raws: Vec<RawFile>,
    ) -> Result<Scenario, ScenarioError> {
        let child = files.len() - 1;
        let Some(meta) = raws[child].scenario.as_ref() else {
            return Err(files[child].error_at(0, "missing [scenario] table with at least `name`"));
        };
        let mut vocabulary = objects(&files, &raws)?;
        add_called(&mut vocabulary, &files, &raws)?;
        add_predicates(&mut vocabulary, &files, &raws)?;
        let skills = super::skills::skills(&files, &raws, &vocabulary)?;
        let file = &files[child];
        let goal = match &meta.goal {
            Some(g) => Some(located_goal(file, g, &vocabulary)?),
            None => None,
        };
        for fix in &meta.expected_fix {
            located_goal(file, fix, &vocabulary)?;
        }
        Ok(Scenario {
            name: meta.name.clone(),
            description: meta.description.clone(),
            instruction: meta.instruction.clone(),
            goal,
            expected_fix: meta
                .expected_fix
                .iter()
                .map(|f| f.get_ref().clone())
                .collect(),
            examples: examples(&files, &raws, &vocabulary)?,
            conventions: conventions(&files, &raws, &vocabulary)?,
            domain: Domain { vocabulary, skills },
            world_kind: world_kind(&raws),
            files,
        })
    }
}

/// The objects of every file, each with every type any file gives it.
fn objects(files: &[SourceFile], raws: &[RawFile]) -> Result<Vocabulary, ScenarioError> {
    let mut vocabulary = Vocabulary::default();
    // Where each object stands in the vocabulary, so a large scene loads in linear time.
    let mut index: HashMap<String, usize> = HashMap::new();
    for (raw, file) in raws.iter().zip(files) {
        for (ty, names) in &raw.objects {
            for name in names {
                let n = name.get_ref().trim();
                if n.is_empty() || n.contains('"') {
                    return Err(file.error_in_string(
                        &name.span(),
                        0,
                        "an object name must be non-empty and contain no quote",
                    ));
                }
                match index.get(n).and_then(|&i| vocabulary.objects.get_mut(i)) {
                    Some(o) if !o.types.contains(ty) => o.types.push(ty.clone()),
                    Some(_) => {}
                    None => {
                        index.insert(n.to_string(), vocabulary.objects.len());
                        vocabulary.objects.push(Object {
                            name: n.to_string(),
                            types: vec![ty.clone()],
                            called: Vec::new(),
                        });
                    }
                }
            }
        }
    }
    Ok(vocabulary)
}

/// Add what each file's `[called]` table says people call its objects (a later file's
/// words join an earlier one's).
fn add_called(
    vocabulary: &mut Vocabulary,
    files: &[SourceFile],
    raws: &[RawFile],
) -> Result<(), ScenarioError> {
    for (raw, file) in raws.iter().zip(files) {
        for (name, words) in &raw.called {
            let Some(object) = vocabulary
                .objects
                .iter_mut()
                .find(|o| o.name == name.get_ref().trim())
            else {
                return Err(file.error_at(
                    name.span().start,
                    format_args!(
                        "[called] names {:?}, which is not an object",
                        name.get_ref()
                    ),
                ));
            };
            for word in words {
                let w = word.get_ref().trim();
                if w.is_empty() || w.contains(['"', '\n', '(', ')', ',']) {
                    return Err(file.error_in_string(
                        &word.span(),
                        0,
                        "what an object is called must be non-empty words without quotes, commas, parentheses or line breaks",
                    ));
                }
                if !object.called.iter().any(|c| c == w) {
                    object.called.push(w.to_string());
                }
            }
        }
    }
    Ok(())
}

/// A predicate's words for it and its opposite: each has a letter or digit, and none is
/// in both lists (it could not tell which way a request asks).
fn state_words(
    file: &SourceFile,
    says: &[Spanned<String>],
    opposite: &[Spanned<String>],
) -> Result<StateWords, ScenarioError> {
    if let Some(w) = without_letters(says.iter().chain(opposite)) {
        return Err(file.error_in_string(&w.span(), 0, "a word of a predicate has no letters"));
    }
    if let Some(w) = opposite
        .iter()
        .find(|o| says.iter().any(|s| same_phrase(s.get_ref(), o.get_ref())))
    {
        return Err(file.error_in_string(
            &w.span(),
            0,
            format!("{:?} is both in says and in opposite", w.get_ref()),
        ));
    }
    let plain = |list: &[Spanned<String>]| list.iter().map(|w| w.get_ref().clone()).collect();
    Ok(StateWords {
        says: plain(says),
        opposite: plain(opposite),
    })
}

/// The first of `words` with no letter or digit: it could match nothing a person says.
fn without_letters<'a>(
    words: impl IntoIterator<Item = &'a Spanned<String>>,
) -> Option<&'a Spanned<String>> {
    words
        .into_iter()
        .find(|w| !w.get_ref().chars().any(char::is_alphanumeric))
}

/// The same words, whatever the case and spacing.
fn same_phrase(a: &str, b: &str) -> bool {
    let words = |s: &str| {
        s.to_lowercase()
            .split_whitespace()
            .collect::<Vec<_>>()
            .join(" ")
    };
    words(a) == words(b)
}

/// Add every file's predicates to `vocabulary` (whose objects are complete); a later
/// file's predicate replaces an earlier one of the same name.
fn add_predicates(
    vocabulary: &mut Vocabulary,
    files: &[SourceFile],
    raws: &[RawFile],
) -> Result<(), ScenarioError> {
    for (raw, file) in raws.iter().zip(files) {
        for p in &raw.predicates {
            let mut arg_types = Vec::new();
            for a in &p.args {
                let types = split_types(a.get_ref());
                for t in &types {
                    if !vocabulary.is_type(t) && vocabulary.object(t).is_none() {
                        return Err(file.error_in_string(
                            &a.span(),
                            0,
                            format!("unknown type {t:?} (no object has it)"),
                        ));
                    }
                }
                arg_types.push(types);
            }
            let predicate = Predicate {
                name: p.name.get_ref().clone(),
                arg_types,
                description: p.description.clone(),
                words: state_words(file, &p.says, &p.opposite)?,
            };
            match vocabulary
                .predicates
                .iter_mut()
                .find(|q| q.name == predicate.name)
            {
                Some(q) => *q = predicate,
                None => vocabulary.predicates.push(predicate),
            }
        }
    }
    Ok(())
}

/// A goal of the `[scenario]` table, its errors located inside its string.
fn located_goal(
    file: &SourceFile,
    text: &Spanned<String>,
    vocabulary: &Vocabulary,
) -> Result<Formula, ScenarioError> {
    goal_in(text.get_ref(), vocabulary).map_err(|e| file.error_in_string(&text.span(), e.at(), e))
}

/// The worked examples of the last file that has any (its own, then its pool's), each
/// goal checked against the vocabulary: a predicate the domain lacks, or given the wrong
/// number of arguments, is refused with its file, line and column, as a mistyped example
/// would teach the model a condition that cannot be planned. Objects are not checked: a
/// pool's examples come from other situations of the domain, with their own objects.
fn examples(
    files: &[SourceFile],
    raws: &[RawFile],
    vocabulary: &Vocabulary,
) -> Result<Vec<Example>, ScenarioError> {
    let Some((file, raw)) = files.iter().zip(raws).rev().find(|(_, r)| {
        !r.examples.is_empty() || r.pooled.as_ref().is_some_and(|(_, p)| !p.is_empty())
    }) else {
        return Ok(Vec::new());
    };
    let own = raw.examples.iter().map(|e| (file, e));
    let pooled = raw
        .pooled
        .iter()
        .flat_map(|(pool, examples)| examples.iter().map(move |e| (pool, e)));
    own.chain(pooled)
        .map(|(file, e)| {
            super::goal_with_objects(e.goal.get_ref(), vocabulary, false)
                .map_err(|err| file.error_in_string(&e.goal.span(), err.at(), err))?;
            Ok(Example {
                instruction: e.instruction.clone(),
                goal: e.goal.get_ref().clone(),
                source: Default::default(),
            })
        })
        .collect()
}

/// The conventions of every file, base file first. A convention's `puts` names a
/// predicate of two arguments and one of its own objects, and comes with the words that
/// invoke it.
fn conventions(
    files: &[SourceFile],
    raws: &[RawFile],
    vocabulary: &Vocabulary,
) -> Result<Vec<Convention>, ScenarioError> {
    let mut out = Vec::new();
    for (file, raw) in files.iter().zip(raws) {
        for c in &raw.conventions {
            let puts = match (&c.puts, c.words.as_slice()) {
                (None, []) => None,
                (None, [first, ..]) => {
                    return Err(file.error_in_string(
                        &first.span(),
                        0,
                        "a convention with words needs `puts`: what they ask for",
                    ));
                }
                (Some(puts), words) => {
                    let at = puts.span().start;
                    let RawPuts { relation, place } = puts.get_ref();
                    if words.is_empty() {
                        return Err(file.error_at(
                            at,
                            "a convention's `puts` needs `words`: the request's words that invoke it",
                        ));
                    }
                    if let Some(w) = without_letters(words) {
                        return Err(file.error_in_string(
                            &w.span(),
                            0,
                            "a convention's word has no letters",
                        ));
                    }
                    if vocabulary
                        .predicate(relation)
                        .is_none_or(|p| p.arg_types.len() != 2)
                    {
                        return Err(file.error_at(
                            at,
                            format!(
                                "`puts` relation {relation:?} is not a predicate of two arguments"
                            ),
                        ));
                    }
                    if !c.objects.contains(place) {
                        return Err(file.error_at(
                            at,
                            format!(
                                "`puts` place {place:?} is not one of the convention's objects"
                            ),
                        ));
                    }
                    Some(ConventionPuts {
                        words: words.iter().map(|w| w.get_ref().clone()).collect(),
                        relation: relation.clone(),
                        place: place.clone(),
                    })
                }
            };
            out.push(Convention {
                text: c.text.trim().to_string(),
                objects: c.objects.clone(),
                puts,
            });
        }
    }
    Ok(out)
}

/// The simulator the last file that names one asks for (`symbolic` when none does).
fn world_kind(raws: &[RawFile]) -> String {
    raws.iter()
        .rev()
        .find_map(|r| r.world.as_ref()?.get("kind")?.as_str().map(str::to_string))
        .unwrap_or_else(|| "symbolic".to_string())
}

/// One skill, its templates checked against the vocabulary.
#[cfg(test)]
mod tests {
    use std::path::Path;

    use crate::scenario::Scenario;

    const BASE: &str = "[scenario]\nname = \"t\"\n\n[objects]\nitem = [\"Chips\", \"Cup\"]\n\n[[predicates]]\nname = \"Holding\"\nargs = [\"item\"]\ndescription = \"held\"\n\n";

    #[test]
    fn what_objects_are_called_reaches_the_vocabulary() {
        let text = format!("{BASE}[called]\nChips = [\"crisps\", \" fries \", \"crisps\"]\n");
        let s = Scenario::from_text(Path::new("t.toml"), text).unwrap();
        let chips = s
            .domain
            .vocabulary
            .objects
            .iter()
            .find(|o| o.name == "Chips")
            .unwrap();
        assert_eq!(
            chips.called,
            vec!["crisps".to_string(), "fries".to_string()]
        );
        let cup = s
            .domain
            .vocabulary
            .objects
            .iter()
            .find(|o| o.name == "Cup")
            .unwrap();
        assert!(cup.called.is_empty());
    }

    #[test]
    fn a_called_entry_for_no_object_or_with_a_bad_word_is_located() {
        let text = format!("{BASE}[called]\nFries = [\"chips\"]\n");
        let e = Scenario::from_text(Path::new("t.toml"), text).unwrap_err();
        assert_eq!((e.line, e.column), (13, 1), "{e}");
        assert!(
            e.message.contains("\"Fries\"") && e.message.contains("not an object"),
            "{e}"
        );

        let text = format!("{BASE}[called]\nChips = [\"crisps\", \"fries, chips\"]\n");
        let e = Scenario::from_text(Path::new("t.toml"), text).unwrap_err();
        assert_eq!((e.line, e.column), (13, 21), "{e}");
        assert!(e.message.contains("commas"), "{e}");
    }

    #[test]
    fn an_example_goal_is_checked_for_its_predicates_but_not_its_objects() {
        // Another situation's object passes; the predicate must be the domain's.
        let ok =
            format!("{BASE}[[examples]]\ninstruction = \"hold the tea\"\ngoal = \"Holding_Tea\"\n");
        let s = Scenario::from_text(Path::new("t.toml"), ok).unwrap();
        assert_eq!(s.examples[0].goal, "Holding_Tea");
        let typo = format!(
            "{BASE}[[examples]]\ninstruction = \"hold the cup\"\ngoal = \"Holding_Chips & Holdin_Cup\"\n"
        );
        let e = Scenario::from_text(Path::new("t.toml"), typo).unwrap_err();
        assert_eq!((e.line, e.column), (14, 25), "{e}");
        assert!(
            e.message.contains("Holdin") && e.message.contains("Holding"),
            "{e}"
        );

        // In a pool file, the error names the pool's file and line.
        let dir = std::env::temp_dir().join(format!("betr-pool-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(
            dir.join("pool.toml"),
            "[[examples]]\ninstruction = \"a\"\ngoal = \"Holding_Cup\"\n\n[[examples]]\ninstruction = \"b\"\ngoal = \"Holding_Cup_Chips\"\n",
        )
        .unwrap();
        let with_pool = BASE.replacen(
            "[scenario]",
            "example_pool = \"pool.toml\"\n\n[scenario]",
            1,
        );
        let e = Scenario::from_text(&dir.join("t.toml"), with_pool).unwrap_err();
        assert!(e.file.ends_with("pool.toml"), "{e}");
        assert_eq!(e.line, 7, "{e}");
        assert!(e.message.contains("argument"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
