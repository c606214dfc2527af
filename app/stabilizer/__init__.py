"""The whole-body stabilizer between the RSG and the joints, one loop per module
(:mod:`app.stabilizer.controller` runs them in order every tick; docs/full-robot.md):
centroidal targets, wrench distribution, landing, estimation, and their options
(:mod:`app.stabilizer.config`)."""
