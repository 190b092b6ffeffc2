//! Condition templates as scenario files write them (`On_{item}_{place}`, `~"{a}" on
//! "{b}"`, `On_{item}_{*}`): reading one against a skill's parameters, and checking it
//! against the vocabulary.

use super::condition::{ANY_OBJECT, Condition};
use super::skill::{AtomTemplate, LiteralTemplate, Param, Term};
use super::vocabulary::Vocabulary;

/// Why a condition template could not be read. Each names the template as written;
/// `at` is a byte offset into it.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum TemplateError {
    #[error("unclosed '{{' in {text:?}")]
    Unclosed { text: String, at: usize },
    #[error(
        "{{{name}}} in {text:?} is not a parameter of this skill (parameters: {})",
        .known.join(", ")
    )]
    UnknownParam {
        text: String,
        at: usize,
        name: String,
        known: Vec<String>,
    },
    #[error("in {text:?}: expected {expected}, found {found}")]
    Syntax {
        text: String,
        at: usize,
        expected: &'static str,
        found: String,
    },
    #[error("in {text:?}: a parameter cannot stand for the predicate")]
    ParamAsPredicate { text: String },
    #[error("in {text:?}: a parameter must be a whole argument")]
    PartialArgument { text: String },
}

impl TemplateError {
    /// The byte offset into the template the error is about (0: the whole template).
    pub fn at(&self) -> usize {
        match self {
            TemplateError::Unclosed { at, .. }
            | TemplateError::UnknownParam { at, .. }
            | TemplateError::Syntax { at, .. } => *at,
            TemplateError::ParamAsPredicate { .. } | TemplateError::PartialArgument { .. } => 0,
        }
    }
}

/// Parse a condition template such as `On_{item}_{place}`, `~"{a}" on "{b}"` or
/// `On_{item}_{*}` against a skill's parameter names.
pub fn parse_template(text: &str, params: &[Param]) -> Result<LiteralTemplate, TemplateError> {
    // Replace each {name} by a sentinel that both atom syntaxes accept, parse with the one
    // atom reader, then map the sentinels back to terms.
    let mut substituted = String::new();
    let mut terms: Vec<Term> = Vec::new();
    // Where each sentinel stands in `substituted` and its `{name}` in `text`, so an error
    // of the atom reader points into the template as written.
    let mut placed: Vec<(std::ops::Range<usize>, std::ops::Range<usize>)> = Vec::new();
    let mut rest = text;
    while let Some(open) = rest.find('{') {
        let at = text.len() - rest.len() + open;
        substituted.push_str(&rest[..open]);
        let Some(close) = rest[open..].find('}') else {
            return Err(TemplateError::Unclosed {
                text: text.to_string(),
                at,
            });
        };
        let name = rest[open + 1..open + close].trim();
        let term = if name == "*" {
            Term::Every
        } else {
            match params.iter().position(|p| p.name == name) {
                Some(i) => Term::Param(i),
                None => {
                    return Err(TemplateError::UnknownParam {
                        text: text.to_string(),
                        at,
                        name: name.to_string(),
                        known: params.iter().map(|p| p.name.clone()).collect(),
                    });
                }
            }
        };
        let sentinel = format!("ZzParam{}zZ", terms.len());
        let from = substituted.len();
        substituted.push_str(&sentinel);
        placed.push((from..substituted.len(), at..at + close + 1));
        terms.push(term);
        rest = &rest[open + close + 1..];
    }
    substituted.push_str(rest);
    let condition = Condition::parse(&substituted).map_err(|e| TemplateError::Syntax {
        text: text.to_string(),
        at: written_offset(&placed, e.at),
        expected: e.expected,
        found: e.found,
    })?;
    if condition.atom.predicate.contains("ZzParam") {
        return Err(TemplateError::ParamAsPredicate {
            text: text.to_string(),
        });
    }
    let partial = || TemplateError::PartialArgument {
        text: text.to_string(),
    };
    let args = condition
        .atom
        .args
        .iter()
        .map(
            |a| match a.strip_prefix("ZzParam").and_then(|r| r.strip_suffix("zZ")) {
                Some(i) => i
                    .parse::<usize>()
                    .ok()
                    .and_then(|i| terms.get(i).cloned())
                    .ok_or_else(partial),
                None if a.contains("ZzParam") => Err(partial()),
                None => Ok(Term::Const(a.clone())),
            },
        )
        .collect::<Result<Vec<_>, _>>()?;
    Ok(LiteralTemplate {
        atom: AtomTemplate {
            predicate: condition.atom.predicate,
            args,
        },
        negated: condition.negated,
    })
}

