"""Blender materials -> MaterialSpec, images -> pixel arrays, with notes on what was approximated.

Plain data only: a MaterialSpec says what toyrt.Scene.add_material / set_material is to get,
naming its texture by the image it comes from (ImageKey); sync.py gives images their texture ids,
sends the specs and compares them with what it sent, so an edit that changes nothing sends
nothing.

Written against Debian's Blender 3.4 (tested) and kept valid on 4.x and 5.0: node sockets that
were renamed are reached by both names (Principled "Transmission" -> "Transmission Weight" in
4.0, "Specular" -> "Specular IOR Level", "Emission" -> "Emission Color")."""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from .material_dielectric import dielectric_spec
from .material_mix import general_mix, mix_of_diffuse_and_glossy

DEFAULT_GREY = (0.8, 0.8, 0.8)   # Blender's default surface colour
MAGENTA = (1.0, 0.0, 1.0)        # placeholder for missing images
PLACEHOLDER_PIXELS = np.array([[MAGENTA]], np.float32)   # one magenta pixel, linear


@dataclass(frozen=True)
class ImageKey:
    """Which texture a material reads: an image by name, decoded from sRGB or not. The magenta
    placeholder (an Image Texture node without an image, or an image without pixels) has the
    name ''."""
    name: str
    srgb: bool
    alpha: bool = False     # keep the image's alpha channel (an opacity texture reads it)

    @property
    def placeholder(self) -> bool:
        return self.name == ""


PLACEHOLDER = ImageKey("", False)


