"""The Normal Map node on a BSDF's Normal input -> NormalMapSpec, the core's
materials/normal_map.h: an Image Texture's Color (Non-Color data) through a Normal Map node, in
tangent space (the mesh then carries MikkTSpace tangents of the node's UV map: mesh_tangents.py),
object or world space, its Strength a constant, 5.x+'s convention (DirectX negates green) where
the node has it.

A Bump node takes the same place: its Height an Image Texture's Color (Rec. 709 luminance) or
Alpha, its Strength and Distance constants, Invert a negative distance, and before 4.4 (no Filter
Width) the height differenced over the ray's footprint as Cycles 3.x does (the core's bump_map,
bump_footprint; docs/render.md). A Bump's own Normal input (a chain of bumps or a normal map under it) is not
followed, noted.

One normal per material: the surface shader's own Normal input (Principled, Diffuse, Glossy,
Glass, Refraction), or for a Mix or Add Shader the one normal map its shaders share. Anything else
on a Normal input (another node, a Normal Map or Bump without an image or fed by another node,
shaders of a Mix with different maps) keeps the surface normal and is noted, as is a linked
Strength (its constant)."""
from __future__ import annotations

from dataclasses import dataclass, replace

from .materials import ImageKey, _blender_version, _constant, _texture, input_socket, linked_node, output_node

# The shaders whose Normal input is honoured.
BSDFS = frozenset({"BSDF_PRINCIPLED", "BSDF_DIFFUSE", "BSDF_GLOSSY", "BSDF_ANISOTROPIC", "BSDF_GLASS",
                   "BSDF_REFRACTION"})
SPACES = frozenset({"TANGENT", "OBJECT", "WORLD", "BLENDER_OBJECT", "BLENDER_WORLD"})


@dataclass(frozen=True)
class NormalMapSpec:
    """A Normal Map node: the image it reads, its Strength, space, convention and UV map ('':
    the render-active one, as Cycles reads an empty uv_map)."""
    texture: ImageKey
    strength: float = 1.0
    space: str = "TANGENT"
    convention: str = "OPENGL"
    uv_map: str = ""
    # How Strength mixes (Cycles' kernels read in 3.4 and 5.0): 3.x blends the bent normal with
    # the smooth one; 4.x+ scales the texel's tangent-space vector.
    strength_mode: str = "tangent"
    # Cycles' shadowing of bent diffuse normals: 3.x Chiang et al.'s term, 4.x+ Conty Estevez et
    # al.'s (the material's Bump Map Correction, on by default; 'none' when off).
    shadowing: str = "conty"
    # Lift the bent normal so the view's mirror stays above the surface: Cycles 3.x for every
    # closure, 4.x+ for glossy ones only (materials.material_spec clears it for a diffuse kind).
    lift: bool = True
    # A Bump node (space 'BUMP'): its Distance (negative: Invert) and the height's channel.
    distance: float = 1.0
    channel: str = "gray"
    # Where a Bump takes the height's slope: 'point' (Cycles 4.4+) or 'pixel', differences over
    # the ray's footprint (Cycles before 4.4, which has no Filter Width).
    footprint: str = "point"

    def arguments(self, texture_id: int) -> dict:
        """add_material's keywords for the core's MaterialNormalMap."""
        if self.space == "BUMP":
            bump = dict(bump_map=texture_id, bump_strength=self.strength, bump_distance=self.distance,
                        bump_channel=self.channel, normal_shadowing=self.shadowing, normal_lift=self.lift)
            if self.footprint != "point":
                bump["bump_footprint"] = self.footprint
            return bump
        return dict(normal_map=texture_id, normal_strength=self.strength, normal_space=self.space,
                    normal_convention=self.convention, normal_strength_mode=self.strength_mode,
                    normal_shadowing=self.shadowing, normal_lift=self.lift)


def surface_shader(mat):
    """The shader node linked to a node material's Material Output Surface, or None."""
    if mat is None or not getattr(mat, "use_nodes", False) or mat.node_tree is None:
        return None
    out = output_node(mat.node_tree, "OUTPUT_MATERIAL")
    return linked_node(input_socket(out, "Surface")) if out is not None else None


def normal_map(name: str, mat, notes: list) -> tuple[NormalMapSpec | None, object]:
    """(spec, Blender image) of the material's normal map, or (None, None): the surface normal."""
    node = surface_shader(mat)
    if node is None:
        return None, None
    correction = bool(getattr(getattr(mat, "cycles", None), "use_bump_map_correction", True))
    if node.type in BSDFS:
        return _from_socket(name, input_socket(node, "Normal"), notes, correction)
    if node.type in ("MIX_SHADER", "ADD_SHADER"):
        shaders = [linked_node(s) for s in node.inputs if s.type == "SHADER"]
        maps = [_from_socket(name, input_socket(s, "Normal"), notes, correction) for s in shaders
                if s is not None and s.type in BSDFS]
        specs = {spec for spec, _ in maps if spec is not None}
        if len(specs) == 1 and all(spec is not None for spec, _ in maps):
            return next((m for m in maps if m[0] is not None))
        if specs:
            notes.append(f"material '{name}': shaders of a {node.bl_idname} with different normals "
                         "(the surface normal)")
    return None, None


