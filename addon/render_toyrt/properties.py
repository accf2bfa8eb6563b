"""TOYRT's render settings, stored per scene at `scene.toyrt`."""
import bpy


class TOYRTRenderSettings(bpy.types.PropertyGroup):
    samples: bpy.props.IntProperty(
        name="Samples", description="Samples per pixel (Sobol-Owen pattern, box filter of one pixel)",
        default=16, min=1, soft_max=4096)
    viewport_samples: bpy.props.IntProperty(
        name="Viewport Samples",
        description="Samples per pixel the 3D viewport's Rendered mode accumulates before it stops using the CPU",
        default=32, min=1, soft_max=1024)
    area_light_sampling: bpy.props.EnumProperty(
        name="Area Lights", description="How soft shadows of rectangular area lights are sampled",
        items=[("solid_angle", "Solid Angle",
                "Uniform over the light's solid angle (spherical rectangles, Urena et al. 2013)"),
               ("area", "Area", "Uniform over the light's area")],
        default="solid_angle")
    light_sampling: bpy.props.EnumProperty(
        name="Light Sampling", description="Which lights a shading point samples",
        items=[("auto", "Auto", "Every light when there are few, one chosen by contribution when there are many"),
               ("all", "All Lights", "A shadow ray to every light at every hit"),
               ("one", "One Light", "One light per hit, chosen by its expected contribution")],
        default="auto")
    builder: bpy.props.EnumProperty(
        name="BVH Builder", description="How acceleration structures are built",
        items=[("auto", "Auto", "Whichever makes build plus tracing cheaper for this render"),
               ("sah", "SAH", "Binned surface area heuristic on the CPU: the fastest trees"),
               ("lbvh", "LBVH", "Linear BVH as OpenCL kernels: the fastest builds")],
        default="auto")
    max_specular_depth: bpy.props.IntProperty(
        name="Max Specular Depth", description="Refractions and reflections a path may take through glass",
        default=8, min=0, max=128)
    use_denoising: bpy.props.BoolProperty(
        name="Denoise", description="Denoise the final render with Intel Open Image Denoise (the pyoidn package), "
        "its albedo and normal from the Diffuse Color and Normal passes; the noisy render is kept as the "
        "Noisy Image pass", default=False)
    seed: bpy.props.IntProperty(
        name="Seed", description="Seed of the sampling pattern (the frame number is added when animating)",
        default=0, min=0)


def register() -> None:
    bpy.utils.register_class(TOYRTRenderSettings)
    bpy.types.Scene.toyrt = bpy.props.PointerProperty(type=TOYRTRenderSettings)


def unregister() -> None:
    del bpy.types.Scene.toyrt
    bpy.utils.unregister_class(TOYRTRenderSettings)
