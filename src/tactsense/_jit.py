"""Numba compilation with an on-disk cache where one can be written, and without one
where none can (a read-only install and an unwritable ``$HOME``).

Numba raises ``RuntimeError: cannot cache function`` at decoration time when it finds
no writable cache folder, which would make ``import tactsense`` fail. Here such a
function is compiled without the cache instead: slower on the first call of each
process, never broken.
"""

from __future__ import annotations

from numba import njit


def jit(**options):
    """``numba.njit(cache=True, **options)``, falling back to ``cache=False``."""

    def decorate(function):
        try:
            return njit(cache=True, **options)(function)
        except RuntimeError as error:
            if "cannot cache" not in str(error):
                raise
            return njit(cache=False, **options)(function)

    return decorate
