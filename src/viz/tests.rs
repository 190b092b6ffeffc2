use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

use rerun::RecordingStreamBuilder;
use rerun::log::{Chunk, LogMsg};

use super::*;
use crate::domain::Domain;
use crate::planner::{Outcome, Planner, RunEnd, RunReport, run_tree};
use crate::scenario::Scenario;
use crate::world::cell::snapshot::PartShape;

/// A run of `tree` streamed to `viz` as the command line does it.
fn run_streamed(tree: &Tree, world: &mut dyn World, domain: &Domain, viz: &mut Viz) -> RunReport {
    viz.run_start(tree, world);
    run_tree(tree, world, domain, 100, |r, w| {
        viz.run_tick(r, w);
        true
    })
}

fn scenario1() -> Scenario {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/cell/red_on_blue.toml");
    Scenario::load(&path).unwrap()
}

/// Every entity path logged, with its component identifiers and the `tick` and `step`
/// values it was logged at.
#[derive(Default)]
struct Logged {
    components: BTreeMap<String, BTreeSet<String>>,
    ticks: BTreeMap<String, BTreeSet<i64>>,
    steps: BTreeMap<String, BTreeSet<i64>>,
    motions: BTreeMap<String, BTreeSet<i64>>,
}

fn decode(msgs: Vec<LogMsg>) -> Logged {
    let mut out = Logged::default();
    for msg in msgs {
        let LogMsg::ArrowMsg(_, arrow) = msg else {
            continue;
        };
        let chunk = Chunk::from_arrow_msg(&arrow).unwrap();
        let path = chunk.entity_path().to_string();
        let path = path.trim_start_matches('/').to_string();
        let comps = out.components.entry(path.clone()).or_default();
        for d in chunk.component_descriptors() {
            comps.insert(d.component.to_string());
        }
        if let Some(column) = chunk.timelines().get(&TIMELINE.into()) {
            out.ticks
                .entry(path.clone())
                .or_default()
                .extend(column.times_raw().iter().copied());
        }
        if let Some(column) = chunk.timelines().get(&STEPS.into()) {
            out.steps
                .entry(path.clone())
                .or_default()
                .extend(column.times_raw().iter().copied());
        }
        if let Some(column) = chunk.timelines().get(&MOTION.into()) {
            out.motions
                .entry(path)
                .or_default()
                .extend(column.times_raw().iter().copied());
        }
    }
    out
}

