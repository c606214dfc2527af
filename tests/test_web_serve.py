"""``rsg run --out D`` then ``rsg replay D`` serves the page; bad folders and hosts are
refused on one line with exit code 2 (subprocesses, the command as a user runs it)."""

from __future__ import annotations

import signal
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import pytest

from conftest import free_port, output_lines

ROOT = Path(__file__).resolve().parents[1]


def rsg(*args: str, timeout: float = 120.0) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "app", *args],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=timeout,
    )


def http_status(url: str, timeout: float = 60.0) -> int:
    end = time.monotonic() + timeout
    while True:
        try:
            with urllib.request.urlopen(url, timeout=5) as response:
                return int(response.status)
        except OSError:
            if time.monotonic() > end:
                raise
            time.sleep(0.3)


@pytest.fixture(scope="module")
def run_folder(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("run")
    done = rsg("run", "--model", "lipm", "--scenario", "walk", "--duration", "2", "--no-plots",
               "--quiet", "--out", str(out))  # fmt: skip
    assert done.returncode in (0, 1), done.stderr
    assert f"wrote {out / 'replay.npz'} (rsg replay {out})" in done.stdout
    return out


@pytest.mark.parametrize("host", ["127.0.0.1", "0.0.0.0"])
def test_replay_of_a_run_answers_http_200_on_its_port(run_folder, host):
    port = free_port()
    server = subprocess.Popen(
        [sys.executable, "-m", "app", "replay", str(run_folder), "--port", str(port),
         "--host", host],
        cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
    )  # fmt: skip
    with output_lines(server) as lines:
        end = time.monotonic() + 60.0
        while not any("rsg replay: open" in line for line in lines) and time.monotonic() < end:
            time.sleep(0.1)
        assert http_status(f"http://127.0.0.1:{port}") == 200
        server.send_signal(signal.SIGINT)
        assert server.wait(30) == 0
    output = "".join(lines)
    assert f"rsg replay: open http://{host}:{port}" in output, output
    warned = "anyone who can reach port" in output
    assert warned == (host != "127.0.0.1"), output
    assert "viser" not in output and "localhost" not in output, output  # the URL bound, only


def rsg_in_process(capsys, *args: str) -> tuple[int, str]:
    """Exit code and stderr of ``rsg ARGS`` run in this process."""
    from app.cli import main

    code = main(list(args))
    return code, capsys.readouterr().err


def test_bad_replay_folders_are_refused_on_one_line(tmp_path, capsys):
    (tmp_path / "replay.npz").write_bytes(b"garbage")
    empty = tmp_path / "empty"
    empty.mkdir()
    for folder, reason in (
        (tmp_path / "missing", "no such folder"),
        (empty, "no replay.npz: not a run folder"),
        (tmp_path, "not a readable replay"),
    ):
        code, err = rsg_in_process(capsys, "replay", str(folder), "--port", str(free_port()))
        assert code == 2, (folder, err)
        assert err.count("\n") == 1 and err.startswith(f"rsg replay: error: {folder}"), err
        assert reason in err


@pytest.mark.parametrize("command", ["demo", "replay"])
def test_a_malformed_host_is_refused_with_a_clear_message(run_folder, command, capsys):
    extra = [str(run_folder)] if command == "replay" else ["--model", "lipm"]
    code, err = rsg_in_process(capsys, command, *extra, "--host", "bad host!", "--port", "8089")
    assert code == 2
    assert f"rsg {command}: error: --host 'bad host!': not an IP address" in err
    assert "in use" not in err


@pytest.mark.parametrize(
    "args,says",
    [(("--controller", "placo-wpg"), "--controller='placo-wpg' is not allowed: expected one"),
     (("--speed", "3"), "argument --speed: invalid choice: 3.0 (choose from 0.1, 0.25, 0.5, 1.0")],
)  # fmt: skip
def test_a_demo_it_cannot_serve_is_refused_saying_why(args, says):
    done = rsg("demo", "--model", "lipm", *args, "--port", str(free_port()))
    assert done.returncode == 2
    assert says in done.stderr and "Traceback" not in done.stderr, done.stderr
