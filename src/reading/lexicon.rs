//! Which words of a request each predicate and object of a scene can answer to, so that a
//! goal can be checked part by part against what was asked.
//!
//! A symbol answers to the words of its own name (`WindowTable6` → window, table, 6;
//! `IsClean` → clean), an object to what the scene says it is called (`Chips` → crisps,
//! fries), and both to the words the scene's example pool pairs with it: a word of
//! the pool's instructions that occurs mostly in examples whose goal uses the symbol
//! ("sweep" with `IsClean`, "deliver" with `On`). Nothing is written by hand per
//! scene: a new scene's pool teaches its own words.

use std::collections::HashMap;

use crate::domain::Vocabulary;
use crate::goal::Formula;
use crate::scenario::Example;

use super::english::is_generic;
use super::words::{same_word, terms};

/// How many examples must use a word with an object before it is taken as the object's
/// word: one example's "sitting" is not a soft drink's word because the example asked a
/// sitting guest for one. Objects have their names and what they are called; a
/// predicate's words are many and varied, and one example teaches one ("lower").
const MIN_TOGETHER: usize = 2;

/// A word of the pool becomes a symbol's word when at least this share of the examples
/// that use the word use the symbol too.
const MIN_SHARE: f64 = 0.5;

#[derive(Debug, Clone, Default, PartialEq)]
pub struct Lexicon {
    words: HashMap<String, Vec<String>>,
    /// The words of the objects' own names (table, 6, coffee, station, ...).
    object_words: Vec<String>,
    /// Words that name an object by themselves: a one-word name (`Chips`) or a one-word
    /// thing it is called ("fries"), not a part of a longer name ("area" of `LoungeArea`).
    whole_names: Vec<String>,
}

impl Lexicon {
    /// The words of `vocabulary`'s predicates and objects, and those `pool` teaches.
    pub fn new(vocabulary: &Vocabulary, pool: &[Example]) -> Self {
        let mut words = own_words(vocabulary);
        let mut object_words: Vec<String> = vocabulary
            .objects
            .iter()
            .flat_map(|o| words.get(&o.name).cloned().unwrap_or_default())
            .collect();
        object_words.sort_unstable();
        object_words.dedup();
        let (uses, together) = count_pool(pool);
        learn_from_pool(&mut words, vocabulary, &uses, &together);
        let mut whole_names: Vec<String> = vocabulary
            .objects
            .iter()
            .flat_map(|o| {
                std::iter::once(o.name.as_str()).chain(o.called.iter().map(String::as_str))
            })
            .map(terms)
            .filter(|t| t.len() == 1 && !is_generic(&t[0]))
            .map(|mut t| t.remove(0))
            .collect();
        whole_names.sort_unstable();
        whole_names.dedup();
        Lexicon {
            words,
            object_words,
            whole_names,
        }
    }

    /// Whether `word` is part of some object's name ("6" of `WindowTable6`).
    pub fn names_an_object(&self, word: &str) -> bool {
        self.object_words.iter().any(|w| same_word(w, word))
    }

    /// Whether `word` names an object by itself ("fries", "coffee"), not as a part of a
    /// longer name ("area", "table").
    pub fn names_an_object_alone(&self, word: &str) -> bool {
        self.whole_names.iter().any(|w| same_word(w, word))
    }

    /// Whether some predicate or object of the scene answers to `word`.
    pub fn knows(&self, word: &str) -> bool {
        self.words
            .values()
            .any(|list| list.iter().any(|w| same_word(w, word)))
    }

    /// The words `symbol` answers to (none for a name the scene does not have).
    pub fn words(&self, symbol: &str) -> &[String] {
        self.words.get(symbol).map_or(&[], Vec::as_slice)
    }

    /// The words of `request` (as [`terms`] gives them) that some predicate or object of
    /// `part` answers to.
    pub fn covered(&self, part: &Formula, request: &[String]) -> Vec<String> {
        let mut symbols: Vec<&str> = Vec::new();
        let atoms = part.atoms();
        for atom in &atoms {
            symbols.push(&atom.predicate);
            symbols.extend(atom.args.iter().map(String::as_str));
        }
        request
            .iter()
            .filter(|w| {
                symbols
                    .iter()
                    .any(|s| self.words(s).iter().any(|x| same_word(x, w)))
            })
            .cloned()
            .collect()
    }
}

