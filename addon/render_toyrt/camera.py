"""Blender's scene camera -> the camera dict toyrt.Scene.render(camera=...) takes.

The camera is read at render time, never stored in the native scene: a camera move costs the
sync nothing. (The 3D viewport's camera is viewport.view_camera; it has no depth of field.)"""
from __future__ import annotations

import numpy as np


def export_camera(depsgraph, camera_object=None) -> dict:
    """The dict for toyrt.Scene.render(camera=...) from the scene's (or the given) camera."""
    bl_scene = depsgraph.scene
    cam = camera_object if camera_object is not None else bl_scene.camera
    if cam is None:
        # The original scene's camera, if the evaluated one is unset for some reason.
        orig = getattr(bl_scene, "original", None)
        cam = getattr(orig, "camera", None)
    if cam is None:
        raise RuntimeError(f"TOYRT: scene '{bl_scene.name}' has no camera; add one and make it the scene camera")
    cam = cam.evaluated_get(depsgraph) if hasattr(cam, "evaluated_get") else cam
    r = bl_scene.render
    d = dict(
        matrix_world=np.array(cam.matrix_world, np.float64),
        resolution_x=int(r.resolution_x), resolution_y=int(r.resolution_y),
        resolution_percentage=int(r.resolution_percentage),
        pixel_aspect_x=float(r.pixel_aspect_x), pixel_aspect_y=float(r.pixel_aspect_y),
        use_border=bool(r.use_border),
        border_min_x=float(r.border_min_x), border_min_y=float(r.border_min_y),
        border_max_x=float(r.border_max_x), border_max_y=float(r.border_max_y),
    )
    if cam.type == "CAMERA":
        c = cam.data
        d.update(type="ORTHO" if c.type == "ORTHO" else "PERSP", lens=float(c.lens),
                 sensor_width=float(c.sensor_width), sensor_height=float(c.sensor_height),
                 sensor_fit=c.sensor_fit, shift_x=float(c.shift_x), shift_y=float(c.shift_y),
                 clip_start=float(c.clip_start), clip_end=float(c.clip_end), ortho_scale=float(c.ortho_scale))
        d.update(depth_of_field(depsgraph, cam, c.dof))
    else:
        # Blender renders through a non-camera object with the default camera settings.
        d.update(type="PERSP", lens=50.0, sensor_width=36.0, sensor_height=24.0, sensor_fit="AUTO",
                 shift_x=0.0, shift_y=0.0, clip_start=0.1, clip_end=1000.0, ortho_scale=6.0)
    return d


def depth_of_field(depsgraph, cam, dof) -> dict:
    """Blender's camera.dof (the same properties in 3.4 and 5.x) as the core's settings; the core
    turns the f-stop into the aperture radius and clamps as Cycles does."""
    if not dof.use_dof:
        return dict(use_dof=False)
    return dict(use_dof=True, focus_distance=focus_distance(depsgraph, cam, dof),
                aperture_fstop=float(dof.aperture_fstop), aperture_blades=int(dof.aperture_blades),
                aperture_rotation=float(dof.aperture_rotation), aperture_ratio=float(dof.aperture_ratio))


def focus_distance(depsgraph, cam, dof) -> float:
    """The focus point's depth along the camera's view axis, as Cycles computes it (|view axis .
    (camera - point)| between world positions), else dof.focus_distance. The point is the focus
    object's origin, or, when dof.focus_subtarget names a bone of that armature, the posed bone's
    head (the object's matrix times the pose bone's, as Cycles 3.4 and 5.x both do)."""
    target = dof.focus_object
    if target is None:
        return float(dof.focus_distance)
    target = getattr(target, "original", target)
    target = target.evaluated_get(depsgraph) if hasattr(target, "evaluated_get") else target
    m = np.array(cam.matrix_world, np.float64)
    t = np.array(target.matrix_world, np.float64)
    bone_name = getattr(dof, "focus_subtarget", "")
    pose = getattr(target, "pose", None)
    if bone_name and pose is not None and bone_name in pose.bones:
        t = t @ np.array(pose.bones[bone_name].matrix, np.float64)
    axis = m[:3, 2] / np.linalg.norm(m[:3, 2])
    return float(abs(axis @ (m[:3, 3] - t[:3, 3])))
