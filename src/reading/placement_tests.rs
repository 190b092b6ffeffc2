use super::*;
use crate::domain::{Predicate, StateWords, Vocabulary};

fn object(name: &str, types: &[&str]) -> Object {
    Object {
        name: name.into(),
        types: types.iter().map(|t| t.to_string()).collect(),
        called: Vec::new(),
    }
}

fn predicate(name: &str, slots: &[&str], says: &[&str]) -> Predicate {
    Predicate {
        name: name.into(),
        arg_types: slots
            .iter()
            .map(|s| s.split('|').map(str::to_string).collect())
            .collect(),
        description: String::new(),
        words: StateWords {
            says: says.iter().map(|w| w.to_string()).collect(),
            opposite: Vec::new(),
        },
    }
}

fn vocabulary() -> Vocabulary {
    Vocabulary {
        objects: vec![
            object("Dessert", &["item", "makable"]),
            object("Water", &["item", "makable"]),
            object("Coffee", &["item", "makable"]),
            object("Cup", &["item"]),
            object("Bar", &["place"]),
            object("Table1", &["place"]),
            object("Table2", &["place"]),
            object("CoffeeStation", &["place"]),
            object("Chips", &["item"]),
            object("WindowTable6", &["place"]),
        ],
        predicates: vec![
            predicate("On", &["item", "place"], &[]),
            predicate("Exists", &["makable"], &["make", "prepare"]),
            predicate("RobotNear", &["place|item"], &["near"]),
            predicate("Holding", &["item"], &["hold"]),
        ],
    }
}

fn put(goal: &str, request: &str) -> Option<String> {
    let goal = Formula::parse(goal).expect("test goal parses");
    put_there(&goal, &Request::among(request, &vocabulary())).map(|g| g.to_string())
}

fn flagged(goal: &str, request: &str) -> Option<(String, String)> {
    let goal = Formula::parse(goal).expect("test goal parses");
    not_put(&goal, &Request::among(request, &vocabulary())).map(|s| (s.item, s.place))
}

#[test]
fn an_item_made_and_the_robot_at_the_place_is_not_the_item_put_there() {
    let request = "Please deliver dessert to table 1.";
    assert_eq!(
        flagged("Exists_Dessert & RobotNear_Table1", request),
        Some(("Dessert".into(), "Table1".into()))
    );
    assert_eq!(flagged("On_Dessert_Table1", request), None);
    assert_eq!(
        put("Exists_Dessert & RobotNear_Table1", request).as_deref(),
        Some("On_Dessert_Table1")
    );
    // A number announced by "number" still names the table.
    let request = "Please deliver the cup to table number one";
    assert_eq!(
        flagged("Holding_Cup", request),
        Some(("Cup".into(), "Table1".into()))
    );
    assert_eq!(
        put("Holding_Cup & RobotNear_Table1", request).as_deref(),
        Some("On_Cup_Table1")
    );
    assert_eq!(
        put(
            "Exists_Dessert & RobotNear_Bar",
            "I would like a dessert at the bar, please"
        )
        .as_deref(),
        Some("On_Dessert_Bar")
    );
}

#[test]
fn each_alternative_and_each_item_goes_to_its_own_place() {
    assert_eq!(
        put(
            "Exists_Dessert & RobotNear_Table1 | Exists_Water & RobotNear_Table2",
            "Deliver some dessert to Table 1 or bring water to Table 2"
        )
        .as_deref(),
        Some("On_Dessert_Table1 | On_Water_Table2")
    );
    assert_eq!(
        put(
            "(Exists_Coffee | Exists_Dessert) & RobotNear_Table2",
            "A coffee or a dessert at table 2, please"
        )
        .as_deref(),
        Some("On_Coffee_Table2 | On_Dessert_Table2")
    );
    // A place's name holds an item's ("coffee" of the coffee station): the item is the
    // dessert alone.
    assert_eq!(
        put(
            "Exists_Dessert & RobotNear_CoffeeStation",
            "Deliver dessert to the coffee station"
        )
        .as_deref(),
        Some("On_Dessert_CoffeeStation")
    );
}

