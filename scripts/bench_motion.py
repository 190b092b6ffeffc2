#!/usr/bin/env python3
"""The anchors of `betr bench motion`, run in the venv under target/.

    bench_motion.py fk URDF PACKAGE_DIR SECONDS TIP...
        Pinocchio's forward kinematics on the same URDF: joint values drawn within the
        limits, forwardKinematics and the placement of each TIP frame, for SECONDS.
        Prints `pinocchio fk_per_s=...`.

    bench_motion.py plan QUERIES_JSON
        OMPL's RRTConnect (path simplified afterwards, as betr shortcuts) with PyBullet's
        contact test as the state validity checker. PyBullet checks what betr checks: the
        URDF's kinematics with betr's collision shapes of the links in place of the
        meshes, the same solids (shared by every query, or each query's own and what its
        hand carries), and only the pairs of parts betr's check of that query tests, a
        pair colliding when the two overlap. Prints one `ompl query=i solved=0|1
        seconds=...` line per query, and on standard error the pair a start or goal
        state collides with.

    bench_motion.py check QUERIES_JSON
        The same check on each query's `states` (joint values of its arm): one
        `check query=i free=0110...` line per query.
"""
import json
import os
import sys
import tempfile
import time


def fk(urdf, package_dir, seconds, tips):
    import numpy as np
    import pinocchio as pin

    model = pin.buildModelFromUrdf(urdf)
    data = model.createData()
    frames = [model.getFrameId(t) for t in tips]
    rng = np.random.default_rng(39)
    low, high = model.lowerPositionLimit, model.upperPositionLimit
    qs = [low + rng.random(model.nq) * (high - low) for _ in range(1000)]
    count = 0
    start = time.perf_counter()
    while time.perf_counter() - start < seconds:
        for q in qs:
            pin.forwardKinematics(model, data, q)
            for f in frames:
                pin.updateFramePlacement(model, data, f)
        count += len(qs)
    elapsed = time.perf_counter() - start
    print(f"pinocchio fk_per_s={count / elapsed:.1f} configurations={count}")


def checked_urdf(urdf, model):
    """The URDF with betr's collision shapes in place of its own (visuals dropped): per
    link the shapes `collision_model` lists, in the link's frame."""
    import xml.etree.ElementTree as ET
    import pybullet as p

    tree = ET.parse(urdf)
    for link in tree.getroot().iter("link"):
        for child in list(link):
            if child.tag in ("collision", "visual"):
                link.remove(child)
        for shape in model["links"].get(link.get("name"), []):
            collision = ET.SubElement(link, "collision")
            rpy = p.getEulerFromQuaternion(shape["orientation"])
            ET.SubElement(collision, "origin", {
                "xyz": " ".join(repr(v) for v in shape["position"]),
                "rpy": " ".join(repr(v) for v in rpy),
            })
            geometry = ET.SubElement(collision, "geometry")
            sizes = shape["sizes"]
            if shape["kind"] == "box":
                ET.SubElement(geometry, "box", {"size": " ".join(repr(2 * h) for h in sizes["half"])})
            elif shape["kind"] == "sphere":
                ET.SubElement(geometry, "sphere", {"radius": repr(sizes["radius"])})
            elif shape["kind"] in ("capsule", "cylinder"):
                ET.SubElement(geometry, shape["kind"], {
                    "radius": repr(sizes["radius"]), "length": repr(sizes["height"])})
            else:
                raise ValueError(f"link {link.get('name')}: no URDF primitive for {shape['kind']}")
    out = tempfile.NamedTemporaryFile("w", suffix=".urdf", delete=False)
    tree.write(out, encoding="unicode")
    out.close()
    return out.name


