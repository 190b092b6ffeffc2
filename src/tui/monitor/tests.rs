use std::time::Duration;

use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
use ratatui::Terminal;
use ratatui::backend::TestBackend;

use crate::monitor::{Address, NodeStatus, Transition, WatchEvent, WatchedTree};

use super::{Connection, MonitorScreen, view};

const TREE: &str = r#"<root BTCPP_format="4">
  <BehaviorTree ID="Main" _fullpath="">
    <Fallback name="serve" _uid="1">
      <ReactiveSequence name="ready_then_work" _uid="2">
        <Inverter name="not_blocked" _uid="3"><IsBlocked name="blocked" _uid="4"/></Inverter>
        <SubTree ID="Work" _fullpath="Work::5" _uid="5"/>
      </ReactiveSequence>
      <Recover name="recover" _uid="8"/>
    </Fallback>
  </BehaviorTree>
  <BehaviorTree ID="Work" _fullpath="Work">
    <RetryUntilSuccessful name="retry" _uid="6" num_attempts="3">
      <Grasp name="grasp" _uid="7" target="{cup}"/>
    </RetryUntilSuccessful>
  </BehaviorTree>
  <TreeNodesModel>
    <Condition ID="IsBlocked"/><Action ID="Grasp"/><Action ID="Recover"/>
    <Control ID="Fallback"/><Control ID="ReactiveSequence"/>
    <Decorator ID="Inverter"/><Decorator ID="RetryUntilSuccessful"/>
  </TreeNodesModel>
</root>"#;

fn connected() -> MonitorScreen {
    let address = Address::parse(":1667").expect("an address");
    let mut screen = MonitorScreen::new(address.clone(), false);
    let tree = WatchedTree::parse(TREE.as_bytes()).expect("the tree reads");
    screen.on_watch(WatchEvent::Connected {
        address,
        tree: Box::new(tree),
        statuses: vec![],
        since: Duration::from_millis(250),
        started: None,
    });
    screen
}

fn change(micros: u64, uid: u16, status: NodeStatus) -> Transition {
    Transition {
        micros,
        uid,
        status,
    }
}

fn drawn(screen: &mut MonitorScreen) -> String {
    drawn_at(screen, 110, 20)
}

fn drawn_at(screen: &mut MonitorScreen, width: u16, height: u16) -> String {
    let mut terminal = Terminal::new(TestBackend::new(width, height)).expect("a test terminal");
    terminal
        .draw(|f| view::draw(f, screen))
        .expect("the screen draws");
    format!("{}", terminal.backend())
}

#[test]
fn the_screen_follows_the_node_the_robot_is_busy_in() {
    let mut screen = connected();
    screen.on_watch(WatchEvent::Changes(vec![
        change(1_000, 1, NodeStatus::Running),
        change(1_100, 2, NodeStatus::Running),
        change(1_200, 4, NodeStatus::Failure),
        change(1_300, 3, NodeStatus::Success),
        change(1_400, 5, NodeStatus::Running),
        change(1_500, 6, NodeStatus::Running),
        change(1_600, 7, NodeStatus::Running),
    ]));
    assert_eq!(screen.selected(), Some(6), "the grasp, deepest running");
    insta::assert_snapshot!(drawn(&mut screen));

    // Moving by hand stops following; `f` follows again.
    screen.on_key(KeyEvent::new(KeyCode::Up, KeyModifiers::NONE));
    assert_eq!(screen.selected(), Some(5));
    screen.on_watch(WatchEvent::Changes(vec![change(
        2_000,
        8,
        NodeStatus::Running,
    )]));
    assert_eq!(screen.selected(), Some(5));
    screen.on_key(KeyEvent::new(KeyCode::Char('f'), KeyModifiers::NONE));
    assert_eq!(screen.selected(), Some(7), "the recovery, now last running");
}

#[test]
fn a_lost_connection_is_shown_with_the_tree_as_last_seen() {
    let mut screen = connected();
    screen.on_watch(WatchEvent::Changes(vec![change(
        10,
        1,
        NodeStatus::Running,
    )]));
    screen.on_watch(WatchEvent::Lost(
        "the connection to 127.0.0.1:1667 was lost: timed out".into(),
    ));
    // A failed try afterwards does not hide that it was lost.
    screen.on_watch(WatchEvent::Waiting("no Groot2 publisher answers".into()));
    assert!(matches!(screen.connection(), Connection::Lost(_)));
    let text = drawn(&mut screen);
    assert!(text.contains("was lost: timed out; trying again"), "{text}");
    assert!(text.contains("serve"), "{text}");
}

#[test]
fn a_small_terminal_keeps_the_state_and_the_quit_key() {
    let mut screen = connected();
    screen.on_watch(WatchEvent::Changes(vec![change(
        1_000,
        1,
        NodeStatus::Running,
    )]));
    insta::assert_snapshot!(drawn_at(&mut screen, 80, 24));
    let mut screen = connected();
    screen.on_watch(WatchEvent::Lost(
        "the connection to 127.0.0.1:1667 was lost: Server disconnected".into(),
    ));
    let text = drawn_at(&mut screen, 80, 24);
    let bar = text.lines().last().unwrap_or_default();
    assert!(
        bar.starts_with("\" the connection to 127.0.0.1:1667 was lost"),
        "{bar}"
    );
    assert!(bar.ends_with("… · q quit\""), "{bar}");
}

