"""The hand's estimator with ``method="joint"`` (issue 34 item 1 on a robot): each pad
patch's contacts are the single-array joint fit's, placed and summed into wrenches by the
same compiled call; point sets keep theirs; the default path is unchanged."""

from __future__ import annotations

import numpy as np
import pytest

from tactsense._validation import TactsenseInputError
from tactsense.estimate.contacts import find_contacts
from tactsense.estimate.robot import CONTACT_COLUMNS, JOINT_COLUMNS, HandLocator
from tactsense.robot import Patch, Pose, RobotSkin, skin_preset
from tactsense.simulate import ContactBatch, frames_from_contacts
from tests.estimate._robot_sim import hand_frames
from tests.estimate.test_robot_locate import small_skin


@pytest.fixture(scope="module")
def pressed():
    """The chain skin (a 16 x 16 pad and a 12-taxel dome) under random spheres."""
    skin = small_skin()
    sim = hand_frames(skin, 6, seed=1)
    frames = {k: v[0] for k, v in sim.items()}
    baselines = {k: v[1] for k, v in sim.items()}
    return skin, frames, baselines


def _rows(contacts, patch):
    """The rows of one patch, in (frame, rank) order."""
    mine = np.flatnonzero(contacts["patch"] == patch)
    return mine[np.lexsort((contacts["contact"][mine], contacts["frame"][mine]))]


def test_joint_rows_are_find_contacts_joint_and_point_sets_keep_theirs(pressed):
    """A pad patch's rows are find_contacts(method="joint")'s on its frames (same frames,
    ranks, positions, forces, sizes: the same call, so exactly); the dome's rows are the
    default locator's (the point sets have no size-aware fit)."""
    skin, frames, baselines = pressed
    joints = {"j1": 0.3, "j2": -0.2}
    joint = HandLocator(skin, baselines, method="joint")
    default = HandLocator(skin, baselines)
    counts = joint.pack(frames)
    mine = joint.locate(counts, joints).contacts
    theirs = default.locate(counts, joints).contacts
    assert tuple(mine) == JOINT_COLUMNS and tuple(theirs) == CONTACT_COLUMNS
    pad = skin.patch("pad").sensor
    table = find_contacts(frames["pad"], pad, baseline=baselines["pad"], method="joint")
    assert len(table.frame) >= 6  # the simulation pressed the pad in several frames
    rows = _rows(mine, "pad")
    order = np.lexsort((table.contact, table.frame))
    np.testing.assert_array_equal(mine["frame"][rows], table.frame[order])
    assert ((table.row > -0.5) & (table.row < 15.5)).all()  # none off the taxels here
    for column, values in (("x_mm", table.x_mm), ("y_mm", table.y_mm),
                           ("force_n", table.force_n),
                           ("contact_radius_mm", table.extra["contact_radius_mm"]),
                           ("flat_share", table.extra["flat_share"])):  # fmt: skip
        np.testing.assert_array_equal(mine[column][rows], values[order], err_msg=column)
    dome_mine, dome_theirs = _rows(mine, "dome"), _rows(theirs, "dome")
    assert len(dome_mine) > 0
    for column in CONTACT_COLUMNS:
        np.testing.assert_array_equal(mine[column][dome_mine], theirs[column][dome_theirs])
    assert np.isnan(mine["contact_radius_mm"][dome_mine]).all()


def test_joint_wrench_is_the_sum_of_its_contacts_force_vectors(pressed):
    """The grasp's total force per hand frame is the sum of the rows' base-frame force
    vectors (-force_n * normal), summed here independently of the compiled call."""
    skin, frames, baselines = pressed
    locator = HandLocator(skin, baselines, method="joint")
    result = locator.locate(locator.pack(frames), {"j1": -0.4, "j3": 0.01})
    c, w = result.contacts, result.wrenches
    total = w["what"] == "total"
    for a, axis in enumerate("xyz"):
        by_frame = np.bincount(c["frame"], c[f"f{axis}_base_n"], minlength=result.n_frames)
        np.testing.assert_allclose(w[f"force_{axis}_n"][total], by_frame, atol=1e-12)
        np.testing.assert_allclose(result.total[:, a], by_frame, atol=1e-12)
    assert np.abs(result.total[:, :3]).max() > 0.1


def test_a_broad_contacts_force_reads_right_with_joint_and_low_without():
    """A 20-mm-diameter sphere at 2 N on hand4's palm pad (18 x 18, 2-mm pitch), without
    flaws, at three places within a taxel: the grasp's total force with ``joint`` within
    2 % of the truth, against ``interpolate``'s 1.6-mm probe amplitude, which reads it
    50-76 % low here. The 2 % is issue 34 item 1's noise-free goal; measured here -1.7 %,
    0.0 % and 0.0 % (the frames come from the fast forward, the layer's exact spectrum,
    which the fit's tabulated response does not share)."""
    sensor = skin_preset("hand4").patch("palm_0").sensor
    skin = RobotSkin(
        name="palm", base_link="palm", links=("palm",), joints=(),
        patches=(Patch("pad", sensor, "palm", Pose((0.0, 0.0, 0.01), (0.0, 0.3, 0.0))),),
    )  # fmt: skip
    where = np.array([[17.0, 17.0], [17.5, 17.0], [18.0, 18.0]])[:, None, :]
    frames = frames_from_contacts(sensor, ContactBatch(where, np.full((3, 1), 2.0), radius_mm=10.0),
                                  flaws="none")  # fmt: skip
    baseline = frames_from_contacts(sensor, ContactBatch(where[:1], np.zeros((1, 1))), flaws="none")
    baselines = {"pad": baseline.reshape(sensor.shape)}
    force = {}
    for method in ("interpolate", "joint"):
        locator = HandLocator(skin, baselines, method=method)
        total = locator.locate(frames).total
        force[method] = np.linalg.norm(total[:, :3], axis=1)
    np.testing.assert_allclose(force["joint"], 2.0, rtol=0.02)
    assert (force["interpolate"] < 0.6 * 2.0).all()