def make_shape(p, solid):
    """A PyBullet collision shape for one of betr's solids (see bench/pybullet.rs)."""
    kind, sizes = solid["kind"], solid["sizes"]
    if kind == "box":
        return p.createCollisionShape(p.GEOM_BOX, halfExtents=sizes["half"])
    if kind == "sphere":
        return p.createCollisionShape(p.GEOM_SPHERE, radius=sizes["radius"])
    if kind == "cylinder":
        return p.createCollisionShape(p.GEOM_CYLINDER, radius=sizes["radius"], height=sizes["height"])
    if kind == "capsule":
        return p.createCollisionShape(p.GEOM_CAPSULE, radius=sizes["radius"], height=sizes["height"])
    if kind == "mesh":
        return p.createCollisionShape(p.GEOM_MESH, vertices=sizes["vertices"])
    raise ValueError(f"unknown solid kind {kind!r}")


def place_solid(p, solid):
    shape = make_shape(p, solid)
    return p.createMultiBody(baseMass=0, baseCollisionShapeIndex=shape,
                             basePosition=solid["position"], baseOrientation=solid["orientation"])


class Cell:
    """The robot with betr's collision shapes, the joints no arm moves where betr holds
    them, and the solids shared by every query."""

    def __init__(self, p, spec):
        self.p = p
        model = spec["collision_model"]
        urdf = checked_urdf(spec["urdf"], model)
        flags = p.URDF_USE_SELF_COLLISION | p.URDF_USE_SELF_COLLISION_INCLUDE_PARENT
        self.robot = p.loadURDF(urdf, basePosition=spec["base"], useFixedBase=True, flags=flags)
        os.unlink(urdf)
        self.joints, self.links = {}, {model["root"]: -1}
        for j in range(p.getNumJoints(self.robot)):
            info = p.getJointInfo(self.robot, j)
            self.joints[info[1].decode()] = j
            self.links[info[12].decode()] = j
        for name, value in model["held_joints"].items():
            p.resetJointState(self.robot, self.joints[name], value)
        # The parts of the robot with shapes, as the tested pairs name them.
        self.robot_parts = {f"link:{name}": (self.robot, self.links[name]) for name in model["links"]}
        self.shared = {s["part"]: (place_solid(p, s), -1) for s in spec.get("solids", [])}


class Query:
    """One query's check: its arm's joints, its solids and what the hand carries placed,
    and PyBullet told to test only the pairs betr's check of this query tests."""

    def __init__(self, cell, spec, query, pairs):
        p = self.p = cell.p
        self.cell = cell
        arms = spec["arms"]
        arm = arms[query["arm"]]
        self.ids = [cell.joints[n] for n in arm["joints"]]
        self.flange = cell.links[arm["tip"]]
        p.resetBasePositionAndOrientation(
            cell.robot, query.get("base", spec["base"]), query.get("base_orientation", [0, 0, 0, 1]))
        others = query.get("others", spec.get("others"))
        for k, other in enumerate(arms):
            if k != query["arm"]:
                for name, v in zip(other["joints"], others[k]):
                    p.resetJointState(cell.robot, cell.joints[name], v)
        self.own = {s["part"]: (place_solid(p, s), -1) for s in query.get("solids", [])}
        self.carried = []
        for s in query.get("carried", []):
            body = p.createMultiBody(baseMass=0, baseCollisionShapeIndex=make_shape(p, s))
            self.carried.append((s["part"], body, s["position"], s["orientation"]))
        parts = dict(cell.robot_parts)
        parts.update(cell.shared)
        parts.update(self.own)
        parts.update({part: (body, -1) for part, body, _, _ in self.carried})
        self.names = {v: k for k, v in parts.items()}
        self.tested = set()
        for a, b in pairs:
            if a in parts and b in parts:
                self.tested.add(frozenset((parts[a], parts[b])))
        # Untested pairs are left out of PyBullet's own work too.
        everything = list(parts.values())
        for i, a in enumerate(everything):
            for b in everything[i + 1:]:
                p.setCollisionFilterPair(a[0], b[0], a[1], b[1], int(frozenset((a, b)) in self.tested))

    def collision(self, state):
        """The first tested pair that overlaps at `state` (names), or None."""
        p = self.p
        for k, joint in enumerate(self.ids):
            p.resetJointState(self.cell.robot, joint, state[k])
        if self.carried:
            at = p.getLinkState(self.cell.robot, self.flange, computeForwardKinematics=True)
            for _, body, pos, orn in self.carried:
                wp, wo = p.multiplyTransforms(at[4], at[5], pos, orn)
                p.resetBasePositionAndOrientation(body, wp, wo)
        p.performCollisionDetection()
        for c in p.getContactPoints():
            # Overlapping only: PyBullet also reports parts within its contact threshold.
            if c[8] >= 0:
                continue
            a, b = (c[1], c[3]), (c[2], c[4])
            if frozenset((a, b)) in self.tested:
                return self.names.get(a), self.names.get(b)
        return None

    def close(self):
        for body, _ in self.own.values():
            self.p.removeBody(body)
        for _, body, _, _ in self.carried:
            self.p.removeBody(body)


