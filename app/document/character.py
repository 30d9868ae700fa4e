"""A character in the studio, without Qt: the character read from its file, the anime cycle's
settings on its hair chains, the spring bones' source, which of the two is shown, the animation
Apply made, and the chain selected.

Every change is a command on one :class:`~app.document.undo.UndoStack`; a command keeps the
whole :class:`CharacterState` before and after it (immutable, so undo is exact by construction),
and the steps of one drag (one slider held) merge into one. What follows from a state (the
cycle's frames, the springs' frames, the Table-1 measure between them) is derived, never stored,
and cached by the settings it came from.
"""

from __future__ import annotations

import dataclasses
import os
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from app.document.undo import Command, UndoStack
from hairtool.anime.pose import bunch_variation
from hairtool.anime.wave import WaveParams
from hairtool.character.compare import compare_motions
from hairtool.character.cycle import ChainWave, CharacterCycle, character_cycle
from hairtool.character.model import Character
from hairtool.character.springs import head_shake, simulate
from hairtool.errors import ParameterError

SOURCES = ("shake", "turn", "animation")  # what drives the spring bones
VIEWS = ("cycle", "springs", "both")  # what the viewport shows on the chains
DERIVED_KEPT = 16
KEY_PENALTY = 0.02  # the springs' optimal keys: a key costs 2 % of the two-key error
AMPLITUDE_SPREAD, PHASE_SPREAD = 0.1, 0.25  # a chain's first variation: hairtool anime's defaults


@dataclass(frozen=True)
class CycleSettings:
    """The anime cycle on the chains: the shared wave, one :class:`ChainWave` per chain, timing."""

    wave: WaveParams = field(default_factory=WaveParams)
    chains: tuple[ChainWave, ...] = ()
    fps: float = 24.0
    hold: int = 2  # frames each drawing is held (the paper's duplication: 2 = on twos)


@dataclass(frozen=True)
class SpringSettings:
    """What drives the spring bones: a head shake or turn of ``turn_deg``, or the character's own
    animation (its last clip); ``frames`` at the cycle's rate (0: as long as the cycle's shot)."""

    source: str = "shake"
    turn_deg: float = 30.0
    frames: int = 0


@dataclass(frozen=True, eq=False)
class CharacterState:
    """What the document holds of a character (immutable; a step keeps two of them)."""

    character: Character
    cycle: CycleSettings
    springs: SpringSettings = field(default_factory=SpringSettings)
    view: str = "cycle"
    applied: CycleSettings | None = None  # the cycle Apply made the character's animation
    selected: int | None = None  # a chain's index


class SetCharacterState(Command):
    """One edit: the state before and after; the steps of one drag (same ``drag`` id) merge."""

    def __init__(self, doc: CharacterDocument, text: str, after: CharacterState, drag: object = None) -> None:
        self.doc, self.text, self.before, self.after, self.drag = doc, text, doc.state, after, drag

    def do(self) -> None:
        self.doc._set(self.after)

    def undo(self) -> None:
        self.doc._set(self.before)

    def merge(self, other: Command) -> bool:
        if self.drag is None or not isinstance(other, SetCharacterState) or other.drag != self.drag:
            return False
        self.after = other.after
        return True


def _varied(count: int, amplitude_spread: float, phase_spread: float, seed: int) -> tuple[ChainWave, ...]:
    scale, phase = bunch_variation(count, amplitude_spread, phase_spread, seed)
    return tuple(
        ChainWave(amplitude_scale=float(a), phase=float(p)) for a, p in zip(scale, phase, strict=True)
    )


def _finite(name: str, value: float) -> float:
    v = float(value)
    if not np.isfinite(v):
        raise ParameterError(name, value, "a finite number")
    return v


