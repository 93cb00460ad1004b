"""The served preview: what listens where, who gets the scene, what is served.

The command runs as a user would start it (`robomax preview CELL`, its own process group) and is
probed from outside with plain sockets: the listening sockets of every process in its group (from
/proc), a connection to each non-loopback address of this machine, raw WebSocket handshakes with
and without the page's Origin, and HTTP requests for files around the viewer.
"""

from __future__ import annotations

import base64
import fcntl
import http.client
import ipaddress
import os
import socket
import struct
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import meshcat
import pytest
import umsgpack
from typer.testing import CliRunner

from robomax_py.app.cli import EXIT_BAD_INPUT, app
from robomax_py.app.preview import populate
from robomax_py.app.preview_program import home_program
from robomax_py.app.preview_server import OriginPolicy, origin_policy
from robomax_py.io.cell import load_cell, load_cell_robot

SmallCell = Callable[..., Path]   # conftest.write_small_cell
Served = Any                      # tests/app/conftest.Served
FreePort = Callable[..., int]     # tests/app/conftest.free_port
SOCKET_TIMEOUT_S = 60.0           # a safety net for a server that stops answering, not a measurement
MAX_FRAMES = 10_000
SIOCGIFADDR = 0x8915
runner = CliRunner()
linux_only = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc and interface addresses the Linux way")


# --------------------------------------------------------------------------------------------------
# probes


def machine_addresses() -> list[str]:
    """This machine's non-loopback addresses: IPv4 of every interface, IPv6 of global scope."""
    found = []
    for _, name in socket.if_nameindex():
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
            try:
                packed = fcntl.ioctl(s.fileno(), SIOCGIFADDR, struct.pack("256s", name.encode()[:15]))
            except OSError:
                continue                       # no IPv4 address on this interface
        found.append(socket.inet_ntoa(packed[20:24]))
    if Path("/proc/net/if_inet6").is_file():
        for line in Path("/proc/net/if_inet6").read_text().splitlines():
            raw, _, _, scope, *_ = line.split()
            if scope == "00":                  # global scope (link-local ones need an interface)
                found.append(str(ipaddress.IPv6Address(bytes.fromhex(raw))))
    return [a for a in dict.fromkeys(found) if not ipaddress.ip_address(a).is_loopback]


def group_sockets(pgid: int) -> dict[str, list[tuple[str, int]]]:
    """The TCP listening and UDP bound sockets of every process in a process group, by kind:
    {"tcp": [(address, port), ...], "udp": [...]} read from /proc."""
    inodes = set()
    for proc in Path("/proc").iterdir():
        if not proc.name.isdigit():
            continue
        try:
            stat = (proc / "stat").read_text()
            if int(stat.rsplit(")", 1)[1].split()[2]) != pgid:
                continue
            for fd in (proc / "fd").iterdir():
                link = os.readlink(fd)
                if link.startswith("socket:["):
                    inodes.add(link[8:-1])
        except (FileNotFoundError, ProcessLookupError):
            continue                           # a process or fd that went away while listing
    found: dict[str, list[tuple[str, int]]] = {"tcp": [], "udp": []}
    for kind in ("tcp", "udp"):
        for table, v6 in ((f"/proc/net/{kind}", False), (f"/proc/net/{kind}6", True)):
            if not Path(table).is_file():
                continue
            for line in Path(table).read_text().splitlines()[1:]:
                fields = line.split()
                local, state, inode = fields[1], fields[3], fields[9]
                if inode not in inodes or (kind == "tcp" and state != "0A"):      # 0A: LISTEN
                    continue
                addr_hex, port_hex = local.split(":")
                raw = bytes.fromhex(addr_hex)
                # /proc prints each 32-bit word in host (little-endian) order.
                words = b"".join(raw[i:i + 4][::-1] for i in range(0, len(raw), 4))
                address = str(ipaddress.IPv6Address(words) if v6 else ipaddress.IPv4Address(words))
                found[kind].append((address, int(port_hex, 16)))
    return found


def reachable(address: str, port: int) -> bool:
    """Whether a TCP connection to address:port is accepted (refused, or the address not
    configured here: False)."""
    family = socket.AF_INET6 if ":" in address else socket.AF_INET
    with socket.socket(family, socket.SOCK_STREAM) as s:
        s.settimeout(SOCKET_TIMEOUT_S)
        try:
            s.connect((address, port))
        except (ConnectionRefusedError, OSError) as exc:
            if isinstance(exc, TimeoutError):
                raise
            return False
    return True


