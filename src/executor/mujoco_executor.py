#!/usr/bin/env python3
"""betr's MuJoCo executor: the tabletop cell in MuJoCo physics, speaking the JSON-lines
protocol of docs/EXECUTORS.md.

The scene comes in the first request ("load"): the robot's URDF (compiled by MuJoCo's
own URDF importer), the table and every object as rigid bodies made of primitive parts
with masses and friction, under gravity. Then for each action betr sends:

- the arm follows the joint path betr's twin planned, under position control (joint
  actuators with gravity compensation), one tick being TICK_SECONDS of simulated time;
- where the path says the fingers act, they close (grasp, flip) or open (place, put_in).
  A grasp holds when both fingers touch the object after closing: a weld is then made
  between the gripper and the object at their relative pose, and it breaks when the
  object's weight exceeds what the grip's friction bears (2 fingers x friction x force;
  the force is the action's force= value, or GRIP_FORCE). The weld is not finger
  friction: an object held does not slide in the fingers, it is held or it is dropped;
- an arm that touches an object the action is not about, or pushes one more than
  PUSH_LIMIT, stops: "No collision free path found";
- skills whose motion the twin does not plan (open, unlock, look_for, move_base) are
  done as ordered: a lid moves to its open pose, the robot's base to where the order
  says; they fail in physics only through what follows them.

Objects released fall and settle before the action reports success. What is observed is
each object's pose (the centre of its footprint) and what the gripper holds.
"""
import json
import math
import re
import sys

import mujoco
import numpy as np

TIMESTEP = 0.001  # seconds: at 2 ms a tube dropped into the centrifuge passes through its floor
TICK_SECONDS = 0.5
JOINT_SPEED = 1.0  # rad/s along a path
FINGER_SECONDS = 0.4
SETTLE_SECONDS = 0.4
CONTROL_STEPS = 10  # steps between two looks of the controller (new targets, contacts)
CONVERGED = 0.002  # radians: every joint this close to its target
CONVERGE_SECONDS = 1.0
FLOOR_DEPTH = 0.03  # metres a fixture's floor on the table reaches into it
PUSH_LIMIT = 0.01  # metres an object the action is not about may be pushed
GRIP_FORCE = 20.0  # newtons, when the action names no force
ARM_KP = 4000.0
ARM_KV = 200.0
FINGER_KP = 300.0
FINGER_OPEN = 0.025
ROBOT_GROUP = 2  # contype bit of the robot's geoms: they touch objects, not the table


# The skills whose motion the twin plans: the arm follows the path it sends.
ARM_SKILLS = ("grasp", "place", "put_in", "flip")


class Refused(Exception):
    pass


def quat_wxyz(xyzw):
    x, y, z, w = xyzw
    return [w, x, y, z]


def quat_xyzw(wxyz):
    w, x, y, z = wxyz
    return [float(x), float(y), float(z), float(w)]


def add_parts(body, parts, friction, rgba, contype, conaffinity):
    for part in parts:
        geom = body.add_geom()
        geom.pos = part["position"]
        geom.quat = quat_wxyz(part["rotation"])
        shape = part["shape"]
        if shape == "box":
            geom.type = mujoco.mjtGeom.mjGEOM_BOX
            geom.size = part["half"]
        elif shape == "cylinder":
            geom.type = mujoco.mjtGeom.mjGEOM_CYLINDER
            geom.size = [part["radius"], part["half_height"], 0]
        elif shape == "ball":
            geom.type = mujoco.mjtGeom.mjGEOM_SPHERE
            geom.size = [part["radius"], 0, 0]
        elif shape == "capsule":
            geom.type = mujoco.mjtGeom.mjGEOM_CAPSULE
            geom.size = [part["radius"], part["half_length"], 0]
        else:
            raise Refused(f"a part of shape {shape!r} (box, cylinder, ball or capsule)")
        geom.friction = [friction, 0.005, 0.0001]
        # Stiff contacts (the time constant at twice the step): a resting object sinks
        # well under a millimetre into its support, as the twin's geometry expects of
        # things at rest, instead of MuJoCo's default few millimetres for a heavy plate.
        geom.solref = [2 * TIMESTEP, 1.0]
        geom.solimp = [0.95, 0.99, 0.001, 0.5, 2.0]
        geom.rgba = rgba
        geom.contype = contype
        geom.conaffinity = conaffinity