/// Scenario 1 before and after the repair the paper finds, streamed to memory.
#[test]
fn scenario1_before_and_after_repair_streams_scene_tree_and_ticks() {
    let scenario = scenario1();
    let world = crate::world::load(&scenario).unwrap();
    let planner = Planner::new(&scenario.domain);
    let goal = scenario.goal.clone().unwrap();
    let plan = planner.plan(&goal.to_dnf(), world.as_ref()).unwrap();
    let Outcome::ActionFailed { node, .. } = plan.outcome else {
        panic!("scenario 1 should fail before repair: {:?}", plan.outcome);
    };

    let (rec, storage) = RecordingStreamBuilder::new("betr-test").memory().unwrap();
    let mut viz = Viz::with_stream(rec);
    viz.instruction("Put the blue cube on the green cube");
    let mut exec = world.fork();
    let before = run_streamed(&plan.tree, exec.as_mut(), &scenario.domain, &mut viz);
    assert!(matches!(before.end, RunEnd::Failure { action: Some(_) }));
    assert_eq!(viz.ticks(), before.ticks as i64);
    // The failing grasp's way down is drawn, red where the red cube is in it.
    let scene = CellWorld::scene_of(exec.as_ref()).unwrap();
    let approach = scene.approach.clone().unwrap();
    assert_eq!(approach.points.len(), snapshot_segments() + 1);
    assert!(approach.collided.iter().any(|c| *c));
    assert!(
        !approach.collided.iter().all(|c| *c),
        "free above the obstacle"
    );

    let fix = scenario.parse_goal(&scenario.expected_fix[0]).unwrap();
    let conditions = fix.to_dnf().0[0].clone();
    let repaired = planner
        .repair(plan.tree, node, &conditions, world.as_ref())
        .unwrap();
    let mut exec = world.fork();
    let after = run_streamed(&repaired.tree, exec.as_mut(), &scenario.domain, &mut viz);
    assert_eq!(after.end, RunEnd::Success);
    assert_eq!(viz.ticks(), (before.ticks + after.ticks) as i64);
    let scene = CellWorld::scene_of(exec.as_ref()).unwrap();
    assert!(scene.approach.unwrap().collided.iter().all(|c| !*c));
    viz.stream().flush_blocking().unwrap();

    let logged = decode(storage.take());
    let has = |path: &str, component: &str| {
        logged
            .components
            .get(path)
            .is_some_and(|c| c.contains(component))
    };
    for solid in ["table", "blue_cube", "green_cube", "red_cube"] {
        let path = format!("world/solids/{solid}");
        assert!(
            has(&path, "Boxes3D:half_sizes"),
            "{path}: {:?}",
            logged.components.get(&path)
        );
        assert!(has(&path, "Boxes3D:colors"));
        assert!(has(&path, "Boxes3D:labels"));
    }
    assert!(has(scene::ROBOT_TORSO, "Boxes3D:centers"));
    assert!(has(scene::ROBOT_ARMS, "LineStrips3D:strips"));
    assert!(has(scene::ROBOT_GRIPPER, "Boxes3D:half_sizes"));
    assert!(has(scene::APPROACH, "LineStrips3D:colors"));
    assert!(has(tree::TREE_GRAPH, "GraphNodes:node_ids"));
    assert!(has(tree::TREE_GRAPH, "GraphNodes:colors"));
    assert!(has(tree::TREE_GRAPH, "GraphEdges:edges"));
    assert!(has(tree::TREE_TEXT, "TextDocument:text"));
    assert!(has(EVENTS, "TextLog:text"));
    assert!(has(EVENTS, "TextLog:level"));

    // One step per tick, before and after the repair, for the tree's statuses and for
    // the scene (step 0 holds the scene before the first tick); on the `tick` timeline
    // each run counts its ticks from 1, as the workbench does.
    let steps = |path: &str| {
        logged
            .steps
            .get(path)
            .map(|t| t.iter().filter(|t| **t > 0).count())
            .unwrap_or_default()
    };
    let total = (before.ticks + after.ticks) as usize;
    assert_eq!(steps(tree::TREE_TEXT), total);
    assert_eq!(steps("world/solids/blue_cube"), total);
    assert_eq!(steps(scene::ROBOT_ARMS), total);
    assert_eq!(viz.steps(), total as i64);
    let ticks: Vec<i64> = logged.ticks[tree::TREE_TEXT].iter().copied().collect();
    let longest = before.ticks.max(after.ticks) as i64;
    assert_eq!(ticks, (0..=longest).collect::<Vec<_>>());
    assert!(has(tree::TREE_GRAPH, "GraphNodes:positions"));
}

fn snapshot_segments() -> usize {
    crate::world::cell::snapshot::PATH_SEGMENTS
}

