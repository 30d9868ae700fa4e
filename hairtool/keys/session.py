"""The whole keyframe solve, for every caller: ``hairtool keys``, the studio's background jobs,
scripts and tests.

A :class:`KeySession` is one animation (or ``(frames, D)`` feature array) under one table
setting: seed 000's features (:mod:`.features`) → the segment cost table (:mod:`.costs`) → the
layered DP for every key count up to a cap (:mod:`.dp`). After that solve the keys for any count
are a back-pointer trace (instant: a key-count slider needs no new solve), and the keys for a
price tau per key (seed 003), an error budget or a worst-frame bound come from the same table.
Errors of a key set are measured on the original vertices against the key curve, a chunk of
frames at a time in float64 (:func:`.reconstruct.key_curve_errors`), so nothing of the size of
a whole reconstruction is ever held.

Long steps take ``progress(fraction, stage)`` and ``cancelled() -> bool`` callbacks; a cancelled
step returns None instead of its result.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hairtool.errors import ParameterError
from hairtool.groom import Animation
from hairtool.keys import notes
from hairtool.keys.constraints import KeyConstraints
from hairtool.keys.costs import INTERPOLATIONS, OBJECTIVES, cost_table
from hairtool.keys.dp import (
    DEFAULT_CURVE_KEYS,
    Selection,
    check_table,
    select_keys,
    solve_layers,
    uniform_keys,
)
from hairtool.keys.edit import KeyEditor
from hairtool.keys.features import FeatureOptions, frame_features
from hairtool.keys.reconstruct import (
    KeyPoses,
    check_keys,
    interpolate_at,
    key_curve_errors,
    key_poses,
    motion_speed,
)

F32 = NDArray[np.float32]
F64 = NDArray[np.float64]
I64 = NDArray[np.int64]

#: How the keys are chosen: a key count, a price tau per key, or an error budget.
KEY_MODES = ("count", "tau", "budget")
MAX_CURVE_KEYS = 200  # the layers (and the error-vs-count curve) cover K = 2..min(frames, this)
KNEE_KEYS = 100  # the default count is the knee of the curve up to this many keys

Progress = Callable[..., None]
CancelCheck = Callable[[], bool]


@dataclass(frozen=True)
class KeySettings:
    """What a caller chose: the mode and its value, the objective, the interpolation, features.

    ``count`` 0 means the knee of the unconstrained error-vs-count curve (:attr:`KeySession.knee`:
    pins and exclusions steer which keys, not how many); ``tau`` is the
    price of a key as a share of the two-key error (:meth:`KeySession.keys_for_tau`), so it means
    the same on any animation; ``samples`` 0 keeps the original vertices instead of resampling M
    points per strand; ``tip_weight`` is seed 000's root-to-tip weight at the tip
    (1 at the root); ``curvature`` is its λ. ``budget`` bounds the total feature-space error
    (objective "total") or the worst frame's (objective "worst"). ``pins`` and ``excludes`` are
    frames that must and must not be keys (:mod:`hairtool.keys.constraints`), in every mode.
    """

    mode: str = "count"
    count: int = 0
    tau: float = 0.01
    budget: float = 1.0
    objective: str = "total"
    interp: str = "linear"
    samples: int = 16
    tip_weight: float = 2.0
    curvature: float = 0.0
    pins: tuple[int, ...] = ()
    excludes: tuple[int, ...] = ()

    def __post_init__(self) -> None:
        c = KeyConstraints(self.pins, self.excludes)  # sorted, unique, whole frames (a project's lists)
        object.__setattr__(self, "pins", c.pins)
        object.__setattr__(self, "excludes", c.excludes)

    @property
    def constraints(self) -> KeyConstraints:
        return KeyConstraints(self.pins, self.excludes)

    def validate(self) -> KeySettings:
        if self.mode not in KEY_MODES:
            raise ParameterError("key mode", self.mode, f"one of {', '.join(KEY_MODES)}")
        if self.objective not in OBJECTIVES:
            raise ParameterError("objective", self.objective, " or ".join(OBJECTIVES))
        if self.interp not in INTERPOLATIONS:
            raise ParameterError("interpolation", self.interp, " or ".join(INTERPOLATIONS))
        if self.mode == "tau" and self.objective != "total":
            raise ParameterError("tau", self.tau, "the total-error objective (a price per key adds up)")
        if self.interp == "hermite-fit" and self.objective != "total":
            raise ParameterError("objective", self.objective, "total with fitted tangents (least squares)")
        if int(self.count) != self.count or self.count < 0:
            raise ParameterError("key count", self.count, "a whole number >= 2 (0: the knee of the curve)")
        for name in ("tau", "budget", "curvature"):
            v = getattr(self, name)
            if not np.isfinite(v) or v < 0:
                raise ParameterError(name, v, "a finite number >= 0")
        if int(self.samples) != self.samples or self.samples == 1 or self.samples < 0:
            raise ParameterError("samples", self.samples, "a whole number >= 2 (0: the original vertices)")
        if not np.isfinite(self.tip_weight) or self.tip_weight <= 0:
            raise ParameterError("tip weight", self.tip_weight, "a finite number > 0")
        return self

    def replace(self, **changes: object) -> KeySettings:
        """These settings with ``changes``, checked again.

        Parameters
        ----------
        **changes : object
            New values by field name.

        Returns
        -------
        KeySettings
            The changed, validated copy.
        """
        return replace(self, **changes).validate()

    @property
    def table_key(self) -> tuple:
        """The settings a cost table depends on: a change here needs a new :func:`solve`."""
        return (self.objective, self.interp, self.samples, self.tip_weight, self.curvature)

    def feature_options(self) -> FeatureOptions:
        return FeatureOptions(samples=self.samples or None, tip_weight=float(self.tip_weight))



class KeySession:
    """A segment cost table and, once :meth:`layers` ran, its layered DP: ``energy[K, n−1]`` is
    the best error with exactly K keys, ``back`` the back-pointers that trace those keys."""

    def __init__(
        self,
        table: ArrayLike,
        *,
        objective: str = "total",
        interp: str = "linear",
        curvature: float = 0.0,
        kmax: int = MAX_CURVE_KEYS,
        table_key: tuple = (),
        constraints: KeyConstraints | None = None,
    ) -> None:
        """A session over ``table``; nothing is solved until :meth:`layers`.

        Parameters
        ----------
        table : array_like
            ``(n, n)`` segment costs.
        objective : {"total", "worst"}, default "total"
            What the table's entries are.
        interp : str, default "linear"
            The curve the table was built for (reported, and kept in :attr:`table_key`).
        curvature : float, default 0.0
            The table's curvature weight (reported likewise).
        kmax : int, default MAX_CURVE_KEYS
            The most keys the layered DP solves for.
        table_key : tuple, default ()
            What the table depends on (empty: built from the above).
        constraints : KeyConstraints, optional
            Pinned and excluded frames.
        """
        self.table = check_table(table)
        if objective not in OBJECTIVES:
            raise ParameterError("objective", objective, " or ".join(OBJECTIVES))
        self.objective, self.interp, self.curvature = objective, interp, float(curvature)
        self.constraints = (constraints or KeyConstraints()).check(self.n_frames)
        self.kmax = int(min(self.n_frames, max(2, kmax)))
        self.table_key = table_key or (objective, interp, None, None, self.curvature)
        self.energy: F64 | None = None  # (kmax + 1, n)
        self.back: I64 | None = None  # (kmax + 1, n)
        self._knee: int | None = None  # of the unconstrained curve: the table's, kept across constrain()

    @property
    def n_frames(self) -> int:
        return int(self.table.shape[0])

    def constrain(self, constraints: KeyConstraints | None) -> KeySession:
        """The same table under other pins and exclusions (the layers are solved again, the
        table is not rebuilt): what a dope sheet edit asks for.

        Parameters
        ----------
        constraints : KeyConstraints or None
            The new pins and exclusions (None: none).

        Returns
        -------
        KeySession
            A session sharing this one's table.
        """
        constraints = (constraints or KeyConstraints()).check(self.n_frames)
        if constraints != self.constraints:
            self.constraints, self.energy, self.back = constraints, None, None
        return self

    @property
    def key_range(self) -> tuple[int, int]:
        """The fewest and the most keys the layers offer under the constraints."""
        lo, hi = self.constraints.key_range(self.n_frames)
        return lo, min(hi, self.kmax)

    def layers(self, progress: Callable[[float], None] | None = None) -> KeySession:
        """Solve the DP for every K up to ``kmax`` (once; later calls return at once);
        ``progress(share)`` as it goes.

        Parameters
        ----------
        progress : callable, optional
            ``progress(share)`` with share in [0, 1].

        Returns
        -------
        KeySession
            This session, solved.
        """
        if self.energy is None:
            self.energy, self.back, _ = solve_layers(
                self.table, self.kmax, self.objective, constraints=self.constraints, progress=progress
            )
        return self

    @property
    def curve(self) -> F64:
        """``(m, 2)`` rows (K, optimal error with K keys) for the counts the constraints allow up
        to kmax (feature units)."""
        self.layers()
        lo, hi = self.key_range
        ks = np.arange(lo, hi + 1)
        return np.column_stack([ks, self.energy[ks, self.n_frames - 1]])

    def keys_for_count(self, k: int) -> I64:
        """The DP keys for exactly ``k`` keys, traced back through the stored layers.

        Parameters
        ----------
        k : int
            The key count, 2 … :attr:`kmax`.

        Returns
        -------
        ndarray
            ``(k,)`` int64 key frames.
        """
        lo, hi = self.key_range
        if not lo <= k <= hi:
            why = "" if not self.constraints else " with these pins and exclusions"
            raise ParameterError("key count", k, f"a whole number in [{lo}, {hi}]{why}")
        self.layers()
        keys = [self.n_frames - 1]
        for depth in range(k, 1, -1):
            keys.append(int(self.back[depth, keys[-1]]))
        return np.array(keys[::-1], dtype=np.int64)

    @property
    def two_key_error(self) -> float:
        """The error of keying only the first and last frame: the scale of this animation's errors."""
        return float(self.table[0, self.n_frames - 1])

    def keys_for_tau(self, tau: float, *, relative: bool = True) -> I64:
        """Seed 003's keys with a price per key (total objective only). ``relative``: tau is a
        share of :attr:`two_key_error` (a key is kept when it saves at least that share of the
        error of keying the ends alone), so 0.01 means the same on a sway and on a 10⁸-unit
        simulation; otherwise tau is seed 003's absolute price, in squared feature units.

        Parameters
        ----------
        tau : float
            The price of a key.
        relative : bool, default True
            ``tau`` is a share of :attr:`two_key_error`, not an absolute error.

        Returns
        -------
        ndarray
            int64 key frames.
        """
        price = float(tau) * self.two_key_error if relative else float(tau)
        return select_keys(self.table, penalty=price, curve_keys=0, constraints=self.constraints).keys

    @property
    def knee(self) -> int:
        """The default key count: :func:`knee_count` of the UNCONSTRAINED curve up to
        :data:`KNEE_KEYS` keys. It is a property of the animation, held while the animator
        steers (as a key reducer's count is): pinning a frame that is already a key changes
        nothing, moving a key keeps the count; the knee of the constrained curve would move with
        every pin."""
        if self._knee is None:
            top = min(self.kmax, KNEE_KEYS)
            if not self.constraints and self.energy is not None:
                energy = self.energy
            else:  # one unconstrained solve of the layers the knee reads (energies only)
                energy, _, _ = solve_layers(self.table, top, self.objective)
            ks = np.arange(2, top + 1)
            self._knee = knee_count(np.column_stack([ks, energy[ks, self.n_frames - 1]]))
        return self._knee

    def default_count(self) -> int:
        """:attr:`knee`, raised or lowered into the counts the pins and exclusions allow."""
        lo, hi = self.constraints.key_range(self.n_frames)
        return min(max(self.knee, lo), hi)

    def keys_for_budget(self, budget: float) -> I64:
        """The fewest keys whose error (total, or worst frame) is within ``budget``.

        Parameters
        ----------
        budget : float
            The error allowed.

        Returns
        -------
        ndarray
            int64 key frames.
        """
        self.layers()
        e = self.energy[2 : self.kmax + 1, self.n_frames - 1]
        fits = np.flatnonzero(e <= budget)
        if fits.size:
            return self.keys_for_count(int(fits[0]) + 2)
        bound = {"budget": budget} if self.objective == "total" else {"max_error": budget}
        return select_keys(
            self.table, objective=self.objective, curve_keys=0, constraints=self.constraints, **bound
        ).keys

    def keys_for(self, settings: KeySettings) -> I64:
        """The DP keys the settings ask for (count, tau or budget, under their pins and exclusions).

        All or nothing: a ParameterError (a budget these pins and exclusions cannot meet) leaves
        the session under its previous constraints, so a refused edit can be dropped whole.

        Parameters
        ----------
        settings : KeySettings
            The mode (count, tau or budget) and its value.

        Returns
        -------
        ndarray
            int64 key frames.
        """
        before = (self.constraints, self.energy, self.back)
        try:
            self.constrain(settings.constraints)
            if settings.mode == "tau":
                return self.keys_for_tau(settings.tau)
            if settings.mode == "budget":
                return self.keys_for_budget(settings.budget)
            lo, hi = self.key_range
            count = settings.count or self.default_count()
            return self.keys_for_count(min(max(count, lo), hi))
        except ParameterError:
            self.constraints, self.energy, self.back = before
            raise

    def explain(self, sel: Selection) -> str | None:
        """Why a tau, budget or bound gave one of the two extremes (a key on every frame the
        constraints allow, or no keys but the ends and pins), in words a user can act on; None
        otherwise (:func:`hairtool.keys.notes.explain`).

        Parameters
        ----------
        sel : Selection
            A selection this session made.

        Returns
        -------
        str or None
            The reason, or None where the selection is not an extreme.
        """
        return notes.explain(self.table, self.constraints, self.objective, sel)

    def select(
        self,
        *,
        keys: int | None = None,
        penalty: float | None = None,
        budget: float | None = None,
        max_error: float | None = None,
        curve_keys: int = DEFAULT_CURVE_KEYS,
        progress: Callable[[float], None] | None = None,
    ) -> Selection:
        """Exactly one of ``keys``, ``penalty``, ``budget``, ``max_error`` (see
        :func:`hairtool.keys.dp.select_keys`), with uniform keys of the same count and the
        error-vs-count curve up to ``curve_keys``: the record ``hairtool keys`` prints.

        Parameters
        ----------
        keys, penalty, budget, max_error : optional
            Exactly one, as :func:`~hairtool.keys.dp.select_keys` takes them.
        curve_keys : int, default DEFAULT_CURVE_KEYS
            The error curve covers K = 2 … this.
        progress : callable, optional
            ``progress(share)`` with share in [0, 1].

        Returns
        -------
        Selection
            The keys, their cost and the uniform keys' for comparison.
        """
        sel = select_keys(
            self.table,
            keys=keys,
            penalty=penalty,
            budget=budget,
            max_error=max_error,
            objective=self.objective,
            curve_keys=curve_keys,
            constraints=self.constraints,
            progress=progress,
        )
        sel.params.update(interp=self.interp, curvature=self.curvature)
        return sel


