"""The sensor in a browser: ``tactsense view`` serves a page that shows a live stream or a
recording as it plays (heat map, interpolated surface, contact, traces, stream health):
a finger unwrapped, a pad as a flat grid in millimetres, a point set as dots.

:class:`LiveFeed` and :class:`RecordingFeed` turn frames into messages;
:class:`ViewServer` serves them (Starlette on uvicorn, websocket push).
"""

from tactsense.view.feed import LiveFeed, RecordingFeed
from tactsense.view.layout import layout_message
from tactsense.view.locators import DeflectionOnly, view_locator
from tactsense.view.server import ViewServer, create_app

__all__ = [
    "DeflectionOnly",
    "LiveFeed",
    "RecordingFeed",
    "ViewServer",
    "create_app",
    "layout_message",
    "view_locator",
]
