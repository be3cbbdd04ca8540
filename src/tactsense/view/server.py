"""The web server of the browser view: Starlette on uvicorn, frames pushed over a websocket.

Routes
------
``/``                the page (``static/index.html``)
``/static/...``      its script, style and the plotting library (uPlot), all in the
                     package: the page works with no internet
``/ws``              websocket: the layout (with the recent history) on connect, then
                     one JSON message per frame; the page sends playback commands back
``/api/health``      JSON: frames in, pages connected, frames each page missed, memory

Memory stays bounded however long the stream runs: the feed keeps at most
:data:`~tactsense.view.feed.MAX_HISTORY` recent frames for new pages, the hand-over
from the feed's thread to the event loop holds at most :data:`PENDING` messages, and
each page has a queue of at most :data:`QUEUE` messages; a page that cannot keep up
loses its oldest frames (counted in ``/api/health`` and shown on the page), never
the server's memory.
"""

from __future__ import annotations

import asyncio
import contextlib
import ipaddress
import json
import resource
import socket
import threading
import time
from collections import deque
from importlib import resources

from starlette.applications import Starlette
from starlette.responses import FileResponse, JSONResponse
from starlette.routing import Mount, Route, WebSocketRoute
from starlette.staticfiles import StaticFiles
from starlette.websockets import WebSocket, WebSocketDisconnect

from tactsense.view.feed import Feed

QUEUE = 256
"""Messages waiting for one page at most; older ones are dropped first."""

PENDING = 1024
"""Messages waiting to enter the event loop at most."""


def static_dir():
    return resources.files("tactsense.view") / "static"


class _Page:
    """One connected page: its queue and the frames it missed."""

    def __init__(self) -> None:
        self.queue: asyncio.Queue[str] = asyncio.Queue(maxsize=QUEUE)
        self.dropped = 0
        self.sent = 0


class Hub:
    """Passes the feed's messages to every page, never holding more than a bounded number."""

    def __init__(self) -> None:
        self.pages: set[_Page] = set()
        self.published = 0
        self.dropped_pending = 0
        self._pending: deque[str] = deque()
        self._scheduled = False
        self._guard = threading.Lock()
        self._loop: asyncio.AbstractEventLoop | None = None

    def bind(self, loop: asyncio.AbstractEventLoop) -> None:
        self._loop = loop

    def publish(self, text: str) -> None:
        """Thread-safe: queue ``text`` for every page."""
        if self._loop is None:
            return
        with self._guard:
            if len(self._pending) >= PENDING:
                self._pending.popleft()
                self.dropped_pending += 1
            self._pending.append(text)
            if self._scheduled:
                return
            self._scheduled = True
        with contextlib.suppress(RuntimeError):  # the loop closed: shutting down
            self._loop.call_soon_threadsafe(self._drain)

    def _drain(self) -> None:
        with self._guard:
            texts = list(self._pending)
            self._pending.clear()
            self._scheduled = False
        for text in texts:
            self.published += 1
            for page in self.pages:
                if page.queue.full():
                    page.queue.get_nowait()
                    page.dropped += 1
                page.queue.put_nowait(text)