def knee_count(curve: ArrayLike) -> int:
    """The knee of an error-vs-key-count curve: the default key count.

    With x the count scaled to [0, 1] over the curve's range and y the error scaled to [0, 1]
    (1 at the fewest keys, 0 at the most), the knee is the count whose point lies farthest below
    the straight line from (0, 1) to (1, 0), i.e. maximises (1 − x) − y (Satopää et al. 2011,
    "Kneedle"): past it, each added key buys less than its share. A flat or straight curve gives
    its first count. ``curve``: ``(m, 2)`` rows (K, error), K increasing, errors finite.

    Parameters
    ----------
    curve : array_like
        Errors by key count.

    Returns
    -------
    int
        The key count at the knee.
    """
    c = np.asarray(curve, dtype=np.float64)
    if c.ndim != 2 or c.shape[0] == 0 or c.shape[1] != 2:
        raise ParameterError("curve", f"shape {c.shape}", "(m, 2) rows (key count, error)")
    k, e = c[:, 0], c[:, 1]
    if c.shape[0] < 3 or not e[0] > e[-1]:
        return int(k[0])
    x = (k - k[0]) / (k[-1] - k[0])
    y = (e - e[-1]) / (e[0] - e[-1])
    gain = (1.0 - x) - y
    best = int(np.argmax(gain))
    return int(k[best]) if gain[best] > 1e-9 else int(k[0])  # a straight line has no knee


