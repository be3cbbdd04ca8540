"""A baseline that stays true: it follows slow drift where taxels are untouched.

A fixed baseline (the median of the first untouched frames) goes stale: the skin creeps
under repeated loads and the electronics drift with temperature, so a lifted frame reads
as a light press and, over a long recording, every frame counts as a contact. Robot skins
(iCub's skin manager among them) answer this by letting the baseline of each taxel follow
its reading while the taxel is untouched, and holding it while the taxel is pressed.

:class:`DriftBaseline` does that, frame by frame and causally (the same numbers whether a
recording is read in one piece or in many):

* a taxel is *touched* when its signal (eq. 4 for capacitive taxels, the strain for
  resistive ones) exceeds the contact threshold; on a grid the taxels next to a touched
  one are held too (``guard`` taxels around it), since a load's flank lies below the
  threshold;
* every other taxel's baseline moves toward its reading by ``1 - exp(-T / tau)`` of the
  difference each frame (``T`` the frame period, ``tau`` the time constant), an
  exponential average with time constant ``tau``;
* a held taxel's baseline moves by the mean step of the untouched ones: drift common to
  the array (temperature, supply) goes on under a press, so a long press does not leave
  its taxels a drift behind when it lifts;
* a taxel reading *below* its baseline by more than the threshold, where no tension
  beside a contact can explain it (:func:`below_baseline`: a capacitive taxel beside a
  contact reads tension, up to the contact's peak), says the baseline was taken under
  load (or the load was still on when the baseline was made): such frames are counted
  in :attr:`DriftBaseline.below_frames` and flagged ``BELOW_BASELINE``; the baseline
  follows them down like any untouched taxel;
* where the creep is not known (no ``creep`` to take out), a touched taxel whose signal
  falls quickly to under :data:`RELEASE_SHARE` of its peak is lifted: the creep left
  behind, which would read as a contact for as long as it stays above the threshold
  (a minute on the paper's skin), is taken into its baseline within a fraction of a
  second (:data:`RELEASE_TIME_CONSTANT_S`), until the taxel rises above the threshold
  again (a new touch); and while a taxel is touched, no untouched taxel's baseline
  follows its reading down (a load pulls its neighbours below their baselines on a
  dome, and a baseline taken down under a press reads as a contact after the lift).

:meth:`DriftBaseline.rezero` replaces the baseline by the next frames' median on demand
(a key or a command in ``live`` and ``view``).
"""

from __future__ import annotations

import math

import numpy as np

from tactsense._jit import jit
from tactsense._signals import deferred_interrupts
from tactsense._validation import TactsenseInputError, check_frames
from tactsense.estimate._kind import kind_or_none
from tactsense.estimate.contacts.health import (  # noqa: F401  (their old path)
    CONSTANT_FRAMES,
    ReadingRange,
    health_warning,
    movement_warning,
    sensor_falls,
    taxel_health,
    taxel_names,
)
from tactsense.estimate.creep import CreepCompensator
from tactsense.estimate.finger._fast import taxel_signal
from tactsense.estimate.reading import at_rail, reading_mode, unusable_baseline
from tactsense.estimate.results import Flag

TIME_CONSTANT_S = 2.0
"""Default time constant of the drift-following average [s]. Measured on the paper's
finger under the ``repeated`` scenario (1 s on, 1 s off, 100 times): with 2 s the lifted
frames stop counting as contacts (12 of 707 against 681 with a fixed baseline); with
10 s or more the creep left after each lift outgrows the threshold before the baseline
catches up, and the taxel stays held (``tests/estimate/test_baseline.py``)."""

RELEASE_SHARE = 0.6
"""A touched taxel whose signal falls below this share of its largest over the last
0.25-0.5 s is lifted [-] (creep not compensated). Measured on pad16 with the twin's
creep (``test_the_release_share_parts_a_lift_from_a_load_that_stays`` in
``tests/reliability/test_round3_pads.py``): 0.25 s after a lift the signal is
0.31-0.33 of its peak after a 10-s press and 0.53-0.55 after a 70-s one (the creep
stored, up to ``creep_fraction`` = 1.14 of the elastic response, over the peak, which
also holds the delayed elasticity, 0.538); a force stepped down to half after 60 s
keeps 0.72-0.76 (the delayed elasticity and the creep leave more slowly than the
force); the peak taxel of a probe 8 mm from one that lifts keeps 0.66."""

