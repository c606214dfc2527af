"""Push the G1 once in PyBullet from Python and read what happened.

8 N s forward over 0.1 s at mid single support of the third step; the RSG adjusts the
next step. Takes about 10 s. Run: python examples/push_g1.py
"""

import numpy as np

from app.runner import run_closed_loop
from app.scenarios import Scenario
from app.setup.build import build_robot_backend
from planner import Push

backend, config, initial = build_robot_backend("g1", "rsg")  # torque-controlled G1
push = Push(time=2.75, impulse=np.array([8.0, 0.0]), duration=0.1)  # [s], [N s], [s]
try:
    result = run_closed_loop(backend, config, Scenario("push", 6.75, (push,)), initial)
finally:
    backend.close()
adjusted = [s.event for s in result.steps if s.event["adjusted"]]
print(f"recovered: {result.recovered}, fell: {result.fall.fell} {result.fall.reason}")
print(f"{len(result.steps)} steps, {len(adjusted)} adjusted:")
for event in adjusted:
    print(f"  t = {event['t']:.2f} s, {event['foot']} foot to {np.round(event['position'], 3)} m")
gamma = config.rsg.lyapunov_threshold
print(f"max V_u = {result.max_lyapunov / gamma:.2f} gamma_v; CoM x at the end "
      f"{result.column('com_x')[-1]:.2f} m")  # fmt: skip
