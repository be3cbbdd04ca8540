"""The finger in a browser: ``tactsense view`` serves a page that shows a live stream or a
recording as it plays (heat map, interpolated surface, contact, traces, stream health).

:class:`LiveFeed` and :class:`RecordingFeed` turn frames into messages;
:class:`ViewServer` serves them (Starlette on uvicorn, websocket push).
"""

from tactsense.view.feed import LiveFeed, RecordingFeed, layout_message
from tactsense.view.server import ViewServer, create_app

__all__ = ["LiveFeed", "RecordingFeed", "ViewServer", "create_app", "layout_message"]
