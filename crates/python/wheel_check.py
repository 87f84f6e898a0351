"""Run by .ci/run with an installed wheel, from a directory outside the checkout and without
EMG_DATA: the README's task plans on every shipped arm from the robots and models inside the
extension, and the files it saves pass the independent checker."""

import extreme_line_motion as elm

plan = elm.Planner("fr3").plan(p0=[0.45, -0.2, 0.25], d=[0, 1, 0], n=[0, 0, -1])
assert plan.path_length_m > 0.9, (plan.path_length_m, plan.termination)
for path in plan.save("line"):
    elm.check(path)
print(f"installed wheel: {plan.path_length_m:.3f} m of at most {plan.reachable_m:.4f} m, checked")
# The other shipped arms plan the same line from the data inside the extension.
for robot in ("iiwa14", "ur5e"):
    planner = elm.Planner(robot)
    assert planner.models == {"diffusion": True, "policy": True}, robot
    other = planner.plan(p0=[0.45, -0.2, 0.25], d=[0, 1, 0], n=[0, 0, -1])
    assert other.path_length_m > 0.9, (robot, other.path_length_m, other.termination)
    for path in other.save(f"line-{robot}"):
        elm.check(path)
    print(f"installed wheel, {robot}: {other.path_length_m:.3f} m, checked")
