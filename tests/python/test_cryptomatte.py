"""Cryptomatte: the add-on's hash (addon/render_toyrt/cryptomatte.py) against published MurmurHash3
test vectors and against the ids Cycles wrote for the same names, the specification's float
conversion, and the native per-pixel ranking (native/render/cryptomatte.h) through render()."""
import importlib.util
import json
import math
from pathlib import Path

import numpy as np
import pytest
from test_passes import camera_down, two_tiles

# The add-on's module on its own: it imports neither bpy nor the rest of the add-on.
_spec = importlib.util.spec_from_file_location(
    "toyrt_cryptomatte", Path(__file__).resolve().parents[2] / "addon" / "render_toyrt" / "cryptomatte.py")
crypto = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(crypto)


# MurmurHash3_x86_32 vectors as published with the reference code's ports (seed, bytes, hash):
# every tail length 0-3, whole blocks, and multi-byte UTF-8.
VECTORS = [
    (0, b"", 0x00000000), (1, b"", 0x514E28B7), (0xFFFFFFFF, b"", 0x81F16F39),
    (0, b"\0\0\0\0", 0x2362F9DE),
    (0x9747B28C, b"aaaa", 0x5A97808A), (0x9747B28C, b"aaa", 0x283E0130), (0x9747B28C, b"aa", 0x5D211726),
    (0x9747B28C, b"a", 0x7FA09EA6), (0x9747B28C, b"abcd", 0xF0478627), (0x9747B28C, b"abc", 0xC84A62DD),
    (0x9747B28C, b"ab", 0x74875592), (0x9747B28C, b"Hello, world!", 0x24884CBA),
    (0x9747B28C, "ππππππππ".encode(), 0xD58063C1),
    (0x9747B28C, b"The quick brown fox jumps over the lazy dog", 0x2FA826CD),
]


@pytest.mark.parametrize("seed,data,expected", VECTORS)
def test_murmurhash3_32_matches_the_published_vectors(seed, data, expected):
    assert crypto.murmurhash3_32(data, seed) == expected


def test_names_hash_as_cycles_hashed_them():
    # Read from the manifests Cycles (Blender 3.4 and 5.0) wrote for these names (UTF-8 included).
    cycles = {"floor": "7819c83c", "box ü": "2f5dbb37", "grün ✓": "aa7accba", "default_surface": "78d05529",
              "red": "eb5026fd", "Root": "d63fb0f2"}
    hashes = crypto.Hashes()
    assert {n: f"{hashes.of(n):08x}" for n in cycles} == cycles
    # And the metadata key of the layer 'ViewLayer.CryptoObject', the first 7 hex digits of its hash.
    assert crypto.layer_key("ViewLayer.CryptoObject", hashes) == "cryptomatte/542cafa"


def test_the_float_conversion_keeps_every_id_finite_and_normal():
    bits = {0x00000000: 0x00800000,   # exponent 0 (zero, denormals) -> 1
            0x7F800000: 0x7F000000,   # exponent 255 (infinity) -> 254
            0xFFFFFFFF: 0xFF7FFFFF,   # exponent 255 (NaN), negative
            0x807FFFFF: 0x80FFFFFF,   # a negative denormal
            0x3F800000: 0x3F800000}   # 1.0: a normal float is left as it is
    for h, expected in bits.items():
        assert int(crypto.float_bits([h])[0]) == expected, hex(h)
    ids = crypto.hash_to_float(np.random.default_rng(1).integers(0, 2**32, 100_000, dtype=np.uint64))
    assert ids.dtype == np.float32 and np.all(np.isfinite(ids))
    assert np.all(np.abs(ids) >= np.finfo(np.float32).tiny)


