"""The preview's web server: meshcat's tornado/ZMQ bridge, bound to one address and fenced.

meshcat's own server (`meshcat.servers.zmqserver.ZMQWebSocketBridge`, meshcat 0.3.2) opens two
listening sockets: the HTTP/WebSocket port through `Application.listen(port)`, i.e. on every
interface (0.0.0.0 and [::]) while it prints 127.0.0.1; and its ZMQ command socket (REP) on
tcp://127.0.0.1. It serves every file of its viewer folder under /static/ and sends the whole scene
to any WebSocket client that sends no Origin header: tornado (6.6) lets a handshake through without
asking `check_origin` when there is no Origin, when the Origin equals the Host header (as it does
for a foreign page that rebinds its own host name to 127.0.0.1) or when the request says
`Sec-Fetch-Site: same-origin`. `PreviewBridge` is that bridge with:

- the HTTP/WebSocket port bound to one address (127.0.0.1 unless `--host` names another); the URL
  printed is built from the socket actually bound;
- the ZMQ command socket, through which the robomax process draws the scene, bound to 127.0.0.1 on a
  port the system picks, whatever `--host` is (only this machine's robomax process drives it);
- the WebSocket handshake answered 403 unless its Origin is the page's own (`OriginPolicy`): a
  missing Origin and any other site are refused, whatever Host or Sec-Fetch-Site say;
- only the viewer served: GET /static/ (meshcat's index.html, with the preview's overlay when one is
  given: `preview_overlay`) and /static/main.min.js; every other
  path is 404 (no directory listing, none of the viewer folder's other files), except the icon
  browsers ask for by themselves, /favicon.ico, answered with an empty 204;
- messages from the page ignored (the page needs to send none; meshcat uses them only to capture
  images, which the preview does not do).

It runs as `python -m robomax_py.app.preview_server --host H [--port P] [--overlay-stdin]` (with
`--overlay-stdin` it first reads one line from stdin: the overlay's HTML as a JSON string), prints
`zmq_url=...` and
`web_url=...` (or one `error=...` line and exits 1), and from then on writes nothing: its stdout and
stderr point at the null device, so that a pipe nobody reads can never stall it (tornado logs every
refused request). It stops when its stdin reaches end of file, i.e. when the robomax process that
started it is gone, however that process ended.
"""

from __future__ import annotations

import argparse
import errno
import ipaddress
import os
import socket
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any
from urllib.parse import urlsplit

LOOPBACK = "127.0.0.1"
FIRST_PORT = 7000            # meshcat's first web port: the URL people are used to
PORT_ATTEMPTS = 100
ZMQ_URL = f"tcp://{LOOPBACK}:*"      # "*": the system picks a free port
# The page never needs to send anything; anything larger than this closes the connection.
MAX_MESSAGE_BYTES = 64 * 1024
# The viewer's files served, by the name after /static/ ("" is the page itself).
SERVED = {"": ("index.html", "text/html; charset=utf-8"),
          "index.html": ("index.html", "text/html; charset=utf-8"),
          "main.min.js": ("main.min.js", "application/javascript; charset=utf-8")}
WILDCARDS = ("0.0.0.0", "::")


@dataclass(frozen=True, slots=True)
class OriginPolicy:
    """Which `Origin` a WebSocket handshake may carry: the preview page's own.

    port : the web port, which the Origin must name (80 when it names none).
    hosts : host names and address literals (lower case, IPv6 without brackets) the page can have
        been opened under: the address bound and the host name asked for; `localhost` too when the
        address is a loopback one.
    any_local_address : bound to a wildcard address: an Origin whose host is an address literal of
        one of this machine's interfaces is the page's own too (a literal address cannot be
        rebound by a foreign site's DNS, unlike a name).
    """

    port: int
    hosts: frozenset[str]
    any_local_address: bool = False

    def allows(self, origin: str | None) -> bool:
        """Whether a handshake with this Origin header (None: absent) is the page's own."""
        if origin is None:
            return False
        try:
            parts = urlsplit(origin.strip())
            port = parts.port
        except ValueError:
            return False
        host = (parts.hostname or "").lower()
        if parts.scheme != "http" or not host or parts.path not in ("", "/") or parts.query or parts.username:
            return False
        if (80 if port is None else port) != self.port:
            return False
        return host in self.hosts or (self.any_local_address and _is_local_address(host))


def is_loopback(host: str) -> bool:
    """Whether `host` (an address literal or `localhost`) reaches only this machine."""
    if host.lower() == "localhost":
        return True
    try:
        return ipaddress.ip_address(host.strip("[]")).is_loopback
    except ValueError:
        return False