#: The progress bar's share for the features (resampling, root removal): quick next to the rest.
FEATURES_SHARE = 0.1


def work_estimate(shape: tuple[int, int], settings: KeySettings, kmax: int) -> tuple[float, float]:
    """Rough operation counts of the cost table and the all-K DP for ``(n, D)`` features, so
    that the progress bar moves in proportion to the time: the Gram product n²D/2 (the worst
    frame: plus n³/6 segment scans; fitted handles: a running solve per segment, n²D), the DP
    about K·n²/2.

    Parameters
    ----------
    shape : tuple of (int, int)
        ``(n, D)`` of the features.
    settings : KeySettings
        The interpolation and objective.
    kmax : int
        The most keys the DP solves for.

    Returns
    -------
    tuple of (float, float)
        The table's and the DP's operation counts.
    """
    n, d = shape
    table = n * n * d / 2.0
    if settings.objective == "worst":
        table += n**3 / 6.0
    if settings.interp == "hermite-fit":
        table += n * n * d
    return table, min(kmax, n) * n * n / 2.0


def solve(
    source: Animation | ArrayLike,
    settings: KeySettings,
    progress: Progress | None = None,
    cancelled: CancelCheck | None = None,
    *,
    features: FeatureOptions | None = None,
    table: ArrayLike | None = None,
    layers: bool = True,
    kmax: int = MAX_CURVE_KEYS,
    constraints: KeyConstraints | None = None,
) -> KeySession | None:
    """Features, cost table and (with ``layers``) the layered DP; None once ``cancelled()``.

    ``source`` is an Animation (seed 000's features, ``features`` or the settings' own) or an
    ``(frames, D)`` feature array used as is; ``table`` replaces the Gram cost table by one the
    caller built (seed 003's quaternion-distance table of a BVH capture); ``constraints`` pins
    and excludes frames (:mod:`hairtool.keys.constraints`; default: the settings' own).

    Parameters
    ----------
    source : Animation or array_like
        The animation, or ``(frames, D)`` features.
    settings : KeySettings
        Interpolation, objective, curvature and the feature options.
    progress : callable, optional
        ``progress(share, stage)`` as it goes.
    cancelled : callable, optional
        Asked between stages; True stops the solve.
    features : FeatureOptions, optional
        Overrides the settings' feature options.
    table : array_like, optional
        A cost table built by the caller.
    layers : bool, default True
        Solve the layered DP now.
    kmax : int, default MAX_CURVE_KEYS
        The most keys the DP solves for.
    constraints : KeyConstraints, optional
        Pinned and excluded frames (None: the settings').

    Returns
    -------
    KeySession or None
        The session, or None once cancelled.
    """
    settings.validate()
    progress = progress or (lambda *a, **k: None)
    cancelled = cancelled or (lambda: False)
    dp_from = 0.0  # the share of the work done when the DP starts
    if table is None:
        progress(0.0, "features")
        x = frame_features(source, features or settings.feature_options())
        if cancelled():
            return None
        work = work_estimate(x.shape, settings, kmax if layers else 0)
        dp_from = FEATURES_SHARE + (1.0 - FEATURES_SHARE) * work[0] / max(sum(work), 1.0)
        progress(FEATURES_SHARE, "cost table")
        table = cost_table(x, settings.interp, settings.curvature, settings.objective)
        del x
        if cancelled():
            return None
    session = KeySession(
        table,
        objective=settings.objective,
        interp=settings.interp,
        curvature=settings.curvature,
        kmax=kmax,
        table_key=settings.table_key,
        constraints=constraints if constraints is not None else settings.constraints,
    )
    if layers:
        progress(dp_from, "dynamic programming")
        session.layers(lambda share: progress(dp_from + (1.0 - dp_from) * share, "dynamic programming"))
        _ = session.knee  # the default count, here in the background (under pins, one more solve)
    progress(1.0, "")
    return session


