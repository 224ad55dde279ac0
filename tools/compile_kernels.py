"""Compile tribokin's numba kernels into numba's cache, as installing a package compiles its bytecode: ``make`` runs
this after installing tribokin, so that the first study run afterwards (and each worker of ``make test``) loads
them instead of compiling them, about 25 CPU seconds each. It runs small studies that call every kernel with the
argument types runs use (one approach and both, sampled and closed-form figures, a plane map's IK, a pose, the
exact engine's batched forward kinematics, and from ``ASYMPTOTIC_CYCLES`` cycles on RP_l_multi's sign mixture and a
test's barycentre shares); a kernel called later with other types compiles then, as it would without this. Nothing
is written but the cache;
on the NumPy path (``TRIBOKIN_KERNELS=numpy``, or numba not installed) it does nothing."""

from __future__ import annotations

import sys

from tribokin import run_study
from tribokin.compiled import use_compiled
from tribokin.iso9283.gaussian_tests import ASYMPTOTIC_CYCLES

#: A UR5 with the raw steel (sampled expected figures) and a scenario with the treated steel (closed form), a
#: 3 x 3 plane map with the directional figures, and one pose.
UR5 = {"study": {"name": "compile-kernels", "cycles": 10, "seed": 1},
       "robot": {"name": "ur5", "payload_kg": 2.0},
       "joints": {"friction": {"preset": "42CD4-raw"}, "stiffness": 1.0e5, "bearing_span_m": 0.08},
       "map": {"kind": "plane", "origin_m": [0.0, -0.5, 0.1], "axis_u": [0, -1, 0], "axis_v": [0, 0, 1],
               "extent_u_m": [-0.2, 0.2], "extent_v_m": [0.0, 0.3], "resolution": [3, 3], "directional": True},
       "poses": [{"name": "P1", "q": [0.3, -1.2, 1.4, -1.8, -1.5, 0.4]}],
       "scenarios": [{"name": "raw"}, {"name": "treated", "joints": {"friction": {"preset": "42CD4-treated"}}}]}


def main() -> int:
    if not use_compiled():
        return 0
    for approach, engine, cycles in (("unidirectional", "fast", 10), ("bidirectional", "fast", 10),
                                     ("unidirectional", "exact", 10), ("unidirectional", "fast", ASYMPTOTIC_CYCLES)):
        run_study({**UR5, "study": {**UR5["study"], "approach": approach, "engine": engine, "cycles": cycles}},
                  meshes=False)
    return 0


if __name__ == "__main__":
    sys.exit(main())