def handshake(port: int, headers: dict[str, str], address: str = "127.0.0.1") -> tuple[int, socket.socket]:
    """A WebSocket opening handshake on GET /; returns the status code and the open socket."""
    family = socket.AF_INET6 if ":" in address else socket.AF_INET
    s = socket.socket(family, socket.SOCK_STREAM)
    s.settimeout(SOCKET_TIMEOUT_S)
    s.connect((address, port))
    fields = {"Host": f"{address}:{port}", "Upgrade": "websocket", "Connection": "Upgrade",
              "Sec-WebSocket-Version": "13", "Sec-WebSocket-Key": base64.b64encode(os.urandom(16)).decode(), **headers}
    lines = ["GET / HTTP/1.1", *[f"{k}: {v}" for k, v in fields.items()]]
    s.sendall(("\r\n".join(lines) + "\r\n\r\n").encode())
    head = b""
    while b"\r\n\r\n" not in head:
        chunk = s.recv(1)
        if not chunk:
            break
        head += chunk
    status = int(head.split(b" ", 2)[1]) if head.startswith(b"HTTP/1.1 ") else 0
    return status, s


def _exactly(s: socket.socket, n: int) -> bytes:
    data = b""
    while len(data) < n:
        chunk = s.recv(n - len(data))
        if not chunk:
            raise ConnectionError("the server closed the WebSocket")
        data += chunk
    return data


def read_message(s: socket.socket) -> bytes:
    """One unfragmented server-to-client WebSocket message (unmasked, RFC 6455 §5.2)."""
    b0, b1 = _exactly(s, 2)
    assert b0 & 0x80, "fragmented message"
    n = b1 & 0x7F
    if n == 126:
        n = struct.unpack(">H", _exactly(s, 2))[0]
    elif n == 127:
        n = struct.unpack(">Q", _exactly(s, 8))[0]
    return _exactly(s, n)


def scene_paths(s: socket.socket, want: set[str]) -> set[str]:
    """The set_object paths the server sends, read until every path in `want` came."""
    got: set[str] = set()
    for _ in range(MAX_FRAMES):
        command = umsgpack.unpackb(read_message(s))
        if command["type"] == "set_object":
            got.add(command["path"])
        if want <= got:
            break
    return got


def get(port: int, path: str, host: str = "127.0.0.1") -> tuple[int, bytes]:
    conn = http.client.HTTPConnection(host, port, timeout=SOCKET_TIMEOUT_S)
    try:
        conn.request("GET", path)
        response = conn.getresponse()
        return response.status, response.read()
    finally:
        conn.close()


class Recorder:
    def __init__(self) -> None:
        self.commands: list[dict[str, Any]] = []

    def send(self, command: Any) -> None:
        self.commands.append(command.lower())


def expected_objects(cell_path: Path) -> set[str]:
    """The set_object paths of the cell's preview at home (drawn in-process, no server)."""
    cell = load_cell(cell_path)
    rec = Recorder()
    populate(meshcat.Visualizer(window=rec), cell, load_cell_robot(cell), home_program(cell))
    return {c["path"] for c in rec.commands if c["type"] == "set_object"}


@pytest.fixture(scope="module")
def cell_path(tmp_path_factory: pytest.TempPathFactory, write_small_cell: SmallCell) -> Path:
    return write_small_cell(tmp_path_factory.mktemp("served"), "small_cell")


@pytest.fixture(scope="module")
def served(serve_preview: Callable[..., Served], cell_path: Path, free_port: FreePort) -> Served:
    """One preview of the small cell at home on loopback, shared by the tests that only look at it."""
    return serve_preview(cell_path, "--port", str(free_port()))


# --------------------------------------------------------------------------------------------------
# the Origin rule, without a server


@pytest.mark.parametrize(("origin", "ok"), [
    (None, False),
    ("http://127.0.0.1:7005", True),
    ("http://localhost:7005", True),
    ("http://LOCALHOST:7005/", True),
    ("http://evil.example", False),
    ("http://evil.example:7005", False),              # a page rebinding its name to 127.0.0.1
    ("http://127.0.0.1:7006", False),                 # another local server's page
    ("http://127.0.0.1", False),
    ("https://127.0.0.1:7005", False),
    ("null", False),                                  # file: pages and sandboxed frames
    ("http://127.0.0.1:7005.evil.example", False),
    ("http://user@127.0.0.1:7005", False),
    ("http://[::1]:7005", False),                      # bound to 127.0.0.1 only
    ("", False),
])
def test_only_the_pages_own_origin_is_allowed(origin: str | None, ok: bool) -> None:
    assert origin_policy("127.0.0.1", ["127.0.0.1"], 7005).allows(origin) is ok