def find_keys(
    source: Animation | ArrayLike,
    *,
    keys: int | None = None,
    penalty: float | None = None,
    budget: float | None = None,
    max_error: float | None = None,
    objective: str = "total",
    interp: str = "linear",
    curvature: float = 0.0,
    features: FeatureOptions | None = None,
    curve_keys: int = DEFAULT_CURVE_KEYS,
    table: ArrayLike | None = None,
    constraints: KeyConstraints | None = None,
) -> Selection:
    """Exact keys of an Animation (seed 000 features) or an ``(n_frames, D)`` array, in one call.

    Exactly one of ``keys``, ``penalty``, ``budget``, ``max_error`` (which implies the worst-frame
    objective); ``table`` and ``constraints`` as in :func:`solve`.

    Parameters
    ----------
    source
        An animation (its frames become seed 000's features: strands resampled, root-relative,
        tips weighted) or an ``(n_frames, D)`` feature array used as is.
    keys
        The number of keys K.
    penalty
        The price tau of one more key, in the cost's units.
    budget
        The largest total error allowed: the fewest keys within it.
    max_error
        The largest error of any frame allowed: the fewest keys within it.
    objective
        ``"total"`` (the sum over the key segments) or ``"worst"`` (the worst frame).
    interp
        How frames between keys are rebuilt: ``"linear"``, ``"hermite"`` or ``"hermite-fit"``.
    curvature
        Weight of the curvature regulariser (0: none).
    features
        How an animation becomes features; None: the defaults.
    curve_keys
        The error-versus-key-count curve covers K = 2 … this.
    table
        A cost table built by the caller (a BVH capture's quaternion-distance table), replacing
        the features' Gram table.
    constraints
        Frames that must be keys and frames that must not; None: none.

    Returns
    -------
    Selection
        The keys (frame indices, ascending), their cost, uniform keys of the same count with
        theirs, and the cost-versus-K curve.

    Raises
    ------
    ParameterError
        Not exactly one of the four, or a value out of range; the message names it.
    """
    if max_error is not None:
        objective = "worst"
    settings = KeySettings(objective=objective, interp=interp, curvature=curvature)
    features = features or FeatureOptions()
    session = solve(source, settings, features=features, table=table, layers=False, constraints=constraints)
    mode = dict(keys=keys, penalty=penalty, budget=budget, max_error=max_error)
    return session.select(curve_keys=curve_keys, **mode)


