"""The whole hand in one compiled call (Numba): every patch's contacts, their places in
the link and base frames, the wrench per link and the grasp's total, for a block of hand
frames.

A hand frame is every taxel of the skin in one flat vector (the patches in skin order,
each patch's taxels row by row). Per patch the mathematics is the single-array
estimator's (:func:`~tactsense.estimate.contacts.find_contacts`, method
``interpolate``, a fixed baseline): the pads through the same compiled passes
(``segment_into``, ``amplitude_fit``, ``merged_force``), or, for a pad patch of a
locator built with ``method="joint"``, its contacts as the joint fit gave them outside
this call (:data:`MODE_GIVEN`: placed and summed here like any other), the point sets through
:mod:`._robot_points` (the neighbour graph's segmentation and the quadratic peak of
``estimate.contacts.points``, compiled). The forward kinematics are URDF's, as
:meth:`tactsense.robot.RobotSkin.link_poses`.
"""

from __future__ import annotations

import math

import numpy as np

from tactsense._jit import jit
from tactsense.estimate._robot_points import points_patch
from tactsense.estimate.contacts._fast import amplitude_fit, merged_force, segment_into
from tactsense.estimate.finger._fast import taxel_signal

# columns of the float output of each contact row (CONTACT_FLOAT) and the int one
F_ROW, F_COL, F_XS, F_YS, F_ZS = 0, 1, 2, 3, 4
F_XL, F_YL, F_ZL, F_NXL, F_NYL, F_NZL = 5, 6, 7, 8, 9, 10
F_XB, F_YB, F_ZB, F_NXB, F_NYB, F_NZB = 11, 12, 13, 14, 15, 16
F_FORCE, F_PEAK = 17, 18
F_RADIUS, F_FLAT = 19, 20  # the joint fit's contact radius [mm] and flat share (else NaN)
N_FLOAT = 21
I_FRAME, I_PATCH, I_LINK, I_RANK, I_TAXELS, I_FLAGS = 0, 1, 2, 3, 4, 5
N_INT = 6

# columns of a patch's float parameters
P_THRESHOLD, P_SADDLE, P_FLOOR, P_RING, P_WEAK, P_FAR, P_COVER = 0, 1, 2, 3, 4, 5, 6
P_FULL_SCALE, P_RESISTIVE, P_FALLING, P_PER_COUNT = 7, 8, 9, 10
P_NOISE_VAR, P_MERGE_FLOOR, P_KERNEL_TOTAL, P_ROW_PITCH, P_COL_PITCH = 11, 12, 13, 14, 15
N_PARAM = 16

MODE_PAD = 0
MODE_POINTS = 1
MODE_GIVEN = 2  # a pad whose contacts were found before the call (the joint fit)


@jit(nogil=True)
def link_poses_into(q, parent, jtype, origin, axis, column, poses):
    """Every link's 4 x 4 pose in the base frame for one joint state ``q`` (URDF): links in
    tree order, ``parent[l]`` (-1: the base), ``jtype[l]`` (0 fixed, 1 revolute or
    continuous, 2 prismatic), ``origin[l]`` the joint's origin, ``axis[l]`` its unit
    axis, ``column[l]`` its position's index in ``q`` (-1: held at 0)."""
    n_links = parent.shape[0]
    motion = np.empty((4, 4))
    for link in range(n_links):
        if parent[link] < 0:
            poses[link] = np.eye(4)
            continue
        value = q[column[link]] if column[link] >= 0 else 0.0
        for i in range(4):
            for j in range(4):
                motion[i, j] = 1.0 if i == j else 0.0
        x, y, z = axis[link, 0], axis[link, 1], axis[link, 2]
        if jtype[link] == 1:  # Rodrigues: I + sin K + (1 - cos) K^2
            s = math.sin(value)
            c1 = 1.0 - math.cos(value)
            motion[0, 0] = 1.0 - c1 * (y * y + z * z)
            motion[1, 1] = 1.0 - c1 * (x * x + z * z)
            motion[2, 2] = 1.0 - c1 * (x * x + y * y)
            motion[0, 1] = -s * z + c1 * x * y
            motion[1, 0] = s * z + c1 * x * y
            motion[0, 2] = s * y + c1 * x * z
            motion[2, 0] = -s * y + c1 * x * z
            motion[1, 2] = -s * x + c1 * y * z
            motion[2, 1] = s * x + c1 * y * z
        elif jtype[link] == 2:
            motion[0, 3] = x * value
            motion[1, 3] = y * value
            motion[2, 3] = z * value
        poses[link] = poses[parent[link]] @ origin[link] @ motion


