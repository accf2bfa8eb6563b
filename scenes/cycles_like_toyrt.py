"""Cycles restricted to TOYRT's light transport: the one definition the parity test
(tests/blender/test_cycles_parity.py) and the benchmarks (bench/blender_bench.py,
bench/blender/configure.py) compare against, so they cannot drift apart.

Direct light only (max bounces 0), or, with glass, only specular chains through it (diffuse
bounces 0; glossy bounces too, since Cycles' glass reflection is a glossy bounce and TOYRT's
Fresnel dielectric reflects as well); Box filter one pixel wide; no denoising, adaptive sampling,
clamping or light threshold (Cycles' probabilistic light termination: unbiased, but noisier);
a fixed seed. Runs inside Blender."""


def configure_cycles(scene, samples, specular_depth):
    scene.render.engine = "CYCLES"
    c = scene.cycles
    c.device = "CPU"
    c.samples = samples
    c.use_denoising = False
    c.use_adaptive_sampling = False
    c.seed = 0
    c.pixel_filter_type = "BOX"
    c.filter_width = 1.0
    c.light_sampling_threshold = 0.0
    c.sample_clamp_direct = c.sample_clamp_indirect = 0.0
    c.blur_glossy = 0.0
    c.caustics_reflective = c.caustics_refractive = True
    c.volume_bounces = 0
    c.diffuse_bounces = 0
    if specular_depth:
        c.max_bounces = specular_depth
        c.glossy_bounces = c.transmission_bounces = specular_depth
    else:
        c.max_bounces = 0
    # Transparent surfaces do not count as bounces in either engine: the same limit, TOYRT's.
    toyrt = getattr(scene, "toyrt", None)
    c.transparent_max_bounces = int(getattr(toyrt, "transparent_max_bounces", 8))
