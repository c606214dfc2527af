"""The push fields: Push applies exactly what they hold, or refuses and says why."""

from __future__ import annotations

import math

import pytest

from web.push_input import (
    PushBounds,
    PushInput,
    field_rules,
    format_field,
    push_refusal,
    read_push,
    wrap_degrees,
)

BOUNDS = PushBounds.for_mass(33.3)
GOOD = {"direction": "30", "impulse": "5.557", "duration": "0.1"}


@pytest.mark.parametrize(
    "text,value",
    [("-180", 180.0), (" 45.5 ", 45.5), ("-36.87", -36.87), ("1e1", 10.0),
     ("190", -170.0), ("360", 0.0), ("-360", 0.0)],
)  # fmt: skip
def test_a_direction_in_the_pages_range_is_wrapped_as_its_hint_says(text, value):
    push = read_push({**GOOD, "direction": text}, BOUNDS)
    assert isinstance(push, PushInput)
    assert push.direction == pytest.approx(value)


def test_the_typed_impulse_and_duration_are_applied_exactly():
    push = read_push(GOOD, BOUNDS)
    assert push == PushInput(30.0, 5.557, 0.1)
    top = read_push({**GOOD, "impulse": repr(BOUNDS.impulse_max)}, BOUNDS)
    assert isinstance(top, PushInput) and top.impulse == BOUNDS.impulse_max


@pytest.mark.parametrize(
    "field,text,says",
    [("impulse", "", "impulse is empty"), ("impulse", "   ", "impulse is empty"),
     ("impulse", "abc", "impulse 'abc' is not a number"),
     ("impulse", "NaN", "impulse 'NaN' is not a number"),
     ("impulse", "inf", "impulse 'inf' is not a number"),
     ("impulse", "1,5", "impulse '1,5' is not a number"),
     ("impulse", "1e9", "impulse 1e9 N s is out of range"),
     ("impulse", "0", "impulse 0 N s is out of range"),
     ("impulse", "-3", "impulse -3 N s is out of range"),
     ("direction", "720.5", "direction 720.5 deg is out of range"),
     ("direction", "1e9", "direction 1e9 deg is out of range"),
     ("direction", "", "direction is empty"),
     ("duration", "5", "duration 5 s is out of range"),
     ("duration", "0.01", "duration 0.01 s is out of range"),
     ("duration", "-", "duration '-' is not a number")],
)  # fmt: skip
def test_a_bad_field_refuses_the_push_naming_the_field_the_text_and_the_range(field, text, says):
    refused = read_push({**GOOD, field: text}, BOUNDS)
    assert isinstance(refused, list) and len(refused) == 1
    assert refused[0].startswith(says)
    assert refused[0].endswith(field_rules(BOUNDS)[field].allowed())


def test_every_bad_field_is_named_at_once():
    refused = read_push({"direction": "x", "impulse": "", "duration": "9"}, BOUNDS)
    assert isinstance(refused, list)
    assert [r.split()[0] for r in refused] == ["direction", "impulse", "duration"]


def test_the_ranges_are_the_robots():
    rules = field_rules(BOUNDS)
    assert rules["impulse"].allowed() == f"more than 0 to {format_field(BOUNDS.impulse_max)} N s"
    assert rules["duration"].allowed() == "from 0.05 to 0.5 s"
    assert rules["direction"].allowed() == "from -360 to 360 deg"


def test_a_zero_impulse_is_refused_as_a_push():
    assert "impulse 0 N s" in push_refusal(PushInput(10.0, 0.0, 0.1))
    assert push_refusal(PushInput(10.0, 0.5, 0.1)) == ""


def test_wrap_degrees_has_no_negative_zero():
    assert math.copysign(1.0, wrap_degrees(-360.0)) == 1.0
    assert format_field(-0.0001) == "0"
