"""Runs a tree betr exported as BehaviorTree.CPP v4 XML in the real BT.CPP (through
behaviortreepy, its Python bindings) against a scripted world, and prints what every node
showed in every tick.

    python scripts/btcpp_driver.py TREE.xml SCRIPT.json

The node types are registered from the file's <TreeNodesModel>: every <Condition> as a
condition, every <Action> as a stateful action (on_start, on_running, on_halted). The
script says, tick by tick, what the leaves answer, in the order betr's ticker asked them:

    {"ticks": [{"leaves": [{"node": "grasped(item=any object)", "result": "SUCCESS"},
                           {"node": "grasp(x=blue cube)", "result": "RUNNING",
                            "started": true}],
                "halted": []}]}

A leaf is named by its node ID and its ports in the model's order. A condition's result
is its predicate's truth (an <Inverter> turns it), an action's result what its step
returned, `started` whether it was a fresh start. A leaf BT.CPP asks that the script does
not answer at that point, an action started where the script continues it (or the other
way round), and a halt the script does not list are problems, printed with the tick.

behaviortreepy registers node types without ports (its registration takes none), and
BT.CPP refuses a port its registered type does not declare. So the driver checks each
leaf's attributes against the <TreeNodesModel> itself (every attribute a declared port,
every port given) and moves them into the node's `name` before BT.CPP parses the file;
every other element and attribute reaches BT.CPP as written. Every node is named by its
path from the root as betr writes it (`root`, `0`, `0.1`), so statuses are reported per
node. Statuses come from BT.CPP's own StdCoutLogger (every status change of every node).

Prints one JSON object on standard output:

    {"ticks": [{"tick": 1, "root": "RUNNING", "statuses": {"root": "RUNNING", ...},
                "problems": []}]}

Statuses are IDLE (not ticked), RUNNING, SUCCESS, FAILURE and HALTED (running in the
previous tick, halted in this one). Exit status 2 when the file does not load or the
script cannot be read, with the reason on standard error.
"""

import json
import os
import re
import sys
import tempfile
import xml.etree.ElementTree as ET

import behaviortreepy as bt

CONTROLS = {"ReactiveSequence", "ReactiveFallback", "Sequence", "Fallback", "Inverter"}
ANSI = re.compile(r"\x1b\[[0-9;]*m")
TRANSITION = re.compile(r"^\[[0-9.]+\]: (\S+)\s+(\w+) -> (\w+)\s*$")


def fail(message):
    print(f"btcpp_driver: {message}", file=sys.stderr)
    sys.exit(2)


def read_model(root):
    """{node ID: ("Condition" | "Action", [port names in order])} from <TreeNodesModel>."""
    model = {}
    for entry in root.iter("TreeNodesModel"):
        for node in entry:
            ports = [p.get("name") for p in node if p.tag.endswith("_port")]
            model[node.get("ID")] = (node.tag, ports)
    return model


def name_nodes(element, path, model, labels, problems):
    """Names every node by its path and moves leaf ports into the name; fills `labels`
    (path → the leaf's script name)."""
    tag = element.tag
    if tag in CONTROLS:
        for key in element.attrib:
            if key != "name":
                problems.append(f"{path}: <{tag}> has the attribute {key}")
        element.attrib = {"name": path}
        if tag == "Inverter":
            children = list(element)
            if len(children) != 1:
                problems.append(f"{path}: <Inverter> needs exactly one child")
            for child in children:
                name_nodes(child, path + "/inverted", model, labels, problems)
            return
        for i, child in enumerate(element):
            child_path = str(i) if path == "root" else f"{path}.{i}"
            name_nodes(child, child_path, model, labels, problems)
        return
    if tag not in model:
        problems.append(f"{path}: <{tag}> is not declared in the TreeNodesModel")
        return
    _, ports = model[tag]
    for key in element.attrib:
        if key not in ports and key != "name":
            problems.append(f"{path}: <{tag}> has the port {key}, which the model does not declare")
    values = [f"{p}={element.get(p)}" for p in ports if element.get(p) is not None]
    labels[path] = f"{tag}({', '.join(values)})"
    element.attrib = {"name": path}


