"""An animated groom's own root motion as the driver of a simulation, as Blender's hair
dynamics follow their emitter: the roots go where the source's roots are at each substep (its
frames interpolated linearly in time, as USD readers play time samples; held before the first
and after the last), and the head (its sphere, the style's frame, the relative gravity) moves
with the roots' best rigid motion (:func:`hairtool.rotation.rigid_fit`)."""

from __future__ import annotations

import numpy as np

from hairtool.errors import ParameterError
from hairtool.groom import Animation
from hairtool.rotation import rigid_fit


def _rigid_fit(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """:func:`~hairtool.rotation.rigid_fit` as a 4×4 (column vectors)."""
    rot, t = rigid_fit(a, b)
    m = np.eye(4)
    m[:3, :3] = rot
    m[:3, 3] = t
    return m


class RootDriver:
    """The roots of ``source`` (an animation of the strands to simulate) over time: ``at(t)``
    the roots at ``t`` seconds after its first frame, ``transform(t)`` the head's rigid 4×4
    (world from head, the identity at t = 0), what :func:`~hairtool.simulate.dynamics.simulate`
    takes as its motion."""

    def __init__(self, source: Animation) -> None:
        if not isinstance(source, Animation):
            raise ParameterError("driver", type(source).__name__, "an Animation of the strands")
        idx = source.topology.root_indices
        self.roots = source.frames[:, idx].astype(np.float64)  # (F, S, 3)
        codes = source.time_codes
        self.seconds = (codes - codes[0]) / source.fps  # each frame's time after the first
        self._fits: dict[float, np.ndarray] = {}

    @property
    def strand_count(self) -> int:
        return int(self.roots.shape[1])

    def at(self, t: float) -> np.ndarray:
        """``(S, 3)`` float64: the roots at ``t`` seconds, linear between the frames."""
        s = self.seconds
        if t <= s[0] or len(s) == 1:
            return self.roots[0]
        if t >= s[-1]:
            return self.roots[-1]
        k = int(np.searchsorted(s, t, side="right")) - 1
        u = (t - s[k]) / (s[k + 1] - s[k])
        return self.roots[k] + u * (self.roots[k + 1] - self.roots[k])

    def transform(self, t: float) -> np.ndarray:
        """The roots' best rigid motion from the first frame to ``t`` (4×4, column vectors)."""
        key = float(t)
        if key not in self._fits:
            self._fits[key] = _rigid_fit(self.roots[0], self.at(key))
        return self._fits[key]