def test_a_contact_fitted_off_the_taxels_has_no_force_and_adds_nothing(monkeypatch):
    """The hand's rule (OFF_TAXELS), on the joint fit's table as given (the fit itself is
    docs/contacts.md's; scripts/hand_joint_numbers.py measures what it does beyond an
    edge): of two contacts, one fitted at row -1.0 (a pitch beyond the first row) keeps
    its row with a NaN force and adds nothing to the wrench; the one inside keeps its
    force, the wrench is its alone; a contact half a pitch beyond the last column (the
    limit) keeps its force."""
    from tactsense.estimate import contacts
    from tactsense.estimate.results import ContactTable

    sensor = skin_preset("hand4").patch("palm_0").sensor
    cols = sensor.shape[1]
    skin = RobotSkin(name="palm", base_link="palm", links=("palm",), joints=(),
                     patches=(Patch("pad", sensor, "palm", Pose((0.0, 0.0, 0.0))),))  # fmt: skip
    row = np.array([-1.0, 8.0, 3.0])
    col = np.array([4.9, 8.0, cols - 0.5])
    n = len(row)

    def fitted(frames, *args, **kwargs):
        return ContactTable(
            frame=np.zeros(n, np.int64), contact=np.arange(n), x_mm=2 * row, y_mm=2 * col,
            z_mm=np.zeros(n), row=row, col=col, force_n=np.array([120.0, 1.0, 0.5]),
            peak=np.ones(n), major_mm=np.ones(n), minor_mm=np.ones(n),
            orientation_deg=np.zeros(n), taxels=np.full(n, 9), area_mm2=np.ones(n),
            flags=np.array([32, 0, 32]), n_frames=1,
            extra={"contact_radius_mm": np.ones(n), "flat_share": np.zeros(n)},
        )  # fmt: skip

    baseline = np.full(sensor.shape, 100.0)
    locator = HandLocator(skin, {"pad": baseline}, method="joint")
    monkeypatch.setattr(contacts, "find_contacts", fitted)
    result = locator.locate(baseline.reshape(1, -1))
    c = result.contacts
    np.testing.assert_array_equal(c["force_n"], [np.nan, 1.0, 0.5])
    np.testing.assert_array_equal(c["flags"], [32, 0, 32])
    normal = (
        np.array([c[f"n{a}_base"][1] for a in "xyz"])
        + np.array([c[f"n{a}_base"][2] for a in "xyz"]) * 0.5
    )
    np.testing.assert_allclose(result.total[0, :3], -normal, atol=1e-12)


def test_bad_method_is_refused_in_one_line():
    skin = small_skin()
    baselines = {p.name: np.zeros(p.sensor.shape) for p in skin.patches}
    for method in ("fit", "cop", "Joint", None):
        with pytest.raises(TactsenseInputError, match="takes one of interpolate, joint"):
            HandLocator(skin, baselines, method=method)


def test_locate_run_method_joint_writes_the_size_columns_and_its_note(tmp_path):
    """``tactsense locate RUN/ --method joint``: the contacts table has the joint fit's
    size columns (NaN on the dome), its pad rows equal HandLocator(method="joint")'s on
    the recording, and the closing note is the joint one (not the probe caveat)."""
    import pyarrow.parquet
    from typer.testing import CliRunner

    from tactsense.cli import app
    from tactsense.robot_batch import locate_robot_recording
    from tests.estimate._robot_sim import write_pressed_recording

    run = write_pressed_recording(tmp_path / "run", small_skin(), frames=10)
    out = tmp_path / "c.parquet"
    result = CliRunner().invoke(app, ["locate", str(run), "--method", "joint", "--out", str(out)])
    assert result.exit_code == 0, result.output
    text = " ".join(result.output.split())
    assert "fitted each pad patch's contacts with their size" in text
    assert "1.6-mm probe" not in text
    table = pyarrow.parquet.read_table(out).to_pydict()
    assert tuple(table) == JOINT_COLUMNS
    assert sorted(set(table["frame"])) == [5, 6, 7, 8, 9]  # the pad, pressed from frame 5
    again = locate_robot_recording(run, method="joint").contacts
    np.testing.assert_allclose(table["force_n"], again["force_n"], rtol=1e-12)
    assert np.isfinite(table["contact_radius_mm"]).all()
