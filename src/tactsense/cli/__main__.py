"""``python -m tactsense.cli``: the same as the ``tactsense`` command."""

from tactsense.cli.app import main

main()
