"""Forward kinematics of the YuMi's arms computed by Pinocchio, as a fixture for betr's
own kinematics (tests/fixtures/motion/yumi_fk.json).

For each arm (a link moved by revolute joints with none below it: the tool flange), 20
joint vectors are drawn inside the joint limits from a fixed seed, and the flange's pose
in the root frame is written with the joint values, in the order of the joints from the
root to the flange. Usage: python motion_fixtures.py URDF OUT.json
"""
import json
import sys

import numpy as np
import pinocchio as pin

urdf, out = sys.argv[1], sys.argv[2]
model = pin.buildModelFromUrdf(urdf)
data = model.createData()
rng = np.random.default_rng(39)

revolute = {j.id for j in model.joints if j.shortname().startswith("JointModelR")}
children = {jid: [] for jid in range(model.njoints)}
for jid in range(1, model.njoints):
    children[model.parents[jid]].append(jid)


def below(jid):
    stack, found = list(children[jid]), []
    while stack:
        j = stack.pop()
        found.append(j)
        stack.extend(children[j])
    return found


arms = []
for frame in model.frames:
    if frame.type != pin.FrameType.BODY:
        continue
    jid = frame.parentJoint
    # The body a revolute joint moves directly, with no revolute joint below that joint.
    if jid not in revolute or model.names[jid] == "universe":
        continue
    if frame.placement != pin.SE3.Identity():
        continue
    if any(j in revolute for j in below(jid)):
        continue
    path = []
    j = jid
    while j != 0:
        path.append(j)
        j = model.parents[j]
    path.reverse()
    cases = []
    for _ in range(20):
        q = pin.neutral(model)
        values = []
        for j in path:
            lo = model.lowerPositionLimit[model.joints[j].idx_q]
            hi = model.upperPositionLimit[model.joints[j].idx_q]
            v = float(rng.uniform(lo, hi))
            q[model.joints[j].idx_q] = v
            values.append(v)
        pin.forwardKinematics(model, data, q)
        pin.updateFramePlacements(model, data)
        m = data.oMf[model.getFrameId(frame.name)]
        cases.append(
            {
                "q": values,
                "translation": [float(x) for x in m.translation],
                "rotation": [[float(x) for x in row] for row in m.rotation],
            }
        )
    arms.append(
        {
            "tip": frame.name,
            "joints": [model.names[j] for j in path],
            "cases": cases,
        }
    )

fixture = {
    "source": "yumi_description/urdf/yumi.urdf from rtb-data 1.0.1",
    "computed_by": f"pinocchio {pin.__version__}",
    "arms": arms,
}
with open(out, "w") as f:
    json.dump(fixture, f, indent=1)
    f.write("\n")
print(f"{out}: {len(arms)} arms, {sum(len(a['cases']) for a in arms)} cases")
