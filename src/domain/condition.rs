//! Conditions: a predicate over object names, possibly negated.
//!
//! Two surface syntaxes name the same thing, so both domains of the paper read naturally:
//!
//! * identifier form (the cafe dataset): `On_Coffee_Table1`, `Holding_Nothing`, `Active_AC`
//!   — the predicate starts with an upper-case letter and `_` separates the arguments;
//! * quoted form (the tabletop cell): `"blue cube" on "green cube"`, `"red cup" upright`,
//!   `"banana" location known` — the first argument in quotes, the predicate as lower-case
//!   words, then any further quoted arguments.
//!
//! Which form an atom prints in follows from its predicate (upper-case start → identifier
//! form), so printing and parsing round-trip without any side table.

use std::fmt;

/// The wildcard object: `"any object" on "blue cube"` holds when some object is on the
/// blue cube; negated, when none is.
pub const ANY_OBJECT: &str = "any object";

/// A predicate applied to object names, e.g. `on("blue cube", "green cube")`.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Atom {
    pub predicate: String,
    pub args: Vec<String>,
}

/// A literal: an atom, or its negation (`~`).
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Condition {
    pub atom: Atom,
    pub negated: bool,
}

/// Why an atom could not be read; `at` is a byte offset into the text that was parsed.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("at byte {at}: expected {expected}, found {found}")]
pub struct AtomError {
    pub at: usize,
    pub expected: &'static str,
    pub found: String,
}

impl Atom {
    pub fn new(
        predicate: impl Into<String>,
        args: impl IntoIterator<Item = impl Into<String>>,
    ) -> Self {
        Atom {
            predicate: predicate.into(),
            args: args.into_iter().map(Into::into).collect(),
        }
    }

    /// True when the atom prints in the quoted form (`"a" on "b"`).
    pub fn is_quoted_form(&self) -> bool {
        is_word_predicate(&self.predicate)
    }

    /// True when printing this atom gives text that parses back to it.
    pub fn is_well_formed(&self) -> bool {
        if self.is_quoted_form() {
            !self.args.is_empty()
                && self
                    .args
                    .iter()
                    .all(|a| !a.is_empty() && !a.contains(['"', '\n', '\\']))
        } else {
            is_ident_segment(&self.predicate) && self.args.iter().all(|a| is_ident_segment(a))
        }
    }

    /// True when any argument is the `"any object"` wildcard.
    pub fn has_wildcard(&self) -> bool {
        self.args.iter().any(|a| a == ANY_OBJECT)
    }

    /// Parse a whole string as one atom.
    pub fn parse(text: &str) -> Result<Atom, AtomError> {
        let (atom, used) = parse_atom_prefix(text, 0)?;
        let rest = &text[used..];
        if let Some(c) = rest.trim_start().chars().next() {
            return Err(AtomError {
                at: text.len() - rest.trim_start().len(),
                expected: "end of condition",
                found: format!("{c:?}"),
            });
        }
        Ok(atom)
    }
}

impl Condition {
    pub fn pos(atom: Atom) -> Self {
        Condition {
            atom,
            negated: false,
        }
    }

    pub fn neg(atom: Atom) -> Self {
        Condition {
            atom,
            negated: true,
        }
    }

    /// The same atom with the opposite sign.
    pub fn negate(&self) -> Self {
        Condition {
            atom: self.atom.clone(),
            negated: !self.negated,
        }
    }

    /// Parse `~`? followed by one atom.
    pub fn parse(text: &str) -> Result<Condition, AtomError> {
        let trimmed = text.trim_start();
        let offset = text.len() - trimmed.len();
        let (negated, body, body_at) = match trimmed.strip_prefix('~') {
            Some(rest) => (true, rest, offset + 1),
            None => (false, trimmed, offset),
        };
        let atom = Atom::parse(body).map_err(|e| AtomError {
            at: e.at + body_at,
            ..e
        })?;
        Ok(Condition { atom, negated })
    }
}