def thickened(part, base_z):
    """A fixture's box part resting on the table, reaching FLOOR_DEPTH down into it: a
    thin floor (a centrifuge's, 1 cm) is otherwise passed through by an object dropped
    onto it, contact pushing it out on the far side. Fixtures do not move, and nothing
    is below the table top, so the part is the same to everything else."""
    if part["shape"] != "box" or abs(base_z) > 1e-6 or part["rotation"] != [0, 0, 0, 1]:
        return part
    hx, hy, hz = part["half"]
    x, y, z = part["position"]
    if abs(z - hz) > 1e-4:
        return part
    return dict(part, half=[hx, hy, hz + FLOOR_DEPTH / 2], position=[x, y, z - FLOOR_DEPTH / 2])


def robot_spec(robot):
    """The robot's URDF as an MjSpec: package paths made absolute, meshes kept."""
    try:
        text = open(robot["urdf"], encoding="utf-8").read()
    except OSError as e:
        raise Refused(f"the robot description {robot['urdf']}: {e}")
    for package, folder in robot["packages"].items():
        text = text.replace(f"package://{package}/", folder.rstrip("/") + "/")
    text = re.sub(
        r"(<robot[^>]*>)",
        r'\1<mujoco><compiler strippath="false" discardvisual="true" fusestatic="false"/></mujoco>',
        text,
        count=1,
    )
    try:
        return mujoco.MjSpec.from_string(text)
    except Exception as e:  # MuJoCo raises ValueError with the compiler's text
        raise Refused(f"the robot description {robot['urdf']} does not compile: {e}")


def gripper_of(arm_spec, flange):
    """The hand hanging from `flange`, its finger joints (the prismatic joints below the
    flange) and the fingers' links."""
    model = arm_spec.copy().compile()
    top = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, flange)
    if top < 0:
        raise Refused(f"the robot description has no link {flange!r}")

    def below(body):
        while body > 0:
            if body == top:
                return True
            body = model.body_parentid[body]
        return False

    fingers, links = [], []
    for j in range(model.njnt):
        body = model.jnt_bodyid[j]
        if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_SLIDE and below(body):
            fingers.append(mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j))
            links.append(mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, body))
    if len(fingers) != 2:
        raise Refused(f"the gripper below {flange!r} has {len(fingers)} finger joints, not 2")
    hand = model.body_parentid[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, links[0])]
    return mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, hand), fingers, links


