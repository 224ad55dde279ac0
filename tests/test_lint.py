"""The code and the examples pass ruff (its rules and line length in pyproject.toml: E, F, I, B, UP at 120
characters)."""

import subprocess
import sys

from conftest import ROOT


def test_ruff_finds_nothing_in_the_code_the_tests_the_tools_the_benchmarks_and_the_examples():
    done = subprocess.run([sys.executable, "-m", "ruff", "check", "--no-cache", "src", "tests", "tools", "benchmarks",
                           "examples"], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stdout + done.stderr
