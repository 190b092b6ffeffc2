//! What a tick returns (`Outcome`) and what a node showed during one tick (`Status`).
//!
//! `Outcome` is the three-valued result every node hands to its parent. `Status` adds the
//! two things an observer of a tick needs besides that result: whether the tick reached the
//! node at all (`Idle`), and whether a previously running action was stopped (`Halted`).

use std::fmt;

/// The result of ticking a node once.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum Outcome {
    /// The node has not finished yet; tick again to make progress.
    Running,
    /// The node achieved what it stands for (condition holds, action done, all children done).
    Success,
    /// The node could not achieve what it stands for.
    Failure,
}

/// What a node showed in one tick.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Status {
    /// Not reached by this tick.
    #[default]
    Idle,
    /// Ticked and returned `Running`.
    Running,
    /// Ticked and returned `Success`.
    Success,
    /// Ticked and returned `Failure`.
    Failure,
    /// Was `Running` in the previous tick and was stopped because this tick no longer
    /// reached it.
    Halted,
}

/// A result a person imposes on a node (a debugger's "force"): the node returns it
/// without its own logic running, so a forced condition is not checked, a forced action
/// is not stepped, and a forced composite does not tick its children.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize,
)]
pub enum Forced {
    Success,
    Failure,
    Running,
}

impl Forced {
    /// The outcome the forced node hands to its parent.
    pub fn outcome(self) -> Outcome {
        match self {
            Forced::Success => Outcome::Success,
            Forced::Failure => Outcome::Failure,
            Forced::Running => Outcome::Running,
        }
    }
}

impl fmt::Display for Forced {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.outcome().fmt(f)
    }
}

impl From<Outcome> for Status {
    fn from(outcome: Outcome) -> Self {
        match outcome {
            Outcome::Running => Status::Running,
            Outcome::Success => Status::Success,
            Outcome::Failure => Status::Failure,
        }
    }
}

impl Status {
    /// The status as one letter (`-` idle, `R` running, `S` success, `F` failure, `H`
    /// halted), as a recording writes a tick's statuses.
    pub fn letter(self) -> char {
        match self {
            Status::Idle => '-',
            Status::Running => 'R',
            Status::Success => 'S',
            Status::Failure => 'F',
            Status::Halted => 'H',
        }
    }

    /// The status a letter of [`Status::letter`] stands for.
    pub fn from_letter(letter: char) -> Option<Status> {
        Some(match letter {
            '-' => Status::Idle,
            'R' => Status::Running,
            'S' => Status::Success,
            'F' => Status::Failure,
            'H' => Status::Halted,
            _ => return None,
        })
    }

    /// True for `Running`.
    pub fn is_active(self) -> bool {
        matches!(self, Status::Running)
    }

    /// True for `Success` and `Failure`.
    pub fn is_completed(self) -> bool {
        matches!(self, Status::Success | Status::Failure)
    }
}

impl fmt::Display for Outcome {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Outcome::Running => "running",
            Outcome::Success => "success",
            Outcome::Failure => "failure",
        })
    }
}

impl fmt::Display for Status {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Status::Idle => "idle",
            Status::Running => "running",
            Status::Success => "success",
            Status::Failure => "failure",
            Status::Halted => "halted",
        })
    }
}

/// Serde for every node's status in a tick: one letter per node, in arena order, so a
/// tick of a large tree stays one short string (a session writes thousands of ticks).
pub(crate) mod letters {
    use super::Status;

    pub fn serialize<S: serde::Serializer>(statuses: &[Status], s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(&statuses.iter().map(|st| st.letter()).collect::<String>())
    }

    pub fn deserialize<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Vec<Status>, D::Error> {
        let text = <String as serde::Deserialize>::deserialize(d)?;
        text.chars()
            .map(|c| {
                Status::from_letter(c)
                    .ok_or_else(|| serde::de::Error::custom(format!("{c:?} is not a status")))
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outcome_maps_to_status() {
        assert_eq!(Status::from(Outcome::Running), Status::Running);
        assert_eq!(Status::from(Outcome::Success), Status::Success);
        assert_eq!(Status::from(Outcome::Failure), Status::Failure);
    }

    #[test]
    fn predicates() {
        assert!(Status::Running.is_active());
        for s in [
            Status::Idle,
            Status::Success,
            Status::Failure,
            Status::Halted,
        ] {
            assert!(!s.is_active(), "{s}");
        }
        assert!(Status::Success.is_completed());
        assert!(Status::Failure.is_completed());
        for s in [Status::Idle, Status::Running, Status::Halted] {
            assert!(!s.is_completed(), "{s}");
        }
        assert_eq!(Status::default(), Status::Idle);
    }
}
