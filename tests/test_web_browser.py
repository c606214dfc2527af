"""The browser pages in real headless Chromium (``pytest -m browser -o addopts=""``).

Needs Debian's ``chromium`` (/usr/bin/chromium) and the Python ``playwright`` package;
the tests are skipped without them. Software WebGL draws the G1 at about one frame
per second, so the waits are generous. Buttons are clicked with the mouse where they
are, as a user clicks (Playwright's ``locator.click`` first waits for two still
animation frames, many seconds here).

The pictures of the README are taken here: docs/demo_screenshot.png (LIPM page),
docs/demo_screenshot_g1.png (G1 page) and docs/replay_screenshot_g1.png (replay).
"""

from __future__ import annotations

import io
import re
import shutil
import socket
import subprocess
import sys
import tempfile
import threading
import time
import urllib.request
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

pytestmark = pytest.mark.browser

ROOT = Path(__file__).resolve().parents[1]
CHROMIUM = "/usr/bin/chromium"
SCREENSHOT = ROOT / "docs" / "demo_screenshot.png"
ROBOT_SCREENSHOT = ROOT / "docs" / "demo_screenshot_g1.png"
REPLAY_SCREENSHOT = ROOT / "docs" / "replay_screenshot_g1.png"
CHROMIUM_FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]
PUSH_LINE = re.compile(r"^push t=(\d+\.\d+) s impulse=\((-?\d+\.\d+), (-?\d+\.\d+)\) N s duration=")
ADJUSTED_LINE = re.compile(r"^step t=(\d+\.\d+) s foot=(left|right) .* adjusted=yes")
STEP_LINE = re.compile(r"^step t=")
PUSH_DELAYS = (0.0, 0.27, 0.54, 0.13)  # [s] after a touchdown, spread over the 0.8 s step
GROUND_TOLERANCE = 4  # [px] ~1.5 cm at the side view's distance
PANEL_LEFT = 860  # [px] the GUI panel covers the canvas right of this (1280 px wide)
# (field, text typed, what the refusal starts with) for the LIPM's 60 kg: each refused.
BAD_PUSHES = (
    ("Impulse [N s]", "", "impulse is empty"),
    ("Impulse [N s]", "NaN", "impulse 'NaN' is not a number"),
    ("Impulse [N s]", "abc", "impulse 'abc' is not a number"),
    ("Impulse [N s]", "1e9", "impulse 1e9 N s is out of range: allowed more than 0 to 30 N s"),
    ("Impulse [N s]", "0", "impulse 0 N s is out of range"),
    ("Direction [deg]", "1e9", "direction 1e9 deg is out of range: allowed from -360 to 360"),
    ("Direction [deg]", "720.5", "direction 720.5 deg is out of range"),
    ("Direction [deg]", "", "direction is empty"),
    ("Duration [s]", "5", "duration 5 s is out of range: allowed from 0.05 to 0.5 s"),
)


class ServerProcess:
    """``rsg ARGS --port P`` in a subprocess; its stdout lines are collected."""

    def __init__(self, *args: str) -> None:
        with socket.socket() as probe:
            probe.bind(("127.0.0.1", 0))
            self.port = probe.getsockname()[1]
        self.url = f"http://127.0.0.1:{self.port}"
        self.lines: list[str] = []
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "app", *args, "--port", str(self.port)],
            cwd=ROOT,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            bufsize=1,
        )
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self) -> None:
        assert self.proc.stdout is not None
        for line in self.proc.stdout:
            self.lines.append(line.rstrip("\n"))

    def wait_for_line(self, pattern: re.Pattern[str] | str, timeout: float, start: int = 0):
        """The first collected line (from index ``start``) matching ``pattern``."""
        regex = re.compile(pattern) if isinstance(pattern, str) else pattern
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            for index, line in enumerate(self.lines[start:], start):
                match = regex.search(line)
                if match:
                    return index, match
            if self.proc.poll() is not None:
                break
            time.sleep(0.1)
        raise AssertionError(f"no line matching {regex.pattern!r}; output:\n" + self.output())

    def output(self) -> str:
        return "\n".join(self.lines[-60:])

    def stop(self) -> int:
        if self.proc.poll() is None:
            self.proc.send_signal(subprocess.signal.SIGINT)  # type: ignore[attr-defined]
            try:
                self.proc.wait(30)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(10)
        self._reader.join(5)
        return self.proc.returncode


@pytest.fixture(scope="module")
def playwright_api():
    sync_api = pytest.importorskip("playwright.sync_api")
    if not Path(CHROMIUM).exists() and shutil.which("chromium") is None:
        pytest.skip("Debian's chromium is not installed (apt-get install chromium)")
    with sync_api.sync_playwright() as api:
        yield api