RELEASE_FRAMES = 2
"""Frames in a row a touched taxel's signal must stay below :data:`RELEASE_SHARE` of its
peak to be taken as lifted [-]. A lift stays; a noise dip does not: with read noise of 1 %
of full scale (fsr16, threshold 5 sigma) a 50-g press's peak taxel, at 2-3 thresholds,
dipped under the share of its noisiest peak (about 2.5 sigma above its mean) in single
frames and lost the last 24 of its 50 frames to the re-zero (``test_round4_lead.py``)."""

RELEASE_WINDOW_S = 0.25
"""The peak :data:`RELEASE_SHARE` is taken of: the largest signal over the last one to
two blocks of this length [s]. Long enough to span a lift (the delayed elasticity, 0.042
s on the paper's skin, is gone in 0.2 s) and short enough that a slow fall (the creep of
a neighbouring load recovering, tens of seconds) never counts as a lift."""

RELEASE_TIME_CONSTANT_S = 0.1
"""Time constant with which a lifted taxel's baseline follows its reading [s]: the lag
is the creep's rate of fall times this, under the threshold for peaks up to about 400
thresholds (creep 0.45 of the peak falling with 20 s: 0.002 of the peak per 0.1 s); a
new press ramped faster than the threshold per 0.1 s (any press of under ~10 s to a
peak of 100 thresholds) still rises above it and is a new touch."""


@jit(inline="always")
def _uncreep(d, creep, memory, r, c):
    """One taxel's signal ``d`` freed of delayed elasticity and creep (its memories
    ``memory[:, r, c]`` move on): stiffening undone, the causal inversion of
    :class:`~tactsense.estimate.creep.CreepCompensator`, stiffening redone."""
    scale = creep[5]
    y = d
    if scale > 0.0:  # d_meas = d / (1 + d / c_s), so d = d_meas / (1 - d_meas / c_s)
        y = min(d, 0.999 * scale)
        y = y / (1.0 - y / scale)
    u = (y - creep[0] * memory[0, r, c] - creep[1] * memory[1, r, c]) * creep[2]
    memory[0, r, c] = creep[3] * memory[0, r, c] + (1.0 - creep[3]) * u
    memory[1, r, c] = creep[4] * memory[1, r, c] + (1.0 - creep[4]) * u
    if scale > 0.0 and u > -0.999 * scale:
        return u / (1.0 + u / scale)
    return u


@jit(nogil=True)
def below_baseline(lowest: float, highest: float, threshold: float, resistive: bool) -> bool:
    """Whether a frame reads below its baseline by more than the noise and tension explain
    (the rule of the flag ``BELOW_BASELINE``).

    The signal is taken with compression positive (eq. 4; the strain on a resistive
    taxel). A taxel below the baseline by more than the contact ``threshold`` (10 counts,
    some 20 times the read noise of 0.3 counts and quantization, so no noise explains it)
    is a fault of the baseline unless it can be tension beside a contact: on a capacitive
    taxel, whose plates part under tension, in a frame that holds a contact (a taxel
    above the threshold) when it is no deeper below the baseline than that contact's
    largest compression (an elastic layer's tension lobes are shallower than the
    compression that makes them). A resistive taxel does not respond to tension: any
    reading below the threshold is a fault.

    Parameters
    ----------
    lowest, highest : float
        The frame's most negative and most positive signal over usable taxels [-]
        (both 0 when none is beyond the baseline).
    threshold : float
        The contact threshold [-].
    resistive : bool
        The taxels are resistive (no response to tension).
    """
    if lowest >= -threshold:
        return False
    if resistive:
        return True
    return not (highest > threshold and -lowest <= highest)


