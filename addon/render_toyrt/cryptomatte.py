"""Cryptomatte object, material and asset passes, as Cycles writes them, so Blender's Cryptomatte node
and any reader of the specification (Psyop's Cryptomatte 1.2) pick mattes from TOYRT's renders:

- the View Layer's switches (use_pass_cryptomatte_object / _material / _asset, pass_cryptomatte_depth)
  turn them on; each kind is (depth + 1) // 2 passes of channels r, g, b, a named CryptoObject00,
  CryptoObject01, ... (CryptoMaterial.., CryptoAsset..), each holding two (id, coverage) pairs:
  Cycles' layout;
- an id is MurmurHash3_32 (seed 0) of the UTF-8 name, its 32 bits read as a float32 whose exponent
  is kept off 0 and 255 (no denormal, infinity or NaN): the specification's uint32_to_float32;
- the names are Cycles': the object's name (an instance's: the instanced object's), the material's
  ('default_surface' for faces without one, Cycles' default shader), the asset's: the top-level
  parent of the object;
- the manifest (name -> the hash as 8 hex digits) goes into the render result's metadata under
  cryptomatte/<first 7 hex digits of the hash of '<view layer>.CryptoObject'>/name, hash,
  conversion, manifest; Cycles writes JSON without escaping, this writes valid JSON (the same text
  for names without quotes or backslashes).

The per-pixel ranking is the native render loop's (native/render/cryptomatte.h); here, only names,
hashes and Blender's side. Nothing in this file imports bpy: the hash is tested on its own."""
from __future__ import annotations

import json
from typing import NamedTuple

import numpy as np

# Cycles' name of the shader of faces without a material (its manifest lists it).
DEFAULT_SURFACE = "default_surface"


class Kind(NamedTuple):
    native: str   # render(cryptomatte={native: ...})
    prefix: str   # Cycles' pass name before the two-digit layer number
    prop: str     # the View Layer switch


# Cycles' order of registration.
KINDS = (Kind("object", "CryptoObject", "use_pass_cryptomatte_object"),
         Kind("material", "CryptoMaterial", "use_pass_cryptomatte_material"),
         Kind("asset", "CryptoAsset", "use_pass_cryptomatte_asset"))
MAX_DEPTH = 16  # Blender's largest pass_cryptomatte_depth; Cycles clamps to it too


# ---- the hash ------------------------------------------------------------------------------------
def murmurhash3_32(data: bytes, seed: int = 0) -> int:
    """MurmurHash3's x86 32-bit variant (Austin Appleby's public-domain reference), as an unsigned int."""
    c1, c2, mask = 0xCC9E2D51, 0x1B873593, 0xFFFFFFFF
    h = seed & mask
    n = len(data) // 4 * 4
    for k in np.frombuffer(data[:n], "<u4").tolist() if n else ():
        k = (k * c1) & mask
        k = ((k << 15) | (k >> 17)) & mask
        h ^= (k * c2) & mask
        h = ((h << 13) | (h >> 19)) & mask
        h = (h * 5 + 0xE6546B64) & mask
    tail = data[n:]
    if tail:
        k = int.from_bytes(tail, "little")
        k = (k * c1) & mask
        k = ((k << 15) | (k >> 17)) & mask
        h ^= (k * c2) & mask
    h ^= len(data)
    h ^= h >> 16
    h = (h * 0x85EBCA6B) & mask
    h ^= h >> 13
    h = (h * 0xC2B2AE35) & mask
    return h ^ (h >> 16)


def float_bits(hashes) -> np.ndarray:
    """uint32_to_float32's bits: an exponent field of 0 or 255 has its lowest bit flipped (to 1 or
    254), so the id is a finite, normal float that survives any float pipeline. Returns uint32s."""
    h = np.asarray(hashes, np.uint32)
    exponent = (h >> np.uint32(23)) & np.uint32(0xFF)
    flip = (exponent == 0) | (exponent == 0xFF)
    return np.where(flip, h ^ np.uint32(1 << 23), h).astype(np.uint32)


def hash_to_float(hashes) -> np.ndarray:
    """The Cryptomatte ids (float32) of MurmurHash3_32 hashes."""
    return float_bits(hashes).view(np.float32)