@pytest.fixture
def serve() -> Iterator:
    servers: list[ServerProcess] = []

    def start(*args: str) -> ServerProcess:
        server = ServerProcess(*args)
        servers.append(server)
        server.wait_for_line("open http://", timeout=180)
        return server

    yield start
    for server in servers:
        assert server.stop() == 0, server.output()


def open_page(api, url: str, profile: str):
    context = api.chromium.launch_persistent_context(
        profile,
        executable_path=CHROMIUM,
        headless=True,
        args=CHROMIUM_FLAGS,
        viewport={"width": 1280, "height": 800},
    )
    page = context.new_page()
    page.set_default_timeout(120_000)
    page.goto(url, timeout=120_000)
    page.locator("canvas").first.wait_for(state="visible", timeout=120_000)
    return context, page


def click(page, locator) -> None:
    """A mouse click at the centre of ``locator`` (scrolled into view first)."""
    locator.evaluate("element => element.scrollIntoView({block: 'center'})")
    box = locator.bounding_box()
    assert box is not None
    page.mouse.click(box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)


def button(page, name: str):
    return page.get_by_role("button", name=name, exact=True)


def _input_xpath(label: str) -> str:
    return (
        f"//label[normalize-space()='{label}']/ancestor::div[1]/following-sibling::div"
        "//input[not(@type='hidden')]"
    )


def field(page, label: str):
    """The input of the GUI field labelled ``label``."""
    return page.locator(f"xpath={_input_xpath(label)}").first


def wait_for_value(page, label: str, value: str, timeout_ms: int = 30_000) -> None:
    """Wait until the field labelled ``label`` shows ``value``."""
    script = (
        f'() => document.evaluate("{_input_xpath(label)}", document, null, 9, null)'
        f".singleNodeValue.value === {value!r}"
    )
    page.wait_for_function(script, timeout=timeout_ms)


def canvas_pixels(page) -> np.ndarray:
    import matplotlib.image as mpimg

    png = page.locator("canvas").first.screenshot(timeout=120_000)
    return mpimg.imread(io.BytesIO(png), format="png")[..., :3] * 255.0


def dismiss_notifications(page) -> None:
    """Close viser's notifications (e.g. "software WebGL") so they do not hide the view."""
    for close in page.locator(".mantine-Notification-closeButton").all():
        try:
            click(page, close)
        except Exception:  # noqa: BLE001 - purely cosmetic
            pass


def wait_for_status(page, text: str, timeout_ms: int = 120_000) -> None:
    page.get_by_text(re.compile(text)).first.wait_for(state="visible", timeout=timeout_ms)


def project(point: np.ndarray, width: int, height: int) -> tuple[float, float]:
    """(column, row) [px] of ``point`` [m] (relative to the stance ankle) in the side view."""
    from web.page import SIDE_VIEW_DISTANCE, SIDE_VIEW_FOV, SIDE_VIEW_HEIGHT, SIDE_VIEW_LOOK_HEIGHT

    camera = np.array([0.0, -SIDE_VIEW_DISTANCE, SIDE_VIEW_HEIGHT])
    forward = np.array([0.0, 0.0, SIDE_VIEW_LOOK_HEIGHT]) - camera
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    focal = (height / 2.0) / np.tan(SIDE_VIEW_FOV / 2.0)
    v = np.asarray(point, float) - camera
    depth = v @ forward
    return width / 2.0 + focal * (v @ right) / depth, height / 2.0 - focal * (v @ up) / depth


def check_robot_on_its_feet(page) -> float:
    """From the side view (the page must be paused): the lowest pixel of the robot, in
    the columns of the stance sole, is on the ground line under that sole, and no
    pixel of the robot is below the ground. Returns the ground's row [px]."""
    from robots import get_robot

    sole = get_robot("g1").sole
    click(page, button(page, "Side view"))
    page.wait_for_timeout(10_000)  # the camera moves, a frame or two render
    dismiss_notifications(page)
    shown = canvas_pixels(page)
    checkbox = field(page, "Robot")
    click(page, checkbox)
    page.wait_for_timeout(8_000)
    hidden = canvas_pixels(page)
    click(page, checkbox)
    robot = np.abs(shown - hidden).max(axis=2) > 40.0  # pixels the robot covers
    height, width = robot.shape
    robot[:, PANEL_LEFT:] = False  # the panel lies over the canvas there (its checkbox)
    assert robot.sum() > 2000, "the robot is not drawn"
    corners = [
        project(np.array([x, y, 0.0]), width, height)
        for x in (sole.x_min, sole.x_max)
        for y in (-sole.half_width, sole.half_width)
    ]
    columns = [c for c, _ in corners]
    ground = [r for _, r in corners]  # rows of the ground under the sole
    band = robot[:, int(np.floor(min(columns))) : int(np.ceil(max(columns))) + 1]
    rows = np.nonzero(band.any(axis=1))[0]
    assert len(rows), "no robot pixel above the stance sole"
    lowest = rows.max()
    message = f"lowest robot row {lowest} px, ground under the sole {min(ground):.1f}-"
    message += f"{max(ground):.1f} px"
    assert min(ground) - GROUND_TOLERANCE <= lowest <= max(ground) + GROUND_TOLERANCE, message
    below = np.nonzero(robot.any(axis=1))[0].max()
    assert below <= max(ground) + GROUND_TOLERANCE, f"robot drawn below the ground: row {below}"
    return max(ground)