@jit(inline="always")
def _place(out_f, row, pose_link, pose_base, xs, ys, zs, nx, ny, nz):
    """Write a contact's sensor-frame point [mm] and normal into the link frame (patch
    pose ``pose_link``, metres) and the base frame (``pose_base``), in mm."""
    for i in range(3):
        out_f[row, F_XL + i] = (
            pose_link[i, 0] * xs + pose_link[i, 1] * ys + pose_link[i, 2] * zs
            + 1e3 * pose_link[i, 3]
        )  # fmt: skip
        out_f[row, F_NXL + i] = pose_link[i, 0] * nx + pose_link[i, 1] * ny + pose_link[i, 2] * nz
        out_f[row, F_XB + i] = (
            pose_base[i, 0] * xs + pose_base[i, 1] * ys + pose_base[i, 2] * zs
            + 1e3 * pose_base[i, 3]
        )  # fmt: skip
        out_f[row, F_NXB + i] = pose_base[i, 0] * nx + pose_base[i, 1] * ny + pose_base[i, 2] * nz


@jit(nogil=True)
def pad_patch(
    signal, counts_rail, param, k_amp, amp_step, k_sig, sig_step, k_max, halves,
    max_contacts, tolerance, max_iterations, pair_ridge, merged_gain, merged_spread,
    frame_flags, saturated_flag, not_converged_flag, edge_flag,
    out_rc, out_value, out_force, out_taxels, out_flags, out_count,
):  # fmt: skip
    """The contacts of one pad over ``n`` frames of its signal (n, rows, cols), as
    ``find_contacts(..., method="interpolate")``: row and column [taxel] in ``out_rc``
    (n, K, 2), interpolated peak, force [N], taxels, flags, count per frame."""
    n, rows, cols = signal.shape
    k = max_contacts
    peak_row = np.empty((n, k), np.int64)
    peak_col = np.empty((n, k), np.int64)
    row = np.empty((n, k))
    col = np.empty((n, k))
    total = np.empty((n, k))
    rr = np.empty((n, k))
    cc = np.empty((n, k))
    rc = np.empty((n, k))
    converged = np.empty((n, k), np.bool_)
    root = np.empty((n, k), np.int64)
    wide = np.zeros((n, k), np.bool_)
    labels = np.empty((n, rows, cols), np.int64)
    segment_into(
        signal, param[P_THRESHOLD], param[P_SADDLE], False, k, True, tolerance,
        max_iterations, out_count, peak_row, peak_col, row, col, out_value, total, rr, cc, rc,
        out_taxels, converged, root, labels, param[P_FLOOR], param[P_RING], param[P_WEAK],
        wide, param[P_FAR], pair_ridge, int(param[P_COVER]),
    )  # fmt: skip
    m = 0
    for f in range(n):
        m += out_count[f]
    frame_of = np.empty(m, np.int64)
    r_flat = np.empty(m)
    c_flat = np.empty(m)
    root_flat = np.empty(m, np.int64)
    rr_flat = np.empty(m)
    cc_flat = np.empty(m)
    rc_flat = np.empty(m)
    force = np.empty(m)
    i = 0
    for f in range(n):
        for j in range(out_count[f]):
            frame_of[i] = f
            r_flat[i] = row[f, j]
            c_flat[i] = col[f, j]
            root_flat[i] = root[f, j]
            rr_flat[i] = rr[f, j]
            cc_flat[i] = cc[f, j]
            rc_flat[i] = rc[f, j]
            i += 1
    amplitude_fit(
        signal, labels, frame_of, root_flat, r_flat, c_flat, k_amp, amp_step,
        (k_amp.shape[2] - 1) // 2, force,
    )  # fmt: skip
    merged_force(
        signal, labels, frame_of, root_flat, r_flat, c_flat, rr_flat, cc_flat, rc_flat, k_sig,
        sig_step, (k_sig.shape[2] - 1) // 2, halves, param[P_NOISE_VAR], merged_gain,
        param[P_MERGE_FLOOR], param[P_THRESHOLD], merged_spread, force, k_max,
    )  # fmt: skip
    i = 0
    for f in range(n):
        for j in range(out_count[f]):
            value = force[i]
            if wide[f, j]:
                value = total[f, j] / param[P_KERNEL_TOTAL]
            flag = frame_flags[f]
            if not converged[f, j]:
                flag |= not_converged_flag
            u, v = row[f, j], col[f, j]
            if u < 0.5 or u > rows - 1.5 or v < 0.5 or v > cols - 1.5:
                flag |= edge_flag
            if flag & saturated_flag:  # no force for a contact holding a clipped reading
                clipped = False
                for a in range(rows):
                    for b in range(cols):
                        if labels[f, a, b] == root[f, j] and counts_rail[f, a, b]:
                            clipped = True
                if clipped:
                    value = np.nan
                else:
                    flag &= ~saturated_flag
            out_rc[f, j, 0] = u
            out_rc[f, j, 1] = v
            out_force[f, j] = value
            out_flags[f, j] = flag
            i += 1


