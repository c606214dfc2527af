"""A long demo under load: hours of simulated walking with pushes, pauses and reconnects.

Starts ``rsg demo --quiet --speed S`` (this checkout) and drives its page in Debian's
headless Chromium as a user would: a push from the page's fields every
``--push-every`` seconds of wall time (direction uniform, impulse uniform in
``--impulse``), Pause and Resume now and then, the tab reloaded (a reconnect) and a
second tab opened and closed every ``--reconnect-every`` seconds. It runs until the
simulation has walked ``--hours`` without a Reset, then presses Reset once. It prints
and writes (``--out``) the simulated time, the robot's distance, the pushes applied
and refused, the falls, any traceback in the server's output, and the server's
memory at the start and the end. Exit code 1 if the server printed a traceback or
the robot fell.

    python benchmarks/soak_demo.py --hours 2 --speed 4 --out results/soak
"""

from __future__ import annotations

import argparse
import json
import random
import re
import socket
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
INPUT = "//label[normalize-space()='{}']/ancestor::div[1]/following-sibling::div//input"
STATUS_TIME = re.compile(r"t = (\d+\.\d+) s")


def rss_mib(pid: int) -> float:
    """Resident memory of process ``pid`` [MiB]."""
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024.0
    return float("nan")


def click(page, name: str) -> None:
    """A mouse click at the centre of the button ``name``, as a user clicks."""
    button = page.get_by_role("button", name=name, exact=True)
    button.evaluate("element => element.scrollIntoView({block: 'center'})")
    box = button.bounding_box()
    page.mouse.click(box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)


def sim_time(page) -> float:
    """The simulated time the page's status shows [s]."""
    text = page.get_by_text(STATUS_TIME).first.inner_text()
    match = STATUS_TIME.search(text)
    return float(match.group(1)) if match else float("nan")


def open_tab(context, url: str):
    page = context.new_page()
    page.set_default_timeout(300_000)
    page.goto(url)
    page.get_by_text(re.compile("running|paused")).first.wait_for(state="visible")
    return page


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--hours", type=float, default=2.0, help="simulated hours to walk")
    parser.add_argument("--speed", type=float, default=4.0, help="the demo's --speed")
    parser.add_argument("--impulse", default="4,7", help="push impulses [N s], low,high")
    parser.add_argument("--push-every", type=float, default=20.0, help="[s] of wall time")
    parser.add_argument("--reconnect-every", type=float, default=300.0, help="[s] of wall time")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--out", type=Path, default=Path("results/soak"))
    args = parser.parse_args()
    low, high = (float(v) for v in args.impulse.split(","))
    rng = random.Random(args.seed)
    from playwright.sync_api import sync_playwright

    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    command = [sys.executable, "-m", "app", "demo", "--quiet", "--speed", f"{args.speed:g}",
               "--port", str(port)]  # fmt: skip
    demo = subprocess.Popen(
        command, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, bufsize=1
    )
    lines: list[str] = []
    assert demo.stdout is not None
    stdout = demo.stdout
    threading.Thread(target=lambda: [lines.append(x.rstrip()) for x in stdout], daemon=True).start()
    while not any("open http" in line for line in lines):
        if demo.poll() is not None:
            print("\n".join(lines))
            return 1
        time.sleep(0.2)
    url = f"http://127.0.0.1:{port}"
    start = time.monotonic()
    memory = [rss_mib(demo.pid)]
    reconnects = pauses = pressed = 0
    times: list[float] = []
    try:
        with sync_playwright() as api, tempfile.TemporaryDirectory() as profile:
            context = api.chromium.launch_persistent_context(
                profile, executable_path="/usr/bin/chromium", headless=True, args=FLAGS,
                viewport={"width": 640, "height": 400},
            )  # fmt: skip
            page = open_tab(context, url)
            last_push = last_reconnect = time.monotonic()
            while True:
                page.wait_for_timeout(5000)
                now = time.monotonic()
                simulated = sim_time(page)
                times.append(simulated)
                if simulated >= 3600.0 * args.hours:
                    break
                if now - last_push >= args.push_every:
                    last_push = now
                    page.locator(f"xpath={INPUT.format('Direction [deg]')}").first.fill(
                        f"{rng.uniform(-180.0, 180.0):.1f}", force=True
                    )
                    page.locator(f"xpath={INPUT.format('Impulse [N s]')}").first.fill(
                        f"{rng.uniform(low, high):.2f}", force=True
                    )
                    page.wait_for_timeout(500)
                    click(page, "Push")
                    pressed += 1
                    if rng.random() < 0.1:  # pause a moment, then resume
                        page.wait_for_timeout(3000)
                        click(page, "Pause")
                        page.wait_for_timeout(3000)
                        click(page, "Resume")
                        pauses += 1
                if now - last_reconnect >= args.reconnect_every:
                    last_reconnect = now
                    page.reload()
                    page.get_by_text(re.compile("running|paused")).first.wait_for(state="visible")
                    other = open_tab(context, url)
                    other.wait_for_timeout(5000)
                    other.close()
                    reconnects += 1
                    memory.append(rss_mib(demo.pid))
                    print(
                        f"{(now - start) / 60:.0f} min: t = {simulated:.0f} s, "
                        f"RSS {memory[-1]:.0f} MiB",
                        flush=True,
                    )
            distance_line = [x for x in lines if x.startswith("push t=")]
            click(page, "Reset")
            page.wait_for_timeout(5000)
            context.close()
    finally:
        demo.send_signal(2)
        demo.wait(30)
    wall = time.monotonic() - start
    summary = {
        "command": " ".join(command[2:]),
        "simulated_s": max(times) if times else 0.0,
        "wall_s": wall,
        "pushes_pressed": pressed,
        "pushes_applied": sum(x.startswith("push t=") for x in lines),
        "pushes_refused": sum(x.startswith("push refused") for x in lines),
        "falls": [x for x in lines if x.startswith("fall")],
        "tracebacks": sum("Traceback" in x for x in lines),
        "errors": [x for x in lines if x.startswith("error")],
        "reconnects": reconnects,
        "pauses": pauses,
        "resets": sum(x.startswith("reset") for x in lines),
        "rss_mib_start_end": [memory[0], rss_mib(demo.pid) if demo.poll() is None else memory[-1]],
        "last_push": distance_line[-1] if distance_line else "",
        "exit_code": demo.returncode,
    }
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "soak.json").write_text(json.dumps(summary, indent=2))
    (args.out / "demo.log").write_text("\n".join(lines) + "\n")
    print(json.dumps(summary, indent=2))
    return 1 if summary["tracebacks"] or summary["falls"] or summary["errors"] else 0


if __name__ == "__main__":
    raise SystemExit(main())
