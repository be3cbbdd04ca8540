"""The plane the page draws a pad or a point set on: the taxels seen from outside, along
their mean normal (:func:`project_points`)."""

from __future__ import annotations

import numpy as np


def project_points(positions_mm: np.ndarray, normals: np.ndarray) -> dict:
    """Taxels projected onto the plane normal to their mean normal, seen from outside.

    An orthographic projection along the mean outward normal ``m`` (``+z`` when the
    normals cancel out): ``u = p . e_u``, ``v = p . e_v`` with ``e_u`` the direction of
    ``+x`` in that plane (``+y`` when ``m`` is along ``x``) and ``e_v = m x e_u``. When
    ``m`` is ``+z`` this is simply ``(x, y)``. Distances within the plane are true [mm];
    distances along a curved surface shrink by the cosine of its slope.

    Parameters
    ----------
    positions_mm : ndarray, shape (N, 3)
        Taxel surface points [mm].
    normals : ndarray, shape (N, 3)
        Outward unit normals [-].

    Returns
    -------
    dict
        ``u_mm``, ``v_mm`` (N,) [mm], the unit vectors ``normal``, ``e_u``, ``e_v`` [-].
    """
    positions = np.asarray(positions_mm, dtype=float).reshape(-1, 3)
    mean = np.asarray(normals, dtype=float).reshape(-1, 3).sum(axis=0)
    size = float(np.linalg.norm(mean))
    m = mean / size if size > 1e-6 * len(positions) else np.array([0.0, 0.0, 1.0])
    e_u = np.array([1.0, 0.0, 0.0]) - m[0] * m
    if np.linalg.norm(e_u) < 1e-6:
        e_u = np.array([0.0, 1.0, 0.0]) - m[1] * m
    e_u /= np.linalg.norm(e_u)
    e_v = np.cross(m, e_u)
    return {
        "u_mm": positions @ e_u,
        "v_mm": positions @ e_v,
        "normal": m,
        "e_u": e_u,
        "e_v": e_v,
    }
