"""The suite's own distribution: tests sharing a module fixture reach the scheduler as one group."""

import os

import pytest


@pytest.fixture(scope="module")
def built_here() -> int:
    return os.getpid()


def test_a_test_using_its_module_s_fixture_is_grouped_by_module(built_here, request):
    """conftest marks it xdist_group(<module>); under make test (-n auto --dist loadgroup) pytest-xdist puts the
    group in the node id it schedules by, which stopped working with pytest 9.2 (pytest-xdist#1386)."""
    module = request.node.path.relative_to(request.config.rootpath).as_posix()
    assert [mark.args for mark in request.node.iter_markers("xdist_group")] == [(module,)]
    if os.environ.get("PYTEST_XDIST_WORKER") and request.config.getvalue("loadgroup"):
        assert request.node.nodeid.endswith(f"@{module}")


@pytest.fixture(scope="module", params=["first", "second"])
def variant_here(request) -> str:
    return request.param


def test_each_parameter_of_a_parametrized_module_fixture_is_a_group_of_its_own(variant_here, request):
    """A module's variants (test_map_execution's figure sets) may run on different workers, each built once."""
    module = request.node.path.relative_to(request.config.rootpath).as_posix()
    group = f"{module}[variant_here={['first', 'second'].index(variant_here)}]"
    assert [mark.args for mark in request.node.iter_markers("xdist_group")] == [(group,)]
    if os.environ.get("PYTEST_XDIST_WORKER") and request.config.getvalue("loadgroup"):
        assert request.node.nodeid.endswith(f"@{group}")
