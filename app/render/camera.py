"""An orbit camera for the viewport and for exports: numpy and pyrr only, no GL, no Qt.

Conventions: y is up; yaw = pitch = 0 looks along −z (the eye sits on +z of the target), which
is also the fixed view of the orthographic 2-D mode. A Z-up scene (``up_axis="Z"``, a USD stage's
or the artist's choice) is seen through the same orbit turned by (x, y, z) ↦ (x, −z, y), the
DCCs' convention (hairtool.metadata's frame): up is +z and the front view looks along +y.
Matrices are pyrr's row-major ones: a row vector ``[x, y, z, 1] @ view @ proj`` gives clip
coordinates, and the same arrays written to a
GLSL ``mat4`` need no transpose. Pixel coordinates have their origin at the top-left corner with
y down, like Qt's mouse events and image rows.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pyrr
from numpy.typing import ArrayLike, NDArray

from hairtool.errors import ParameterError

ORBIT_RAD_PER_PX = 0.01
ZOOM_PER_STEP = 1.15
PITCH_LIMIT = math.radians(89.0)
UP_AXES = ("Y", "Z")
FRAME_MARGIN = 1.08  # frame-all leaves this much room around the box


def _vec3(value: ArrayLike, name: str) -> NDArray[np.float64]:
    v = np.asarray(value, dtype=np.float64).reshape(-1)
    if v.shape != (3,) or not np.all(np.isfinite(v)):
        raise ParameterError(name, value, "three finite numbers")
    return v


def _positive(value: float, name: str) -> float:
    v = float(value)
    if not math.isfinite(v) or v <= 0:
        raise ParameterError(name, value, "a finite positive number")
    return v


class Camera:
    """Orbit camera around ``target``; perspective, or orthographic looking down −z for 2-D grooms.

    ``distance`` is the eye's distance from the target (world units), ``yaw``/``pitch`` in radians,
    ``fov_y`` in degrees, ``ortho_height`` the world height the orthographic view shows. Near and
    far planes come from the scene sphere set by :meth:`frame` (or :meth:`set_scene`).
    """

    def __init__(
        self,
        target: ArrayLike = (0.0, 0.0, 0.0),
        distance: float = 5.0,
        yaw: float = 0.0,
        pitch: float = 0.0,
        fov_y: float = 35.0,
        ortho: bool = False,
        ortho_height: float = 2.0,
        up_axis: str = "Y",
    ) -> None:
        self.target = _vec3(target, "target")
        self.up_axis = str(up_axis).upper()
        if self.up_axis not in UP_AXES:
            raise ParameterError("up axis", up_axis, "Y or Z")
        self.distance = _positive(distance, "distance")
        self.yaw = float(yaw)
        self.pitch = float(np.clip(pitch, -PITCH_LIMIT, PITCH_LIMIT))
        fov = float(fov_y)
        if not 1.0 <= fov <= 170.0:
            raise ParameterError("fov_y", fov_y, "degrees in [1, 170]")
        self.fov_y = fov
        self.ortho = bool(ortho)
        self.ortho_height = _positive(ortho_height, "ortho_height")
        self.scene_center = self.target.copy()
        self.scene_radius = 1.0

    # -- placing ---------------------------------------------------------------------
    @classmethod
    def for_bounds(
        cls, lo: ArrayLike, hi: ArrayLike, *, ortho: bool = False, aspect: float = 1.0, up_axis: str = "Y"
    ) -> Camera:
        """A camera framing the box: a front view in 2-D, a three-quarter view in 3-D, with
        ``up_axis`` (Y or Z) up on screen."""
        cam = cls(ortho=ortho, up_axis=up_axis) if ortho else cls(yaw=0.35, pitch=0.15, up_axis=up_axis)
        cam.frame(lo, hi, aspect=aspect)
        return cam

    @classmethod
    def for_groom(cls, groom: Any, aspect: float = 1.0) -> Camera:
        """Auto-framed camera: orthographic for planar (2-D) grooms."""
        lo, hi = groom.bounds
        return cls.for_bounds(lo, hi, ortho=bool(groom.is_planar), aspect=aspect)

    def set_scene(self, lo: ArrayLike, hi: ArrayLike) -> None:
        """Record the scene box that near/far planes must enclose (without moving the camera)."""
        lo_v, hi_v = _vec3(lo, "lo"), _vec3(hi, "hi")
        self.scene_center = (lo_v + hi_v) / 2.0
        self.scene_radius = max(float(np.linalg.norm(hi_v - lo_v)) / 2.0, 1e-6)

    def frame(self, lo: ArrayLike, hi: ArrayLike, aspect: float = 1.0) -> None:
        """Frame-all: centre the box and fit it in view (``aspect`` = width / height)."""
        aspect = _positive(aspect, "aspect")
        self.set_scene(lo, hi)
        lo_v, hi_v = _vec3(lo, "lo"), _vec3(hi, "hi")
        self.target = self.scene_center.copy()
        r = self.scene_radius
        if self.ortho:
            self.yaw = self.pitch = 0.0
            extent = hi_v - lo_v
            height = max(extent[1 if self.up_axis == "Y" else 2], extent[0] / aspect, 1e-6)
            self.ortho_height = height * FRAME_MARGIN
            self.distance = 2.0 * r + 1.0
        else:
            half = math.radians(self.fov_y) / 2.0
            half_x = math.atan(math.tan(half) * aspect)
            self.distance = r * FRAME_MARGIN / math.sin(min(half, half_x))

    # -- interaction -----------------------------------------------------------------
    def orbit(self, dx_px: float, dy_px: float) -> None:
        """Turn around the target by a mouse drag; a no-op in the orthographic 2-D mode."""
        if self.ortho:
            return
        self.yaw -= float(dx_px) * ORBIT_RAD_PER_PX
        self.pitch = float(np.clip(self.pitch + float(dy_px) * ORBIT_RAD_PER_PX, -PITCH_LIMIT, PITCH_LIMIT))

    def world_per_pixel(self, viewport_h: float) -> float:
        """World units per pixel at the target's depth."""
        h = _positive(viewport_h, "viewport_h")
        if self.ortho:
            return self.ortho_height / h
        return 2.0 * self.distance * math.tan(math.radians(self.fov_y) / 2.0) / h

    def pan(self, dx_px: float, dy_px: float, viewport_h: float) -> None:
        """Move the target so the scene follows the cursor (pixels, y down)."""
        s = self.world_per_pixel(viewport_h)
        right, up, _ = self.basis()
        self.target = self.target - right * (float(dx_px) * s) + up * (float(dy_px) * s)

    def zoom(self, steps: float) -> None:
        """Wheel steps; positive zooms in (each step by 15 %)."""
        f = ZOOM_PER_STEP ** float(steps)
        if not math.isfinite(f) or f <= 0:
            raise ParameterError("steps", steps, "a finite number of wheel steps")
        r = self.scene_radius
        if self.ortho:
            self.ortho_height = float(np.clip(self.ortho_height / f, r * 1e-4, r * 1e4))
        else:
            self.distance = float(np.clip(self.distance / f, r * 1e-3, r * 1e4))

    # -- geometry --------------------------------------------------------------------
    def _world(self, x: float, y: float, z: float) -> NDArray[np.float64]:
        """A direction of the Y-up orbit frame in world axes (turned for a Z-up scene)."""
        return np.array([x, y, z] if self.up_axis == "Y" else [x, -z, y])

    def forward(self) -> NDArray[np.float64]:
        """Unit view direction, from the eye toward the target."""
        cp = math.cos(self.pitch)
        return self._world(-cp * math.sin(self.yaw), -math.sin(self.pitch), -cp * math.cos(self.yaw))

    def eye(self) -> NDArray[np.float64]:
        return self.target - self.forward() * self.distance

    def basis(self) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """Unit ``(right, up, forward)`` of the view in world space: right = f × up, up = right × f,
        written out (np.cross costs ~10 µs a call, and a drag frame asks for the basis a dozen
        times)."""
        cp = math.cos(self.pitch)
        fx, fy, fz = -cp * math.sin(self.yaw), -math.sin(self.pitch), -cp * math.cos(self.yaw)
        n = math.hypot(fz, fx)
        rx, rz = -fz / n, fx / n
        w = self._world
        return w(rx, 0.0, rz), w(-rz * fy, rz * fx - rx * fz, rx * fy), w(fx, fy, fz)

    def near_far(self) -> tuple[float, float]:
        """Clip planes that enclose the scene sphere (and the target) with some slack."""
        depth = float(np.dot(self.scene_center - self.eye(), self.forward()))
        r = self.scene_radius * 1.5
        far = max(depth + r, self.distance + r, 1e-3)
        if self.ortho:
            return min(depth - r, self.distance - r), far
        return max(depth - r, far * 1e-4), far

    def view_matrix(self) -> NDArray[np.float32]:
        """(4, 4) float32, pyrr row-major: world → eye."""
        m = pyrr.matrix44.create_look_at(self.eye(), self.target, self.basis()[1], dtype=np.float64)
        return m.astype(np.float32)

    def projection_matrix(self, aspect: float) -> NDArray[np.float32]:
        """(4, 4) float32, pyrr row-major: eye → clip, for ``aspect`` = width / height."""
        aspect = _positive(aspect, "aspect")
        near, far = self.near_far()
        if self.ortho:
            h = self.ortho_height / 2.0
            m = pyrr.matrix44.create_orthogonal_projection(
                -h * aspect, h * aspect, -h, h, near, far, dtype=np.float64
            )
        else:
            m = pyrr.matrix44.create_perspective_projection(self.fov_y, aspect, near, far, dtype=np.float64)
        return m.astype(np.float32)

    def view_projection(self, width: float, height: float) -> NDArray[np.float64]:
        """``(4, 4)`` float64: a row vector ``[x, y, z, 1]`` times it gives clip coordinates."""
        return self._view_proj(width, height)

    def _view_proj(self, width: float, height: float) -> NDArray[np.float64]:
        w, h = _positive(width, "width"), _positive(height, "height")
        view = self.view_matrix().astype(np.float64)
        return view @ self.projection_matrix(w / h).astype(np.float64)

    def project(self, points: ArrayLike, width: float, height: float) -> NDArray[np.float64]:
        """``(n, 3)`` world points → ``(n, 2)`` pixel coordinates (origin top-left, y down).

        Pixel ``(col, row)`` holds the point when ``floor`` of the coordinates equals it.
        """
        p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        clip = np.column_stack([p, np.ones(len(p))]) @ self._view_proj(width, height)
        ndc = clip[:, :2] / clip[:, 3:4]
        return np.column_stack([(ndc[:, 0] + 1.0) * 0.5 * width, (1.0 - ndc[:, 1]) * 0.5 * height])

    def depth(self, points: ArrayLike) -> NDArray[np.float64]:
        """``(n,)`` distance of each point in front of the eye, along the view direction."""
        p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        return (p - self.eye()) @ self.forward()

    def ray(self, x_px: float, y_px: float, width: float, height: float) -> tuple[np.ndarray, np.ndarray]:
        """World ``(origin, unit direction)`` of the ray through a pixel position."""
        inv = np.linalg.inv(self._view_proj(width, height))
        nx = 2.0 * float(x_px) / width - 1.0
        ny = 1.0 - 2.0 * float(y_px) / height
        a = np.array([nx, ny, -1.0, 1.0]) @ inv
        b = np.array([nx, ny, 1.0, 1.0]) @ inv
        a, b = a[:3] / a[3], b[:3] / b[3]
        d = b - a
        return a, d / np.linalg.norm(d)

    def unproject_to_plane(
        self, x_px: float, y_px: float, width: float, height: float, plane_point: ArrayLike
    ) -> NDArray[np.float64]:
        """The cursor on the plane through ``plane_point`` facing the camera, ``(3,)`` float64."""
        q = _vec3(plane_point, "plane_point")
        origin, d = self.ray(x_px, y_px, width, height)
        n = self.forward()
        # The plane faces the camera, so the ray always meets it (d · n > 0).
        s = float(np.dot(q - origin, n)) / float(np.dot(d, n))
        return origin + s * d

    def pixels_per_unit_at(self, point: ArrayLike, height: float) -> float:
        """Pixels per world unit at ``point``'s depth (to draw a world-size brush radius)."""
        h = _positive(height, "height")
        if self.ortho:
            return h / self.ortho_height
        z = max(float(self.depth(_vec3(point, "point"))[0]), 1e-9)
        return h / (2.0 * z * math.tan(math.radians(self.fov_y) / 2.0))

    # -- saving ----------------------------------------------------------------------
    def state(self) -> dict[str, Any]:
        """JSON-friendly settings (plain floats and lists)."""
        return {
            "target": [float(v) for v in self.target],
            "distance": self.distance,
            "yaw": self.yaw,
            "pitch": self.pitch,
            "fov_y": self.fov_y,
            "ortho": self.ortho,
            "ortho_height": self.ortho_height,
            "scene_center": [float(v) for v in self.scene_center],
            "scene_radius": self.scene_radius,
            "up_axis": self.up_axis,
        }

    @classmethod
    def from_state(cls, state: dict[str, Any]) -> Camera:
        try:
            cam = cls(
                target=state["target"],
                distance=state["distance"],
                yaw=state["yaw"],
                pitch=state["pitch"],
                fov_y=state["fov_y"],
                ortho=state["ortho"],
                ortho_height=state["ortho_height"],
                up_axis=state.get("up_axis", "Y"),
            )
        except (KeyError, TypeError) as e:
            raise ParameterError("camera state", state, f"a dict from Camera.state() ({e})") from None
        if "scene_center" in state:
            cam.scene_center = _vec3(state["scene_center"], "scene_center")
            cam.scene_radius = _positive(state.get("scene_radius", 1.0), "scene_radius")
        return cam

    def copy(self) -> Camera:
        return Camera.from_state(self.state())

    def __repr__(self) -> str:
        mode = f"ortho h={self.ortho_height:.3g}" if self.ortho else f"fov={self.fov_y:g}"
        return (
            f"Camera(target={np.round(self.target, 3).tolist()}, distance={self.distance:.3g}, "
            f"yaw={self.yaw:.3f}, pitch={self.pitch:.3f}, {mode})"
        )
