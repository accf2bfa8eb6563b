"""The Principled BSDF -> MaterialSpec, per Blender version (docs/render.md, 'Principled BSDF and
Multiscatter GGX'): 4.0+'s Lambert base energy-layered under a dielectric layer (F0 from the IOR
and Specular IOR Level, a tint colour) or a metal (F82-tint); 3.x's Burley diffuse base with the
layer added (F0 = 0.08 x Specular, a scalar Specular Tint towards the base colour's hue) or its
metal (the dielectric curve blended from the base colour). What is not modelled goes in the note."""
from __future__ import annotations

from dataclasses import replace

from .material_dielectric import ior_value
from .material_emission import emission_of
from .materials import (
    _blender_version,
    _color_material,
    _constant,
    _finite_color,
    input_socket,
)


def principled_spec(name, node, notes):
    """A Principled BSDF as (MaterialSpec, image): a metal at Metallic 1, else the 'principled'
    kind (or the plain base) as the Blender version's Cycles shades it, its Transmission a glass
    beside the opaque parts."""
    metal = input_socket(node, "Metallic")
    if metal is not None and not metal.is_linked and metal.default_value >= 0.999:
        return _metal(name, node, notes)
    extras = []
    metallic = _constant(name, metal, "Metallic", 0.0, notes, 0.0, 1.0)
    glass = _transmission(name, node, notes)
    coat = _coat(name, node, glass, notes) or _clearcoat(name, node, notes)
    for label, names in (("sheen", ("Sheen Weight", "Sheen")),
                         ("subsurface", ("Subsurface Weight", "Subsurface")), ("anisotropy", ("Anisotropic",)),
                         ("diffuse roughness", ("Diffuse Roughness",)), ("thin film", ("Thin Film Thickness",))):
        sock = input_socket(node, *names)
        if sock is not None and (sock.is_linked or sock.default_value > 0.0):
            extras.append(label)
    emission, emission_key = emission_of(name, node, notes)
    base, image = _color_material(name, input_socket(node, "Base Color"), notes)
    if base.texture is None:
        base = replace(base, color=_finite_color(name, base.color, "base colour", notes))
    layer = _specular_layer(name, node, base, extras, notes)
    if extras:
        notes.append(f"material '{name}': Principled {', '.join(extras)} (not modelled)")
    tint_3x = input_socket(node, "Specular Tint") if _blender_version() < (4, 0, 0) else None
    if glass and tint_3x is not None and (tint_3x.is_linked or tint_3x.default_value > 0.0):
        # 3.x tints the glass's reflection towards the base colour too (towards white at grazing)
        notes.append(f"material '{name}': Principled Specular Tint on the glass's reflection (white)")
    if layer is None and (metallic > 0.0 or glass):   # no dielectric layer, but a metal or glass beside the base
        new = _blender_version() >= (4, 0, 0)
        layer = dict(roughness=_constant(name, input_socket(node, "Roughness"), "roughness", 0.5, notes, 0.0, 1.0),
                     ior=1.0, multiscatter=new and getattr(node, "distribution", "GGX") == "MULTI_GGX",
                     shadowing="correlated" if new else "separable", layered=new)
    if layer is None and coat:   # a coat over a plain base: the 'principled' kind without a layer
        new = _blender_version() >= (4, 0, 0)
        layer = dict(roughness=0.5, ior=1.0, multiscatter=False, shadowing="correlated" if new else "separable",
                     layered=new, burley=not new)
    spec = base if layer is None else replace(base, kind="principled", metallic=metallic, **layer, **glass, **coat)
    return replace(spec, emission=emission, emission_texture=emission_key), image


def _color_socket(name, node, socket, notes) -> tuple[float, float, float]:
    """A colour socket of 4.0+'s Principled (white if absent, or not a colour): its constant
    value, NaN or negative channels 0 (noted); a linked one is its constant colour, noted."""
    sock = input_socket(node, socket)
    if sock is None or not hasattr(sock.default_value, "__len__"):
        return (1.0, 1.0, 1.0)
    if sock.is_linked:
        notes.append(f"material '{name}': linked {socket} (its constant colour)")
    return _finite_color(name, sock.default_value, socket, notes)