@dataclass(frozen=True)
class MaterialSpec:
    """What the core's material is made of: kind 'diffuse' (a colour or a texture), 'refraction'
    or 'glass' (an index of refraction), 'glossy' (a colour, a roughness and the masking-shadowing
    of the Blender version: 'separable' in 3.x, 'correlated' since 4.0), 'principled' (a base
    colour or texture under a specular layer: roughness, IOR, Specular IOR Level and Tint)."""
    kind: str
    color: tuple[float, float, float] = DEFAULT_GREY
    texture: ImageKey | None = None
    ior: float = 1.45
    roughness: float = 0.5
    shadowing: str = "separable"
    diffuse_weight: float = 1.0                              # 'diffuse_glossy': the diffuse part's weight
    glossy_color: tuple[float, float, float] = DEFAULT_GREY  # 'diffuse_glossy': the glossy part's colour
    multiscatter: bool = False                               # 'glossy', 'principled', 'glass': 4.0+'s Multiscatter GGX
    specular_ior_level: float = 0.5                          # 'principled' (4.0+'s socket)
    specular_tint: tuple[float, float, float] = (1.0, 1.0, 1.0)  # 'principled': the layer's F0 tint
    layered: bool = True                                     # 'principled': 4.0+ (False: 3.x's sum)
    burley: bool = False                                     # 'principled': 3.x's Burley diffuse base
    transmission: float = 0.0                                # 'principled': the glass's weight
    transmission_ior: float = 1.45                           # 'principled': the glass's IOR
    refraction_roughness: float = -1.0                       # 'principled', 3.x: its refraction's (< 0: roughness)
    metallic: float = 0.0                                    # 'principled': Metallic (1: a metal of the base colour)
    coat_weight: float = 0.0                                 # 'principled', 4.0+: the coat (0: none)
    coat_roughness: float = 0.03
    coat_ior: float = 1.5
    coat_tint: tuple[float, float, float] = (1.0, 1.0, 1.0)
    emission: tuple[float, float, float] = (0.0, 0.0, 0.0)   # colour x strength, linear radiance
    emission_sampling: str = "AUTO"                           # Blender 4.x's names (3.x: AUTO or NONE)
    emission_texture: ImageKey | None = None                 # the emission colour's image (emission: its strength)
    fresnel: str = "microfacet"                              # 'glass': 4.0+'s per microfacet, 3.x's 'macro'
    distribution: str = "ggx"                                # 'glossy', 'glass', 'refraction': or 'beckmann'
    # The part rays pass through (material_alpha.py, the core's materials/transparency.h): the
    # BSDF's weight `opacity` (or a texture's alpha or gray, 1 - it when inverted), the rest a
    # transparent closure of colour transparent_color. Every kind takes them.
    opacity: float = 1.0
    opacity_texture: ImageKey | None = None
    opacity_channel: str = "alpha"
    opacity_invert: bool = False
    transparent_color: tuple[float, float, float] = (1.0, 1.0, 1.0)
    normal_map: object = None    # material_normal.NormalMapSpec: the Normal Map on the Normal input
    # 'mix' (material_mix.general_mix, the core's materials/material_mix.h): a Mix or Add Shader
    # of two other specs (None: an unlinked input, black), one drawn per hit by its weight; the
    # factor a constant, an image's 'alpha' or 'gray' (mix_fac_texture), 'fresnel' (mix_fac_param:
    # the IOR), 'layer_fresnel' or 'layer_facing' (mix_fac_param: the blend).
    mix_inputs: tuple = ()
    mix_add: bool = False
    mix_fac: float = 0.5
    mix_fac_source: str = "constant"
    mix_fac_texture: ImageKey | None = None
    mix_fac_param: float = 0.5

    @property
    def transparent(self) -> bool:
        return self.opacity < 1.0 or self.opacity_texture is not None or self.opacity_invert

    def arguments(self, texture_id: int = -1, opacity_texture_id: int = -1, normal_texture_id: int = -1,
                  emission_texture_id: int = -1) -> dict:
        """Keyword arguments of toyrt.Scene.add_material / set_material, with the textures' ids."""
        args = dict(kind=self.kind, color=self.color, texture=texture_id, ior=self.ior, emission=self.emission,
                    emission_sampling=self.emission_sampling)
        if self.emission_texture is not None:
            args["emission_texture"] = emission_texture_id
        if self.normal_map is not None:
            args.update(self.normal_map.arguments(normal_texture_id))
        if self.transparent:
            args.update(opacity=self.opacity, opacity_texture=opacity_texture_id, opacity_channel=self.opacity_channel,
                        opacity_invert=self.opacity_invert, transparent_color=self.transparent_color)
        if self.kind in ("glossy", "diffuse_glossy", "principled"):   # the core refuses keywords a kind does not read
            args.update(roughness=self.roughness, shadowing=self.shadowing)
        if self.kind in ("glossy", "principled"):
            args.update(multiscatter=self.multiscatter)
        if self.kind == "glossy":
            args.update(distribution=self.distribution)
        if self.kind in ("glass", "refraction"):                    # rough when roughness > 0
            args.update(roughness=self.roughness, shadowing=self.shadowing, distribution=self.distribution)
        if self.kind == "glass":
            args.update(fresnel=self.fresnel, multiscatter=self.multiscatter)
        if self.kind == "principled":
            args.update(specular_ior_level=self.specular_ior_level, specular_tint=self.specular_tint,
                        layered=self.layered, metallic=self.metallic, burley=self.burley,
                        transmission=self.transmission, transmission_ior=self.transmission_ior)
            if self.refraction_roughness >= 0.0:
                args.update(refraction_roughness=self.refraction_roughness)
            if self.coat_weight > 0.0:
                args.update(coat_weight=self.coat_weight, coat_roughness=self.coat_roughness, coat_ior=self.coat_ior,
                            coat_tint=self.coat_tint)
        if self.kind == "diffuse_glossy":
            args.update(diffuse_weight=self.diffuse_weight, glossy_color=self.glossy_color)
        if self.kind == "mix":   # its inputs' ids: the caller's (sync_materials.py sends them first)
            args.update(add=self.mix_add, fac=self.mix_fac, fac_source=self.mix_fac_source,
                        fac_param=self.mix_fac_param)
        return args


