"""Emission sockets -> the core's MaterialEmission (materials/emission.h): colour x strength as a
constant, or, with the colour linked to an Image Texture's Color, the strength times that image
(emission_texture), read at the UV where rays meet the surface and where shadow rays sample it.

The Emission shader's Color / Strength and the Principled BSDF's Emission Color (3.x: Emission)
/ Emission Strength. Anything else linked to them is taken at its constant value, noted."""
from __future__ import annotations

from .materials import ImageKey, _texture, input_socket, linked_node, rgb

# The shaders whose emission sockets are read, and those sockets: (colour, strength) by name.
SOCKETS = {"EMISSION": (("Color",), ("Strength",)),
           "BSDF_PRINCIPLED": (("Emission Color", "Emission"), ("Emission Strength",))}


def emission_of(name, node, notes) -> tuple[tuple[float, float, float], ImageKey | None]:
    """(colour x strength, None), or (strength x white, the image's key) for a colour that an
    Image Texture's Color feeds."""
    colors, strengths = SOCKETS[node.type]
    color, strength = input_socket(node, *colors), input_socket(node, *strengths)
    if color is None:
        return (0.0, 0.0, 0.0), None
    k = float(strength.default_value) if strength is not None else 1.0
    if strength is not None and strength.is_linked:
        notes.append(f"material '{name}': linked emission strength (its constant value)")
    src = linked_node(color)
    if src is not None and src.type == "TEX_IMAGE" and _from_color_output(color) and k > 0.0:
        key, _ = _texture(name, src, notes)
        return (k, k, k), key
    if src is not None:
        notes.append(f"material '{name}': emission colour from {src.bl_idname} (its constant value)")
    return tuple(max(0.0, c * k) for c in rgb(color.default_value)), None


def emission_image(mat, key: ImageKey | None):
    """The Blender image behind `key` among the material's Image Texture nodes (None: the
    placeholder, or no key)."""
    if key is None or key.placeholder or mat is None or mat.node_tree is None:
        return None
    for node in mat.node_tree.nodes:
        image = getattr(node, "image", None) if node.type == "TEX_IMAGE" else None
        if image is not None and image.name_full == key.name:
            return image
    return None


def _from_color_output(socket) -> bool:
    """Whether the link into `socket` leaves its node's Color output (not Alpha)."""
    links = getattr(socket, "links", ())
    return bool(links) and links[0].from_socket.name == "Color"
