//! How sure a reading is: the evidence for it, gathered while it was read, summed up in a
//! doubt level. A doubtful reading waits for a person as a choice of readings does, so a
//! wrong first reading comes with a mark on it that says where to look.
//!
//! The evidence is what the reading already had to find out: whether the model's first
//! answer survived the checks, how far ahead of its runner-up with another goal it was
//! among the model's beams, how many candidates agreed, whether the request needed
//! feedback, what the checks doubted, and whether the request was read in parts. What speaks
//! against a reading raises the margin between the model's beams it needs to run without
//! a person. The rule was calibrated on the tuned sets of `docs/eval-suite.toml` and is
//! measured on the others (docs/EVAL.md, "Doubt").

use serde::{Deserialize, Serialize};

/// The beam margin (log-probability, nats) a reading needs to run without a person when
/// nothing else speaks against it; what does speak against it raises the margin needed.
/// Calibrated on the sets the reading was tuned on (the cafe dataset, the cafe's first
/// held-out requests, the cell's scenarios: docs/EVAL.md, "Doubt"); the margin alone
/// tells a right reading from a wrong one poorly, what speaks against it well.
pub const MARGIN_NEEDED: f64 = 0.1;
/// What the model's first answer failing its checks adds to the margin needed.
const IF_REPLACED: f64 = 3.0;
/// What a doubt of the checks (it holds already, a condition from an example) adds.
const IF_CHECKS_DOUBT: f64 = 2.0;
/// What reading the request in parts adds (the margin is the weakest part's).
const IF_PARTS: f64 = 1.0;
/// What needing feedback adds.
const IF_FEEDBACK: f64 = 2.0;
/// A margin beyond this says nothing more (every beam alike counts as this).
const MARGIN_CAP: f64 = 5.0;

/// What was found while reading a request, for and against the goal chosen.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Evidence {
    /// The model's first answer is the goal chosen.
    pub first_kept: bool,
    /// How far the model's best beam is ahead (log-probability, nats) of its best beam
    /// with another goal; `None` when there were no beams or every beam read alike.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub margin: Option<f64>,
    /// How many beams the model searched for its first answer (0 or 1: no runner-up to
    /// compare with).
    #[serde(default)]
    pub beams: usize,
    /// Candidates with the chosen goal, of the usable candidates of the round it won.
    pub votes: usize,
    pub candidates: usize,
    /// Rounds of feedback the reading needed.
    pub feedback_rounds: usize,
    /// What the checks doubt about the goal chosen (it holds already, a condition comes
    /// from an example), when anything.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub checked_doubt: Option<String>,
    /// Wishes the request was read in, each on its own (0: read whole).
    #[serde(default)]
    pub parts: usize,
}

/// The doubt level a reading's evidence sums up to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Level {
    /// Nothing speaks against it: it runs without a person (`--yes` takes it).
    Low,
    /// It waits for a person, who sees why.
    Doubtful,
}

impl Evidence {
    /// The margin this reading needs, what speaks against it added.
    pub fn margin_needed(&self) -> f64 {
        let mut needed = MARGIN_NEEDED;
        if !self.first_kept {
            needed += IF_REPLACED;
        }
        if self.checked_doubt.is_some() {
            needed += IF_CHECKS_DOUBT;
        }
        if self.parts > 1 {
            needed += IF_PARTS;
        }
        if self.feedback_rounds > 0 {
            needed += IF_FEEDBACK;
        }
        needed
    }

    /// The margin the model's beams give, capped; `None` when no beams were searched (a
    /// backend without them).
    fn margin_known(&self) -> Option<f64> {
        match (self.margin, self.beams) {
            (Some(m), _) => Some(m.min(MARGIN_CAP)),
            (None, beams) if beams > 1 => Some(MARGIN_CAP),
            _ => None,
        }
    }

    pub fn level(&self) -> Level {
        let needed = self.margin_needed();
        let doubtful = match self.margin_known() {
            Some(m) => m < needed,
            // Without beams, anything against it but being read in parts.
            None => needed > MARGIN_NEEDED + IF_PARTS,
        };
        if doubtful {
            Level::Doubtful
        } else {
            Level::Low
        }
    }

    /// Why the reading is doubtful, in one line; `None` when the doubt is low.
    pub fn doubt(&self) -> Option<String> {
        if self.level() == Level::Low {
            return None;
        }
        let mut against = Vec::new();
        if let Some(why) = &self.checked_doubt {
            against.push(why.clone());
        }
        if !self.first_kept {
            against.push("the model's first answer failed its checks".into());
        }
        if self.feedback_rounds > 0 {
            against.push(format!(
                "found after {} round(s) of feedback",
                self.feedback_rounds
            ));
        }
        if let Some(m) = self.margin_known() {
            against.push(format!(
                "the model's margin over another goal is {m:.2}, under the {:.2} this reading needs",
                self.margin_needed()
            ));
        }
        Some(against.join("; "))
    }

