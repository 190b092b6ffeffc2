//! betr's tree text (`bt::parse`, `bt::to_text`) and the actions and values on its lines
//! (`ActionCall::parse`, `parse_value`).
//!
//! Properties: a parsed tree prints to text that parses to a tree printing the same text,
//! with as many nodes, and ticks; an error names a line of the input and a column inside
//! that line, and quotes that line; a parsed action or value prints and reads back the
//! same; an action error's offset lies in the text on a character boundary.

use super::{
    Rng, Target, Violation, atoms_of, check_line_column, check_offset, ensure, random_tree,
    strings, text_of,
};
use crate::bt::{self, ActionStep, Leaves, NodeId, Ticker};
use crate::domain::action::parse_value;
use crate::domain::{ActionCall, Atom, Condition, Domain};
use crate::fuzz::Corpus;
use crate::fuzz::Material;

/// Lines of an input whose actions and values are checked too.
const LINES_CHECKED: usize = 40;

/// A tree written by hand: values, negations, comments and blank lines.
const SAMPLE: &str = "\
# a comment
sequence
  fallback
    \"blue cube\" on \"green cube\"?
    sequence
      ~\"any object\" on \"blue cube\"?
      grasp \"blue cube\" {force = 5.3 N}!

      move \"pillow\" {speed = 0.6 m/s, tool = \"shovel\"}!
  PutDown \"Coffee\" \"Table1\"!
  ~On_Coffee_Table1?
  Sweep!
";

pub struct TreeTarget {
    material: Material,
    domains: Vec<(Domain, Vec<Atom>)>,
}

impl TreeTarget {
    pub fn new(corpus: &Corpus) -> TreeTarget {
        let mut seeds = vec![SAMPLE.as_bytes().to_vec()];
        seeds.extend(
            corpus
                .scenarios
                .iter()
                .filter_map(|s| s.planned.as_ref())
                .map(|t| bt::to_text(t).into_bytes()),
        );
        TreeTarget {
            material: Material {
                seeds,
                tokens: strings(&[
                    "sequence\n",
                    "fallback\n",
                    "  ",
                    "\n  ",
                    "?",
                    "!",
                    "~",
                    "# ",
                    "\"",
                    " {",
                    "}",
                    " = ",
                    ", ",
                    " N",
                    " m/s",
                    "force",
                    "\"any object\"",
                    " on ",
                    "_",
                    "\t",
                    "\r",
                ]),
                brackets: super::pairs(&[
                    ("sequence\n  ", ""),
                    ("  ", ""),
                    ("{", "}"),
                    ("\"", "\""),
                ]),
            },
            domains: distinct_domains(corpus),
        }
    }

    fn tree(&self, text: &str) -> Result<(), Violation> {
        match bt::parse(text) {
            Ok(tree) => {
                let printed = bt::to_text(&tree);
                let back = bt::parse(&printed);
                let again = back.as_ref().map(bt::to_text);
                ensure(
                    again.as_ref() == Ok(&printed),
                    "a printed tree reads back to the same text",
                    || format!("{printed:?} read back as {again:?}"),
                )?;
                let len = back.map_or(0, |b| b.len());
                ensure(
                    len == tree.len(),
                    "a printed tree reads back as many nodes",
                    || format!("{} nodes, then {len}: {printed:?}", tree.len()),
                )?;
                tick(&tree);
                Ok(())
            }
            Err(e) => {
                check_line_column(
                    text,
                    e.line,
                    e.column,
                    "a tree error names a place in the input",
                )?;
                if !e.text.is_empty() {
                    let line = text.lines().nth(e.line - 1);
                    ensure(
                        line == Some(e.text.as_str()),
                        "a tree error quotes its line",
                        || format!("{e} quotes {:?}, the line is {line:?}", e.text),
                    )?;
                }
                Ok(())
            }
        }
    }