impl fmt::Display for Atom {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.is_quoted_form() {
            let mut args = self.args.iter();
            if let Some(first) = args.next() {
                write!(f, "\"{first}\" ")?;
            }
            f.write_str(&self.predicate)?;
            for a in args {
                write!(f, " \"{a}\"")?;
            }
            Ok(())
        } else {
            f.write_str(&self.predicate)?;
            for a in &self.args {
                write!(f, "_{a}")?;
            }
            Ok(())
        }
    }
}

impl fmt::Display for Condition {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.negated {
            f.write_str("~")?;
        }
        write!(f, "{}", self.atom)
    }
}

/// A predicate written as lower-case words (`on`, `near robot`) prints in quoted form.
pub fn is_word_predicate(predicate: &str) -> bool {
    !predicate.is_empty()
        && predicate
            .split(' ')
            .all(|w| !w.is_empty() && w.chars().all(|c| c.is_ascii_lowercase()))
}

fn is_ident_segment(s: &str) -> bool {
    let mut chars = s.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_alphanumeric())
        && chars.all(|c| c.is_ascii_alphanumeric())
}

/// Parse one atom starting at byte `start` of `text` (leading spaces allowed). Returns the
/// atom and the byte offset just after it. Stops before anything that is not part of an
/// atom (`&`, `|`, `)`, `?`, `!`, `{`, end of line), so formula and tree parsers can use it.
pub fn parse_atom_prefix(text: &str, start: usize) -> Result<(Atom, usize), AtomError> {
    let bytes = text.as_bytes();
    let mut i = skip_spaces(bytes, start);
    match bytes.get(i) {
        Some(b'"') => parse_quoted_atom(text, i),
        Some(c) if c.is_ascii_alphabetic() => {
            let begin = i;
            while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_') {
                i += 1;
            }
            let word = &text[begin..i];
            let mut parts = word.split('_');
            let predicate = parts.next().unwrap_or_default().to_string();
            let args: Vec<String> = parts.map(str::to_string).collect();
            if args.iter().any(String::is_empty) {
                return Err(AtomError {
                    at: begin,
                    expected: "an atom of parts joined by underscores, none of them empty",
                    found: format!("{word:?}"),
                });
            }
            if is_word_predicate(&predicate) && !args.is_empty() {
                return Err(AtomError {
                    at: begin,
                    expected: "a predicate starting with an upper-case letter, or a quoted object followed by a predicate word",
                    found: format!("{word:?}"),
                });
            }
            Ok((Atom { predicate, args }, i))
        }
        Some(_) => Err(AtomError {
            at: i,
            expected: "a condition: a predicate atom, or a quoted object followed by a predicate word",
            found: found_at(text, i),
        }),
        None => Err(AtomError {
            at: i,
            expected: "a condition",
            found: "end of text".into(),
        }),
    }
}

fn parse_quoted_atom(text: &str, start: usize) -> Result<(Atom, usize), AtomError> {
    let bytes = text.as_bytes();
    let (first, mut i) = parse_quoted(text, start)?;
    let mut words: Vec<&str> = Vec::new();
    loop {
        let j = skip_spaces(bytes, i);
        let begin = j;
        let mut k = j;
        while k < bytes.len() && bytes[k].is_ascii_alphabetic() {
            k += 1;
        }
        if k == begin {
            break;
        }
        let word = &text[begin..k];
        if !word.chars().all(|c| c.is_ascii_lowercase()) {
            return Err(AtomError {
                at: begin,
                expected: "a lower-case predicate word (on, in, grasped, open, upright, ...)",
                found: format!("{word:?}"),
            });
        }
        words.push(word);
        i = k;
    }
    if words.is_empty() {
        let j = skip_spaces(bytes, i);
        return Err(AtomError {
            at: j,
            expected: "a predicate after the quoted object (on, in, grasped, ...)",
            found: found_at(text, j),
        });
    }
    let mut args = vec![first];
    loop {
        let j = skip_spaces(bytes, i);
        if bytes.get(j) == Some(&b'"') {
            let (arg, next) = parse_quoted(text, j)?;
            args.push(arg);
            i = next;
        } else {
            break;
        }
    }
    Ok((
        Atom {
            predicate: words.join(" "),
            args,
        },
        i,
    ))
}