@jit(nogil=True)
def _follow(
    frames, baseline, unusable, full_scale, resistive, falling, per_count, threshold, alpha,
    guard,
    grid, nan_flag, sat_flag, dead_flag, below_flag, compensate, creep, memory,
    release, release_alpha, release_share, release_frames, block, releasing, low, peaks,
    phase, below,
):  # fmt: skip
    """Signal and flags of each frame against a baseline updated after every frame.

    With ``compensate``, each taxel's signal is freed of delayed elasticity and creep
    before it is thresholded: ``creep`` holds ``(a_d e_d, a_c e_c, 1 / c, e_d, e_c,
    c_s)`` (:class:`~tactsense.estimate.creep.CreepCompensator`'s recursion; ``c_s`` the
    stiffening scale undone first and redone after, 0 for none) and ``memory`` (2, rows,
    cols) the two memories, updated in place. An untouched taxel's baseline then
    follows the reading less its predicted creep, so that the creep left after a lift
    is neither taken for a contact nor taken into the baseline.

    With ``release`` (creep not compensated), a touched taxel whose signal falls below
    ``release_share`` of its largest signal over the last ``block`` to ``2 block`` frames
    (``peaks[0]`` this block's, ``peaks[1]`` the last block's; ``phase[0]`` the frames
    into this block) is *releasing*: not touched, its baseline following its reading by
    ``release_alpha`` of the difference each frame, until its signal rises more than the
    threshold above its lowest since the release (``low``), which is a new touch. The fall
    must last ``release_frames`` frames in a row (``below`` counts them): on a noisy array
    (read noise of 1-2 % of full scale) a held press's taxel dips below the share of its
    noisiest peak for a frame by noise alone, and was taken as lifted."""
    n, rows, cols = frames.shape
    signal = np.empty((n, rows, cols), np.float64)
    flags = np.zeros(n, np.int64)
    held = np.zeros((rows, cols), np.bool_)
    any_unusable = False
    for r in range(rows):
        for c in range(cols):
            if unusable[r, c]:
                any_unusable = True
    n_releasing = 0
    if release:
        for r in range(rows):
            for c in range(cols):
                if releasing[r, c]:
                    n_releasing += 1
    for f in range(n):
        flag = dead_flag if any_unusable else 0
        any_touched = False
        for r in range(rows):
            for c in range(cols):
                held[r, c] = False
        lowest = 0.0
        highest = 0.0
        for r in range(rows):
            for c in range(cols):
                d, bits = taxel_signal(
                    float(frames[f, r, c]), baseline[r, c], unusable[r, c], full_scale,
                    resistive, falling, per_count, nan_flag, sat_flag, dead_flag,
                )  # fmt: skip
                flag |= bits
                if compensate and bits == 0 and not unusable[r, c]:
                    d = _uncreep(d, creep, memory, r, c)
                lowest = min(lowest, d)
                highest = max(highest, d)
                signal[f, r, c] = d
                touched = d > threshold
                if release and not (touched or releasing[r, c]):
                    below[r, c] = 0
                elif release:
                    if releasing[r, c]:
                        if d < low[r, c]:
                            low[r, c] = d
                        if touched and d > low[r, c] + threshold:
                            releasing[r, c] = False  # risen again: a new touch
                            n_releasing -= 1
                        else:
                            touched = False
                    elif d < release_share * max(peaks[0, r, c], peaks[1, r, c]):
                        below[r, c] += 1
                        if below[r, c] >= release_frames:
                            releasing[r, c] = True  # a lift: what is left is creep
                            n_releasing += 1
                            low[r, c] = d
                            touched = False
                            below[r, c] = 0
                    else:
                        below[r, c] = 0
                    if touched and d > peaks[0, r, c]:
                        peaks[0, r, c] = d
                if touched:
                    any_touched = True
                    if grid:
                        for rr in range(max(0, r - guard), min(rows, r + guard + 1)):
                            for cc in range(max(0, c - guard), min(cols, c + guard + 1)):
                                held[rr, cc] = True
                    else:
                        held[r, c] = True
        if below_baseline(lowest, highest, threshold, resistive):
            flag |= below_flag
        flags[f] = flag
        if release:
            phase[0] += 1
            if phase[0] >= block:  # a new block: this one's peaks become the last one's
                phase[0] = 0
                for r in range(rows):
                    for c in range(cols):
                        peaks[1, r, c] = peaks[0, r, c]
                        peaks[0, r, c] = -math.inf
        lifting = release and n_releasing > 0
        pulled = release and any_touched
        moved = 0.0
        n_moved = 0
        for r in range(rows):
            for c in range(cols):
                v = float(frames[f, r, c])
                if unusable[r, c] or not math.isfinite(v):
                    continue
                # a reading of 0: an open capacitive junction, or a falling reading's
                # rail; a rising resistive cell at rest (it follows)
                if v <= 0.0 and (falling or not resistive):
                    continue
                if lifting and releasing[r, c]:  # the creep left after a lift
                    if v < full_scale:
                        baseline[r, c] += release_alpha * (v - baseline[r, c])
                    continue
                if held[r, c] or v >= full_scale:
                    continue
                if compensate:  # the reading this signal stands for, without creep
                    s = signal[f, r, c]
                    if resistive:
                        step = alpha * s / per_count
                    else:
                        step = alpha * baseline[r, c] * s / (1.0 - s)
                    if falling:  # the reading moves the other way
                        step = -step
                else:
                    step = alpha * (v - baseline[r, c])
                    if pulled and (step > 0.0 if falling else step < 0.0):
                        step = 0.0  # a load's flank pulls its neighbours down: no drift
                baseline[r, c] += step
                moved += step
                n_moved += 1
        if n_moved > 0:
            # held taxels follow the drift common to the untouched ones
            common = moved / n_moved
            for r in range(rows):
                for c in range(cols):
                    if held[r, c] and not unusable[r, c]:
                        if not (lifting and releasing[r, c]):
                            baseline[r, c] += common
    return signal, flags


