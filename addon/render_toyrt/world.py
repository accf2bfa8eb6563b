"""Blender's world -> WorldSpec: the background colour and whether it lights diffuse surfaces.

Plain data only; sync.py sets toyrt.Scene.background / background_lighting from it."""
from __future__ import annotations

from dataclasses import dataclass

from .materials import input_socket, linked_node, output_node, rgb


@dataclass(frozen=True)
class WorldSpec:
    background: tuple[float, float, float]   # linear RGB radiance of rays leaving the scene
    background_lighting: bool | None         # None: no world, the scene's setting is left as it is
    notes: tuple[str, ...] = ()


def world_spec(bl_scene) -> WorldSpec:
    """The scene's world as the core's background: a plain colour (a Background node's colour
    times its strength, or the node-less world colour); anything else is black."""
    world = bl_scene.world
    if world is None:
        return WorldSpec((0.0, 0.0, 0.0), None)
    # Cycles lights diffuse surfaces with the world unless its diffuse ray visibility is off.
    visibility = getattr(world, "cycles_visibility", None)
    lighting = bool(getattr(visibility, "diffuse", True))
    if not getattr(world, "use_nodes", False) or world.node_tree is None:
        return WorldSpec(rgb(world.color), lighting)
    out = output_node(world.node_tree, "OUTPUT_WORLD")
    node = linked_node(input_socket(out, "Surface")) if out is not None else None
    if node is not None and node.type == "BACKGROUND":
        color, strength = input_socket(node, "Color"), input_socket(node, "Strength")
        if not color.is_linked and not strength.is_linked:
            s = float(strength.default_value)
            return WorldSpec(tuple(c * s for c in rgb(color.default_value)), lighting)
    return WorldSpec((0.0, 0.0, 0.0), lighting, (f"world '{world.name}': not a plain colour (black)",))
