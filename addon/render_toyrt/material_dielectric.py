"""Blender's Glass and Refraction BSDFs (and a Principled BSDF's full transmission's IOR) as the
core's 'glass' and 'refraction' materials: the IOR with Cycles' floor, the roughness, the
distribution and the Blender version's masking and Fresnel conventions, each approximation noted."""
from __future__ import annotations


def ior_value(name, node, notes) -> float:
    """The IOR socket's value: NaN is Blender's default 1.45 and a value below Cycles' floor 1e-5
    (0, negative) that floor (a mirror: every direction is beyond the critical angle), both noted;
    1 is kept (nothing bends: the surface passes light straight through, as in Cycles), noted."""
    from .materials import input_socket
    sock = input_socket(node, "IOR")
    if sock is None:
        return 1.45
    if sock.is_linked:
        notes.append(f"material '{name}': linked IOR (its constant value)")
    ior = float(sock.default_value)
    if ior != ior:
        notes.append(f"material '{name}': IOR is NaN (1.45)")
        return 1.45
    if ior < 1e-5:
        notes.append(f"material '{name}': IOR {ior:g} (1e-05, Cycles' floor: a mirror)")
        return 1e-5
    if ior == 1.0:
        notes.append(f"material '{name}': IOR 1 (no refraction: the surface is invisible)")
    return min(ior, 3.4e38)


def dielectric_spec(name, node, kind, label, notes):
    """Blender's Glass and Refraction BSDFs: sharp, or a rough GGX or Beckmann dielectric (alpha =
    roughness^2; 3.x's separable masking and Fresnel-weighted pair of lobes, 4.0+'s height-correlated
    masking and Fresnel term per microfacet). Multiscatter GGX is 4.0+'s energy compensation; 3.x's
    (a random walk) is drawn as single-scatter GGX, noted. Returns a MaterialSpec."""
    from .materials import MaterialSpec, _blender_version, _constant, _finite_color, _shadowing, input_socket
    color = input_socket(node, "Color")
    tint = (1.0, 1.0, 1.0)
    if color is not None and color.is_linked:
        notes.append(f"material '{name}': linked {label} Color (white)")
    elif color is not None:  # every ray through or mirrored by the surface takes it, as in Cycles
        tint = _finite_color(name, color.default_value, f"{label} Color", notes)
    distribution = getattr(node, "distribution", "GGX")
    roughness = 0.0
    if distribution != "SHARP":
        roughness = _constant(name, input_socket(node, "Roughness"), "roughness", 0.0, notes, 0.0, 1.0)
    new = _blender_version() >= (4, 0, 0)
    # 4.0+'s Multiscatter GGX glass is the GGX lobe with energy compensation, which the core has;
    # 3.x's is a random walk between microfacets.
    multiscatter = new and kind == "glass" and distribution == "MULTI_GGX"
    if roughness > 0.0 and distribution == "MULTI_GGX" and not multiscatter:
        notes.append(f"material '{name}': Multiscatter GGX {label} (single-scatter GGX: darker at high roughness)")
    fresnel = "microfacet" if new else "macro"
    return MaterialSpec(kind, color=tint, ior=ior_value(name, node, notes), roughness=roughness, shadowing=_shadowing(),
                        fresnel=fresnel, distribution="beckmann" if distribution == "BECKMANN" else "ggx",
                        multiscatter=multiscatter)
