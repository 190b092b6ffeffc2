//! The English every reader of requests knows, in one place: one list per kind of word,
//! each word in one list (a test checks it; the one word two lists share says why in
//! [`SHARED`]). What a domain's words mean — what its objects are called, the words that
//! ask for each predicate and its opposite, its conventions — is not here: it is data in
//! the domain's scenario file, read through [`super::lexicon::Lexicon`].

/// How a word joins what follows it to what came before.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Join {
    And,
    Or,
}

/// Words that introduce a noun and say nothing of what is asked.
pub const ARTICLES: &[&str] = &["a", "an", "the", "some", "any"];

/// Words that soften a request without changing it ("maybe bring", "either the milk").
pub const HEDGES: &[&str] = &["either", "maybe", "perhaps"];

/// Words that ask for every object of the kind named after them ("both vents", "all the
/// tables").
pub const QUANTIFIERS: &[&str] = &["both", "all", "every", "each"];

/// Words that restrict what follows: before a verb they soften it ("or just bring"),
/// before a thing they make it the only one ("or just a mug").
pub const RESTRICTING: &[&str] = &["just"];

/// Conjunctions proper: they join two things in one wish ("water and chips") or two wishes
/// ("clean the chairs and deliver coffee").
pub const CONJUNCTIONS: &[(&str, Join)] =
    &[("and", Join::And), ("but", Join::And), ("or", Join::Or)];

/// Words that link a clause to the one before; `true` where the word after a comma begins
/// a wish of its own ("…, also bring water"; "…, so it is warm" does not).
pub const LINKING: &[(&str, Join, bool)] = &[
    ("also", Join::And, true),
    ("then", Join::And, true),
    ("while", Join::And, false),
    ("so", Join::And, false),
    ("otherwise", Join::Or, true),
    ("else", Join::Or, true),
    ("alternatively", Join::Or, true),
    ("instead", Join::Or, false),
];

/// Phrases that begin a wish of their own after a comma, with how they join it; any of
/// them or of the wish-opening [`LINKING`] words may follow a conjunction ("or if not").
pub const OPENING_PHRASES: &[(&str, Join)] = &[
    ("after that", Join::And),
    ("at least", Join::Or),
    ("if not", Join::Or),
    ("failing that", Join::Or),
    ("if you can't", Join::Or),
    ("if you cannot", Join::Or),
    ("if that's not possible", Join::Or),
    ("if that is not possible", Join::Or),
];

/// Words that turn around what follows them in their clause ("n't" is read as "not").
pub const NEGATIONS: &[&str] = &["not", "no", "never", "nor", "neither", "without", "cannot"];

/// Words of a statement that only link what it says of an object to the object ("the red
/// cube *is still* on the blue cube", "it *lies* on").
pub const BEING: &[&str] = &[
    "is",
    "are",
    "was",
    "were",
    "be",
    "been",
    "being",
    "has",
    "have",
    "had",
    "still",
    "currently",
    "already",
    "now",
    "also",
    "remains",
    "stays",
    "lies",
    "rests",
    "sits",
    "stands",
    "placed",
    "located",
];

/// Words by which a statement says what must hold rather than what holds ("the cube
/// *must* not be on the table", "*needs to* be").
pub const NEEDING: &[&str] = &[
    "must", "should", "need", "needs", "needed", "to", "ought", "required",
];

/// Words by which a statement names the condition a failure lacks ("the *missing*
/// condition is").
pub const MISSING: &[&str] = &["missing", "lacking", "lacks", "absent"];

/// Words by which a clause only supposes ("*if* the cube were on the table") and claims
/// nothing of the world.
pub const HYPOTHETICAL: &[&str] = &[
    "if", "once", "after", "when", "until", "unless", "would", "could", "might", "may", "will",
    "whether", "suppose",
];

/// Verbs that ask for something not to happen ("avoid the bar", "forget the milk").
pub const NEGATING_VERBS: &[&str] = &["avoid", "forget", "refrain"];

/// Words that only announce a number ("table No. 6", "number one", "bar nr 2").
pub const NUMBERING: &[&str] = &["no", "no.", "number", "nr", "nr.", "num", "#"];