/// Each predicate's and object's own words: those of its name, what an object is called,
/// and the words the scene lists for a predicate.
fn own_words(vocabulary: &Vocabulary) -> HashMap<String, Vec<String>> {
    let mut words: HashMap<String, Vec<String>> = HashMap::new();
    let names = vocabulary
        .predicates
        .iter()
        .map(|p| p.name.as_str())
        .chain(vocabulary.objects.iter().map(|o| o.name.as_str()));
    for name in names {
        let own: Vec<String> = terms(name).into_iter().filter(|t| !is_generic(t)).collect();
        words.insert(name.to_string(), own);
    }
    // What an object is called is its own too ("fries" is `Chips`'s word).
    for object in &vocabulary.objects {
        let list = words.entry(object.name.clone()).or_default();
        for word in object.called.iter().flat_map(|c| terms(c)) {
            if !is_generic(&word) && !list.contains(&word) {
                list.push(word);
            }
        }
    }
    // So are the words the scene lists for a predicate, either way round ("come to"
    // and "near" for the robot near a place, "off" for a device on).
    for predicate in &vocabulary.predicates {
        let list = words.entry(predicate.name.clone()).or_default();
        let said = predicate.words.says.iter().chain(&predicate.words.opposite);
        for word in said.flat_map(|c| terms(c)) {
            if !is_generic(&word) && !list.contains(&word) {
                list.push(word);
            }
        }
    }
    words
}

/// How many examples use a word.
type Uses = HashMap<String, usize>;
/// How many examples use a word together with a symbol, by (symbol, word).
type Together = HashMap<(String, String), usize>;

/// How many examples of `pool` use each word, and each word together with each symbol of
/// their goal (examples whose goal does not parse are left out).
fn count_pool(pool: &[Example]) -> (Uses, Together) {
    let mut uses: Uses = HashMap::new();
    let mut together: Together = HashMap::new();
    for example in pool {
        let Ok(goal) = Formula::parse(&example.goal) else {
            continue;
        };
        let mut symbols: Vec<String> = Vec::new();
        for atom in goal.atoms() {
            for s in std::iter::once(&atom.predicate).chain(&atom.args) {
                if !symbols.contains(s) {
                    symbols.push(s.clone());
                }
            }
        }
        let mut said = terms(&example.instruction);
        said.sort_unstable();
        said.dedup();
        for w in said {
            *uses.entry(w.clone()).or_default() += 1;
            for s in &symbols {
                *together.entry((s.clone(), w.clone())).or_default() += 1;
            }
        }
    }
    (uses, together)
}

/// Add to `words` each word the pool uses mostly with a symbol, when no symbol is named
/// by it: a word that names a symbol belongs to that symbol alone ("coffee" is Coffee's
/// word even though most requests for coffee also use On).
fn learn_from_pool(
    words: &mut HashMap<String, Vec<String>>,
    vocabulary: &Vocabulary,
    uses: &Uses,
    together: &Together,
) {
    let named: Vec<String> = words.values().flatten().cloned().collect();
    let objects: Vec<&str> = vocabulary.objects.iter().map(|o| o.name.as_str()).collect();
    let mut learned: Vec<(&(String, String), &usize)> = together.iter().collect();
    learned.sort();
    for ((symbol, word), n) in learned {
        let total = uses.get(word).copied().unwrap_or(0).max(1);
        let known = words.contains_key(symbol);
        let names_other = named.iter().any(|x| same_word(x, word));
        if known
            && !names_other
            && (*n >= MIN_TOGETHER || !objects.contains(&symbol.as_str()))
            && *n as f64 / total as f64 >= MIN_SHARE
            && !is_generic(word)
        {
            let list = words.entry(symbol.clone()).or_default();
            if !list.contains(word) {
                list.push(word.clone());
            }
        }
    }
}

