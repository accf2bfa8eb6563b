"""Mix Shader (constant factor) and Add Shader nodes of a Diffuse and a Glossy BSDF, as the core's
'diffuse_glossy' material (the two lobes side by side, each with its weight); one lobe alone as
that lobe, its colour weighted. Anything else (a linked factor, other shaders, two lobes of one
kind) is None: the caller's fallback, which notes it."""
from __future__ import annotations

from dataclasses import replace

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
    return replace(sd, kind="diffuse_glossy", diffuse_weight=wd, glossy_color=tuple(wg * c for c in sg.color),
                   roughness=sg.roughness, shadowing=sg.shadowing), image