def _from_socket(name, socket, notes, correction=True):
    if socket is None or not socket.is_linked:
        return None, None
    src = linked_node(socket)
    if src is None:
        return None, None
    if src.type == "BUMP":
        return _bump(name, src, notes, correction)
    if src.type != "NORMAL_MAP":
        notes.append(f"material '{name}': normal input from {src.bl_idname} (the surface normal)")
        return None, None
    found = _image_on(name, input_socket(src, "Color"), "Normal Map colour", "Normal Map", notes)
    if found is None:
        return None, None
    key, image, _ = found
    strength_socket = input_socket(src, "Strength")
    strength = 1.0
    if strength_socket is not None:
        if strength_socket.is_linked:
            notes.append(f"material '{name}': linked Normal Map strength (its constant value)")
        strength = float(strength_socket.default_value)
        if strength != strength:
            notes.append(f"material '{name}': Normal Map strength is NaN (1)")
            strength = 1.0
    space = getattr(src, "space", "TANGENT")
    if space not in SPACES:
        notes.append(f"material '{name}': Normal Map space {space} (the surface normal)")
        return None, None
    convention = str(getattr(src, "convention", "OPENGL")).upper()   # 5.x+ where present
    if convention not in ("OPENGL", "DIRECTX"):
        convention = "OPENGL"
    mode = "tangent" if _blender_version() >= (4, 0, 0) else "blend"
    return NormalMapSpec(key, strength, space, convention, str(getattr(src, "uv_map", "") or ""), mode,
                         _shadowing(correction)), image


def _image_on(name, socket, what, node_label, notes):
    """(key, image, output name) of the Image Texture linked to `socket`, or None (noted): linked
    to another node or to nothing, or an image that does not load."""
    links = getattr(socket, "links", ()) if socket is not None else ()
    tex = linked_node(socket) if socket is not None else None
    if tex is None or tex.type != "TEX_IMAGE" or not links:
        source = tex.bl_idname if tex is not None else "a constant"
        notes.append(f"material '{name}': {what} from {source} (the surface normal)")
        return None
    key, image = _texture(name, tex, notes)
    if image is None or not _has_pixels(image):
        notes.append(f"material '{name}': {node_label} without an image (the surface normal)")
        return None
    return key, image, links[0].from_socket.name


def _shadowing(correction: bool) -> str:
    """Cycles' shadowing of bent diffuse normals in this Blender version."""
    if _blender_version() >= (4, 0, 0):
        return "conty" if correction else "none"
    return "chiang"


def _bump(name, src, notes, correction):
    """A Bump node's NormalMapSpec (space 'BUMP'), or (None, None): the surface normal, noted."""
    found = _image_on(name, input_socket(src, "Height"), "Bump height", "Bump", notes)
    if found is None:
        return None, None
    key, image, output = found
    normal = input_socket(src, "Normal")
    if normal is not None and normal.is_linked:
        notes.append(f"material '{name}': a Bump's Normal input (the surface normal under the bump)")
    # Before 4.4 (no Filter Width) Cycles differences the height over the ray's footprint.
    footprint = "pixel" if input_socket(src, "Filter Width") is None else "point"
    channel = "alpha" if output == "Alpha" else "gray"
    strength = _constant(name, input_socket(src, "Strength"), "Bump Strength", 1.0, notes)
    distance = _constant(name, input_socket(src, "Distance"), "Bump Distance", 1.0, notes)
    if getattr(src, "invert", False):
        distance = -distance
    return NormalMapSpec(replace(key, alpha=True), strength, "BUMP", shadowing=_shadowing(correction),
                         distance=distance, channel=channel, footprint=footprint), image


def _has_pixels(image) -> bool:
    """Whether Blender could load the image (reading the size loads it, packed or from disk)."""
    try:
        w, h = image.size[:]
    except (RuntimeError, ReferenceError):
        return False
    return w > 0 and h > 0


def tangent_uv_map(mat) -> str | None:
    """The UV map whose tangents the material's normal map reads ('' for the render-active one),
    or None when it reads none (no normal map, or not in tangent space). Notes are not collected
    here: the material's conversion says them."""
    spec, _ = normal_map("", mat, [])
    return spec.uv_map if spec is not None and spec.space == "TANGENT" else None
