"""The floating-point kernels the tests run on, pinned so that their runs repeat bit for
bit across CPUs: numpy and OpenBLAS pick kernels by CPU, and a push at the edge of what
the robot recovers goes either way with them (on an AVX-512 machine two slow G1 tests
lost their pushes unpinned). Set before numpy loads (``tests/conftest.py``) and in the
behaviour record's subprocesses (``tests/behaviour_cases.py``)."""

from __future__ import annotations

import os

ENVIRONMENT = {
    "OPENBLAS_CORETYPE": "Haswell",
    "OPENBLAS_NUM_THREADS": "1",
    "OMP_NUM_THREADS": "1",
    "NPY_DISABLE_CPU_FEATURES": "AVX512F AVX512CD AVX512_SKX AVX512_CLX AVX512_CNL "
    "AVX512_ICL AVX512_SPR",
}


def pin() -> None:
    """Set the kernels in this process's environment, unless already set."""
    for name, value in ENVIRONMENT.items():
        os.environ.setdefault(name, value)