def create_app(feed: Feed) -> Starlette:
    """The ASGI application showing ``feed``; the feed starts and stops with it."""
    hub = Hub()

    @contextlib.asynccontextmanager
    async def lifespan(app):
        hub.bind(asyncio.get_running_loop())
        feed.start(hub.publish)
        try:
            yield
        finally:
            feed.stop()

    async def index(request):
        return FileResponse(str(static_dir() / "index.html"))

    async def health(request):
        usage = resource.getrusage(resource.RUSAGE_SELF)
        return JSONResponse(
            {
                "feed": feed.health(),
                "published": hub.published,
                "dropped_before_pages": hub.dropped_pending,
                "pages": [{"sent": p.sent, "dropped": p.dropped} for p in hub.pages],
                "max_rss_mb": usage.ru_maxrss / 1024.0,
                "rss_mb": _rss_mb(),
            }
        )

    async def stream(websocket: WebSocket):
        await websocket.accept()
        page = _Page()
        hub.pages.add(page)

        async def send() -> None:
            while True:
                text = await page.queue.get()
                await websocket.send_text(text)
                page.sent += 1

        sender = None
        try:
            await websocket.send_text(json.dumps(feed.layout(), allow_nan=False))
            sender = asyncio.create_task(send())
            while True:
                try:
                    message = await websocket.receive_json()
                except (ValueError, KeyError):
                    continue  # not a command: ignore it, keep the page
                if isinstance(message, dict):
                    feed.command(message)
        except WebSocketDisconnect:
            pass
        finally:
            hub.pages.discard(page)
            if sender is not None:
                sender.cancel()
                with contextlib.suppress(asyncio.CancelledError, Exception):
                    await sender

    return Starlette(
        routes=[
            Route("/", index),
            Route("/api/health", health),
            WebSocketRoute("/ws", stream),
            Mount("/static", app=StaticFiles(directory=str(static_dir())), name="static"),
        ],
        lifespan=lifespan,
    )


def _rss_mb() -> float:
    """Resident memory of this process now [MB] (Linux; NaN elsewhere)."""
    try:
        with open("/proc/self/statm") as statm:
            pages = int(statm.read().split()[1])
    except (OSError, ValueError, IndexError):
        return float("nan")
    return pages * resource.getpagesize() / 2**20


def is_loopback(host: str) -> bool:
    """Whether ``host`` names this machine only (127.0.0.0/8, ::1, localhost)."""
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def bind_socket(host: str, port: int) -> socket.socket:
    """A listening TCP socket on ``host:port`` (port 0: a free one), made before serving so
    the address can be printed and nothing else can take the port meanwhile."""
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    sock = socket.socket(family, socket.SOCK_STREAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        sock.bind((host, port))
    except OSError:
        sock.close()
        raise
    sock.listen(128)
    sock.set_inheritable(True)
    return sock


def url_of(sock: socket.socket) -> str:
    host, port = sock.getsockname()[:2]
    if ":" in host:
        host = f"[{host}]"
    return f"http://{host}:{port}/"


class ViewServer:
    """Serve the view of ``feed`` on ``host:port`` with uvicorn (in this thread or another).

    Examples
    --------
    >>> server = ViewServer(feed)                    # doctest: +SKIP
    >>> server.start()        # in a background thread
    >>> print(server.url)                             # doctest: +SKIP
    >>> server.stop()
    """

    def __init__(self, feed: Feed, *, host: str = "127.0.0.1", port: int = 0):
        import uvicorn

        self.feed = feed
        self.socket = bind_socket(host, port)
        self.url = url_of(self.socket)
        config = uvicorn.Config(
            create_app(feed), log_level="warning", lifespan="on", ws="websockets-sansio"
        )
        self._server = uvicorn.Server(config)
        self._thread: threading.Thread | None = None

    def run(self) -> None:
        """Serve until :meth:`stop` or Ctrl-C (uvicorn's signal handling)."""
        try:
            self._server.run(sockets=[self.socket])
        finally:
            self.socket.close()

    def start(self, wait_s: float = 10.0) -> None:
        """Serve in a background thread; returns once the server accepts connections."""
        self._thread = threading.Thread(target=self.run, name="tactsense-view", daemon=True)
        self._thread.start()
        deadline = time.perf_counter() + wait_s
        while not self._server.started and time.perf_counter() < deadline:
            if not self._thread.is_alive():
                raise RuntimeError("the view server stopped while starting")
            time.sleep(0.02)
        if not self._server.started:
            raise RuntimeError(f"the view server did not start within {wait_s:g} s")

    def stop(self, wait_s: float = 5.0) -> None:
        self._server.should_exit = True
        if self._thread is not None:
            self._thread.join(wait_s)