/// The offset in the template as written of byte `at` of its substituted form: a
/// position inside a sentinel is the start of its `{name}`.
fn written_offset(placed: &[(std::ops::Range<usize>, std::ops::Range<usize>)], at: usize) -> usize {
    let mut shift: isize = 0;
    for (sentinel, written) in placed {
        if at < sentinel.start {
            break;
        }
        if at < sentinel.end {
            return written.start;
        }
        shift = written.end as isize - sentinel.end as isize;
    }
    (at as isize + shift).max(0) as usize
}

/// Why a template does not fit the vocabulary.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum TemplateFitError {
    #[error("unknown predicate {predicate:?} (known: {})", .known.join(", "))]
    UnknownPredicate {
        predicate: String,
        known: Vec<String>,
    },
    #[error("{predicate:?} takes {expected} argument(s), found {found}")]
    Arity {
        predicate: String,
        expected: usize,
        found: usize,
    },
    #[error("{object:?} is not a known object of type {}", .types.join(" or "))]
    NotAnObject { object: String, types: Vec<String> },
    #[error(
        "parameter {param:?} ({}) can never fit {predicate:?}'s argument of type {}",
        .param_types.join("|"),
        .types.join(" or ")
    )]
    ParamNeverFits {
        param: String,
        param_types: Vec<String>,
        predicate: String,
        types: Vec<String>,
    },
}

impl AtomTemplate {
    /// Check the template against the vocabulary: its predicate exists with this many
    /// arguments and every constant is an object of its argument's type. With `params`
    /// (the skill's), each parameter must also be able to stand for some object of its
    /// argument's type.
    pub fn check(
        &self,
        vocabulary: &Vocabulary,
        params: Option<&[Param]>,
    ) -> Result<(), TemplateFitError> {
        let Some(pred) = vocabulary.predicate(&self.predicate) else {
            return Err(TemplateFitError::UnknownPredicate {
                predicate: self.predicate.clone(),
                known: vocabulary
                    .predicates
                    .iter()
                    .map(|p| p.name.clone())
                    .collect(),
            });
        };
        if pred.arg_types.len() != self.args.len() {
            return Err(TemplateFitError::Arity {
                predicate: self.predicate.clone(),
                expected: pred.arg_types.len(),
                found: self.args.len(),
            });
        }
        for (term, types) in self.args.iter().zip(&pred.arg_types) {
            match (term, params) {
                (Term::Const(c), _) if c != ANY_OBJECT && !vocabulary.fits(c, types) => {
                    return Err(TemplateFitError::NotAnObject {
                        object: c.clone(),
                        types: types.clone(),
                    });
                }
                (Term::Param(i), Some(params)) => {
                    let Some(p) = params.get(*i) else { continue };
                    if !p.candidates(vocabulary).any(|o| vocabulary.fits(o, types)) {
                        return Err(TemplateFitError::ParamNeverFits {
                            param: p.name.clone(),
                            param_types: p.types.clone(),
                            predicate: self.predicate.clone(),
                            types: types.clone(),
                        });
                    }
                }
                _ => {}
            }
        }
        Ok(())
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Parameters named after their types.
    pub(crate) fn params(names: &[&str]) -> Vec<Param> {
        names
            .iter()
            .map(|n| Param {
                name: n.to_string(),
                types: vec![n.to_string()],
                except: vec![],
            })
            .collect()
    }

    #[test]
    fn templates_parse_both_syntaxes() {
        let ps = params(&["a", "b"]);
        let t = parse_template("~\"{a}\" on \"{b}\"", &ps).unwrap();
        assert!(t.negated);
        assert_eq!(t.atom.args, vec![Term::Param(0), Term::Param(1)]);
        let t = parse_template("On_{a}_{*}", &ps).unwrap();
        assert_eq!(t.atom.args, vec![Term::Param(0), Term::Every]);
        let t = parse_template("\"{a}\" on \"table\"", &ps).unwrap();
        assert_eq!(t.atom.args[1], Term::Const("table".into()));
        let e = parse_template("On_{c}_x", &ps).unwrap_err();
        assert!(e.to_string().contains("not a parameter"), "{e}");
        assert_eq!(e.at(), 3);
        assert_eq!(
            parse_template("\"{a} cube\" on \"x\"", &ps),
            Err(TemplateError::PartialArgument {
                text: "\"{a} cube\" on \"x\"".into()
            })
        );
        let e = parse_template("On_{a}_{b} &", &ps).unwrap_err();
        assert!(matches!(e, TemplateError::Syntax { at: 11, .. }), "{e:?}");
    }
}