def origin_policy(host: str, bound: list[str], port: int) -> OriginPolicy:
    """The policy for a server asked to bind `host` that bound the addresses `bound` on `port`."""
    given = host.strip("[]").lower()
    wildcard = given in WILDCARDS
    hosts = {a.lower() for a in bound if a not in WILDCARDS}
    if not wildcard:
        hosts.add(given)
    if wildcard or all(is_loopback(a) for a in bound):
        hosts.add("localhost")
    if wildcard:
        # Not getfqdn: it asks DNS, which may hang on an offline machine.
        hosts.update({LOOPBACK, "::1", socket.gethostname().lower()})
    return OriginPolicy(port, frozenset(hosts), any_local_address=wildcard)


def url_host(address: str) -> str:
    """An address as it appears in a URL (IPv6 in brackets)."""
    return f"[{address}]" if ":" in address else address


def _is_local_address(host: str) -> bool:
    """Whether `host` is an address literal of one of this machine's interfaces (it can be bound)."""
    try:
        ip = ipaddress.ip_address(host)
    except ValueError:
        return False
    family = socket.AF_INET6 if ip.version == 6 else socket.AF_INET
    try:
        with socket.socket(family, socket.SOCK_STREAM) as probe:
            probe.bind((str(ip), 0))
    except OSError:
        return False
    return True


def _viewer_files(overlay: str | None = None) -> dict[str, tuple[bytes, str]]:
    """The served files' bytes (read once) by the name after /static/; `overlay` (an HTML fragment)
    put into the page."""
    from meshcat.servers.zmqserver import VIEWER_ROOT

    from robomax_py.app.preview_overlay import inject

    files = {}
    for name, (file, kind) in SERVED.items():
        body = (Path(VIEWER_ROOT) / file).read_bytes()
        if overlay is not None and file == "index.html":
            body = inject(body.decode("utf-8"), overlay).encode("utf-8")
        files[name] = (body, kind)
    return files


def read_overlay(fd: int) -> str | None:
    """The overlay sent as the first line of `fd` (a JSON string); None at end of file (the process
    that started this one is gone).

    Read with os.read, not a buffered file, so that nothing after the line is taken from the pipe
    that `_watch_parent` watches afterwards.
    """
    import json

    line = b""
    while not line.endswith(b"\n"):
        chunk = os.read(fd, 1)
        if not chunk:
            return None
        line += chunk
    value = json.loads(line)
    if isinstance(value, str):
        return value
    raise ValueError("the overlay sent on stdin is not a JSON string")


def _handlers() -> tuple[type, type, type]:
    """The WebSocket, file and icon handler classes (tornado and meshcat are imported only here)."""
    import tornado.web
    from meshcat.servers.zmqserver import WebSocketHandler

    class SceneSocket(WebSocketHandler):  # type: ignore[misc]
        """meshcat's scene socket, opened only for the page's own Origin."""

        def initialize(self, policy: OriginPolicy) -> None:
            self.policy = policy

        def prepare(self) -> None:
            # Decided here, before tornado's own check, because tornado lets a missing Origin,
            # an Origin equal to Host and `Sec-Fetch-Site: same-origin` through without asking.
            if not self.policy.allows(self.request.headers.get("Origin")):
                self.set_status(403)
                self.finish("Forbidden: the preview's scene is served only to its own page")

        def check_origin(self, origin: str) -> bool:
            return self.policy.allows(origin)

        def on_message(self, message: Any) -> None:
            return                                   # the page needs to send nothing

    class ViewerFile(tornado.web.RequestHandler):
        """One of the viewer's files, from memory; anything else is 404."""

        def initialize(self, files: dict[str, tuple[bytes, str]]) -> None:
            self.files = files

        def get(self, name: str) -> None:
            if name not in self.files:
                raise tornado.web.HTTPError(404)
            body, kind = self.files[name]
            self.set_header("Content-Type", kind)
            self.set_header("Cache-Control", "no-store, no-cache, must-revalidate, max-age=0")
            self.set_header("X-Content-Type-Options", "nosniff")
            self.finish(body)

    class NoIcon(tornado.web.RequestHandler):
        """/favicon.ico: nothing, without the error a 404 puts in the browser's console."""

        def get(self) -> None:
            self.set_status(204)
            self.finish()

    return SceneSocket, ViewerFile, NoIcon