#[test]
fn session_events_stream_the_tree_ticks_and_the_log() {
    let scenario = scenario1();
    let world = crate::world::load(&scenario).unwrap();
    let plan = Planner::new(&scenario.domain)
        .plan(&scenario.goal.clone().unwrap().to_dnf(), world.as_ref())
        .unwrap();
    let (rec, storage) = RecordingStreamBuilder::new("betr-test").memory().unwrap();
    let mut viz = Viz::with_stream(rec);
    let tree = Arc::new(plan.tree);
    viz.on_event(&Event::TreeChanged {
        tree: tree.clone(),
        new_nodes: Vec::new(),
        learned: Vec::new(),
        why: "planned".into(),
    });
    let mut exec = world.fork();
    let mut ticker = crate::bt::Ticker::new();
    let mut leaves = crate::planner::WorldLeaves {
        world: exec.as_mut(),
        domain: &scenario.domain,
    };
    for _ in 0..3 {
        let record = Arc::new(ticker.tick(&tree, &mut leaves));
        viz.on_event(&Event::Ticked { record });
        let scene = CellWorld::scene_of(&*leaves.world).unwrap();
        viz.on_event(&Event::Scene {
            scene: Arc::new(scene),
        });
    }
    viz.on_event(&Event::Approved);
    viz.stream().flush_blocking().unwrap();
    assert_eq!(viz.ticks(), 3);
    // The plan's tree, three ticks and the approval: a step each.
    assert_eq!(viz.steps(), 5);
    let logged = decode(storage.take());
    assert_eq!(
        logged.ticks[tree::TREE_TEXT].len(),
        4,
        "unticked tree + 3 ticks"
    );
    assert!(logged.components.contains_key("world/solids/red_cube"));
    assert!(logged.components[EVENTS].contains("TextLog:text"));
}

#[test]
fn colours_come_from_the_names_and_shapes_from_the_parts() {
    let scenario = scenario1();
    let world = crate::world::load(&scenario).unwrap();
    let scene = CellWorld::scene_of(world.as_ref()).unwrap();
    let red = scene.solids.iter().find(|s| s.name == "red cube").unwrap();
    assert_eq!(red.colour, [220, 50, 47]);
    assert!(matches!(red.parts[0].shape, PartShape::Box { .. }));
    assert_eq!(scene.robot.arms.len(), 2);
    assert!(scene.out_of_reach.is_empty());
    assert!(scene.approach.is_none());
    assert_eq!(scene::slug("red cube"), "red_cube");
}

#[test]
fn viewer_flags_parse() {
    assert_eq!("spawn".parse::<Viewer>().unwrap(), Viewer::Spawn);
    let localhost: std::net::IpAddr = std::net::Ipv4Addr::LOCALHOST.into();
    assert_eq!("web".parse::<Viewer>().unwrap(), Viewer::Web(localhost));
    assert_eq!(
        "web=0.0.0.0".parse::<Viewer>().unwrap(),
        Viewer::Web(std::net::Ipv4Addr::UNSPECIFIED.into())
    );
    // Only this machine or every interface: betr streams to the viewer at 127.0.0.1.
    for refused in ["web=", "web=10.1.2.3", "web=somewhere"] {
        let e = refused.parse::<Viewer>().unwrap_err().to_string();
        assert!(e.contains(refused) && e.contains("web=0.0.0.0"), "{e}");
    }
    assert_eq!(
        viewer::web_page(DEFAULT_URL, WEB_PORT),
        "http://127.0.0.1:9090/?url=rerun%2Bhttp%3A%2F%2F127.0.0.1%3A9876%2Fproxy"
    );
    assert_eq!("connect".parse::<Viewer>().unwrap(), Viewer::Connect(None));
    assert_eq!(
        "connect=rerun+http://127.0.0.1:9999/proxy"
            .parse::<Viewer>()
            .unwrap(),
        Viewer::Connect(Some("rerun+http://127.0.0.1:9999/proxy".into()))
    );
    assert!("show".parse::<Viewer>().is_err());
    assert_eq!(
        address("rerun+http://127.0.0.1:9999/proxy").as_deref(),
        Some("127.0.0.1:9999")
    );
}

#[test]
fn a_viewer_that_is_not_there_is_said_once_and_the_session_goes_on() {
    // Nothing listens on port 9 (discard) here.
    let viz = Viz::open(&Sinks {
        viewer: Some(Viewer::Connect(Some(
            "rerun+http://127.0.0.1:9/proxy".into(),
        ))),
        ..Sinks::default()
    })
    .unwrap()
    .unwrap();
    assert!(viz.notice().unwrap().starts_with(NOT_CONNECTED));
    let mut viz = viz;
    viz.log(rerun::TextLogLevel::INFO, "still works");
}