# Robot mass [kg] per model: the page's presets are the paper's impulses x mass / 60 kg.
MODEL_MASS = {"pybullet": 33.341, "lipm": 60.0}


def push_until_adjusted(page, demo: ServerProcess, model: str) -> None:
    """Press Push (the paper's first push) until a push is followed by an adjusted step.

    Whether a push needs one depends on the gait phase it hits (on the LIPM a push
    0.35-0.55 s into a 0.8 s step is absorbed by the ZMP alone), so each attempt waits for
    a touchdown and presses Push a different delay after it: a 0.25 s window of phases
    holds at most two of the four delays."""
    for delay in PUSH_DELAYS:
        demo.wait_for_line(STEP_LINE, timeout=60, start=len(demo.lines))
        page.wait_for_timeout(delay * 1000.0)
        before = len(demo.lines)
        click(page, button(page, "Push"))
        index, push = demo.wait_for_line(PUSH_LINE, timeout=60, start=before)
        assert "source=page" in demo.lines[index]
        impulse = np.array([float(push.group(2)), float(push.group(3))])
        expected = np.array([8.0, -6.0]) * MODEL_MASS[model] / 60.0  # the first preset
        np.testing.assert_allclose(impulse, expected, atol=0.06)
        push_time = float(push.group(1))
        try:
            _, found = demo.wait_for_line(ADJUSTED_LINE, timeout=15, start=index)
        except AssertionError:
            continue
        if push_time <= float(found.group(1)) <= push_time + 2.0:
            return
    raise AssertionError("no adjusted step after a push:\n" + demo.output())


def test_lipm_page_push_fields_aim_pause_and_reset(playwright_api, serve):
    demo = serve("demo", "--model", "lipm")
    with tempfile.TemporaryDirectory() as profile:
        context, page = open_page(playwright_api, demo.url, profile)
        try:
            wait_for_status(page, r"t = \d+\.\d+ s")
            wait_for_status(page, "running")
            page.wait_for_timeout(3000)
            # Fields: Push reads what they hold at that moment; a bad value is refused
            # at once, on the page and in the log, the field left as typed, nothing pushed.
            start = len(demo.lines)
            for label, bad, says in BAD_PUSHES:
                box = field(page, label)
                good = box.input_value()
                box.fill(bad)
                before = len(demo.lines)
                click(page, button(page, "Push"))
                index, _ = demo.wait_for_line(r"^push refused: ", timeout=30, start=before)
                assert demo.lines[index].startswith(f"push refused: {says}"), demo.lines[index]
                wait_for_status(page, "push refused: " + re.escape(says), timeout_ms=30_000)
                assert box.input_value() == bad  # never rewritten by the page
                box.fill(good)
            assert not any(line.startswith("push t=") for line in demo.lines[start:])
            # Typed key by key on a slow page: the field is not rewritten while typing,
            # and the push is the value typed, exactly.
            impulse = field(page, "Impulse [N s]")
            impulse.fill("")
            impulse.press_sequentially("5.557", delay=700)
            page.wait_for_timeout(3000)
            assert impulse.input_value() == "5.557"
            before = len(demo.lines)
            click(page, button(page, "Push"))
            _, push = demo.wait_for_line(PUSH_LINE, timeout=30, start=before)
            assert np.hypot(float(push.group(2)), float(push.group(3))) == pytest.approx(
                5.557, abs=0.01
            )
            wait_for_status(page, "pushed 5.557 N s")
            page.wait_for_timeout(4000)  # the LIPM recovers before the paper's push
            # The paper's first push, typed in: applied, followed by an adjusted step.
            direction = field(page, "Direction [deg]")
            direction.fill("-36.87")
            impulse.fill("10")
            page.wait_for_timeout(3000)
            push_until_adjusted(page, demo, "lipm")
            click(page, button(page, "Pause"))
            wait_for_status(page, "paused")
            wait_for_status(page, r"pushes [1-4] ")
            dismiss_notifications(page)
            page.wait_for_timeout(4000)  # a few frames with the adjusted (red) step
            pixels = canvas_pixels(page)
            assert pixels.mean(axis=2).var() > 100.0, "the 3-D view looks blank"
            page.screenshot(path=str(SCREENSHOT))
            # A click on the ground aims the push from the robot towards the point.
            box = page.locator("canvas").first.bounding_box()
            assert box is not None
            before = len(demo.lines)
            page.mouse.click(box["x"] + 0.25 * box["width"], box["y"] + 0.8 * box["height"])
            demo.wait_for_line(r"^aim direction=-?\d+ deg", timeout=60, start=before)
            before = len(demo.lines)
            click(page, button(page, "Reset"))
            demo.wait_for_line(r"^reset", timeout=60, start=before)
            wait_for_status(page, "pushes 0")
        finally:
            context.close()


