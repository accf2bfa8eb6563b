"""Blender light objects -> light specs: plain data, one dataclass per light type the core has.

Each spec names its core light type (`light_type`, Blender's light.type) and gives that type's
parameters (`arguments()`), so sync.py sends any spec the same way, `Scene.add_light(type,
**arguments)`, and compares the specs with those it sent (lights are re-sent only when they
changed). A new light type touches this file and the core only (docs/architecture.md).

Units across Blender versions: the core's area light has Blender 3.x's radiance P / (4 area)
(docs/render.md); light_power converts 4.x's watts, exposure and unnormalized area lights. Where
Cycles changed a light's model between versions (a spot's cone edge, a sun's disc), the spec
names the running version's model; point and spot lights follow use_soft_falloff (4.0+)."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from .materials import rgb

Vec3 = tuple[float, float, float]


@dataclass(frozen=True)
class Visibility:
    """Blender's switches of a light object, as the core's add_light keywords."""
    visible_camera: bool = True
    visible_glossy: bool = True
    visible_transmission: bool = True
    visible_diffuse: bool = True
    cast_shadow: bool = True
    # Light linking (4.0+, light_linking.py): masks of the receiver sets it lights and of the
    # blocker sets that shadow it; all bits: not linked.
    receiver_sets: int = (1 << 64) - 1
    blocker_sets: int = (1 << 64) - 1

    def arguments(self) -> dict:
        linked = {k: getattr(self, k) for k in ("receiver_sets", "blocker_sets") if getattr(self, k) != (1 << 64) - 1}
        return dict(visible_camera=self.visible_camera, visible_glossy=self.visible_glossy,
                    visible_transmission=self.visible_transmission, visible_diffuse=self.visible_diffuse,
                    cast_shadow=self.cast_shadow, **linked)


@dataclass(frozen=True)
class PointLightSpec:
    light_type: ClassVar[str] = "POINT"
    position: Vec3
    power: float                        # watts
    color: Vec3
    radius: float                       # metres (0: hard shadows)
    soft_falloff: bool = True           # a disk facing the shading point (Cycles 3.x, 4.x's default)
    visibility: Visibility = Visibility()

    def arguments(self) -> dict:
        return dict(position=self.position, power=self.power, color=self.color, radius=self.radius,
                    soft_falloff=self.soft_falloff, **self.visibility.arguments())


@dataclass(frozen=True)
class AreaLightSpec:
    light_type: ClassVar[str] = "AREA"
    matrix: tuple[tuple[float, ...], ...]   # the light object's (4, 4) world matrix, rows
    shape: str                              # 'SQUARE', 'RECTANGLE', 'DISK', 'ELLIPSE'
    size: float
    size_y: float | None
    power: float                            # watts, in Blender 3.x's units (light_power)
    color: Vec3
    visibility: Visibility = Visibility()
    spread: float = np.pi                   # radians; pi: no slats (Blender's default)

    def arguments(self) -> dict:
        return dict(matrix=np.array(self.matrix, np.float64), shape=self.shape, size=self.size,
                    size_y=self.size_y, power=self.power, color=self.color, spread=self.spread,
                    **self.visibility.arguments())


@dataclass(frozen=True)
class SpotLightSpec:
    light_type: ClassVar[str] = "SPOT"
    matrix: tuple[tuple[float, ...], ...]
    power: float
    color: Vec3
    radius: float
    soft_falloff: bool
    spot_size: float                        # radians, the cone's full angle
    spot_blend: float
    falloff: str                            # 'SMOOTHSTEP' (Cycles 4.0+) or 'COSINE_SMOOTHSTEP' (3.x)
    visibility: Visibility = Visibility()

    def arguments(self) -> dict:
        return dict(matrix=np.array(self.matrix, np.float64), power=self.power, color=self.color,
                    radius=self.radius, soft_falloff=self.soft_falloff, spot_size=self.spot_size,
                    spot_blend=self.spot_blend, falloff=self.falloff, **self.visibility.arguments())


@dataclass(frozen=True)
class SunLightSpec:
    light_type: ClassVar[str] = "SUN"
    matrix: tuple[tuple[float, ...], ...]
    strength: float                         # W/m^2
    color: Vec3
    angle: float                            # radians, the disc's full angular diameter
    disc: str                               # 'CONE' (Cycles 4.0+) or 'TANGENT_DISK' (3.x)
    visibility: Visibility = Visibility()

    def arguments(self) -> dict:
        return dict(matrix=np.array(self.matrix, np.float64), strength=self.strength, color=self.color,
                    angle=self.angle, disc=self.disc, **self.visibility.arguments())


LightSpec = PointLightSpec | AreaLightSpec | SpotLightSpec | SunLightSpec


def light_visibility(obj) -> Visibility:
    """The light object's ray visibility (Blender 3.0+; all on by default, as in Cycles) and its
    shadow switch (3.x: light.cycles.cast_shadow; 4.x+: light.use_shadow)."""
    light = obj.data
    if hasattr(light, "use_shadow"):
        shadow = bool(light.use_shadow)
    else:
        shadow = bool(getattr(getattr(light, "cycles", None), "cast_shadow", True))
    return Visibility(visible_camera=bool(getattr(obj, "visible_camera", True)),
                      visible_glossy=bool(getattr(obj, "visible_glossy", True)),
                      visible_transmission=bool(getattr(obj, "visible_transmission", True)),
                      visible_diffuse=bool(getattr(obj, "visible_diffuse", True)),
                      cast_shadow=shadow)


def _rows(matrix: np.ndarray) -> tuple[tuple[float, ...], ...]:
    return tuple(tuple(float(v) for v in row) for row in matrix.tolist())


def light_spec(obj, matrix: np.ndarray) -> tuple[LightSpec | None, tuple[str, ...]]:
    """An evaluated light object at `matrix` (its instance's world matrix) as a spec, or None
    for a light that emits nothing in Cycles (a portal) or a type the core does not have; and
    what was approximated."""
    light = obj.data
    notes = []
    color = light_color(light)
    power = light_power(light, matrix)
    # The core refuses these too, but without the object's name; a scene may hold hundreds of lights.
    if not (math.isfinite(power) and power >= 0.0):
        raise ValueError(f"light '{obj.name}': its power or strength must be finite and >= 0 "
                         f"(TOYRT has no negative lights), got {float(light.energy):g}")
    if not all(math.isfinite(c) for c in color):
        raise ValueError(f"light '{obj.name}': its colour is not finite: {tuple(color)}")
    if getattr(light, "use_nodes", False):
        notes.append(f"light '{obj.name}': node setup (its colour and power)")
    visibility = light_visibility(obj)
    cycles4 = _blender_version() >= (4, 0, 0)
    # Blender 4.0 added use_soft_falloff (on by default): off makes point and spot lights true
    # spheres. 3.x has no switch and always renders the soft falloff's disk.
    soft = bool(getattr(light, "use_soft_falloff", True))
    if light.type == "POINT":
        position = tuple(float(v) for v in matrix[:3, 3])
        return (PointLightSpec(position, power, color, float(light.shadow_soft_size), soft, visibility),
                tuple(notes))
    if light.type == "AREA":
        if getattr(getattr(light, "cycles", None), "is_portal", False):
            return None, tuple(notes)  # a portal only guides Cycles' world sampling; it emits nothing
        shape = light.shape
        size_y = float(light.size_y) if shape in ("RECTANGLE", "ELLIPSE") else None
        return (AreaLightSpec(_rows(matrix), shape, float(light.size), size_y, power, color, visibility,
                              _spread(obj.name, light, cycles4, notes)), tuple(notes))
    if light.type == "SPOT":
        return (SpotLightSpec(_rows(matrix), power, color, float(light.shadow_soft_size), soft,
                              float(light.spot_size), float(light.spot_blend),
                              "SMOOTHSTEP" if cycles4 else "COSINE_SMOOTHSTEP", visibility), tuple(notes))
    if light.type == "SUN":
        return (SunLightSpec(_rows(matrix), power, color, float(light.angle),
                             "CONE" if cycles4 else "TANGENT_DISK", visibility), tuple(notes))
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


# Cycles 3.x renders a spread of at least 1 degree; 4.0+ takes any, 0 being a parallel beam.
_MIN_SPREAD = np.radians(1.0)


def _spread(name: str, light, cycles4: bool, notes: list) -> float:
    """The area light's spread for the core (lights/area_spread.h: the beam of a soft box's slats,
    the same function in Cycles 3.x and 4.x+), at least 1 degree: Cycles 3.x's own floor, and on
    4.0+, where a smaller one is allowed, a note."""
    spread = float(getattr(light, "spread", np.pi))
    if not np.isfinite(spread):
        notes.append(f"area light '{name}': spread is not a number (180 degrees)")
        return float(np.pi)
    if spread < _MIN_SPREAD:
        if cycles4:
            notes.append(f"area light '{name}': spread below 1 degree (rendered as 1 degree)")
        return float(_MIN_SPREAD)
    return min(spread, float(np.pi))


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