def _bridge_class() -> type:
    from meshcat.servers.zmqserver import ZMQWebSocketBridge

    class PreviewBridge(ZMQWebSocketBridge):  # type: ignore[misc]
        """meshcat's bridge bound to `host` (web) and 127.0.0.1 (ZMQ), serving only the scene.

        meshcat's `__init__` is not called: it binds the web port on every interface and the ZMQ
        socket on `host`. Everything after binding (scene tree, ZMQ commands, sending the scene to
        a page) is meshcat's.
        """

        def __init__(self, host: str, port: int | None, overlay: str | None = None) -> None:
            import tornado.httpserver
            import tornado.ioloop
            from meshcat.servers.tree import SceneTree

            self.host = host
            self.websocket_pool: set[Any] = set()
            self.tree = SceneTree()
            self.ioloop = tornado.ioloop.IOLoop.current()
            self.zmq_socket, self.zmq_stream, self.zmq_url = self.setup_zmq(ZMQ_URL)
            sockets = _bind_web(host, port)
            self.fileserver_port = sockets[0].getsockname()[1]
            bound = sorted({s.getsockname()[0] for s in sockets})
            self.policy = origin_policy(host, bound, self.fileserver_port)
            self.overlay = overlay
            self.app = self.make_app()
            server = tornado.httpserver.HTTPServer(self.app, xheaders=False)
            server.add_sockets(sockets)
            shown = host if not _is_address(host) else bound[0]
            self.web_url = f"http://{url_host(shown)}:{self.fileserver_port}/static/"

        def make_app(self) -> Any:
            import tornado.web

            scene_socket, viewer_file, no_icon = _handlers()
            return tornado.web.Application(
                [(r"/static/([A-Za-z0-9_.-]*)", viewer_file, {"files": _viewer_files(self.overlay)}),
                 (r"/favicon\.ico", no_icon),
                 (r"/", scene_socket, {"bridge": self, "policy": self.policy})],
                websocket_max_message_size=MAX_MESSAGE_BYTES,
            )

        def setup_zmq(self, url: str) -> tuple[Any, Any, str]:
            import zmq

            zmq_socket, zmq_stream, _ = super().setup_zmq(url)
            # The endpoint actually bound (the port the system picked for "*").
            return zmq_socket, zmq_stream, zmq_socket.getsockopt_string(zmq.LAST_ENDPOINT)

    return PreviewBridge


def _is_address(host: str) -> bool:
    try:
        ipaddress.ip_address(host.strip("[]"))
    except ValueError:
        return False
    return True


def _bind_web(host: str, port: int | None) -> list[socket.socket]:
    """Listening sockets on `host` only: on `port`, or on the first free port from FIRST_PORT."""
    from tornado.netutil import bind_sockets

    address = host.strip("[]")
    if not address:
        # tornado reads an empty address as every interface; that must be asked for by name.
        raise ValueError("no address given (0.0.0.0 is every interface)")
    if port is not None:
        return bind_sockets(port, address=address)
    for candidate in range(FIRST_PORT, FIRST_PORT + PORT_ATTEMPTS):
        try:
            return bind_sockets(candidate, address=address)
        except OSError as exc:
            if exc.errno != errno.EADDRINUSE:
                raise
    raise OSError(f"no free port in {FIRST_PORT}..{FIRST_PORT + PORT_ATTEMPTS - 1} on {host}")


def _watch_parent(bridge: Any) -> None:
    """Stop the server when stdin (a pipe from the process that started it) reaches end of file."""
    fd = sys.stdin.fileno()

    def readable(fd: int, events: int) -> None:
        if not os.read(fd, 4096):
            bridge.ioloop.remove_handler(fd)
            bridge.ioloop.stop()

    bridge.ioloop.add_handler(fd, readable, bridge.ioloop.READ)


def _silence() -> None:
    """Point stdout and stderr at the null device (nobody reads them after the start)."""
    sys.stdout.flush()
    sys.stderr.flush()
    null = os.open(os.devnull, os.O_WRONLY)
    os.dup2(null, 1)
    os.dup2(null, 2)
    os.close(null)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description="robomax preview: meshcat's server, bound and fenced")
    parser.add_argument("--host", default=LOOPBACK)
    parser.add_argument("--port", type=int, default=None)
    parser.add_argument("--overlay-stdin", action="store_true", help="read the page's overlay (a JSON string line) from stdin first")
    args = parser.parse_args(argv)
    overlay = None
    if args.overlay_stdin:
        try:
            overlay = read_overlay(sys.stdin.fileno())
        except ValueError as exc:
            print(f"error=bad overlay: {exc}", flush=True)
            return 1
        if overlay is None:
            print("error=stdin closed before the overlay arrived", flush=True)
            return 1
    try:
        bridge = _bridge_class()(args.host, args.port, overlay)
    except (OSError, ValueError) as exc:
        detail = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        print(f"error=cannot listen on {args.host}" + (f" port {args.port}" if args.port is not None else "")
              + f": {detail}", flush=True)
        return 1
    print(f"zmq_url={bridge.zmq_url}")
    print(f"web_url={bridge.web_url}", flush=True)
    _silence()
    _watch_parent(bridge)
    try:
        bridge.run()
    except KeyboardInterrupt:
        pass
    return 0


if __name__ == "__main__":
    sys.exit(main())
