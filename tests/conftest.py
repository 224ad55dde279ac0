"""Shared fixtures: paths and small study mappings."""

from __future__ import annotations

import copy
import importlib
import itertools
import os
import sys
import traceback
from pathlib import Path

import pytest
from hypothesis import settings
from threadpoolctl import threadpool_limits

#: One BLAS thread in each test process and in the commands it starts: the suite's workers already fill the cores
#: (make test: one per core), and two BLAS threads in each of two workers on two cores spin for each other (a pose
#: study: 5.3-6.3 s of CPU on two threads, 2.8 s on one, in no less time). Outputs do not depend on it (calibrate
#: fits on one thread whatever the setting; test_calibrate checks one against two).
os.environ.update(dict.fromkeys(("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"), "1"))
threadpool_limits(1)  # this process's BLAS, if NumPy loaded it before the variables were set

ROOT = Path(__file__).resolve().parents[1]
AXIS_URDF = ROOT / "urdf" / "prismatic_axis.urdf"
#: Kinova's Gen3 (7 joints, 4 of them continuous), trimmed of its meshes (its provenance and licence beside it).
GEN3_URDF = ROOT / "tests" / "data" / "kinova-gen3" / "gen3.urdf"
STUDIES = ROOT / "studies"
TOOLS = ROOT / "tools"


def load_tool(name: str):
    """The script ``tools/<name>.py`` as a module, with ``tools/`` on the path as when it runs (its sibling imports)."""
    if str(TOOLS) not in sys.path:
        sys.path.insert(0, str(TOOLS))
    return importlib.import_module(name)

#: A study file of the prismatic axis: one pose, 12 cycles.
AXIS_STUDY_TOML = f"""[study]
name = "cli"
cycles = 12
seed = 3

[robot]
urdf = "{AXIS_URDF}"
tool_frame = "tool"

[joints]
friction = {{ preset = "42CD4-raw" }}
normal_force_N = 150.0
stiffness = 2.0e6

[[poses]]
name = "P1"
q = [0.25]
"""

#: A study file of a 25 x 40 plane map of the gantry, in 40 chunks of one row: the treated steel's Gaussian law, so
#: its expected figures are in closed form (the sampled ones cost about 15 s a map: tests of chunks, resume and
#: refusals use this one; :data:`GANTRY_SAMPLED_MAP_TOML` where sampling is what is tested).
GANTRY_MAP_TOML = f"""
[study]
name = "gantry-resume"
cycles = 400
seed = 8

[robot]
urdf = "{ROOT / 'urdf' / 'cartesian_xyz.urdf'}"
tool_frame = "tool"
payload_kg = 5.0

[joints]
friction = {{ preset = "42CD4-treated" }}
stiffness = 2.0e7
bearing_span_m = 0.2

[map]
kind = "plane"
origin_m = [0.2, 0.0, 0.4]
axis_u = [1, 0, 0]
axis_v = [0, 1, 0]
extent_u_m = [0.0, 0.6]
extent_v_m = [0.0, 0.6]
resolution = [25, 40]
chunk_rows = 1
"""

#: :data:`GANTRY_MAP_TOML` with the raw steel's uniform law: expected figures sampled by common random numbers.
GANTRY_SAMPLED_MAP_TOML = GANTRY_MAP_TOML.replace("42CD4-treated", "42CD4-raw")


def killed_after(steps: int, functions: tuple[str, ...], action) -> bool:
    """Run ``action()`` in a forked process killed (``os._exit``, no clean-up) right after its ``steps``-th
    call of the ``functions`` (``"module.name"``); whether it was killed before finishing."""
    child = os.fork()
    if child == 0:  # pragma: no cover (measured in the parent)
        try:
            calls = itertools.count(1)
            for function in functions:
                module, _, name = function.rpartition(".")
                real = getattr(sys.modules[module], name)

                def step(*args, real=real, **options):
                    done = real(*args, **options)
                    if next(calls) == steps:
                        os._exit(9)
                    return done

                setattr(sys.modules[module], name, step)
            action()
        except BaseException:
            traceback.print_exc()
            os._exit(1)
        os._exit(0)  # never back into pytest
    return os.waitstatus_to_exitcode(os.waitpid(child, 0)[1]) == 9


def axis_study(**joints) -> dict:
    """A one-pose study of the prismatic axis; ``joints`` overrides the [joints] table."""
    return {
        "study": {"name": "axis", "cycles": 30, "seed": 1},
        "robot": {"urdf": str(AXIS_URDF), "tool_frame": "tool"},
        "joints": {"friction": {"law": "constant", "mu": 0.0}, "stiffness": 1.0e6, "normal_force_N": 100.0,
                   **joints},
        "poses": [{"name": "P1", "q": [0.2]}],
    }


@pytest.fixture
def axis_mapping():
    return copy.deepcopy(axis_study())


# Property tests (hypothesis): derandomized, so a run is reproducible on CI; no deadline (the first
# example pays for imports and robot loading); modest example counts keep the suite fast.
# HYPOTHESIS_PROFILE=thorough explores far more, randomly.
settings.register_profile("tribokin", derandomize=True, deadline=None, max_examples=25, database=None,
                          print_blob=True)
settings.register_profile("thorough", deadline=None, max_examples=1000)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "tribokin"))


@pytest.fixture(params=["numpy", "compiled"])
def kernel_path(request, monkeypatch):
    """Each kernel path in turn (``TRIBOKIN_KERNELS``, :mod:`tribokin.compiled`): a test of both."""
    monkeypatch.setenv("TRIBOKIN_KERNELS", request.param)
    return request.param


def pytest_itemcollected(item):
    """A test that uses its module's own module-scoped fixtures runs on the xdist worker of the module's other such
    tests (make test passes --dist loadgroup), so that each fixture is built once, not once per worker; where such a
    fixture is parametrized, each of its parameters is a group of its own (``<module>[<fixture>=<index>]``), so that a
    module's variants spread over the workers."""
    module = item.nodeid.split("::")[0]
    definitions = getattr(item, "_fixtureinfo", None)
    own = [d[-1] for d in definitions.name2fixturedefs.values()
           if d[-1].scope == "module" and d[-1].baseid == module] if definitions else []
    if own:
        indices = getattr(getattr(item, "callspec", None), "indices", {})
        params = [f"{d.argname}={indices[d.argname]}" for d in own if d.params is not None and d.argname in indices]
        item.add_marker(pytest.mark.xdist_group(module + (f"[{','.join(params)}]" if params else "")))
