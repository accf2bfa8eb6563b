"""Blender light objects -> light specs: plain data, one dataclass per light type the core has.

Each spec names its core light type (`light_type`, Blender's light.type) and gives that type's
parameters (`arguments()`), so sync.py sends any spec the same way, `Scene.add_light(type,
**arguments)`, and compares the specs with those it sent (lights are re-sent only when they
changed). A new light type touches this file and the core only (docs/architecture.md).

Units across Blender versions: the core's area light has Blender 3.x's radiance P / (4 area)
(docs/render.md); light_power converts 4.x's watts, exposure and unnormalized area lights."""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from .materials import rgb

Vec3 = tuple[float, float, float]


@dataclass(frozen=True)
class PointLightSpec:
    light_type: ClassVar[str] = "POINT"
    position: Vec3
    power: float                        # watts
    color: Vec3
    radius: float                       # metres (0: hard shadows)
    visible_camera: bool = True
    visible_specular: bool = True

    def arguments(self) -> dict:
        return dict(position=self.position, power=self.power, color=self.color, radius=self.radius,
                    visible_camera=self.visible_camera, visible_specular=self.visible_specular)


@dataclass(frozen=True)
class AreaLightSpec:
    light_type: ClassVar[str] = "AREA"
    matrix: tuple[tuple[float, ...], ...]   # the light object's (4, 4) world matrix, rows
    shape: str                              # 'SQUARE', 'RECTANGLE', 'DISK', 'ELLIPSE'
    size: float
    size_y: float | None
    power: float                            # watts, in Blender 3.x's units (light_power)
    color: Vec3
    visible_camera: bool = True
    visible_specular: bool = True

    def arguments(self) -> dict:
        return dict(matrix=np.array(self.matrix, np.float64), shape=self.shape, size=self.size,
                    size_y=self.size_y, power=self.power, color=self.color,
                    visible_camera=self.visible_camera, visible_specular=self.visible_specular)


LightSpec = PointLightSpec | AreaLightSpec


def light_spec(obj, matrix: np.ndarray) -> tuple[LightSpec | None, tuple[str, ...]]:
    """An evaluated light object at `matrix` (its instance's world matrix) as a spec, or None
    for a type the core does not have; and what was approximated."""
    light = obj.data
    notes = []
    color = light_color(light)
    power = light_power(light, matrix)
    if getattr(light, "use_nodes", False):
        notes.append(f"light '{obj.name}': node setup (its colour and power)")
    # Ray visibility of the light object (Blender 3.0+; all visible by default, as in Cycles):
    # TOYRT's specular rays are Cycles' glossy and transmission rays.
    visible = dict(visible_camera=bool(getattr(obj, "visible_camera", True)),
                   visible_specular=bool(getattr(obj, "visible_glossy", True)
                                         and getattr(obj, "visible_transmission", True)))
    if light.type == "POINT":
        position = tuple(float(v) for v in matrix[:3, 3])
        return PointLightSpec(position, power, color, float(light.shadow_soft_size), **visible), tuple(notes)
    if light.type == "AREA":
        shape = light.shape
        size_y = float(light.size_y) if shape in ("RECTANGLE", "ELLIPSE") else None
        rows = tuple(tuple(float(v) for v in row) for row in matrix.tolist())
        return AreaLightSpec(rows, shape, float(light.size), size_y, power, color, **visible), tuple(notes)
    notes.append(f"{light.type.lower()} light '{obj.name}' (skipped)")
    return None, tuple(notes)


def _blender_version():
    try:
        import bpy
        return tuple(bpy.app.version)
    except ImportError:      # outside Blender (the converters' arrays are also used by scripts)
        return (3, 4, 0)


def light_color(light) -> Vec3:
    """The light's colour, times its blackbody colour when "use temperature" is on (4.5+)."""
    color = rgb(light.color)
    if getattr(light, "use_temperature", False):
        color = tuple(a * b for a, b in zip(color, rgb(light.temperature_color)))
    return color


def light_power(light, matrix: np.ndarray) -> float:
    """The power to give the core, whose area light has Blender 3.x's radiance P / (4 area)
    (docs/render.md).

    Measured against Cycles on the same scene (bpy 4.2.0, 4.5.4 and 5.0.1 against Debian's
    3.4.1): from 4.x on, Cycles' area lights of every shape are 4 / pi brighter at the same power,
    i.e. radiance P / (pi area), a Lambertian emitter of exitance P / area; so 4.x's watts become
    4 / pi times as many in 3.x's units. 4.x also scales every light by 2^exposure, and an area
    light with "normalize" off is not divided by its area (its power is per square metre)."""
    power = float(light.energy) * 2.0 ** float(getattr(light, "exposure", 0.0))
    if light.type == "AREA":
        if _blender_version() >= (4, 0, 0):
            power *= 4.0 / np.pi
        if not getattr(light, "normalize", True):
            sx = float(np.linalg.norm(matrix[:3, 0]))
            sy = float(np.linalg.norm(matrix[:3, 1]))
            w = float(light.size)
            h = float(light.size_y) if light.shape in ("RECTANGLE", "ELLIPSE") else w
            area = w * h * (np.pi / 4.0 if light.shape in ("DISK", "ELLIPSE") else 1.0)
            power *= area * sx * sy
    return power
