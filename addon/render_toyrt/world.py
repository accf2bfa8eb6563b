"""Blender's world -> WorldSpec: the background colour, or an Environment Texture or a Sky Texture
(an environment map world_sky.py computes), and whether the world lights diffuse surfaces.

Plain data only; sync.py sets toyrt.Scene.background / background_lighting / set_environment
from it (the environment's image gets its texture id through the material sync's texture table)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .materials import PLACEHOLDER, ImageKey, image_key, input_socket, linked_node, output_node, rgb


@dataclass(frozen=True)
class EnvironmentSpec:
    texture: ImageKey                              # the image (PLACEHOLDER: missing, magenta)
    strength: tuple[float, float, float]           # the Background's strength x a constant colour factor
    matrix: tuple[tuple[float, ...], ...]          # world direction -> the map's frame, (3, 3) rows
    image: object = field(default=None, compare=False)
    # A map the add-on computed (a Sky Texture's, world_sky.py): its (height, width, 3) float32
    # pixels, and the settings it was computed from (compared: an edit sends the map again).
    pixels: object = field(default=None, compare=False)
    computed_from: tuple = ()


@dataclass(frozen=True)
class WorldSpec:
    background: tuple[float, float, float]   # linear RGB radiance of rays leaving the scene
    background_lighting: bool | None         # None: no world, the scene's setting is left as it is
    notes: tuple[str, ...] = ()
    environment: EnvironmentSpec | None = None
    visible_camera: bool = True              # camera rays see it (world.cycles_visibility.camera)
    visible_glossy: bool = True              # reflections see it (.glossy)
    visible_transmission: bool = True        # rays through glass see it (.transmission)


def world_spec(bl_scene) -> WorldSpec:
    """The scene's world as the core's background: a plain colour (a Background node's colour
    times its strength, or the node-less world colour), or an Environment Texture feeding the
    Background's colour (equirectangular, through an optional Mapping node), or a Sky Texture
    there (its model as such a map); anything else is black."""
    world = bl_scene.world
    if world is None:
        return WorldSpec((0.0, 0.0, 0.0), None)
    # Cycles lights diffuse surfaces with the world unless its diffuse ray visibility is off.
    visibility = getattr(world, "cycles_visibility", None)
    lighting = bool(getattr(visibility, "diffuse", True))
    # Camera, glossy and transmission: which rays leaving the scene see it (black otherwise).
    seen = dict(visible_camera=bool(getattr(visibility, "camera", True)),
                visible_glossy=bool(getattr(visibility, "glossy", True)),
                visible_transmission=bool(getattr(visibility, "transmission", True)))
    if not getattr(world, "use_nodes", False) or world.node_tree is None:
        return WorldSpec(rgb(world.color), lighting, **seen)
    out = output_node(world.node_tree, "OUTPUT_WORLD")
    node = linked_node(input_socket(out, "Surface")) if out is not None else None
    if node is not None and node.type == "BACKGROUND":
        color, strength = input_socket(node, "Color"), input_socket(node, "Strength")
        if not strength.is_linked:
            s = float(strength.default_value)
            if not color.is_linked:
                return WorldSpec(tuple(c * s for c in rgb(color.default_value)), lighting, **seen)
            source = linked_node(color)
            kind = source.type if source is not None else None
            if kind in ("TEX_ENVIRONMENT", "TEX_SKY"):
                from .world_sky import sky_environment  # here: world_sky reads this module's types

                notes: list[str] = []
                env = (_environment if kind == "TEX_ENVIRONMENT" else sky_environment)(world.name, source, s, notes)
                return WorldSpec((0.0, 0.0, 0.0), lighting, tuple(notes), env, **seen)
    return WorldSpec((0.0, 0.0, 0.0), lighting, (f"world '{world.name}': not a plain colour (black)",),
                     **seen)


def _environment(name, node, strength, notes) -> EnvironmentSpec:
    if getattr(node, "projection", "EQUIRECTANGULAR") != "EQUIRECTANGULAR":
        notes.append(f"world '{name}': environment projection {node.projection} (equirectangular)")
    if getattr(node, "interpolation", "Linear") != "Linear":
        notes.append(f"world '{name}': environment interpolation {node.interpolation} (bilinear)")
    matrix = mapping_matrix(name, input_socket(node, "Vector"), notes)
    image = node.image
    if image is None:
        notes.append(f"world '{name}': Environment Texture without an image (magenta)")
        key = PLACEHOLDER
    else:
        key = image_key(image)
    rows = tuple(tuple(float(v) for v in row) for row in matrix.tolist())
    return EnvironmentSpec(key, (strength,) * 3, rows, image)


def mapping_matrix(name, vector, notes) -> np.ndarray:
    """The (3, 3) matrix taking world directions to the map's frame: identity for an unlinked
    vector (the ray's direction) or Generated coordinates; a Mapping node's rotation and scale
    (Point and Vector: R diag(scale); Texture: its inverse)."""
    source = linked_node(vector) if vector is not None else None
    if source is None or (source.type == "TEX_COORD" and _output_used(source) in ("Generated", "Object", None)):
        return np.eye(3)
    if source.type != "MAPPING":
        notes.append(f"world '{name}': environment coordinates from {source.bl_idname} (the view direction)")
        return np.eye(3)
    inner = linked_node(input_socket(source, "Vector"))
    if inner is not None and inner.type != "TEX_COORD":
        notes.append(f"world '{name}': Mapping input from {inner.bl_idname} (the view direction)")
    rot, scale = input_socket(source, "Rotation"), input_socket(source, "Scale")
    if (rot is not None and rot.is_linked) or (scale is not None and scale.is_linked):
        notes.append(f"world '{name}': Mapping with linked rotation or scale (unrotated)")
        return np.eye(3)
    from mathutils import Euler  # Blender's own Euler convention (XYZ order)

    r = np.array(Euler(tuple(rot.default_value), "XYZ").to_matrix()) if rot is not None else np.eye(3)
    s = np.array(scale.default_value, float) if scale is not None else np.ones(3)
    kind = getattr(source, "vector_type", "POINT")
    if kind in ("POINT", "VECTOR"):
        return r @ np.diag(s)
    if kind == "TEXTURE":
        return np.diag(1.0 / s) @ r.T
    notes.append(f"world '{name}': Mapping type {kind} (unrotated)")
    return np.eye(3)


def _output_used(node) -> str | None:
    linked = [o.name for o in node.outputs if o.is_linked]
    return linked[0] if linked else None
