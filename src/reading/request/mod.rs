//! A request read once, with the scene it is read in: its words, its clauses and
//! sentences, the negation scopes its conditions are read in, the choices it offers, and
//! (computed on first use, then kept) the scene's objects it mentions, what it asks for
//! in the scene's words and the kinds it asks for every object of. Every reader of a request takes this value, so no reader
//! splits the text again.
//!
//! What a request is read into is computed here, and the readers import it from here:
//! its clauses, negation scopes and choices ([`mod@clauses`]), where its words name the
//! scene's objects ([`mod@mentions`]), what it asks for one way in each negation scope
//! ([`mod@asked`]), the items it sends to a place ([`mod@sent`]) and the kinds it asks for
//! every object of ([`mod@every_of_kind`]).

use std::sync::OnceLock;

use crate::domain::{Atom, Object, Vocabulary};
use crate::scenario::{Convention, Scenario};

use super::lexicon::Lexicon;
use super::words::{every_term, terms};

pub mod asked;
pub mod clauses;
pub mod every_of_kind;
pub mod mentions;
pub mod sent;

use asked::{Asked, asked_in_sentences};
use clauses::{choices_offered, clauses, without_numbering};
use every_of_kind::{EveryOfKind, every_of_kind_in};
use mentions::mentions;
use sent::{Sent, relating, sent};

/// Where a run of words names one of the scene's objects: (first word, how many words,
/// the object's name).
pub type Mention = (usize, usize, String);

/// A negation scope: a clause of a sentence, in which each negation before a word of a
/// predicate turns it around.
#[derive(Debug, Clone, PartialEq)]
pub struct Scope {
    /// The clause's words as [`every_term`] gives them, "n't" as "not".
    pub words: Vec<String>,
    /// Whether the clause's sentence offers a choice ("or", "either"): what it asks for
    /// may be one alternative of several.
    pub choice: bool,
}

/// A request read once; see the module.
pub struct Request<'a> {
    /// The request as the person wrote it.
    pub text: &'a str,
    /// Its words as [`terms`] gives them (stop words dropped).
    pub terms: Vec<String>,
    /// Its words as [`every_term`] gives them (stop words kept), as written.
    pub words: Vec<String>,
    /// Its words with those that only announce a number left out ("table No. 6" is
    /// table, 6), stop words kept.
    pub unnumbered_words: Vec<String>,
    /// Its clauses, cut at punctuation and commas, each as [`every_term`] gives it, with
    /// the words that only announce a number left out.
    pub clauses: Vec<Vec<String>>,
    /// Its sentences, cut at `.`, `;`, `!` and `?`, each as [`every_term`] gives it, with
    /// the words that only announce a number left out.
    pub sentences: Vec<Vec<String>>,
    /// The clauses a negation turns the words after it around in, sentence by sentence.
    pub scopes: Vec<Scope>,
    /// How many choices it offers: each "or" (and "if not", ...), and each comma of a
    /// list that ends in "or".
    pub choices: usize,
    pub vocabulary: &'a Vocabulary,
    /// The scene's conventions (what some words ask for by the scene's custom).
    pub conventions: &'a [Convention],
    pub lexicon: &'a Lexicon,
    mentions: OnceLock<Vec<Mention>>,
    clause_mentions: OnceLock<Vec<Vec<Mention>>>,
    asked: OnceLock<Vec<Asked>>,
    sent: OnceLock<Vec<Sent>>,
    every_of_kind: OnceLock<Vec<EveryOfKind>>,
}

impl<'a> Request<'a> {
    /// `text` read in `scenario`, whose words `lexicon` knows.
    pub fn new(text: &'a str, scenario: &'a Scenario, lexicon: &'a Lexicon) -> Self {
        Self::in_scene(
            text,
            &scenario.domain.vocabulary,
            &scenario.conventions,
            lexicon,
        )
    }

    /// `text` read among `vocabulary`'s objects and predicates, with `conventions`.
    pub fn in_scene(
        text: &'a str,
        vocabulary: &'a Vocabulary,
        conventions: &'a [Convention],
        lexicon: &'a Lexicon,
    ) -> Self {
        let unnumbered = without_numbering(text);
        let split_words = |marks: &[char]| -> Vec<Vec<String>> {
            unnumbered.split(marks).map(every_term).collect()
        };
        let sentences = split_words(&['.', ';', '!', '?']);
        let scopes = unnumbered
            .split(['.', '!', '?', ';'])
            .zip(&sentences)
            .flat_map(|(sentence, words)| {
                let choice = words.iter().any(|w| w == "or" || w == "either");
                clauses(sentence)
                    .into_iter()
                    .map(move |words| Scope { words, choice })
            })
            .collect();
        Request {
            text,
            terms: terms(text),
            words: every_term(text),
            unnumbered_words: every_term(&unnumbered),
            clauses: split_words(&['.', ';', '!', '?', ',']),
            sentences,
            scopes,
            choices: choices_offered(text),
            vocabulary,
            conventions,
            lexicon,
            mentions: OnceLock::new(),
            clause_mentions: OnceLock::new(),
            asked: OnceLock::new(),
            sent: OnceLock::new(),
            every_of_kind: OnceLock::new(),
        }
    }

    /// The scene's objects the whole request mentions, in the order found (an object
    /// may be mentioned more than once), the positions in [`Request::unnumbered_words`].
    pub fn mentions(&self) -> &[Mention] {
        self.mentions
            .get_or_init(|| mentions(&self.unnumbered_words, &self.objects(), &[]))
    }

