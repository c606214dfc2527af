"""The push fields: what the user types becomes the value used, shown in the field."""

from __future__ import annotations

import math

import numpy as np
import pytest

from web.push_input import (
    PushBounds,
    PushInput,
    format_field,
    push_refusal,
    read_field,
    wrap_degrees,
)

BOUNDS = PushBounds.for_mass(33.3)


def clip_impulse(value: float) -> float:
    return float(np.clip(value, 0.0, BOUNDS.impulse_max))


@pytest.mark.parametrize(
    "text,value,shown",
    [("720", 0.0, "0"), ("-180", 180.0, "180"), (" 45.5 ", 45.5, "45.5"), ("-405", -45.0, "-45"),
     ("1e1", 10.0, "10"), ("190", -170.0, "-170")],
)  # fmt: skip
def test_direction_field_wraps_and_shows_the_value_used(text, value, shown):
    read = read_field(text, 30.0, "direction", "deg", wrap_degrees)
    assert read.value == pytest.approx(value) and read.text == shown and read.refused == ""


@pytest.mark.parametrize("text", ["", "   ", "abc", "1,5", "nan", "inf", "-", "1e"])
def test_empty_or_non_numeric_text_is_refused_and_the_field_shows_the_value_in_use(text):
    read = read_field(text, 5.6, "impulse", "N s", clip_impulse)
    assert read.value == 5.6 and read.text == "5.6"
    assert read.refused.startswith("impulse: ") and read.refused.endswith("using 5.6 N s")
    assert ("empty" in read.refused) == (text.strip() == "")


def test_impulse_above_the_bound_is_clipped_and_shown():
    read = read_field("99", 5.0, "impulse", "N s", clip_impulse)
    assert read.value == pytest.approx(BOUNDS.impulse_max) == pytest.approx(16.65)
    assert read.text == format_field(BOUNDS.impulse_max) and read.refused == ""


def test_a_zero_impulse_is_refused_as_a_push():
    assert "impulse 0 N s" in push_refusal(PushInput(10.0, 0.0, 0.1))
    assert push_refusal(PushInput(10.0, 0.5, 0.1)) == ""


def test_wrap_degrees_has_no_negative_zero():
    assert math.copysign(1.0, wrap_degrees(-360.0)) == 1.0
    assert format_field(-0.0001) == "0"
