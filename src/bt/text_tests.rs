//! Unit and property tests for `text.rs`.

use proptest::prelude::*;

use super::*;
use crate::bt::test_util::{act, cond};
use crate::domain::{ActionCall, Atom, Value};

const SAMPLE: &str = "\
sequence
  fallback
    \"blue cube\" on \"green cube\"?
    sequence
      ~\"any object\" on \"blue cube\"?
      grasp \"blue cube\" {force = 5.3 N}!
  PutDown \"Coffee\" \"Table1\"!
  ~On_Coffee_Table1?
  Sweep!
";

#[test]
fn sample_parses_and_prints_back() {
    let t = parse(SAMPLE).unwrap();
    assert_eq!(t.len(), 9);
    let f = t.node_at_path(&[0]).unwrap();
    assert_eq!(t.kind(f).unwrap(), &NodeKind::Fallback);
    let grasp = t.node_at_path(&[0, 1, 1]).unwrap();
    assert_eq!(
        t.kind(grasp).unwrap(),
        &act("grasp \"blue cube\" {force = 5.3 N}")
    );
    assert_eq!(
        t.kind(t.node_at_path(&[2]).unwrap()).unwrap(),
        &cond("~On_Coffee_Table1")
    );
    assert_eq!(
        t.kind(t.node_at_path(&[3]).unwrap()).unwrap(),
        &act("Sweep")
    );
    assert_eq!(to_text(&t), SAMPLE);
}

#[test]
fn blank_lines_comments_and_trailing_blanks_are_ignored() {
    let text =
        "# policy: stack\n\nsequence   \n  # a comment\n\n  Active_AC ?  \n  grasp \"x\"!\t\n";
    let t = parse(text).unwrap();
    assert_eq!(to_text(&t), "sequence\n  Active_AC?\n  grasp \"x\"!\n");
    // A lone leaf is a tree; no trailing newline needed.
    assert_eq!(to_text(&parse("Sweep!").unwrap()), "Sweep!\n");
}

fn err(text: &str) -> ParseError {
    parse(text).unwrap_err()
}

#[test]
fn errors_point_at_line_and_column() {
    let e = err("sequence\n  Sweep!\n   Mop!\n");
    assert_eq!((e.line, e.column), (3, 4));
    assert_eq!(e.text, "   Mop!");
    assert_eq!(
        e.to_string(),
        "line 3, column 4: expected indentation of two spaces per level, found 3 spaces in:    Mop!"
    );

    let e = err("sequence\n  fallback\n      Sweep!\n");
    assert_eq!((e.line, e.column), (3, 1));
    assert!(e.expected.contains("at most 4 spaces"), "{e}");

    let e = err("  sequence\n");
    assert_eq!((e.line, e.column), (1, 1));

    let e = err("sequence\n  Sweep!\n    Mop!\n");
    assert_eq!((e.line, e.column), (3, 5));
    assert!(e.expected.contains("`Sweep!` is a leaf"), "{e}");

    let e = err("sequence\n  fallback\n  Sweep!\n");
    assert_eq!((e.line, e.column, e.found.as_str()), (2, 3, "no children"));
    let e = err("# header\nfallback\n");
    assert_eq!((e.line, e.column), (2, 1));

    let e = err("sequence\n  Sweep! now\n");
    assert_eq!((e.line, e.column, e.found.as_str()), (2, 10, "'n'"));
    assert_eq!(e.expected, "end of line after `?` or `!`");
    let e = err("sequence\n  \"a\" on \"b\"? x\n");
    assert_eq!((e.line, e.column), (2, 15));

    let e = err("sequense\n  Sweep!\n");
    assert_eq!((e.line, e.column, e.found.as_str()), (1, 1, "\"sequense\""));

    let e = err("Sweep!\nMop!\n");
    assert_eq!((e.line, e.found.as_str()), (2, "a second root"));

    let e = err("sequence\n  grasp \"x\"\n");
    assert_eq!((e.line, e.column, e.found.as_str()), (2, 12, "end of line"));
    let e = err("sequence\n  grasp \"x\"?\n");
    assert_eq!((e.line, e.column, e.found.as_str()), (2, 12, "'?'"));
    let e = err("sequence\n  \"blue cube on\"?\n");
    assert_eq!(e.line, 2);
    assert!(e.expected.contains("predicate"), "{e}");
    let e = err("sequence\n  ~\"a\" on \"b\"!\n");
    assert_eq!(
        (e.column, e.expected.as_str()),
        (14, "`?` after the condition")
    );
    let e = err("sequence\n\tSweep!\n");
    assert_eq!((e.line, e.column), (2, 1));

    let e = err("\n# only a comment\n");
    assert_eq!(e.found, "no nodes");
    assert_eq!(err("").found, "no nodes");
}

