"""What the planner drives: the point-mass LIPM (:mod:`app.backends.lipm`) and the full
robot in PyBullet (:mod:`app.backends.pybullet`), behind :class:`app.backends.base.Backend`."""