@dataclass(frozen=True)
class ConvertedMaterial:
    """A material's spec, what it approximated, and the Blender image its texture reads (None
    for no texture or the placeholder; not part of the comparison)."""
    spec: MaterialSpec
    notes: tuple[str, ...] = ()
    image: object = field(default=None, compare=False)
    opacity_image: object = field(default=None, compare=False)   # the image opacity_texture reads
    normal_image: object = field(default=None, compare=False)    # the image the normal map reads
    emission_image: object = field(default=None, compare=False)  # the image the emission colour reads


def material_spec(mat) -> ConvertedMaterial:
    """A Blender material (None: an empty slot) as the core's material."""
    notes = []
    spec, image = _convert(mat, notes)
    if any(c > 0.0 for c in spec.emission):
        spec = replace(spec, emission_sampling=_emission_sampling(mat))
    opacity_image = None
    if isinstance(image, OpacityImages):
        image, opacity_image = image.color, image.opacity
    from .material_normal import normal_map  # it reads this module's node helpers
    bent, normal_image = normal_map(mat.name if mat is not None else "", mat, notes)
    if bent is not None:
        lift = spec.kind != "diffuse" or _blender_version() < (4, 0, 0)   # 4.x+ lifts glossy normals only
        spec = replace(spec, normal_map=replace(bent, lift=lift))
    from .material_emission import emission_image
    return ConvertedMaterial(spec, tuple(dict.fromkeys(notes)), image, opacity_image, normal_image,
                             emission_image(mat, spec.emission_texture))


@dataclass(frozen=True)
class OpacityImages:
    """What a converter returns in the image's place when the material reads an opacity image
    too (material_alpha.py): both images."""
    color: object
    opacity: object


def _emission_sampling(mat) -> str:
    """Whether Cycles samples the material's emission as a light, and towards which sides:
    4.x+ material.cycles.emission_sampling, 3.x material.cycles.sample_as_light."""
    cycles = getattr(mat, "cycles", None)
    sampling = getattr(cycles, "emission_sampling", None)
    if isinstance(sampling, str):
        return sampling
    return "AUTO" if getattr(cycles, "sample_as_light", True) else "NONE"


def image_key(image) -> ImageKey:
    """Blender keeps float images in scene-linear memory (converted from their colour space when
    loaded) and 8-bit images as their file's bytes: only 8-bit sRGB needs decoding."""
    return ImageKey(image.name_full, image.colorspace_settings.name == "sRGB" and not image.is_float)


def image_pixels(image, alpha: bool = False) -> np.ndarray | None:
    """(height, width, 3) pixels, or (height, width, 4) with `alpha`, rows from the bottom (uint8
    for 8-bit images, float32 for float images); None if the image has no data."""
    try:
        w, h = image.size[:]            # reading the size loads the image (packed or on disk)
        channels = image.channels
        n = len(image.pixels)
    except (RuntimeError, ReferenceError):
        return None
    if w <= 0 or h <= 0 or channels <= 0 or n != w * h * channels:
        return None
    if hasattr(image, "has_data") and not image.has_data:
        return None
    buf = np.empty(n, np.float32)
    image.pixels.foreach_get(buf)
    buf = buf.reshape(h, w, channels)
    a = buf[..., 3:4] if channels == 4 else (buf[..., 1:2] if channels == 2 else np.ones_like(buf[..., :1]))
    if channels == 1 or channels == 2:
        buf = np.repeat(buf[..., :1], 3, axis=2)
    buf = np.concatenate([buf[..., :3], a], axis=2) if alpha else buf[..., :3]
    if not image.is_float:
        # An 8-bit image: pass its bytes (exact: Blender's pixels are byte / 255), a quarter of
        # the memory, and the core knows it is an 8-bit image (Cycles filters 8-bit sRGB
        # images before decoding them; see docs/parity.md).
        return np.ascontiguousarray(np.rint(np.clip(buf, 0.0, 1.0) * 255.0).astype(np.uint8))
    return np.ascontiguousarray(buf)


