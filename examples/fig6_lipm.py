"""The paper's Fig. 6 on the point-mass LIPM, with the RSG used as a library.

Two pushes hit the walking LIPM; the RSG adjusts the step after the first one and the
Lyapunov level V_u of the DCM error falls back below gamma_v. Run: python examples/fig6_lipm.py
"""

import numpy as np

from app.backends.lipm import LipmBackend
from app.runner import walking_start
from app.scenarios import BUILT_IN
from planner import MeasuredState, PlannerConfig, ReactiveStepGenerator

config = PlannerConfig()  # the paper's point mass: 60 kg, c_z = 0.8 m
scenario = BUILT_IN["paper-fig6"]  # its two pushes [N s] over 0.1 s
start = walking_start(config)
backend = LipmBackend(config.model)
rsg = ReactiveStepGenerator(config)
rsg.reset(start.stance, start.swing)
state = backend.reset(start)
dt = backend.control_period  # [s]
levels = []
for k in range(round(scenario.duration / dt)):
    t = k * dt
    out = rsg.update(MeasuredState(t, state.com_position, state.com_velocity), dt)
    levels.append(out.lyapunov)
    if out.step is not None:
        kind = "adjusted" if out.step.adjusted else "nominal"
        where = np.round(out.step.position, 3)
        print(f"t = {t:5.2f} s  {kind:8s} step of the {out.step.foot} foot to {where} m")
    force = scenario.impulse_between(t, t + dt) / dt  # [N], the tick's mean push force
    state = backend.step(out, force)
gamma = config.rsg.lyapunov_threshold
print(f"max V_u = {max(levels) / gamma:.2f} gamma_v, final V_u = {levels[-1] / gamma:.3f} gamma_v")
assert levels[-1] < gamma and not backend.fall_status().fell
