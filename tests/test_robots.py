"""Robot descriptions and the derived URDF."""

from __future__ import annotations

import dataclasses
import xml.etree.ElementTree as ET

import pytest

from planner.exceptions import ParameterError
from robots import available_robots, get_robot
from robots.urdf_cache import derive_urdf_text, derived_urdf, robots_share_dir


@pytest.fixture(autouse=True)
def _cache_in_tmp(tmp_path, monkeypatch):
    monkeypatch.setenv("RSG_CACHE_DIR", str(tmp_path))


def test_registry_lists_g1_and_rejects_unknown_names():
    assert "g1" in available_robots()
    assert get_robot("g1").name == "g1"
    with pytest.raises(ParameterError) as error:
        get_robot("no_such_robot")
    assert "g1" in error.value.allowed


def test_description_validates_its_fields():
    g1 = get_robot("g1")
    with pytest.raises(ParameterError):
        dataclasses.replace(g1, com_height=-1.0)
    with pytest.raises(ParameterError):
        dataclasses.replace(g1, urdf_source="/abs/path.urdf")
    with pytest.raises(ParameterError):
        dataclasses.replace(g1, left_ankle_link=g1.right_ankle_link)


def test_derived_urdf_is_reproducible_and_has_the_frames(tmp_path):
    g1 = get_robot("g1")
    path = derived_urdf(g1)
    assert path.is_relative_to(tmp_path)
    first = path.read_text()
    path.unlink()
    assert derived_urdf(g1).read_text() == first
    source = (robots_share_dir() / g1.urdf_source).read_text()
    assert derive_urdf_text(g1, source, robots_share_dir()) == first

    root = ET.fromstring(first)
    links = {link.get("name"): link for link in root.iter("link")}
    for frame in ("left_foot", "right_foot", "trunk"):
        assert frame in links
    assert all(link.find("inertial") is not None for link in links.values())
    meshes = [mesh.get("filename") for mesh in root.iter("mesh")]
    assert meshes and not any(name.startswith("package://") for name in meshes)
    joints = {joint.find("child").get("link"): joint for joint in root.iter("joint")}
    assert joints["left_foot"].find("parent").get("link") == g1.left_ankle_link
    assert joints["left_foot"].find("origin").get("xyz") == "0 0 -0.035"


def test_urdf_mass_matches_description():
    g1 = get_robot("g1")
    root = ET.parse(derived_urdf(g1)).getroot()
    mass = sum(float(element.get("value")) for element in root.iter("mass"))
    assert mass == pytest.approx(g1.total_mass, abs=0.1)