def test_the_manifest_is_json_of_each_name_once_in_first_seen_order():
    hashes = crypto.Hashes()
    assert hashes.manifest(["floor", "box ü", "floor"]) == '{"floor":"7819c83c","box ü":"2f5dbb37"}'
    assert hashes.manifest([]) == "{}"
    # A name Cycles would write as broken JSON is escaped.
    name = 'say "hi" \\ back'
    assert json.loads(hashes.manifest([name])) == {name: f"{hashes.of(name):08x}"}


def test_layers_hold_two_pairs_each_and_the_depth_rounds_up_as_cycles():
    class Layer:
        def __init__(self, depth):
            self.pass_cryptomatte_depth = depth
    assert [crypto.layers(Layer(d)) for d in (2, 3, 6, 15, 16)] == [1, 2, 3, 8, 8]
    assert crypto.depth(Layer(5)) == 6
    assert crypto.pass_names(crypto.KINDS[1], 3) == ["CryptoMaterial00", "CryptoMaterial01", "CryptoMaterial02"]


IDS = dict(object=np.array([1.5, 2.5], np.float32), material=np.array([4.5, 5.5], np.float32),
           asset=np.array([7.5, 7.5], np.float32))


def test_each_tile_is_its_own_id_with_full_coverage_and_the_seam_shares_it():
    s = two_tiles()
    # A 2 m view of the two 5 m tiles: every pixel is covered; the seam x = 0 runs between columns 7 and 8.
    image = s.render(camera_down(), samples=16, cryptomatte=IDS, cryptomatte_depth=2)
    p = s.last_passes
    assert sorted(p) == ["cryptomatte_asset", "cryptomatte_material", "cryptomatte_object"]
    assert p["cryptomatte_object"].shape == (16, 16, 4)
    obj, mat, asset = p["cryptomatte_object"], p["cryptomatte_material"], p["cryptomatte_asset"]
    assert np.all(obj[:, :7, 0] == 1.5) and np.all(obj[:, 9:, 0] == 2.5)
    assert np.all(mat[:, :7, 0] == 4.5) and np.all(mat[:, 9:, 0] == 5.5)
    assert np.all(asset[..., 0] == 7.5) and np.all(asset[..., 1] == 1.0) and np.all(asset[..., 2:] == 0.0)
    assert np.allclose(obj[..., 1] + obj[..., 3], 1.0)   # fully covered: the shares sum to 1
    assert np.all(obj[..., 1] >= obj[..., 3])             # ranked
    # The image is the same with or without the passes.
    assert np.array_equal(image, s.render(camera_down(), samples=16))


def test_misses_carry_no_id():
    s = two_tiles()
    cam = camera_down(height=5.0)
    cam["ortho_scale"] = 20.0  # the tiles span 10 m of the 20 m view: the rest is the world
    s.render(cam, samples=4, cryptomatte={"object": IDS["object"]}, cryptomatte_depth=1)
    obj = s.last_passes["cryptomatte_object"]
    assert np.all(obj[0, :] == 0.0) and np.all(obj[:, 0] == 0.0)   # the world: id 0, coverage 0
    assert obj[8, 4, 0] == 1.5 and obj[8, 4, 1] == 1.0


def test_bad_cryptomatte_arguments_are_value_errors():
    s = two_tiles()
    with pytest.raises(ValueError, match="unknown Cryptomatte kind 'light'"):
        s.render(camera_down(), samples=1, cryptomatte={"light": IDS["object"]}, cryptomatte_depth=2)
    with pytest.raises(ValueError, match=r"cryptomatte_depth must be in \[0, 16\]"):
        s.render(camera_down(), samples=1, cryptomatte=IDS, cryptomatte_depth=17)
    with pytest.raises(ValueError, match="needs cryptomatte_depth >= 1"):
        s.render(camera_down(), samples=1, cryptomatte=IDS)
    s.render(camera_down(), samples=1, cryptomatte=IDS, cryptomatte_depth=16)   # Blender's largest
    assert s.last_passes["cryptomatte_object"].shape == (16, 16, 32)
    assert not math.isnan(float(s.last_passes["cryptomatte_object"].sum()))
