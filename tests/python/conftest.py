"""Shared set-up of the Python module's tests: the module, the CLI beside it, the checkout.

ctest (tests/CMakeLists.txt) runs them with PYTHONPATH at the module's build folder and
SKYBAKE_BINARY at the CLI; by hand:
    PYTHONPATH=build/python SKYBAKE_BINARY=build/skybake /usr/bin/python3 -m pytest -q tests/python
"""
import os
import pathlib
import subprocess

import pytest

SOURCE_DIR = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def source_dir():
    return SOURCE_DIR


@pytest.fixture(scope="session")
def cli():
    binary = os.environ.get("SKYBAKE_BINARY", str(SOURCE_DIR / "build" / "skybake"))
    if not os.access(binary, os.X_OK):
        pytest.fail(f"the skybake CLI is not at {binary}: build it, or set SKYBAKE_BINARY")

    def run(*args, cwd=SOURCE_DIR):
        return subprocess.run([binary, *map(str, args)], cwd=cwd, capture_output=True, text=True)

    return run


@pytest.fixture
def in_source(monkeypatch):
    """Relative style paths, as the CLI is given them: the manifest and EXRs record the path."""
    monkeypatch.chdir(SOURCE_DIR)
    return SOURCE_DIR
