//! Recursive-descent goal parser. Atoms are read by
//! [`crate::domain::condition::parse_atom_prefix`]; this module only adds the operators.

use super::{Formula, GoalError, column_of};
use crate::domain::condition::parse_atom_prefix;

/// Deeper nesting of `(` and `~` than this is refused, so hostile input cannot overflow
/// the stack.
const MAX_DEPTH: usize = 256;

const EXAMPLE: &str =
    "a condition: a predicate atom, or a quoted object followed by a predicate word";

/// What came just before the operand being read, for the error message.
#[derive(Clone, Copy)]
enum After {
    Start,
    And,
    Or,
    Not,
    Open,
}

impl After {
    fn expected(self) -> &'static str {
        match self {
            After::Start => "a condition",
            After::And => "a condition after '&'",
            After::Or => "a condition after '|'",
            After::Not => "a condition or '(' after '~'",
            After::Open => "a condition after '('",
        }
    }
}

struct Parser<'a> {
    text: &'a str,
    pos: usize,
    depth: usize,
}

pub(super) fn parse(text: &str) -> Result<Formula, GoalError> {
    let mut p = Parser {
        text,
        pos: 0,
        depth: 0,
    };
    let formula = p.or(After::Start)?;
    p.skip_ws();
    match p.peek() {
        None => match formula.check_alternatives(super::MAX_ALTERNATIVES) {
            Ok(()) => Ok(formula),
            Err(e) => Err(GoalError::new(
                text,
                0,
                format!("a goal of at most {} alternatives", e.limit),
                "more (its '|' choices multiply out)",
            )),
        },
        Some(')') => Err(p.error(
            p.pos,
            "'&', '|' or end of goal (this ')' has no matching '(')",
        )),
        Some(_) => Err(p.error(p.pos, "'&', '|' or end of goal")),
    }
}