def test_origins_for_a_chosen_host() -> None:
    named = origin_policy("cell-pc.example", ["192.0.2.7"], 8080)
    assert named.allows("http://cell-pc.example:8080") and named.allows("http://192.0.2.7:8080")
    assert not named.allows("http://localhost:8080") and not named.allows("http://evil.example:8080")
    v6 = origin_policy("::1", ["::1"], 7000)
    assert v6.allows("http://[::1]:7000") and v6.allows("http://localhost:7000")
    everywhere = origin_policy("0.0.0.0", ["0.0.0.0"], 7000)
    assert everywhere.any_local_address and everywhere.allows("http://127.0.0.1:7000")
    assert not everywhere.allows("http://evil.example:7000")
    assert not everywhere.allows("http://198.51.100.9:7000")          # not an address of this machine
    assert OriginPolicy(80, frozenset({"a.example"})).allows("http://a.example")     # port 80 unnamed


# --------------------------------------------------------------------------------------------------
# the running command


@linux_only
def test_listens_only_on_loopback(served: Served) -> None:
    """Both of the server's sockets (web, ZMQ) are on 127.0.0.1; the URL printed is the one bound;
    the port is closed on every other address of this machine."""
    assert served.url == f"http://127.0.0.1:{served.port}/static/"
    sockets = group_sockets(served.proc.pid)
    assert len(sockets["tcp"]) == 2, sockets                          # the web port and the ZMQ port
    assert all(address == "127.0.0.1" for address, _ in sockets["tcp"]), sockets
    assert ("127.0.0.1", served.port) in sockets["tcp"]
    assert sockets["udp"] == [], sockets
    assert reachable("127.0.0.1", served.port)
    assert not reachable("::1", served.port)
    others = machine_addresses()
    if not others:
        pytest.skip("this machine has only loopback addresses: nothing else to probe")
    assert [a for a in others if reachable(a, served.port)] == []


def test_websocket_needs_the_pages_own_origin(served: Served, cell_path: Path) -> None:
    port = served.port
    foreign = [
        {},                                                           # no Origin: not a browser page
        {"Origin": "http://evil.example"},
        {"Origin": f"http://127.0.0.1:{port + 1}"},
        {"Origin": "null"},
        {"Sec-WebSocket-Origin": f"http://127.0.0.1:{port}"},         # the pre-RFC name does not count
        # A page that rebinds its own name to 127.0.0.1: same-origin to the browser, not to us.
        {"Origin": f"http://evil.example:{port}", "Host": f"evil.example:{port}"},
        {"Origin": f"http://evil.example:{port}", "Host": f"evil.example:{port}", "Sec-Fetch-Site": "same-origin"},
    ]
    for headers in foreign:
        status, s = handshake(port, headers)
        with s:
            assert status == 403, headers
    want = expected_objects(cell_path)
    assert len(want) > 5
    for origin in (f"http://127.0.0.1:{port}", f"http://localhost:{port}"):
        status, s = handshake(port, {"Origin": origin})
        with s:
            assert status == 101, origin
            assert scene_paths(s, want) == want


def test_serves_only_the_viewer(served: Served) -> None:
    status, page = get(served.port, "/static/")
    assert status == 200 and b"MeshCat.Viewer" in page and b'src="main.min.js"' in page
    assert get(served.port, "/static/index.html") == (200, page)
    status, script = get(served.port, "/static/main.min.js")
    assert status == 200 and len(script) > 100_000
    for path in ("/static/main.js", "/static/animation-dev.html", "/static/main.min.js.LICENSE.txt",
                 "/static/.gitignore", "/static/..%2f..%2fservers%2fzmqserver.py", "/static/../__init__.py",
                 "/static", "/index.html", "/static/viewer/", "/favicon.ico/x"):
        assert get(served.port, path)[0] == 404, path
    assert get(served.port, "/favicon.ico") == (204, b"")               # browsers ask by themselves
    assert get(served.port, "/")[0] == 403                            # the WebSocket's path, no Origin


@pytest.mark.slow
def test_ctrl_c_ends_the_command_and_its_server(serve_preview: Callable[..., Served], cell_path: Path, free_port: FreePort) -> None:
    served = serve_preview(cell_path, "--port", str(free_port()))
    code, printed = served.stop()
    assert code == 0 and "preview stopped" in printed
    assert not reachable("127.0.0.1", served.port)
    if sys.platform.startswith("linux"):
        assert group_sockets(served.proc.pid) == {"tcp": [], "udp": []}


