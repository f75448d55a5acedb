"""2D LiDAR geometry against a floor plan's wall segments, and the FloorPlan2Nav correction.

Walls are line segments ``(N, 4)`` rows ``[x0, y0, x1, y1]`` in metres (world frame, x right,
y up); a pose is ``[x, y, theta]`` (metres, radians; theta counter-clockwise from +x). A scan is
``num_beams`` ranges [m]; beam ``i`` points at ``2*pi*i/num_beams`` in the robot frame; a beam
with no return is ``+inf`` or beyond ``max_range_m``.

The *paper* correction (FloorPlan2Nav) extracts straight lines from the scan by split-and-merge,
keeps the near-axis-aligned ones, matches each to the closest visible plan wall of the same
orientation, and shifts x by the median offset of the vertical matches and y by that of the
horizontal ones; yaw is trusted to the IMU. Scan-to-plan ICP lives in
:mod:`f2n_drake.localization.scan_matching`.
"""

from __future__ import annotations

import numpy as np

from f2n_drake.core.errors import InputError


def as_segments(segments: np.ndarray) -> np.ndarray:
    """``segments`` as a float ``(N, 4)`` array; raises InputError on another shape."""
    seg = np.asarray(segments, dtype=float)
    if seg.ndim != 2 or seg.shape[1] != 4:
        raise InputError(f"wall segments must be an (N, 4) array, got shape {seg.shape}")
    return seg


def beam_angles(num_beams: int) -> np.ndarray:
    """Beam angles ``2*pi*i/num_beams`` [rad] in the robot frame."""
    return 2.0 * np.pi * np.arange(num_beams) / num_beams


def transform_points(points: np.ndarray, pose: np.ndarray) -> np.ndarray:
    """Points ``(M, 2)`` given in the frame of ``pose`` [x, y, theta], expressed in the world."""
    c, s = np.cos(pose[2]), np.sin(pose[2])
    rotation = np.array([[c, -s], [s, c]])
    return np.asarray(points, dtype=float) @ rotation.T + np.asarray(pose[:2], dtype=float)


def pose_delta(new_pose: np.ndarray, old_pose: np.ndarray) -> np.ndarray:
    """World-frame correction ``[dx, dy, dtheta]`` taking ``old_pose`` to ``new_pose``.

    It is the rigid motion ``T`` with ``new = T o old``; :func:`apply_pose_delta` applies it to a
    later estimate (so motion integrated since ``old_pose`` was read is kept).
    """
    dtheta = float(new_pose[2] - old_pose[2])
    c, s = np.cos(dtheta), np.sin(dtheta)
    moved = np.array([c * old_pose[0] - s * old_pose[1], s * old_pose[0] + c * old_pose[1]])
    return np.array([new_pose[0] - moved[0], new_pose[1] - moved[1], dtheta])


def apply_pose_delta(delta: np.ndarray, pose: np.ndarray) -> np.ndarray:
    """``T o pose`` for a correction ``T = [dx, dy, dtheta]`` from :func:`pose_delta`."""
    xy = transform_points(np.reshape(pose[:2], (1, 2)), delta)[0]
    return np.array([xy[0], xy[1], pose[2] + delta[2]])


def segments_near(segments: np.ndarray, xy: np.ndarray, radius_m: float) -> np.ndarray:
    """The rows of ``segments`` that pass within ``radius_m`` of the point ``xy``."""
    seg = as_segments(segments)
    return seg[point_segment_distances(np.reshape(xy, (1, 2)), seg)[0] <= radius_m]


def point_segment_distances(points: np.ndarray, segments: np.ndarray) -> np.ndarray:
    """Euclidean distances ``(M, N)`` [m] from each point ``(M, 2)`` to each segment ``(N, 4)``."""
    a, ab = segments[:, :2], segments[:, 2:] - segments[:, :2]
    length2 = np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-18)
    ap = points[:, None, :] - a[None, :, :]
    u = np.clip(np.einsum("mnk,nk->mn", ap, ab) / length2, 0.0, 1.0)
    diff = ap - u[..., None] * ab[None, :, :]
    return np.sqrt(np.einsum("mnk,mnk->mn", diff, diff))


