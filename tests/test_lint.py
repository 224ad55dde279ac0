"""The code and the examples pass ruff (its rules and line length in pyproject.toml: E, F, I, B, UP and Google-style
docstrings, at 120 characters)."""

import subprocess
import sys

from conftest import ROOT


def test_ruff_finds_nothing_in_the_code_the_tests_the_tools_the_benchmarks_and_the_examples():
    done = subprocess.run([sys.executable, "-m", "ruff", "check", "--no-cache", "src", "tests", "tools", "benchmarks",
                           "examples"], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stdout + done.stderr


def test_a_docstring_whose_args_section_leaves_out_a_parameter_fails_the_lint(tmp_path):
    """The docstrings follow Google's convention (pyproject.toml's pydocstyle rules): an ``Args`` section names every
    parameter."""
    module = tmp_path / "module.py"
    module.write_text('"""A module."""\n\n\ndef f(a, b):\n    """Add.\n\n    Args:\n        a: one [m].\n    """\n'
                      "    return a + b\n")
    done = subprocess.run([sys.executable, "-m", "ruff", "check", "--no-cache", "--config", ROOT / "pyproject.toml",
                           module], cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert done.returncode == 1 and "D417" in done.stdout, done.stdout + done.stderr
