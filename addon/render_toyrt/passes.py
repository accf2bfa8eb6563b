"""Render passes through Blender's own switches: the View Layer's use_pass_* properties choose
them, and each is registered under the name, channels and type Cycles gives it on the running
Blender (Cycles' list_render_passes, intern/cycles/blender/addon/engine.py), so a compositing setup
or a multilayer EXR reader made for Cycles works with TOYRT. The values are the core's
(native/render/aovs.h: Cycles' definitions); a pass TOYRT cannot produce is registered and left
black, with one note."""
from __future__ import annotations

from typing import NamedTuple

import bpy

from . import cryptomatte


class Pass(NamedTuple):
    prop: str       # the View Layer property that turns it on
    name_3: str     # Cycles' name on Blender 3.x-4.x
    name_5: str     # Cycles' name on Blender 5.x
    channels: str   # channel ids, one letter per channel
    kind: str       # register_pass's type
    native: str | None  # the core's pass (render(passes=...)); None: left black
    albedo: bool = False  # the denoiser's albedo: the core's pass clipped to [0, 1] (denoise.albedo)

    @property
    def name(self) -> str:
        return self.name_5 if bpy.app.version >= (5, 0, 0) else self.name_3


# Cycles' order of list_render_passes, the View Layer's standard properties only (its own
# view_layer.cycles ones need the Cycles add-on and are not TOYRT's).
PASSES = (
    Pass("use_pass_z", "Depth", "Depth", "Z", "VALUE", "depth"),
    Pass("use_pass_mist", "Mist", "Mist", "Z", "VALUE", "mist"),
    Pass("use_pass_position", "Position", "Position", "XYZ", "VECTOR", "position"),
    Pass("use_pass_normal", "Normal", "Normal", "XYZ", "VECTOR", "normal"),
    Pass("use_pass_vector", "Vector", "Vector", "XYZW", "VECTOR", None),
    Pass("use_pass_uv", "UV", "UV", "UVA", "VECTOR", None),
    Pass("use_pass_object_index", "IndexOB", "Object Index", "X", "VALUE", "object_index"),
    Pass("use_pass_material_index", "IndexMA", "Material Index", "X", "VALUE", "material_index"),
    Pass("use_pass_diffuse_direct", "DiffDir", "Diffuse Direct", "RGB", "COLOR", None),
    Pass("use_pass_diffuse_indirect", "DiffInd", "Diffuse Indirect", "RGB", "COLOR", None),
    Pass("use_pass_diffuse_color", "DiffCol", "Diffuse Color", "RGB", "COLOR", "diffuse_color"),
    Pass("use_pass_glossy_direct", "GlossDir", "Glossy Direct", "RGB", "COLOR", None),
    Pass("use_pass_glossy_indirect", "GlossInd", "Glossy Indirect", "RGB", "COLOR", None),
    # The glossy lobes' albedo and glass's reflection (native/render/glossy_color.h).
    Pass("use_pass_glossy_color", "GlossCol", "Glossy Color", "RGB", "COLOR", "glossy_color"),
    Pass("use_pass_transmission_direct", "TransDir", "Transmission Direct", "RGB", "COLOR", None),
    Pass("use_pass_transmission_indirect", "TransInd", "Transmission Indirect", "RGB", "COLOR", None),
    Pass("use_pass_transmission_color", "TransCol", "Transmission Color", "RGB", "COLOR", None),
    Pass("use_pass_emit", "Emit", "Emission", "RGB", "COLOR", "emission"),
    Pass("use_pass_environment", "Env", "Environment", "RGB", "COLOR", "environment"),
    Pass("use_pass_shadow", "Shadow", "Shadow", "RGB", "COLOR", None),  # a 3.x property only
    Pass("use_pass_ambient_occlusion", "AO", "Ambient Occlusion", "RGB", "COLOR", None),
)

# World mist falloff -> Cycles' exponent (blender/sync.cpp).
_MIST_FALLOFF = {"QUADRATIC": 2.0, "LINEAR": 1.0, "INVERSE_QUADRATIC": 0.5}


# Cycles' Denoising Data passes (its view_layer.cycles.denoising_store_passes; TOYRT's is
# view_layer.toyrt.denoising_store_passes): the denoiser's auxiliary images, for denoising in the
# compositor. Cycles' list changed in 5.x (seen in 5.3's Cycles add-on; 3.4 and 5.0 have the first).
# Albedo and Normal are what TOYRT's denoiser reads (denoise.py), Depth is the Depth pass; the
# specular albedo and roughness TOYRT does not produce are left black, noted as any such pass.
_DENOISING_DATA_3 = (
    Pass("denoising_store_passes", "Denoising Normal", "Denoising Normal", "XYZ", "VECTOR", "normal"),
    Pass("denoising_store_passes", "Denoising Albedo", "Denoising Albedo", "RGB", "COLOR", "diffuse_color", True),
    Pass("denoising_store_passes", "Denoising Depth", "Denoising Depth", "Z", "VALUE", "depth"),
)
_DENOISING_DATA_5_1 = (
    _DENOISING_DATA_3[1],
    Pass("denoising_store_passes", "Denoising Specular Albedo", "Denoising Specular Albedo", "RGB", "COLOR", None),
    _DENOISING_DATA_3[0],
    Pass("denoising_store_passes", "Denoising Roughness", "Denoising Roughness", "X", "VALUE", None),
    _DENOISING_DATA_3[2],
)