class ScriptedWorld:
    """Answers the leaves from the script, one tick at a time."""

    def __init__(self, labels):
        self.labels = labels
        self.pending = []
        self.halted = []
        self.problems = []

    def start_tick(self, entry):
        self.pending = list(entry.get("leaves", []))
        self.halted = []
        self.problems = []

    def answer(self, node, kind, started):
        path = node.name()
        label = self.labels.get(path, path)
        for i, want in enumerate(self.pending):
            if want["node"] == label:
                del self.pending[i]
                if kind == "action" and bool(want.get("started")) != started:
                    how = "started" if started else "continued"
                    self.problems.append(f"{path} {label}: BT.CPP {how} it, betr did not")
                return getattr(bt.NodeStatus, want["result"])
        self.problems.append(f"{path} {label}: ticked by BT.CPP, not answered by the script here")
        return bt.NodeStatus.FAILURE

    def condition(self, node):
        return self.answer(node, "condition", False)

    def start(self, node):
        return self.answer(node, "action", True)

    def running(self, node):
        return self.answer(node, "action", False)

    def halt(self, node):
        self.halted.append(self.labels.get(node.name(), node.name()))


def statuses_of(transitions, before):
    """What every node showed in one tick, from its status changes in that tick and its
    status before it (`before`, updated to the status after)."""
    shown = {}
    for name, old, new in transitions:
        if new != "IDLE":
            shown[name] = new
        elif old == "RUNNING" and before.get(name) == "RUNNING" and name not in shown:
            shown[name] = "HALTED"
        before[name] = new
    for name, status in before.items():
        if status == "RUNNING" and name not in shown:
            shown[name] = "RUNNING"
    return shown


def main():
    if len(sys.argv) != 3:
        fail("usage: btcpp_driver.py TREE.xml SCRIPT.json")
    tree_path, script_path = sys.argv[1], sys.argv[2]
    try:
        document = ET.parse(tree_path)
    except (OSError, ET.ParseError) as e:
        fail(f"{tree_path}: {e}")
    try:
        with open(script_path, encoding="utf-8") as f:
            script = json.load(f)
    except (OSError, ValueError) as e:
        fail(f"{script_path}: {e}")

    root = document.getroot()
    model = read_model(root)
    main_id = root.get("main_tree_to_execute")
    trees = [t for t in root.iter("BehaviorTree") if t.get("ID") == main_id]
    if len(trees) != 1 or len(list(trees[0])) != 1:
        fail(f"{tree_path}: no single <BehaviorTree ID=\"{main_id}\"> with one root node")
    labels = {}
    problems = []
    name_nodes(list(trees[0])[0], "root", model, labels, problems)
    if problems:
        fail(f"{tree_path}: " + "; ".join(problems))

    world = ScriptedWorld(labels)
    factory = bt.BehaviorTreeFactory()
    for node_id, (kind, _) in model.items():
        if kind == "Condition":
            factory.register_simple_condition(node_id, world.condition)
        elif kind == "Action":
            factory.register_simple_stateful_action(
                node_id, world.start, world.running, world.halt
            )
    text = ET.tostring(root, encoding="unicode")
    try:
        tree = factory.create_tree_from_text(text)
    except RuntimeError as e:
        fail(f"BT.CPP refused {tree_path}: {e}")

    # BT.CPP's logger writes to the process's standard output; it goes to a file while
    # the tree ticks and is read back after each tick.
    sys.stdout.flush()
    saved = os.dup(1)
    log = tempfile.TemporaryFile(mode="w+b")
    os.dup2(log.fileno(), 1)
    logger = bt.StdCoutLogger(tree)
    results = []
    before = {}
    read_to = 0
    try:
        for number, entry in enumerate(script["ticks"], start=1):
            world.start_tick(entry)
            root_status = tree.tick_exactly_once()
            logger.flush()
            log.seek(read_to)
            chunk = log.read().decode("utf-8", "replace")
            read_to = log.tell()
            transitions = []
            for line in ANSI.sub("", chunk).splitlines():
                m = TRANSITION.match(line.strip())
                if m and "/inverted" not in m.group(1):
                    transitions.append(m.groups())
            shown = statuses_of(transitions, before)
            tick_problems = list(world.problems)
            for left in world.pending:
                tick_problems.append(f"{left['node']}: answered by the script, not ticked by BT.CPP")
            if sorted(world.halted) != sorted(entry.get("halted", [])):
                tick_problems.append(
                    f"halted {sorted(world.halted)} by BT.CPP, {sorted(entry.get('halted', []))} by betr"
                )
            results.append(
                {
                    "tick": number,
                    "root": bt.to_string(root_status),
                    "statuses": shown,
                    "problems": tick_problems,
                }
            )
    finally:
        sys.stdout.flush()
        os.dup2(saved, 1)
        os.close(saved)
    json.dump({"ticks": results}, sys.stdout)
    print()


if __name__ == "__main__":
    main()
