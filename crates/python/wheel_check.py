"""Run by .ci/run with an installed wheel, from a directory outside the checkout and without
EMG_DATA: the README's task plans from the robots and models inside the extension, and the
files it saves pass the independent checker."""

import extreme_line_motion as elm

plan = elm.Planner("fr3").plan(p0=[0.45, -0.2, 0.25], d=[0, 1, 0], n=[0, 0, -1])
assert plan.path_length_m > 0.9, (plan.path_length_m, plan.termination)
for path in plan.save("line"):
    elm.check(path)
assert elm.Planner("iiwa14").models == {"diffusion": True, "policy": True}
print(f"installed wheel: {plan.path_length_m:.3f} m of at most {plan.reachable_m:.2f} m, checked")