#[test]
fn a_search_marks_every_match_and_goes_from_one_to_the_next() {
    let mut screen = connected();
    let key = |c| KeyEvent::new(KeyCode::Char(c), KeyModifiers::NONE);
    for c in ['/', 'G', 'R', 'A'] {
        screen.on_key(key(c));
    }
    screen.on_key(KeyEvent::new(KeyCode::Enter, KeyModifiers::NONE));
    assert_eq!(screen.selected(), Some(6), "Grasp, by its ID in any case");
    assert!(screen.matches(6) && !screen.matches(5));
    for c in "/{cup}".chars() {
        screen.on_key(key(c));
    }
    screen.on_key(KeyEvent::new(KeyCode::Enter, KeyModifiers::NONE));
    assert_eq!(screen.selected(), Some(6), "by a port's blackboard entry");
    for c in "/o".chars() {
        screen.on_key(key(c));
    }
    screen.on_key(KeyEvent::new(KeyCode::Enter, KeyModifiers::NONE));
    assert_eq!(
        screen.selected(),
        Some(7),
        "the next after the selection: Recover"
    );
    screen.on_key(key('n'));
    assert_eq!(
        screen.selected(),
        Some(1),
        "round past the end: ready_then_work"
    );
    for c in "/zebra".chars() {
        screen.on_key(key(c));
    }
    screen.on_key(KeyEvent::new(KeyCode::Enter, KeyModifiers::NONE));
    assert_eq!(
        screen.selected(),
        Some(1),
        "nothing found: the selection stays"
    );
    let text = drawn(&mut screen);
    assert!(text.contains("no node matches \"zebra\""), "{text}");
}

#[test]
fn breakpoint_keys_become_commands_for_the_publisher() {
    use crate::monitor::WatchCommand;
    let mut screen = connected();
    let key = |c| KeyEvent::new(KeyCode::Char(c), KeyModifiers::NONE);
    // The widget moves through the rows it last drew.
    drawn(&mut screen);
    screen.on_key(KeyEvent::new(KeyCode::End, KeyModifiers::NONE));
    screen.on_key(key('b'));
    assert_eq!(
        screen.take_commands(),
        [WatchCommand::Break(8)],
        "before Recover"
    );
    // `c`, `s` and `x` mean nothing until the tree stops.
    screen.on_key(key('x'));
    assert!(screen.take_commands().is_empty());
    screen.on_watch(WatchEvent::Stopped(8));
    assert_eq!(screen.selected(), Some(7));
    screen.on_key(key('x'));
    assert_eq!(
        screen.take_commands(),
        [WatchCommand::Release {
            uid: 8,
            forced: Some(NodeStatus::Failure)
        }]
    );
    // Taking away the breakpoint the tree waits at releases it first.
    screen.on_watch(WatchEvent::Stopped(8));
    screen.on_key(key('b'));
    assert_eq!(
        screen.take_commands(),
        [
            WatchCommand::Release {
                uid: 8,
                forced: None
            },
            WatchCommand::Unbreak(8)
        ]
    );
    let text = drawn(&mut screen);
    assert!(!text.contains("stopped before"), "{text}");
}

/// A tree file of every BT.CPP node kind on the screen: whole, every node idle, the
/// SubTree's tree under it, and the file's keys in the status bar.
#[test]
fn a_tree_file_is_shown_whole() {
    let xml = include_str!("../../../tests/fixtures/btcpp/every_kind.xml");
    let tree = crate::monitor::WatchedTree::parse_file(xml.as_bytes()).expect("reads");
    let mut view = super::FileView::new(tree, "every_kind.xml", None, false);
    insta::assert_snapshot!(drawn_at(&mut view.0, 120, 40));
    // Breakpoint keys do nothing on a file.
    view.0.on_key(crossterm::event::KeyEvent::from(
        crossterm::event::KeyCode::Char('b'),
    ));
    assert!(view.0.take_commands().is_empty());
}

/// A file the workbench was asked to run and betr's engine does not: shown whole, with why
/// beside the tree where the status changes would be.
#[test]
fn a_tree_file_not_run_says_why_beside_it() {
    let xml = include_str!("../../../tests/fixtures/btcpp/every_kind.xml");
    let tree = crate::monitor::WatchedTree::parse_file(xml.as_bytes()).expect("reads");
    let why = "every_kind.xml: line 8, column 7, <Script code=\"attempts := 0\"/>: Script is a \
               BehaviorTree.CPP action that betr's engine does not run";
    let mut view = super::FileView::new(tree, "every_kind.xml", Some(why.into()), false);
    let drawn = drawn_at(&mut view.0, 120, 40);
    assert!(drawn.contains("not run by betr's engine"), "{drawn}");
    assert!(
        drawn.contains("a file betr's engine does not run"),
        "{drawn}"
    );
    insta::assert_snapshot!(drawn);
}