@pytest.mark.slow
@linux_only
def test_a_killed_command_leaves_no_server(serve_preview: Callable[..., Served], cell_path: Path, free_port: FreePort) -> None:
    """SIGKILL to the command alone (not its group): the server sees its stdin close and stops."""
    import select

    served = serve_preview(cell_path, "--port", str(free_port()))
    (server,) = [int(p.name) for p in Path("/proc").iterdir()
                 if p.name.isdigit() and p.name != str(served.proc.pid) and _pgid(p) == served.proc.pid]
    server_fd = os.pidfd_open(server)
    try:
        served.proc.kill()
        served.proc.wait()
        select.select([server_fd], [], [])            # a pidfd turns readable when its process ends
    finally:
        os.close(server_fd)
    assert not reachable("127.0.0.1", served.port)


def _pgid(proc: Path) -> int:
    try:
        return int((proc / "stat").read_text().rsplit(")", 1)[1].split()[2])
    except (FileNotFoundError, ProcessLookupError):
        return -1


@pytest.mark.slow
@linux_only
def test_host_0_0_0_0_warns_and_keeps_zmq_on_loopback(serve_preview: Callable[..., Served], cell_path: Path,
                                                     free_port: FreePort) -> None:
    port = free_port("0.0.0.0")
    served = serve_preview(cell_path, "--host", "0.0.0.0", "--port", str(port))
    assert served.url == f"http://0.0.0.0:{port}/static/"
    sockets = group_sockets(served.proc.pid)
    assert [s for s in sockets["tcp"] if s[1] == port] == [("0.0.0.0", port)], sockets
    zmq = [s for s in sockets["tcp"] if s[1] != port]
    assert len(zmq) == 1 and zmq[0][0] == "127.0.0.1", sockets
    status, s = handshake(port, {"Origin": "http://evil.example"})
    s.close()
    assert status == 403
    status, s = handshake(port, {})
    s.close()
    assert status == 403
    others = [a for a in machine_addresses() if ":" not in a]
    if others:
        # The port is open to the network now, and a page opened by the machine's address may connect.
        assert reachable(others[0], port)
        status, s = handshake(port, {"Origin": f"http://{others[0]}:{port}"}, address=others[0])
        s.close()
        assert status == 101
    code, _ = served.stop()
    assert code == 0
    warning = " ".join(served.stderr().split())
    assert "warning: --host 0.0.0.0: the preview listens on every interface of this machine" in warning
    assert "see the cell" in warning


@pytest.mark.slow
def test_a_loopback_host_does_not_warn(serve_preview: Callable[..., Served], cell_path: Path, free_port: FreePort) -> None:
    served = serve_preview(cell_path, "--host", "localhost", "--port", str(free_port()))
    assert served.url == f"http://localhost:{served.port}/static/"
    status, s = handshake(served.port, {"Origin": f"http://localhost:{served.port}"})
    s.close()
    assert status == 101
    assert served.stop()[0] == 0
    assert "warning: --host" not in served.stderr()      # (the small cell's zero clearance is noted)


def test_a_host_or_port_it_cannot_listen_on_is_one_line(cell_path: Path) -> None:
    foreign = "198.51.100.254"                                          # TEST-NET-2, no interface of ours
    result = runner.invoke(app, ["preview", str(cell_path), "--host", foreign])
    assert result.exit_code == EXIT_BAD_INPUT, result.output
    text = " ".join(result.output.split())
    assert f"error: cannot listen on {foreign}" in text and "Traceback" not in text and "warning: --host" not in text
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        result = runner.invoke(app, ["preview", str(cell_path), "--port", str(port)])
    assert result.exit_code == EXIT_BAD_INPUT, result.output
    assert f"error: cannot listen on 127.0.0.1 port {port}: Address already in use" in " ".join(result.output.split())
    result = runner.invoke(app, ["preview", str(cell_path), "--host", ""])
    assert result.exit_code == EXIT_BAD_INPUT and "no address given" in result.output, result.output


def test_html_takes_no_host(cell_path: Path, tmp_path: Path) -> None:
    result = runner.invoke(app, ["preview", str(cell_path), "--html", str(tmp_path / "p.html"), "--host", "0.0.0.0"])
    assert result.exit_code == 2 and not (tmp_path / "p.html").exists()