class CharacterDocument:
    """The studio's character; see the module docstring. ``stack``: the document's undo stack."""

    def __init__(self, character: Character, stack: UndoStack | None = None) -> None:
        if not character.chains:
            raise ParameterError("chains", 0, f"hair chains in {character.path}")
        waves = _varied(len(character.chains), AMPLITUDE_SPREAD, PHASE_SPREAD, 0)
        self.state = CharacterState(character, CycleSettings(chains=waves))
        self.stack = stack if stack is not None else UndoStack()
        self._listeners: list[Callable[[], None]] = []
        self._cycles: OrderedDict[CycleSettings, CharacterCycle] = OrderedDict()
        self._springs: OrderedDict[tuple, np.ndarray] = OrderedDict()

    @property
    def character(self) -> Character:
        return self.state.character

    # -- observing -----------------------------------------------------------------------------
    def observe(self, callback: Callable[[], None]) -> None:
        """``callback()`` after every change of the state (an edit, an undo, a redo)."""
        self._listeners.append(callback)

    def _set(self, state: CharacterState) -> None:
        self.state = state
        for callback in list(self._listeners):
            callback()

    def _push(self, text: str, after: CharacterState, drag: object = None) -> None:
        self.stack.push(SetCharacterState(self, text, after, drag))

    # -- edits ---------------------------------------------------------------------------------
    def set_wave(self, drag: object = None, **changes: float) -> None:
        """The shared wave (amplitude, wavelength, gravity, profile, period); refused before any change."""
        s = self.state
        wave = dataclasses.replace(s.cycle.wave, **changes)  # WaveParams checks its own values
        self._push("Wave", dataclasses.replace(s, cycle=dataclasses.replace(s.cycle, wave=wave)), drag)

    def set_chain(self, chain: int, drag: object = None, **changes: object) -> None:
        """One chain's bend axis (None: its own), amplitude scale, phase (cycles) and p (None: shared)."""
        s = self.state
        if not 0 <= chain < len(s.cycle.chains):
            raise ParameterError("chain", chain, f"a chain index below {len(s.cycle.chains)}")
        unknown = set(changes) - {"axis", "amplitude_scale", "phase", "profile"}
        if unknown:
            raise ParameterError(
                "chain setting", sorted(unknown)[0], "axis, amplitude_scale, phase or profile"
            )
        old = s.cycle.chains[chain]
        wave = dataclasses.replace(old, **changes)
        _finite("amplitude_scale", wave.amplitude_scale)
        _finite("phase", wave.phase)
        if wave.profile is not None and (not np.isfinite(wave.profile) or wave.profile < 0):
            raise ParameterError("profile", wave.profile, "p ≥ 0, or the shared p")
        if wave.axis is not None:
            a = np.asarray(wave.axis, dtype=np.float64)
            if a.shape != (3,) or not np.all(np.isfinite(a)) or not np.any(a):
                raise ParameterError("axis", wave.axis, "a non-zero, finite 3-vector, or the chain's own")
            wave = dataclasses.replace(wave, axis=tuple(float(v) for v in a))
        chains = (*s.cycle.chains[:chain], wave, *s.cycle.chains[chain + 1 :])
        name = self.character.chains[chain].name
        after = dataclasses.replace(s, cycle=dataclasses.replace(s.cycle, chains=chains))
        self._push(f"Chain {name}", after, drag)

    def vary(self, amplitude_spread: float, phase_spread: float, seed: int = 0) -> None:
        """Every chain's amplitude scale 1 ± ``amplitude_spread`` and phase in [0, ``phase_spread``)
        cycles, drawn from ``seed`` as ``hairtool anime`` draws them (axes and p kept)."""
        s = self.state
        drawn = _varied(len(s.cycle.chains), amplitude_spread, phase_spread, seed)
        chains = tuple(
            dataclasses.replace(old, amplitude_scale=new.amplitude_scale, phase=new.phase)
            for old, new in zip(s.cycle.chains, drawn, strict=True)
        )
        self._push("Vary chains", dataclasses.replace(s, cycle=dataclasses.replace(s.cycle, chains=chains)))

    def set_timing(self, *, fps: float | None = None, hold: int | None = None) -> None:
        """The limited-animation timing: frames per second and the frames each drawing is held."""
        s = self.state
        fps = s.cycle.fps if fps is None else _finite("fps", fps)
        hold = s.cycle.hold if hold is None else hold
        if fps <= 0:
            raise ParameterError("fps", fps, "a positive frame rate")
        if int(hold) != hold or hold < 1:
            raise ParameterError("hold", hold, "a whole number of frames ≥ 1")
        cycle = dataclasses.replace(s.cycle, fps=fps, hold=int(hold))
        character_cycle(
            self.character, cycle.wave, fps=fps, hold=int(hold)
        )  # refuse a timing the paper's rules cannot meet
        self._push("Timing", dataclasses.replace(s, cycle=cycle))

    def set_springs(
        self, *, source: str | None = None, turn_deg: float | None = None, frames: int | None = None
    ) -> None:
        """What drives the spring bones (shake, turn or the character's own animation)."""
        s = self.state
        springs = dataclasses.replace(
            s.springs,
            **{
                k: v
                for k, v in {"source": source, "turn_deg": turn_deg, "frames": frames}.items()
                if v is not None
            },
        )
        if springs.source not in SOURCES:
            raise ParameterError("source", springs.source, ", ".join(SOURCES))
        if springs.source == "animation" and not self.character.clips:
            raise ParameterError(
                "source", "animation", f"an animation in {self.character.path} (it has none)"
            )
        _finite("turn_deg", springs.turn_deg)
        if int(springs.frames) != springs.frames or springs.frames < 0:
            raise ParameterError("frames", springs.frames, "a whole number ≥ 0 (0: the cycle's length)")
        self._push("Spring source", dataclasses.replace(s, springs=springs))

    def set_view(self, view: str) -> None:
        """Show the cycle, the springs, or both side by side on the same chains."""
        if view not in VIEWS:
            raise ParameterError("view", view, ", ".join(VIEWS))
        self._push("Show " + view, dataclasses.replace(self.state, view=view))

    def select(self, chain: int | None) -> None:
        """Select one chain (None: none)."""
        if chain is not None and not 0 <= chain < len(self.character.chains):
            raise ParameterError("chain", chain, f"a chain index below {len(self.character.chains)}")
        if chain != self.state.selected:
            self._push("Select chain", dataclasses.replace(self.state, selected=chain))

    def apply(self) -> None:
        """Make the cycle as set now the character's animation (what the timeline plays)."""
        self._push("Apply cycle", dataclasses.replace(self.state, applied=self.state.cycle))

    def undo(self) -> bool:
        return self.stack.undo()

    def redo(self) -> bool:
        return self.stack.redo()

    # -- what follows --------------------------------------------------------------------------
    def cycle(self, settings: CycleSettings | None = None) -> CharacterCycle:
        """The cycle of ``settings`` (default the ones being edited)."""
        c = self.state.cycle if settings is None else settings
        if c not in self._cycles:
            waves = dict(enumerate(c.chains))
            self._cycles[c] = character_cycle(self.character, c.wave, fps=c.fps, hold=c.hold, waves=waves)
            while len(self._cycles) > DERIVED_KEPT:
                self._cycles.popitem(last=False)
        return self._cycles[c]

    def animation(self) -> np.ndarray:
        """``(F, J, 4)`` what the timeline plays: the applied cycle, else the character's own
        animation at its rate, else its rest pose (one frame)."""
        s = self.state
        if s.applied is not None:
            return self.cycle(s.applied).frames()
        if self.character.clips:
            clip = self.character.clips[-1]
            return clip.frames(self.character.nodes, clip.frame_rate())
        return self.character.nodes.rotation[None].copy()

    @property
    def fps(self) -> float:
        s = self.state
        if s.applied is not None:
            return s.applied.fps
        return self.character.clips[-1].frame_rate() if self.character.clips else s.cycle.fps

    def drawing_frames(self) -> np.ndarray:
        """The frames on which the applied cycle shows a new drawing (the timeline's keys)."""
        if self.state.applied is None:
            return np.zeros(0, dtype=np.int64)
        holds = self.cycle(self.state.applied).schedule.holds
        return np.concatenate([[0], np.cumsum(holds)[:-1]]).astype(np.int64)

    def springs(self) -> np.ndarray:
        """``(F, J, 4)`` the spring bones on their source, at the cycle's rate."""
        s = self.state
        fps = s.cycle.fps
        frames = s.springs.frames or self.cycle().schedule.n_frames * 4
        key = (s.springs, fps, frames)
        if key not in self._springs:
            c = self.character
            if s.springs.source == "animation":
                clip = c.clips[-1]
                driver = np.stack([clip.sample(c.nodes, f / fps) for f in range(frames)])
            else:
                period = 1.0 if s.springs.source == "shake" else frames / fps * 2
                driver = head_shake(c, frames, fps, turn_deg=s.springs.turn_deg, period=period)
            self._springs[key] = simulate(c, driver, fps)
            while len(self._springs) > DERIVED_KEPT:
                self._springs.popitem(last=False)
        return self._springs[key]

    def cycle_frames(self, count: int) -> np.ndarray:
        """``(count, J, 4)`` the cycle being edited, looped over ``count`` frames."""
        return self.cycle().frames(count)

    def measure(self) -> dict:
        """The paper's Table 1 between the cycle and the springs over the springs' frames: mean
        angular error (degrees) and node displacement (% of chain length)."""
        springs = self.springs()
        return compare_motions(self.character, self.cycle_frames(len(springs)), springs)

    def pose(self, frame: int, which: str = "animation") -> np.ndarray:
        """``(J, 4)`` local rotations on ``frame`` of "animation", "cycle" or "springs" (held
        at the ends)."""
        frames = {"animation": self.animation, "springs": self.springs}.get(which)
        if which == "cycle":
            cyc = self.cycle()
            return cyc.pictures[cyc.schedule.exposure[max(frame, 0) % cyc.schedule.n_frames]]
        if frames is None:
            raise ParameterError("motion", which, "animation, cycle or springs")
        f = frames()
        return f[int(np.clip(frame, 0, len(f) - 1))]

    def spring_keys(self, penalty: float = KEY_PENALTY) -> np.ndarray:
        """Optimal key frames of the springs (seeds 000 and 003 on the chains' BVH rotations,
        ``penalty`` the price of a key as a share of the two-key error), first and last included."""
        from hairtool.character.bvh import chains_motion
        from hairtool.keys.session import find_keys
        from hairtool.mocap.costs import motion_features

        springs = self.springs()
        x = motion_features(chains_motion(self.character, springs, self.state.cycle.fps), "rotations")
        return np.asarray(find_keys(x, penalty=penalty).keys, dtype=np.int64)

    # -- files out -------------------------------------------------------------------------------
    def export(
        self,
        path: str | os.PathLike[str],
        which: str = "cycle",
        key_frames: np.ndarray | None = None,
        interp: str = "linear",
    ) -> dict:
        """Write the character with an animation: the cycle (STEP keys at the drawings, a closing
        key so it loops), the springs (LINEAR on every frame, or ``key_frames`` optimal keys,
        CUBICSPLINE with ``interp`` "hermite-fit"), through the library's writer."""
        from hairtool.character.export import write_animated

        c = self.character
        if which == "cycle":
            cyc = self.cycle()
            return write_animated(
                c.path,
                path,
                cyc.frames(),
                c.nodes.rotation,
                cyc.schedule.fps,
                name="anime cycle",
                step=True,
                loop_frames=cyc.schedule.n_frames,
            )
        if which == "springs":
            return write_animated(
                c.path,
                path,
                self.springs(),
                c.nodes.rotation,
                self.state.cycle.fps,
                name="spring bones",
                step=False,
                key_frames=key_frames,
                interp=interp,
            )
        raise ParameterError("motion", which, "cycle or springs")

    def export_bvh(self, path: str | os.PathLike[str], which: str = "cycle") -> None:
        """The hair chains' motion as BVH."""
        from hairtool.character.bvh import write_chains_bvh

        if which not in ("cycle", "springs"):
            raise ParameterError("motion", which, "cycle or springs")
        motion = self.cycle().frames() if which == "cycle" else self.springs()
        write_chains_bvh(path, self.character, motion, self.state.cycle.fps)
