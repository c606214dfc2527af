"""The robot view poses the URDF meshes like viser's own ``update_cfg`` (no browser)."""

from __future__ import annotations

import socket

import numpy as np
import pytest

viser = pytest.importorskip("viser")


def test_closed_form_joint_rotations_match_update_cfg():
    from robots import get_robot
    from robots.urdf_cache import derived_urdf
    from web.robot_view import RobotView

    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    server = viser.ViserServer(host="127.0.0.1", port=port, verbose=False)
    try:
        view = RobotView(server, derived_urdf(get_robot("g1")), "/world/robot")
        assert len(view.joint_names) == 29
        rng = np.random.default_rng(1)
        joints = {name: float(rng.uniform(-0.8, 0.8)) for name in view.joint_names}
        view.update(np.array([0.1, 0.2, 0.7]), np.array([1.0, 0.0, 0.0, 0.0]), joints)
        frames = [frame for _, frame in view._moving]
        ours = np.array([frame.wxyz for frame in frames])
        view.urdf.update_cfg(np.array([joints[name] for name in view.joint_names]))
        reference = np.array([frame.wxyz for frame in frames])
        sign = np.sign(np.sum(ours * reference, axis=1))[:, None]  # q and -q: same rotation
        np.testing.assert_allclose(ours * sign, reference, atol=1e-12)
        np.testing.assert_allclose(view.base.position, [0.1, 0.2, 0.7])
    finally:
        server.stop()
