"""Errors: one base class users catch; the study layer turns physics errors into one-line InputErrors."""

import pytest

import tribokin
from tribokin import InputError, LawError, Study, TribokinError, load_study, run_study
from tribokin.errors import ConfigurationError, located


def test_the_package_exports_what_users_touch():
    assert callable(run_study) and callable(load_study) and isinstance(Study, type)
    assert issubclass(InputError, TribokinError) and issubclass(LawError, TribokinError)
    assert all(hasattr(tribokin, name) for name in tribokin.__all__)
    assert {"run_study", "load_study", "Study", "TribokinError", "InputError", "__version__"} <= set(tribokin.__all__)


def test_located_names_the_file_and_key_of_a_physics_error():
    with pytest.raises(InputError) as error:
        with located("s.toml", "poses[0].q"):
            raise ConfigurationError("joint 'x' = 2 is outside its limits [0, 1]")
    assert str(error.value) == "s.toml: poses[0].q: joint 'x' = 2 is outside its limits [0, 1]"
    with pytest.raises(InputError) as error:
        with located("s.toml", lambda e: f"joints.friction.{e.parameter}"):
            raise LawError("must be >= 0", "std")
    assert error.value.key == "joints.friction.std"


def test_an_input_error_passes_located_unchanged():
    with pytest.raises(InputError) as error:
        with located("s.toml", "robot"):
            raise InputError("bad", "other.toml", "k")
    assert error.value.one_line() == "other.toml: k: bad"


def test_a_bad_pose_configuration_in_a_study_names_the_file_and_the_pose(axis_mapping):
    axis_mapping["poses"][0]["q"] = [9.0]
    with pytest.raises(InputError, match=r"^<mapping>: poses\[0\].q: joint 'x' = 9 m is outside its limits "
                       r"\[0, 0\.\d+\] m \(q is in metres for prismatic joints, radians for revolute ones\)$"):
        run_study(axis_mapping, cycles=2)