def _first_hits(
    origins: np.ndarray, angles: np.ndarray, seg: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Distance along each ray ``(B,)`` to the first segment hit (``inf`` if none) and its
    row in ``seg`` (``-1`` if none); ``origins`` is ``(B, 2)``."""
    d = np.stack([np.cos(angles), np.sin(angles)], axis=1)  # (B, 2)
    e = seg[:, 2:] - seg[:, :2]  # (N, 2)
    w = seg[None, :, :2] - origins[:, None, :]  # (B, N, 2)
    denom = d[:, None, 0] * e[None, :, 1] - d[:, None, 1] * e[None, :, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (w[..., 0] * e[None, :, 1] - w[..., 1] * e[None, :, 0]) / denom
        u = (w[..., 0] * d[:, None, 1] - w[..., 1] * d[:, None, 0]) / denom
    hit = (np.abs(denom) > 1e-12) & (t >= 0.0) & (u >= 0.0) & (u <= 1.0)
    t = np.where(hit, t, np.inf)
    index = np.argmin(t, axis=1)
    distance = t[np.arange(len(t)), index]
    return distance, np.where(np.isfinite(distance), index, -1)


def as_circles(circles: np.ndarray | None) -> np.ndarray:
    """``circles`` as a float ``(K, 3)`` array of ``[x, y, radius]`` [m] (None: none)."""
    if circles is None:
        return np.zeros((0, 3))
    arr = np.asarray(circles, dtype=float)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise InputError(f"circles must be a (K, 3) array, got shape {arr.shape}")
    return arr


def circle_hits(origins: np.ndarray, angles: np.ndarray, circles: np.ndarray) -> np.ndarray:
    """Distance ``(B,)`` along each ray (``origins`` ``(B, 2)``, ``angles`` ``(B,)``) to the first
    circle ``[x, y, r]`` it enters; ``inf`` if none. A circle round a ray's origin is not seen
    from inside."""
    if len(circles) == 0:
        return np.full(len(angles), np.inf)
    d = np.stack([np.cos(angles), np.sin(angles)], axis=1)  # (B, 2)
    w = origins[:, None, :] - circles[None, :, :2]  # (B, K, 2)
    b = np.einsum("bk,bnk->bn", d, w)
    c = np.einsum("bnk,bnk->bn", w, w) - circles[None, :, 2] ** 2
    disc = b * b - c
    with np.errstate(invalid="ignore"):
        t = -b - np.sqrt(disc)
    t = np.where((disc >= 0.0) & (c > 0.0) & (t >= 0.0), t, np.inf)
    return t.min(axis=1)


def cast_rays(
    origins_xy: np.ndarray,
    angles: np.ndarray,
    segments: np.ndarray,
    max_range: float,
    circles: np.ndarray | None = None,
) -> np.ndarray:
    """Distance [m] along each ray to the first segment or circle it hits; ``+inf`` past
    ``max_range``.

    Args:
        origins_xy: ``(2,)`` shared origin or ``(B, 2)`` one origin per ray [m].
        angles: ``(B,)`` world-frame ray directions [rad].
        segments: ``(N, 4)`` walls [m]; segments out of reach of a shared origin are culled.
        max_range: longest distance reported [m].
        circles: ``(K, 3)`` round obstacles ``[x, y, radius]`` [m] (furniture, people),
            culled likewise; see :func:`circle_hits`.
    """
    seg = as_segments(segments)
    circ = as_circles(circles)
    angles = np.asarray(angles, dtype=float).reshape(-1)
    origins = np.broadcast_to(np.asarray(origins_xy, dtype=float), (angles.size, 2))
    if np.ndim(origins_xy) == 1:
        seg = segments_near(seg, origins_xy, max_range)
        centre_distance = np.hypot(*(circ[:, :2] - np.asarray(origins_xy, float)).T)
        circ = circ[centre_distance - circ[:, 2] <= max_range]
    ranges = np.full(angles.size, np.inf)
    if seg.shape[0] and angles.size:
        ranges = _first_hits(origins, angles, seg)[0]
    if circ.shape[0] and angles.size:
        ranges = np.minimum(ranges, circle_hits(origins, angles, circ))
    ranges[ranges > max_range] = np.inf
    return ranges


def visible_segments(
    xy: np.ndarray, segments: np.ndarray, max_range: float, num_rays: int = 720
) -> np.ndarray:
    """The rows of ``segments`` that a ray from ``xy`` hits first within ``max_range`` [m]
    (``num_rays`` evenly spaced rays): the wall faces a LiDAR there can see."""
    seg = segments_near(as_segments(segments), xy, max_range)
    if len(seg) == 0:
        return seg
    distance, index = _first_hits(
        np.broadcast_to(np.asarray(xy, float), (num_rays, 2)), beam_angles(num_rays), seg
    )
    return seg[np.unique(index[distance <= max_range])]


def simulate_scan(
    pose: np.ndarray,
    segments: np.ndarray,
    num_beams: int = 360,
    min_range: float = 0.12,
    max_range: float = 3.5,
    *,
    noise_std_m: float = 0.0,
    rng: np.random.Generator | None = None,
    circles: np.ndarray | None = None,
) -> np.ndarray:
    """An ideal 2D LiDAR scan from ``pose`` (tests and benchmarks); no return is ``+inf``.

    Gaussian range noise of ``noise_std_m`` [m] is drawn from ``rng`` (required if noise > 0);
    ``circles`` ``(K, 3)`` [m] are round obstacles seen besides the segments.
    """
    ranges = cast_rays(
        np.asarray(pose[:2], float),
        beam_angles(num_beams) + pose[2],
        segments,
        max_range,
        circles,
    )
    if noise_std_m > 0.0:
        if rng is None:
            raise InputError("simulate_scan needs an rng when noise_std_m > 0")
        ranges = ranges + rng.normal(0.0, noise_std_m, ranges.shape)
    ranges[(ranges < min_range) | (ranges > max_range)] = np.inf
    return ranges


def scan_to_points_robot(
    ranges: np.ndarray, min_range: float = 0.12, max_range: float = 3.5
) -> np.ndarray:
    """Valid returns of a scan as ``(M, 2)`` robot-frame points [m], in beam order."""
    ranges = np.asarray(ranges, dtype=float)
    angles = beam_angles(ranges.size)
    valid = np.isfinite(ranges) & (ranges >= min_range) & (ranges <= max_range)
    r, a = ranges[valid], angles[valid]
    return np.stack([r * np.cos(a), r * np.sin(a)], axis=1)


def scan_to_points(
    ranges: np.ndarray, pose: np.ndarray, min_range: float = 0.12, max_range: float = 3.5
) -> np.ndarray:
    """Valid returns of a scan taken at ``pose`` as ``(M, 2)`` world points [m]."""
    return transform_points(scan_to_points_robot(ranges, min_range, max_range), pose)


def _split(points: np.ndarray, threshold: float, min_points: int) -> list[np.ndarray]:
    """Iterative end-point fit: chunks of ordered points no farther than ``threshold`` from
    the chord joining their ends."""
    out, stack = [], [points]
    while stack:
        chunk = stack.pop()
        if len(chunk) < min_points:
            continue
        chord = chunk[-1] - chunk[0]
        norm = np.hypot(*chord)
        if norm < 1e-9:
            continue
        dist = np.abs(
            chord[0] * (chunk[:, 1] - chunk[0, 1]) - chord[1] * (chunk[:, 0] - chunk[0, 0])
        )
        worst = int(np.argmax(dist))
        if dist[worst] / norm <= threshold:
            out.append(chunk)
        else:
            stack.extend([chunk[worst:], chunk[: worst + 1]])
    return out


def _fit_line(points: np.ndarray) -> np.ndarray:
    """Total-least-squares line through ``points`` clipped to their extent: ``[x0, y0, x1, y1]``."""
    centre = points.mean(axis=0)
    direction = np.linalg.svd(points - centre, full_matrices=False)[2][0]
    t = (points - centre) @ direction
    return np.concatenate([centre + t.min() * direction, centre + t.max() * direction])


def _merge(pieces: list[np.ndarray], threshold: float) -> list[np.ndarray]:
    """Join consecutive pieces whose union still fits one line within ``threshold``."""
    merged: list[np.ndarray] = []
    for piece in pieces:
        if merged:
            both = np.concatenate([merged[-1], piece])
            line = _fit_line(both)
            normal = np.array([line[1] - line[3], line[2] - line[0]])
            normal /= max(np.hypot(*normal), 1e-12)
            if np.abs((both - line[:2]) @ normal).max() <= threshold:
                merged[-1] = both
                continue
        merged.append(piece)
    return merged


def extract_line_segments(
    points_robot: np.ndarray,
    *,
    split_threshold_m: float = 0.04,
    max_gap_m: float = 0.25,
    min_points: int = 8,
    min_length_m: float = 0.3,
) -> np.ndarray:
    """Straight walls in an ordered (beam order, wrapping round) scan, by split-and-merge.

    The scan is cut where neighbouring returns are more than ``max_gap_m`` apart, each run is
    split until every point lies within ``split_threshold_m`` of its chord, neighbouring
    collinear pieces are merged, and pieces of at least ``min_points`` points and
    ``min_length_m`` are fitted by total least squares. Returns ``(K, 4)`` segments [m] in the
    frame of the points.
    """
    pts = np.asarray(points_robot, dtype=float)
    if len(pts) < min_points:
        return np.zeros((0, 4))
    gaps = np.hypot(*(np.roll(pts, -1, axis=0) - pts).T)  # gap after each point, wrapping
    breaks = np.flatnonzero(gaps > max_gap_m)
    if breaks.size:  # start right after a break so no run straddles the wrap-around
        pts = np.roll(pts, -(breaks[-1] + 1), axis=0)
        gaps = np.roll(gaps, -(breaks[-1] + 1))
    runs = np.split(pts, np.flatnonzero(gaps[:-1] > max_gap_m) + 1)
    segments = []
    for run in runs:
        pieces = _merge(_split(run, split_threshold_m, min_points), split_threshold_m)
        if breaks.size == 0 and len(pieces) > 1:  # closed scan: first and last may be one wall
            wrapped = _merge([pieces[-1], pieces[0]], split_threshold_m)
            if len(wrapped) == 1:
                pieces = wrapped + pieces[1:-1]
        for piece in pieces:
            line = _fit_line(piece)
            if np.hypot(line[2] - line[0], line[3] - line[1]) >= min_length_m:
                segments.append(line)
    return np.array(segments).reshape(-1, 4)


def _axis_class(segments: np.ndarray, tolerance_rad: float) -> np.ndarray:
    """0 near-horizontal, 1 near-vertical, -1 neither, for each segment."""
    angle = np.mod(
        np.arctan2(segments[:, 3] - segments[:, 1], segments[:, 2] - segments[:, 0]), np.pi
    )
    off_horizontal = np.minimum(angle, np.pi - angle)
    cls = np.full(len(segments), -1)
    cls[off_horizontal <= tolerance_rad] = 0
    cls[np.abs(angle - np.pi / 2) <= tolerance_rad] = 1
    return cls


def correct_axis_aligned(
    scan_segments_robot: np.ndarray,
    estimated_pose: np.ndarray,
    wall_segments: np.ndarray,
    *,
    angle_tolerance_deg: float = 10.0,
    gate_m: float = 0.3,
    max_range: float = 3.5,
    visibility_tolerance_m: float = 0.05,
) -> tuple[np.ndarray, int]:
    """FloorPlan2Nav correction of x and y (not yaw) on an axis-aligned plan.

    Each scan line (robot frame, e.g. from :func:`extract_line_segments`) is placed in the world
    with ``estimated_pose``; a near-vertical one is matched to the vertical plan wall within
    ``gate_m`` of it whose extent overlaps it and whose facing side is visible from the robot
    (likewise horizontal). x moves by the median offset of the vertical matches, y by that of
    the horizontal ones. Returns ``(corrected_pose, number_of_matches)``.
    """
    pose = np.asarray(estimated_pose, dtype=float).copy()
    walls = segments_near(as_segments(wall_segments), pose[:2], max_range + gate_m)
    scan = np.asarray(scan_segments_robot, dtype=float).reshape(-1, 4)
    if len(scan) == 0 or len(walls) == 0:
        return pose, 0
    world = np.concatenate(
        [transform_points(scan[:, :2], pose), transform_points(scan[:, 2:], pose)], axis=1
    )
    tolerance = np.deg2rad(angle_tolerance_deg)
    scan_cls, wall_cls = _axis_class(world, tolerance), _axis_class(walls, np.deg2rad(1.0))
    offsets: list[list[float]] = [[], []]  # [horizontal -> dy, vertical -> dx]
    for line, cls in zip(world, scan_cls, strict=True):
        if cls < 0:
            continue
        across, along = (1, 0) if cls == 0 else (0, 1)  # coordinate fixed by the wall / along it
        level = 0.5 * (line[across] + line[across + 2])
        lo, hi = sorted((line[along], line[along + 2]))
        cand = walls[wall_cls == cls]
        cand_level = 0.5 * (cand[:, across] + cand[:, across + 2])
        cand_lo = np.minimum(cand[:, along], cand[:, along + 2])
        cand_hi = np.maximum(cand[:, along], cand[:, along + 2])
        ok = (np.abs(cand_level - level) <= gate_m) & (cand_lo < hi) & (cand_hi > lo)
        for k in np.argsort(np.abs(cand_level - level)):
            if not ok[k]:
                continue
            target = np.empty(2)  # point of the candidate wall opposite the scan line's middle
            target[across] = cand_level[k]
            target[along] = np.clip(0.5 * (lo + hi), cand_lo[k], cand_hi[k])
            ray = target - pose[:2]
            dist = np.hypot(*ray)
            seen = cast_rays(pose[:2], np.array([np.arctan2(ray[1], ray[0])]), walls, dist + 1.0)[0]
            if seen >= dist - visibility_tolerance_m:
                offsets[cls].append(cand_level[k] - level)
                break
    if offsets[1]:
        pose[0] += float(np.median(offsets[1]))
    if offsets[0]:
        pose[1] += float(np.median(offsets[0]))
    return pose, len(offsets[0]) + len(offsets[1])