class Cell:
    def __init__(self, scene):
        self.scene = scene
        self.names = [o["name"] for o in scene["objects"]]
        spec = mujoco.MjSpec()
        spec.option.timestep = TIMESTEP
        spec.option.gravity = [0, 0, -9.81]
        spec.option.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
        spec.option.impratio = 10
        world = spec.worldbody
        self.arms = []
        robot = scene.get("robot")
        if not robot:
            raise Refused(
                "the MuJoCo cell needs the robot's description (the scenario names none, or "
                "betr could not read it), to move its arms along the twin's paths"
            )
        self.attach_robot(spec, robot)
        for obj in scene["objects"]:
            self.add_object(spec, world, obj)
        for obj in scene["objects"]:
            if obj.get("lid"):
                self.add_lid(spec, world, obj)
        for arm in self.arms:
            for name in self.names:
                if self.movable(name):
                    weld = spec.add_equality()
                    weld.type = mujoco.mjtEq.mjEQ_WELD
                    weld.name1 = arm["hand"]
                    weld.name2 = f"object:{name}"
                    weld.objtype = mujoco.mjtObj.mjOBJ_BODY
                    weld.name = f"grip:{arm['index']}:{name}"
                    weld.active = False
        try:
            self.model = spec.compile()
        except Exception as e:
            raise Refused(f"the MuJoCo model does not compile: {e}")
        self.data = mujoco.MjData(self.model)
        self.index()
        self.reset()

    def movable(self, name):
        obj = self.scene["objects"][self.names.index(name)]
        return not obj["fixed"]

    def attach_robot(self, spec, robot):
        arm_spec = robot_spec(robot)
        hands = [gripper_of(arm_spec, arm["flange"]) for arm in robot["arms"]]
        mount = spec.worldbody.add_body()
        mount.name = "robot mount"
        mount.mocap = True
        mount.pos = robot["base"]
        frame = mount.add_frame()
        frame.attach_body(arm_spec.worldbody.first_body(), "robot:", "")
        for body in spec.bodies:
            if body.name.startswith("robot:"):
                body.gravcomp = 1.0
        for geom in spec.geoms:
            if geom.parent.name.startswith("robot:"):
                geom.contype = ROBOT_GROUP
                geom.conaffinity = 0
        for joint in spec.joints:
            if joint.name.startswith("robot:"):
                joint.armature = 0.05
                joint.damping = 1.0
        for i, (arm, (hand, fingers, finger_links)) in enumerate(zip(robot["arms"], hands)):
            for joint, kp, kv in [(j, ARM_KP, ARM_KV) for j in arm["joints"]] + [
                (f, FINGER_KP, 5.0) for f in fingers
            ]:
                actuator = spec.add_actuator()
                actuator.name = f"act:{joint}"
                actuator.target = "robot:" + joint
                actuator.trntype = mujoco.mjtTrn.mjTRN_JOINT
                actuator.set_to_position(kp=kp, kv=kv)
            self.arms.append(
                {
                    "index": i,
                    "flange": arm["flange"],
                    "joints": ["robot:" + j for j in arm["joints"]],
                    "fingers": ["robot:" + f for f in fingers],
                    "finger_links": ["robot:" + l for l in finger_links],
                    "hand": "robot:" + hand,
                    "rest": arm["rest"],
                }
            )

    def add_object(self, spec, world, obj):
        name = obj["name"]
        body = world.add_body()
        body.name = f"object:{name}"
        body.pos = obj["position"]
        body.quat = quat_wxyz(obj["rotation"])
        if obj["fixed"]:
            parts = [thickened(p, obj["position"][2]) for p in obj["parts"]]
            add_parts(body, parts, obj["friction"], [0.6, 0.5, 0.4, 1], 1, 1 | ROBOT_GROUP)
            return
        body.add_freejoint().name = f"free:{name}"
        add_parts(body, obj["parts"], obj["friction"], [0.3, 0.4, 0.8, 1], 1, 1 | ROBOT_GROUP)
        for geom in body.geoms:
            geom.density = 0  # the mass below is the body's
        body.mass = obj["mass"]
        # Inertia of the parts' bounding box at the given mass: MuJoCo would otherwise
        # infer it from a density the scene does not give.
        hx, hy, hz = obj["half_extent"]
        body.ipos = [0, 0, hz]
        body.inertia = [
            obj["mass"] / 3 * (hy * hy + hz * hz),
            obj["mass"] / 3 * (hx * hx + hz * hz),
            obj["mass"] / 3 * (hx * hx + hy * hy),
        ]
        body.explicitinertial = True

    def add_lid(self, spec, world, obj):
        lid = obj["lid"]
        body = world.add_body()
        body.name = f"lid:{obj['name']}"
        body.mocap = True
        add_parts(body, lid["parts"], obj["friction"], [0.5, 0.5, 0.5, 1], 1, 1 | ROBOT_GROUP)

    def index(self):
        m = self.model
        self.bodies = {n: mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, f"object:{n}") for n in self.names}
        self.robot_bodies = {
            b for b in range(m.nbody) if (mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, b) or "").startswith("robot:")
        }
        for arm in self.arms:
            arm["qadr"] = [m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, j)] for j in arm["joints"]]
            arm["act"] = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, f"act:{j[6:]}") for j in arm["joints"]]
            arm["finger_act"] = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, f"act:{f[6:]}") for f in arm["fingers"]]
            arm["finger_qadr"] = [m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, f)] for f in arm["fingers"]]
            arm["finger_bodies"] = {mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, l) for l in arm["finger_links"]}
            arm["hand_id"] = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, arm["hand"])
        self.mount = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "robot mount")
        self.welds = {}
        for e in range(m.neq):
            name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_EQUALITY, e)
            _, arm, obj = name.split(":", 2)
            self.welds[(int(arm), obj)] = e

    def reset(self):
        m, d = self.model, self.data
        mujoco.mj_resetData(m, d)
        for arm in self.arms:
            for adr, act, q in zip(arm["qadr"], arm["act"], arm["rest"]):
                d.qpos[adr] = q
                d.ctrl[act] = q
            for adr, act in zip(arm["finger_qadr"], arm["finger_act"]):
                d.qpos[adr] = FINGER_OPEN
                d.ctrl[act] = FINGER_OPEN
        for obj in self.scene["objects"]:
            if obj.get("lid"):
                self.place_lid(obj["name"], obj["lid"]["open"] and obj["lid"]["is_open"])
        d.eq_active[:] = 0
        self.held = None
        self.force = {}
        mujoco.mj_forward(m, d)
        self.step(SETTLE_SECONDS)

    def place_lid(self, name, is_open):
        obj = self.scene["objects"][self.names.index(name)]
        lid = obj["lid"]
        local = lid["open"] if is_open else lid["closed"]
        body = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, f"lid:{name}")
        mocap = self.model.body_mocapid[body]
        base_pos = np.array(obj["position"])
        base_q = np.array(quat_wxyz(obj["rotation"]))
        pos = np.zeros(3)
        mujoco.mju_rotVecQuat(pos, np.array(local["position"], dtype=float), base_q)
        q = np.zeros(4)
        mujoco.mju_mulQuat(q, base_q, np.array(quat_wxyz(local["rotation"]), dtype=float))
        self.data.mocap_pos[mocap] = base_pos + pos
        self.data.mocap_quat[mocap] = q

    def set_pose(self, name, seen):
        """Put `name` at the pose `seen` (an observation's), just above it, at rest."""
        m, d = self.model, self.data
        j = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, f"free:{name}")
        adr = m.jnt_qposadr[j]
        d.qpos[adr : adr + 3] = seen["position"]
        d.qpos[adr + 2] += 0.002
        d.qpos[adr + 3 : adr + 7] = quat_wxyz(seen["rotation"])
        d.qvel[m.jnt_dofadr[j] : m.jnt_dofadr[j] + 6] = 0
        mujoco.mj_forward(m, d)

    def converge(self, arm, watch):
        """Hold the arm's targets until it is within CONVERGED of them (at most
        CONVERGE_SECONDS)."""
        for _ in range(round(CONVERGE_SECONDS / TIMESTEP)):
            error = max(abs(self.data.qpos[q] - self.data.ctrl[a]) for q, a in zip(arm["qadr"], arm["act"]))
            if error < CONVERGED:
                return None
            why = self.step(TIMESTEP, watch)
            if why:
                return why
        return None

    def step(self, seconds, watch=None):
        """Simulate, the grip and `watch` looked at every CONTROL_STEPS steps; with
        `watch`, stop early with the reason an arm must stop."""
        left = max(1, round(seconds / TIMESTEP))
        while left > 0:
            n = min(CONTROL_STEPS, left)
            mujoco.mj_step(self.model, self.data, nstep=n)
            left -= n
            self.check_grip()
            if watch is not None:
                why = watch()
                if why:
                    return why
        return None

    def check_grip(self):
        if self.held is None:
            return
        arm, name = self.held
        mass = self.model.body_subtreemass[self.bodies[name]]
        bears = 2 * self.friction(name) * self.force.get(name, GRIP_FORCE)
        if mass * 9.81 > bears:
            self.release()
            self.slipped = name

    def friction(self, name):
        return self.scene["objects"][self.names.index(name)]["friction"]

    def pose(self, name):
        b = self.bodies[name]
        return self.data.xpos[b].copy(), self.data.xquat[b].copy()

    def observation(self):
        objects = []
        for name in self.names:
            pos, q = self.pose(name)
            objects.append({"name": name, "position": [float(v) for v in pos], "rotation": quat_xyzw(q)})
        return {"reply": "observation", "objects": objects, "held": self.held[1] if self.held else None}

    def touching(self, body_a_set, body_b):
        d = self.data
        if d.ncon == 0:
            return False
        bodies = self.model.geom_bodyid
        a = bodies[d.contact.geom1[: d.ncon]]
        b = bodies[d.contact.geom2[: d.ncon]]
        group = np.fromiter(body_a_set, dtype=a.dtype)
        return bool(np.any((np.isin(a, group) & (b == body_b)) | (np.isin(b, group) & (a == body_b))))

    def grip(self, arm, name):
        """Weld `name` to the hand if both fingers touch it."""
        a = self.arms[arm]
        body = self.bodies[name]
        for finger in a["finger_bodies"]:
            if not self.touching({finger}, body):
                return False
        e = self.welds[(arm, name)]
        m, d = self.model, self.data
        hand = a["hand_id"]
        # The object's pose in the hand's frame, kept by the weld from now on.
        hq_inv = np.zeros(4)
        mujoco.mju_negQuat(hq_inv, d.xquat[hand])
        rel = np.zeros(3)
        mujoco.mju_rotVecQuat(rel, d.xpos[body] - d.xpos[hand], hq_inv)
        relq = np.zeros(4)
        mujoco.mju_mulQuat(relq, hq_inv, d.xquat[body])
        # eq_data of a weld: anchor (3), the relative pose (3 + 4), torque scale.
        m.eq_data[e][0:3] = 0
        # MuJoCo's relpose is body2's frame in body1's: the hand is body1.
        m.eq_data[e][3:6] = rel
        m.eq_data[e][6:10] = relq
        m.eq_data[e][10] = 1.0
        d.eq_active[e] = 1
        self.held = (arm, name)
        return True

    def release(self):
        if self.held is None:
            return
        self.data.eq_active[self.welds[self.held]] = 0
        self.held = None


