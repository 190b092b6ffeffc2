#!/usr/bin/env python3
"""The anchors of `betr bench motion`, run in the venv under target/.

    bench_motion.py fk URDF PACKAGE_DIR SECONDS TIP...
        Pinocchio's forward kinematics on the same URDF: joint values drawn within the
        limits, forwardKinematics and the placement of each TIP frame, for SECONDS.
        Prints `pinocchio fk_per_s=...`.

    bench_motion.py plan QUERIES_JSON
        OMPL's RRTConnect (path simplified afterwards, as betr shortcuts) with PyBullet's
        contact test as the state validity checker, on the same URDF and solids (boxes
        for every query, or each query's own solids and what its hand carries). Prints one
        `ompl query=i solved=0|1 seconds=...` line per query.
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


def resolved_urdf(urdf, package, package_dir):
    """The URDF with package:// paths made absolute, for PyBullet."""
    with open(urdf) as f:
        text = f.read()
    text = text.replace(f"package://{package}/", package_dir.rstrip("/") + "/")
    out = tempfile.NamedTemporaryFile("w", suffix=".urdf", delete=False)
    out.write(text)
    out.close()
    return out.name


def make_shape(p, solid):
    """A PyBullet collision shape for one of betr's solids (see bench/cell_motion.rs)."""
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


def plan(queries_json):
    import pybullet as p
    from ompl import base as ob, geometric as og

    with open(queries_json) as f:
        spec = json.load(f)
    p.connect(p.DIRECT)
    urdf = resolved_urdf(spec["urdf"], spec["package"], spec["package_dir"])
    robot = p.loadURDF(urdf, basePosition=spec["base"], useFixedBase=True)
    os.unlink(urdf)
    joints, links = {}, {}
    parents = {}
    for j in range(p.getNumJoints(robot)):
        info = p.getJointInfo(robot, j)
        joints[info[1].decode()] = j
        links[info[12].decode()] = j
        parents[j] = info[16]
    # The random targets' clutter: boxes for every query.
    for box in spec.get("boxes", []):
        shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=box["half"])
        p.createMultiBody(baseMass=0, baseCollisionShapeIndex=shape, basePosition=box["center"])
    arms = spec["arms"]  # per arm: joint names, lower, upper, tip link
    for i, query in enumerate(spec["queries"]):
        arm = arms[query["arm"]]
        ids = [joints[n] for n in arm["joints"]]
        others = query.get("others", spec.get("others"))
        p.resetBasePositionAndOrientation(robot, query.get("base", spec["base"]), [0, 0, 0, 1])
        # The other arms where the query holds them.
        for k, other in enumerate(arms):
            if k != query["arm"]:
                for name, v in zip(other["joints"], others[k]):
                    p.resetJointState(robot, joints[name], v)
        # The query's own solids (the cell scenarios' motions), and what the hand carries,
        # placed relative to the flange at every check.
        bodies = []
        for solid in query.get("solids", []):
            bodies.append(p.createMultiBody(
                baseMass=0, baseCollisionShapeIndex=make_shape(p, solid),
                basePosition=solid["position"], baseOrientation=solid["orientation"]))
        carried = []
        for solid in query.get("carried", []):
            body = p.createMultiBody(baseMass=0, baseCollisionShapeIndex=make_shape(p, solid))
            carried.append((body, solid["position"], solid["orientation"]))
        carried_ids = {b for b, _, _ in carried}
        flange = links.get(arm.get("tip", ""), ids[-1])

        def own_link(j, first=ids[0]):
            while j >= 0:
                if j == first:
                    return True
                j = parents[j]
            return False

        dof = len(ids)
        space = ob.RealVectorStateSpace(dof)
        bounds = ob.RealVectorBounds(dof)
        for k in range(dof):
            bounds.setLow(k, arm["lower"][k])
            bounds.setHigh(k, arm["upper"][k])
        space.setBounds(bounds)
        ss = og.SimpleSetup(space)

        def valid(state, ids=ids, dof=dof, carried=carried, carried_ids=carried_ids, flange=flange, own_link=own_link):
            for k in range(dof):
                p.resetJointState(robot, ids[k], state[k])
            if carried:
                at = p.getLinkState(robot, flange, computeForwardKinematics=True)
                for body, pos, orn in carried:
                    wp, wo = p.multiplyTransforms(at[4], at[5], pos, orn)
                    p.resetBasePositionAndOrientation(body, wp, wo)
            p.performCollisionDetection()
            # Without URDF_USE_SELF_COLLISION PyBullet reports only the robot against
            # the solids; the hand holds what it carries.
            for c in p.getContactPoints(bodyA=robot):
                if c[2] not in carried_ids:
                    return False
            # What the hand carries against the solids and the robot but this arm.
            for body in carried_ids:
                for c in p.getContactPoints(bodyA=body):
                    if c[2] == robot and own_link(c[4]):
                        continue
                    if c[2] in carried_ids:
                        continue
                    return False
            return True

        ss.setStateValidityChecker(valid)
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
        for body in bodies + [b for b, _, _ in carried]:
            p.removeBody(body)


def main():
    if len(sys.argv) >= 5 and sys.argv[1] == "fk":
        fk(sys.argv[2], sys.argv[3], float(sys.argv[4]), sys.argv[5:])
    elif len(sys.argv) == 3 and sys.argv[1] == "plan":
        plan(sys.argv[2])
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main()
