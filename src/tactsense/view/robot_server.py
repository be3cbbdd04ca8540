"""The web server of the hand's view: the single-array view's server
(:func:`tactsense.view.server.create_app`: websocket, health, static files, bounded
queues) with the hand's page (``static/hand.html``) at ``/``."""

from __future__ import annotations

import threading

from starlette.responses import FileResponse
from starlette.routing import Route

from tactsense.view.server import ViewServer, bind_socket, create_app, static_dir, url_of


def create_robot_app(feed):
    """The ASGI application showing a hand's ``feed`` (:mod:`tactsense.view.robot_feed`)."""
    app = create_app(feed)

    async def hand_page(request):
        return FileResponse(str(static_dir() / "hand.html"))

    app.router.routes.insert(0, Route("/", hand_page))  # before the single array's page
    return app


class RobotViewServer(ViewServer):
    """:class:`~tactsense.view.server.ViewServer` serving the hand's page."""

    def __init__(self, feed, *, host: str = "127.0.0.1", port: int = 0):
        import uvicorn

        self.feed = feed
        self.socket = bind_socket(host, port)
        self.url = url_of(self.socket)
        config = uvicorn.Config(
            create_robot_app(feed), log_level="warning", lifespan="on", ws="websockets-sansio"
        )
        self._server = uvicorn.Server(config)
        self._thread: threading.Thread | None = None
