//! BehaviorTree.CPP v4 XML read onto a scenario's domain (`interop::from_btcpp`), for a
//! domain of each kind: the cafe, the cell, the cell with value parameters.
//!
//! Properties: a tree read from XML is written back (`to_btcpp`) to XML that reads as the
//! same tree; an error names a line of the input and a column inside that line.

use super::{
    Rng, Target, Violation, atoms_of, check_line_column, ensure, random_tree, strings, text_of,
};
use crate::bt::{self, NodeKind, Tree};
use crate::domain::{Atom, Domain};
use crate::fuzz::Corpus;
use crate::fuzz::Material;
use crate::interop::{from_btcpp, to_btcpp};

pub struct BtcppTarget {
    material: Material,
    domains: Vec<(Domain, Vec<Atom>)>,
}

impl BtcppTarget {
    pub fn new(corpus: &Corpus) -> BtcppTarget {
        let mut domains: Vec<(Domain, Vec<Atom>)> = Vec::new();
        let mut seeds: Vec<Vec<u8>> = corpus.xml.iter().map(|x| x.as_bytes().to_vec()).collect();
        for s in &corpus.scenarios {
            let d = &s.scenario.domain;
            // Only domains that can be written (no two predicates share a BT.CPP ID).
            if to_btcpp(&Tree::new(NodeKind::Sequence), d, "T").is_err() {
                continue;
            }
            if let Some(tree) = &s.planned
                && let Ok(xml) = to_btcpp(tree, d, "T")
            {
                seeds.push(xml.into_bytes());
            }
            let values = d.skills.iter().any(|k| !k.values.is_empty());
            let kind_known = domains.iter().any(|(o, _)| {
                o.vocabulary.predicates == d.vocabulary.predicates
                    && o.skills.iter().any(|k| !k.values.is_empty()) == values
            });
            if !kind_known {
                domains.push((d.clone(), atoms_of(d, 40)));
            }
        }
        BtcppTarget {
            material: Material {
                seeds,
                tokens: strings(&[
                    "<ReactiveSequence>",
                    "</ReactiveSequence>",
                    "<ReactiveFallback>",
                    "</ReactiveFallback>",
                    "<Sequence>",
                    "</Sequence>",
                    "<Fallback>",
                    "</Fallback>",
                    "<Inverter>",
                    "</Inverter>",
                    "<SubTree ID=\"x\"/>",
                    "<Condition ID=\"on\" arg1=\"blue cube\" arg2=\"green cube\"/>",
                    "<Action ID=\"grasp\" x=\"egg\" force=\"5 N\"/>",
                    "<on item=\"blue cube\" item_or_fixture=\"green cube\"/>",
                    "<grasp x=\"egg\"/>",
                    "<BehaviorTree ID=\"T\">",
                    "</BehaviorTree>",
                    "<root BTCPP_format=\"4\">",
                    "</root>",
                    " ID=\"",
                    " name=\"n\"",
                    " arg1=\"",
                    " item=\"",
                    " _skipIf=\"x\"",
                    " port=\"{bb}\"",
                    " main_tree_to_execute=\"T\"",
                    "BTCPP_format=\"3\"",
                    "/>",
                    "</",
                    "<!-- c -->",
                    "<![CDATA[x]]>",
                    "<?xml version=\"1.0\"?>",
                    "<!DOCTYPE root [<!ENTITY e \"blue cube\">]>",
                    "&e;",
                    "&amp;",
                    "&#x0;",
                    "&#1114112;",
                    "&#xD800;",
                    "xmlns:a=\"u\"",
                    "<a:b/>",
                ]),
                brackets: super::pairs(&[
                    ("<ReactiveSequence>", "</ReactiveSequence>"),
                    ("<Inverter>", "</Inverter>"),
                    ("<Fallback>", "</Fallback>"),
                    ("<a>", "</a>"),
                    ("<!--", "-->"),
                ]),
            },
            domains,
        }
    }

    fn read(&self, text: &str, domain: &Domain) -> Result<(), Violation> {
        match from_btcpp(text, domain) {
            Ok(imported) => {
                let printed = bt::to_text(&imported.tree);
                let written = to_btcpp(&imported.tree, domain, "T");
                let Ok(written) = written else {
                    return ensure(false, "a tree read from XML can be written as XML", || {
                        format!("{printed:?}: {written:?}")
                    });
                };
                let back = from_btcpp(&written, domain).map(|i| bt::to_text(&i.tree));
                ensure(
                    back.as_ref() == Ok(&printed),
                    "a tree read from XML and written again reads the same",
                    || format!("{printed:?} wrote {written:?}, read back as {back:?}"),
                )
            }
            Err(e) => {
                let (line, column) = (e.line as usize, e.column as usize);
                check_line_column(
                    text,
                    line,
                    column,
                    "an XML error names a place in the input",
                )
            }
        }
    }
}

impl Target for BtcppTarget {
    fn name(&self) -> &'static str {
        "btcpp"
    }

    fn material(&self) -> &Material {
        &self.material
    }

    fn generate(&self, rng: &mut Rng) -> Vec<u8> {
        if rng.chance(10) {
            let depth = rng
                .pick(&[250usize, 256, 257, 258, 1000, 5000])
                .copied()
                .unwrap_or(300);
            let tag = rng
                .pick(&["ReactiveSequence", "Fallback", "Inverter"])
                .copied()
                .unwrap_or("a");
            return format!(
                "<root BTCPP_format=\"4\"><BehaviorTree ID=\"T\">{}<Sweep/>{}</BehaviorTree></root>",
                format!("<{tag}>").repeat(depth),
                format!("</{tag}>").repeat(depth)
            )
            .into_bytes();
        }
        let Some((domain, atoms)) = rng.pick(&self.domains) else {
            return Vec::new();
        };
        let size = rng.small(40);
        let tree = random_tree(rng, atoms, domain, size);
        let mut xml = to_btcpp(&tree, domain, "T").unwrap_or_default();
        if rng.chance(30) {
            xml = xml.replace("Reactive", "");
        }
        xml.into_bytes()
    }

    fn check(&self, input: &[u8]) -> Result<(), Violation> {
        let text = text_of(input);
        for (domain, _) in &self.domains {
            self.read(&text, domain)?;
        }
        Ok(())
    }
}
