"""meshcat's server with both its ports on 127.0.0.1, ending with the process that started it.

``python -m tribokin.viz.meshcat_server PARENT_PID`` runs meshcat-python's ZMQ/WebSocket bridge, whose
web server would otherwise listen on every address (``Application.listen(port)``), prints
``zmq_url=...`` and ``web_url=...`` as ``meshcat-server`` does, and then writes nothing more (so an
unread pipe never fills). On Linux it is killed when ``PARENT_PID`` ends, even by SIGKILL.
"""

from __future__ import annotations

import ctypes
import functools
import os
import signal
import sys

from meshcat.servers.zmqserver import ZMQWebSocketBridge

LOOPBACK = "127.0.0.1"
PR_SET_PDEATHSIG = 1  # <linux/prctl.h>


class LoopbackBridge(ZMQWebSocketBridge):
    """meshcat's bridge whose web server, like its zmq socket, listens on 127.0.0.1 only."""

    def __init__(self) -> None:
        super().__init__(host=LOOPBACK)

    def make_app(self):
        app = super().make_app()
        app.listen = functools.partial(app.listen, address=LOOPBACK)
        return app


def die_with_parent(parent_pid: int) -> None:
    """Have the kernel SIGKILL this process when its parent ends (Linux); exit now if it already has."""
    if not sys.platform.startswith("linux"):
        return
    libc = ctypes.CDLL(None, use_errno=True)
    if libc.prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0) != 0:
        raise OSError(ctypes.get_errno(), "prctl(PR_SET_PDEATHSIG) failed")
    if os.getppid() != parent_pid:
        sys.exit(1)


def main(argv: list[str]) -> None:
    die_with_parent(int(argv[0]))
    bridge = LoopbackBridge()
    print(f"zmq_url={bridge.zmq_url}\nweb_url={bridge.web_url}", flush=True)
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)  # meshcat logs each browser connection; nobody reads those lines
    os.dup2(devnull, 2)
    bridge.run()


if __name__ == "__main__":
    main(sys.argv[1:])
