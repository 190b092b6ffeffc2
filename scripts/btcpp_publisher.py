"""A BehaviorTree.CPP tree ticked in the real library (behaviortreepy, its Python
bindings) under Groot2's publisher, for `betr monitor`'s tests and for trying the monitor
by hand.

    python scripts/btcpp_publisher.py PORT [TICKS]
    python scripts/btcpp_publisher.py PORT 0 --nodes N --period-ms P

Builds a tree with Fallback, ReactiveSequence, Inverter, RetryUntilSuccessful and a
SubTree whose leaves answer from a fixed script (the main tree's blackboard holds
`target` and `grasps`, the grasps tried so far), publishes it on PORT (and PORT + 1, as
Groot2's publisher does), prints `ready PORT` and waits for a line on standard input.
Then it ticks the tree TICKS times (default 6; 0 ticks until standard input closes), 20 ms
apart, and prints on one line the status changes BT.CPP's own StdCoutLogger saw, in
order, as JSON: [[node name, old status, new status], ...]. It keeps publishing for a
second after, so a monitor can collect the last changes, and exits.

With --nodes (`betr bench monitor`), the tree is N nodes instead — groups of a Fallback
over an Inverted condition and an action, half of them visited in each tick, the
conditions turning so that half the visited actions run — ticked every P milliseconds
(default 10, 100 Hz),
without BT.CPP's logger; at the end it prints {"ticks": T, "late": L}: the ticks made and
those that started later than their period.
"""

import argparse
import itertools
import json
import os
import re
import sys
import tempfile
import threading
import time

import behaviortreepy as bt

TREE = """
<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Fallback name="serve">
      <ReactiveSequence name="ready_then_work">
        <Inverter name="not_blocked">
          <IsBlocked name="blocked"/>
        </Inverter>
        <SubTree ID="Work" name="Work"/>
      </ReactiveSequence>
      <Recover name="recover"/>
    </Fallback>
  </BehaviorTree>
  <BehaviorTree ID="Work">
    <RetryUntilSuccessful name="retry" num_attempts="3">
      <Grasp name="grasp"/>
    </RetryUntilSuccessful>
  </BehaviorTree>
</root>
"""

ANSI = re.compile(r"\x1b\[[0-9;]*m")
TRANSITION = re.compile(r"^\[[0-9.]+\]: (\S+)\s+(\w+) -> (\w+)\s*$")


def sized_tree(nodes):
    """A tree of `nodes` nodes (rounded down to 4k + 4): a Fallback over two Sequences of
    Fallback groups, the first guarded by a condition that holds every other tick, so each
    tick visits half the groups."""
    groups = max(2, (nodes - 4) // 4)

    def group(i):
        return (
            f'<Fallback name="group{i}"><Inverter name="not{i}"><Check name="check{i}"/>'
            f'</Inverter><Work name="work{i}"/></Fallback>'
        )

    first = "".join(group(i) for i in range(groups // 2))
    second = "".join(group(i) for i in range(groups // 2, groups))
    return (
        '<root BTCPP_format="4" main_tree_to_execute="Main"><BehaviorTree ID="Main">'
        f'<Fallback name="halves"><Sequence name="first"><OddTick name="odd"/>{first}</Sequence>'
        f'<Sequence name="second">{second}</Sequence></Fallback></BehaviorTree></root>'
    )


def tick_sized(port, nodes, period):
    """Ticks a sized tree every `period` seconds until standard input closes."""
    count = itertools.count()
    factory = bt.BehaviorTreeFactory()
    factory.register_simple_condition(
        "Check",
        lambda node: bt.NodeStatus.SUCCESS if next(count) % 2 else bt.NodeStatus.FAILURE,
    )
    factory.register_simple_action("Work", lambda node: bt.NodeStatus.SUCCESS)
    odd = itertools.cycle([bt.NodeStatus.SUCCESS, bt.NodeStatus.FAILURE])
    factory.register_simple_condition("OddTick", lambda node: next(odd))
    tree = factory.create_tree_from_text(sized_tree(nodes))
    publisher = bt.Groot2Publisher(tree, port)
    print(f"ready {port}", flush=True)
    if not sys.stdin.readline():
        return
    stop = threading.Event()
    threading.Thread(target=lambda: (sys.stdin.read(), stop.set()), daemon=True).start()
    ticks = late = 0
    next_at = time.monotonic()
    while not stop.is_set():
        tree.tick_exactly_once()
        ticks += 1
        next_at += period
        wait = next_at - time.monotonic()
        if wait > 0:
            time.sleep(wait)
        else:
            late += 1
    print(json.dumps({"ticks": ticks, "late": late}), flush=True)
    time.sleep(1.0)
    del publisher


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("port", type=int)
    parser.add_argument("ticks", type=int, nargs="?", default=6)
    parser.add_argument("--nodes", type=int)
    parser.add_argument("--period-ms", type=float, default=10.0)
    args = parser.parse_args()
    port, ticks = args.port, args.ticks
    if args.nodes:
        tick_sized(port, args.nodes, args.period_ms / 1000)
        return

    # The leaves' answers, tick after tick: blocked in the third tick (the recovery runs),
    # the grasp failing once in every second try (the retry tries again).
    blocked = itertools.cycle([False, False, True])
    grasps = itertools.cycle([bt.NodeStatus.FAILURE, bt.NodeStatus.SUCCESS])
    factory = bt.BehaviorTreeFactory()
    factory.register_simple_condition(
        "IsBlocked", lambda node: bt.NodeStatus.SUCCESS if next(blocked) else bt.NodeStatus.FAILURE
    )
    tried = itertools.count(1)

    def grasp(node):
        board.set_int("grasps", next(tried))
        return next(grasps)

    factory.register_simple_action("Grasp", grasp)
    factory.register_simple_action("Recover", lambda node: bt.NodeStatus.SUCCESS)
    tree = factory.create_tree_from_text(TREE)
    # The main tree's blackboard: what the grasp is for, and how many grasps were tried.
    board = tree.root_blackboard()
    board.set_string("target", "red cube")
    publisher = bt.Groot2Publisher(tree, port)

    # BT.CPP's logger writes to the process's standard output: into a file while ticking.
    sys.stdout.flush()
    saved = os.dup(1)
    log = tempfile.TemporaryFile(mode="w+b")
    print(f"ready {port}", flush=True)
    if not sys.stdin.readline():
        return
    os.dup2(log.fileno(), 1)
    logger = bt.StdCoutLogger(tree)
    try:
        count = itertools.count() if ticks == 0 else range(ticks)
        for _ in count:
            tree.tick_exactly_once()
            time.sleep(0.02)
        logger.flush()
    finally:
        sys.stdout.flush()
        os.dup2(saved, 1)
        os.close(saved)
    log.seek(0)
    seen = []
    for line in ANSI.sub("", log.read().decode("utf-8", "replace")).splitlines():
        m = TRANSITION.match(line.strip())
        if m:
            seen.append(list(m.groups()))
    print(json.dumps(seen), flush=True)
    time.sleep(1.0)
    del publisher


if __name__ == "__main__":
    main()
