//! The condition vocabulary of a scenario: typed objects and predicates with one-line
//! descriptions. Everything that reaches a tree (from a file, a person or an LLM) is checked
//! against it, and the prompts of later stages are written from it.

use super::condition::{ANY_OBJECT, Atom, Condition};

/// A named object and the types it belongs to (`Coffee` is an `item` and a `makable`).
#[derive(Debug, Clone, PartialEq)]
pub struct Object {
    pub name: String,
    pub types: Vec<String>,
    /// What people call it when its name does not say so (`Chips`: crisps, fries), as
    /// the scene's `[called]` table lists; shown to the model beside the name and taken
    /// as the object's words when an answer is checked against the request.
    pub called: Vec<String>,
}

impl Object {
    /// Whether this object fits a slot that accepts `types` (type names, or object names
    /// standing for themselves).
    pub fn fits(&self, types: &[String]) -> bool {
        types.contains(&self.name) || self.types.iter().any(|ot| types.contains(ot))
    }
}

/// A predicate with the types each argument slot accepts (a union: `place|item`).
#[derive(Debug, Clone, PartialEq)]
pub struct Predicate {
    pub name: String,
    pub arg_types: Vec<Vec<String>>,
    pub description: String,
    /// The words people use for the condition and for its opposite, as the scene file
    /// lists them.
    pub words: StateWords,
}

/// The words that say a condition holds ("on", "activate" for an appliance that is on)
/// and those that say its opposite ("off"), phrases of several words included ("draw
/// back" the curtain that is closed). A request's word, with the negations before it,
/// tells which way it asks for the condition.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct StateWords {
    pub says: Vec<String>,
    pub opposite: Vec<String>,
}

#[derive(Debug, Clone, Default, PartialEq)]
pub struct Vocabulary {
    pub objects: Vec<Object>,
    pub predicates: Vec<Predicate>,
}

/// Why a condition does not fit the vocabulary.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum VocabularyError {
    #[error("unknown predicate {predicate:?} in {atom} (known: {known})")]
    UnknownPredicate {
        atom: String,
        predicate: String,
        known: String,
    },
    #[error("{atom}: {predicate:?} takes {expected} argument(s), found {found}")]
    Arity {
        atom: String,
        predicate: String,
        expected: usize,
        found: usize,
    },
    #[error("unknown object {object:?} in {atom}")]
    UnknownObject { atom: String, object: String },
    #[error(transparent)]
    WrongType(Box<WrongType>),
}

/// An object in a slot of the wrong type (boxed: it is the largest error here).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "{atom}: argument {position} of {predicate:?} must be {expected}, but {object:?} is {actual}"
)]
pub struct WrongType {
    pub atom: String,
    pub predicate: String,
    pub position: usize,
    pub object: String,
    pub expected: String,
    pub actual: String,
}

impl Vocabulary {
    /// Every object's name, in the scenario's order.
    pub fn object_names(&self) -> Vec<String> {
        self.objects.iter().map(|o| o.name.clone()).collect()
    }

    pub fn object(&self, name: &str) -> Option<&Object> {
        self.objects.iter().find(|o| o.name == name)
    }

    pub fn predicate(&self, name: &str) -> Option<&Predicate> {
        self.predicates.iter().find(|p| p.name == name)
    }

    /// True when `name` is a type some object has.
    pub fn is_type(&self, name: &str) -> bool {
        self.objects
            .iter()
            .any(|o| o.types.iter().any(|t| t == name))
    }

    /// Whether `object` fits a slot that accepts `types` (type names, or object names
    /// standing for themselves).
    pub fn fits(&self, object: &str, types: &[String]) -> bool {
        types.iter().any(|t| t == object) || self.object(object).is_some_and(|o| o.fits(types))
    }

