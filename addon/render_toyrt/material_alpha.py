"""Cut-outs: the part of a surface rays pass through, as Cycles' transparent closure (the core's
materials/transparency.h). Three shapes of node tree give one:
- a Principled BSDF's Alpha (a constant, or an Image Texture's Alpha or Color output): the BSDF
  weighted by alpha, a white transparent closure weighted by 1 - alpha;
- a Transparent BSDF alone: only the transparent closure, of its Color;
- a Mix Shader of a Transparent BSDF and another shader, its Fac a constant or an Image
  Texture's Alpha or Color (the leaf cut-out): the transparent closure weighted by (1 - Fac) in
  the first input, Fac in the second, the other shader by the rest.
An image's Color output used as a factor is its Rec. 709 luminance, as Blender converts a colour
to a float. The factor is clamped to [0, 1] as Cycles clamps it; NaN becomes opaque, noted."""
from __future__ import annotations

from dataclasses import replace

from .materials import MaterialSpec, OpacityImages, input_socket, rgb


def _linked_output(socket):
    """(node, output socket name) feeding `socket`, following reroutes; None when unlinked."""
    seen = 0
    while socket is not None and socket.is_linked and seen < 64:
        link = socket.links[0]
        if getattr(link, "is_muted", False):
            return None
        if link.from_node.type == "REROUTE":
            socket = link.from_node.inputs[0]
            seen += 1
            continue
        return link.from_node, link.from_socket.name
    return None


def _factor(name, socket, label, notes):
    """The factor `socket` gives, as (constant, texture key, image, channel): the constant when
    unlinked (clamped, NaN opaque), an Image Texture's Alpha or Color output as a texture, anything
    else its constant value, noted."""
    from .materials import _texture  # the Image Texture node's checks and notes
    linked = _linked_output(socket)
    if linked is not None and linked[0].type == "TEX_IMAGE":
        node, output = linked
        key, image = _texture(name, node, notes)
        return 1.0, replace(key, alpha=True), image, "alpha" if output == "Alpha" else "gray"
    if linked is not None:
        notes.append(f"material '{name}': {label} from {linked[0].bl_idname} (its constant value)")
    v = float(socket.default_value)
    if v != v:
        notes.append(f"material '{name}': {label} is NaN (opaque)")
        return 1.0, None, None, "alpha"
    if v < 0.0 or v > 1.0:
        notes.append(f"material '{name}': {label} outside [0, 1] (clamped)")
    return min(max(v, 0.0), 1.0), None, None, "alpha"


def _with_opacity(name, spec, image, factor, invert, notes, color=(1.0, 1.0, 1.0)):
    """(spec, image) of `spec` cut out by `factor` (from _factor): the opacity is the factor, or
    1 - it when `invert`. The shader's emission is weighted by the opacity too, as Cycles weights
    every closure of the shader; by a texture's, per texel, it is not (noted)."""
    value, key, opacity_image, channel = factor
    opacity = (1.0 - value if invert else value) if key is None else 1.0
    emission = tuple(opacity * c for c in spec.emission)
    if key is not None and any(c > 0.0 for c in spec.emission):
        notes.append(f"material '{name}': emission of a cut-out by a texture (not weighted by its opacity)")
    spec = replace(spec, opacity=opacity, opacity_texture=key, opacity_channel=channel,
                   opacity_invert=invert and key is not None, transparent_color=color, emission=emission)
    return spec, (OpacityImages(image, opacity_image) if key is not None else image)


def principled_alpha(name, node, spec, image, notes):
    """A Principled BSDF's (spec, image) with its Alpha socket applied."""
    alpha = input_socket(node, "Alpha")
    if alpha is None or (not alpha.is_linked and alpha.default_value >= 1.0):
        return spec, image
    return _with_opacity(name, spec, image, _factor(name, alpha, "Alpha", notes), False, notes)


def transparent_color(name, node, notes):
    color = input_socket(node, "Color")
    if color is None:
        return (1.0, 1.0, 1.0)
    if color.is_linked:
        notes.append(f"material '{name}': linked Transparent BSDF colour (its constant colour)")
    return tuple(min(max(c, 0.0), 1e30) if c == c else 0.0 for c in rgb(color.default_value))


def transparent_alone(name, node, notes):
    """A Transparent BSDF: nothing but the transparent closure (a black opaque part of weight 0)."""
    return MaterialSpec("diffuse", color=(0.0, 0.0, 0.0), opacity=0.0,
                        transparent_color=transparent_color(name, node, notes)), None


def transparent_mix(name, node, notes, convert):
    """(spec, image) of a Mix Shader with a Transparent BSDF in one input, or None."""
    from .materials import linked_node
    if node.type != "MIX_SHADER":
        return None
    sources = [linked_node(node.inputs[1]), linked_node(node.inputs[2])]
    slots = [i for i, src in enumerate(sources) if src is not None and src.type == "BSDF_TRANSPARENT"]
    if len(slots) != 1:
        return None
    slot = slots[0]
    other = sources[1 - slot]
    if other is None:          # an unlinked shader input adds nothing: a black opaque part
        spec, image = MaterialSpec("diffuse", color=(0.0, 0.0, 0.0)), None
    else:
        spec, image = convert(name, other, notes)
        if spec.transparent:
            notes.append(f"material '{name}': a cut-out inside a Mix with a Transparent BSDF (the outer one)")
        if image is not None and isinstance(image, OpacityImages):
            image = image.color
    color = transparent_color(name, sources[slot], notes)
    # Mix: (1 - Fac) x input 1 + Fac x input 2; the opaque part's weight is the opacity.
    return _with_opacity(name, spec, image, _factor(name, node.inputs[0], "Mix factor", notes), slot == 1, notes,
                         color)
