//! How sure a reading is: the evidence for it, gathered while it was read, summed up in a
//! doubt level. A doubtful reading waits for a person as a choice of readings does, so a
//! wrong first reading comes with a mark on it that says where to look.
//!
//! The evidence is what the reading already had to find out: whether the model's first
//! answer survived the checks, how far ahead of its runner-up with another goal it was
//! among the model's beams, how many candidates agreed, whether the request needed
//! feedback, what the checks doubted, and whether the request was read in parts. The rule
//! that sums them up was calibrated on the tuned sets of `docs/eval-suite.toml` and is
//! measured on the others (docs/EVAL.md, "Doubt").

use serde::{Deserialize, Serialize};

/// The log-probability margin (nats) under which the model's best beam is too close to a
/// beam with another goal to be trusted: calibrated on the tuned sets.
pub const MARGIN_SURE: f64 = 1.0;

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
    /// The reasons against the goal chosen, each in words; none: the doubt is low.
    pub fn against(&self) -> Vec<String> {
        let mut out = Vec::new();
        if let Some(why) = &self.checked_doubt {
            out.push(why.clone());
        }
        if !self.first_kept {
            out.push("the model's first answer failed its checks".into());
        }
        if self.feedback_rounds > 0 {
            out.push(format!(
                "found after {} round(s) of feedback",
                self.feedback_rounds
            ));
        }
        if let Some(m) = self.margin.filter(|m| *m < MARGIN_SURE) {
            out.push(format!(
                "the model almost wrote another goal (margin {m:.2} between its beams)"
            ));
        }
        out
    }

    pub fn level(&self) -> Level {
        if self.against().is_empty() {
            Level::Low
        } else {
            Level::Doubtful
        }
    }

    /// Why the reading is doubtful, in one line; `None` when the doubt is low.
    pub fn doubt(&self) -> Option<String> {
        let against = self.against();
        (!against.is_empty()).then(|| against.join("; "))
    }

    /// The doubt level and what it rests on, in one line, for beside the goal.
    pub fn summary(&self) -> String {
        if let Some(why) = self.doubt() {
            return format!("doubtful: {why}");
        }
        let mut for_it = vec!["first answer kept".to_string()];
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
    fn each_reason_alone_makes_a_reading_doubtful() {
        assert_eq!(sure().level(), Level::Low);
        assert!(sure().summary().starts_with("doubt low"));
        let close = Evidence {
            margin: Some(0.4),
            ..sure()
        };
        assert_eq!(close.level(), Level::Doubtful);
        assert!(close.doubt().unwrap().contains("margin 0.40"));
        let replaced = Evidence {
            first_kept: false,
            ..sure()
        };
        assert_eq!(replaced.level(), Level::Doubtful);
        let fed_back = Evidence {
            feedback_rounds: 1,
            ..sure()
        };
        assert_eq!(fed_back.level(), Level::Doubtful);
        let checked = Evidence {
            checked_doubt: Some("it holds already".into()),
            ..sure()
        };
        assert_eq!(checked.doubt().as_deref(), Some("it holds already"));
        // No beams to compare is no evidence against.
        let greedy = Evidence {
            margin: None,
            ..sure()
        };
        assert_eq!(greedy.level(), Level::Low);
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
