"""Step 2, body frame: the motion plane, the segment origins on the motor axes, the body pose.

Following the paper's "Data Processing":

- the XY plane is the least-squares plane of the rigid segment markers: the direction
  along which every rigid marker keeps the most constant height over the trial (the
  smallest principal axis of the pooled, per-marker-centred positions), with the mean
  height of the four top-surface markers at Z = 0;
- each outer segment gets a 2D frame from its two top-surface markers projected on that
  plane; the tail's frame can then be refined by a per-frame least-squares rigid fit of
  all its rigid markers (`rigid_fit`: the two top markers and ``tail_back``), whose
  positions in the two-marker frame are learned as their trial means. The segment
  origins are the points fixed in those frames whose distance to each other stays
  constant (the motor axes, joined rigidly by the middle segment). They are
  found by linear least squares on the squared-distance condition, refined by nonlinear
  least squares on the distance itself;
- the body origin is the midpoint of the two segment origins, +X from the tail origin to
  the head origin, Z up.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from suds_exp.errors import PreprocessError

#: At most this many frames feed the nonlinear joint refinement (the linear start uses all).
JOINT_FIT_FRAMES = 4000


@dataclass(frozen=True)
class Plane:
    """The motion plane of a trial, in the capture's world frame.

    Attributes
    ----------
    basis : array of shape (3, 3)
        Rows are the plane frame's X, Y, Z axes in world coordinates (Z = plane normal,
        pointing up; X = world X projected on the plane).
    height_mm : float
        World offset along the normal of the plane's Z = 0, mm.
    """

    basis: np.ndarray
    height_mm: float

    def project(self, xyz: np.ndarray) -> np.ndarray:
        """World points (..., 3) mm -> plane coordinates (..., 3) mm."""
        local = xyz @ self.basis.T
        local[..., 2] -= self.height_mm
        return local


def fit_plane(rigid: np.ndarray, top: np.ndarray) -> Plane:
    """Least-squares motion plane of a rigid-marker set.

    Parameters
    ----------
    rigid : array of shape (n_frames, n_markers, 3), mm
        Markers fixed on the segments (top-surface, spoke, back-edge), world frame.
    top : array of shape (n_frames, n_top, 3), mm
        The top-surface markers, whose mean height becomes Z = 0.
    """
    centred = rigid - rigid.mean(axis=0, keepdims=True)
    flat = centred.reshape(-1, 3)
    scatter = flat.T @ flat
    _, vectors = np.linalg.eigh(scatter)
    normal = vectors[:, 0]
    if normal[2] < 0:
        normal = -normal
    x_axis = np.array([1.0, 0.0, 0.0]) - normal[0] * normal
    if np.linalg.norm(x_axis) < 1e-6:  # plane perpendicular to world X: use world Y
        x_axis = np.array([0.0, 1.0, 0.0]) - normal[1] * normal
    x_axis /= np.linalg.norm(x_axis)
    y_axis = np.cross(normal, x_axis)
    basis = np.stack([x_axis, y_axis, normal])
    height = float((top @ normal).mean())
    return Plane(basis, height)


@dataclass(frozen=True)
class SegmentFrames:
    """Per-frame 2D frames of the head and tail segments from their top-surface markers.

    ``*_origin`` (n_frames, 2) mm: centroid of the segment's two top markers (plane XY);
    ``*_angle`` (n_frames,) rad: heading of the line top_1 -> top_2.
    """

    head_origin: np.ndarray
    head_angle: np.ndarray
    tail_origin: np.ndarray
    tail_angle: np.ndarray


def segment_frames(head_top: np.ndarray, tail_top: np.ndarray) -> SegmentFrames:
    """Frames from top markers, each array of shape (n_frames, 2, 2) (marker, plane XY) mm."""

    def frame(top):
        d = top[:, 1] - top[:, 0]
        if np.any(np.hypot(d[:, 0], d[:, 1]) < 1e-6):
            raise PreprocessError("a segment's two top-surface markers coincide")
        return top.mean(axis=1), np.arctan2(d[:, 1], d[:, 0])

    ho, ha = frame(head_top)
    to, ta = frame(tail_top)
    return SegmentFrames(ho, ha, to, ta)


def rotate(angle: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Rotate 2-vectors ``v`` (n, ..., 2), or (1, ..., 2) for the same vectors in every
    frame, by per-frame angles ``angle`` (n,) rad."""
    shape = (len(angle),) + (1,) * (v.ndim - 2)
    c, s = np.cos(angle).reshape(shape), np.sin(angle).reshape(shape)
    return np.stack([c * v[..., 0] - s * v[..., 1], s * v[..., 0] + c * v[..., 1]], axis=-1)


