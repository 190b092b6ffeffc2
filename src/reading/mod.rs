//! How a request is understood, in one place, with no model, world or planner in it: the
//! words of a text ([`words`]) and the English every reader knows ([`english`], one list
//! per kind of word); which words of a scene's requests each predicate and object answers
//! to ([`lexicon`], from the scenario's data: names, what objects are called, the words
//! listed for each predicate and its opposite, the example pool); a request cut into the
//! wishes it is made of ([`parts`]); a request read once, the value every reader below
//! takes ([`request`]); and the plain misreadings of a request, each a
//! detector registered in one list ([`misreading`]), built on what a request's words say
//! about conditions ([`polarity`]), about items sent to places ([`placement`]), about
//! the relation said before a place
//! and a scene's conventions ([`relation_words`]), and about a goal's objects and
//! conjuncts ([`names`]), about the order of a relation's objects ([`order`]), and about
//! the kinds a "both", "all" or "every" asks each object of ([`kinds`]). What a model's
//! reasoning claims of the scene's conditions is read here too ([`claims`]).
//!
//! The session asks the model and judges its answers with what is here; formula rewrites
//! that know nothing of words (rename, map atoms, flip) are [`crate::goal::rewrite`]'s.

pub mod claims;
pub mod english;
pub mod kinds;
pub mod lexicon;
pub mod misreading;
pub mod names;
pub mod order;
pub mod parts;
pub mod placement;
pub mod polarity;
pub mod relation_words;
pub mod request;
pub mod side_by_side;
pub mod words;

pub use lexicon::Lexicon;
pub use misreading::{MISREADINGS, Misreading, UnknownMisreading, misreadings_without};
pub use request::Request;
