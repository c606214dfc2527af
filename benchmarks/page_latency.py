"""Click-to-applied latency of the demo page in headless Chromium without GPU.

Starts ``rsg demo`` (this checkout), opens the page in Debian's Chromium with software
WebGL, waits for the robot to render, then clicks Push several times, as a user does
(a mouse click at the button, not Playwright's ``locator.click``, which first waits for
the button to be still over two animation frames, several seconds here), and measures
the wall time from the click to the simulation's ``push t=`` line. Also measures the
page's animation-frame rate (software WebGL draws the G1 at about one frame per
second). Prints one line. Needs /usr/bin/chromium and the ``playwright`` package.

    python benchmarks/page_latency.py --model pybullet --frame-rate 40 --pushes 5
"""

from __future__ import annotations

import argparse
import re
import socket
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update",
         "--disable-sync"]  # fmt: skip
APPLIED = ("push ",)  # the simulation's line for a push request (applied, refused, ignored)
TIMEOUT = 180.0  # [s] a click not answered by then counts as this


FRAME_RATE_JS = """() => new Promise(done => {
  let frames = 0; const start = performance.now();
  function frame() {
    frames++;
    if (performance.now() - start < 5000) requestAnimationFrame(frame);
    else done(frames / ((performance.now() - start) / 1000));
  }
  requestAnimationFrame(frame);
})"""


def wait_for_line(
    page, locator, lines: list[tuple[float, str]], prefixes: tuple[str, ...]
) -> float:
    """Seconds from a mouse click at the centre of ``locator``, as a user clicks, to the
    first new line starting with one of ``prefixes``. (Where the button is, is read
    before: reading it waits for the page's busy main thread too.)"""
    box = locator.bounding_box()
    before = len(lines)
    clicked = time.perf_counter()
    page.mouse.click(box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)
    while time.perf_counter() - clicked < TIMEOUT:
        found = next((t for t, line in lines[before:] if line.startswith(prefixes)), None)
        if found is not None:
            return found - clicked
        time.sleep(0.01)
    return TIMEOUT


def measure(
    model: str, frame_rate: float | None, pushes: int, settle: float
) -> tuple[list[float], float]:
    from playwright.sync_api import sync_playwright

    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    command = [sys.executable, "-m", "app", "demo", "--model", model, "--port", str(port)]
    if frame_rate is not None:
        command += ["--frame-rate", str(frame_rate)]
    demo = subprocess.Popen(command, cwd=ROOT, stdout=subprocess.PIPE, text=True, bufsize=1)
    lines: list[tuple[float, str]] = []
    assert demo.stdout is not None
    stdout = demo.stdout
    threading.Thread(
        target=lambda: [lines.append((time.perf_counter(), line)) for line in stdout], daemon=True
    ).start()
    latencies = []
    try:
        while not any("open http" in line for _, line in lines):
            time.sleep(0.2)
        with sync_playwright() as api, tempfile.TemporaryDirectory() as profile:
            context = api.chromium.launch_persistent_context(
                profile, executable_path="/usr/bin/chromium", headless=True, args=FLAGS,
                viewport={"width": 1280, "height": 800},
            )  # fmt: skip
            page = context.new_page()
            page.set_default_timeout(300_000)
            page.goto(f"http://127.0.0.1:{port}")
            page.get_by_text(re.compile("running")).first.wait_for(state="visible")
            page.wait_for_timeout(settle * 1000)  # meshes load, the page settles
            button = page.get_by_role("button", name="Push", exact=True)
            reset = page.get_by_role("button", name="Reset", exact=True)
            frame_rate = page.evaluate(FRAME_RATE_JS)
            for _ in range(pushes):
                wait_for_line(page, reset, lines, ("reset",))  # a walking robot to push
                page.wait_for_timeout(5000)
                latencies.append(wait_for_line(page, button, lines, APPLIED))
                page.wait_for_timeout(3000)
            context.close()
    finally:
        demo.send_signal(2)
        demo.wait(30)
    return latencies, frame_rate


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", choices=("lipm", "pybullet"), default="pybullet")
    parser.add_argument("--frame-rate", type=float, default=None, help="default: the demo's")
    parser.add_argument("--pushes", type=int, default=5)
    parser.add_argument("--settle", type=float, default=40.0, help="wait after load [s]")
    args = parser.parse_args()
    latencies, browser_rate = measure(args.model, args.frame_rate, args.pushes, args.settle)
    shown = "default" if args.frame_rate is None else f"{args.frame_rate:g} Hz"
    print(
        f"{args.model} page rate {shown}, browser {browser_rate:.2f} frames/s: click-to-applied "
        f"median "
        f"{statistics.median(latencies):.2f} s, max {max(latencies):.2f} s over {len(latencies)} "
        f"pushes ({', '.join(f'{v:.2f}' for v in latencies)})"
    )


if __name__ == "__main__":
    main()