def parse_action(text):
    """`grasp "hammer" {force = 40 N}` -> ("grasp", ["hammer"], {"force": 40.0}), as
    betr writes actions: the skill, the quoted objects, the values in braces."""
    head, _, tail = text.partition(" {")
    parts = re.findall(r'"([^"]*)"|(\S+)', head)
    skill = parts[0][1]
    objects = [quoted for quoted, _ in parts[1:] if quoted]
    values = {}
    if tail:
        for item in tail.rstrip("}").split(","):
            key, _, value = item.partition("=")
            number = re.match(r"\s*([-+0-9.eE]+)", value)
            values[key.strip()] = float(number.group(1)) if number else value.strip().strip('"')
    return skill, objects, values


class Action:
    """One action under way: its schedule of arm targets and where it stands."""

    def __init__(self, cell, order):
        self.cell = cell
        self.skill, self.objects, self.values = parse_action(order["action"])
        self.order = order
        self.t = 0.0
        self.waypoints = []
        self.acted = False
        path = order.get("path")
        self.arm = None
        if path and cell.arms:
            flanges = [a["flange"] for a in cell.arms]
            if path["arm"] not in flanges:
                raise Refused(f"the order's arm {path['arm']!r} is not one of {flanges}")
            self.arm = flanges.index(path["arm"])
            self.waypoints = [np.array(q, dtype=float) for q in path["joints"]]
            self.acts_at = path["acts_at"]
            bx, by = path["base"]
            cell.data.mocap_pos[cell.model.body_mocapid[cell.mount]] = [bx, by, 0.0]
        self.next = 0
        self.start = {n: cell.pose(n)[0] for n in cell.names}
        self.settle = 0.0
        cell.slipped = None
        if "force" in self.values and self.objects:
            cell.force[self.objects[0]] = self.values["force"]

    def bystanders(self):
        held = {self.cell.held[1]} if self.cell.held else set()
        return [n for n in self.cell.names if n not in self.objects and n not in held]

    def watch(self):
        cell = self.cell
        for name in self.bystanders():
            if cell.touching(cell.robot_bodies, cell.bodies[name]):
                return "No collision free path found"
            if np.linalg.norm(cell.pose(name)[0] - self.start[name]) > PUSH_LIMIT:
                return "No collision free path found"
        return None

    def tick(self):
        """Advance one tick: None while running, else ("success"|"failure", error)."""
        cell = self.cell
        if not self.waypoints and self.skill in ARM_SKILLS:
            return ("failure", f"{self.skill} came without the arm's path to follow")
        if not self.waypoints:
            return self.finish_without_path()
        budget = TICK_SECONDS
        arm = cell.arms[self.arm]
        while budget > 0 and self.next < len(self.waypoints):
            target = self.waypoints[self.next]
            now = np.array([cell.data.ctrl[a] for a in arm["act"]])
            span = float(np.max(np.abs(target - now))) / JOINT_SPEED
            dt = min(budget, max(span, TIMESTEP))
            steps = max(1, round(dt / TIMESTEP))
            # The target moves along the segment every CONTROL_STEPS steps (10 ms).
            done = 0
            while done < steps:
                n = min(CONTROL_STEPS, steps - done)
                done += n
                q = now + (target - now) * min(1.0, done * TIMESTEP / max(span, TIMESTEP))
                cell.data.ctrl[arm["act"]] = q
                why = cell.step(n * TIMESTEP, self.watch)
                if why:
                    self.hold_still()
                    return ("failure", why)
            budget -= steps * TIMESTEP
            if np.max(np.abs(np.array([cell.data.ctrl[a] for a in arm["act"]]) - target)) < 1e-9:
                if self.next == self.acts_at and not self.acted:
                    why = self.act()
                    if why:
                        self.hold_still()
                        return ("failure", why)
                self.next += 1
        if self.next < len(self.waypoints):
            return None
        why = cell.step(SETTLE_SECONDS)
        if cell.slipped:
            name = cell.slipped
            force = cell.force.get(name, GRIP_FORCE)
            mass = cell.model.body_subtreemass[cell.bodies[name]]
            # What holds it: its weight borne by the friction of two fingers.
            needed = mass * 9.81 / (2 * cell.friction(name))
            return (
                "failure",
                f"Object {name!r} slipped from the grasp: {force:g} N is too little force to "
                f"hold its {mass:.1f} kg ({math.ceil(needed)} N at least)",
            )
        return ("success", None)

    def act(self):
        cell = self.cell
        self.acted = True
        arm = cell.arms[self.arm]
        # A controller reaches the pose before the fingers act (a fine point), not while
        # the arm still lags behind its path.
        cell.converge(arm, self.watch)
        closing = self.skill in ("grasp", "flip")
        for a in arm["finger_act"]:
            cell.data.ctrl[a] = 0.0 if closing else FINGER_OPEN
        if not closing:
            cell.release()
            cell.step(FINGER_SECONDS)
            return None
        # The grip is made the moment both fingers touch, and the fingers stop there.
        target = self.objects[0]
        for _ in range(round(FINGER_SECONDS / TIMESTEP)):
            cell.step(TIMESTEP)
            if self.skill == "grasp" and cell.grip(self.arm, target):
                for a, q in zip(arm["finger_act"], arm["finger_qadr"]):
                    cell.data.ctrl[a] = cell.data.qpos[q]
                break
        if self.skill == "grasp" and cell.held is None:
            return f"Grasp failed: the fingers closed without holding {target!r}"
        if self.skill == "flip":
            expected = {o["name"]: o for o in (self.order.get("expected") or {}).get("objects", [])}
            turned = expected.get(self.objects[0])
            for a in arm["finger_act"]:
                cell.data.ctrl[a] = FINGER_OPEN
            if turned:
                cell.set_pose(self.objects[0], turned)
        return None

    def finish_without_path(self):
        cell = self.cell
        if self.skill == "open" and self.objects:
            obj = cell.scene["objects"][cell.names.index(self.objects[0])]
            if obj.get("lid"):
                cell.place_lid(self.objects[0], True)
        cell.step(SETTLE_SECONDS)
        return ("success", None)

    def hold_still(self):
        cell = self.cell
        arm = cell.arms[self.arm]
        for a, adr in zip(arm["act"], arm["qadr"]):
            cell.data.ctrl[a] = cell.data.qpos[adr]