/// The failure, the question, the proposal and the approval with its repair each take a
/// step of their own after the failing tick, so the failing tick's frame stays visible.
#[test]
fn the_resolve_loop_takes_its_own_steps_after_the_failing_tick() {
    let scenario = scenario1();
    let world = crate::world::load(&scenario).unwrap();
    let plan = Planner::new(&scenario.domain)
        .plan(&scenario.goal.clone().unwrap().to_dnf(), world.as_ref())
        .unwrap();
    let (rec, storage) = RecordingStreamBuilder::new("betr-test").memory().unwrap();
    let mut viz = Viz::with_stream(rec);
    let tree = Arc::new(plan.tree);
    let changed = |tree: &Arc<Tree>, why: &str| Event::TreeChanged {
        tree: tree.clone(),
        new_nodes: Vec::new(),
        learned: Vec::new(),
        why: why.into(),
    };
    viz.on_event(&changed(&tree, "planned"));
    let mut exec = world.fork();
    let mut ticker = crate::bt::Ticker::new();
    let mut leaves = crate::planner::WorldLeaves {
        world: exec.as_mut(),
        domain: &scenario.domain,
    };
    let record = Arc::new(ticker.tick(&tree, &mut leaves));
    assert!(
        !record.failures.is_empty(),
        "scenario 1 fails at its first tick"
    );
    viz.on_event(&Event::Ticked {
        record: record.clone(),
    });
    assert_eq!(viz.steps(), 2);
    let failing = viz.steps();
    viz.on_event(&Event::ActionFailed {
        node: record.failures[0].0,
        node_path: vec![1, 0, 1, 1],
        action: crate::domain::ActionCall::new("grasp", ["blue cube"]),
        error: record.failures[0].1.clone(),
        executor: None,
    });
    viz.on_event(&Event::Asking {
        what: crate::session::Question::Preconditions {
            action: crate::domain::ActionCall::new("grasp", ["blue cube"]),
        },
    });
    viz.on_event(&Event::Approved);
    viz.on_event(&Event::Repaired {
        added_nodes: 9,
        valued_nodes: 0,
    });
    viz.on_event(&changed(&tree, "repaired"));
    // failure, question, approval (with the repair and its tree): three more steps.
    assert_eq!(viz.steps(), failing + 3);
    viz.stream().flush_blocking().unwrap();
    let logged = decode(storage.take());
    // The failing tick's statuses stay at their step; the repaired tree is logged later.
    let tree_steps = &logged.steps[tree::TREE_TEXT];
    assert!(tree_steps.contains(&failing), "{tree_steps:?}");
    assert!(tree_steps.contains(&(failing + 3)), "{tree_steps:?}");
    assert!(!tree_steps.contains(&(failing + 1)), "{tree_steps:?}");
    let event_steps = &logged.steps[EVENTS];
    for step in failing..=failing + 3 {
        assert!(event_steps.contains(&step), "{step}: {event_steps:?}");
    }
}

#[test]
fn the_tidy_layout_puts_parents_over_their_children_and_leaves_apart() {
    let scenario = scenario1();
    let world = crate::world::load(&scenario).unwrap();
    let tree = Planner::new(&scenario.domain)
        .plan(&scenario.goal.clone().unwrap().to_dnf(), world.as_ref())
        .unwrap()
        .tree;
    let order = tree.preorder();
    let (graph, _) = tree::graph_of(&tree, None, true, &[]);
    let positions = graph.positions;
    let at = |id| positions[order.iter().position(|n| *n == id).unwrap()];
    for &id in &order {
        let children = tree.children(id).unwrap();
        let (x, y) = at(id);
        for &c in children {
            assert!(at(c).1 > y, "a child lies below its parent");
        }
        if let (Some(&first), Some(&last)) = (children.first(), children.last()) {
            assert!((x - (at(first).0 + at(last).0) / 2.0).abs() < 1e-3);
        }
    }
    let mut leaves: Vec<f32> = order
        .iter()
        .filter(|n| tree.children(**n).unwrap().is_empty())
        .map(|n| at(*n).0)
        .collect();
    let unsorted = leaves.clone();
    leaves.sort_by(f32::total_cmp);
    assert_eq!(leaves, unsorted, "leaves left to right in tree order");
    assert!(leaves.windows(2).all(|w| w[1] - w[0] >= 90.0));
}

