"""docs/paper.md names real code and real tests, and has a row for every equation.

The tables of docs/paper.md have the columns equation | what it is | file | function |
test. Every file must exist, every function (``name`` or ``Class.attribute``) must be
found in that file's module, every ``tests/...py::test_name`` must be defined, and every
equation number of the paper (and each lettered part) must have a row. The paper text is
not in the repository: that last check is skipped when it is absent.
"""

from __future__ import annotations

import importlib
import re
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "paper.md"
PAPER = Path("/work/shared/paper/000_ec8243f101bd98ce.txt")
HEADER = ["equation", "what it is", "file", "function", "test"]
NONE = "-"


@dataclass(frozen=True)
class Row:
    """One row of an equation table."""

    line: int
    equation: str
    file: str
    functions: tuple[str, ...]
    test: str


def _cells(line: str) -> list[str]:
    return [cell.strip() for cell in line.strip().strip("|").split("|")]


def _code(cell: str) -> list[str]:
    """The backticked names of a cell, or [] for "-"."""
    if cell == NONE:
        return []
    names = re.findall(r"`([^`]+)`", cell)
    if not names:
        raise ValueError(f"expected `names` or {NONE!r}, got {cell!r}")
    return names


def parse_tables(text: str) -> list[Row]:
    """The rows of every table of ``text`` whose header is :data:`HEADER`."""
    rows: list[Row] = []
    lines = text.splitlines()
    index = 0
    while index < len(lines):
        if lines[index].startswith("|") and _cells(lines[index]) == HEADER:
            index += 2  # the header and its |---| line
            while index < len(lines) and lines[index].startswith("|"):
                cells = _cells(lines[index])
                if len(cells) != len(HEADER):
                    raise ValueError(f"line {index + 1}: {len(cells)} cells: {lines[index]!r}")
                files = _code(cells[2])
                tests = _code(cells[4])
                if len(files) > 1 or len(tests) > 1:
                    raise ValueError(f"line {index + 1}: one file and one test per row")
                rows.append(
                    Row(
                        line=index + 1,
                        equation=cells[0],
                        file=files[0] if files else NONE,
                        functions=tuple(_code(cells[3])),
                        test=tests[0] if tests else NONE,
                    )
                )
                index += 1
        index += 1
    return rows


def _module_name(file: str) -> str:
    return file.removesuffix(".py").replace("/", ".")


def code_problems(rows: list[Row], root: Path = ROOT) -> list[str]:
    """Files that do not exist, names not found in their module."""
    problems = []
    for row in rows:
        if row.file == NONE:
            if row.functions:
                problems.append(f"line {row.line}: functions {row.functions} without a file")
            continue
        if not (root / row.file).is_file():
            problems.append(f"line {row.line}: no file {row.file}")
            continue
        if not row.functions:
            problems.append(f"line {row.line}: {row.file} without a function")
        module = importlib.import_module(_module_name(row.file))
        for name in row.functions:
            target: object = module
            for part in name.split("."):
                if not hasattr(target, part):
                    problems.append(f"line {row.line}: no {name} in {row.file}")
                    break
                target = getattr(target, part)
    return problems


def missing_tests(text: str, root: Path = ROOT) -> list[str]:
    """``tests/...py::name`` references of the whole page that do not exist."""
    problems = []
    for path, name in re.findall(r"`(tests/[\w/]+\.py)(?:::(\w+))?`", text):
        file = root / path
        if not file.is_file():
            problems.append(f"no test file {path}")
        elif name and not re.search(rf"^\s*def {re.escape(name)}\(", file.read_text(), re.M):
            problems.append(f"no test {name} in {path}")
    return problems


def paper_equations(text: str) -> tuple[int, set[str]]:
    """N, the largest equation number of the paper, and its lettered labels ("27b")."""
    labels = re.findall(r"\\tag\{(\d+)([a-z]?)\}|\((\d+)([a-z]?)\)", text)
    numbers: set[int] = set()
    lettered: set[str] = set()
    for tag_number, tag_letter, number, letter in labels:
        n, suffix = (tag_number, tag_letter) if tag_number else (number, letter)
        if int(n) == 0:  # xi*(0), an argument, not an equation
            continue
        numbers.add(int(n))
        if suffix:
            lettered.add(f"{int(n)}{suffix}")
    return max(numbers), lettered


def missing_equations(rows: list[Row], count: int, lettered: set[str]) -> list[str]:
    """Equation numbers 1..count and lettered labels without a row."""
    covered = set()
    for row in rows:
        covered.update(re.findall(r"\((\d+[a-z]?)\)", row.equation))
    numbers = {re.match(r"\d+", label).group() for label in covered}  # type: ignore[union-attr]
    missing = [f"({n})" for n in range(1, count + 1) if str(n) not in numbers]
    missing += [f"({label})" for label in sorted(lettered) if label not in covered]
    return missing


@pytest.fixture(scope="module")
def page() -> str:
    return PAGE.read_text()


@pytest.fixture(scope="module")
def rows(page: str) -> list[Row]:
    return parse_tables(page)


def test_the_page_has_equation_tables(rows: list[Row]) -> None:
    assert len(rows) > 30
    assert any(row.file != NONE for row in rows)


def test_every_named_file_and_function_exists(rows: list[Row]) -> None:
    assert code_problems(rows) == []


def test_every_named_test_exists(page: str) -> None:
    assert missing_tests(page) == []


def test_every_equation_of_the_paper_has_a_row(rows: list[Row]) -> None:
    if not PAPER.is_file():
        pytest.skip(f"the paper text is not here ({PAPER})")
    count, lettered = paper_equations(PAPER.read_text())
    assert count >= 27, "the paper's equations are not found: has its format changed?"
    assert missing_equations(rows, count, lettered) == []


def test_the_checks_catch_a_broken_page(page: str) -> None:
    """A renamed function, a missing file, a renamed test and a dropped row are caught."""
    broken = page.replace("`design_lyapunov`", "`design_lyapunov_renamed`")
    broken = broken.replace("`planner/qp.py`", "`planner/no_such_file.py`")
    broken = broken.replace(
        "::test_closed_loop_lyapunov_inequality`", "::test_no_such_test_anywhere`"
    )
    broken = "\n".join(line for line in broken.splitlines() if not line.startswith("| (23) |"))
    rows = parse_tables(broken)
    problems = code_problems(rows)
    assert any("design_lyapunov_renamed" in p for p in problems), problems
    assert any("planner/no_such_file.py" in p for p in problems), problems
    assert any("test_no_such_test_anywhere" in p for p in missing_tests(broken))
    assert "(23)" in missing_equations(rows, 27, set())