def _coat(name, node, glass, notes) -> dict:
    """4.0+'s Coat (Weight, Roughness, IOR, Tint) as the 'principled' kind's coat arguments ({} for
    none): Cycles 4.0+'s dielectric layer over everything opaque. A linked socket is its constant
    value, a Coat Normal is not modelled, the glass of Transmission is not coated: each noted.
    (3.x's Clearcoat, a GTR1 lobe added beside the rest: _clearcoat.)"""
    weight_sock = input_socket(node, "Coat Weight")
    if weight_sock is None:
        return {}
    weight = _constant(name, weight_sock, "Coat Weight", 0.0, notes, 0.0, 1.0)
    if weight <= 0.0:
        return {}
    rough = _constant(name, input_socket(node, "Coat Roughness"), "Coat Roughness", 0.03, notes, 0.0, 1.0)
    ior = _constant(name, input_socket(node, "Coat IOR"), "Coat IOR", 1.5, notes, 1.0, 1e30)
    tint = _color_socket(name, node, "Coat Tint", notes)
    normal = input_socket(node, "Coat Normal")
    if normal is not None and normal.is_linked:
        notes.append(f"material '{name}': Principled Coat Normal (not modelled)")
    if glass:
        notes.append(f"material '{name}': Principled coat over Transmission (the glass uncoated)")
    return dict(coat_weight=weight, coat_roughness=rough, coat_ior=ior, coat_tint=tint)


def _clearcoat(name, node, notes) -> dict:
    """3.x's Clearcoat and Clearcoat Roughness as the 'principled' kind's coat arguments ({} for
    none; the core reads them, with layered False, as Cycles 3.x's GTR1 clearcoat added beside the
    rest: materials/clearcoat.h). A linked socket is its constant value, a Clearcoat Normal is not
    modelled: noted."""
    sock = input_socket(node, "Clearcoat")
    if sock is None or input_socket(node, "Coat Weight") is not None:
        return {}
    weight = _constant(name, sock, "Clearcoat", 0.0, notes, 0.0, 1.0)
    if weight <= 0.0:
        return {}
    rough = _constant(name, input_socket(node, "Clearcoat Roughness"), "Clearcoat Roughness", 0.03, notes, 0.0, 1.0)
    normal = input_socket(node, "Clearcoat Normal")
    if normal is not None and normal.is_linked:
        notes.append(f"material '{name}': Principled Clearcoat Normal (not modelled)")
    return dict(coat_weight=weight, coat_roughness=rough)


def _transmission(name, node, notes) -> dict:
    """Transmission (3.x) / Transmission Weight (4.0+) as the 'principled' kind's transmission
    arguments ({} for none): the weight and the IOR socket's value (3.x's Specular sets the layer's
    IOR, not the glass's). 3.x's Transmission Roughness roughens the refraction alone, as Cycles
    3.x combines it with the Roughness: 1 - (1 - Roughness)(1 - Transmission Roughness) with the
    GGX distribution; Multiscatter GGX's glass is one closure of the Roughness, so it is unused."""
    trans = input_socket(node, "Transmission Weight", "Transmission")
    weight = _constant(name, trans, "Transmission", 0.0, notes, 0.0, 1.0)
    if weight <= 0.0:
        return {}
    glass = dict(transmission=weight, transmission_ior=ior_value(name, node, notes))
    extra = input_socket(node, "Transmission Roughness")   # 3.x only
    if extra is not None and getattr(node, "distribution", "GGX") == "GGX":
        amount = _constant(name, extra, "Transmission Roughness", 0.0, notes, 0.0, 1.0)
        if amount > 0.0:
            # The Roughness's own notes (linked, NaN, clamped) are the layer's (_specular_layer).
            rough = _constant(name, input_socket(node, "Roughness"), "roughness", 0.5, [], 0.0, 1.0)
            glass["refraction_roughness"] = 1.0 - (1.0 - rough) * (1.0 - amount)
    return glass


# The luminance Cycles 3.x's Principled specular divides the base colour by for its Specular Tint:
# a fixed approximation, not the scene's Rec.709 weights.
_LUMINANCE = (0.3, 0.6, 0.1)


