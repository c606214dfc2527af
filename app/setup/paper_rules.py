"""The paper's rules: the extensions of the algorithm, and the values that turn them off."""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace

from planner.parameters import PlannerConfig, RsgParameters


@dataclass(frozen=True)
class Extension:
    """A documented extension of the paper, and its value under the paper's rules.

    Attributes:
        name: What it is, in words.
        field: Its parameter, in :class:`planner.parameters.RsgParameters` or
            :class:`planner.parameters.Constraints`.
        paper_value: The value that turns it off.
    """

    name: str
    field: str
    paper_value: object


# What --paper-rules turns off: the one list the CLI help and the README refer to.
PAPER_RULES: tuple[Extension, ...] = (
    Extension("the push hold", "push_hold_time", 0.0),
    Extension("the step reaction time", "step_reaction_time", 0.0),
    Extension("the QP's location for a timing jump below gamma_v", "qp_at_timing_jump", False),
    Extension("the announced foothold at a nominal jump", "announced_foothold", False),
    Extension("the next step previewed at the touchdown", "preview_at_touchdown", False),
    Extension("a timing jump at an early touchdown", "touchdown_window", 0.0),
    Extension("the leg reach in the step QP", "com_reach", math.inf),
    Extension("the DCM row (27c')", "dcm_inset", None),
)
# What it keeps (README, "Implementation notes"): the misprint fixes, and two departures
# without which the paper's own nominal walk fails with these limits.
PAPER_RULES_KEPT = (
    "the misprints fixed, and two documented departures: the double-support compensation "
    "added after the saturation of K_u e_u, and D_S gated by s~ >= T_DSP + T_SP"
)
PAPER_RULES_HELP = (
    "the paper's algorithm: turns off "
    + ", ".join(f"{e.name} ({e.field}={e.paper_value})" for e in PAPER_RULES)
    + "; keeps "
    + PAPER_RULES_KEPT
    + " (app/setup/paper_rules.py)"
)


def paper_rules(config: PlannerConfig) -> PlannerConfig:
    """``config`` under the paper's rules: every extension of :data:`PAPER_RULES` off."""
    rsg_fields = {f.name for f in fields(RsgParameters)}
    rsg = {e.field: e.paper_value for e in PAPER_RULES if e.field in rsg_fields}
    constraints = {e.field: e.paper_value for e in PAPER_RULES if e.field not in rsg_fields}
    return replace(
        config,
        rsg=replace(config.rsg, **rsg),  # type: ignore[arg-type]
        constraints=replace(config.constraints, **constraints),  # type: ignore[arg-type]
    )