/// `goal` with the alternatives of every `|` in the order `request` (as [`terms`] gives
/// it) names them: a behavior tree tries a fallback's alternatives in order, and "fries or
/// a dessert" asks for the fries first. An alternative is placed by the first word of the
/// request that it answers to and its sibling alternatives do not (the table both are
/// brought to places neither); one that no such word names keeps its place after those
/// that are named.
pub fn in_request_order(lexicon: &Lexicon, goal: &Formula, request: &[String]) -> Formula {
    match goal {
        Formula::Atom(_) => goal.clone(),
        Formula::Not(inner) => Formula::Not(Box::new(in_request_order(lexicon, inner, request))),
        Formula::And(items) => Formula::And(
            items
                .iter()
                .map(|i| in_request_order(lexicon, i, request))
                .collect(),
        ),
        Formula::Or(items) => {
            let items: Vec<Formula> = items
                .iter()
                .map(|i| in_request_order(lexicon, i, request))
                .collect();
            let covered: Vec<Vec<String>> =
                items.iter().map(|i| lexicon.covered(i, request)).collect();
            let first_own_word = |k: usize| {
                request.iter().position(|w| {
                    covered[k].contains(w)
                        && covered
                            .iter()
                            .enumerate()
                            .any(|(j, other)| j != k && !other.contains(w))
                })
            };
            let mut order: Vec<(usize, Formula)> = items
                .into_iter()
                .enumerate()
                .map(|(k, item)| (first_own_word(k).unwrap_or(usize::MAX), item))
                .collect();
            order.sort_by_key(|(at, _)| *at);
            Formula::Or(order.into_iter().map(|(_, item)| item).collect())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::{Object, Predicate};

    fn vocabulary() -> Vocabulary {
        let object = |n: &str, t: &str| Object {
            name: n.into(),
            types: vec![t.into()],
            called: Vec::new(),
        };
        let predicate = |n: &str, args: &[&str]| Predicate {
            name: n.into(),
            arg_types: args.iter().map(|a| vec![(*a).to_string()]).collect(),
            description: String::new(),
            words: Default::default(),
        };
        Vocabulary {
            objects: vec![
                object("Floor", "furniture"),
                object("Chairs", "furniture"),
                object("Coffee", "item"),
                object("WindowTable6", "place"),
            ],
            predicates: vec![
                predicate("IsClean", &["furniture"]),
                predicate("On", &["item", "place"]),
                predicate("RobotNear", &["place"]),
            ],
        }
    }

    fn example(instruction: &str, goal: &str) -> Example {
        Example {
            instruction: instruction.into(),
            goal: goal.into(),
            source: Default::default(),
        }
    }

    #[test]
    fn names_and_pool_give_words() {
        let pool = [
            example("Sweep the floor.", "IsClean_Floor"),
            example("Sweep up under the chairs.", "IsClean_Chairs"),
            example(
                "Deliver a coffee to window table six.",
                "On_Coffee_WindowTable6",
            ),
            example("Wait for me at window table six.", "RobotNear_WindowTable6"),
        ];
        let lexicon = Lexicon::new(&vocabulary(), &pool);
        assert!(lexicon.words("IsClean").contains(&"clean".to_string()));
        assert!(lexicon.words("IsClean").contains(&"sweep".to_string()));
        assert!(lexicon.words("WindowTable6").contains(&"6".to_string()));
        assert!(lexicon.words("On").contains(&"deliver".to_string()));
        // "window" is used with both On and RobotNear: it names the table, not either.
        assert!(lexicon.words("RobotNear").contains(&"wait".to_string()));
        assert!(!lexicon.words("IsClean").contains(&"window".to_string()));
        assert!(lexicon.words("Unknown").is_empty());
    }

    #[test]
    fn a_part_covers_the_words_its_symbols_answer_to() {
        let lexicon = Lexicon::new(&vocabulary(), &[]);
        let request = terms("Bring a coffee to the sixth table by the window");
        let part = Formula::parse("On_Coffee_WindowTable6").expect("parses");
        let covered = lexicon.covered(&part, &request);
        assert!(covered.contains(&"coffee".to_string()));
        assert!(covered.contains(&"6".to_string()));
        let unrelated = Formula::parse("IsClean_Floor").expect("parses");
        assert!(lexicon.covered(&unrelated, &request).is_empty());
    }

    #[test]
    fn the_words_a_scene_lists_for_a_predicate_are_its_own() {
        let mut v = vocabulary();
        if let Some(near) = v.predicates.iter_mut().find(|p| p.name == "RobotNear") {
            near.words.says = vec!["come to".into()];
            near.words.opposite = vec!["stay away".into()];
        }
        let lexicon = Lexicon::new(&v, &[]);
        let words = lexicon.words("RobotNear");
        assert!(words.contains(&"come".to_string()), "{words:?}");
        assert!(words.contains(&"away".to_string()), "{words:?}");
    }

    #[test]
    fn spellings_of_a_longer_word_are_one_word() {
        assert!(same_word("yoghurt", "yogurt"));
        assert!(!same_word("water", "waiter"));
        assert!(!same_word("chips", "chops"));
        assert!(same_word("clean", "cleaning"));
        assert!(!same_word("water", "watermelon"));
    }

    #[test]
    fn an_object_learns_a_word_from_two_examples_not_one() {
        let v = vocabulary();
        let example = |instruction: &str, goal: &str| Example {
            instruction: instruction.into(),
            goal: goal.into(),
            source: Default::default(),
        };
        let once = [example(
            "I'm sitting by the window, a soda please",
            "On_Coffee_Table1",
        )];
        assert!(
            !Lexicon::new(&v, &once)
                .words("Coffee")
                .contains(&"sitt".to_string())
        );
        let twice = [
            example(
                "I'm sitting by the window, a soda please",
                "On_Coffee_Table1",
            ),
            example("sitting here, a soda", "On_Coffee_Table1"),
        ];
        assert!(
            Lexicon::new(&v, &twice)
                .words("Coffee")
                .contains(&"sitt".to_string())
        );
    }
}

#[cfg(test)]
mod order_tests {
    use super::*;
    use crate::domain::{Object, Predicate};

    fn lexicon() -> Lexicon {
        let object = |n: &str, t: &str, called: &[&str]| Object {
            name: n.into(),
            types: vec![t.into()],
            called: called.iter().map(|c| (*c).to_string()).collect(),
        };
        let vocabulary = Vocabulary {
            objects: vec![
                object("Chips", "item", &["crisps", "fries"]),
                object("Dessert", "item", &[]),
                object("Coffee", "item", &[]),
                object("Table3", "place", &[]),
                object("AC", "appliance", &["air conditioning"]),
            ],
            predicates: vec![
                Predicate {
                    name: "On".into(),
                    arg_types: vec![vec!["item".into()], vec!["place".into()]],
                    description: String::new(),
                    words: Default::default(),
                },
                Predicate {
                    name: "Active".into(),
                    arg_types: vec![vec!["appliance".into()]],
                    description: String::new(),
                    words: Default::default(),
                },
            ],
        };
        Lexicon::new(&vocabulary, &[])
    }

    fn ordered(goal: &str, request: &str) -> String {
        let goal = Formula::parse(goal).expect("parses");
        in_request_order(&lexicon(), &goal, &terms(request)).to_string()
    }

    #[test]
    fn alternatives_follow_the_order_the_request_names_them() {
        // What an object is called places it too; the table both go to places neither.
        assert_eq!(
            ordered(
                "On_Dessert_Table3 | On_Chips_Table3",
                "I'm at the third table, bring me fries or a dessert"
            ),
            "On_Chips_Table3 | On_Dessert_Table3"
        );
        // Inside a conjunction, and already in order: unchanged.
        assert_eq!(
            ordered(
                "Active_AC & (On_Coffee_Table3 | On_Dessert_Table3)",
                "Turn on the air conditioning and bring a coffee or a dessert to table 3"
            ),
            "Active_AC & (On_Coffee_Table3 | On_Dessert_Table3)"
        );
        // An alternative no word names keeps its place after the named ones.
        assert_eq!(
            ordered(
                "Active_AC | On_Coffee_Table3 | On_Dessert_Table3",
                "a dessert, or else a coffee, at table three"
            ),
            "On_Dessert_Table3 | On_Coffee_Table3 | Active_AC"
        );
    }
}