def to_frame(points: np.ndarray, origin: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Plane points (n, m, 2) into per-frame 2D frames (origin (n, 2), angle (n,))."""
    return rotate(-angle, points - origin[:, None, :])


def best_rotation(template: np.ndarray, points: np.ndarray, near: np.ndarray) -> np.ndarray:
    """Per-frame angle (n,) rad of the rotation about the origin that best maps
    ``template`` ((m, 2) or (n, m, 2)) onto ``points`` (n, m, 2) (least squares, closed
    form), unwrapped next to ``near`` (n,)."""
    sxx = (template[..., 0] * points[..., 0] + template[..., 1] * points[..., 1]).sum(axis=-1)
    sxy = (template[..., 0] * points[..., 1] - template[..., 1] * points[..., 0]).sum(axis=-1)
    return near + np.angle(np.exp(1j * (np.arctan2(sxy, sxx) - near)))


def procrustes(
    template: np.ndarray, points: np.ndarray, near: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Per-frame 2D rigid transform best mapping ``template`` ((m, 2) or (n, m, 2), in the
    frame) onto ``points`` (n, m, 2) in the plane, equal weights, closed form: (origin
    (n, 2), angle (n,) rad, unwrapped next to ``near``)."""
    t_c = template.mean(axis=-2, keepdims=True)
    p_c = points.mean(axis=1, keepdims=True)
    angle = best_rotation(template - t_c, points - p_c, near)
    t_c = np.broadcast_to(t_c, (len(points), 1, 2))
    return (p_c - rotate(angle, t_c))[:, 0], angle


def refine_with_circles(
    origin: np.ndarray,
    angle: np.ndarray,
    template: np.ndarray,
    points: np.ndarray,
    circles: list[tuple[np.ndarray, np.ndarray, float]],
    iterations: int,
) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Newton refinement of per-frame 2D frames (origin (n, 2) mm, angle (n,) rad).

    Minimises, per frame, the squared misfits of ``template`` ((m, 2) or (n, m, 2) mm, in
    the frame) against ``points`` (n, m, 2) mm in the plane, plus, for each circle
    ``(marker (n, 2) mm in the plane, centre ((2,) or (n, 2) mm in the frame, radius
    mm)``, the squared distance of the marker from its circle (one equation each: the
    hinged part's angle stays free). Analytic Jacobian."""
    n = len(points)
    m = points.shape[1]
    x = np.column_stack([origin, angle])
    for _ in range(iterations):
        placed = rotate(x[:, 2], np.broadcast_to(template, (n, m, 2)))
        res = [(x[:, None, :2] + placed - points).reshape(n, 2 * m)]
        jac = np.zeros((n, 2 * m, 3))
        jac[:, 0::2, 0] = 1.0
        jac[:, 1::2, 1] = 1.0
        jac[:, 0::2, 2] = -placed[..., 1]
        jac[:, 1::2, 2] = placed[..., 0]
        jacs = [jac]
        for marker, centre, radius in circles:
            rc = rotate(x[:, 2], np.broadcast_to(centre, (n, 2))[:, None])[:, 0]
            e = marker - x[:, :2] - rc
            dist = np.hypot(e[:, 0], e[:, 1])
            u = e / np.maximum(dist, 1e-9)[:, None]
            res.append((dist - radius)[:, None])
            # d(dist)/d(origin) = -u; d(dist)/d(angle) = -u . d(rc)/d(angle)
            d_angle = u[:, 0] * rc[:, 1] - u[:, 1] * rc[:, 0]
            jacs.append(np.concatenate([-u, d_angle[:, None]], axis=1)[:, None, :])
        r = np.concatenate(res, axis=1)
        jm = np.concatenate(jacs, axis=1)
        hess = np.einsum("nij,nik->njk", jm, jm)
        grad = np.einsum("nij,ni->nj", jm, r)
        x = x - np.linalg.solve(hess, grad[..., None])[..., 0]
    return x[:, :2], x[:, 2]


def rigid_fit(
    points: np.ndarray, origin: np.ndarray, angle: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Per-frame least-squares rigid fit of a segment's rigid markers, in its own frame.

    ``points`` (n_frames, n_markers, 2) mm in the plane, markers fixed on one segment;
    ``origin`` (n_frames, 2) mm and ``angle`` (n_frames,) rad: a first estimate of the
    segment frame (e.g. from two of the markers). The markers' positions in that frame
    are learned as their means over the frames; each frame's origin and angle are then
    the 2D rigid transform that best maps those positions onto the measured ones (equal
    weights, closed form). With more than two markers this averages the markers' noise
    down; the frame keeps the first estimate's convention, so the angle stays unwrapped
    alongside ``angle``. Returns (origin (n_frames, 2) mm, angle (n_frames,) rad).
    """
    template = to_frame(points, origin, angle).mean(axis=0)
    return procrustes(template, points, angle)


#: A hinged marker constrains its segment's frame only if its circle is well determined:
#: points spread over at least this arc (5th to 95th percentile), rad ...
HINGE_MIN_ARC_RAD = 0.3
#: ... and lying within this RMS distance of the fitted circle, mm.
HINGE_MAX_RMS_MM = 1.0


def _circle(u: np.ndarray) -> tuple[np.ndarray, float, float, float]:
    """Algebraic least-squares circle through points (n, 2): centre, radius, RMS radial
    residual and the arc the points span (5th to 95th percentile of their angle)."""
    design = np.column_stack([2 * u, np.ones(len(u))])
    sol, *_ = np.linalg.lstsq(design, (u**2).sum(axis=1), rcond=None)
    centre = sol[:2]
    radius = float(np.sqrt(max(sol[2] + centre @ centre, 0.0)))
    d = u - centre
    rms = float(np.sqrt(np.mean((np.hypot(d[:, 0], d[:, 1]) - radius) ** 2)))
    ang = np.unwrap(np.arctan2(d[:, 1], d[:, 0]))
    arc = float(np.percentile(ang, 95) - np.percentile(ang, 5))
    return centre, radius, rms, arc


def hinge_circles(
    hinged: np.ndarray, origin: np.ndarray, angle: np.ndarray
) -> list[tuple[int, np.ndarray, float]]:
    """The well-determined circles of hinged markers in a segment frame.

    ``hinged`` (n_frames, h, 2) mm in the plane; ``origin`` (n_frames, 2) mm and ``angle``
    (n_frames,) rad: the segment frame. Returns ``(k, centre (2,) mm, radius mm)`` for each
    marker k whose points span at least `HINGE_MIN_ARC_RAD` and lie within
    `HINGE_MAX_RMS_MM` of their algebraic least-squares circle.
    """
    local = to_frame(hinged, origin, angle)
    circles = []
    for k in range(hinged.shape[1]):
        centre, radius, rms, arc = _circle(local[:, k])
        if arc >= HINGE_MIN_ARC_RAD and rms <= HINGE_MAX_RMS_MM:
            circles.append((k, centre, radius))
    return circles


def hinged_fit(
    rigid: np.ndarray,
    hinged: np.ndarray,
    origin: np.ndarray,
    angle: np.ndarray,
    iterations: int = 3,
) -> tuple[np.ndarray, np.ndarray]:
    """Per-frame least-squares fit of a segment frame to its rigid and hinged markers.

    ``rigid`` (n_frames, m, 2) mm: markers fixed on the segment; ``hinged`` (n_frames, h, 2)
    mm: markers on parts hinged to it (flippers), each moving on a circle fixed in the
    segment frame; ``origin`` (n_frames, 2) mm and ``angle`` (n_frames,) rad: a first
    estimate of the frame (e.g. `rigid_fit`). The rigid markers' positions and each hinged
    marker's circle (algebraic fit) are learned in that frame over the trial; a hinged
    marker whose circle is poorly determined (its points span less than
    `HINGE_MIN_ARC_RAD`, e.g. a flipper resting on its stop, or lie further than
    `HINGE_MAX_RMS_MM` from it) is left out. Each frame then minimises the squared
    rigid-marker misfits plus the squared distances of the hinged markers from their
    circles (one equation each: the flipper angle stays free), by Gauss-Newton from the
    first estimate (`refine_with_circles`). Returns (origin (n_frames, 2) mm,
    angle (n_frames,) rad).
    """
    template = to_frame(rigid, origin, angle).mean(axis=0)
    circles = hinge_circles(hinged, origin, angle)
    if not circles:
        return origin, angle

    chosen = [(hinged[:, k], centre, radius) for k, centre, radius in circles]
    return refine_with_circles(origin, angle, template, rigid, chosen, iterations)


@dataclass(frozen=True)
class Joints:
    """Segment origins (motor axes) in the head and tail top-marker frames.

    ``head`` and ``tail`` (2,) mm in their segment frames; ``length_mm`` their distance
    (the middle segment's length, fitted or given); ``rms_mm`` the RMS of the distance's
    deviation.
    """

    head: np.ndarray
    tail: np.ndarray
    length_mm: float
    rms_mm: float
    #: how far (mm) the origins move when the trials' own marker noise is added once more
    #: (`noise_shift`); NaN when not measured
    noise_shift_mm: float = float("nan")

    def points(self, frames: SegmentFrames) -> tuple[np.ndarray, np.ndarray]:
        """Head and tail segment origins per frame, each (n_frames, 2) mm in the plane."""
        return (
            frames.head_origin + rotate(frames.head_angle, self.head[None]),
            frames.tail_origin + rotate(frames.tail_angle, self.tail[None]),
        )


def fit_joints(frames: SegmentFrames, length_mm: float | None = None) -> Joints:
    """Points fixed in the head and tail frames that keep a constant distance, mm.

    ``length_mm``: that distance when it is known (the robot's drawing), else fitted too.
    """
    # Head frame expressed in the tail frame: relative offset p and angle psi.
    d = frames.head_origin - frames.tail_origin
    ta = frames.tail_angle
    c, s = np.cos(ta), np.sin(ta)
    p = np.stack([c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1]], axis=1)
    psi = frames.head_angle - ta
    cp, sp = np.cos(psi), np.sin(psi)
    # |p + R(psi) a_h - a_t|^2 = L^2 is linear in (a_h, a_t, w1, w2, K) with
    # w1 = a_t . a_h, w2 = a_t[1] a_h[0] - a_t[0] a_h[1], K = |a_h|^2 + |a_t|^2 - L^2.
    rtp = np.stack([cp * p[:, 0] + sp * p[:, 1], -sp * p[:, 0] + cp * p[:, 1]], axis=1)
    design = np.column_stack([2 * rtp, -2 * p, -2 * cp, -2 * sp, np.ones(len(p))])
    rhs = -(p**2).sum(axis=1)
    scale = np.abs(design).max(axis=0) + 1e-12
    u, *_ = np.linalg.lstsq(design / scale, rhs, rcond=None)
    u /= scale
    gap = p + rotate(psi, u[None, :2]) - u[2:4]
    start = np.concatenate([u[:4], [np.sqrt(np.mean(np.sum(gap**2, axis=1)))]])

    step = max(1, len(p) // JOINT_FIT_FRAMES)
    ps, cps, sps = p[::step], cp[::step], sp[::step]

    def residual(x):
        ah, at = x[:2], x[2:4]
        length = x[4] if length_mm is None else length_mm
        jx = ps[:, 0] + cps * ah[0] - sps * ah[1] - at[0]
        jy = ps[:, 1] + sps * ah[0] + cps * ah[1] - at[1]
        return np.hypot(jx, jy) - length

    fit = least_squares(residual, start if length_mm is None else start[:4], method="lm")
    if not fit.success and fit.status <= 0:
        raise PreprocessError(f"segment origins: least squares did not converge ({fit.message})")
    ah, at = fit.x[:2], fit.x[2:4]
    dist = np.hypot(*(p + rotate(psi, ah[None]) - at).T)
    length = float(np.mean(dist)) if length_mm is None else float(length_mm)
    return Joints(ah, at, length, float(np.sqrt(np.mean((dist - length) ** 2))))


#: Savitzky-Golay window (frames) and order whose residual estimates the frames' noise:
#: short enough that a gait at 100 Hz is a local quadratic over it, so what is left is noise
NOISE_WINDOW, NOISE_ORDER = 11, 2


def noise_shift(
    trials: Sequence[SegmentFrames], joints: Joints, length_mm: float | None, seed: int
) -> float:
    """How far the segment origins move (mm, the larger of the two) when noise like the
    trials' own is added to the frames once more and the origins are fitted again.

    Marker noise biases the constant-distance fit (its unknowns enter nonlinearly: errors
    in variables), and doubling the noise about doubles the bias, so this shift
    estimates the bias of ``joints`` itself (the first step of SIMEX, Cook & Stefanski
    1994). It is large when the trials leave the fit nearly free along one direction,
    e.g. a single gait whose shape loop is a circle. The noise of each channel (both
    origins' x, y and both angles) is the RMS of its residual from a local quadratic,
    per trial. Averaged over two draws of ``seed``'s generator.
    """
    from scipy.signal import savgol_coeffs, savgol_filter

    # the residual of a least-squares smoother keeps 1 - h_00 of white noise's variance
    keep = np.sqrt(1.0 - savgol_coeffs(NOISE_WINDOW, NOISE_ORDER)[NOISE_WINDOW // 2])
    channels = []
    for tr in trials:
        if len(tr.head_angle) <= NOISE_WINDOW:
            continue
        arrays = (
            tr.head_origin,
            np.unwrap(tr.head_angle),
            tr.tail_origin,
            np.unwrap(tr.tail_angle),
        )
        channels.append(arrays)
    if not channels:
        return float("nan")
    sigma = [
        np.sqrt(
            np.mean(
                np.concatenate(
                    [
                        (a[k] - savgol_filter(a[k], NOISE_WINDOW, NOISE_ORDER, axis=0)) ** 2
                        for a in channels
                    ]
                ),
                axis=0,
            )
        )
        / keep
        for k in range(4)
    ]
    pooled = [np.concatenate([a[k] for a in channels]) for k in range(4)]
    rng = np.random.default_rng(seed)
    shifted = []
    for _ in range(2):
        noisy = [x + rng.normal(size=x.shape) * sd for x, sd in zip(pooled, sigma, strict=True)]
        again = fit_joints(SegmentFrames(*noisy), length_mm)
        shifted.append(np.concatenate([again.head, again.tail]))
    moved = np.mean(shifted, axis=0) - np.concatenate([joints.head, joints.tail])
    return float(max(np.hypot(*moved[:2]), np.hypot(*moved[2:])))


@dataclass(frozen=True)
class BodyPose:
    """Body frame per frame: ``xy`` (n_frames, 2) mm in the plane, ``heading`` (n_frames,)
    rad unwrapped; ``head_joint``/``tail_joint`` (n_frames, 2) mm, the segment origins."""

    xy: np.ndarray
    heading: np.ndarray
    head_joint: np.ndarray
    tail_joint: np.ndarray


def body_pose(frames: SegmentFrames, joints: Joints) -> BodyPose:
    """Body origin = midpoint of the segment origins, +X = tail origin -> head origin."""
    head, tail = joints.points(frames)
    axis = head - tail
    heading = np.unwrap(np.arctan2(axis[:, 1], axis[:, 0]))
    return BodyPose(0.5 * (head + tail), heading, head, tail)