class DriftBaseline:
    """A baseline of every taxel that follows slow drift while the taxel is untouched.

    Parameters
    ----------
    baseline : array_like, shape (rows, cols)
        The untouched readings to start from [counts] (e.g. the median of the first
        frames, :func:`~tactsense.estimate.finger.deflection.baseline_from`).
    sensor : SensorSpec, PadSpec or PointsSpec
    frame_period_s : float
        Time between frames [s].
    threshold : float
        The contact threshold [-]: above it a taxel is touched and its baseline held.
    time_constant_s : float
        How fast the baseline follows an untouched taxel's reading [s], > 0; ``inf``
        keeps it fixed (the frames below it are still counted and flagged).
    guard : int
        On a grid, taxels around a touched one that are held too (0-3) [taxel].
    rezero_frames : int
        Frames whose median makes the new baseline after :meth:`rezero`.
    creep : Viscoelastic, optional
        Delayed elasticity and creep to take out of every taxel's signal, causally,
        before it is thresholded (e.g. the sensor description's,
        :func:`~tactsense.estimate.creep.described_creep`): without it the creep left
        after a long press reads as a contact for as long as the creep time constant
        (a minute on the paper's skin, whatever ``time_constant_s``, since a touched
        taxel's baseline is held).
    stiffening : float
        With ``creep``: the deflection scale ``c`` of the stiffening law ``d_meas = d /
        (1 + d / c)`` that acts after the creep (the description's
        ``nonlinear_saturation``); undone before the compensation and redone after, so
        the signal keeps its scale [-]. 0: none.
    release : bool, optional
        Without ``creep``: a touched taxel whose signal falls quickly below
        :data:`RELEASE_SHARE` of its peak (:data:`RELEASE_WINDOW_S`) is taken as lifted,
        and its baseline follows its reading (:data:`RELEASE_TIME_CONSTANT_S`) until it
        rises above the threshold again: the creep left after a lift, which nothing
        takes out, is re-zeroed in a fraction of a second instead of reading as a
        contact for as long as it stays above the threshold (the whole minute after a
        10-s press on the paper's skin). Default: on for a pad or a point set exactly
        when ``creep`` is None; off on a finger, whose creep compensation is its
        calibration's (``tactsense calibrate --steps``), as its documented figures are.
    """

    def __init__(
        self,
        baseline,
        sensor,
        *,
        frame_period_s: float,
        threshold: float,
        time_constant_s: float = TIME_CONSTANT_S,
        guard: int = 1,
        rezero_frames: int = 5,
        creep=None,
        stiffening: float = 0.0,
        release: bool | None = None,
    ):
        for name, value in (("frame_period_s", frame_period_s), ("threshold", threshold)):
            if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
                raise TactsenseInputError(f"{name} must be a positive number; got {value!r}")
        if not (isinstance(time_constant_s, int | float) and time_constant_s > 0):
            raise TactsenseInputError(
                f"time_constant_s must be a positive number (inf: a fixed baseline); "
                f"got {time_constant_s!r}"
            )
        if not (isinstance(guard, int | np.integer) and 0 <= guard <= 3):
            raise TactsenseInputError(f"guard must be an integer in 0-3 [taxels]; got {guard!r}")
        if not (isinstance(rezero_frames, int | np.integer) and rezero_frames >= 1):
            raise TactsenseInputError(f"rezero_frames must be at least 1; got {rezero_frames!r}")
        self.sensor = sensor
        base = check_frames(baseline, sensor.shape, "baseline").astype(np.float64)
        if base.ndim != 2:
            raise TactsenseInputError(f"baseline has shape {base.shape}; expected {sensor.shape}")
        self.baseline = np.ascontiguousarray(base)
        """The current baseline [counts] (updated in place frame by frame)."""
        self.frame_period_s = float(frame_period_s)
        self.threshold = float(threshold)
        self.time_constant_s = float(time_constant_s)
        self.guard = int(guard)
        self.alpha = -math.expm1(-self.frame_period_s / self.time_constant_s)
        """Share of the difference to the reading taken each frame [-]."""
        self.rezero_frames = int(rezero_frames)
        self.below_frames = 0
        """Frames so far flagged ``BELOW_BASELINE`` (:func:`below_baseline`)."""
        self.first_baseline = self.baseline.copy()
        """The baseline the frames started from (the first frames' median, or the last
        re-zero's) [counts]: not moved by drift or a release."""
        self.below_first_frames = 0
        """Of :attr:`below_frames`, those that read below :attr:`first_baseline` by the
        same rule: only these say the first frames were touched (the others read below
        a baseline that followed the reading, e.g. a slow unload taken for the creep
        after a lift)."""
        self.frames_seen = 0
        self.last_signal: np.ndarray | None = None
        """The signal of the frames last given to :meth:`signal` (a caller that scales
        it in place, as a calibration's gains do, leaves it scaled)."""
        self._collect: list[np.ndarray] | None = None
        self._resistive, self._falling, self._per_count = reading_mode(sensor)
        kind = kind_or_none(sensor)
        self._grid = kind is None or kind.image_grid
        if not (isinstance(stiffening, int | float) and math.isfinite(stiffening)):
            raise TactsenseInputError(f"stiffening must be a number >= 0; got {stiffening!r}")
        if stiffening < 0:
            raise TactsenseInputError(f"stiffening must be a number >= 0; got {stiffening!r}")
        self.creep = creep
        """The creep model taken out of the signal (None: none)."""
        self._creep = np.zeros(6)
        if creep is not None:
            compensator = CreepCompensator(creep, self.frame_period_s)
            self._creep[:5] = compensator.coefficients
            self._creep[5] = float(stiffening)
        self.creep_memory = np.zeros((2, *self.baseline.shape))
        """The creep model's two memories (delayed, creep) per taxel [-], carried from
        frame to frame; zero after a re-zero."""
        if release is None:  # a finger's creep is its calibration's (calibrate --steps)
            release = creep is None and kind is not None and kind.array_calibration
        self.release = bool(release)
        """Whether a lift's creep is re-zeroed (``release``)."""
        self._release_alpha = -math.expm1(-self.frame_period_s / RELEASE_TIME_CONSTANT_S)
        self._block = max(1, round(RELEASE_WINDOW_S / self.frame_period_s))
        self._reset_release()

    def _reset_release(self) -> None:
        shape = self.baseline.shape
        self.releasing = np.zeros(shape, np.bool_)
        """Taxels taken as lifted, whose baseline follows their reading."""
        self._low = np.zeros(shape)
        self._below = np.zeros(shape, np.int64)
        self._peaks = np.full((2, *shape), -np.inf)
        self._phase = np.zeros(1, np.int64)

    def rezero(self) -> None:
        """Make the next ``rezero_frames`` frames' median the baseline (taken untouched)."""
        self._collect = []

    @property
    def rezeroing(self) -> bool:
        """True while frames are being collected for a new baseline."""
        return self._collect is not None

    def signal(self, frames, *, dead=None):
        """The signal of every frame against the baseline as it stood before that frame,
        and each frame's flags; the baseline moves on as the frames go by.

        Returns
        -------
        signal : ndarray, shape (N, rows, cols) [-]
        flags : ndarray of int64, shape (N,)
        """
        frames = check_frames(frames, self.sensor.shape).reshape(-1, *self.sensor.shape)
        if self._collect is not None:
            frames = self._take_rezero(frames)
        unusable = unusable_baseline(self.baseline, self.sensor)
        if dead is not None:
            unusable = unusable | np.asarray(dead, dtype=bool)
        source = frames if frames.dtype in (np.uint16, np.int32, np.int64, np.float64) else (
            frames.astype(np.float64))  # fmt: skip
        with deferred_interrupts():
            signal, flags = _follow(
                # writable: a read-only array is another signature to compile
                np.require(source, requirements=("C", "W")), self.baseline, unusable,
                float(2**self.sensor.electronics.adc_bits - 1), self._resistive,
                self._falling, self._per_count, self.threshold, self.alpha, self.guard,
                self._grid,
                int(Flag.NAN_INPUT), int(Flag.SATURATED), int(Flag.DEAD_TACTEL),
                int(Flag.BELOW_BASELINE), self.creep is not None, self._creep,
                self.creep_memory, self.release, self._release_alpha, RELEASE_SHARE,
                RELEASE_FRAMES, self._block, self.releasing, self._low, self._peaks,
                self._phase, self._below,
            )  # fmt: skip
        below = np.flatnonzero(flags & int(Flag.BELOW_BASELINE))
        self.below_frames += below.size
        if below.size:
            self.below_first_frames += self._below_first(source[below], unusable)
        self.frames_seen += len(frames)
        self.last_signal = signal
        return signal, flags

    def _below_first(self, frames: np.ndarray, unusable: np.ndarray) -> int:
        """How many of ``frames`` read below :attr:`first_baseline` by the rule of
        :func:`below_baseline` (the signal as :func:`taxel_signal` takes it, without
        creep compensation or saturated and unusable taxels)."""
        v = frames.astype(float)
        base = self.first_baseline
        sign = -1.0 if self._falling else 1.0
        with np.errstate(all="ignore"):
            if self._resistive:
                d = sign * (v - base) * self._per_count
            elif self._falling:  # an open junction (w <= 0 or v <= 0): no signal
                d = np.where(2.0 * base - v > 0, (base - v) / (2.0 * base - v), np.nan)
            else:
                d = np.where(v > 0, (v - base) / v, np.nan)
        usable = np.isfinite(d) & ~unusable & ~at_rail(frames, self.sensor)
        d = np.where(usable, d, 0.0).reshape(len(frames), -1)
        lowest, highest = np.minimum(d.min(axis=1), 0.0), np.maximum(d.max(axis=1), 0.0)
        return sum(
            bool(below_baseline(lo, hi, self.threshold, self._resistive))
            for lo, hi in zip(lowest.tolist(), highest.tolist(), strict=True)
        )

    def _take_rezero(self, frames: np.ndarray) -> np.ndarray:
        # frames collected for the new baseline still get a signal against the old one
        need = self.rezero_frames - len(self._collect)
        self._collect.extend(np.asarray(frames[:need], dtype=float))
        if len(self._collect) >= self.rezero_frames:
            self.baseline = np.ascontiguousarray(np.nanmedian(np.stack(self._collect), axis=0))
            self.first_baseline = self.baseline.copy()
            self._collect = None
            self.creep_memory[:] = 0.0  # the new baseline holds whatever creep is left
            self._reset_release()
        return frames