#[test]
fn columns_count_characters() {
    let e = err("sequence\n  \"café\" on \"b\"? !\n");
    assert_eq!(e.column, 18);
}

fn name() -> impl Strategy<Value = String> {
    "[a-z0-9][a-z0-9 ]{0,8}"
}

fn ident() -> impl Strategy<Value = String> {
    "[A-Za-z0-9]{1,6}"
}

fn atom() -> impl Strategy<Value = Atom> {
    prop_oneof![
        (
            "[A-Z][A-Za-z0-9]{0,6}",
            prop::collection::vec(ident(), 0..3)
        )
            .prop_map(|(p, args)| Atom::new(p, args)),
        (
            prop::collection::vec("[a-z]{1,6}", 1..3),
            prop::collection::vec(name(), 1..4)
        )
            .prop_map(|(words, args)| Atom::new(words.join(" "), args)),
    ]
}

fn value() -> impl Strategy<Value = Value> {
    prop_oneof![
        (
            -1.0e6..1.0e6f64,
            prop_oneof![Just(""), Just("N"), Just("m/s")]
        )
            .prop_map(|(value, unit)| Value::Number {
                value,
                unit: unit.into()
            }),
        "[a-z][a-z0-9]{0,6}".prop_map(Value::Category),
    ]
}

fn action() -> impl Strategy<Value = ActionCall> {
    (
        "[A-Za-z][A-Za-z0-9_]{0,8}",
        prop::collection::vec(name(), 0..3),
        prop::collection::vec(("[a-z][a-z_]{0,5}", value()), 0..3),
    )
        .prop_map(|(skill, args, values)| ActionCall {
            skill,
            args,
            values,
        })
}

fn leaf() -> impl Strategy<Value = NodeKind> {
    prop_oneof![
        (atom(), any::<bool>())
            .prop_map(|(atom, negated)| NodeKind::Condition(Condition { atom, negated })),
        action().prop_map(NodeKind::Action),
    ]
}

/// A tree shape: a leaf, or a composite with 1..4 children.
#[derive(Clone, Debug)]
enum Shape {
    Leaf(NodeKind),
    Composite(NodeKind, Vec<Shape>),
}

fn shape() -> impl Strategy<Value = Shape> {
    leaf()
        .prop_map(Shape::Leaf)
        .prop_recursive(5, 40, 4, |inner| {
            (
                prop_oneof![Just(NodeKind::Sequence), Just(NodeKind::Fallback)],
                prop::collection::vec(inner, 1..4),
            )
                .prop_map(|(kind, children)| Shape::Composite(kind, children))
        })
}

fn build(shape: &Shape) -> Tree {
    fn grow(t: &mut Tree, parent: NodeId, children: &[Shape]) {
        for child in children {
            match child {
                Shape::Leaf(kind) => {
                    t.add_child(parent, kind.clone()).unwrap();
                }
                Shape::Composite(kind, grandchildren) => {
                    let id = t.add_child(parent, kind.clone()).unwrap();
                    grow(t, id, grandchildren);
                }
            }
        }
    }
    match shape {
        Shape::Leaf(kind) => Tree::new(kind.clone()),
        Shape::Composite(kind, children) => {
            let mut t = Tree::new(kind.clone());
            let root = t.root();
            grow(&mut t, root, children);
            t
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn text_round_trips(shape in shape()) {
        let t = build(&shape);
        prop_assert!(t.validate().is_ok());
        let text = to_text(&t);
        let back = parse(&text).map_err(|e| TestCaseError::fail(format!("{e}\n{text}")))?;
        prop_assert_eq!(&back, &t, "{}", text);
        prop_assert_eq!(to_text(&back), text);
    }
}

/// A tree `levels` sequences deep with one condition at the bottom.
fn nested(levels: usize) -> String {
    let mut text = String::new();
    for depth in 0..levels {
        text.push_str(&"  ".repeat(depth));
        text.push_str("sequence\n");
    }
    text.push_str(&"  ".repeat(levels));
    text.push_str("Done?\n");
    text
}

#[test]
fn nesting_deeper_than_the_limit_is_refused_at_its_line() {
    // The condition sits at depth MAX_DEPTH: allowed.
    assert!(parse(&nested(crate::bt::MAX_DEPTH)).is_ok());
    let e = parse(&nested(crate::bt::MAX_DEPTH + 1)).unwrap_err();
    assert_eq!(e.line, crate::bt::MAX_DEPTH + 2);
    assert!(e.expected.contains("levels of nesting"), "{e:?}");
}