def image_data(image, alpha: bool = False) -> tuple[np.ndarray | None, tuple[str, ...]]:
    """The image's pixels (image_pixels) ready for the core, and what loading it approximated
    (image_notes). Non-finite floats (HDR files can hold inf or NaN texels) become 0 (NaN, -inf)
    or float16's largest value (+inf), with a note: the core refuses non-finite texels, and one
    must not fail a render or poison every pixel that samples it."""
    pixels = image_pixels(image, alpha)
    notes = image_notes(image, pixels)
    if pixels is not None and pixels.dtype == np.float32:
        bad = int(np.count_nonzero(~np.isfinite(pixels)))
        if bad:
            np.nan_to_num(pixels, copy=False, nan=0.0, posinf=65504.0, neginf=0.0)
            notes += (f"image '{image.name}': {bad} non-finite values (NaN and -inf as 0, +inf as 65504)",)
    return pixels, notes


def image_notes(image, pixels: np.ndarray | None) -> tuple[str, ...]:
    """What loading `image` approximated: a missing image (the placeholder), or a colour space
    the core reads as linear."""
    if pixels is None:
        return (f"missing image '{image.name}' ({image.filepath or 'no file'}): magenta placeholder",)
    if not image.is_float and image.colorspace_settings.name not in (
            "sRGB", "Linear", "Linear Rec.709", "Non-Color", "Raw"):
        return (f"image '{image.name}': colour space {image.colorspace_settings.name} (linear)",)
    return ()


# ---------------------------------------------------------------------------------------------
# node helpers

def input_socket(node, *names: str) -> object | None:
    """The first of the named input sockets the node has (names moved between versions)."""
    for n in names:
        sock = node.inputs.get(n)
        if sock is not None:
            return sock
    return None


def linked_node(socket) -> object | None:
    """The node feeding `socket`, following reroutes; None when unlinked."""
    seen = 0
    while socket is not None and socket.is_linked and seen < 64:
        link = socket.links[0]
        if hasattr(link, "is_muted") and link.is_muted:
            return None
        node = link.from_node
        if node.type == "REROUTE":
            socket = node.inputs[0]
            seen += 1
            continue
        return node
    return None


def output_node(ntree, output_type: str) -> object | None:
    """The active output node of a node tree for Cycles (or for all renderers)."""
    get = getattr(ntree, "get_output_node", None)
    if get is not None:
        for target in ("CYCLES", "ALL"):
            try:
                node = get(target)
            except (TypeError, ValueError):
                node = None
            if node is not None:
                return node
    candidates = [n for n in ntree.nodes if n.type == output_type]
    for n in candidates:
        if getattr(n, "is_active_output", False):
            return n
    return candidates[0] if candidates else None


def rgb(value) -> tuple[float, float, float]:
    return tuple(float(c) for c in tuple(value)[:3])


# ---------------------------------------------------------------------------------------------
# the conversion: (MaterialSpec, image or None), notes appended to `notes`

def _diffuse(color):
    return MaterialSpec("diffuse", color=color), None


# From this version Cycles' default surface (an object or slot without a material) is a Principled
# BSDF with its defaults, no longer a Diffuse BSDF of 0.8 grey: measured on 5.0 (bit for bit the
# same image as an explicit default Principled; 0.9 % darker than the Diffuse on the torus_file
# parity scene) and seen in a 4.5-era Cycles source; 3.4 has the Diffuse. 4.0-4.4 are not verified.
DEFAULT_SURFACE_PRINCIPLED_FROM = (4, 5, 0)


def _default_surface():
    """Cycles' default surface in this Blender version, as (MaterialSpec, image)."""
    if _blender_version() < DEFAULT_SURFACE_PRINCIPLED_FROM:
        return _diffuse(DEFAULT_GREY)
    return MaterialSpec("principled", color=DEFAULT_GREY, ior=1.5, roughness=0.5, specular_ior_level=0.5,
                        shadowing="correlated", multiscatter=True, layered=True), None


