"""The Python examples of the README and of the docs pages run as written (from the repository's root, in one
namespace, in order; a block the README and a page share runs once), and each line ``expression  # (shape) ...``
gives an array (or a ``.shape``) of that shape."""

import ast
import re

import numpy as np

from conftest import ROOT

PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
BLOCKS = list(dict.fromkeys(block for page in PAGES for block in re.findall(r"^```python\n(.*?)^```",
                                                                              page.read_text(encoding="utf-8"),
                                                                              re.DOTALL | re.MULTILINE)))
SHAPE_COMMENT = re.compile(r"^(\S.*?)\s+# (\([\d, ]*\))", re.MULTILINE)


def test_readme_python_examples_run_and_give_the_shapes_they_say(monkeypatch):
    assert len(BLOCKS) >= 2  # the pose and the map examples
    monkeypatch.chdir(ROOT)
    namespace, shapes = {}, 0
    for number, block in enumerate(BLOCKS, 1):
        exec(compile(block, f"python block {number}", "exec"), namespace)
        for expression, shape in SHAPE_COMMENT.findall(block):
            value = eval(expression, namespace)
            assert (value if isinstance(value, tuple) else np.shape(value)) == ast.literal_eval(shape), expression
            shapes += 1
    assert shapes >= 5