/// Numbers written as words, cardinal and ordinal, with their digits.
pub const NUMBERS: &[(&str, &str, &str)] = &[
    ("one", "first", "1"),
    ("two", "second", "2"),
    ("three", "third", "3"),
    ("four", "fourth", "4"),
    ("five", "fifth", "5"),
    ("six", "sixth", "6"),
    ("seven", "seventh", "7"),
    ("eight", "eighth", "8"),
    ("nine", "ninth", "9"),
    ("ten", "tenth", "10"),
];

/// Verbs that send or give a thing somewhere.
pub const SENDING_VERBS: &[&str] = &[
    "bring", "deliver", "serve", "take", "put", "place", "fetch", "carry", "give", "send", "hand",
    "set",
];

/// Verbs of the robot's own moving: an item before one is not sent to a place after it
/// ("make coffee and come to table 2").
pub const MOVING_VERBS: &[&str] = &[
    "come", "go", "move", "head", "walk", "drive", "return", "join", "meet", "visit", "approach",
    "proceed", "stay", "wait",
];

/// Verbs that ask for a state of a thing ("open", "clean", "switch").
pub const STATE_VERBS: &[&str] = &[
    "prepare",
    "brew",
    "turn",
    "switch",
    "open",
    "close",
    "shut",
    "clean",
    "sweep",
    "wipe",
    "mop",
    "tidy",
    "clear",
    "wash",
    "hold",
    "grab",
    "pick",
    "draw",
    "activate",
    "deactivate",
    "remove",
    "lower",
    "raise",
    "increase",
    "decrease",
];

/// Verbs that ask, but for nothing by themselves ("make sure", "keep", "leave it").
pub const LIGHT_VERBS: &[&str] = &["make", "keep", "leave", "ensure", "check", "try"];

/// The ways of asking before a verb ("could you", "please", "do").
pub const MODALS: &[&str] = &["could", "can", "would", "will", "please", "do"];

/// Words by which a wish refers to the thing of the wish before it.
pub const BACK_REFERENCES: &[&str] = &["it", "them", "it's", "its", "they", "those", "these"];

/// Words that send an item to the place named after them.
pub const TOWARDS: &[&str] = &["to", "at", "on", "onto", "into", "in"];

/// Words that say where an item comes from, not where it goes ("bring the lettuce in
/// from the cold frame to the bench").
pub const SOURCES: &[&str] = &["from"];

/// Words of courtesy and time that ask for nothing ("thanks", "right away").
pub const COURTESY: &[&str] = &[
    "need", "have", "now", "too", "right", "away", "thank", "thanks", "kindly", "over",
];

/// Other words that say nothing about what is asked.
pub const FUNCTION_WORDS: &[&str] = &[
    "of", "for", "me", "my", "i", "im", "you", "your", "is", "be", "that", "this", "with", "by",
    "up", "we", "us", "our", "id", "like", "want", "there", "here", "am", "are", "was", "get",
    "let", "mind", "object",
];

/// Words that never name a symbol of a scene: an instruction's "robot" asks for nothing.
pub const ROBOT_WORDS: &[&str] = &["robot", "nothing"];

/// The words two lists share, and why.
pub const SHARED: &[(&str, &str)] = &[(
    "no",
    "a negation, and before a number only the announcement of the number (\"table No. 6\")",
)];

fn has(list: &[&str], word: &str) -> bool {
    list.contains(&word)
}

/// Whether `word` asks for every object of the kind named after it.
pub fn is_quantifier(word: &str) -> bool {
    has(QUANTIFIERS, word)
}

/// Whether `word` says nothing about what is asked (matches are made without it).
pub fn is_stopword(word: &str) -> bool {
    has(ARTICLES, word)
        || has(HEDGES, word)
        || has(RESTRICTING, word)
        || CONJUNCTIONS.iter().any(|(w, _)| *w == word)
        || LINKING.iter().any(|(w, _, _)| *w == word)
        || has(TOWARDS, word)
        || has(MODALS, word)
        || has(BACK_REFERENCES, word)
        || has(FUNCTION_WORDS, word)
}

/// Whether `word` never names a symbol.
pub fn is_generic(word: &str) -> bool {
    is_stopword(word) || has(ROBOT_WORDS, word)
}

