"""The one door in: Blender's depsgraph -> the native toyrt.Scene.

The only code of the add-on that walks `depsgraph.object_instances` and the only writer of the
native scene. The converters (mesh.py, materials.py, lights.py, world.py, camera.py) return plain
data; SceneSync compares it with what it sent and sends only the difference. F12 and animations
(one SceneSync per Blender scene: render_cache.for_render), the 3D viewport (one per view) and the tests and
benchmarks (export_scene, a one-shot sync) all go through it.

    sync = SceneSync(toyrt)
    sync.sync(depsgraph)                        # first time: everything
    sync.sync(depsgraph, depsgraph.updates)     # later (view_update): only what changed
    sync.commit(builder="auto", threads=0)      # builds changed meshes' BVHs and the top level

What an update costs (`sync.counters` counts it, the tests read them):
- a camera (or view) move: nothing; the camera is read at render time (camera.export_camera);
- a transform edit: new instance matrices (set_instance_transform), a commit of the top level only;
- a geometry edit: that mesh converted again in place (replace_mesh: same id, its instances stay);
- a material / image edit: that material / texture replaced in place; a light edit: the lights
  sent again (they are few) if their specs changed; the world: its colour.
Objects added or deleted place every instance again (cheap: a transform each); a mesh nobody
shows any more is emptied and its id reused, so a long session or an animation does not grow.

An instance whose matrix the core cannot invert (scaled to zero along an axis: mesh.singular) is
baked: its own mesh with the matrix applied, placed with the identity, keyed by its matrix; so a
flattened object renders flattened, as in Cycles, on every path.

For final renders (`sync(depsgraph)` without updates, once per frame) a mesh is reused when its
evaluated geometry has the same fingerprint (vertex positions, topology sizes) as last frame."""
from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np

from . import materials, passes
from .camera import export_camera
from .light_linking import linked_light, read_links
from .lights import LightSpec, light_spec
from .materials import ImageKey
from .mesh import (
    RENDERABLE,
    ExportCancelled,
    evaluated_geometry,
    fingerprint,
    instance_arguments,
    instance_flags,
    mesh_key,
    singular,
    stop_if,
    to_array,
)
from .sync_materials import MaterialSync
from .world import WorldSpec, world_spec

__all__ = ["SceneSync", "ExportCancelled", "export_scene"]

# should_cancel is polled every this many object instances, and between the stages of each mesh.
_POLL_EVERY = 256
_IDENTITY = np.eye(4)