fn parse_quoted(text: &str, start: usize) -> Result<(String, usize), AtomError> {
    let rest = &text[start + 1..];
    match rest.find(['"', '\n']) {
        Some(end) if rest.as_bytes()[end] == b'"' => {
            let name = &rest[..end];
            if name.trim().is_empty() {
                return Err(AtomError {
                    at: start,
                    expected: "an object name inside the quotes",
                    found: "\"\"".into(),
                });
            }
            Ok((name.to_string(), start + 1 + end + 1))
        }
        _ => Err(AtomError {
            at: start,
            expected: "a closing quote",
            found: "end of line".into(),
        }),
    }
}

fn skip_spaces(bytes: &[u8], mut i: usize) -> usize {
    while i < bytes.len() && (bytes[i] == b' ' || bytes[i] == b'\t') {
        i += 1;
    }
    i
}

fn found_at(text: &str, i: usize) -> String {
    match text[i..].chars().next() {
        Some(c) => format!("{c:?}"),
        None => "end of text".into(),
    }
}

crate::domain::as_text::serde_as_text!(Atom, Atom::parse);
crate::domain::as_text::serde_as_text!(Condition, Condition::parse);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identifier_form_round_trips() {
        for text in [
            "On_Coffee_Table1",
            "Holding_Nothing",
            "Active_AC",
            "~Low_ACTemperature",
        ] {
            let c = Condition::parse(text).unwrap();
            assert_eq!(c.to_string(), text);
        }
        let c = Condition::parse("On_Coffee_Table1").unwrap();
        assert_eq!(c.atom.predicate, "On");
        assert_eq!(c.atom.args, vec!["Coffee", "Table1"]);
    }

    #[test]
    fn quoted_form_round_trips() {
        for text in [
            "\"blue cube\" on \"green cube\"",
            "~\"any object\" on \"blue cube\"",
            "\"red cup\" upright",
            "\"banana\" near robot",
            "\"banana\" location known",
        ] {
            let c = Condition::parse(text).unwrap();
            assert_eq!(c.to_string(), text, "{c:?}");
        }
        let c = Condition::parse("\"banana\" location known").unwrap();
        assert_eq!(c.atom.predicate, "location known");
        assert!(
            Condition::parse("~\"any object\" on \"blue cube\"")
                .unwrap()
                .atom
                .has_wildcard()
        );
    }

    #[test]
    fn prefix_parse_stops_at_operators() {
        let text = "\"a\" on \"b\" & \"c\" upright";
        let (atom, used) = parse_atom_prefix(text, 0).unwrap();
        assert_eq!(atom.to_string(), "\"a\" on \"b\"");
        assert_eq!(&text[used..], " & \"c\" upright");
        let (atom, used) = parse_atom_prefix("Active_AC|X", 0).unwrap();
        assert_eq!(atom.predicate, "Active");
        assert_eq!(used, 9);
    }

    #[test]
    fn errors_point_at_the_problem() {
        let e = Condition::parse("\"blue cube on").unwrap_err();
        assert_eq!(e.expected, "a closing quote");
        let e = Condition::parse("\"blue cube\"").unwrap_err();
        assert_eq!(e.at, 11);
        let e = Condition::parse("On__Table1").unwrap_err();
        assert_eq!(e.at, 0);
        let e = Condition::parse("On_Coffee &").unwrap_err();
        assert_eq!(e.expected, "end of condition");
        assert_eq!(e.at, 10);
        let e = Condition::parse("\"a\" On \"b\"").unwrap_err();
        assert!(e.expected.contains("lower-case"));
    }
}