impl Parser<'_> {
    fn peek(&self) -> Option<char> {
        self.text.get(self.pos..).and_then(|s| s.chars().next())
    }

    fn skip_ws(&mut self) {
        let rest = self.text.get(self.pos..).unwrap_or_default();
        self.pos += rest.len() - rest.trim_start().len();
    }

    fn found(&self, at: usize) -> String {
        match self.text.get(at..).and_then(|s| s.chars().next()) {
            Some(c) => format!("{c:?}"),
            None => "end of goal".into(),
        }
    }

    fn error(&self, at: usize, expected: impl Into<String>) -> GoalError {
        GoalError::new(self.text, at, expected, self.found(at))
    }

    fn or(&mut self, after: After) -> Result<Formula, GoalError> {
        let mut items = vec![self.and(after)?];
        loop {
            self.skip_ws();
            if self.peek() != Some('|') {
                break;
            }
            self.pos += 1;
            items.push(self.and(After::Or)?);
        }
        Ok(Formula::or(items))
    }

    fn and(&mut self, after: After) -> Result<Formula, GoalError> {
        let mut items = vec![self.unary(after)?];
        loop {
            self.skip_ws();
            if self.peek() != Some('&') {
                break;
            }
            self.pos += 1;
            items.push(self.unary(After::And)?);
        }
        Ok(Formula::and(items))
    }

    fn deeper(&mut self) -> Result<(), GoalError> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return Err(self.error(self.pos, format!("at most {MAX_DEPTH} nested '(' and '~'")));
        }
        Ok(())
    }

    fn unary(&mut self, after: After) -> Result<Formula, GoalError> {
        self.skip_ws();
        match self.peek() {
            None | Some('&' | '|' | ')') => Err(self.error(self.pos, after.expected())),
            Some('~') => {
                self.deeper()?;
                self.pos += 1;
                let inner = self.unary(After::Not)?;
                self.depth -= 1;
                Ok(Formula::Not(Box::new(inner)))
            }
            Some('(') => {
                self.deeper()?;
                let open = self.pos;
                self.pos += 1;
                let inner = self.or(After::Open)?;
                self.skip_ws();
                if self.peek() != Some(')') {
                    let expected = format!(
                        "')' to close the '(' at column {}",
                        column_of(self.text, open)
                    );
                    return Err(self.error(self.pos, expected));
                }
                self.pos += 1;
                self.depth -= 1;
                Ok(inner)
            }
            Some(_) => {
                let start = self.pos;
                let (atom, end) = parse_atom_prefix(self.text, start)
                    .map_err(|e| GoalError::new(self.text, e.at, e.expected, e.found))?;
                if !atom.is_well_formed() {
                    let word = self.text.get(start..end).unwrap_or_default();
                    return Err(GoalError::new(
                        self.text,
                        start,
                        EXAMPLE,
                        format!("{word:?}"),
                    ));
                }
                self.pos = end;
                Ok(Formula::Atom(atom))
            }
        }
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::super::{equivalent, formula::Formula};
    use crate::domain::Atom;
    use proptest::prelude::*;

    fn p(text: &str) -> Formula {
        Formula::parse(text).unwrap()
    }

    fn err(text: &str) -> super::GoalError {
        Formula::parse(text).unwrap_err()
    }

    #[test]
    fn precedence_groups_and_before_or() {
        let f = p("~Closed_Curtain | Active_AC & ~Low_ACTemperature");
        let Formula::Or(items) = &f else {
            panic!("{f:?}")
        };
        assert_eq!(items.len(), 2);
        assert!(matches!(&items[0], Formula::Not(_)));
        assert!(matches!(&items[1], Formula::And(v) if v.len() == 2));
        assert_eq!(f, p("(~Closed_Curtain) | (Active_AC & ~Low_ACTemperature)"));
    }

    #[test]
    fn not_applies_to_atom_or_group() {
        let f = p("~(A | B) & C");
        let Formula::And(items) = &f else {
            panic!("{f:?}")
        };
        assert!(matches!(&items[0], Formula::Not(x) if matches!(**x, Formula::Or(_))));
        let q = p("~\"any object\" on \"blue cube\" & \"blue cube\" on \"green cube\"");
        let Formula::And(items) = &q else {
            panic!("{q:?}")
        };
        let Formula::Not(inner) = &items[0] else {
            panic!("{q:?}")
        };
        assert_eq!(
            **inner,
            Formula::Atom(Atom::new("on", ["any object", "blue cube"]))
        );
        assert_eq!(
            items[1],
            Formula::Atom(Atom::new("on", ["blue cube", "green cube"]))
        );
    }

    #[test]
    fn flattens_and_accepts_any_whitespace() {
        assert_eq!(p("A & (B & (C))"), p("A&B&C"));
        assert_eq!(p(" A\t|\n( B | C ) \r\n"), p("A | B | C"));
        assert!(matches!(p("A & B & C"), Formula::And(v) if v.len() == 3));
        assert_eq!(p("((On_Coffee_Table1))"), p("On_Coffee_Table1"));
    }

    #[test]
    fn errors_name_column_expected_and_found() {
        let e = err("Active_AC &");
        assert_eq!((e.at, e.column), (11, 12));
        assert_eq!(
            e.to_string(),
            "column 12: expected a condition after '&', found end of goal"
        );
        assert_eq!(err("").expected, "a condition");
        assert_eq!(err("   ").found, "end of goal");
        assert_eq!(err("| A").found, "'|'");
        assert_eq!(err("A | | B").expected, "a condition after '|'");
        assert_eq!(err("~").expected, "a condition or '(' after '~'");
        let e = err("(A & B");
        assert_eq!(e.expected, "')' to close the '(' at column 1");
        assert_eq!(e.found, "end of goal");
        let e = err("A & B)");
        assert_eq!((e.column, e.found.as_str()), (6, "')'"));
        assert!(e.expected.contains("no matching '('"));
        assert_eq!(err("()").expected, "a condition after '('");
        let e = err("A # B");
        assert_eq!((e.at, e.found.as_str()), (2, "'#'"));
        let e = err("A & é");
        assert_eq!((e.at, e.column), (4, 5));
        let e = err("é | #");
        assert_eq!(e.column, 1);
        let e = err("A & \"blue cube\" & B");
        assert_eq!(e.column, 17);
        assert!(e.expected.contains("predicate"));
        assert!(err("A & lowercase").expected.contains("predicate atom"));
        assert!(err("A B").expected.contains("end of goal"));
    }

    #[test]
    fn deep_nesting_is_an_error_not_a_crash() {
        let deep = format!("{}A{}", "(".repeat(10_000), ")".repeat(10_000));
        assert!(err(&deep).expected.contains("nested"));
        assert!(Formula::parse(&format!("{}A", "~".repeat(10_000))).is_err());
        let ok = format!("{}A{}", "(".repeat(100), ")".repeat(100));
        assert_eq!(p(&ok), p("A"));
    }

    fn atom() -> impl Strategy<Value = Formula> {
        prop_oneof![
            Just(Atom::new("Active", ["AC"])),
            Just(Atom::new("On", ["Coffee", "Table1"])),
            Just(Atom::new("Closed", ["Curtain"])),
            Just(Atom::new("Exists", ["Water"])),
            Just(Atom::new("on", ["any object", "blue cube"])),
            Just(Atom::new("upright", ["red cup"])),
        ]
        .prop_map(Formula::Atom)
    }

    pub(in crate::goal) fn formula() -> impl Strategy<Value = Formula> {
        atom().prop_recursive(4, 24, 4, |inner| {
            prop_oneof![
                inner.clone().prop_map(|f| Formula::Not(Box::new(f))),
                prop::collection::vec(inner.clone(), 1..4).prop_map(Formula::And),
                prop::collection::vec(inner, 1..4).prop_map(Formula::Or),
            ]
        })
    }

    proptest! {
        #[test]
        fn parse_never_panics(text in "\\PC{0,40}") {
            let _ = Formula::parse(&text);
        }

        #[test]
        fn parse_never_panics_on_goal_like_text(
            text in "[ ()~&|\"A-Za-z_0-9é]{0,40}"
        ) {
            if let Err(e) = Formula::parse(&text) {
                prop_assert!(e.at <= text.len());
                prop_assert!(!e.to_string().is_empty());
            }
        }

        #[test]
        fn print_then_parse_round_trips(f in formula()) {
            let printed = f.to_string();
            let back = Formula::parse(&printed);
            prop_assert!(back.is_ok(), "{printed}: {back:?}");
            let back = back.unwrap_or_else(|_| Formula::Or(vec![]));
            prop_assert_eq!(&back, &f.flatten(), "{}", printed);
            prop_assert_eq!(equivalent(&back, &f), Ok(true));
        }
    }
}