/// Whether `word` turns around what follows it.
pub fn is_negation(word: &str) -> bool {
    has(NEGATIONS, word) || has(NEGATING_VERBS, word)
}

/// Whether `word` (lower case) negates as a contraction ("don't", "won't", "dont").
pub fn is_negated_form(word: &str) -> bool {
    word.ends_with("n't") || word.ends_with("n’t") || word == "dont"
}

/// Whether `word` (lower case) begins a wish: a verb requests ask with, a way of asking,
/// or their negated form ("don't").
pub fn asks(word: &str) -> bool {
    has(SENDING_VERBS, word)
        || has(MOVING_VERBS, word)
        || has(STATE_VERBS, word)
        || has(LIGHT_VERBS, word)
        || has(MODALS, word)
        || has(NEGATING_VERBS, word)
        || is_negated_form(word)
}

/// Whether `word` asks for no condition by itself: how a request is phrased, not what it
/// asks for.
pub fn is_phrasing(word: &str) -> bool {
    has(SENDING_VERBS, word)
        || has(MOVING_VERBS, word)
        || has(LIGHT_VERBS, word)
        || has(COURTESY, word)
}

/// Whether `word` may stand between a conjunction and the verb of the wish it begins
/// ("or maybe bring", "and then clean").
pub fn may_precede_verb(word: &str) -> bool {
    has(HEDGES, word) || has(RESTRICTING, word) || opens_and(word)
}

/// A linking word that opens a wish joined by "and" ("also", "then").
fn opens_and(word: &str) -> bool {
    LINKING
        .iter()
        .any(|(w, j, opens)| *w == word && *opens && *j == Join::And)
}

/// Whether `word` may stand between a conjunction and the thing it joins ("or a dessert",
/// "and either the milk").
pub fn may_precede_thing(word: &str) -> bool {
    has(ARTICLES, word) || has(HEDGES, word) || opens_and(word)
}

/// How `word` joins clauses, when it starts one ("and", "but", "or", "also", "then", ...).
pub fn clause_start(word: &str) -> Option<Join> {
    CONJUNCTIONS
        .iter()
        .map(|(w, j)| (*w, *j))
        .chain(LINKING.iter().map(|(w, j, _)| (*w, *j)))
        .find(|(w, _)| *w == word)
        .map(|(_, j)| j)
}

/// Whether `word` offers a choice between what comes before and after it.
pub fn offers_choice(word: &str) -> bool {
    clause_start(word) == Some(Join::Or)
}

/// The phrases that begin a wish of their own after a comma, longest first, with how they
/// join: the wish-opening [`LINKING`] words and [`OPENING_PHRASES`], alone or after a
/// conjunction ("and also", "or if not").
pub fn wish_openers() -> Vec<(String, Join)> {
    let alone: Vec<(String, Join)> = LINKING
        .iter()
        .filter(|(_, _, opens)| *opens)
        .map(|(w, j, _)| (w.to_string(), *j))
        .chain(OPENING_PHRASES.iter().map(|(p, j)| (p.to_string(), *j)))
        .collect();
    let mut out: Vec<(String, Join)> = CONJUNCTIONS
        .iter()
        .flat_map(|(c, _)| {
            // "but alternatively" is no opener people say; "and"/"or" before one are.
            alone
                .iter()
                .filter(move |(_, j)| *c != "but" && (*c == "and") == (*j == Join::And))
                .map(move |(p, j)| (format!("{c} {p}"), *j))
        })
        .chain(alone.iter().cloned())
        .collect();
    out.sort_by(|a, b| b.0.len().cmp(&a.0.len()).then(a.0.cmp(&b.0)));
    out
}

/// The digit a number word stands for ("three", "third" → "3").
pub fn number_digit(word: &str) -> Option<&'static str> {
    NUMBERS
        .iter()
        .find(|(cardinal, ordinal, _)| word == *cardinal || word == *ordinal)
        .map(|(_, _, digit)| *digit)
}

