"""Every command in the README runs as written: each ``rsg`` line parses with the real
command line, and the short ones run to the end in a scratch folder."""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from app.cli import build_parser

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"

#: Commands of the README that finish in seconds: they are run, not only parsed.
SHORT = (
    "rsg run --model lipm --scenario paper-fig6 --out results/fig6",
    "rsg run --model lipm --push 3.8:8,-6:0.1 --out results/one",
    "python examples/fig6_lipm.py",
)


def readme_commands(text: str) -> list[str]:
    """The commands of the README: lines of its ``bash`` blocks (comments and ``&&``
    chains split) and inline code that starts with ``rsg `` or ``python ``, except the
    bare verbs the commands table lists (``rsg run``, ``rsg replay DIR``)."""
    commands: list[str] = []
    for block in re.findall(r"```bash\n(.*?)```", text, re.S):
        for line in block.splitlines():
            line = line.split(" #")[0].strip()
            commands += [part.strip() for part in line.split("&&") if part.strip()]
    for code in re.findall(r"(?<!`)`([^`\n]+)`(?!`)", text):
        verb_only = re.fullmatch(r"rsg [a-z]+( DIR)?", code)
        if code.startswith(("rsg ", "python ")) and not verb_only:
            commands.append(code)
    return commands


def test_the_readme_lists_its_short_commands_and_the_two_set_up_commands():
    commands = readme_commands(README.read_text())
    for command in SHORT:
        assert command in commands
    assert 'pip install -e ".[test]"' in commands
    assert "rsg demo" in commands and "python -m pytest" in commands


@pytest.mark.parametrize(
    "command", [c for c in readme_commands(README.read_text()) if c.startswith("rsg ")]
)
def test_every_rsg_command_of_the_readme_parses(command, capsys):
    words = shlex.split(command)[1:]
    try:
        build_parser().parse_args(words)
    except SystemExit as exc:  # --help exits with 0
        if exc.code != 0:
            pytest.fail(f"{command!r} does not parse: {capsys.readouterr().err.strip()}")


@pytest.mark.parametrize("command", SHORT)
def test_the_short_readme_commands_run_as_written(command, tmp_path):
    words = shlex.split(command)
    if words[0] == "rsg":
        words = [sys.executable, "-m", "app", *words[1:]]
    elif words[0] == "python":
        words = [sys.executable, str(ROOT / words[1]), *words[2:]]
    env = {**os.environ, "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg"}
    done = subprocess.run(words, cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    if "--out" in words:
        out = tmp_path / words[words.index("--out") + 1]
        assert (out / "summary.json").is_file() and (out / "timeseries.csv").is_file()