# -- errors of a key set, chunked ---------------------------------------------------------------
@dataclass
class FrameErrors:
    """Per-frame vertex distances |p − p̂| (scene units) of one reconstruction."""

    keys: I64
    mean: F64  # (F,) mean over all vertices
    tip: F64  # (F,) mean over strand tips
    max: F64  # (F,) worst vertex

    def summary(self) -> dict:
        return {"mean": float(self.mean.mean()), "tip": float(self.tip.mean()), "max": float(self.max.max())}


@dataclass
class Analysis:
    """Both reconstructions' errors (the DP keys and uniform keys of the same count) and the speed."""

    dp: FrameErrors
    uniform: FrameErrors
    speed: F64 | None = None
    extra: dict = field(default_factory=dict)


def frame_errors(
    animation: Animation,
    kp: KeyPoses,
    cancelled: CancelCheck | None = None,
    progress: Callable[[float], None] | None = None,
) -> FrameErrors | None:
    """Mean, tip-mean and max vertex error per frame of the key curve.

    Parameters
    ----------
    animation : Animation
        The full-rate animation.
    kp : KeyPoses
        Its key poses.
    cancelled : callable, optional
        Asked between chunks; True stops.
    progress : callable, optional
        ``progress(share)`` after each chunk.

    Returns
    -------
    FrameErrors or None
        The errors, or None once cancelled.
    """
    err = key_curve_errors(animation, kp, cancelled=cancelled, progress=progress)
    if err is None:
        return None
    return FrameErrors(kp.keys, err.per_frame_mean, err.per_frame_tip, err.per_frame_max)


