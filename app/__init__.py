"""The command line and the experiments around the planner: backends (LIPM, PyBullet),
the whole-body stabilizer, the closed loop (:mod:`app.runner`), experiments and results.
"""
