"""One tab's view: a push that acted between two of its frames is still drawn, where it
acted (ending at the CoM), and the frame's token carries the pushes it shows."""

from __future__ import annotations

import time
from types import SimpleNamespace

import numpy as np
import pytest
import viser
from test_web_scene_model import FOOT_LOWER, FOOT_UPPER, make_state

from conftest import free_port
from web.client_view import PUSH_SHOW_TIME, ClientView, Frame
from web.scene_model import push_arrow
from web.snapshot import PageStatus, Snapshot


@pytest.fixture(scope="module")
def server():
    server = viser.ViserServer(host="127.0.0.1", port=free_port(), verbose=False)
    yield server
    server.stop()


def tab_of(server: viser.ViserServer) -> ClientView:
    """A view drawing into the server's scene, as a tab's view draws into its own."""
    client = SimpleNamespace(scene=server.scene, client_id=0, atomic=server.atomic)
    return ClientView(client, None, lambda: None, 40.0)  # type: ignore[arg-type]


def frame(serial: int, pushes: int, acting: bool) -> Frame:
    state = make_state(push_impulse=np.array([8.0, -6.0]) if acting else None)
    snap = Snapshot(
        serial, state, None, PageStatus(), foot_lower=FOOT_LOWER, foot_upper=FOOT_UPPER,
        pushes_applied=pushes, last_push=np.array([8.0, -6.0]) if pushes else None,
    )  # fmt: skip
    return Frame(serial, snap)


def test_a_push_between_two_frames_is_drawn_in_the_next_one_then_hidden(server):
    view = tab_of(server)
    assert view._draw(frame(1, 0, acting=False), 0.0) == "rsg-frame:1:0"
    assert not view.push_node.visible
    # The push acted and ended between the tab's frames: the next frame draws it anyway.
    assert view._draw(frame(2, 1, acting=False), 1.0) == "rsg-frame:2:1"
    assert view.push_node.visible
    state = frame(2, 1, acting=False).snap.state
    expected = push_arrow(state.com, state.com_height, np.array([8.0, -6.0]))
    np.testing.assert_allclose(view.push_node.points[0], expected, atol=1e-6)
    np.testing.assert_allclose(expected[1, :2], state.com, atol=1e-12)  # ends at the CoM
    time.sleep(PUSH_SHOW_TIME + 0.05)
    view._draw(frame(3, 1, acting=False), 1.0)
    assert not view.push_node.visible


def test_a_reset_forgets_the_pushes_shown(server):
    view = tab_of(server)
    view._draw(frame(1, 2, acting=True), 0.0)
    assert view.push_node.visible
    assert view._draw(frame(2, 0, acting=False), 1.0) == "rsg-frame:2:0"
    assert not view.push_node.visible


def test_the_world_is_shifted_under_the_robot_and_the_grid_follows(server):
    view = tab_of(server)
    view._draw(frame(1, 0, acting=False), 0.0)
    com = frame(1, 0, acting=False).snap.state.com
    np.testing.assert_allclose(view.world.position[:2], -com, atol=1e-12)
    np.testing.assert_allclose(view.grid.position[:2], np.round(com), atol=1e-12)


def test_the_same_state_redrawn_does_not_move_the_view(server):
    """A redraw without a new state (the robot hidden, say) leaves the world where it was
    drawn: the side view's camera and the drawn soles stay on the ground's line."""
    view = tab_of(server)
    view._draw(frame(1, 0, acting=False), 0.0)
    view.offset = view.offset + 0.5  # as if the view was still following the robot
    view.world.position = (-view.offset[0], -view.offset[1], 0.0)
    before = np.array(view.world.position)
    hidden = frame(1, 0, acting=False)
    view._draw(Frame(2, hidden.snap, None, robot_visible=False), 1.0)
    np.testing.assert_array_equal(view.world.position, before)


def test_a_slow_tab_gets_the_newest_frame_each_time_not_a_backlog(server):
    """A tab that takes 0.2 s to apply a frame while frames are published at up to 200 Hz
    is sent at most one frame per 0.2 s, each the newest published when it was sent (the
    bounds hold however loaded the machine is: each frame waits for its token)."""
    published: list[Frame] = []
    sent: list[tuple[int, int]] = []  # (frame drawn, newest published then)

    class SlowStorage:
        def get_item(self, key: str, timeout: float) -> None:
            time.sleep(0.2)  # the tab draws the frame

    client = SimpleNamespace(
        scene=server.scene, client_id=7, atomic=server.atomic, flush=lambda: None,
        local_storage=SlowStorage(),
    )  # fmt: skip
    view = ClientView(client, None, lambda: published[-1] if published else None, 60.0)
    draw = view._draw

    def recording_draw(frame: Frame, dt: float) -> str:
        sent.append((frame.serial, published[-1].serial))
        return draw(frame, dt)

    view._draw = recording_draw  # type: ignore[method-assign]
    view.start()
    start = time.perf_counter()
    serial = 0
    while time.perf_counter() - start < 1.5:
        serial += 1
        published.append(frame(serial, 0, acting=False))
        view.changed()
        time.sleep(0.005)
    view.stop()
    assert 2 <= len(sent) <= 9 < serial, sent  # 1.5 s / 0.2 s + 1, not one per frame
    assert all(newest - drawn <= 3 for drawn, newest in sent), sent  # a few ms apart
    assert view.frame_rate <= 5.0 + 1e-9