def vertex_errors(animation: Animation, kp: KeyPoses, frame: int) -> F32:
    """``(V,)`` distance of each vertex from the key curve at one frame.

    Parameters
    ----------
    animation : Animation
        The full-rate animation.
    kp : KeyPoses
        Its key poses.
    frame : int
        The frame.

    Returns
    -------
    ndarray
        ``(V,)`` float32 distances.
    """
    d = animation.frames[frame].astype(np.float64) - interpolate_at(kp, [frame])[0]
    return np.sqrt(np.einsum("vi,vi->v", d, d)).astype(np.float32)


def speed(animation: Animation, cancelled: CancelCheck | None = None) -> F64 | None:
    """``(F,)`` mean vertex speed in units/s (:func:`hairtool.keys.reconstruct.motion_speed`).

    Parameters
    ----------
    animation : Animation
        The full-rate animation.
    cancelled : callable, optional
        Asked between chunks; True stops.

    Returns
    -------
    ndarray or None
        ``(F,)`` float64, or None once cancelled.
    """
    return motion_speed(animation.frames, animation.fps, cancelled)


def analyse(
    animation: Animation,
    dp_keys: ArrayLike,
    interp: str,
    *,
    with_speed: bool = True,
    progress: Progress | None = None,
    cancelled: CancelCheck | None = None,
) -> Analysis | None:
    """Errors of the DP keys and of uniform keys of the same count (and the motion speed).

    Parameters
    ----------
    animation : Animation
        The full-rate animation.
    dp_keys : array_like
        The optimal keys.
    interp : str
        The curve through the keys.
    with_speed : bool, default True
        Also measure the motion's speed per frame.
    progress : callable, optional
        ``progress(share, stage)`` as it goes.
    cancelled : callable, optional
        Asked between steps; True stops.

    Returns
    -------
    Analysis or None
        The errors of both key sets, or None once cancelled.
    """
    k = check_keys(dp_keys, animation.n_frames)
    uni = uniform_keys(animation.n_frames, k.size)
    parts = []
    for i, keys in enumerate((k, uni)):
        step = (lambda x, i=i: progress(0.45 * (i + x), "errors")) if progress is not None else None
        err = frame_errors(animation, key_poses(animation.frames, keys, interp), cancelled, step)
        if err is None:
            return None
        parts.append(err)
    v = speed(animation, cancelled) if with_speed else None
    if with_speed and v is None:
        return None
    return Analysis(parts[0], parts[1], v)