@jit()  # holds the GIL: a live loop's reader threads would keep it for a switch interval
def hand_block(
    counts, fresh, q, parent, jtype, origin, axis, column,
    p_mode, p_offset, p_rows, p_cols, p_link, p_kernel, p_param, p_pose, p_graph_offset,
    baseline, unusable, normals, positions, neighbours, nb_offset, pt_kernel, pt_kernel_offset,
    k_amp, amp_step, k_sig, sig_step, k_max, halves,
    max_contacts, tolerance, max_iterations, pair_ridge, merged_gain, merged_spread, flag_bits,
    held, held_count, out_i, out_f, wrench_link, wrench_total, contacts_link,
    given_start, given_count, given_rc, given_value, given_force, given_taxels, given_flags,
    given_size,
):  # fmt: skip
    """Contacts and wrenches of ``n`` hand frames.

    ``counts`` (n, T) [counts]; ``fresh`` (n, P): the patch has a new frame (else its
    contacts are not written again and its last wrench is held, ``held`` (P, 6): force
    [N] and torque [N mm] in its link's frame about the link's origin, ``held_count`` (P,)
    its contacts); ``q`` (n, J)
    joint positions [rad or m]. Contact rows go to ``out_i``/``out_f`` (their number is
    returned; -1 when they do not fit); ``wrench_link`` (n, L, 6) per link in its own
    frame, ``wrench_total`` (n, 6) the grasp's total in the base frame about the base
    origin [N, N mm], ``contacts_link`` (n, L) contacts held on each link.

    A :data:`MODE_GIVEN` patch's contacts come in ``given_*``: its ``i``-th new frame
    is slot ``given_start[p] + i`` with ``given_count`` contacts, their row and column
    [taxel] (S, K, 2), peak, force [N], taxels, flags and (radius [mm], flat share) in
    ``given_size`` (S, K, 2).
    """
    nan_flag, sat_flag, dead_flag, nc_flag, edge_flag = (
        flag_bits[0], flag_bits[1], flag_bits[2], flag_bits[3], flag_bits[4]
    )  # fmt: skip
    n = counts.shape[0]
    n_patches = p_offset.shape[0]
    n_links = parent.shape[0]
    k = max_contacts
    poses = np.empty((n, n_links, 4, 4))
    for f in range(n):
        link_poses_into(q[f], parent, jtype, origin, axis, column, poses[f])
    patch_wrench = np.empty((n, n_patches, 6))
    patch_contacts = np.zeros((n, n_patches), np.int64)
    written = 0
    for p in range(n_patches):
        rows, cols, off = p_rows[p], p_cols[p], p_offset[p]
        size = rows * cols
        param = p_param[p]
        link = p_link[p]
        pose_link = p_pose[p]
        # the frames of this patch that are new, as a block (n_new, rows, cols)
        n_new = 0
        for f in range(n):
            if fresh[f, p]:
                n_new += 1
        if n_new == 0:  # nothing new: its last wrench held through the block
            for f in range(n):
                for c in range(6):
                    patch_wrench[f, p, c] = held[p, c]
                patch_contacts[f, p] = held_count[p]
            continue
        which = np.empty(n_new, np.int64)
        given = p_mode[p] == MODE_GIVEN
        signal = np.empty((0 if given else n_new, rows, cols))
        rail = np.zeros((n_new, rows, cols), np.bool_)
        frame_flags = np.zeros(n_new, np.int64)
        any_unusable = False
        for t in range(size):
            if unusable[off + t]:
                any_unusable = True
        i = 0
        for f in range(n):
            if not fresh[f, p]:
                continue
            which[i] = f
            flag = dead_flag if any_unusable else 0
            for t in range(0 if given else size):
                value = float(counts[f, off + t])
                d, bits = taxel_signal(
                    value, baseline[off + t], unusable[off + t], param[P_FULL_SCALE],
                    param[P_RESISTIVE] > 0, param[P_FALLING] > 0, param[P_PER_COUNT],
                    nan_flag, sat_flag, dead_flag,
                )  # fmt: skip
                flag |= bits
                signal[i, t // cols, t % cols] = d
                if bits & sat_flag:
                    rail[i, t // cols, t % cols] = True
            frame_flags[i] = flag
            i += 1
        rc = np.empty((n_new, k, 2))
        value = np.empty((n_new, k))
        force = np.empty((n_new, k))
        taxels = np.empty((n_new, k), np.int64)
        flags = np.empty((n_new, k), np.int64)
        count = np.zeros(n_new, np.int64)
        point = np.empty((n_new, k, 3))
        normal_at = np.empty((n_new, k), np.int64)
        size_of = np.full((n_new, k, 2), np.nan)
        if given:
            for f in range(n_new):
                slot = given_start[p] + f
                count[f] = given_count[slot]
                for j in range(count[f]):
                    rc[f, j, 0] = given_rc[slot, j, 0]
                    rc[f, j, 1] = given_rc[slot, j, 1]
                    value[f, j] = given_value[slot, j]
                    force[f, j] = given_force[slot, j]
                    taxels[f, j] = given_taxels[slot, j]
                    flags[f, j] = given_flags[slot, j]
                    size_of[f, j, 0] = given_size[slot, j, 0]
                    size_of[f, j, 1] = given_size[slot, j, 1]
        elif p_mode[p] == MODE_PAD:
            pad_patch(
                signal, rail, param, k_amp[p_kernel[p]], amp_step, k_sig[p_kernel[p]], sig_step,
                k_max[p_kernel[p]], halves, k, tolerance, max_iterations, pair_ridge,
                merged_gain, merged_spread, frame_flags, sat_flag, nc_flag, edge_flag,
                rc, value, force, taxels, flags, count,
            )  # fmt: skip
        if p_mode[p] != MODE_POINTS:
            for f in range(n_new):
                for j in range(count[f]):
                    point[f, j, 0] = rc[f, j, 0] * param[P_ROW_PITCH]
                    point[f, j, 1] = rc[f, j, 1] * param[P_COL_PITCH]
                    point[f, j, 2] = 0.0
                    a = min(max(np.int64(rc[f, j, 0] + 0.5), 0), rows - 1)
                    b = min(max(np.int64(rc[f, j, 1] + 0.5), 0), cols - 1)
                    normal_at[f, j] = a * cols + b
        else:
            g0 = p_graph_offset[p]
            points_patch(
                signal, rail, param[P_THRESHOLD], param[P_SADDLE], param[P_FLOOR], k,
                positions[off : off + size], normals[off : off + size],
                nb_offset[g0 : g0 + size + 1], neighbours,
                pt_kernel[pt_kernel_offset[p] : pt_kernel_offset[p] + size * size],
                frame_flags, sat_flag, nc_flag, point, value, force, taxels, flags, count,
                normal_at,
            )  # fmt: skip
            for f in range(n_new):
                for j in range(count[f]):
                    rc[f, j, 0] = np.nan
                    rc[f, j, 1] = np.nan
        # rows, and each new frame's wrench in the link frame about its origin
        i = 0
        for f in range(n):
            if not fresh[f, p]:
                for c in range(6):
                    patch_wrench[f, p, c] = held[p, c]
                patch_contacts[f, p] = held_count[p]
                continue
            for c in range(6):
                held[p, c] = 0.0
            held_count[p] = count[i]
            pose_base = poses[f, link] @ pose_link
            for j in range(count[i]):
                if written >= out_i.shape[0]:
                    return -1
                row = written
                t = off + normal_at[i, j]
                _place(
                    out_f, row, pose_link, pose_base, point[i, j, 0], point[i, j, 1],
                    point[i, j, 2], normals[t, 0], normals[t, 1], normals[t, 2],
                )  # fmt: skip
                out_f[row, F_ROW] = rc[i, j, 0]
                out_f[row, F_COL] = rc[i, j, 1]
                out_f[row, F_XS] = point[i, j, 0]
                out_f[row, F_YS] = point[i, j, 1]
                out_f[row, F_ZS] = point[i, j, 2]
                out_f[row, F_FORCE] = force[i, j]
                out_f[row, F_PEAK] = value[i, j]
                out_f[row, F_RADIUS] = size_of[i, j, 0]
                out_f[row, F_FLAT] = size_of[i, j, 1]
                out_i[row, I_FRAME] = f
                out_i[row, I_PATCH] = p
                out_i[row, I_LINK] = link
                out_i[row, I_RANK] = j
                out_i[row, I_TAXELS] = taxels[i, j]
                out_i[row, I_FLAGS] = flags[i, j]
                written += 1
                if math.isfinite(force[i, j]):  # pressing inward: -force along the normal
                    fx = -force[i, j] * out_f[row, F_NXL]
                    fy = -force[i, j] * out_f[row, F_NYL]
                    fz = -force[i, j] * out_f[row, F_NZL]
                    x, y, z = out_f[row, F_XL], out_f[row, F_YL], out_f[row, F_ZL]
                    held[p, 0] += fx
                    held[p, 1] += fy
                    held[p, 2] += fz
                    held[p, 3] += y * fz - z * fy
                    held[p, 4] += z * fx - x * fz
                    held[p, 5] += x * fy - y * fx
            for c in range(6):
                patch_wrench[f, p, c] = held[p, c]
            patch_contacts[f, p] = count[i]
            i += 1
    # per link, and the total in the base frame (about the base origin)
    for f in range(n):
        for link in range(n_links):
            for c in range(6):
                wrench_link[f, link, c] = 0.0
            contacts_link[f, link] = 0
        for p in range(n_patches):
            link = p_link[p]
            contacts_link[f, link] += patch_contacts[f, p]
            for c in range(6):
                wrench_link[f, link, c] += patch_wrench[f, p, c]
        for c in range(6):
            wrench_total[f, c] = 0.0
        for link in range(n_links):
            pose = poses[f, link]
            w = wrench_link[f, link]
            fb0 = pose[0, 0] * w[0] + pose[0, 1] * w[1] + pose[0, 2] * w[2]
            fb1 = pose[1, 0] * w[0] + pose[1, 1] * w[1] + pose[1, 2] * w[2]
            fb2 = pose[2, 0] * w[0] + pose[2, 1] * w[1] + pose[2, 2] * w[2]
            px, py, pz = 1e3 * pose[0, 3], 1e3 * pose[1, 3], 1e3 * pose[2, 3]
            wrench_total[f, 0] += fb0
            wrench_total[f, 1] += fb1
            wrench_total[f, 2] += fb2
            wrench_total[f, 3] += (
                pose[0, 0] * w[3] + pose[0, 1] * w[4] + pose[0, 2] * w[5] + py * fb2 - pz * fb1
            )
            wrench_total[f, 4] += (
                pose[1, 0] * w[3] + pose[1, 1] * w[4] + pose[1, 2] * w[5] + pz * fb0 - px * fb2
            )
            wrench_total[f, 5] += (
                pose[2, 0] * w[3] + pose[2, 1] * w[4] + pose[2, 2] * w[5] + px * fb1 - py * fb0
            )
    return written