class Hashes:
    """name -> MurmurHash3_32 of its UTF-8 bytes, remembered: an animation's frames (and a scene's
    many instances of one object) hash each name once."""

    def __init__(self) -> None:
        self._known: dict[str, int] = {}

    def of(self, name: str) -> int:
        h = self._known.get(name)
        if h is None:
            h = self._known[name] = murmurhash3_32(name.encode("utf-8"))
        return h

    def ids(self, names) -> np.ndarray:
        """The float32 ids of `names`, in order."""
        return hash_to_float([self.of(n) for n in names]) if len(names) else np.zeros(0, np.float32)

    def manifest(self, names) -> str:
        """The manifest's JSON: each distinct name (first seen first) -> its hash as 8 hex digits."""
        table = {n: f"{self.of(n):08x}" for n in dict.fromkeys(names)}
        return json.dumps(table, ensure_ascii=False, separators=(",", ":"))


# ---- Blender's side --------------------------------------------------------------------------------
def depth(view_layer) -> int:
    """(id, coverage) pairs per pixel, as Cycles writes them: two per RGBA layer, the layers
    Blender's depth rounded up to an even count (at most MAX_DEPTH)."""
    return 2 * layers(view_layer)


def layers(view_layer) -> int:
    return (min(MAX_DEPTH, max(1, int(getattr(view_layer, "pass_cryptomatte_depth", 6)))) + 1) // 2


def enabled(view_layer) -> list[Kind]:
    """The kinds the View Layer turns on (none without a View Layer)."""
    return [k for k in KINDS if view_layer is not None and getattr(view_layer, k.prop, False)]


def pass_names(kind: Kind, count: int) -> list[str]:
    """Cycles' names of the kind's first `count` RGBA layers."""
    return [f"{kind.prefix}{i:02d}" for i in range(count)]


def register(engine, scene, view_layer) -> None:
    """update_render_passes' part: the RGBA passes of every kind turned on. Their channels are
    lower-case r, g, b, a as Cycles names them (the specification's names, which OpenEXR's DWA
    compression also keeps lossless)."""
    for kind in enabled(view_layer):
        for name in pass_names(kind, layers(view_layer)):
            engine.register_pass(scene, view_layer, name, 4, "rgba", "COLOR")


def asset_name(obj) -> str:
    """Cycles' asset: the name of the object's top-level parent (its own name without a parent)."""
    while obj.parent is not None:
        obj = obj.parent
    return obj.name


def material_names(materials: dict, used: dict) -> list[str]:
    """A name per native material id, from sync's name -> (id, spec) table and the Blender materials
    the walk saw ({name_full: material}); the id of faces without a material gets Cycles' default
    shader's name, an id the walk did not see none ('': no id)."""
    names = {materials[full][0]: mat.name for full, mat in used.items() if full in materials}
    if "" in materials:
        names[materials[""][0]] = DEFAULT_SURFACE
    return [names.get(k, "") for k in range(max(names, default=-1) + 1)]


def layer_key(name: str, hashes: Hashes) -> str:
    """The metadata prefix of a Cryptomatte layer ('ViewLayer.CryptoObject'): its hash's first 7 hex digits."""
    return "cryptomatte/" + f"{hashes.of(name):08x}"[:7]


def stamp(result, view_layer_name: str, kind: Kind, names, hashes: Hashes) -> None:
    """The layer's manifest into the render result's metadata, under Cycles' keys."""
    name = f"{view_layer_name}.{kind.prefix}"
    prefix = layer_key(name, hashes) + "/"
    result.stamp_data_add_field(prefix + "name", name)
    result.stamp_data_add_field(prefix + "hash", "MurmurHash3_32")
    result.stamp_data_add_field(prefix + "conversion", "uint32_to_float32")
    result.stamp_data_add_field(prefix + "manifest", hashes.manifest([n for n in names if n]))


def split(pairs: np.ndarray) -> list[np.ndarray]:
    """The native (h, w, 2 * depth) pairs as the RGBA layers: (id, coverage, id, coverage) each."""
    return [pairs[..., 4 * i:4 * i + 4] for i in range(pairs.shape[2] // 4)]
