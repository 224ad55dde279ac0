"""Figures are drawn through matplotlib's Figure API: importing and drawing switch no backend and start no pyplot."""

import os
import subprocess
import sys

DRAW = """
import sys
import matplotlib
import numpy as np
import tribokin.viz.figures, tribokin.viz.maps
from tribokin.viz.tribology import save_profile
x = np.linspace(0.0, 1e-3, 50)
save_profile(x, 1e-6 * np.sin(4e3 * x), np.array([5, 20]), sys.argv[1])
print(matplotlib.get_backend(), "matplotlib.pyplot" in sys.modules)
"""


def test_drawing_keeps_the_callers_backend_and_no_pyplot(tmp_path):
    env = {**os.environ, "MPLBACKEND": "svg"}
    done = subprocess.run([sys.executable, "-c", DRAW, str(tmp_path / "profile.png")], env=env, capture_output=True,
                          text=True, check=True)
    assert done.stdout.split() == ["svg", "False"]
    assert (tmp_path / "profile.png").read_bytes().startswith(b"\x89PNG")
