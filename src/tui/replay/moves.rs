//! Moving in a replay: a position is the number of steps applied (0: nothing yet, the
//! number of steps: the end). Ticks, failures and model calls are stops found by binary
//! search in lists made once.

use crate::record::Step;
use crate::session::Event;

use super::super::keys::Action;

/// Where a key asks the replay to go.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Move {
    /// One step (an event or a command).
    EventForward,
    EventBack,
    TickForward,
    TickBack,
    NextFailure,
    PreviousFailure,
    NextModelCall,
    PreviousModelCall,
    Start,
    End,
}

impl Move {
    /// The move a key's action asks for, if it is one.
    pub fn of(action: Action) -> Option<Move> {
        Some(match action {
            Action::EventForward => Move::EventForward,
            Action::EventBack => Move::EventBack,
            Action::TickForward => Move::TickForward,
            Action::TickBack => Move::TickBack,
            Action::NextFailure => Move::NextFailure,
            Action::PreviousFailure => Move::PreviousFailure,
            Action::NextModelCall => Move::NextModelCall,
            Action::PreviousModelCall => Move::PreviousModelCall,
            Action::Start => Move::Start,
            Action::End => Move::End,
            _ => return None,
        })
    }

    /// What the move looks for, to say there is none.
    pub fn looks_for(self) -> &'static str {
        match self {
            Move::EventForward | Move::End => "later step",
            Move::EventBack | Move::Start => "earlier step",
            Move::TickForward => "later tick",
            Move::TickBack => "earlier tick",
            Move::NextFailure => "later failed action",
            Move::PreviousFailure => "earlier failed action",
            Move::NextModelCall => "later model call",
            Move::PreviousModelCall => "earlier model call",
        }
    }
}

/// The positions each kind of move stops at.
#[derive(Debug, Clone, Default)]
pub struct Stops {
    /// After each tick and the change of facts it made, so the world pane shows the
    /// tick's world.
    ticks: Vec<usize>,
    /// After each failed action.
    failures: Vec<usize>,
    /// After each question to the model and each reply.
    model_calls: Vec<usize>,
    steps: usize,
}

impl Stops {
    pub fn new<'a>(steps: impl IntoIterator<Item = &'a Step>) -> Stops {
        let mut stops = Stops::default();
        let mut steps = steps.into_iter().enumerate().peekable();
        while let Some((i, step)) = steps.next() {
            stops.steps = i + 1;
            let Step::Event(event) = step else { continue };
            match event {
                Event::Ticked { .. } => {
                    let facts_follow = matches!(
                        steps.peek(),
                        Some((_, Step::Event(Event::WorldChanged { reset: false, .. })))
                    );
                    stops.ticks.push(i + 1 + usize::from(facts_follow));
                }
                Event::ActionFailed { .. } => stops.failures.push(i + 1),
                Event::Asking { .. } | Event::Replied { .. } => stops.model_calls.push(i + 1),
                _ => {}
            }
        }
        stops
    }

    /// Where `m` goes from position `p`; `None` when there is nothing that way.
    pub fn target(&self, p: usize, m: Move) -> Option<usize> {
        let p = p.min(self.steps);
        let target = match m {
            Move::EventForward => (p < self.steps).then_some(p + 1),
            Move::EventBack => p.checked_sub(1),
            Move::TickForward => after(&self.ticks, p),
            Move::TickBack => before(&self.ticks, p),
            Move::NextFailure => after(&self.failures, p),
            Move::PreviousFailure => before(&self.failures, p),
            Move::NextModelCall => after(&self.model_calls, p),
            Move::PreviousModelCall => before(&self.model_calls, p),
            Move::Start => Some(0),
            Move::End => Some(self.steps),
        };
        target.filter(|&q| q != p)
    }
}

/// The first stop after `p`.
fn after(stops: &[usize], p: usize) -> Option<usize> {
    stops.get(stops.partition_point(|&s| s <= p)).copied()
}

/// The last stop before `p`.
fn before(stops: &[usize], p: usize) -> Option<usize> {
    stops
        .partition_point(|&s| s < p)
        .checked_sub(1)
        .and_then(|i| stops.get(i))
        .copied()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stops_are_found_both_ways_and_nothing_is_none() {
        let stops = Stops {
            ticks: vec![2, 5, 9],
            failures: vec![6],
            model_calls: Vec::new(),
            steps: 10,
        };
        assert_eq!(stops.target(0, Move::TickForward), Some(2));
        assert_eq!(stops.target(2, Move::TickForward), Some(5));
        assert_eq!(stops.target(5, Move::TickBack), Some(2));
        assert_eq!(stops.target(6, Move::TickBack), Some(5));
        assert_eq!(stops.target(2, Move::TickBack), None);
        assert_eq!(stops.target(9, Move::TickForward), None);
        assert_eq!(stops.target(10, Move::PreviousFailure), Some(6));
        assert_eq!(stops.target(6, Move::PreviousFailure), None);
        assert_eq!(stops.target(3, Move::NextModelCall), None);
        assert_eq!(stops.target(10, Move::EventForward), None);
        assert_eq!(stops.target(10, Move::EventBack), Some(9));
        assert_eq!(stops.target(0, Move::EventBack), None);
        assert_eq!(stops.target(0, Move::Start), None);
        assert_eq!(stops.target(4, Move::End), Some(10));
    }
}
