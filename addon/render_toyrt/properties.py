"""TOYRT's render settings, stored per scene at `scene.toyrt`."""
import bpy


def _redraw_viewports(_self, context) -> None:
    """A setting the viewport renders with changed: redraw the 3D views, whose draw sees the change
    and restarts their render (viewport.py). A property of an add-on's own settings sends Blender
    no view_update, and no redraw of the 3D views when set from a script."""
    for window in context.window_manager.windows:
        for area in window.screen.areas:
            if area.type == "VIEW_3D":
                area.tag_redraw()


class TOYRTRenderSettings(bpy.types.PropertyGroup):
    samples: bpy.props.IntProperty(
        name="Samples", description="Samples per pixel (Sobol-Owen pattern, box filter of one pixel)",
        default=16, min=1, soft_max=4096)
    # Cycles' names and meaning (scene.cycles.use_adaptive_sampling, adaptive_threshold,
    # adaptive_min_samples, time_limit), so users find them where they expect.
    use_adaptive_sampling: bpy.props.BoolProperty(
        name="Noise Threshold", description="Stop sampling a pixel once its noise estimate is below the "
        "threshold (Cycles' adaptive sampling)", default=False)
    adaptive_threshold: bpy.props.FloatProperty(
        name="Noise Threshold", description="Noise level at which a pixel stops being sampled; 0 for an "
        "automatic value from the sample count", default=0.01, min=0.0, max=1.0, soft_min=0.001, precision=4)
    adaptive_min_samples: bpy.props.IntProperty(
        name="Min Samples", description="Samples every pixel takes before adaptive sampling may stop it; 0 for "
        "an automatic count from the threshold", default=0, min=0, max=4096)
    time_limit: bpy.props.FloatProperty(
        name="Time Limit", description="Stop rendering a frame after this time (scene export and BVH build "
        "not counted); the frame is complete for the samples taken. 0 for no limit",
        default=0.0, min=0.0, subtype="TIME_ABSOLUTE", unit="TIME_ABSOLUTE")
    viewport_samples: bpy.props.IntProperty(
        name="Viewport Samples",
        description="Samples per pixel the 3D viewport's Rendered mode accumulates before it stops using the CPU",
        default=32, min=1, soft_max=1024, update=_redraw_viewports)
    area_light_sampling: bpy.props.EnumProperty(
        name="Area Lights", description="How soft shadows of rectangular area lights are sampled",
        items=[("solid_angle", "Solid Angle",
                "Uniform over the light's solid angle (spherical rectangles, Urena et al. 2013)"),
               ("area", "Area", "Uniform over the light's area")],
        default="solid_angle", update=_redraw_viewports)
    light_sampling: bpy.props.EnumProperty(
        name="Light Sampling", description="Which lights a shading point samples",
        items=[("auto", "Auto", "Every light when there are few, one chosen by contribution when there are many"),
               ("all", "All Lights", "A shadow ray to every light at every hit"),
               ("one", "One Light", "One light per hit, chosen by its expected contribution")],
        default="auto", update=_redraw_viewports)
    builder: bpy.props.EnumProperty(
        name="BVH Builder", description="How acceleration structures are built",
        items=[("auto", "Auto", "Whichever makes build plus tracing cheaper for this render"),
               ("sah", "SAH", "Binned surface area heuristic on the CPU: the fastest trees"),
               ("lbvh", "LBVH", "Linear BVH, on the CPU or as OpenCL kernels on a GPU: the fastest builds")],
        default="auto")
    max_specular_depth: bpy.props.IntProperty(
        name="Max Specular Depth", description="Refractions and reflections a path may take through glass",
        default=8, min=0, max=128, update=_redraw_viewports)
    transparent_max_bounces: bpy.props.IntProperty(
        name="Transparent Max Bounces", description="Transparent surfaces (alpha cut-outs, Transparent BSDF) a "
        "path or a shadow ray may pass through, as Cycles' setting of that name: past them a path stops at the "
        "next surface and a shadow is cast", default=8, min=0, max=1024, update=_redraw_viewports)
    use_denoising: bpy.props.BoolProperty(
        name="Denoise", description="Denoise the final render with Intel Open Image Denoise (the pyoidn package), "
        "its albedo and normal from the Diffuse Color and Normal passes; the noisy render is kept as the "
        "Noisy Image pass", default=False)
    use_preview_denoising: bpy.props.BoolProperty(
        name="Viewport Denoise", description="Denoise the 3D viewport's Rendered mode with Intel Open Image "
        "Denoise after each pass of samples, its albedo and normal from the same samples", default=False,
        update=_redraw_viewports)
    seed: bpy.props.IntProperty(
        name="Seed", description="Seed of the sampling pattern (the frame number is added when animating)",
        default=0, min=0, update=_redraw_viewports)


class TOYRTViewLayerSettings(bpy.types.PropertyGroup):
    """TOYRT's settings of a View Layer, at `view_layer.toyrt` (Cycles keeps its own at
    `view_layer.cycles`)."""
    denoising_store_passes: bpy.props.BoolProperty(
        name="Denoising Data", description="Store the denoiser's auxiliary images as the Denoising Albedo and "
        "Denoising Normal passes (Cycles' names), to denoise in the compositor", default=False)


def register() -> None:
    bpy.utils.register_class(TOYRTRenderSettings)
    bpy.utils.register_class(TOYRTViewLayerSettings)
    bpy.types.Scene.toyrt = bpy.props.PointerProperty(type=TOYRTRenderSettings)
    bpy.types.ViewLayer.toyrt = bpy.props.PointerProperty(type=TOYRTViewLayerSettings)


def unregister() -> None:
    del bpy.types.ViewLayer.toyrt
    del bpy.types.Scene.toyrt
    bpy.utils.unregister_class(TOYRTViewLayerSettings)
    bpy.utils.unregister_class(TOYRTRenderSettings)