def denoising_data(view_layer) -> tuple[Pass, ...]:
    """The Denoising Data passes when the View Layer stores them (after every other pass, as Cycles lists them)."""
    settings = getattr(view_layer, "toyrt", None)
    if settings is None or not settings.denoising_store_passes:
        return ()
    return _DENOISING_DATA_5_1 if bpy.app.version >= (5, 1, 0) else _DENOISING_DATA_3


def enabled(view_layer) -> list[Pass]:
    """The passes the View Layer turns on, in Cycles' order (Combined is always there)."""
    return [p for p in PASSES if getattr(view_layer, p.prop, False)] + list(denoising_data(view_layer))


def register(engine, scene, view_layer) -> None:
    """RenderEngine.update_render_passes: Combined, every pass turned on, and (denoising) the
    noisy render, as Cycles keeps it."""
    engine.register_pass(scene, view_layer, "Combined", 4, "RGBA", "COLOR")
    for p in enabled(view_layer):
        engine.register_pass(scene, view_layer, p.name, len(p.channels), p.channels, p.kind)
    cryptomatte.register(engine, scene, view_layer)
    if denoising(scene):
        engine.register_pass(scene, view_layer, NOISY, 4, "RGBA", "COLOR")


NOISY = "Noisy Image"  # Cycles' name of the render before denoising, the same in 3.x and 5.x


def denoising(scene) -> bool:
    settings = getattr(scene, "toyrt", None)
    return bool(settings is not None and settings.use_denoising)


def mist(world) -> tuple[float, float, float]:
    """(start, depth, falloff exponent) of the World's mist settings; Blender's defaults without a world."""
    if world is None:
        return 5.0, 25.0, 2.0
    m = world.mist_settings
    return float(m.start), float(m.depth), _MIST_FALLOFF.get(m.falloff, 2.0)


def black(passes: list[Pass]) -> list[str]:
    """The names of the passes TOYRT leaves black."""
    return [p.name for p in passes if p.native is None]


def per_material_id(materials: dict, used: dict) -> list[int]:
    """Material pass_index per native material id, from sync's name -> (id, spec) table and the
    Blender materials the walk saw (0 for an id none of them has)."""
    ids = {materials[name][0]: mat.pass_index for name, mat in used.items() if name in materials}
    return [ids.get(k, 0) for k in range(max(ids, default=-1) + 1)]


class PassTables:
    """What the index and Cryptomatte passes need to know of each instance (in the native scene's
    instance order) and each material id, gathered by sync's walk of a final render. The names
    are read only when the View Layer asks for a Cryptomatte pass: a scene of many objects pays
    for them only then."""

    def __init__(self, view_layer=None, hashes: cryptomatte.Hashes | None = None) -> None:
        self.cryptomatte = cryptomatte.enabled(view_layer)
        self.cryptomatte_depth = cryptomatte.depth(view_layer) if self.cryptomatte else 0  # pairs per pixel
        self.hashes = hashes if hashes is not None else cryptomatte.Hashes()  # kept from frame to frame
        self.object_pass_index: list[int] = []
        self.material_pass_index: list[int] = []
        self.object_names: list[str] = []   # per instance (Cryptomatte asked for)
        self.asset_names: list[str] = []
        self.material_names: list[str] = []  # per material id
        self.material_manifest: list[str] = []  # the materials this walk saw, and Cycles' default shader

    def add(self, obj) -> None:
        """The next instance, showing the (evaluated) object `obj`."""
        self.object_pass_index.append(obj.pass_index)
        if self.cryptomatte:
            self.object_names.append(obj.name)
            self.asset_names.append(cryptomatte.asset_name(obj))

    def finish(self, materials: dict, used: dict) -> None:
        """The per-material-id tables, from sync's name -> (id, spec) table and the materials seen."""
        self.material_pass_index = per_material_id(materials, used)
        if self.cryptomatte:
            self.material_names = cryptomatte.material_names(materials, used)
            self.material_manifest = [cryptomatte.DEFAULT_SURFACE] + [mat.name for mat in used.values()]

    def names(self, kind: str) -> list[str]:
        """The name of each instance ('object', 'asset') or material id ('material')."""
        return {"object": self.object_names, "material": self.material_names, "asset": self.asset_names}[kind]

    def manifest_names(self, kind: str) -> list[str]:
        """The names the manifest lists: every instance's (Cycles lists every object), the materials
        this frame uses (sync keeps the ids of earlier frames' too) beside Cycles' default shader."""
        return self.material_manifest if kind == "material" else self.names(kind)

    def cryptomatte_ids(self) -> dict | None:
        """render()'s `cryptomatte`: the float32 ids per instance / material id of each kind asked for."""
        return {k.native: self.hashes.ids(self.names(k.native)) for k in self.cryptomatte} or None