    /// The doubt level and what it rests on, in one line, for beside the goal.
    pub fn summary(&self) -> String {
        if let Some(why) = self.doubt() {
            return format!("doubtful: {why}");
        }
        let mut for_it = vec![
            if self.first_kept {
                "first answer kept"
            } else {
                "first answer replaced"
            }
            .to_string(),
        ];
        match self.margin {
            Some(m) => for_it.push(format!("margin {m:.2} over another goal")),
            None if self.beams > 1 => for_it.push(format!("all {} beams alike", self.beams)),
            None => {}
        }
        if self.candidates > 1 {
            for_it.push(format!(
                "{} of {} candidates agree",
                self.votes, self.candidates
            ));
        }
        if self.parts > 1 {
            for_it.push(format!("{} parts", self.parts));
        }
        format!("doubt low: {}", for_it.join(", "))
    }

    /// The evidence of a goal joined from parts read each on its own: the weakest part's
    /// margin, every part's first answer kept, the most feedback a part needed; the joined
    /// goal's own checks' doubt.
    pub fn joined(parts: &[Evidence], checked_doubt: Option<String>) -> Evidence {
        Evidence {
            first_kept: parts.iter().all(|p| p.first_kept),
            margin: parts
                .iter()
                .filter_map(|p| p.margin)
                .min_by(|a, b| a.total_cmp(b)),
            beams: parts.iter().map(|p| p.beams).min().unwrap_or(0),
            votes: parts.iter().map(|p| p.votes).min().unwrap_or(0),
            candidates: parts.iter().map(|p| p.candidates).max().unwrap_or(0),
            feedback_rounds: parts.iter().map(|p| p.feedback_rounds).max().unwrap_or(0),
            checked_doubt,
            parts: parts.len(),
        }
    }
}

/// The margin between the best beam and the best beam whose goal is another: `beams` are
/// the beams' goals (`None`: unreadable) with their log-probabilities, best first, and
/// `same` says whether two goals are one.
pub fn margin<G>(beams: &[(Option<G>, f64)], same: impl Fn(&G, &G) -> bool) -> Option<f64> {
    let (Some(best), score) = beams.first()? else {
        return None;
    };
    beams
        .iter()
        .skip(1)
        .filter_map(|(g, s)| Some((g.as_ref()?, *s)))
        .find(|(g, _)| !same(best, g))
        .map(|(_, s)| score - s)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sure() -> Evidence {
        Evidence {
            first_kept: true,
            margin: Some(3.0),
            votes: 1,
            candidates: 1,
            ..Evidence::default()
        }
    }

    #[test]
    fn what_speaks_against_a_reading_raises_the_margin_it_needs() {
        assert_eq!(sure().level(), Level::Low);
        assert!(sure().summary().starts_with("doubt low"));
        let close = Evidence {
            margin: Some(0.05),
            ..sure()
        };
        assert_eq!(close.level(), Level::Doubtful);
        assert!(close.doubt().unwrap().contains("0.05, under the 0.10"));
        // Replaced by another candidate: doubtful unless the beams were far apart.
        let replaced = Evidence {
            first_kept: false,
            ..sure()
        };
        assert_eq!(replaced.level(), Level::Doubtful);
        let replaced_far = Evidence {
            first_kept: false,
            margin: Some(4.5),
            ..sure()
        };
        assert_eq!(replaced_far.level(), Level::Low);
        let checked = Evidence {
            checked_doubt: Some("it holds already".into()),
            margin: Some(1.2),
            ..sure()
        };
        assert!(checked.doubt().unwrap().starts_with("it holds already"));
        let fed_back = Evidence {
            feedback_rounds: 1,
            margin: Some(2.0),
            ..sure()
        };
        assert_eq!(fed_back.level(), Level::Doubtful);
        // Every beam alike is as sure as beams go.
        let alike = Evidence {
            margin: None,
            beams: 4,
            ..sure()
        };
        assert_eq!(alike.level(), Level::Low);
        // No beams searched: what speaks against it decides alone.
        let greedy = Evidence {
            margin: None,
            beams: 0,
            ..sure()
        };
        assert_eq!(greedy.level(), Level::Low);
        let greedy_replaced = Evidence {
            first_kept: false,
            ..greedy.clone()
        };
        assert_eq!(greedy_replaced.level(), Level::Doubtful);
        let greedy_parts = Evidence { parts: 2, ..greedy };
        assert_eq!(greedy_parts.level(), Level::Low);
    }

    #[test]
    fn the_margin_is_to_the_best_beam_with_another_goal() {
        let same = |a: &&str, b: &&str| a == b;
        let beams = [
            (Some("A"), -1.0),
            (Some("A"), -1.5),
            (None, -1.6),
            (Some("B"), -2.5),
        ];
        assert_eq!(margin(&beams, same), Some(1.5));
        assert_eq!(margin(&[(Some("A"), -1.0), (Some("A"), -2.0)], same), None);
        assert_eq!(margin(&[(None, -1.0), (Some("A"), -2.0)], same), None);
        assert_eq!(margin::<&str>(&[], same), None);
    }

    #[test]
    fn a_joined_reading_is_as_sure_as_its_weakest_part() {
        let close = Evidence {
            margin: Some(0.2),
            ..sure()
        };
        let joined = Evidence::joined(&[sure(), close], None);
        assert_eq!(joined.margin, Some(0.2));
        assert_eq!(joined.parts, 2);
        assert_eq!(joined.level(), Level::Doubtful);
        assert_eq!(
            Evidence::joined(&[sure(), sure()], None).level(),
            Level::Low
        );
    }
}
