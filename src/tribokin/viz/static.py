"""A meshcat scene kept in memory and exported as one self-contained HTML page, with no server.

``meshcat.Visualizer(window=StaticWindow())`` accepts every scene command; the
window keeps the scene tree the way ``meshcat-server`` does
(``meshcat.servers.tree.SceneTree``) and :meth:`StaticWindow.static_html`
inlines the viewer's JavaScript and every command, so the page makes no
network request.

Same scene, same bytes: meshcat names every geometry, material, texture and
object with ``uuid.uuid1()`` (the clock and the machine's network address); the
window renames them ``00000000-0000-0000-0000-000000000001``, ``…02``, … in the
order they reach it (three.js uses them only as keys linking an object to its
geometry and material). meshcat itself is left untouched.
"""

from __future__ import annotations

import uuid
from pathlib import Path

import meshcat
import umsgpack
from meshcat.servers.tree import SceneTree, find_node, walk
from meshcat.servers.zmqserver import VIEWER_ROOT, create_command


class StaticWindow:
    """A meshcat window that records scene commands instead of sending them to a server."""

    def __init__(self):
        self.tree = SceneTree()
        self.uuids: dict[str, str] = {}

    def send(self, command) -> None:
        """Apply one lowered meshcat command to the scene tree, as ``meshcat-server`` does."""
        data = command.lower()
        self.uuids.update((name, str(uuid.UUID(int=len(self.uuids) + 1))) for name in _declared_uuids(data)
                          if name not in self.uuids)
        data = _renamed(data, self.uuids)
        kind = data["type"]
        path = [part for part in data["path"].split("/") if part]
        packed = umsgpack.packb(data)
        if kind == "delete":
            if path:
                find_node(self.tree, path[:-1]).pop(path[-1], None)
            else:
                self.tree = SceneTree()
            return
        node = find_node(self.tree, path)
        if kind == "set_object":
            node.object, node.properties = packed, []
        elif kind == "set_property":
            node.properties.append(packed)
        elif kind == "set_transform":
            node.transform = packed
        elif kind == "set_animation":
            node.animation = packed

    def commands_js(self) -> str:
        """The scene as JavaScript statements that replay it into a ``viewer``."""
        parts = []
        for node in walk(self.tree):
            for packed in ([node.object] + node.properties + [node.transform, node.animation]):
                if packed is not None:
                    parts.append(create_command(packed))
        return "".join(parts)

    def get_scene(self) -> str:
        """The page ``meshcat.Visualizer.static_html()`` returns."""
        return static_html(self.commands_js())


def _declared_uuids(node):
    """The values of every ``"uuid"`` key in a lowered command, in order."""
    if isinstance(node, dict):
        if isinstance(node.get("uuid"), str):
            yield node["uuid"]
        for value in node.values():
            yield from _declared_uuids(value)
    elif isinstance(node, list):
        for value in node:
            yield from _declared_uuids(value)


def _renamed(node, names: dict[str, str]):
    """``node`` with every string that is a key of ``names`` (a uuid or a reference to one) replaced."""
    if isinstance(node, dict):
        return {key: _renamed(value, names) for key, value in node.items()}
    if isinstance(node, list):
        return [_renamed(value, names) for value in node]
    return names.get(node, node) if isinstance(node, str) else node


def viewer_js() -> str:
    """meshcat's bundled viewer (three.js and its GUI), ≈ 0.85 MB of JavaScript."""
    return (Path(VIEWER_ROOT) / "main.min.js").read_text(encoding="utf-8")


def static_html(commands_js: str) -> str:
    """A full-window meshcat viewer page that replays ``commands_js``."""
    return f"""<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>tribokin scene</title>
<style>body {{ margin: 0; }} #meshcat-pane {{ width: 100vw; height: 100vh; overflow: hidden; }}</style>
</head><body><div id="meshcat-pane"></div>
<script>{viewer_js()}</script>
<script>var viewer = new MeshCat.Viewer(document.getElementById("meshcat-pane"));
{commands_js}</script>
</body></html>
"""


def static_visualizer() -> meshcat.Visualizer:
    """A :class:`meshcat.Visualizer` drawing into a new :class:`StaticWindow` (``vis.window``)."""
    return meshcat.Visualizer(window=StaticWindow())
