"""`simkit view KIT`: the kit's GLB in the browser, served on 127.0.0.1 only.

The page (`web/index.html`, `web/viewer.js`) and a pinned three.js (`web/vendor/three/`, MIT)
come from the simkit package; everything else from the kit folder (or a kit zip, unpacked to a
temporary folder): robot.json for joints, limits, named poses and frames, the GLB, and
`meshes/collision/*.obj` (older kits: `.stl`) for the collision pieces (the GLB holds the
visual geometry only).
No request leaves the machine. URL layout: `/` the page, `/vendor/...` three.js,
`/kit/PATH` a kit file, `/kit-files.json` the sorted list of kit files.
"""

from __future__ import annotations

import json
import mimetypes
import signal
import tempfile
import threading
from collections.abc import Callable
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from urllib.parse import unquote, urlsplit

from simkit.errors import SimkitError
from simkit.kitio import interrupt

WEB = Path(__file__).resolve().parent / "web"
TYPES = {
    ".html": "text/html; charset=utf-8",
    ".js": "text/javascript; charset=utf-8",
    ".css": "text/css; charset=utf-8",
    ".json": "application/json",
    ".glb": "model/gltf-binary",
    ".stl": "model/stl",
    ".obj": "model/obj",
    ".png": "image/png",
    ".wasm": "application/wasm",  # MuJoCo's WebAssembly build: compiled while it streams
}


#: characters: longer URL paths are answered 404 without touching the file system
MAX_PATH = 1024


def _inside(root: Path, rel: str) -> Path | None:
    """`root/rel` if it is a file inside root (no `..` escapes), else None. A path the file
    system refuses (too long, a name over 255 bytes) is not found either."""
    if len(rel) > MAX_PATH:
        return None
    try:
        path = (root / rel).resolve()
        if path.is_file() and path.is_relative_to(root.resolve()):
            return path
    except (OSError, ValueError):  # ENAMETOOLONG, ELOOP, ...
        return None
    return None


def kit_files(kit: Path) -> list[str]:
    return sorted(
        p.relative_to(kit).as_posix()
        for p in kit.rglob("*")
        if p.is_file() and "__pycache__" not in p.parts
    )


def make_handler(kit: Path) -> type[BaseHTTPRequestHandler]:
    """A request handler serving the page, three.js and the files of `kit`."""

    class Handler(BaseHTTPRequestHandler):
        server_version = "simkit-view"

        def log_message(self, format: str, *args) -> None:  # quiet: no access log
            return

        def _send(self, body: bytes, ctype: str, head: bool) -> None:
            self.send_response(HTTPStatus.OK)
            self.send_header("Content-Type", ctype)
            self.send_header("Content-Length", str(len(body)))
            self.send_header("Cache-Control", "no-store")
            self.end_headers()
            if not head:
                self.wfile.write(body)

        def _serve(self, head: bool) -> None:
            try:
                path = unquote(urlsplit(self.path).path, errors="strict")
            except (UnicodeDecodeError, ValueError):
                return self.send_error(HTTPStatus.BAD_REQUEST, "malformed URL")
            if any(ord(c) < 32 or ord(c) == 127 for c in path):  # %00, %0a, ...
                return self.send_error(HTTPStatus.BAD_REQUEST, "control character in URL")
            if path == "/kit-files.json":
                body = json.dumps(kit_files(kit)).encode()
                return self._send(body, TYPES[".json"], head)
            if path.startswith("/kit/"):
                found = _inside(kit, path[len("/kit/") :])
            else:
                found = _inside(WEB, "index.html" if path == "/" else path.lstrip("/"))
            if found is None:
                return self.send_error(HTTPStatus.NOT_FOUND)
            ctype = TYPES.get(found.suffix) or mimetypes.guess_type(found.name)[0]
            self._send(found.read_bytes(), ctype or "application/octet-stream", head)

        def do_GET(self) -> None:
            self._serve(head=False)

        def do_HEAD(self) -> None:
            self._serve(head=True)

    return Handler