def _convert(mat, notes):
    if mat is None:
        return _default_surface()
    name = mat.name
    if not getattr(mat, "use_nodes", False) or mat.node_tree is None:
        # Cycles renders a node-less material as a diffuse of its viewport colour.
        return _diffuse(rgb(mat.diffuse_color))
    out = output_node(mat.node_tree, "OUTPUT_MATERIAL")
    if out is None:
        notes.append(f"material '{name}': no Material Output (grey diffuse)")
        return _diffuse(DEFAULT_GREY)
    node = linked_node(input_socket(out, "Surface"))
    if node is None:
        # Cycles renders an unconnected surface black; the nearest we have is a black diffuse.
        notes.append(f"material '{name}': nothing linked to the Surface output (black)")
        return _diffuse((0.0, 0.0, 0.0))
    return _convert_node(name, node, notes)


def _convert_node(name, node, notes):
    """The shader node `node` of material `name` as (MaterialSpec, image)."""
    t = node.type
    if t == "BSDF_DIFFUSE":
        rough = input_socket(node, "Roughness")
        if rough is not None and not rough.is_linked and rough.default_value > 0.0:
            notes.append(f"material '{name}': Diffuse roughness (Lambert)")
        return _color_material(name, input_socket(node, "Color"), notes)
    if t == "BSDF_PRINCIPLED":
        from .material_alpha import principled_alpha
        from .material_principled import principled_spec  # it reads this module's socket helpers
        return principled_alpha(name, node, *principled_spec(name, node, notes), notes)
    if t == "BSDF_TRANSPARENT":
        from .material_alpha import transparent_alone
        return transparent_alone(name, node, notes)
    if t in ("BSDF_GLOSSY", "BSDF_ANISOTROPIC"):   # 4.0+: the Glossy node is ShaderNodeBsdfAnisotropic
        return _glossy(name, node, notes)
    if t in ("MIX_SHADER", "ADD_SHADER"):
        from .material_alpha import transparent_mix
        mixed = transparent_mix(name, node, notes, _convert_node) or mix_of_diffuse_and_glossy(
            name, node, notes, _convert_node) or general_mix(name, node, notes, _convert_node)
        if mixed is not None:
            return mixed
    if t == "EMISSION":
        # Emission alone has no BSDF: a black surface that glows (Cycles).
        from .material_emission import emission_of
        emission, key = emission_of(name, node, notes)
        return MaterialSpec("diffuse", color=(0.0, 0.0, 0.0), emission=emission, emission_texture=key), None
    if t == "BSDF_REFRACTION":
        return dielectric_spec(name, node, "refraction", "Refraction", notes), None
    if t == "BSDF_GLASS":
        return dielectric_spec(name, node, "glass", "Glass", notes), None
    # Anything else: the colour it has, as a diffuse, else grey.
    color = input_socket(node, "Color", "Base Color")
    if color is not None and not color.is_linked and hasattr(color.default_value, "__len__"):
        notes.append(f"material '{name}': {node.bl_idname} (diffuse of its colour)")
        return _diffuse(rgb(color.default_value))
    notes.append(f"material '{name}': {node.bl_idname} (grey diffuse)")
    return _diffuse(DEFAULT_GREY)


def _blender_version() -> tuple:
    try:
        import bpy
        return tuple(bpy.app.version)
    except ImportError:      # outside Blender
        return (3, 4, 0)


def _shadowing() -> str:
    """Cycles' GGX masking-shadowing: separable G1 G1 in 3.x, height-correlated since 4.0."""
    return "separable" if _blender_version() < (4, 0, 0) else "correlated"


def _constant(name, sock, label, fallback, notes, lo=None, hi=None) -> float:
    """A float socket's constant value (a linked socket: that value, noted); NaN becomes
    `fallback` and a value outside [lo, hi] is clamped, both noted."""
    if sock is None:
        return fallback
    if sock.is_linked:
        notes.append(f"material '{name}': linked {label} (its constant value)")
    v = float(sock.default_value)
    if v != v:
        notes.append(f"material '{name}': {label} is NaN ({fallback})")
        return fallback
    if (lo is not None and v < lo) or (hi is not None and v > hi):
        v = min(max(v, lo), hi)
        notes.append(f"material '{name}': {label} outside [{lo}, {hi}] (clamped to {v:g})")
    return v


