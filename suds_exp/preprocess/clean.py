"""Step 1, cleaning: find marker jumps, remove the points they displaced, fill the gaps.

The paper scanned the tracks for jumps larger than 9 mm, removed the points adjacent to
them and filled the gaps by linear interpolation. Here a jump is a frame-to-frame step
that differs by more than ``jump_mm`` from the marker's own motion (the running median of
its steps over `MEDIAN_STEPS` frames), so a fast-moving marker (a segment end at 1 Hz
moves up to ~10 mm per frame) is not mistaken for a jumping one. A jump has two adjacent
points and only one of them is wrong, so each jump-free run of a track is judged against
a trusted one: the longest run is trusted, and a neighbouring run is kept when its first
(or last) point continues the trusted one, moving at the marker's expected velocity,
within the threshold (widened across a gap by the track's unexplained motion per frame).
A spike thus loses one point, a marker displaced for several frames loses those frames,
and a clean point is not removed.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.ndimage import median_filter

from suds_exp.errors import PreprocessError

#: Steps in the running median that gives a marker's expected motion per frame.
MEDIAN_STEPS = 7
#: Longest span (frames) over which one run of a track is predicted from another.
COMPARE_FRAMES = 15


@dataclass(frozen=True)
class CleanResult:
    """Cleaned tracks and what was done to them.

    Attributes
    ----------
    xyz : array of shape (n_frames, n_markers, 3), mm
        Tracks with removed and missing points filled by linear interpolation (held
        constant before the first and after the last seen point).
    removed : array of shape (n_frames, n_markers), bool
        Points removed because a jump displaced them.
    filled : array of shape (n_frames, n_markers), bool
        Points filled: removed ones and those the capture had missing.
    n_jumps : int
        Number of frame-to-frame steps longer than the threshold.
    longest_gap : int
        Longest run of filled frames of any marker, frames.
    """

    xyz: np.ndarray
    removed: np.ndarray
    filled: np.ndarray
    n_jumps: int
    longest_gap: int

    @property
    def removed_fraction(self) -> float:
        return float(self.removed.mean()) if self.removed.size else 0.0

    @property
    def filled_fraction(self) -> float:
        return float(self.filled.mean()) if self.filled.size else 0.0


def _point_velocity(xyz: np.ndarray, jump_mm: float) -> np.ndarray:
    """Each frame's marker velocity, (n_frames, n_markers, 3) mm/frame.

    The running median of the frame-to-frame steps around the frame (mirrored at the
    ends), leaving out the steps next to a change of step larger than half the jump
    threshold (a jump, or clean motion no marker makes: ~1 mm per frame squared here),
    with the left-out steps and those next to unseen frames interpolated from their
    neighbours; so a jump next to a gap or an end of the record cannot drag it along.
    """
    n, m, _ = xyz.shape
    if n < 2:
        return np.zeros_like(xyz)
    raw = (xyz[1:] - xyz[:-1]).reshape(n - 1, -1)

    def running_median(steps: np.ndarray) -> np.ndarray:
        steps = steps.copy()
        rows = np.arange(n - 1)
        for col in np.flatnonzero(np.isnan(steps).any(axis=0)):
            ok = ~np.isnan(steps[:, col])
            steps[:, col] = np.interp(rows, rows[ok], steps[ok, col]) if ok.any() else 0.0
        return median_filter(steps, size=(MEDIAN_STEPS, 1), mode="mirror")

    # a step next to a large change of step (second difference) may be a jump: leave it
    # out of the median, whatever the gaps around it
    steps = raw.reshape(n - 1, m, 3)
    change = np.linalg.norm(np.diff(steps, axis=0), axis=2) > 0.5 * jump_mm
    spoiled = np.zeros((n - 1, m), dtype=bool)
    spoiled[:-1] |= change
    spoiled[1:] |= change
    cleaned = steps.copy()
    cleaned[spoiled] = np.nan
    med = running_median(cleaned.reshape(n - 1, -1))
    return np.vstack([med[:1], med]).reshape(n, m, 3)


def _bad_runs(
    points: np.ndarray, index: np.ndarray, velocity: np.ndarray, jump_mm: float
) -> tuple[np.ndarray, int]:
    """Mask of the seen points of one marker that jumps displaced, and the jump count.

    points, velocity : (n_seen, 3) mm, mm/frame; index : (n_seen,) their frame positions.
    """
    bad = np.zeros(len(points), dtype=bool)
    if len(points) < 2:
        return bad, 0
    gaps = np.diff(index)

    fast = float(np.percentile(np.linalg.norm(velocity, axis=1), 99))

    def miss(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """How far points b lie from points a moved on at the mean of their velocities,
        and the allowance for the change of velocity over the frames between, mm."""
        frames = (index[b] - index[a])[:, None]
        mean_v = 0.5 * (velocity[a] + velocity[b])
        off = np.linalg.norm(points[b] - points[a] - mean_v * frames, axis=1)
        n = np.abs(frames[:, 0])
        # Over seen frames: the change of velocity. Across unseen ones the velocity at the
        # gap's ends is poorly known (fast, accelerating flippers), so allow the marker's
        # whole travel at the faster of its ends' speeds and its typical high speed: a
        # jump hidden by a gap may pass, a clean run is not thrown away.
        speed = np.maximum(np.linalg.norm(velocity[a], axis=1), np.linalg.norm(velocity[b], axis=1))
        speed = np.maximum(speed, fast)
        unseen = (index[b] - index[a]) != (b - a)  # the span crosses unseen frames
        change = 0.5 * np.linalg.norm(velocity[b] - velocity[a], axis=1) * n
        return off, np.where(unseen, n * speed, change)

    pairs = np.arange(len(points) - 1)
    excess, turn = miss(pairs, pairs + 1)
    consecutive = excess[gaps == 1]
    # unexplained motion per frame, widening the threshold across a gap
    slack = float(np.percentile(consecutive, 99)) if consecutive.size else 0.0
    is_jump = excess > jump_mm + turn + (gaps - 1) * slack
    n_jumps = int(is_jump.sum())
    if n_jumps == 0:
        return bad, 0
    # runs of the track: split at every jump and at every gap in the capture
    starts = np.concatenate([[0], np.flatnonzero(is_jump | (gaps > 1)) + 1])
    ends = np.concatenate([starts[1:], [len(points)]])  # exclusive

    def continues(a: int, b: int) -> bool:
        """Seen points a < b are consistent with one unbroken track."""
        frames = int(index[b]) - int(index[a])
        off, allowance = miss(np.array([a]), np.array([b]))
        if b - a > 1:
            # the points between belong to runs not trusted yet (two jumps a few frames
            # apart): they say nothing about the path, so the span counts as unseen, as
            # across a gap; otherwise a long clean run is thrown away because a fast
            # marker does not move linearly over the up to COMPARE_FRAMES frames between
            speed = max(np.linalg.norm(velocity[a]), np.linalg.norm(velocity[b]), fast)
            allowance = np.array([frames * speed])
        return float(off[0]) <= jump_mm + float(allowance[0]) + (frames - 1) * slack

    # Longest runs first: a run must continue the nearest trusted run on each side that is
    # close enough to predict (linear motion fails over longer spans), so of two runs a
    # jump splits, the shorter one is the displaced one.
    good = np.zeros(len(starts), dtype=bool)
    for r in np.argsort(-(ends - starts), kind="stable"):
        left = np.flatnonzero(good[:r])
        right = r + 1 + np.flatnonzero(good[r + 1 :])
        ok = True
        if left.size and index[starts[r]] - index[ends[left[-1]] - 1] <= COMPARE_FRAMES:
            ok &= continues(ends[left[-1]] - 1, starts[r])
        if right.size and index[starts[right[0]]] - index[ends[r] - 1] <= COMPARE_FRAMES:
            ok &= continues(ends[r] - 1, starts[right[0]])
        good[r] = ok
        if not ok:
            bad[starts[r] : ends[r]] = True
    return bad, n_jumps


def clean_tracks(
    xyz: np.ndarray,
    jump_mm: float = 9.0,
    max_gap_frames: int | None = None,
    marker_names: Sequence[str] | None = None,
) -> CleanResult:
    """Remove jump-displaced points and fill every gap by linear interpolation.

    Parameters
    ----------
    xyz : array of shape (n_frames, n_markers, 3), mm
        Marker tracks; NaN where the capture did not see the marker.
    jump_mm : float
        A frame-to-frame step longer than this is a jump, mm.
    max_gap_frames : int, optional
        Refuse (`PreprocessError`) tracks with a longer run of frames to fill.
    marker_names : sequence of str, optional
        Names used in error messages.

    Returns
    -------
    CleanResult
    """
    xyz = np.asarray(xyz, dtype=float)
    n_frames, n_markers, _ = xyz.shape
    names = list(marker_names) if marker_names is not None else [str(i) for i in range(n_markers)]
    seen = np.isfinite(xyz).all(axis=2)
    removed = np.zeros_like(seen)
    velocity = _point_velocity(xyz, jump_mm)
    out = np.empty_like(xyz)
    frames = np.arange(n_frames)
    n_jumps = 0
    longest = 0
    for m in range(n_markers):
        index = np.flatnonzero(seen[:, m])
        if index.size == 0:
            raise PreprocessError(f"marker {names[m]} is never seen")
        bad, jumps = _bad_runs(xyz[index, m], index, velocity[index, m], jump_mm)
        n_jumps += jumps
        removed[index[bad], m] = True
        keep = index[~bad]
        # a gap is a run of frames between kept points (or before the first / after the last)
        edges = np.concatenate([[-1], keep, [n_frames]])
        runs = np.diff(edges) - 1
        worst = int(np.argmax(runs))
        if runs[worst] > longest:
            longest = int(runs[worst])
        if max_gap_frames is not None and runs[worst] > max_gap_frames:
            raise PreprocessError(
                f"marker {names[m]} has a gap of {runs[worst]} frames starting at frame "
                f"index {edges[worst] + 1}, longer than the {max_gap_frames} frames allowed "
                "(raise params max_gap_s or leave the trial out)",
                param="params",
            )
        for c in range(3):
            out[:, m, c] = np.interp(frames, keep, xyz[keep, m, c])
    filled = removed | ~seen
    return CleanResult(out, removed, filled, n_jumps, longest)