class SceneSync(MaterialSync):
    """One native scene kept in step with a Blender depsgraph, and what each part was made from."""

    def __init__(self, toyrt, *, fingerprints: bool = True) -> None:
        """fingerprints: remember each mesh's content, for the next final-render frame to match
        (False for a one-shot sync, which has no next frame: hashing a 1M-triangle mesh's
        vertices costs ~10 ms)."""
        self.toyrt = toyrt
        self.keep_fingerprints = fingerprints
        self.scene = toyrt.Scene()
        self.approximated: list[str] = []      # what the converters approximated (for one warning)
        self.meshes: dict[tuple, list] = {}    # mesh key -> [mesh id or -1, triangles, fingerprint]
        self.free_ids: list[int] = []          # emptied meshes, reused by the next new mesh
        self.placed: list | None = []          # [(mesh id, matrix as bytes, mesh.instance_flags)] in instance order
        self.owner_keys: dict[int, tuple] = {}         # object pointer -> the mesh key it showed last
        self.owner_instances: dict[int, list] = {}     # object pointer -> its instance ids (plain objects)
        # Keyed by name, not pointer: a final render's depsgraph may hand out new copies of the same
        # material every frame, and they must be found again.
        self.materials: dict[str, tuple[int, materials.MaterialSpec]] = {}  # name ('': none) -> (id, spec sent)
        self.mix_parts: dict[str, list[int]] = {}  # a mix material's name -> the ids its inputs were sent into
        self.tangent_maps: dict[str, str | None] = {}  # material name -> the UV map its normal map's tangents read
        self.material_users: dict[str, set[int]] = {}  # name -> objects sent with it (original pointers)
        self.textures: dict[ImageKey, int] = {}        # image -> texture id (missing: the placeholder's)
        self.texture_notes: dict[ImageKey, tuple[str, ...]] = {}
        self.lights: tuple[LightSpec, ...] | None = None   # the light specs last sent
        self.world: WorldSpec | None = None
        # Index and Cryptomatte passes (final-render walks): per instance, per material id.
        self.pass_tables = passes.PassTables()
        self._should_cancel: Callable[[], bool] | None = None   # set by sync() for a full walk
        self._converted_now: set[str] = set()  # materials converted during the current walk
        self.synced = False
        self.stats: dict = {}
        self.counters = dict(syncs=0, walks=0, meshes_exported=0, meshes_freed=0, instance_resets=0,
                             transforms_set=0, fast_moves=0, materials_converted=0, textures_refreshed=0, light_sends=0,
                             commits=0, mesh_bvhs_built=0, top_level_builds=0)

    # ---------------------------------------------------------------------------------------
    def sync(self, depsgraph, updates=None, should_cancel: Callable[[], bool] | None = None) -> None:
        """Bring the native scene up to date with `depsgraph`. Without `updates` (the first sync,
        and final renders) everything is walked and meshes are compared by fingerprint; with
        `depsgraph.updates` only what they name is done. should_cancel() (e.g. the engine's
        test_break) is polled during a full walk; when true, ExportCancelled is raised and the
        scene is half updated: drop this SceneSync (discard_render_cache)."""
        self.counters["syncs"] += 1
        if not self.synced or updates is None:
            self._should_cancel = should_cancel
            try:
                self._walk(depsgraph, dirty_objects=None, fingerprints=True)
            finally:
                self._should_cancel = None
            self.synced = True
            return
        geometry, walk, scene_update, moved = set(), False, False, []
        for update in updates:
            id_ = update.id
            kind = type(id_).__name__
            original = getattr(id_, "original", None) or id_
            if kind == "Object":
                if id_.type == "CAMERA":
                    continue  # read at render time
                slots = self.owner_instances.get(original.as_pointer())
                if (update.is_updated_transform and not update.is_updated_geometry and slots is not None
                        and not id_.is_instancer):
                    moved.append((slots, id_))  # a plain object moved: its instances only
                    continue
                walk = True
                if update.is_updated_geometry:
                    geometry.add(original.as_pointer())
            elif kind == "Material":
                self.counters["materials_converted"] += self._reconvert(id_)
                if self._tangents_changed(id_):  # a normal map added or removed: send its meshes again
                    walk = True
                    geometry |= self.material_users.get(id_.name_full, set())
            elif kind == "Image":
                self.counters["textures_refreshed"] += self._refresh_image(id_)
            elif kind == "World":
                self._world(depsgraph)
            elif kind in ("Light",):
                walk = True  # lights are compared and sent again only if they changed
            elif kind == "Scene":
                scene_update = True
            elif kind in ("Mesh", "Curve", "TextCurve", "MetaBall", "Collection", "ParticleSettings",
                          "GeometryNodeTree", "NodeTree"):
                walk = True
        # A Scene update alone (a setting, a frame change, a deleted object, which has no update
        # of its own) walks, converting nothing unchanged; with moved objects it is theirs.
        walk = walk or (scene_update and not moved)
        if not walk and moved and not self._move(moved):
            walk = True
        if walk:
            self._walk(depsgraph, dirty_objects=geometry, fingerprints=False)

    def commit(self, builder: str = "auto", threads: int = 0, expected_rays: float | None = None,
               should_cancel: Callable[[], bool] | None = None) -> bool:
        """Commit if anything changed; returns whether it did. A build stopped by should_cancel
        leaves the scene uncommitted (returns False): the next commit builds what is missing."""
        if self.scene.committed:
            return False
        if not self.scene.commit(builder=builder, threads=threads, expected_rays=expected_rays,
                                 should_cancel=should_cancel):
            return False
        info = self.scene.last_commit
        self.counters["commits"] += 1
        self.counters["mesh_bvhs_built"] += info["meshes_built"]
        self.counters["top_level_builds"] += 1
        return True

    # ---------------------------------------------------------------------------------------
    def _move(self, moved) -> bool:
        """New matrices for the instances of moved plain objects, without walking the depsgraph
        (a walk over 10,000 instances costs 0.2-0.4 s here). False if a matrix is singular:
        the object is to be baked, which a walk does."""
        changes = []
        for slots, obj in moved:
            matrix = to_array(obj.matrix_world)
            if singular(matrix):
                return False
            changes += [(i, matrix) for i in slots]
        for i, matrix in changes:
            if self.placed[i][1] != matrix.tobytes():
                self.scene.set_instance_transform(i, matrix)
                self.placed[i] = (self.placed[i][0], matrix.tobytes(), self.placed[i][2])
                self.counters["transforms_set"] += 1
        self.counters["fast_moves"] += 1
        return True

    def _walk(self, depsgraph, dirty_objects, fingerprints: bool) -> None:
        """One pass over depsgraph.object_instances: meshes converted where new or changed,
        instances, lights and the world compared with what the native scene has."""
        t0 = time.perf_counter()
        self.counters["walks"] += 1
        placed, seen, exported_now, light_specs = [], set(), set(), []
        links = read_links(depsgraph)  # Blender 4.0+'s light linking (empty without it)
        tables = passes.PassTables(depsgraph.view_layer if fingerprints else None, self.pass_tables.hashes)
        used_materials = {}
        tri_instanced = 0
        pool, by_fingerprint, owners = {}, {}, {}
        self._converted_now = set()
        if fingerprints:
            # Each final render reports what it approximates now (materials are converted again
            # below, lights and the world re-read), not what earlier frames did.
            del self.approximated[:]
            # A final render's depsgraph hands out new mesh datablocks every frame (their
            # addresses, hence the keys, change or even get reused by another object): last
            # frame's meshes are matched by content instead, then by the object that made them.
            pool, self.meshes = self.meshes, {}
            for k, e in pool.items():
                if e[2] is not None:  # identical copies (objects with the same modifiers) share a list
                    by_fingerprint.setdefault(e[2], []).append(k)
        self._note(links.notes)  # after the final render's reset of the notes above
        poll = self._should_cancel
        for n, inst in enumerate(depsgraph.object_instances):
            if poll is not None and n % _POLL_EVERY == 0 and poll():
                raise ExportCancelled()
            obj = inst.object  # for instances: a temporary object showing the instanced geometry
            if obj is None:
                continue
            otype = obj.type
            if otype == "LIGHT":
                spec, notes = light_spec(obj, to_array(inst.matrix_world))
                self._note(notes)
                if spec is not None:
                    if not links.empty and obj.name in links.receiver_sets.keys() | links.blocker_sets.keys():
                        spec = linked_light(spec, links, obj.name)
                    light_specs.append(spec)
                continue
            if otype not in RENDERABLE:
                continue
            if not inst.is_instance and not inst.show_self:
                continue  # e.g. a particle emitter with "show emitter" off
            matrix = to_array(inst.matrix_world)
            key = mesh_key(obj)
            bake = None
            if singular(matrix):
                bake = matrix  # its own mesh, keyed by the matrix that flattened it
                key = ("baked", matrix.tobytes()) + key
            owner = None if inst.is_instance else obj.original.as_pointer()
            if fingerprints:
                entry = self._match(key, obj, owner, pool, by_fingerprint, depsgraph, bake)
                seen.add(key)
                exported_now.add(key)
            else:
                entry = self.meshes.get(key)
            stale = False
            if entry is None and owner is not None:
                # Blender re-evaluated the object into a new mesh datablock (an edit, a frame
                # change), or its baking matrix changed: take over the mesh its previous key
                # made, to replace it in place.
                previous = self.owner_keys.get(owner)
                if previous is not None and previous != key and previous in self.meshes and previous not in seen:
                    entry = self.meshes.pop(previous)
                    stale = key[0] == "baked" or previous[0] == "baked"
            if owner is not None:
                self.owner_keys[owner] = key
            if key not in exported_now:
                if entry is None or stale or self._changed(inst, obj, dirty_objects):
                    entry = self._export_mesh(obj, depsgraph, entry, bake=bake)
                    self.meshes[key] = entry
                exported_now.add(key)
            seen.add(key)
            if fingerprints:
                for slot in obj.material_slots:
                    if slot.material is not None:
                        used_materials[slot.material.name_full] = slot.material
            if entry[0] >= 0:
                if owner is not None and bake is None:
                    owners.setdefault(owner, []).append(len(placed))
                flags = instance_flags(inst, obj, links)
                placed.append((entry[0], _IDENTITY if bake is not None else matrix, flags))
                tables.add(obj)
                tri_instanced += entry[1]

        for entry in pool.values():
            if entry[0] >= 0:
                self._empty(entry[0])
        self._free_unseen(seen)
        self._place(placed)
        self.owner_instances = owners
        self._send_lights(tuple(light_specs))
        self._world(depsgraph)
        if fingerprints:
            # Final renders have no update list: materials (animated colours) are converted again
            # and sent if they changed, which costs a few node reads each.
            for name, mat in used_materials.items():
                if name not in self._converted_now:
                    self.counters["materials_converted"] += self._reconvert(mat)
            tables.finish(self.materials, used_materials)
            self.pass_tables = tables
        live = [e for e in self.meshes.values() if e[0] >= 0]
        tri_stored = sum(e[1] for e in live)
        self.stats = dict(export_s=time.perf_counter() - t0, meshes=len(live), instances=len(placed),
                          lights=len(light_specs), materials=len(self.materials),
                          textures=len(set(self.textures.values())), triangles_stored=tri_stored,
                          triangles_instanced=tri_instanced, triangles=tri_instanced,
                          approximated=list(self.approximated))

    def _match(self, key, obj, owner, pool, by_fingerprint, depsgraph, bake):
        """Final renders: this frame's entry for `key`: already made this frame, last frame's
        mesh with the same content (kept as is), or last frame's mesh of the same object
        (replaced in place), or a new one."""
        entry = self.meshes.get(key)
        if entry is not None:
            return entry
        fp = fingerprint(obj, bake) if self.keep_fingerprints else None
        candidates = by_fingerprint.get(fp, []) if fp is not None else []
        same = candidates.pop() if candidates else None
        if same is not None and same in pool:
            entry = pool.pop(same)
        else:
            previous = self.owner_keys.get(owner) if owner is not None else None
            reuse = pool.pop(previous, None) if previous is not None else None
            entry = self._export_mesh(obj, depsgraph, reuse, fp, bake)
        self.meshes[key] = entry
        if owner is not None:
            self.owner_keys[owner] = key
        return entry

    def _changed(self, inst, obj, dirty_objects) -> bool:
        """With updates: whether Blender says the geometry of the object (or of the instancer
        that made this instance) changed."""
        if not dirty_objects:
            return False
        source = inst.parent if inst.is_instance and inst.parent is not None else obj
        original = getattr(source, "original", None) or source
        return original.as_pointer() in dirty_objects or obj.original.as_pointer() in dirty_objects

    # ---- meshes and instances ------------------------------------------------------------------
    def _export_mesh(self, obj, depsgraph, entry, fingerprint=None, bake=None) -> list:
        # A mesh's conversion can take a few hundred ms: Esc is asked between its stages
        # (mesh.evaluated_geometry) and once more before the copy into the native scene.
        poll = self._should_cancel
        geometry = evaluated_geometry(obj, depsgraph, poll=poll, bake=bake, tangents_for=self._tangent_uv_map)
        stop_if(poll)
        self.counters["meshes_exported"] += 1
        old_id = entry[0] if entry is not None else -1
        if geometry is None:
            if old_id >= 0:
                self._empty(old_id)
            return [-1, 0, fingerprint]
        slot_ids = np.array([self._material_id(m) for m in geometry.materials], np.int32)
        for m in geometry.materials:
            if m is not None:
                self.material_users.setdefault(m.name_full, set()).add(obj.original.as_pointer())
        mat_ids = slot_ids[geometry.slots]
        g = geometry
        if g.tangents is None and (uv_map := self._tangent_uv_map(g.materials)) is not None:
            self._note((f"object '{obj.name}': no UV map {uv_map or '(render-active)'} for its normal map "
                        "(the surface normal)",))
        mid = old_id if old_id >= 0 else (self.free_ids.pop() if self.free_ids else -1)
        if mid >= 0:
            self.scene.replace_mesh(mid, g.vertices, g.triangles, normals=g.normals, uvs=g.uvs, material_ids=mat_ids,
                                    tangents=g.tangents)
        else:
            # Stored only: _place() puts its instances where the walk found them.
            mid = self.scene.add_mesh(g.vertices, g.triangles, normals=g.normals, uvs=g.uvs, material_ids=mat_ids,
                                      instance=False, tangents=g.tangents)
        return [mid, len(g.triangles), fingerprint]

    def _empty(self, mid: int) -> None:
        self.scene.replace_mesh(mid, np.zeros((0, 3), np.float32), np.zeros((0, 3), np.uint32))
        self.free_ids.append(mid)
        self.counters["meshes_freed"] += 1

    def _free_unseen(self, seen) -> None:
        live = set(self.meshes) & seen
        self.owner_keys = {o: k for o, k in self.owner_keys.items() if k in live}
        for key in [k for k in self.meshes if k not in seen]:
            mid = self.meshes.pop(key)[0]
            if mid >= 0:
                self._empty(mid)

    def _place(self, placed) -> None:
        """Instances: matrices only when the same meshes are placed in the same order, else all again."""
        old = self.placed
        if old is not None and len(old) == len(placed) and all(a[0] == b[0] and a[2] == b[2]
                                                               for a, b in zip(old, placed)):
            for i, ((_, before, _), (_, now, _)) in enumerate(zip(old, placed)):
                if before != now.tobytes():
                    self.scene.set_instance_transform(i, now)
                    self.counters["transforms_set"] += 1
        else:
            self.scene.clear_instances()
            for mid, matrix, flags in placed:
                self.scene.add_instance(mid, matrix, **instance_arguments(flags))
            self.counters["instance_resets"] += 1
        self.placed = [(mid, matrix.tobytes(), shadow) for mid, matrix, shadow in placed]

    # ---- lights, world ---------------------------------------------------------------------
    def _send_lights(self, specs: tuple[LightSpec, ...]) -> None:
        if specs == self.lights:
            return
        self.scene.clear_lights()
        for spec in specs:
            self.scene.add_light(spec.light_type, **spec.arguments())
        self.lights = specs
        self.counters["light_sends"] += 1

    def _world(self, depsgraph) -> None:
        spec = world_spec(depsgraph.scene)
        self._note(spec.notes)
        if spec.environment is not None:
            # Its notes (a missing image) again for every render, as a material's texture's are.
            env = spec.environment
            tid = self._environment_texture_id(env, self.world)
        if spec != self.world:
            self.scene.background = spec.background
            if spec.background_lighting is not None:
                self.scene.background_lighting = spec.background_lighting
            self.scene.background_visible_camera = spec.visible_camera
            self.scene.background_visible_glossy = spec.visible_glossy
            self.scene.background_visible_transmission = spec.visible_transmission
            if spec.environment is None:
                self.scene.set_environment(-1)
            else:
                self.scene.set_environment(tid, strength=env.strength, matrix=np.array(env.matrix))
            self.world = spec

    def _note(self, notes) -> None:
        self.approximated.extend(n for n in notes if n not in self.approximated)


# ---------------------------------------------------------------------------------------------
# One-shot: tests, benchmarks and scripts enter through the same door as F12 and the viewport.

def export_scene(depsgraph, toyrt, *, report: Callable | None = None,
                 camera_object=None) -> tuple[object, dict, dict]:
    """Blender depsgraph -> (toyrt.Scene, camera dict, stats), by one full sync of a new
    SceneSync. The caller commits the scene.

    stats: export_s, meshes, instances, lights, materials, textures, triangles_stored (each mesh
    once), triangles_instanced (= triangles: over all instances), approximated (list of strings).
    With `report` (a RenderEngine's or an operator's report), one note lists what was
    approximated (report.note: a WARNING in the UI, a `TOYRT note:` line in background mode)."""
    t0 = time.perf_counter()
    camera = export_camera(depsgraph, camera_object)  # fail early, before any work
    sync = SceneSync(toyrt, fingerprints=False)
    sync.sync(depsgraph)
    stats = dict(sync.stats, export_s=time.perf_counter() - t0)
    if sync.approximated and report is not None:
        from .report import note  # the add-on's reporting policy: a warning in the UI, a note on farms

        note("approximated: " + "; ".join(sync.approximated), report)
    return sync.scene, camera, stats
