"""A MeshCat server process on 127.0.0.1 and the ``meshcat.Visualizer`` that talks to it.

The process runs :mod:`pinarms.viz._bridge` (MeshCat's bridge with both sockets on the loopback
interface, serving pinarms' page); :class:`MeshcatServer` starts it, hands out its URLs
and stops it (also when garbage-collected or at exit).
"""

from __future__ import annotations

import contextlib
import io
import subprocess
import sys
import threading
import weakref
from pathlib import Path


from pinarms.errors import InvalidInput

from pinarms.viz._meshcat import ViewerWindow, meshcat
from pinarms.viz.errors import ViewerError

__all__ = ["MeshcatServer"]

_BRIDGE_SCRIPT = Path(__file__).with_name("_bridge.py")
_START_TIMEOUT_S = 30.0


def _stop_process(proc: subprocess.Popen, timeout: float = 5.0) -> None:
    """Terminate ``proc`` (SIGTERM, then SIGKILL after ``timeout`` s) and reap it."""
    if proc.poll() is None:
        proc.terminate()
        try:
            proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()
    for stream in (proc.stdout, proc.stderr):
        if stream is not None:
            stream.close()


class MeshcatServer:
    """A MeshCat server process bound to 127.0.0.1, and a :class:`meshcat.Visualizer` talking to it.

    Attributes:
        url: the page to open (``http://127.0.0.1:<port>/static/``).
        zmq_url: the server's command socket.
        pid: the server's process id.
        visualizer: the ``meshcat.Visualizer`` (scene root ``/meshcat``).
    """

    def __init__(self, port: int | None = None) -> None:
        if port is not None and (not isinstance(port, int) or isinstance(port, bool) or not 0 <= port <= 65535):
            raise InvalidInput(f"port must be an integer in 0..65535 (0 or None: any free port), got {port!r}")
        # -I: the script's folder (viz/) must not shadow standard modules such as html
        cmd = [sys.executable, "-I", "-u", str(_BRIDGE_SCRIPT), "--port", str(port or 0)]
        proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True)
        watchdog = threading.Timer(_START_TIMEOUT_S, proc.kill)
        watchdog.start()
        urls: dict[str, str] = {}
        try:
            while len(urls) < 2:
                line = proc.stdout.readline().decode("utf-8", "replace").strip()
                if not line:
                    break
                key, _, value = line.partition("=")
                if key in ("zmq_url", "web_url"):
                    urls[key] = value
        finally:
            watchdog.cancel()
        if len(urls) < 2:
            err = ""
            if proc.poll() is not None and proc.stderr is not None:
                err = proc.stderr.read().decode("utf-8", "replace").strip().splitlines()[-1:]  # type: ignore[assignment]
            _stop_process(proc)
            hint = f" ({err[0]})" if err else ""
            advice = (
                f"; port {port} may be in use: pick another one, or let pinarms choose a free port "
                "(port=None in Python, no --port on the command line)"
                if port is not None
                else ""
            )
            raise ViewerError(f"the MeshCat server did not start{hint}{advice}")
        self._proc = proc
        self.pid: int = proc.pid
        self.url: str = urls["web_url"]
        self.zmq_url: str = urls["zmq_url"]
        with contextlib.redirect_stdout(io.StringIO()):  # ViewerWindow prints the URL
            self._window = ViewerWindow(zmq_url=self.zmq_url, start_server=False, server_args=[])
        self.visualizer = meshcat.Visualizer(window=self._window)
        self._finalizer = weakref.finalize(self, _shutdown, proc, self._window)

    @property
    def running(self) -> bool:
        """Whether the server process is alive."""
        return self._proc.poll() is None

    def static_html(self) -> str:
        """The current scene as one self-contained HTML page (MeshCat's static export)."""
        if not self.running:
            raise ViewerError("the MeshCat server is stopped; start a new one")
        return self.visualizer.static_html()

    def close(self) -> None:
        """Stop the server process and close the command socket (idempotent)."""
        self._finalizer()

    def __enter__(self) -> "MeshcatServer":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _shutdown(proc: subprocess.Popen, window: ViewerWindow) -> None:
    sock = getattr(window, "zmq_socket", None)
    if sock is not None:
        sock.close(linger=0)
    _stop_process(proc)