#[test]
fn the_viewer_marks_are_ones_its_fonts_have() {
    assert_eq!(tree::VIEWER_GLYPHS.failure, "×");
    assert!(
        [
            tree::VIEWER_GLYPHS.idle,
            tree::VIEWER_GLYPHS.running,
            tree::VIEWER_GLYPHS.success,
            tree::VIEWER_GLYPHS.failure,
            tree::VIEWER_GLYPHS.halted,
        ]
        .iter()
        .all(|g| !g.contains('✕'))
    );
}

#[test]
fn spawning_without_a_display_says_so() {
    if std::env::var_os("DISPLAY").is_some() || std::env::var_os("WAYLAND_DISPLAY").is_some() {
        return;
    }
    let viz = Viz::open(&Sinks {
        viewer: Some(Viewer::Spawn),
        ..Sinks::default()
    })
    .unwrap()
    .unwrap();
    let notice = viz.notice().unwrap();
    assert!(
        notice.contains("no display for the native viewer"),
        "{notice}"
    );
    assert!(notice.contains("--viewer web"), "{notice}");
}

/// With the usual ports held by another program, the web viewer's ports are others the
/// system gives, both free and different; held only while they are chosen.
#[test]
fn the_web_viewer_moves_off_ports_that_are_taken() {
    // Hold the usual ports where this test can (another program may hold them already,
    // which serves the test as well).
    let _held: Vec<std::net::TcpListener> = [viewer::GRPC_PORT, viewer::WEB_PORT]
        .iter()
        .filter_map(|p| std::net::TcpListener::bind(("0.0.0.0", *p)).ok())
        .collect();
    let (grpc, web) = viewer::free_ports().unwrap();
    assert_ne!(grpc, viewer::GRPC_PORT);
    assert_ne!(web, viewer::WEB_PORT);
    assert_ne!(grpc, web);
    for port in [grpc, web] {
        assert!(
            std::net::TcpListener::bind(("0.0.0.0", port)).is_ok(),
            "{port}"
        );
    }
}

/// A viewer program that stops at once is tried again on new ports, then refused with the
/// ports tried and how to use a viewer started by hand; one that is not there is said.
#[test]
fn a_web_viewer_that_stops_at_once_is_said_with_its_ports() {
    let localhost = std::net::Ipv4Addr::LOCALHOST.into();
    let error = viewer::start_web(
        std::ffi::OsStr::new("false"),
        ViewerLife::StopsWithSession,
        localhost,
    )
    .err()
    .unwrap();
    let said = error.to_string();
    assert!(
        matches!(error, viewer::ViewerError::Stopped { attempts: 3, .. }),
        "{said}"
    );
    assert!(said.contains("before listening on ports"), "{said}");
    assert!(said.contains("--viewer connect=URL"), "{said}");
    let missing = viewer::start_web(
        std::ffi::OsStr::new("/nonexistent/rerun"),
        ViewerLife::StopsWithSession,
        localhost,
    )
    .err()
    .unwrap();
    assert!(
        matches!(missing, viewer::ViewerError::NotInstalled),
        "{missing}"
    );
}

/// The YuMi's real arms in the view.
#[path = "robot_tests.rs"]
mod arms;

