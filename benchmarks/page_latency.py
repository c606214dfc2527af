"""Click-to-screen latency of the demo page in headless Chromium (software WebGL).

Starts ``rsg demo`` (this checkout), opens the page in Debian's Chromium and clicks
Push several times, as a user does (a mouse click at the button). A probe injected
into the page records the end of every animation frame in which the page applied a
scene frame; each scene frame carries a token with the number of pushes it shows
(``web.client_view``), so the first frame that shows a push is known. Click-to-screen
is the time from the mouse click (sent to the browser) to the end of that frame, on
this machine's clock. Also reported: the tab's drawn frame rate, the input delay (the
click to the page's ``pointerdown``: a page busy drawing handles input between
frames) and the time from the click to the simulation's ``push t=`` line
(click-to-applied).

Two renderers, both software (this machine has no GPU): ``slow`` is a 1280 x 800
window, ``fast`` a 480 x 300 one (a fifth of the pixels to shade). Needs
/usr/bin/chromium and the ``playwright`` package.

    python benchmarks/page_latency.py --model pybullet --renderer slow --pushes 5
"""

from __future__ import annotations

import argparse
import json
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
VIEWPORTS = {"slow": (1280, 800), "fast": (480, 300)}
TIMEOUT = 60.0  # [s] a push not on screen by then counts as this

# Records frame tokens (key -> request uuid) arriving from viser's websocket worker,
# the answers the page sends back while it applies a frame, and the end of that
# animation frame; and every click.
PROBE = """
(() => {
  const keys = {}; window.__rsgFrames = []; window.__rsgClicks = [];
  let applied = null;
  const Original = window.Worker;
  window.Worker = class extends Original {
    constructor(...args) {
      super(...args);
      const post = this.postMessage.bind(this);
      this.postMessage = (data, transfer) => {
        const m = data && data.message;
        if (data && data.type === "send" && m && m.type === "LocalStorageGetItemResponseMessage")
          applied = keys[m.request_uuid];
        return transfer === undefined ? post(data) : post(data, transfer);
      };
      const setter = Object.getOwnPropertyDescriptor(Original.prototype, "onmessage").set;
      Object.defineProperty(this, "onmessage", { set(handler) {
        setter.call(this, (event) => {
          const d = event.data;
          if (d && d.type === "message_batch")
            for (const m of d.messages)
              if (m.type === "LocalStorageGetItemRequestMessage") keys[m.request_uuid] = m.key;
          handler(event);
        });
      } });
    }
  };
  const raf = window.requestAnimationFrame.bind(window);
  window.requestAnimationFrame = (callback) => raf((stamp) => {
    callback(stamp);
    if (applied !== null) {
      window.__rsgFrames.push([applied, performance.timeOrigin + performance.now()]);
      applied = null;
    }
  });
  window.addEventListener("pointerdown",
    () => window.__rsgClicks.push(performance.timeOrigin + performance.now()), true);
})();
"""


def pushes_of(key: str | None) -> int:
    """The push count a frame token's key carries (rsg-frame:<serial>:<pushes>)."""
    if not key or not key.startswith("rsg-frame:"):
        return -1
    return int(key.rsplit(":", 1)[1])


def measure(model: str, renderer: str, pushes: int, settle: float) -> dict:
    from playwright.sync_api import sync_playwright

    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    command = [sys.executable, "-m", "app", "demo", "--quiet", "--model", model, "--port",
               str(port)]  # fmt: skip
    demo = subprocess.Popen(command, cwd=ROOT, stdout=subprocess.PIPE, text=True, bufsize=1)
    lines: list[tuple[float, str]] = []
    assert demo.stdout is not None
    stdout = demo.stdout
    threading.Thread(
        target=lambda: [lines.append((time.perf_counter(), line)) for line in stdout], daemon=True
    ).start()
    screen, applied, rates, delays = [], [], [], []
    try:
        while not any("open http" in line for _, line in lines):
            time.sleep(0.2)
        width, height = VIEWPORTS[renderer]
        with sync_playwright() as api, tempfile.TemporaryDirectory() as profile:
            context = api.chromium.launch_persistent_context(
                profile, executable_path="/usr/bin/chromium", headless=True, args=FLAGS,
                viewport={"width": width, "height": height},
            )  # fmt: skip
            context.add_init_script(PROBE)
            page = context.new_page()
            page.set_default_timeout(300_000)
            page.goto(f"http://127.0.0.1:{port}")
            page.get_by_text(re.compile("running")).first.wait_for(state="visible")
            page.wait_for_timeout(settle * 1000)  # meshes load, the page settles
            button = page.get_by_role("button", name="Push", exact=True)
            for number in range(1, pushes + 1):
                button.scroll_into_view_if_needed()
                box = button.bounding_box()
                before = len(lines)
                clicked, clicked_epoch = time.perf_counter(), 1000.0 * time.time()
                page.mouse.click(box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)
                while time.perf_counter() - clicked < TIMEOUT:
                    frames = page.evaluate("window.__rsgFrames")
                    if any(pushes_of(key) >= number for key, _ in frames):
                        break
                    time.sleep(0.05)
                delays.append((page.evaluate("window.__rsgClicks")[-1] - clicked_epoch) / 1000.0)
                frames = page.evaluate("window.__rsgFrames")
                shown = [t for key, t in frames if pushes_of(key) >= number and t >= clicked_epoch]
                screen.append((min(shown) - clicked_epoch) / 1000.0 if shown else TIMEOUT)
                found = [t for t, line in lines[before:] if line.startswith("push t=")]
                applied.append(found[0] - clicked if found else TIMEOUT)
                recent = [t for _, t in frames if t >= frames[-1][1] - 5000.0]
                if len(recent) >= 2:
                    rates.append((len(recent) - 1) / ((recent[-1] - recent[0]) / 1000.0))
                page.wait_for_timeout(6000)  # the robot recovers before the next push
            context.close()
    finally:
        demo.send_signal(2)
        demo.wait(30)
    return {
        "model": model,
        "renderer": renderer,
        "viewport": list(VIEWPORTS[renderer]),
        "frames_per_s": statistics.median(rates) if rates else 0.0,
        "click_to_screen_s": screen,
        "input_delay_s": delays,
        "click_to_applied_s": applied,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", choices=("lipm", "pybullet", "mujoco"), default="pybullet")
    parser.add_argument("--renderer", choices=tuple(VIEWPORTS), default="slow")
    parser.add_argument("--pushes", type=int, default=5)
    parser.add_argument("--settle", type=float, default=40.0, help="wait after load [s]")
    parser.add_argument("--out", type=Path, default=None, help="also write the figures here")
    args = parser.parse_args()
    result = measure(args.model, args.renderer, args.pushes, args.settle)
    screen, applied = result["click_to_screen_s"], result["click_to_applied_s"]
    print(
        f"{args.model}, {args.renderer} renderer {result['viewport'][0]}x"
        f"{result['viewport'][1]}, tab draws {result['frames_per_s']:.1f} frames/s: "
        f"click-to-screen median {statistics.median(screen):.2f} s, max {max(screen):.2f} s; "
        f"input delay median {statistics.median(result['input_delay_s']):.2f} s; "
        f"click-to-applied median {statistics.median(applied):.2f} s over {len(screen)} pushes "
        f"({', '.join(f'{v:.2f}' for v in screen)})"
    )
    if args.out is not None:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text(json.dumps(result, indent=2))


if __name__ == "__main__":
    main()
