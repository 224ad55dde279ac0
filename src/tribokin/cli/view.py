"""``tribokin view``: an output folder's scene in a live meshcat viewer."""

from __future__ import annotations

from tribokin.cli.options import option_named
from tribokin.errors import InputError
from tribokin.kinematics.urdf_meshes import WITHOUT_MESHES


def add_parser(commands) -> None:
    """The ``view`` command's arguments."""
    parser = commands.add_parser("view", help="show an output folder's scene in a live meshcat viewer")
    parser.add_argument("folder", help="output folder written by `tribokin run`")
    parser.add_argument("--meshes", choices=("full", "light"), default="full",
                      help="robot visual meshes (full, default) or collision meshes (light)")
    parser.set_defaults(handler=view)



def view(args) -> None:
    """Serve the folder's scene in a live meshcat viewer until Ctrl-C."""
    from tribokin.viz.live import live_scene, stop_signals_interrupt

    try:
        with stop_signals_interrupt(), option_named(WITHOUT_MESHES, "repair the file; a run with --report none "
                                                     "reads no mesh"), \
                live_scene(args.folder, args.meshes) as (server, info):
            notes = info.notes + ([info.robot.skeleton_text()] if info.robot.geometry == "skeleton" else [])
            for note in notes:
                print(f"note: {note}")
            print(f"clouds magnified ×{info.magnification:g}")
            print(f"scene at {server.web_url} (meshcat-server pid {server.process.pid}; Ctrl-C to stop)", flush=True)
            server.process.wait()
    except KeyboardInterrupt:  # Ctrl-C, SIGTERM or SIGHUP; live_scene has stopped the server
        print("viewer stopped")
        return
    raise InputError("meshcat-server stopped unexpectedly; run `tribokin view` again", "meshcat-server")