    /// The objects that fit a slot, in declaration order.
    pub fn objects_fitting<'a>(
        &'a self,
        types: &'a [String],
    ) -> impl Iterator<Item = &'a str> + 'a {
        self.objects_fitting_except(types, &[])
    }

    /// The objects that fit `types` and not `except`, in declaration order. Each object's
    /// types are read where it stands (looking it up by name again, as `fits` does, makes
    /// listing a large scene quadratic).
    pub fn objects_fitting_except<'a>(
        &'a self,
        types: &'a [String],
        except: &'a [String],
    ) -> impl Iterator<Item = &'a str> + 'a {
        self.objects
            .iter()
            .filter(move |o| o.fits(types) && !o.fits(except))
            .map(|o| o.name.as_str())
    }

    /// Check that an atom names a known predicate with the right number of arguments, each
    /// a known object of an accepted type (or the `"any object"` wildcard).
    pub fn check_atom(&self, atom: &Atom) -> Result<(), VocabularyError> {
        let text = atom.to_string();
        let Some(pred) = self.predicate(&atom.predicate) else {
            return Err(VocabularyError::UnknownPredicate {
                atom: text,
                predicate: atom.predicate.clone(),
                known: self
                    .predicates
                    .iter()
                    .map(|p| p.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", "),
            });
        };
        if pred.arg_types.len() != atom.args.len() {
            return Err(VocabularyError::Arity {
                atom: text,
                predicate: pred.name.clone(),
                expected: pred.arg_types.len(),
                found: atom.args.len(),
            });
        }
        for (position, (arg, types)) in atom.args.iter().zip(&pred.arg_types).enumerate() {
            if arg == ANY_OBJECT {
                continue;
            }
            let Some(object) = self.object(arg) else {
                if types.iter().any(|t| t == arg) {
                    continue;
                }
                return Err(VocabularyError::UnknownObject {
                    atom: text,
                    object: arg.clone(),
                });
            };
            if !self.fits(arg, types) {
                return Err(VocabularyError::WrongType(Box::new(WrongType {
                    atom: text,
                    predicate: pred.name.clone(),
                    position: position + 1,
                    object: arg.clone(),
                    expected: types.join(" or "),
                    actual: object.types.join(", "),
                })));
            }
        }
        Ok(())
    }

    pub fn check_condition(&self, condition: &Condition) -> Result<(), VocabularyError> {
        self.check_atom(&condition.atom)
    }

    /// Every ground atom the vocabulary can form (used by exhaustive checks and prompts).
    pub fn ground_atoms(&self) -> Vec<Atom> {
        let mut out = Vec::new();
        for pred in &self.predicates {
            let mut partial: Vec<Vec<String>> = vec![Vec::new()];
            for types in &pred.arg_types {
                let choices: Vec<&str> = self.objects_fitting(types).collect();
                partial = partial
                    .into_iter()
                    .flat_map(|p| {
                        choices.iter().map(move |c| {
                            let mut next = p.clone();
                            next.push((*c).to_string());
                            next
                        })
                    })
                    .collect();
            }
            out.extend(partial.into_iter().map(|args| Atom {
                predicate: pred.name.clone(),
                args,
            }));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cafe() -> Vocabulary {
        Vocabulary {
            objects: vec![
                Object {
                    name: "Coffee".into(),
                    types: vec!["item".into(), "makable".into()],
                    called: Vec::new(),
                },
                Object {
                    name: "Table1".into(),
                    types: vec!["place".into()],
                    called: Vec::new(),
                },
            ],
            predicates: vec![Predicate {
                name: "On".into(),
                arg_types: vec![vec!["item".into()], vec!["place".into()]],
                description: "the item is at the place".into(),
                words: Default::default(),
            }],
        }
    }

    #[test]
    fn accepts_well_typed_atoms() {
        let v = cafe();
        assert!(
            v.check_atom(&Atom::parse("On_Coffee_Table1").unwrap())
                .is_ok()
        );
        assert_eq!(v.ground_atoms().len(), 1);
    }

    #[test]
    fn names_what_is_wrong() {
        let v = cafe();
        let e = v
            .check_atom(&Atom::parse("On_Table1_Coffee").unwrap())
            .unwrap_err();
        assert!(
            matches!(&e, VocabularyError::WrongType(w) if w.position == 1),
            "{e}"
        );
        let e = v
            .check_atom(&Atom::parse("On_Fries_Table1").unwrap())
            .unwrap_err();
        assert!(e.to_string().contains("\"Fries\""), "{e}");
        let e = v
            .check_atom(&Atom::parse("Under_Coffee_Table1").unwrap())
            .unwrap_err();
        assert!(e.to_string().contains("known: On"), "{e}");
        let e = v
            .check_atom(&Atom::parse("On_Coffee").unwrap())
            .unwrap_err();
        assert!(matches!(
            e,
            VocabularyError::Arity {
                expected: 2,
                found: 1,
                ..
            }
        ));
    }
}
