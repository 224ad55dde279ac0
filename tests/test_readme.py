"""The README's Python examples run as written (from the repository's root, in one namespace, in order)."""

import re

from conftest import ROOT

BLOCKS = re.findall(r"^```python\n(.*?)^```", (ROOT / "README.md").read_text(encoding="utf-8"), re.DOTALL | re.MULTILINE)


def test_readme_python_examples_run(monkeypatch):
    assert len(BLOCKS) >= 2  # the pose and the map examples
    monkeypatch.chdir(ROOT)
    namespace = {}
    for number, block in enumerate(BLOCKS, 1):
        exec(compile(block, f"README.md python block {number}", "exec"), namespace)
