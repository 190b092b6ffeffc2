//! Tests of the vote among candidate goals and of reflective feedback.

use super::*;
use crate::session::interpret::judge::vote;

fn candidate(goal: Option<&str>, problem: Option<&str>) -> Candidate {
    Candidate {
        text: format!("Goal: {}", goal.unwrap_or("?")),
        read: match goal {
            Some(g) => Ok(GoalAnswer {
                goal: Formula::parse(g).expect("parses"),
                reasoning: None,
            }),
            None => Err(ReplyError::NoConditions),
        },
        problem: problem.map(|p| GoalProblem::wrong(p.to_string())),
        first: false,
    }
}

#[test]
fn the_largest_group_of_equivalent_survivors_wins() {
    let cs = vec![
        candidate(Some("Active_AC"), Some("holds already")),
        candidate(Some("On_Apple_Bar2"), None),
        candidate(Some("Active_TubeLight & ~Closed_Curtain"), None),
        candidate(Some("~Closed_Curtain & Active_TubeLight"), None),
        candidate(None, Some("unusable")),
    ];
    let chosen = vote(&cs, Candidate::clean).expect("a winner");
    assert_eq!(
        chosen.goal.to_string(),
        "Active_TubeLight & ~Closed_Curtain"
    );
    // A tie goes to the earliest.
    let cs = vec![
        candidate(Some("On_Apple_Bar2"), None),
        candidate(Some("On_Apple_Table3"), None),
    ];
    assert_eq!(
        vote(&cs, Candidate::clean)
            .expect("a winner")
            .goal
            .to_string(),
        "On_Apple_Bar2"
    );
    assert!(
        vote(
            &[candidate(Some("Active_AC"), Some("no"))],
            Candidate::clean
        )
        .is_none()
    );
}

#[test]
fn feedback_tells_each_problem_once() {
    let mut messages = vec![Message::user("request")];
    let cs = vec![
        candidate(Some("On_Chips_Bar"), Some("it holds already")),
        candidate(Some("On_Chips_Bar"), Some("it holds already")),
    ];
    feedback(&mut messages, &cs);
    assert_eq!(messages.len(), 3);
    assert_eq!(messages[1].role, Role::Assistant);
    assert_eq!(messages[2].content.matches("On_Chips_Bar").count(), 1);
}
