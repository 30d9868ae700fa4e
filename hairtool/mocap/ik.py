"""Inverse kinematics on one pose of a capture: move a joint to a target by rotating its parents.

Seed 003 §5 edits a key pose by dragging a joint as an end effector; the joints above it turn
so that it arrives. Only rotation channels change: the bone lengths are the skeleton's offsets
(rotations cannot stretch them) and the root's translation stays where the capture put it.

- :func:`solve_two_bone` the analytic solve of a chain of two (upper and lower limb): the law of
  cosines bends the middle joint, then the top joint turns the limb onto the target and twists
  it so the middle joint stays on the side it bent to (the pole is the current bend);
- :func:`solve_dls` damped least squares (Levenberg–Marquardt damping) on the chain's rotation
  channels themselves, for any chain length and any channel layout, started from the current
  angles so the solution stays continuous with them;
- :func:`euler_nearest` writes a rotation back as angles in a joint's channel order, the
  representation nearest given angles (no 360° turns, no jump to the other Euler family).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hairtool.errors import ParameterError
from hairtool.mocap import quaternion as quat
from hairtool.mocap.bvh import Motion

F64 = NDArray[np.float64]

#: Convergence of a solve, as a share of the figure's height (issue 30: 1e-4).
TOLERANCE = 1e-4
_MAX_ITERATIONS = 300
_MAX_STEP_DEGREES = 20.0  # per channel and iteration: keeps a far target from wrapping a joint


def figure_height(motion: Motion) -> float:
    """The rest skeleton's (all channels 0) largest extent over joints and End Sites: a standing
    figure's height, the length scale of the IK's tolerance.

    Parameters
    ----------
    motion : Motion
        The capture.

    Returns
    -------
    float
        The height, in the capture's units.
    """
    rest = motion.with_values(np.zeros((1, motion.n_channels)))
    p = rest.joint_positions(end_sites=True)[0]
    h = float(np.max(p.max(axis=0) - p.min(axis=0)))
    return h if h > 0 else 1.0


def ancestors(motion: Motion, joint: int, n: int) -> list[int]:
    """The ``n`` nearest ancestors of ``joint``, nearest first (its parent, its grandparent, …).

    Parameters
    ----------
    motion : Motion
        The capture.
    joint : int
        The joint's index.
    n : int
        How many, at most the joint's ancestors (ParameterError otherwise).

    Returns
    -------
    list of int
        Their indices.
    """
    out: list[int] = []
    j = int(motion.parents[joint])
    while j >= 0 and len(out) < n:
        out.append(j)
        j = int(motion.parents[j])
    if len(out) < n:
        name = motion.joint_names[joint]
        raise ParameterError("chain", n, f"at most {len(out)}, the ancestors of joint '{name}'")
    return out


def rotation_columns(motion: Motion, joint: int) -> tuple[list[int], str]:
    """The value columns of a joint's rotation channels and their axis order (e.g. "ZXY").

    Parameters
    ----------
    motion : Motion
        The capture.
    joint : int
        The joint's index.

    Returns
    -------
    tuple of (list of int, str)
        The columns and the axis order (empty for a joint without rotation channels).
    """
    start = int(motion._starts[joint])
    chans = motion.channels[joint]
    cols = [start + k for k, c in enumerate(chans) if c.endswith("rotation")]
    return cols, "".join(chans[c - start][0] for c in cols)


def is_ball_joint(motion: Motion, joint: int) -> bool:
    """Three rotation channels about three distinct axes: any orientation, a quaternion's worth.

    Parameters
    ----------
    motion : Motion
        The capture.
    joint : int
        The joint's index.

    Returns
    -------
    bool
        True for a ball joint.
    """
    _, order = rotation_columns(motion, joint)
    return len(order) == 3 and len(set(order)) == 3


@dataclass
class Solve:
    """The channel values of the solved pose, how far the effector is from its target (scene
    units), how many iterations it took (0: analytic) and which solver ran."""

    values: F64
    miss: float
    iterations: int
    method: str


class _Pose:
    """One frame's local translations and rotations, and forward kinematics along the path from
    the root to one joint (all an effector's position depends on)."""

    def __init__(self, motion: Motion, values: F64, effector: int) -> None:
        self.motion = motion
        one = motion.with_values(np.asarray(values, dtype=np.float64)[None])
        self.t = one.local_translations()[0]
        self.q = one.local_rotations()[0]
        path = [effector]
        while motion.parents[path[-1]] >= 0:
            path.append(int(motion.parents[path[-1]]))
        self.path = path[::-1]  # root first

    def set_angles(self, joint: int, values: F64) -> None:
        cols, order = rotation_columns(self.motion, joint)
        if cols:
            self.q[joint] = quat.from_euler(values[cols], order)

    def forward(self) -> tuple[dict[int, F64], dict[int, F64]]:
        """World positions and rotations of the joints on the path."""
        pos: dict[int, F64] = {}
        rot: dict[int, F64] = {}
        for j in self.path:
            p = int(self.motion.parents[j])
            if p < 0:
                pos[j], rot[j] = self.t[j].copy(), self.q[j].copy()
            else:
                pos[j] = pos[p] + quat.rotate(rot[p], self.t[j])
                rot[j] = quat.multiply(rot[p], self.q[j])
        return pos, rot


def _solve(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The damped step: ``a`` is symmetric positive semi-definite plus λ²·I, but λ² can vanish
    beside its other entries (two joints turning the effector the same way make two equal
    columns): then the least-squares step, never ``LinAlgError: Singular matrix``."""
    try:
        return np.linalg.solve(a, b)
    except np.linalg.LinAlgError:
        return np.linalg.lstsq(a, b, rcond=None)[0]


def _check_target(target: ArrayLike) -> F64:
    t = np.asarray(target, dtype=np.float64)
    if t.shape != (3,) or not np.all(np.isfinite(t)):
        raise ParameterError("target", t.tolist() if t.size <= 3 else f"shape {t.shape}", "3 finite numbers")
    return t


def _dofs(motion: Motion, chain: list[int]) -> list[tuple[int, int, int]]:
    """``(joint, column, position in the joint's order)`` for every rotation channel of the chain."""
    out = []
    for j in chain:
        cols, _ = rotation_columns(motion, j)
        out += [(j, c, k) for k, c in enumerate(cols)]
    return out


def _jacobian(motion: Motion, pose: _Pose, dofs, values: F64, effector: int) -> tuple[F64, F64]:
    """The effector's position and its ``(3, n)`` derivatives by each channel, per degree.

    Channel k of a joint with order c1 c2 c3 turns about the world axis W_parent·R_c1…R_c(k−1)·e_ck
    through the joint, so the effector moves by that axis × (P_e − P_joint) per radian."""
    pos, rot = pose.forward()
    pe = pos[effector]
    jac = np.empty((3, len(dofs)))
    for n, (j, _, k) in enumerate(dofs):
        cols, order = rotation_columns(motion, j)
        p = int(motion.parents[j])
        frame = quat.identity() if p < 0 else rot[p]
        if k:
            frame = quat.multiply(frame, quat.from_euler(values[cols[:k]], order[:k]))
        axis = quat.rotate(frame, np.eye(3)["XYZ".index(order[k])])
        jac[:, n] = np.cross(axis, pe - pos[j]) * (np.pi / 180.0)
    return pe, jac


def solve_dls(
    motion: Motion,
    values: ArrayLike,
    effector: int,
    chain: list[int],
    target: ArrayLike,
    tolerance: float,
    max_iterations: int = _MAX_ITERATIONS,
) -> Solve:
    """Damped least squares on the chain's rotation channels (degrees), from the given angles.

    Each step solves (JᵀJ + λ²I) δ = Jᵀ e; λ shrinks while steps reduce the miss and grows when
    one would not (Levenberg–Marquardt), so far from the target it walks and near it converges
    as fast as Gauss–Newton. Stops within ``tolerance`` (scene units) or when no step helps (a
    target out of reach: the effector as near as the limb allows).

    Parameters
    ----------
    motion : Motion
        The capture.
    values : array_like
        ``(C,)`` the pose's channel values, the start.
    effector : int
        The joint moved.
    chain : list of int
        The joints turned.
    target : array_like
        Three finite numbers, world space.
    tolerance : float
        How near is there, in scene units.
    max_iterations : int, default 300
        The most steps.

    Returns
    -------
    Solve
        The new values, the miss, the steps taken and the solver's name.
    """
    t = _check_target(target)
    x = np.array(values, dtype=np.float64, copy=True)
    dofs = _dofs(motion, chain)
    if not dofs:
        raise ParameterError("chain", [motion.joint_names[j] for j in chain], "joints with rotation channels")
    cols = np.array([c for _, c, _ in dofs])
    pose = _Pose(motion, x, effector)
    pe, jac = _jacobian(motion, pose, dofs, x, effector)
    miss = float(np.linalg.norm(t - pe))
    scale = max(float(np.linalg.norm(jac)), 1e-12)
    lam = 1e-3 * scale
    it = 0
    while miss > tolerance and it < max_iterations:
        it += 1
        e = t - pe
        a = jac.T @ jac + (lam * lam) * np.eye(len(dofs))
        step = _solve(a, jac.T @ e)
        big = float(np.max(np.abs(step)))
        if big > _MAX_STEP_DEGREES:
            step *= _MAX_STEP_DEGREES / big
        trial = x.copy()
        trial[cols] += step
        for j in chain:
            pose.set_angles(j, trial)
        pe_t, jac_t = _jacobian(motion, pose, dofs, trial, effector)
        miss_t = float(np.linalg.norm(t - pe_t))
        if miss_t < miss:
            x, pe, jac, miss = trial, pe_t, jac_t, miss_t
            lam = max(lam * 0.3, 1e-9 * scale)
        else:
            for j in chain:
                pose.set_angles(j, x)
            lam *= 4.0
            if lam > 1e6 * scale:
                break  # no step reduces the miss: as near as the chain reaches
    return Solve(x, miss, it, "damped least squares")


def _rotation_between(u: F64, v: F64) -> F64:
    """The shortest rotation taking direction u to direction v."""
    u = u / np.linalg.norm(u)
    v = v / np.linalg.norm(v)
    axis = np.cross(u, v)
    s, c = float(np.linalg.norm(axis)), float(np.dot(u, v))
    if s < 1e-12:
        if c > 0:
            return quat.identity()
        other = np.eye(3)[int(np.argmin(np.abs(u)))]
        axis = np.cross(u, other)
        return quat.from_axis_angle(axis / np.linalg.norm(axis), np.pi)
    return quat.from_axis_angle(axis / s, np.arctan2(s, c))


def _about(axis: F64, u: F64, v: F64) -> float:
    """Signed angle from u to v about ``axis`` (unit), both projected onto the plane normal to it."""
    pu = u - np.dot(u, axis) * axis
    pv = v - np.dot(v, axis) * axis
    if np.linalg.norm(pu) < 1e-12 or np.linalg.norm(pv) < 1e-12:
        return 0.0
    return float(np.arctan2(np.dot(axis, np.cross(pu, pv)), np.dot(pu, pv)))


def _local_after(world_parent: F64, turn: F64, local: F64) -> F64:
    """A joint's new local rotation once its world frame is turned by ``turn``: W_p⁻¹ D W_p L."""
    inside = quat.multiply(quat.conjugate(world_parent), quat.multiply(turn, world_parent))
    return quat.multiply(inside, local)


def solve_two_bone(
    motion: Motion, values: ArrayLike, effector: int, target: ArrayLike, reference: ArrayLike | None = None
) -> Solve | None:
    """The analytic solve of the effector's parent (middle) and grandparent (top), or None where
    it does not apply (either joint lacks three rotation channels, or a bone has no length).

    The middle joint turns about the normal of the plane the limb bends in until the top-to-
    effector distance is the top-to-target distance (law of cosines; clamped to the reach); the
    top joint then turns the effector onto the target by the shortest rotation and twists about
    the top-to-target axis to put the middle joint back on its side of it (the pole is the
    current bend). Angles come back nearest ``reference`` (default: the given values).

    Parameters
    ----------
    motion : Motion
        The capture.
    values : array_like
        ``(C,)`` the pose's channel values.
    effector : int
        The joint moved.
    target : array_like
        Three finite numbers, world space.
    reference : array_like, optional
        ``(C,)`` values the new angles are written nearest (None: ``values``).

    Returns
    -------
    Solve or None
        The solve, or None where it does not apply.
    """
    t = _check_target(target)
    x = np.array(values, dtype=np.float64, copy=True)
    mid = int(motion.parents[effector])
    top = int(motion.parents[mid]) if mid >= 0 else -1
    if top < 0 or not (is_ball_joint(motion, mid) and is_ball_joint(motion, top)):
        return None
    pose = _Pose(motion, x, effector)
    pos, rot = pose.forward()
    s, e, w = pos[top], pos[mid], pos[effector]
    upper, lower = e - s, w - e
    a, b = float(np.linalg.norm(upper)), float(np.linalg.norm(lower))
    if min(a, b) < 1e-9 * figure_height(motion):
        return None
    reach = t - s
    d = float(np.clip(np.linalg.norm(reach), abs(a - b), a + b))
    normal = np.cross(upper, lower)
    if np.linalg.norm(normal) < 1e-9 * a * b:  # a straight limb: bend it towards the target
        normal = np.cross(upper, reach)
        if np.linalg.norm(normal) < 1e-9 * a * float(np.linalg.norm(reach)) + 1e-300:
            normal = np.cross(upper, np.eye(3)[int(np.argmin(np.abs(upper)))])
    normal /= np.linalg.norm(normal)
    bend = float(np.arctan2(np.dot(normal, np.cross(upper, lower)), np.dot(upper, lower)))
    want = np.pi - float(np.arccos(np.clip((a * a + b * b - d * d) / (2 * a * b), -1.0, 1.0)))
    turn_mid = quat.from_axis_angle(normal, want - bend)
    lower2 = quat.rotate(turn_mid, lower)
    turn_top = _rotation_between(upper + lower2, reach) if np.linalg.norm(reach) > 0 else quat.identity()
    axis = reach / max(float(np.linalg.norm(reach)), 1e-300)
    twist = _about(axis, quat.rotate(turn_top, upper), upper)
    turn_top = quat.multiply(quat.from_axis_angle(axis, twist), turn_top)

    q_mid = _local_after(rot[top], turn_mid, pose.q[mid])
    p_top = int(motion.parents[top])
    world_above = quat.identity() if p_top < 0 else rot[p_top]
    q_top = _local_after(world_above, turn_top, pose.q[top])
    ref = x if reference is None else np.asarray(reference, dtype=np.float64)
    for j, q in ((mid, q_mid), (top, q_top)):
        cols, order = rotation_columns(motion, j)
        x[cols] = euler_follow(ref[cols], q, order)
    pose = _Pose(motion, x, effector)
    miss = float(np.linalg.norm(t - pose.forward()[0][effector]))
    return Solve(x, miss, 0, "two-bone")


def solve(
    motion: Motion,
    values: ArrayLike,
    effector: int,
    chain: int,
    target: ArrayLike,
    tolerance: float | None = None,
    method: str = "auto",
    reference: ArrayLike | None = None,
) -> Solve:
    """Move ``effector`` to ``target`` by turning its ``chain`` nearest ancestors.

    ``method``: "auto" (two-bone where chain = 2 and it applies, then damped least squares to
    finish if the analytic pose misses by more than the tolerance; damped least squares
    otherwise), "two-bone" or "dls". ``tolerance`` defaults to 1e-4 of the figure's height.

    Parameters
    ----------
    motion : Motion
        The capture.
    values : array_like
        ``(C,)`` the pose's channel values.
    effector : int
        The joint moved.
    chain : int
        How many of its nearest ancestors turn.
    target : array_like
        Three finite numbers, world space.
    tolerance : float, optional
        How near is there (None: 1e-4 of the figure's height).
    method : {"auto", "two-bone", "dls"}, default "auto"
        The solver.
    reference : array_like, optional
        ``(C,)`` values the new angles are written nearest (None: ``values``).

    Returns
    -------
    Solve
        The new values, the miss (out of reach: as near as the chain allows), the steps and the
        solver.
    """
    tol = TOLERANCE * figure_height(motion) if tolerance is None else float(tolerance)
    joints = ancestors(motion, effector, chain)
    if method not in ("auto", "two-bone", "dls"):
        raise ParameterError("method", method, "auto, two-bone or dls")
    if method == "dls" or (method == "auto" and chain != 2):
        return solve_dls(motion, values, effector, joints, target, tol)
    if chain != 2:
        raise ParameterError("chain", chain, "2 for the two-bone solve")
    out = solve_two_bone(motion, values, effector, target, reference)
    if out is None:
        if method == "two-bone":
            why = "two joints with three rotation channels and bones of some length"
            raise ParameterError("method", method, why)
        return solve_dls(motion, values, effector, joints, target, tol)
    if method == "auto" and out.miss > tol:
        # Out of reach (the limb straight at its clamp) or a degenerate bend: the DLS from the
        # analytic pose says whether any pose gets nearer.
        more = solve_dls(motion, out.values, effector, joints, target, tol)
        if more.miss < out.miss:
            return Solve(more.values, more.miss, more.iterations, "two-bone + damped least squares")
    return out


def euler_nearest(q: ArrayLike, order: str, reference: ArrayLike) -> F64:
    """Angles (degrees) in ``order`` for the rotation q, nearest ``reference`` angles.

    A rotation has two Euler triples, (a, b, c) and (a + 180°, 180° − b, c + 180°), each up to
    whole turns per angle: of these, the one with the least squared distance to ``reference``.
    Orders with fewer than three distinct axes take the nearest whole turns of their angles.

    Parameters
    ----------
    q : array_like
        ``(4,)`` a unit quaternion.
    order : str
        The axis order, e.g. "ZXY".
    reference : array_like
        ``(3,)`` angles in degrees.

    Returns
    -------
    ndarray
        ``(3,)`` float64 angles in degrees.
    """
    ref = np.asarray(reference, dtype=np.float64)
    o = order.upper()
    if len(o) != 3 or len(set(o)) != 3:
        raise ParameterError("order", order, "three distinct axes")
    base = quat.to_euler(q, o)
    other = base + np.array([180.0, 0.0, 180.0])
    other[..., 1] = 180.0 - base[..., 1]
    best, best_d = None, None
    for cand in (base, other):
        c = cand + 360.0 * np.round((ref - cand) / 360.0)
        dist = np.sum((c - ref) ** 2, axis=-1)
        if best is None:
            best, best_d = c, dist
        else:
            pick = dist < best_d
            best = np.where(pick[..., None], c, best)
            best_d = np.where(pick, dist, best_d)
    return best


def euler_follow(start: ArrayLike, q: ArrayLike, order: str, step_degrees: float = 2.0) -> F64:
    """Angles (degrees) in ``order`` for the rotation q, reached from the angles ``start`` by
    following the shortest turn between the two rotations in small steps, each written nearest
    the last: the angles a joint's channels pass through as it turns continuously there. Where
    the turn passes near gimbal lock the first and last angles swing together, and the result
    stays on the side of the lock the turn takes (the nearest triple to ``start`` may not).

    Parameters
    ----------
    start : array_like
        ``(3,)`` angles in degrees, where the turn starts.
    q : array_like
        ``(4,)`` the rotation reached.
    order : str
        The axis order.
    step_degrees : float, default 2.0
        The largest turn between two steps.

    Returns
    -------
    ndarray
        ``(3,)`` float64 angles in degrees.
    """
    a = np.asarray(start, dtype=np.float64)
    q0 = quat.from_euler(a, order)
    q1 = np.asarray(q, dtype=np.float64)
    turn = np.degrees(2.0 * float(quat.distance(q0, q1)))
    n = max(1, int(np.ceil(turn / step_degrees)))
    for t in np.arange(1, n + 1) / n:
        a = euler_nearest(quat.slerp(q0, q1, t), order, a)
    return a
