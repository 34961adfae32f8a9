"""MeshCat server bound to 127.0.0.1 only, on a free (or given) port, serving pinarms' page.

Run as ``python viz/_bridge.py [--port N]`` (:class:`pinarms.viz.server.MeshcatServer` does): it
prints ``zmq_url=...`` and ``web_url=...`` (the same lines as MeshCat's own server) and
serves until terminated. MeshCat 0.3.2's own server makes its web server listen on every
network interface and takes no port option; this one reuses MeshCat's bridge but binds
both sockets to the loopback interface, and serves MeshCat's page with the page script
``page.js`` of this folder added (title, colour bar, framing, controls: see viz/page.py).
It runs isolated (``python -I``) and imports nothing of pinarms.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

import tornado.httpserver
import tornado.netutil
import tornado.web
import zmq
from meshcat.servers.zmqserver import VIEWER_HTML, VIEWER_ROOT, ZMQWebSocketBridge

HOST = "127.0.0.1"
PAGE_SCRIPT = Path(__file__).with_name("page.js")


def viewer_page() -> str:
    """MeshCat's viewer page with pinarms' page script before its last ``</body>``."""
    page = Path(VIEWER_ROOT, VIEWER_HTML).read_text(encoding="utf-8")
    page = page.replace("<title>MeshCat</title>", "<title>pinarms viewer</title>", 1)
    script = PAGE_SCRIPT.read_text(encoding="utf-8")
    head, end, tail = page.rpartition("</body>")
    return f"{head}<script>\n{script}\n</script>\n{end}{tail}"


class PageHandler(tornado.web.RequestHandler):
    """``/static/`` and ``/static/index.html``: the viewer page (never cached)."""

    def get(self) -> None:
        self.set_header("Content-Type", "text/html; charset=utf-8")
        self.set_header("Cache-Control", "no-store, no-cache, must-revalidate, max-age=0")
        self.write(viewer_page())


class LoopbackBridge(ZMQWebSocketBridge):
    """MeshCat's ZMQ ↔ websocket bridge with its HTTP server on 127.0.0.1."""

    def make_app(self):  # noqa: D102 - MeshCat's hook
        app = super().make_app()
        # host rules added later are matched before MeshCat's own (static files, websocket)
        app.add_handlers(r".*", [(r"/static/(?:index\.html)?", PageHandler)])

        def listen(port: int, **kwargs):
            sockets = tornado.netutil.bind_sockets(port, address=HOST)
            server = tornado.httpserver.HTTPServer(app, **kwargs)
            server.add_sockets(sockets)
            app.bound_port = sockets[0].getsockname()[1]
            return server

        app.listen = listen
        return app


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description="MeshCat server on 127.0.0.1")
    parser.add_argument("--port", type=int, default=0, help="HTTP port (0: any free port)")
    args = parser.parse_args(argv)
    bridge = LoopbackBridge(zmq_url=f"tcp://{HOST}:*", host=HOST, port=args.port)
    bridge.zmq_url = bridge.zmq_socket.getsockopt(zmq.LAST_ENDPOINT).decode()
    bridge.fileserver_port = bridge.app.bound_port
    bridge.web_url = f"http://{HOST}:{bridge.fileserver_port}/static/"
    print(f"zmq_url={bridge.zmq_url}", flush=True)
    print(f"web_url={bridge.web_url}", flush=True)
    # nobody reads our output from now on: keep the pipes from filling up
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)
    os.dup2(devnull, 2)
    sys.stdout = sys.stderr = open(os.devnull, "w")
    try:
        bridge.run()
    except KeyboardInterrupt:  # pragma: no cover
        pass


if __name__ == "__main__":
    main()
