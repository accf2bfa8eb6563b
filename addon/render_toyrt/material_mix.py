"""Mix Shader (constant factor) and Add Shader nodes of a Diffuse and a Glossy BSDF, as the core's
'diffuse_glossy' material (the two lobes side by side, each with its weight); one lobe alone as
that lobe, its colour weighted. Anything else (a linked factor, other shaders, two lobes of one
kind) is None: the caller's fallback, which notes it."""
from __future__ import annotations

from dataclasses import dataclass, replace

LOBES = ("BSDF_DIFFUSE", "BSDF_GLOSSY", "BSDF_ANISOTROPIC")


def _source(socket):
    """The node feeding a shader socket, or None (the caller's linked_node follows reroutes)."""
    from .materials import linked_node
    return linked_node(socket)


def mix_of_diffuse_and_glossy(name, node, notes, convert):
    """(MaterialSpec, image) for a Mix or Add shader of material `name`, or None. `convert` turns
    one shader node into (MaterialSpec, image), appending its notes."""
    if node.type == "MIX_SHADER":
        fac = node.inputs[0]
        if fac.is_linked:
            return None
        k = min(max(float(fac.default_value), 0.0), 1.0)   # Cycles clamps the factor
        if k != k:
            return None
        pairs = ((1.0 - k, node.inputs[1]), (k, node.inputs[2]))
    else:
        pairs = ((1.0, node.inputs[0]), (1.0, node.inputs[1]))
    diffuse, glossy = [], []
    for weight, socket in pairs:
        src = _source(socket)
        if src is None:
            continue                    # an unlinked shader input adds nothing (black)
        if src.type not in LOBES:
            return None
        spec, image = convert(name, src, notes)
        (diffuse if spec.kind == "diffuse" else glossy).append((weight, spec, image))
    if len(diffuse) > 1 or len(glossy) > 1 or not (diffuse or glossy):
        return None
    if not diffuse:
        weight, spec, _ = glossy[0]
        return replace(spec, color=tuple(weight * c for c in spec.color)), None
    wd, sd, image = diffuse[0]
    if not glossy:
        if sd.texture is not None and wd != 1.0:
            return None
        return replace(sd, color=tuple(wd * c for c in sd.color)), image
    wg, sg, _ = glossy[0]
    if sg.multiscatter or sg.distribution != "ggx":
        return None   # 'diffuse_glossy' is single-scatter GGX: the general mix keeps the glossy's own model
    return replace(sd, kind="diffuse_glossy", diffuse_weight=wd, glossy_color=tuple(wg * c for c in sg.color),
                   roughness=sg.roughness, shadowing=sg.shadowing), image


# ---------------------------------------------------------------------------------------------
# Any two shaders: the core's 'mix' kind (materials/material_mix.h), one input drawn per hit.

MAX_DEPTH = 8          # nested Mix / Add Shaders followed (the core follows 16)
_depth = [0]           # the nesting of the conversion under way (conversions are not concurrent)


@dataclass(frozen=True)
class MixImages:
    """What general_mix returns in the image's place: the Blender image of every texture key its
    inputs and factor read."""
    images: tuple = ()     # ((ImageKey, image), ...)


def _images_of(spec, image) -> tuple:
    """(ImageKey, image) pairs of one converted input."""
    from .materials import OpacityImages
    if isinstance(image, MixImages):
        return image.images
    if isinstance(image, OpacityImages):
        pairs = ((spec.texture, image.color), (spec.opacity_texture, image.opacity))
        if isinstance(image.color, MixImages):
            pairs = image.color.images + ((spec.opacity_texture, image.opacity),)
        return tuple((k, i) for k, i in pairs if k is not None)
    return ((spec.texture, image),) if spec.texture is not None else ()


