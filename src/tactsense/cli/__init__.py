"""The ``tactsense`` command line (:mod:`tactsense.cli.app` mounts the groups)."""

from tactsense.cli.app import app, main

__all__ = ["app", "main"]
