"""The small costs the code's design rests on: imports kept out of every command, a robot's serial chain, a xacro
expansion stopped at its limits.

Run from the repository root: ``OPENBLAS_NUM_THREADS=1 PYTHONPATH=src python benchmarks/startup.py``. Writes
``benchmarks/results/startup.json`` and prints it. Figures:

* ``imports_s``: seconds to import, in a fresh interpreter that has imported NumPy and tribokin already, each
  library some commands import only when they need it: ``scipy.spatial`` (never: ``iso9283.metrics.largest_distance``
  and ``measurement.registration`` do without it or import it late), ``scipy.stats`` (``tribology.laws``: not
  for a map of Gaussian or constant laws), ``scipy.interpolate`` (``iso9283.gaussian_tests.ShapeTable.at``), and
  matplotlib's Agg canvas with meshcat (what ``output.views_process`` imports while the command's serial start runs);
  each the best of ``--repeats``;
* ``serial_chain_us``: µs to build the UR5's :class:`~tribokin.kinematics.chain.SerialChain` (which
  :func:`~tribokin.kinematics.chain.serial_chain` then keeps on the robot), the best of 50;
* ``xacro_macro_growth``: the 26 macros each calling the previous twice (``tests/kinematics/test_urdf_xacro.py``'s
  ``laughs``) stopped at the default limit of 20 000 elements: seconds, and the peak of Python's allocations in a
  second run under tracemalloc [MB];
* ``xacro_lexer_s``: seconds xacro's lexer takes over a text of ``$a`` pairs whose length times its ``$`` signs is
  :data:`~tribokin.kinematics.xacro_guard.LEXED_CHARACTERS`, the most the guard lets it read.

Timings are wall clock on whatever machine runs this, which may be shared: compare figures measured in the same run.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
import tracemalloc
from pathlib import Path

import numpy as np

RESULTS = Path(__file__).resolve().parent / "results" / "startup.json"
IMPORTS = {"scipy.spatial": "import scipy.spatial", "scipy.stats": "from scipy import stats",
           "scipy.interpolate": "from scipy.interpolate import RegularGridInterpolator",
           "matplotlib Agg + meshcat": "import matplotlib.backends.backend_agg, matplotlib.figure, meshcat"}


def import_seconds(statement: str, repeats: int) -> float:
    """The best of ``repeats`` fresh interpreters' time to run ``statement`` after NumPy and tribokin."""
    code = ("import time, numpy, tribokin, tribokin.kinematics.robot; start = time.perf_counter(); "
            f"{statement}; print(time.perf_counter() - start)")
    return min(float(subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                                    env=os.environ).stdout) for _ in range(repeats))


def serial_chain_us() -> float:
    """µs to build the UR5's serial chain, the best of 50."""
    from tribokin.kinematics.chain import _build_serial_chain
    from tribokin.kinematics.robot import Robot

    robot = Robot.from_example_robot_data("ur5")
    best = float("inf")
    for _ in range(50):
        start = time.perf_counter()
        _build_serial_chain(robot)
        best = min(best, time.perf_counter() - start)
    return best * 1e6


def macro_growth(depth: int = 26) -> dict[str, float]:
    """Seconds and the peak of Python's allocations [MB] of the macro growth stopped at the element limit."""
    from tribokin.errors import RobotDescriptionError
    from tribokin.kinematics.urdf_xacro import expand_xacro

    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "laughs.urdf.xacro"
        path.write_text("\n".join(['<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">',
                                   '<xacro:macro name="m0"><link name="l"/></xacro:macro>',
                                   *(f'<xacro:macro name="m{k}"><xacro:m{k - 1}/><xacro:m{k - 1}/></xacro:macro>'
                                     for k in range(1, depth + 1)),
                                   f'<xacro:m{depth}/></robot>']))
        seconds = []
        for traced in (False, True):  # timed without tracemalloc, which slows the expansion down several times
            if traced:
                tracemalloc.start()
            start = time.perf_counter()
            try:
                expand_xacro(path, {}, [Path(folder)])
            except RobotDescriptionError as error:
                stopped = error.message
            seconds.append(time.perf_counter() - start)
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
    return {"seconds": seconds[0], "peak_MB": peak / 1e6, "stopped": stopped}


def lexer_seconds() -> float:
    """Seconds xacro's lexer takes over ``$a`` pairs at the guard's limit of length times ``$`` signs."""
    import xacro

    from tribokin.kinematics.xacro_guard import LEXED_CHARACTERS

    text = "$a" * int((LEXED_CHARACTERS / 2) ** 0.5)
    lexer = xacro.QuickLexer(xacro.LEXER)
    start = time.perf_counter()
    lexer.lex(text)
    while lexer.peek() is not None:  # as xacro's eval_text reads it: each token copies the rest of the text
        lexer.next()
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3, help="fresh interpreters per import (default 3)")
    args = parser.parse_args()
    results = {
        "machine": {"python": platform.python_version(), "numpy": np.__version__, "cpus": os.cpu_count(),
                    "platform": platform.platform(), "OPENBLAS_NUM_THREADS": os.environ.get("OPENBLAS_NUM_THREADS")},
        "imports_s": {name: import_seconds(statement, args.repeats) for name, statement in IMPORTS.items()},
        "serial_chain_us": serial_chain_us(),
        "xacro_macro_growth": macro_growth(),
        "xacro_lexer_s": lexer_seconds(),
    }
    RESULTS.parent.mkdir(exist_ok=True)
    RESULTS.write_text(json.dumps(results, indent=2) + "\n")
    print(json.dumps(results, indent=2))


if __name__ == "__main__":
    main()