def key_poses_of(animation: Animation, keys: ArrayLike, interp: str) -> KeyPoses:
    """Key poses (and Hermite tangents) of an animation, stored as float32 to halve their size
    (a studio holds two sets for the whole session); evaluated in float64 all the same.

    Parameters
    ----------
    animation : Animation
        The full-rate animation.
    keys : array_like
        Its key frames.
    interp : str
        The curve through the keys.

    Returns
    -------
    KeyPoses
        float32 key poses and tangents.
    """
    kp = key_poses(animation.frames, keys, interp)
    tangents = None if kp.tangents is None else kp.tangents.astype(np.float32)
    arriving = None if kp.tangents_in is None else kp.tangents_in.astype(np.float32)
    return KeyPoses(kp.keys, kp.poses.astype(np.float32), tangents, kp.n_frames, kp.interp, arriving)


def key_edit_block(
    frames: NDArray, keys: ArrayLike, interp: str, key_frame: int, pose: ArrayLike
) -> tuple[int, NDArray]:
    """``(start, block)``: the frames ``start .. start + len(block) − 1`` after the pose at
    ``key_frame`` is replaced, through :class:`hairtool.keys.edit.KeyEditor`'s residual scheme.

    An edit changes only the frames between the key's neighbouring keys, so the editor runs on
    that stretch plus one frame each side (which keeps the Hermite tangents at the neighbouring
    keys those of the whole animation): the result equals editing the whole animation.

    Parameters
    ----------
    frames : ndarray
        ``(F, ...)`` the animation's frames.
    keys : array_like
        Its key frames.
    interp : str
        The key curve.
    key_frame : int
        The key edited.
    pose : array_like
        Its new pose.

    Returns
    -------
    tuple of (int, ndarray)
        The first frame changed and the changed frames.
    """
    n = frames.shape[0]
    k = check_keys(keys, n)
    hit = np.flatnonzero(k == key_frame)
    if hit.size == 0:
        raise ParameterError("key frame", key_frame, f"one of the keys {k.tolist()}")
    a = int(hit[0])
    lo = int(k[a - 1]) if a > 0 else int(key_frame)
    hi = int(k[a + 1]) if a < k.size - 1 else int(key_frame)
    s0, s1 = max(lo - 1, 0), min(hi + 1, n - 1)
    sub_keys = np.array(sorted({s0, lo, int(key_frame), hi, s1}), dtype=np.int64) - s0
    editor = KeyEditor(frames[s0 : s1 + 1], sub_keys, interp)
    editor.set_key_pose(int(key_frame) - s0, pose)
    return s0, editor.frames(frames.dtype)