def test_g1_page_robot_on_its_feet_and_a_push(playwright_api, serve):
    demo = serve("demo")
    with tempfile.TemporaryDirectory() as profile:
        context, page = open_page(playwright_api, demo.url, profile)
        try:
            wait_for_status(page, "pybullet g1")
            wait_for_status(page, "running")
            page.wait_for_timeout(30_000)  # the meshes load and render at ~1 frame/s
            # The walk started with the server: restart it so the push meets a walking robot.
            before = len(demo.lines)
            click(page, button(page, "Reset"))
            demo.wait_for_line(r"^reset", timeout=120, start=before)
            page.wait_for_timeout(3000)
            push_until_adjusted(page, demo, "pybullet")
            click(page, button(page, "Reset"))
            wait_for_status(page, r"t = [3-9]\.\d+ s")
            dismiss_notifications(page)
            page.wait_for_timeout(4000)
            pixels = canvas_pixels(page)
            assert pixels.var() > 100.0, "the 3-D view looks blank"
            page.screenshot(path=str(ROBOT_SCREENSHOT))
            click(page, button(page, "Pause"))
            wait_for_status(page, "paused")
            check_robot_on_its_feet(page)
        finally:
            context.close()


def test_replay_page_of_a_g1_run_scrubs_and_plays(playwright_api, serve, tmp_path):
    run = subprocess.run(
        [sys.executable, "-m", "app", "run", "--scenario", "paper-fig6", "--duration", "6",
         "--no-plots", "--quiet", "--out", str(tmp_path)],
        cwd=ROOT, capture_output=True, text=True, timeout=600,
    )  # fmt: skip
    assert run.returncode in (0, 1), run.stderr
    replay = serve("replay", str(tmp_path))
    with urllib.request.urlopen(replay.url, timeout=30) as response:
        assert response.status == 200
    with tempfile.TemporaryDirectory() as profile:
        context, page = open_page(playwright_api, replay.url, profile)
        try:
            wait_for_status(page, r"t = 0\.00 s")
            page.wait_for_timeout(30_000)  # the meshes load
            time_field = field(page, "Time [s]")
            time_field.fill("3.85")  # the paper's first push acts (3.8 s to 3.9 s)
            time_field.press("Enter")
            wait_for_status(page, r"t = 3\.85 s")
            wait_for_status(page, r"pushes 1 of 1")  # the second push comes after 6 s
            dismiss_notifications(page)
            page.wait_for_timeout(6000)
            page.screenshot(path=str(REPLAY_SCREENSHOT))
            shown = canvas_pixels(page)[:, :PANEL_LEFT]
            red = (shown[..., 0] > 150) & (shown[..., 1] < 110) & (shown[..., 2] < 110)
            assert red.sum() > 100, "no push arrow while the push acts"  # shaded red
            click(page, button(page, "Play"))
            wait_for_status(page, "playing")
            # It plays to the end of the run (5.99 s) and stops there.
            wait_for_status(page, r"t = 5\.99 s of 5\.99 · paused", timeout_ms=60_000)
            time_field.fill("4.35")  # mid-swing after the push
            time_field.press("Enter")
            wait_for_status(page, r"t = 4\.35 s")
            ground = check_robot_on_its_feet(page)
            # No push arrow once the push is over (the side view sees the arrow at the
            # CoM's height, above the footholds, which may be red: adjusted steps).
            later = canvas_pixels(page)[: int(ground) - 20, :PANEL_LEFT]
            red = (later[..., 0] > 150) & (later[..., 1] < 110) & (later[..., 2] < 110)
            assert red.sum() < 20, "a push arrow after the push"
        finally:
            context.close()