def _finite_color(name, value, label, notes) -> tuple[float, float, float]:
    """A colour with NaN or negative channels replaced by 0, noted."""
    c = rgb(value)
    clean = tuple(x if x == x and x >= 0.0 else 0.0 for x in c)
    if clean != c:
        notes.append(f"material '{name}': {label} has NaN or negative channels (0)")
    return tuple(min(x, 3.4e38) for x in clean)


def _glossy_spec(name, color_sock, rough_sock, notes) -> MaterialSpec:
    if color_sock is not None and color_sock.is_linked:
        notes.append(f"material '{name}': linked glossy colour (its constant colour)")
    color = _finite_color(name, color_sock.default_value, "colour", notes) if color_sock is not None else DEFAULT_GREY
    rough = _constant(name, rough_sock, "roughness", 0.5, notes, 0.0, 1.0)
    return MaterialSpec("glossy", color=color, roughness=rough, shadowing=_shadowing())


def _glossy(name, node, notes):
    """Blender's Glossy BSDF: GGX or Beckmann (Sharp in 3.x is roughness 0); Ashikhmin-Shirley as GGX."""
    distribution = getattr(node, "distribution", "GGX")
    if distribution == "SHARP":
        rough = None
    else:
        rough = input_socket(node, "Roughness")
        if distribution == "MULTI_GGX" and _blender_version() < (4, 0, 0):   # 3.x's is a random walk
            notes.append(f"material '{name}': Multiscatter GGX (single-scatter GGX: darker at high roughness)")
        elif distribution not in ("GGX", "BECKMANN", "MULTI_GGX"):
            notes.append(f"material '{name}': {distribution.title()} glossy distribution (GGX)")
    aniso = input_socket(node, "Anisotropy")
    if aniso is not None and (aniso.is_linked or aniso.default_value != 0.0):
        notes.append(f"material '{name}': anisotropic glossy (isotropic)")
    spec = _glossy_spec(name, input_socket(node, "Color"), rough, notes)
    if distribution == "MULTI_GGX" and _blender_version() >= (4, 0, 0):
        spec = replace(spec, multiscatter=True)
    if distribution == "BECKMANN":
        spec = replace(spec, distribution="beckmann")
    return (replace(spec, roughness=0.0) if rough is None else spec), None


def _color_material(name, sock, notes):
    if sock is None:
        return _diffuse(DEFAULT_GREY)
    src = linked_node(sock)
    if src is None:
        return _diffuse(rgb(sock.default_value))
    if src.type == "TEX_IMAGE":
        key, image = _texture(name, src, notes)
        return MaterialSpec("diffuse", texture=key), image
    notes.append(f"material '{name}': colour from {src.bl_idname} (its constant colour)")
    return _diffuse(rgb(sock.default_value))


def _texture(name, node, notes):
    """The image an Image Texture node reads, as (ImageKey, image); the placeholder without one."""
    vec = input_socket(node, "Vector")
    if vec is not None and vec.is_linked:
        src = linked_node(vec)
        if src is None or src.type not in ("UVMAP", "TEX_COORD"):
            notes.append(f"material '{name}': texture coordinates from "
                         f"{src.bl_idname if src else 'a link'} (the mesh's UV map)")
    if getattr(node, "extension", "REPEAT") != "REPEAT":
        notes.append(f"material '{name}': image extension {node.extension} (repeat)")
    if getattr(node, "interpolation", "Linear") not in ("Linear",):
        notes.append(f"material '{name}': image interpolation {node.interpolation} (bilinear)")
    if getattr(node, "projection", "FLAT") != "FLAT":
        notes.append(f"material '{name}': image projection {node.projection} (flat)")
    image = node.image
    if image is None:
        notes.append(f"material '{name}': Image Texture without an image (magenta)")
        return PLACEHOLDER, None
    return image_key(image), image