/// Whether `word` is a cardinal number word ("six").
pub fn is_number_word(word: &str) -> bool {
    NUMBERS.iter().any(|(cardinal, _, _)| *cardinal == word)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every list with its name, as entries (a phrase is one entry).
    fn lists() -> Vec<(&'static str, Vec<String>)> {
        let plain = |l: &[&str]| l.iter().map(|w| w.to_string()).collect::<Vec<_>>();
        vec![
            ("ARTICLES", plain(ARTICLES)),
            ("HEDGES", plain(HEDGES)),
            ("RESTRICTING", plain(RESTRICTING)),
            (
                "CONJUNCTIONS",
                CONJUNCTIONS.iter().map(|(w, _)| w.to_string()).collect(),
            ),
            (
                "LINKING",
                LINKING.iter().map(|(w, _, _)| w.to_string()).collect(),
            ),
            (
                "OPENING_PHRASES",
                OPENING_PHRASES.iter().map(|(w, _)| w.to_string()).collect(),
            ),
            ("NEGATIONS", plain(NEGATIONS)),
            ("NEGATING_VERBS", plain(NEGATING_VERBS)),
            ("NUMBERING", plain(NUMBERING)),
            (
                "NUMBERS",
                NUMBERS
                    .iter()
                    .flat_map(|(c, o, d)| [c.to_string(), o.to_string(), d.to_string()])
                    .collect(),
            ),
            ("QUANTIFIERS", plain(QUANTIFIERS)),
            ("SENDING_VERBS", plain(SENDING_VERBS)),
            ("MOVING_VERBS", plain(MOVING_VERBS)),
            ("STATE_VERBS", plain(STATE_VERBS)),
            ("LIGHT_VERBS", plain(LIGHT_VERBS)),
            ("MODALS", plain(MODALS)),
            ("BACK_REFERENCES", plain(BACK_REFERENCES)),
            ("TOWARDS", plain(TOWARDS)),
            ("SOURCES", plain(SOURCES)),
            ("COURTESY", plain(COURTESY)),
            ("FUNCTION_WORDS", plain(FUNCTION_WORDS)),
            ("ROBOT_WORDS", plain(ROBOT_WORDS)),
        ]
    }

    #[test]
    fn no_two_lists_share_a_word_unless_said_why() {
        let lists = lists();
        let mut clashes = Vec::new();
        for (i, (a, words)) in lists.iter().enumerate() {
            let mut seen = words.clone();
            seen.sort();
            let before = seen.len();
            seen.dedup();
            assert_eq!(before, seen.len(), "{a} lists a word twice");
            for (b, other) in &lists[i + 1..] {
                for w in words.iter().filter(|w| other.contains(w)) {
                    if !SHARED.iter().any(|(s, _)| s == w) {
                        clashes.push(format!("{w:?} in {a} and {b}"));
                    }
                }
            }
        }
        assert!(clashes.is_empty(), "words in two lists: {clashes:?}");
    }

    #[test]
    fn every_shared_word_is_in_two_lists() {
        for (word, why) in SHARED {
            let holders = lists()
                .into_iter()
                .filter(|(_, l)| l.iter().any(|w| w == word))
                .count();
            assert!(
                holders >= 2,
                "{word:?} is said to be shared ({why}) but is not"
            );
        }
    }

    #[test]
    fn derived_sets_follow_the_lists() {
        assert!(asks("bring") && asks("don't") && asks("avoid") && asks("could"));
        assert!(!asks("milk") && !asks("and"));
        assert!(offers_choice("or") && offers_choice("otherwise") && !offers_choice("and"));
        assert_eq!(clause_start("but"), Some(Join::And));
        assert!(is_stopword("the") && is_stopword("please") && !is_stopword("table"));
        assert!(is_phrasing("bring") && is_phrasing("thanks") && !is_phrasing("clean"));
        let openers = wish_openers();
        for (phrase, join) in [
            ("and also", Join::And),
            ("or if not", Join::Or),
            ("failing that", Join::Or),
            ("then", Join::And),
        ] {
            assert!(
                openers.contains(&(phrase.to_string(), join)),
                "{phrase}: {openers:?}"
            );
        }
        assert!(
            !openers
                .iter()
                .any(|(p, _)| p == "and otherwise" || p == "so")
        );
        // Longest first, so "or if not" is found before "if not".
        assert!(openers.windows(2).all(|w| w[0].0.len() >= w[1].0.len()));
        assert_eq!(number_digit("third"), Some("3"));
    }
}