    fn line(&self, line: &str) -> Result<(), Violation> {
        let body = line.trim_end().trim_end_matches('!');
        match ActionCall::parse(body) {
            Ok(a) => {
                let back = ActionCall::parse(&a.to_string());
                ensure(
                    back.as_ref() == Ok(&a),
                    "a printed action reads back the same",
                    || format!("{body:?} printed as {a} reads back as {back:?}"),
                )?;
            }
            Err(e) => check_offset(body, e.at, "an action error's offset is inside the text")?,
        }
        if let Some((_, value)) = body.split_once('=') {
            let value = value.trim_end_matches('}');
            match parse_value(value) {
                Ok(v) => {
                    let back = parse_value(&v.to_string());
                    ensure(
                        back.as_ref() == Ok(&v),
                        "a printed value reads back the same",
                        || format!("{value:?} printed as {v} reads back as {back:?}"),
                    )?;
                }
                Err(e) => check_offset(value, e.at, "a value error's offset is inside the text")?,
            }
        }
        Ok(())
    }
}

/// Leaves that answer from the text of what they are asked: a condition holds when its
/// text has an even length, an action runs for a tick, then succeeds or fails.
struct TextLeaves;

impl Leaves for TextLeaves {
    fn check(&mut self, condition: &Condition) -> bool {
        condition.to_string().len().is_multiple_of(2)
    }

    fn step(&mut self, _: NodeId, action: &ActionCall, started: bool) -> ActionStep {
        match (started, action.skill.len() % 2) {
            (true, _) => ActionStep::Running,
            (false, 0) => ActionStep::Success,
            (false, _) => ActionStep::Failure("it failed".into()),
        }
    }

    fn halt(&mut self, _: NodeId, _: &ActionCall) {}
}

/// A tree read from text is ticked like any tree (three ticks, then halted).
fn tick(tree: &bt::Tree) {
    let mut ticker = Ticker::new();
    for _ in 0..3 {
        ticker.tick(tree, &mut TextLeaves);
    }
    ticker.halt_all(tree, &mut TextLeaves);
}

/// One domain per vocabulary, with atoms to build trees from.
fn distinct_domains(corpus: &Corpus) -> Vec<(Domain, Vec<Atom>)> {
    let mut out: Vec<(Domain, Vec<Atom>)> = Vec::new();
    for s in &corpus.scenarios {
        let d = &s.scenario.domain;
        let values = d.skills.iter().any(|k| !k.values.is_empty());
        if !out.iter().any(|(o, _)| {
            o.vocabulary.predicates == d.vocabulary.predicates
                && o.skills.iter().any(|k| !k.values.is_empty()) == values
        }) {
            out.push((d.clone(), atoms_of(d, 40)));
        }
    }
    out
}

pub(super) fn tree_text(rng: &mut Rng, domains: &[(Domain, Vec<Atom>)]) -> String {
    let Some((domain, atoms)) = rng.pick(domains) else {
        return SAMPLE.to_string();
    };
    if rng.chance(8) {
        // Deep nesting: a chain of composites, each indented under the one before.
        let depth = rng.between(100, 1000);
        let mut text = String::new();
        for d in 0..depth {
            text.push_str(&"  ".repeat(d));
            text.push_str(if d % 2 == 0 {
                "sequence\n"
            } else {
                "fallback\n"
            });
        }
        text.push_str(&"  ".repeat(depth));
        text.push_str("Sweep!\n");
        return text;
    }
    let size = rng.small(60);
    let tree = random_tree(rng, atoms, domain, size);
    let mut text = bt::to_text(&tree);
    if rng.chance(30) {
        // Comments, blank lines and trailing blanks between the nodes.
        text = text
            .lines()
            .map(|l| format!("{l} \t\n# note\n\n"))
            .collect::<String>();
    }
    text
}

impl Target for TreeTarget {
    fn name(&self) -> &'static str {
        "tree"
    }

    fn material(&self) -> &Material {
        &self.material
    }

    fn generate(&self, rng: &mut Rng) -> Vec<u8> {
        tree_text(rng, &self.domains).into_bytes()
    }

    fn check(&self, input: &[u8]) -> Result<(), Violation> {
        let text = text_of(input);
        self.tree(&text)?;
        for line in text.lines().take(LINES_CHECKED) {
            self.line(line.trim_start())?;
        }
        Ok(())
    }
}
