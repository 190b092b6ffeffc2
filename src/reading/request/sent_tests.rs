use super::*;
use crate::domain::StateWords;
use crate::reading::words::every_term;

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

#[test]
fn items_sent_where_no_name_says_are_not_sent_to_the_next_place() {
    let v = vocabulary();
    let sent = |request: &str| {
        sent(&Request::among(request, &v))
            .into_iter()
            .map(|s| format!("{}@{}", s.item, s.place))
            .collect::<Vec<_>>()
    };
    assert_eq!(
        sent("Take a coffee to the sofa by the door and water to table 2."),
        ["Water@Table2"]
    );
    assert_eq!(
        sent("Bring the coffee to me at table 2."),
        ["Coffee@Table2"]
    );
}

#[test]
fn a_name_spread_over_a_few_words_is_a_mention() {
    let v = vocabulary();
    let objects: Vec<&Object> = v.objects.iter().collect();
    let named = |request: &str| {
        mentions(&every_term(request), &objects, &[])
            .into_iter()
            .map(|(_, _, name)| name)
            .collect::<Vec<_>>()
    };
    assert_eq!(
        named("chips to table 6 by the window"),
        ["Chips", "WindowTable6"]
    );
    assert_eq!(
        named("chips to the window table 6"),
        ["Chips", "WindowTable6"]
    );
    // Too far apart: the window is not the table's.
    assert_eq!(named("by the window, chips go to the table 6"), ["Chips"]);
}