    /// The scene's objects each of [`Request::clauses`] mentions, the positions in the
    /// clause.
    pub fn clause_mentions(&self) -> &[Vec<Mention>] {
        self.clause_mentions.get_or_init(|| {
            let objects = self.objects();
            self.clauses
                .iter()
                .map(|words| mentions(words, &objects, &[]))
                .collect()
        })
    }

    /// The conditions the request asks for one way in the scene's words
    /// ([`mod@asked`]).
    pub(super) fn asked(&self) -> &[Asked] {
        self.asked.get_or_init(|| asked_in_sentences(self))
    }

    /// The conditions about one object the request asks for one way in the scene's words,
    /// each with whether it is asked to hold ([`mod@asked`]: the words the scene
    /// lists for the condition and its opposite, turned by the negations before them; "both
    /// rooms" asks it of each).
    pub fn asked_of_one_object(&self) -> Vec<(Atom, bool)> {
        self.asked()
            .iter()
            .filter_map(|(subject, wanted, _, _)| {
                let atom = subject.atom();
                let takes_one = self
                    .vocabulary
                    .predicate(&atom.predicate)
                    .is_some_and(|p| p.arg_types.len() == 1);
                takes_one.then_some((atom, *wanted))
            })
            .collect()
    }

    /// The items the request sends to a place, each as the condition of the scene's one
    /// relation of an item and a place that puts it there; none in a scene with no such
    /// relation or several (which one a request means is not read here).
    pub fn sent_by_the_relation(&self) -> Vec<Atom> {
        let relating = relating(self.vocabulary);
        let [relation] = relating.as_slice() else {
            return Vec::new();
        };
        self.sent()
            .iter()
            .map(|s| Atom::new(relation.name.clone(), vec![s.item.clone(), s.place.clone()]))
            .filter(|a| self.vocabulary.check_atom(a).is_ok())
            .collect()
    }

    /// The items the request sends to a place ([`mod@sent`]).
    pub(super) fn sent(&self) -> &[Sent] {
        self.sent.get_or_init(|| sent(self))
    }

    /// The kinds it asks for every object of ("both vents"; [`mod@every_of_kind`]).
    pub fn every_of_kind(&self) -> &[EveryOfKind] {
        self.every_of_kind
            .get_or_init(|| every_of_kind_in(&self.unnumbered_words, self.vocabulary, self.lexicon))
    }

    fn objects(&self) -> Vec<&'a Object> {
        self.vocabulary.objects.iter().collect()
    }
}

/// An empty vocabulary and lexicon, for tests of readers that need less than a scene.
#[cfg(test)]
static NO_VOCABULARY: std::sync::LazyLock<Vocabulary> =
    std::sync::LazyLock::new(Vocabulary::default);
#[cfg(test)]
static NO_WORDS: std::sync::LazyLock<Lexicon> = std::sync::LazyLock::new(Lexicon::default);

#[cfg(test)]
impl<'a> Request<'a> {
    /// `text` read among `vocabulary`'s objects and predicates, with no conventions and an
    /// empty lexicon: for readers that use neither.
    pub(crate) fn among(text: &'a str, vocabulary: &'a Vocabulary) -> Self {
        Self::in_scene(text, vocabulary, &[], &NO_WORDS)
    }

    /// `text` read in no scene: for readers that look only at the request's words.
    pub(crate) fn words_only(text: &'a str) -> Self {
        Self::among(text, &NO_VOCABULARY)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn cafe() -> Scenario {
        Scenario::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/cafe/cafe.toml"))
            .expect("cafe scenario")
    }

    #[test]
    fn a_request_is_read_into_its_words_clauses_scopes_and_mentions() {
        let cafe = cafe();
        let lexicon = Lexicon::new(&cafe.domain.vocabulary, &cafe.examples);
        let request = Request::new(
            "Bring coffee to table No. 1, don't open the curtain. Or chips?",
            &cafe,
            &lexicon,
        );
        // "No." only announces the number: gone from the unnumbered words, kept as written.
        assert!(request.words.contains(&"no".to_string()));
        assert!(!request.unnumbered_words.contains(&"no".to_string()));
        assert_eq!(request.clauses.len(), 4, "{:?}", request.clauses);
        assert_eq!(request.sentences.len(), 3, "{:?}", request.sentences);
        // The negation is in the curtain's scope, and the sentence with "or" offers a choice.
        let curtain = request
            .scopes
            .iter()
            .find(|s| s.words.iter().any(|w| w == "curtain"))
            .expect("a scope about the curtain");
        assert!(curtain.words.contains(&"not".to_string()), "{curtain:?}");
        assert!(!curtain.choice);
        assert!(
            request
                .scopes
                .iter()
                .any(|s| s.choice && s.words.contains(&"chip".to_string())),
            "{:?}",
            request.scopes
        );
        assert_eq!(request.choices, 1);
        let named: Vec<&str> = request
            .mentions()
            .iter()
            .map(|(_, _, name)| name.as_str())
            .collect();
        assert_eq!(named, ["Coffee", "Table1", "Curtain", "Chips"]);
        // Each mention's span is the object's words in the unnumbered words.
        let (at, len, _) = &request.mentions()[1];
        assert_eq!(request.unnumbered_words[*at..at + len], ["table", "1"]);
        let by_clause: Vec<usize> = request.clause_mentions().iter().map(Vec::len).collect();
        assert_eq!(by_clause, [2, 1, 1, 0]);
    }
}