def _specular_layer(name, node, base, extras, notes):
    """The Principled BSDF's dielectric specular layer as the 'principled' kind's arguments, per
    Blender version; 4.0+: None where there is none (Specular IOR Level 0, IOR 1); 3.x always (its
    Burley diffuse base is the 'principled' kind's, with IOR 1 for Specular 0: no layer)."""
    rough = _constant(name, input_socket(node, "Roughness"), "roughness", 0.5, notes, 0.0, 1.0)
    distribution = getattr(node, "distribution", "GGX")
    if _blender_version() >= (4, 0, 0):
        # A Lambert base energy-layered under the layer; F0 from the IOR times 2 x Specular IOR
        # Level, tinted by the Specular Tint colour; Multiscatter GGX by default.
        ior = _constant(name, input_socket(node, "IOR"), "IOR", 1.5, notes, 1e-5, 1e30)
        level = _constant(name, input_socket(node, "Specular IOR Level"), "Specular IOR Level", 0.5, notes, 0.0, 1e30)
        tint = _color_socket(name, node, "Specular Tint", notes)
        if ior == 1.0 or level == 0.0:
            return None
        if distribution not in ("GGX", "MULTI_GGX"):
            notes.append(f"material '{name}': Principled {distribution.title()} distribution (GGX)")
        return dict(roughness=rough, ior=ior, specular_ior_level=level, specular_tint=tint,
                    multiscatter=distribution == "MULTI_GGX", shadowing="correlated", layered=True)
    # 3.x: the layer added to a whole Burley diffuse base (no layering); F0 = 0.08 x Specular,
    # tinted towards the base colour's hue by Specular Tint; the IOR socket is for transmission only.
    specular = _constant(name, input_socket(node, "Specular"), "Specular", 0.5, notes, 0.0, 1e30)
    if specular == 0.0:
        return dict(roughness=rough, ior=1.0, multiscatter=False, shadowing="separable", layered=False, burley=True)
    if distribution == "MULTI_GGX":
        notes.append(f"material '{name}': Multiscatter GGX of Blender 3.x (single-scatter GGX)")
    amount = _constant(name, input_socket(node, "Specular Tint"), "Specular Tint", 0.0, notes, 0.0, 1.0)
    tint = (1.0, 1.0, 1.0)
    if amount > 0.0:
        if base.texture is not None:
            notes.append(f"material '{name}': Specular Tint of a textured base colour (untinted)")
        else:
            lum = sum(w * c for w, c in zip(_LUMINANCE, base.color))
            hue = tuple(c / lum for c in base.color) if lum > 0.0 else (1.0, 1.0, 1.0)
            tint = tuple(1.0 + amount * (h - 1.0) for h in hue)
    f0 = min(0.08 * specular, 0.99)
    root = f0 ** 0.5
    return dict(roughness=rough, ior=(1.0 + root) / (1.0 - root), specular_ior_level=0.5, specular_tint=tint,
                multiscatter=False, shadowing="separable", layered=False, burley=True)


def _metal(name, node, notes):
    """Principled BSDF with Metallic 1: a metal layer whose reflectance at normal incidence is the
    base colour (or its texture), no base under it, emission kept. 4.0+: F82-tint Fresnel with
    Specular Tint, Multiscatter GGX by default; 3.x: the dielectric curve of the Specular's IOR
    blended from the base colour to white. The coat (4.0+) or Clearcoat (3.x) as over the other
    kinds; anisotropy and other distributions go in the one note."""
    extras = []
    aniso = input_socket(node, "Anisotropic")
    if aniso is not None and (aniso.is_linked or aniso.default_value > 0.0):
        extras.append("anisotropy")
    distribution = getattr(node, "distribution", "GGX")
    new = _blender_version() >= (4, 0, 0)
    if distribution not in ("GGX", "MULTI_GGX"):
        extras.append(f"{distribution.title()} distribution (GGX)")
    elif distribution == "MULTI_GGX" and not new:
        extras.append("Multiscatter GGX of Blender 3.x (single-scatter GGX)")
    if extras:
        notes.append(f"material '{name}': Principled metal without {', '.join(extras)}")
    base, image = _color_material(name, input_socket(node, "Base Color"), notes)
    if base.texture is None:
        base = replace(base, color=_finite_color(name, base.color, "base colour", notes))
    rough = _constant(name, input_socket(node, "Roughness"), "roughness", 0.5, notes, 0.0, 1.0)
    if new:
        tint = _color_socket(name, node, "Specular Tint", notes)
        layer = dict(ior=1.5, specular_tint=tint, multiscatter=distribution == "MULTI_GGX", shadowing="correlated",
                     layered=True)
    else:
        specular = _constant(name, input_socket(node, "Specular"), "Specular", 0.5, notes, 0.0, 1e30)
        root = min(0.08 * specular, 0.99) ** 0.5
        layer = dict(ior=(1.0 + root) / (1.0 - root), multiscatter=False, shadowing="separable", layered=False)
    coat = _coat(name, node, {}, notes) or _clearcoat(name, node, notes)
    spec = replace(base, kind="principled", roughness=rough, metallic=1.0, **layer, **coat)
    emission, emission_key = emission_of(name, node, notes)
    return replace(spec, emission=emission, emission_texture=emission_key), image
