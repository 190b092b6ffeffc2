"""A BehaviorTree.CPP tree ticked in the real library (behaviortreepy, its Python
bindings) under Groot2's publisher, for `betr monitor`'s tests and for trying the monitor
by hand.

    python scripts/btcpp_publisher.py PORT [TICKS]

Builds a tree with Fallback, ReactiveSequence, Inverter, RetryUntilSuccessful and a
SubTree whose leaves answer from a fixed script, publishes it on PORT (and PORT + 1, as
Groot2's publisher does), prints `ready PORT` and waits for a line on standard input.
Then it ticks the tree TICKS times (default 6; 0 ticks until standard input closes), 20 ms
apart, and prints on one line the status changes BT.CPP's own StdCoutLogger saw, in
order, as JSON: [[node name, old status, new status], ...]. It keeps publishing for a
second after, so a monitor can collect the last changes, and exits.
"""

import itertools
import json
import os
import re
import sys
import tempfile
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


def main():
    if len(sys.argv) not in (2, 3):
        print("usage: btcpp_publisher.py PORT [TICKS]", file=sys.stderr)
        sys.exit(2)
    port = int(sys.argv[1])
    ticks = int(sys.argv[2]) if len(sys.argv) == 3 else 6

    # The leaves' answers, tick after tick: blocked in the third tick (the recovery runs),
    # the grasp failing once in every second try (the retry tries again).
    blocked = itertools.cycle([False, False, True])
    grasps = itertools.cycle([bt.NodeStatus.FAILURE, bt.NodeStatus.SUCCESS])
    factory = bt.BehaviorTreeFactory()
    factory.register_simple_condition(
        "IsBlocked", lambda node: bt.NodeStatus.SUCCESS if next(blocked) else bt.NodeStatus.FAILURE
    )
    factory.register_simple_action("Grasp", lambda node: next(grasps))
    factory.register_simple_action("Recover", lambda node: bt.NodeStatus.SUCCESS)
    tree = factory.create_tree_from_text(TREE)
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