def _mix_factor(name, socket, notes):
    """(fac, source, texture key, image, param) of a Mix Shader's Fac socket: a constant (clamped
    to [0, 1], as Cycles clamps it), an Image Texture's Alpha or Color output, a Fresnel node's
    output or a Layer Weight node's Fresnel or Facing output; from another node its constant
    value, noted."""
    from .material_alpha import _linked_output
    from .materials import _constant, _texture, input_socket
    linked = _linked_output(socket)
    default = float(socket.default_value)
    default = 0.5 if default != default else min(max(default, 0.0), 1.0)
    if linked is None:
        if float(socket.default_value) != float(socket.default_value):
            notes.append(f"material '{name}': Mix factor is NaN (0.5)")
        return default, "constant", None, None, 0.5
    src, output = linked
    if src.type == "TEX_IMAGE":
        key, image = _texture(name, src, notes)
        return default, "alpha" if output == "Alpha" else "gray", replace(key, alpha=True), image, 0.5
    if src.type in ("FRESNEL", "LAYER_WEIGHT"):
        normal = input_socket(src, "Normal")
        if normal is not None and normal.is_linked:
            notes.append(f"material '{name}': {src.bl_idname}'s Normal input (the shading normal)")
        if src.type == "FRESNEL":
            return default, "fresnel", None, None, _constant(name, input_socket(src, "IOR"), "Fresnel IOR", 1.45,
                                                             notes)
        blend = _constant(name, input_socket(src, "Blend"), "Layer Weight blend", 0.5, notes)
        return default, "layer_facing" if output == "Facing" else "layer_fresnel", None, None, blend
    notes.append(f"material '{name}': Mix factor from {src.bl_idname} (its constant value)")
    return default, "constant", None, None, 0.5


def general_mix(name, node, notes, convert):
    """(MaterialSpec 'mix', MixImages) of a Mix or Add Shader of any two shaders `convert` turns
    into specs (nested mixes too, MAX_DEPTH deep), or None deeper than that (the caller's
    fallback, noted)."""
    from .materials import MaterialSpec
    if _depth[0] >= MAX_DEPTH:
        notes.append(f"material '{name}': Mix / Add Shaders nested deeper than {MAX_DEPTH}")
        return None
    add = node.type == "ADD_SHADER"
    sockets = (node.inputs[0], node.inputs[1]) if add else (node.inputs[1], node.inputs[2])
    fac, source, key, fac_image, param = (1.0, "constant", None, None, 0.5) if add else _mix_factor(
        name, node.inputs[0], notes)
    parts, images = [], []
    _depth[0] += 1
    try:
        for socket in sockets:
            src = _source(socket)
            if src is None:
                parts.append(None)          # an unlinked shader input adds nothing (black)
                continue
            spec, image = convert(name, src, notes)
            images.extend(_images_of(spec, image))
            if spec.transparent:
                # The cut-out is the slot's, and this mix's slot is opaque unless a Transparent
                # BSDF beside it makes it one (material_alpha.transparent_mix).
                notes.append(f"material '{name}': a cut-out inside a Mix / Add Shader (opaque)")
                spec = replace(spec, opacity=1.0, opacity_texture=None, opacity_invert=False)
            parts.append(spec)
    finally:
        _depth[0] -= 1
    if key is not None:
        images.append((key, fac_image))
    # The inputs' emission moves to the mix's slot (the one the mesh's triangles name), weighted as
    # Cycles weights it; by a factor that varies over the surface, with its constant value, noted.
    w = (1.0, 1.0) if add else (1.0 - fac, fac)
    emission = [0.0, 0.0, 0.0]
    emitting = [(weight, spec) for weight, spec in zip(w, parts)
                if spec is not None and weight > 0.0 and any(c > 0.0 for c in spec.emission)]
    for weight, spec in emitting:
        emission = [e + weight * c for e, c in zip(emission, spec.emission)]
    # An image on one input's emission colour stays the slot's; beside another input's emission
    # the slot has one image or none: the strengths alone, noted.
    glow = emitting[0][1].emission_texture if len(emitting) == 1 else None
    if len(emitting) > 1 and any(spec.emission_texture is not None for _, spec in emitting):
        notes.append(f"material '{name}': an emission image beside another emission in a Mix (white x strength)")
    if source != "constant" and any(c > 0.0 for c in emission):
        notes.append(f"material '{name}': emission inside a Mix with a varying factor (weighted by its constant value)")
    parts = tuple(replace(p, emission=(0.0, 0.0, 0.0), emission_texture=None) if p is not None else None
                  for p in parts)
    spec = MaterialSpec("mix", color=(0.0, 0.0, 0.0), mix_inputs=parts, mix_add=add, mix_fac=fac,
                        mix_fac_source=source, mix_fac_texture=key, mix_fac_param=param, emission=tuple(emission),
                        emission_texture=glow)
    return spec, MixImages(tuple(images))
