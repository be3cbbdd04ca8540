"""``python -m tactsense``: the same as the ``tactsense`` command."""

from tactsense_launcher import main

main()
