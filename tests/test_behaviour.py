"""The fixed LIPM and G1 runs of behaviour_cases.py repeat their recorded bits."""

import json

import numpy as np
import pytest
from behaviour_cases import CASES, RECORD, run_in_child


@pytest.mark.parametrize("name", sorted(CASES))
def test_run_repeats_its_record_bit_for_bit(name, tmp_path):
    with np.load(RECORD) as data:
        recorded = {k.split("/", 1)[1]: data[k] for k in data.files if k.startswith(f"{name}/")}
    assert recorded, f"{name} is not in {RECORD}: record it (python tests/behaviour_cases.py)"
    again = run_in_child(name, tmp_path / "again.npz")
    assert sorted(again) == sorted(recorded)
    assert json.loads(str(again["steps"])) == json.loads(str(recorded["steps"]))
    for column, values in recorded.items():
        if column == "steps":
            continue
        differs = np.flatnonzero(
            ~((again[column] == values) | (np.isnan(values) & np.isnan(again[column])))
        )
        assert again[column].shape == values.shape and differs.size == 0, (
            f"{name}: {column} first differs at tick {differs[:1]}"
        )


def test_the_recorded_g1_run_adjusts_a_step_after_its_push():
    """The G1 case exercises the push path (not only nominal walking)."""
    with np.load(RECORD) as data:
        steps = json.loads(str(data["g1-push/steps"]))
    assert any(step["adjusted"] for step in steps)