class QuietNative:
    """Standard output of native code silenced (PyBullet prints while it loads a URDF,
    unbuffered, into the lines this script answers on)."""

    def __enter__(self):
        sys.stdout.flush()
        self.saved = os.dup(1)
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, 1)
        os.close(devnull)

    def __exit__(self, *_):
        import ctypes

        ctypes.CDLL(None).fflush(None)
        os.dup2(self.saved, 1)
        os.close(self.saved)


def queries(spec):
    """Each query of `spec` with its check, in order."""
    import pybullet as p

    with QuietNative():
        p.connect(p.DIRECT)
        cell = Cell(p, spec)
    for i, query in enumerate(spec["queries"]):
        pairs = query.get("pairs") or spec["pairs_by_arm"][query["arm"]]
        check = Query(cell, spec, query, pairs)
        yield i, query, check
        check.close()


def plan(queries_json):
    from ompl import base as ob, geometric as og

    with open(queries_json) as f:
        spec = json.load(f)
    arms = spec["arms"]
    for i, query, check in queries(spec):
        arm = arms[query["arm"]]
        dof = len(check.ids)
        for which in ("start", "goal"):
            hit = check.collision(query[which])
            if hit:
                print(f"query {i}: the {which} collides: {hit[0]} with {hit[1]}", file=sys.stderr)
        space = ob.RealVectorStateSpace(dof)
        bounds = ob.RealVectorBounds(dof)
        for k in range(dof):
            bounds.setLow(k, arm["lower"][k])
            bounds.setHigh(k, arm["upper"][k])
        space.setBounds(bounds)
        ss = og.SimpleSetup(space)
        ss.setStateValidityChecker(lambda state, check=check: check.collision(state) is None)
        si = ss.getSpaceInformation()
        # The same joint-space resolution as betr's segment checks.
        si.setStateValidityCheckingResolution(spec["resolution"] / space.getMaximumExtent())
        start, goal = space.allocState(), space.allocState()
        for k in range(dof):
            start[k] = query["start"][k]
            goal[k] = query["goal"][k]
        ss.setStartAndGoalStates(start, goal)
        ss.setPlanner(og.RRTConnect(si))
        began = time.perf_counter()
        solved = ss.solve(spec["budget_s"])
        exact = bool(solved) and ss.haveExactSolutionPath()
        if exact:
            ss.simplifySolution()
        seconds = time.perf_counter() - began
        print(f"ompl query={i} solved={int(exact)} seconds={seconds:.6f}", flush=True)


def check(queries_json):
    """PyBullet's verdict on each query's `states` (1: free), one line per query."""
    with open(queries_json) as f:
        spec = json.load(f)
    for i, query, check in queries(spec):
        verdicts = "".join("0" if check.collision(q) else "1" for q in query["states"])
        print(f"check query={i} free={verdicts}", flush=True)


def main():
    if len(sys.argv) >= 5 and sys.argv[1] == "fk":
        fk(sys.argv[2], sys.argv[3], float(sys.argv[4]), sys.argv[5:])
    elif len(sys.argv) == 3 and sys.argv[1] == "plan":
        plan(sys.argv[2])
    elif len(sys.argv) == 3 and sys.argv[1] == "check":
        check(sys.argv[2])
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main()
