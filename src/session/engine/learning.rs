//! Keeping approved fixes as rules in the engine: after a change of conditions is applied
//! (and its verification passed), each condition is offered as a rule of the failing
//! action's skill, lifted to its objects where the vocabulary allows and, as the other
//! choice, only for the fix's objects. A rule a person keeps is checked
//! (`knowledge::check_rule`), written to the knowledge file and added to the engine's own
//! domain at once, so the rest of the session plans with it too. Nothing is kept unasked.

use std::sync::Arc;

use crate::domain::{ActionCall, Condition, LearnedRule};
use crate::session::knowledge::{self, KeptRule, Provenance, learned_in_tree, offered_rule};
use crate::session::types::{Event, Proposal};

use super::Engine;

/// The knowledge file, and the fixes of the last applied change that may be kept in it.
pub(super) struct Learning {
    /// Where kept rules are written (none: nothing is offered).
    knowledge: Option<knowledge::Knowledge>,
    offers: Vec<RuleOffer>,
}

impl Learning {
    pub(super) fn new(knowledge: Option<knowledge::Knowledge>) -> Learning {
        Learning {
            knowledge,
            offers: Vec::new(),
        }
    }
}

/// A fix that may be kept as a rule.
#[derive(Debug, Clone)]
pub(super) struct RuleOffer {
    action: ActionCall,
    condition: Condition,
    author: String,
    lifted: LearnedRule,
    only: LearnedRule,
}

impl Engine {
    /// Queue the conditions of an applied change as rule offers (only when the engine has
    /// a knowledge file), and show the first.
    pub(super) fn offer_rules(&mut self, proposal: &Proposal, author: &str) {
        if self.learning.knowledge.is_none() {
            return;
        }
        let Proposal::Conditions {
            action, conditions, ..
        } = proposal
        else {
            return;
        };
        self.learning.offers = conditions
            .iter()
            .map(|c| RuleOffer {
                action: action.clone(),
                condition: c.clone(),
                author: author.to_string(),
                lifted: offered_rule(action, c, false),
                only: offered_rule(action, c, true),
            })
            .collect();
        self.show_offer();
    }

    /// Offers of a change that was undone are gone with it.
    pub(super) fn drop_offers(&mut self) {
        self.learning.offers.clear();
    }

    fn show_offer(&self) {
        let Some(offer) = self.learning.offers.first() else {
            return;
        };
        let domain = &self.settings.scenario.domain;
        let general = offer.lifted != offer.only;
        self.emit(Event::RuleOffered {
            rule: if general {
                offer.lifted.describe(domain)
            } else {
                offer.only.describe(domain)
            },
            only: general.then(|| offer.only.describe(domain)),
            remaining: self.learning.offers.len(),
        });
    }

    /// Keep the first offer as a rule (`only`: for the fix's objects alone).
    pub(super) fn keep_rule(&mut self, only: bool) {
        if self.learning.offers.is_empty() {
            return self.error("no fix to keep as a rule: approve a fix of conditions first");
        }
        let offer = self.learning.offers.remove(0);
        let rule = if only { offer.only } else { offer.lifted };
        let settings = &mut self.settings;
        let words = rule.describe(&settings.scenario.domain);
        let Some(store) = self.learning.knowledge.as_mut() else {
            return;
        };
        if let Err(refusal) = knowledge::check_rule(&rule, &settings.scenario, store) {
            self.emit(Event::RuleRefused {
                rule: words,
                reason: refusal.to_string(),
            });
            return self.show_offer();
        }
        let kept = store.keep(KeptRule::new(
            &rule,
            &settings.scenario,
            Provenance {
                scenario_file: settings.scenario_path.display().to_string(),
                action: &offer.action,
                condition: &offer.condition,
                proposed_by: offer.author.clone(),
                kept_by: "a person (workbench)".into(),
            },
        ));
        match kept {
            Ok((kept, _)) => {
                let mut learned = rule.clone();
                learned.id = kept.id.clone();
                // Checked above: the rule fits this domain.
                let _ = Arc::make_mut(&mut settings.scenario).domain.learn(&learned);
                let path = store.path.clone();
                self.emit(Event::RuleKept {
                    id: kept.id,
                    rule: words,
                    path,
                });
                if let Some(tree) = self.task.tree.clone() {
                    // The tree is unchanged; its conditions from rules are marked now.
                    self.emit(Event::TreeChanged {
                        learned: learned_in_tree(&self.settings.scenario.domain, &tree)
                            .into_iter()
                            .map(|l| (l.node, l.rules))
                            .collect(),
                        tree: Arc::new(tree),
                        new_nodes: Vec::new(),
                        why: "a fix was kept as a rule".into(),
                    });
                }
            }
            Err(e) => self.error(format!("the rule was not kept: {e}")),
        }
        self.show_offer();
    }

    /// Keep `goal` as what `instruction` means, a worked example of the domain for later
    /// requests (this session's too), when the engine has a knowledge directory and the
    /// goal is one the scene can plan; said either way.
    pub(super) fn keep_correction(
        &mut self,
        instruction: &str,
        goal: &crate::goal::Formula,
        replaced: Option<&crate::goal::Formula>,
        kept_by: &str,
    ) {
        let settings = &mut self.settings;
        let Some(store) = self.learning.knowledge.as_mut() else {
            return;
        };
        let kept = store.examples.keep_correction(
            (&settings.scenario, &settings.scenario_path),
            (instruction, goal),
            replaced,
            kept_by,
        );
        match kept {
            Ok((kept, new)) => {
                if new {
                    // The pool's kept examples as the file holds them now (one the new
                    // example replaced is gone from both).
                    let scenario = Arc::make_mut(&mut settings.scenario);
                    scenario
                        .examples
                        .retain(|e| !matches!(e.source, crate::scenario::ExampleSource::Kept(_)));
                    let (kept_now, _) = store.examples.for_scenario(scenario);
                    scenario.examples.extend(kept_now);
                    crate::session::interpret::made_pool::fill(scenario);
                }
                let path = store.examples.path.display().to_string();
                self.notice(format!(
                    "correction kept as example {} of the {} domain: \u{ab}{}\u{bb} \u{2192} {}; later requests like it are read with it ({path}; betr knowledge revoke {} takes it out)",
                    kept.id, kept.domain, kept.instruction, kept.goal, kept.id
                ));
            }
            Err(e) => self.notice(e.to_string()),
        }
    }

    /// Keep nothing of the first offer.
    pub(super) fn decline_rule(&mut self) {
        if self.learning.offers.is_empty() {
            return self.error("no fix is offered as a rule");
        }
        self.learning.offers.remove(0);
        self.notice("not kept as a rule");
        self.show_offer();
    }

    /// The kept rules of this scenario's domain, in words, for a view.
    pub(super) fn show_knowledge(&self) {
        let Some(store) = &self.learning.knowledge else {
            return self.error("no knowledge file: the workbench has no policy directory");
        };
        let scenario = &self.settings.scenario;
        let domain = knowledge::domain_of(scenario);
        let rules = store
            .rules_of(&domain)
            .map(|r| {
                let words = r.rule().describe(&scenario.domain);
                format!(
                    "{}: {words}. From {} ({} before {}!), proposed by {}, kept by {} at {}",
                    r.id, r.scenario, r.condition, r.action, r.proposed_by, r.kept_by, r.kept_at
                )
            })
            .collect();
        self.emit(Event::Knowledge {
            path: store.path.clone(),
            rules,
        });
    }
}