def start_server(kit: Path, port: int = 0) -> ThreadingHTTPServer:
    """Serve `kit` (a kit folder) on 127.0.0.1:`port` (0: any free port) from a daemon
    thread; `server.server_address[1]` is the port, `server.shutdown()` stops it."""
    if not (kit / "robot.json").is_file():
        raise SimkitError(f"{kit}: not a kit folder (no robot.json at its top)")
    try:
        server = ThreadingHTTPServer(("127.0.0.1", port), make_handler(kit.resolve()))
    except OSError as exc:
        raise SimkitError(f"--port {port}: cannot listen on 127.0.0.1 ({exc.strerror})") from None
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return server


def _unzip(path: Path, into: Path) -> Path:
    """Write a kit zip's files under `into`; a zip holding a file and a folder of one name
    (`a` and `a/b`) is refused in one line, before anything is written."""
    from simkit.diff import load_kit

    files = load_kit(path)
    folders = {
        "/".join(name.split("/")[:i]) for name in files for i in range(1, name.count("/") + 1)
    }
    clash = sorted(folders & set(files))
    if clash:
        raise SimkitError(f"{path}: '{clash[0]}' is both a file and a folder in the zip")
    for name, data in files.items():
        target = into / name
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_bytes(data)
    return into


def serve_kit(
    kit: Path, port: int, open_browser: bool = True, say: Callable[[str], None] | None = None
) -> None:
    """`simkit view`: serve until Ctrl-C, opening the page in the default browser."""
    with tempfile.TemporaryDirectory(prefix="simkit-view-") as tmp:
        if kit.is_file():
            folder = _unzip(kit, Path(tmp))
        elif kit.is_dir():
            folder = kit
        else:
            raise SimkitError(f"{kit}: no such kit folder or zip")
        server = start_server(folder, port)
        url = f"http://127.0.0.1:{server.server_address[1]}/"
        try:  # from the "Ctrl-C stops" line on, Ctrl-C is a clean stop
            if say is not None:
                say(f"viewing {kit} at {url} (Ctrl-C stops)")
            if open_browser:
                import webbrowser

                webbrowser.open(url)
            threading.Event().wait()
        except KeyboardInterrupt:  # without the CLI's handlers (the library called directly)
            pass
        except interrupt.Interrupted as stop:  # the CLI: Ctrl-C is the way to stop viewing
            if stop.signum != signal.SIGINT:
                raise
        finally:
            server.shutdown()
            server.server_close()


def pose_pictures(kit: Path) -> dict[str, bytes]:
    """{pose: PNG} of a built kit at each named pose (`simkit render`'s defaults), for the kit
    pages of `simkit publish`."""
    from simkit.review.render import render_kit

    with tempfile.TemporaryDirectory(prefix="simkit-pictures-") as tmp:
        try:
            paths = render_kit(kit, Path(tmp) / "pictures")
        except SimkitError as exc:  # no OpenGL here: say how to publish without pictures
            raise SimkitError(f"{exc}; or publish with --no-pictures") from None
        return {path.stem: path.read_bytes() for path in paths}


def start_site_server(folder: Path, port: int = 0) -> ThreadingHTTPServer:
    """A plain static server of `folder` on 127.0.0.1:`port` (what `python -m http.server -b
    127.0.0.1 -d FOLDER` does, without the access log) from a daemon thread."""
    from functools import partial
    from http.server import SimpleHTTPRequestHandler

    class Quiet(SimpleHTTPRequestHandler):
        def log_message(self, format: str, *args) -> None:
            return

    if not folder.is_dir():
        raise SimkitError(f"{folder}: no such site folder")
    try:
        server = ThreadingHTTPServer(("127.0.0.1", port), partial(Quiet, directory=str(folder)))
    except OSError as exc:
        raise SimkitError(f"--port {port}: cannot listen on 127.0.0.1 ({exc.strerror})") from None
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return server


def serve_site(folder: Path, port: int, say: Callable[[str], None] | None = None) -> None:
    """`simkit publish --serve`: the site folder on 127.0.0.1 until Ctrl-C."""
    server = start_site_server(folder, port)
    try:
        if say is not None:
            say(f"serving {folder} at http://127.0.0.1:{server.server_address[1]}/ (Ctrl-C stops)")
        threading.Event().wait()
    except KeyboardInterrupt:
        pass
    except interrupt.Interrupted as stop:
        if stop.signum != signal.SIGINT:
            raise
    finally:
        server.shutdown()
        server.server_close()