#[test]
fn the_robots_own_moving_and_conditions_asked_in_their_words_stay() {
    // The robot comes to the table; nothing is sent there.
    assert_eq!(
        flagged(
            "Exists_Coffee & RobotNear_Table2",
            "Make coffee and come to table 2"
        ),
        None
    );
    assert_eq!(
        put(
            "Exists_Coffee & RobotNear_Table2",
            "Make coffee and come to table 2"
        ),
        None
    );
    // "hold" asks for holding; "near" for the robot near.
    assert_eq!(
        flagged("Holding_Cup & RobotNear_Bar", "Hold the cup near the bar"),
        None
    );
    assert_eq!(
        put("Holding_Cup & RobotNear_Bar", "Hold the cup near the bar"),
        None
    );
    // A goal that leaves the item out is another misreading, not this one.
    assert_eq!(
        flagged("RobotNear_Table1", "Deliver dessert to table 1"),
        None
    );
    // A clause ends at a comma: "the dessert" is not sent to the bar.
    assert_eq!(
        flagged(
            "Exists_Dessert & RobotNear_Bar",
            "Make the dessert, then wait at the bar"
        ),
        None
    );
}

#[test]
fn the_scenes_own_worked_examples_put_what_they_send() {
    crate::session::for_each_worked_example(|scene, scenario, example, goal| {
        let vocabulary = &scenario.domain.vocabulary;
        let request = &example.instruction;
        assert_eq!(
            not_put(goal, &Request::among(request, vocabulary)),
            None,
            "{scene}: {request:?}"
        );
        assert_eq!(
            put_there(goal, &Request::among(request, vocabulary)),
            None,
            "{scene}: {request:?}"
        );
    });
}

#[test]
fn alternatives_and_an_item_with_no_place_at_all_are_put_there() {
    // One alternative sent there is enough to put both: the other is what the request
    // names beside it, in other words.
    assert_eq!(
        put(
            "(Exists_Coffee | Exists_Dessert) & RobotNear_Table2",
            "Bring a coffee or a cake to table 2."
        )
        .as_deref(),
        Some("On_Coffee_Table2 | On_Dessert_Table2")
    );
    // Made, and no condition about the station at all.
    assert_eq!(
        put("Exists_Dessert", "Deliver dessert to CoffeeStation.").as_deref(),
        Some("On_Dessert_CoffeeStation")
    );
    // A condition about the place that is no place-alone one: left as it is.
    assert_eq!(
        put(
            "Exists_Dessert & ~On_Cup_Bar",
            "Make dessert, put it on the bar, no cup on the bar."
        ),
        None
    );
}

#[test]
fn an_item_at_a_place_the_request_never_names_is_moved_where_it_is_sent() {
    let v = vocabulary();
    let moved = |goal: &str, request: &str| {
        let goal = Formula::parse(goal).expect("test goal parses");
        moved_there(&goal, &Request::among(request, &v)).map(|g| g.to_string())
    };
    assert_eq!(
        moved(
            "On_Coffee_Table2 & RobotNear_Bar",
            "Bring a coffee to the bar."
        )
        .as_deref(),
        Some("On_Coffee_Bar & RobotNear_Bar")
    );
    // The request names both places: which one was meant is the model's to say.
    assert_eq!(
        moved(
            "On_Coffee_Table2",
            "Bring a coffee to the bar, not table 2."
        ),
        None
    );
    // Sent to two places: not moved.
    assert_eq!(
        moved(
            "On_Coffee_Table2",
            "Coffee to the bar, and coffee to table 1."
        ),
        None
    );
    // The place it comes from is not where it is sent, and an item left there is moved.
    assert_eq!(
        flagged("On_Cup_Table1", "Take the cup in from table 1 to the bar."),
        Some(("Cup".into(), "Bar".into()))
    );
    assert_eq!(
        moved("On_Cup_Table1", "Take the cup in from table 1 to the bar.").as_deref(),
        Some("On_Cup_Bar")
    );
}

#[test]
fn an_alternative_about_an_item_alone_is_put_where_it_is_sent() {
    assert_eq!(
        put(
            "Active_AC & (Exists_Dessert | On_Water_Table2)",
            "Turn on the AC, and either bring a dessert to table 1 or water to table 2."
        )
        .as_deref(),
        Some("Active_AC & (On_Dessert_Table1 | On_Water_Table2)")
    );
    // The goal has a condition about that place already: left as it is.
    assert_eq!(
        put(
            "RobotNear_Table1 & (Exists_Dessert | On_Water_Table2)",
            "Wait near table 1, and either bring a dessert to table 1 or water to table 2."
        ),
        None
    );
}