/// The cafe goal of five wishes plans a tree of more than 40 nodes. Its graph shows the
/// way to the node each tick is at, each composite off that way folded into one node that
/// says what it is for; the nodes a change added are marked.
#[test]
fn a_large_tree_graph_shows_the_way_to_the_tick_and_folds_the_rest() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/cafe/no_coffee.toml");
    let scenario = Scenario::load(&path).unwrap();
    let goal = scenario
        .parse_goal(
            "On_Water_Table2 & On_Dessert_Table3 & Active_AC & IsClean_Floor & On_Coffee_Table1",
        )
        .unwrap();
    let mut world = crate::world::load(&scenario).unwrap();
    let tree = Planner::new(&scenario.domain)
        .plan(&goal.to_dnf(), world.as_ref())
        .unwrap()
        .tree;
    let whole = tree.preorder().len();
    assert!(whole > tree::WHOLE_GRAPH_NODES, "{whole} nodes");

    // Not ticked yet: the root and its children, each folded.
    let (graph, edges) = tree::graph_of(&tree, None, false, &[]);
    let root_children = tree.children(tree.root()).unwrap().len();
    assert_eq!(graph.ids.len(), 1 + root_children, "{:?}", graph.labels);
    assert_eq!(edges.map(|e| e.len()), Some(root_children));
    assert!(
        graph
            .labels
            .iter()
            .any(|l| l.starts_with("▸ ? fallback for ") && l.ends_with(" more)")),
        "{:?}",
        graph.labels
    );

    // Ticked: the running action is shown, with every node on the way to it.
    let mut records = Vec::new();
    run_tree(&tree, world.as_mut(), &scenario.domain, 3, |r, _| {
        records.push(r.clone());
        true
    });
    let record = records.last().unwrap();
    let (graph, _) = tree::graph_of(&tree, Some(record), false, &[]);
    assert!(
        graph.ids.len() < whole / 2,
        "{} of {whole}",
        graph.ids.len()
    );
    let running: Vec<&String> = graph
        .labels
        .iter()
        .filter(|l| {
            l.starts_with(tree::VIEWER_GLYPHS.running) && l.ends_with('!') && !l.contains("→")
        })
        .collect();
    assert_eq!(running.len(), 1, "{:?}", graph.labels);
    // Parents over their children, as in the whole graph.
    for (i, id) in graph.ids.iter().enumerate() {
        let node = crate::bt::NodeId(id.parse().unwrap());
        if let Some(parent) = tree.parent(node).unwrap() {
            let p = graph
                .ids
                .iter()
                .position(|x| *x == parent.0.to_string())
                .unwrap();
            assert!(graph.positions[p].1 < graph.positions[i].1);
        }
    }

    // A change's new nodes are marked.
    let first_leaf = *tree
        .preorder()
        .iter()
        .find(|n| tree.children(**n).unwrap().is_empty())
        .unwrap();
    let (graph, _) = tree::graph_of(&tree, None, false, &[first_leaf]);
    let at = graph
        .ids
        .iter()
        .position(|x| *x == first_leaf.0.to_string())
        .unwrap();
    assert!(graph.labels[at].starts_with("+ "), "{}", graph.labels[at]);
}

#[test]
fn a_divergence_draws_the_twins_prediction_beside_reality_until_the_world_resets() {
    let scenario = scenario1();
    let world = crate::world::load(&scenario).unwrap();
    let scene = Arc::new(CellWorld::scene_of(world.as_ref()).unwrap());
    let (rec, storage) = RecordingStreamBuilder::new("betr-test").memory().unwrap();
    let mut viz = Viz::with_stream(rec);
    viz.on_event(&Event::Scene {
        scene: scene.clone(),
    });
    viz.on_event(&Event::Diverged {
        executor: "mujoco".into(),
        action: crate::domain::ActionCall::new("grasp", ["blue cube"]),
        reality: "Grasp failed".into(),
        predicted: Some(scene),
    });
    viz.on_event(&Event::WorldChanged {
        facts: Vec::new(),
        reset: true,
    });
    viz.stream().flush_blocking().unwrap();
    let logged = decode(storage.take());
    // Every solid that moves, faint where the twin expected it; the table is not drawn.
    assert!(logged.components.contains_key("world/twin/blue_cube"));
    assert!(!logged.components.contains_key("world/twin/table"));
    assert!(logged.components[EVENTS].contains("TextLog:text"));
    // The reset cleared it (a recursive clear at the twin's root).
    assert!(
        logged
            .components
            .get(scene::TWIN)
            .is_some_and(|c| c.iter().any(|k| k.starts_with("Clear"))),
        "{:?}",
        logged.components.get(scene::TWIN)
    );
}