def log(cell, action, result):
    """One line on standard error (betr's log) per action ended: what, how, and where
    every movable object is."""
    where = ", ".join(
        f"{n} ({p[0]:.3f}, {p[1]:.3f}, {p[2]:.3f})"
        for n in cell.names
        if cell.movable(n)
        for p in [cell.pose(n)[0]]
    )
    held = cell.held[1] if cell.held else "nothing"
    how = result[0] + (f": {result[1]}" if result[1] else "")
    print(f"{action.order['action']}: {how} at {cell.data.time:.2f} s; holds {held}; {where}",
          file=sys.stderr, flush=True)


def serve(lines, out):
    cell = None
    action = None
    for line in lines:
        try:
            request = json.loads(line)
            kind = request["request"]
            if kind == "load":
                cell = Cell(request["scene"])
                reply = {"reply": "done"}
            elif cell is None:
                reply = {"reply": "refused", "error": f"{kind} before the scene was loaded"}
            elif kind == "perform":
                if request["started"] or action is None:
                    action = Action(cell, request["order"])
                result = action.tick()
                if result is None:
                    reply = {"reply": "running"}
                else:
                    reply = {"reply": result[0]}
                    if result[1]:
                        reply["error"] = result[1]
                    log(cell, action, result)
                    action = None
            elif kind == "halt":
                if action is not None and action.arm is not None:
                    action.hold_still()
                action = None
                reply = {"reply": "done"}
            elif kind == "observe":
                reply = cell.observation()
            elif kind == "reset":
                cell.reset()
                action = None
                reply = {"reply": "done"}
            else:
                reply = {"reply": "refused", "error": f"unknown request {kind!r}"}
        except Refused as e:
            reply = {"reply": "refused", "error": str(e)}
        except (KeyError, TypeError, ValueError, IndexError) as e:
            reply = {"reply": "refused", "error": f"a malformed request: {type(e).__name__}: {e}"}
        out.write(json.dumps(reply) + "\n")
        out.flush()


def step_rate(scene_file, seconds):
    """How fast the cell simulates: the scene in `scene_file` (a load request's scene)
    with every arm swinging 0.3 rad about its rest values, for `seconds` of wall time."""
    import time

    with open(scene_file, encoding="utf-8") as f:
        cell = Cell(json.load(f))
    steps, began = 0, time.perf_counter()
    while time.perf_counter() - began < seconds:
        for arm in cell.arms:
            for k, (a, q) in enumerate(zip(arm["act"], arm["rest"])):
                cell.data.ctrl[a] = q + 0.3 * math.sin(cell.data.time * (1 + 0.2 * k))
        for _ in range(100):
            mujoco.mj_step(cell.model, cell.data)
        steps += 100
    wall = time.perf_counter() - began
    print(json.dumps({"steps": steps, "wall": wall, "simulated": steps * TIMESTEP}))


if __name__ == "__main__":
    if len(sys.argv) == 4 and sys.argv[1] == "--step-rate":
        step_rate(sys.argv[2], float(sys.argv[3]))
    else:
        serve(sys.stdin, sys.stdout)
