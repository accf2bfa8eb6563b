"""Incremental export: one native scene kept between updates, and what each part was made from.

    cache = SceneCache(toyrt)
    cache.sync(depsgraph)                       # first time: everything
    cache.sync(depsgraph, depsgraph.updates)    # later (view_update): only what changed
    cache.commit(builder="auto", threads=0)     # builds changed meshes' BVHs and the top level

What an update costs (`cache.counters` counts it, the tests read them):
- a camera (or view) move: nothing; the camera is read at render time;
- a transform edit: new instance matrices (set_instance_transform), a commit of the top level only;
- a geometry edit: that mesh re-exported in place (replace_mesh: same id, its instances stay);
- a material / image edit: that material / texture replaced in place; a light edit: the lights
  sent again (they are few); the world: its colour.
Objects added or deleted place every instance again (cheap: a transform each); a mesh nobody
shows any more is emptied and its id reused, so a long session or an animation does not grow.

For final renders (`sync(depsgraph)` without updates, once per frame) a mesh is reused when its
evaluated geometry has the same fingerprint (vertex positions, topology sizes) as last frame."""
import hashlib

import numpy as np

from . import export


class _CachedMaterials(export._Materials):
    """The exporter's material converter, remembering which Blender material made each id so an
    edit can convert it again into the same id."""

    def reconvert(self, mat):
        """Convert `mat` again into the id it already has; returns 1, or 0 if it has none yet."""
        mid = self.by_material.get(mat.name_full)
        if mid is None:
            return 0
        real = self.scene
        self.scene = _InPlace(real, mid)
        try:
            self._convert(mat)
        finally:
            self.scene = real
        return 1

    def refresh_image(self, image):
        """Send an edited image's pixels again into its texture ids."""
        count = 0
        for key, tid in self.by_image.items():
            if key[0] == image.name_full:
                pixels = self._pixels(image)
                if pixels is not None:
                    self.scene.set_texture(tid, pixels, srgb=key[1])
                    count += 1
        return count


class _InPlace:
    """Stands in for the scene while a material is converted again: its add_material becomes
    set_material of the id being refreshed."""

    def __init__(self, scene, material_id):
        self._scene, self._id = scene, material_id

    def add_material(self, kind, **kwargs):
        self._scene.set_material(self._id, kind, **kwargs)
        return self._id

    def __getattr__(self, name):
        return getattr(self._scene, name)


class _LightRecorder:
    """Collects the lights the exporter would add, so they are sent only when they changed."""

    def __init__(self):
        self.calls = []

    def add_point_light(self, *args, **kwargs):
        self.calls.append(("add_point_light", _plain(args), _plain(kwargs)))

    def add_area_light(self, *args, **kwargs):
        self.calls.append(("add_area_light", _plain(args), _plain(kwargs)))


def _plain(value):
    """Arguments as comparable tuples (matrices to nested tuples)."""
    if isinstance(value, dict):
        return tuple(sorted((k, _plain(v)) for k, v in value.items()))
    if isinstance(value, (list, tuple)):
        return tuple(_plain(v) for v in value)
    if isinstance(value, np.ndarray):
        return tuple(map(tuple, value.tolist())) if value.ndim == 2 else tuple(value.tolist())
    return value


def _fingerprint(obj):
    """What a final render compares between frames to reuse a mesh: for mesh objects the
    evaluated vertex positions and the topology sizes (a deforming modifier or shape key moves
    vertices; a generating one changes counts). Other types (curves, text) return None: always
    exported again."""
    if obj.type != "MESH" or obj.data is None:
        return None
    mesh = obj.data
    co = np.empty(len(mesh.vertices) * 3, np.float32)
    mesh.vertices.foreach_get("co", co)
    h = hashlib.blake2b(co.tobytes(), digest_size=16)
    h.update(np.array([len(mesh.vertices), len(mesh.loops), len(mesh.polygons)], np.int64).tobytes())
    # The materials are part of what is stored (material ids per triangle).
    h.update("|".join(s.material.name_full if s.material else "" for s in obj.material_slots).encode())
    return h.digest()


# Raised by sync() when its should_cancel answers true (export.py raises it between the stages
# of one mesh too). The cache is then half updated: the caller must drop it
# (discard_render_cache) so the next render starts from scratch.
ExportCancelled = export.ExportCancelled


# should_cancel is polled every this many object instances, and before each mesh export.
_POLL_EVERY = 256


class SceneCache:
    def __init__(self, toyrt):
        self.toyrt = toyrt
        self.scene = toyrt.Scene()
        self.approximated = []                 # what the exporter approximated (for one warning)
        self.materials = _CachedMaterials(self.scene, self.approximated)
        self.meshes = {}                       # mesh key -> [mesh id or -1, triangles, fingerprint]
        self.free_ids = []                     # emptied meshes, reused by the next new mesh
        self.placed = []                       # [(mesh id, matrix as bytes)] in instance order
        self.owner_keys = {}                   # object pointer -> the mesh key it showed last
        self.owner_instances = {}              # object pointer -> its instance ids (plain objects)
        self.lights = None                     # the recorded light calls last sent
        self._should_cancel = None             # set by sync() for the length of a full walk
        self.synced = False
        self.stats = {}
        self.counters = dict(syncs=0, walks=0, meshes_exported=0, meshes_freed=0, instance_resets=0,
                             transforms_set=0, fast_moves=0, materials_converted=0, textures_refreshed=0, light_sends=0,
                             commits=0, mesh_bvhs_built=0, top_level_builds=0)

    # ---------------------------------------------------------------------------------------
    def sync(self, depsgraph, updates=None, should_cancel=None):
        """Bring the native scene up to date with `depsgraph`. Without `updates` (the first sync,
        and final renders) everything is walked and meshes are compared by fingerprint; with
        `depsgraph.updates` only what they name is done. should_cancel() (e.g. the engine's
        test_break) is polled during a full walk; when true, ExportCancelled is raised."""
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
                self.counters["materials_converted"] += self.materials.reconvert(id_)
            elif kind == "Image":
                self.counters["textures_refreshed"] += self.materials.refresh_image(id_)
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
        # of its own) walks, re-exporting nothing unchanged; with moved objects it is theirs.
        walk = walk or (scene_update and not moved)
        if not walk and moved and not self._move(moved):
            walk = True
        if walk:
            self._walk(depsgraph, dirty_objects=geometry, fingerprints=False)

    def _move(self, moved):
        """New matrices for the instances of moved plain objects, without walking the depsgraph
        (a walk over 10,000 instances costs about 0.45 s here). False if a matrix is singular."""
        changes = []
        for slots, obj in moved:
            matrix = np.array(obj.matrix_world, np.float64)
            if export._singular(matrix):
                return False
            changes += [(i, matrix) for i in slots]
        for i, matrix in changes:
            if self.placed[i][1] != matrix.tobytes():
                self.scene.set_instance_transform(i, matrix)
                self.placed[i] = (self.placed[i][0], matrix.tobytes())
                self.counters["transforms_set"] += 1
        self.counters["fast_moves"] += 1
        return True

    def commit(self, builder="auto", threads=0, expected_rays=None, should_cancel=None):
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
    def _walk(self, depsgraph, dirty_objects, fingerprints):
        """One pass over depsgraph.object_instances: meshes exported where new or changed,
        instances and lights compared with what the native scene has."""
        import time

        t0 = time.perf_counter()
        self.counters["walks"] += 1
        placed, seen, exported_now = [], set(), set()
        recorder = _LightRecorder()
        used_materials = {}
        tri_instanced = 0
        pool, by_fingerprint, owners = {}, {}, {}
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
        poll = self._should_cancel
        for n, inst in enumerate(depsgraph.object_instances):
            if poll is not None and n % _POLL_EVERY == 0 and poll():
                raise ExportCancelled()
            obj = inst.object
            if obj is None:
                continue
            otype = obj.type
            if otype == "LIGHT":
                export._export_light(recorder, obj, np.array(inst.matrix_world, np.float64), self.approximated)
                continue
            if otype not in export.RENDERABLE:
                continue
            if not inst.is_instance and not inst.show_self:
                continue
            if export._singular(np.array(inst.matrix_world, np.float64)):
                # Scaled to zero along an axis: the core refuses the matrix (export._singular).
                # At zero scale nothing of it can be hit; a flattened object is left out too.
                continue
            key = export._mesh_key(obj)
            owner = None if inst.is_instance else obj.original.as_pointer()
            if fingerprints:
                entry = self._match(key, obj, owner, pool, by_fingerprint, depsgraph)
                seen.add(key)
                exported_now.add(key)
            else:
                entry = self.meshes.get(key)
            if entry is None and owner is not None:
                # Blender re-evaluated the object into a new mesh datablock (an edit, a frame
                # change): take over the mesh its previous one made, to replace it in place.
                previous = self.owner_keys.get(owner)
                if previous is not None and previous != key and previous in self.meshes and previous not in seen:
                    entry = self.meshes.pop(previous)
            if owner is not None:
                self.owner_keys[owner] = key
            if key not in exported_now:
                if entry is None or self._changed(inst, obj, dirty_objects):
                    entry = self._export_mesh(obj, depsgraph, entry)
                    self.meshes[key] = entry
                exported_now.add(key)
            seen.add(key)
            if fingerprints:
                for slot in obj.material_slots:
                    if slot.material is not None:
                        used_materials[slot.material.name_full] = slot.material
            if entry[0] >= 0:
                if owner is not None:
                    owners.setdefault(owner, []).append(len(placed))
                placed.append((entry[0], np.array(inst.matrix_world, np.float64)))
                tri_instanced += entry[1]

        for entry in pool.values():
            if entry[0] >= 0:
                self._empty(entry[0])
        self._free_unseen(seen)
        self._place(placed)
        self.owner_instances = owners
        if recorder.calls != self.lights:
            self.scene.clear_lights()
            for name, args, kwargs in recorder.calls:
                getattr(self.scene, name)(*args, **dict(kwargs))
            self.lights = recorder.calls
            self.counters["light_sends"] += 1
        self._world(depsgraph)
        if fingerprints:
            # Final renders have no update list: materials (animated colours) are converted again
            # into their ids, which costs a few node reads each.
            for mat in used_materials.values():
                self.counters["materials_converted"] += self.materials.reconvert(mat)
        live = [e for e in self.meshes.values() if e[0] >= 0]
        self.stats = dict(export_s=time.perf_counter() - t0, meshes=len(live), instances=len(placed),
                          lights=len(recorder.calls), triangles_stored=sum(e[1] for e in live),
                          triangles=tri_instanced, approximated=list(self.approximated))

    def _world(self, depsgraph):
        notes = []
        export._export_world(self.scene, depsgraph.scene, notes)
        self.approximated.extend(n for n in notes if n not in self.approximated)

    def _match(self, key, obj, owner, pool, by_fingerprint, depsgraph):
        """Final renders: this frame's entry for `key`: already made this frame, last frame's
        mesh with the same content (kept as is), or last frame's mesh of the same object
        (replaced in place), or a new one."""
        entry = self.meshes.get(key)
        if entry is not None:
            return entry
        fp = _fingerprint(obj)
        candidates = by_fingerprint.get(fp, []) if fp is not None else []
        same = candidates.pop() if candidates else None
        if same is not None and same in pool:
            entry = pool.pop(same)
        else:
            previous = self.owner_keys.get(owner) if owner is not None else None
            entry = self._export_mesh(obj, depsgraph, pool.pop(previous, None) if previous is not None else None, fp)
        self.meshes[key] = entry
        if owner is not None:
            self.owner_keys[owner] = key
        return entry

    def _changed(self, inst, obj, dirty_objects):
        """With updates: whether Blender says the geometry of the object (or of the instancer
        that made this instance) changed."""
        if not dirty_objects:
            return False
        source = inst.parent if inst.is_instance and inst.parent is not None else obj
        original = getattr(source, "original", None) or source
        return original.as_pointer() in dirty_objects or obj.original.as_pointer() in dirty_objects

    def _export_mesh(self, obj, depsgraph, entry, fingerprint=None):
        # A mesh export can take a few hundred ms: Esc is asked between its stages (export.py)
        # and once more before the copy into the native scene.
        poll = self._should_cancel
        data = export.mesh_data(obj, self.materials, depsgraph, poll=poll)
        export._stop_if(poll)
        self.counters["meshes_exported"] += 1
        old_id = entry[0] if entry is not None else -1
        if data is None:
            if old_id >= 0:
                self._empty(old_id)
            return [-1, 0, fingerprint]
        verts, tris, normals, uvs, mat_ids = data
        mid = old_id if old_id >= 0 else (self.free_ids.pop() if self.free_ids else -1)
        if mid >= 0:
            self.scene.replace_mesh(mid, verts, tris, normals=normals, uvs=uvs, material_ids=mat_ids)
        else:
            # add_mesh places one instance too: _place() lays every instance out again after it.
            mid = self.scene.add_mesh(verts, tris, normals=normals, uvs=uvs, material_ids=mat_ids)
            self.placed = None
        return [mid, len(tris), fingerprint]

    def _empty(self, mid):
        self.scene.replace_mesh(mid, np.zeros((0, 3), np.float32), np.zeros((0, 3), np.uint32))
        self.free_ids.append(mid)
        self.counters["meshes_freed"] += 1

    def _free_unseen(self, seen):
        live = set(self.meshes) & seen
        self.owner_keys = {o: k for o, k in self.owner_keys.items() if k in live}
        for key in [k for k in self.meshes if k not in seen]:
            mid = self.meshes.pop(key)[0]
            if mid >= 0:
                self._empty(mid)

    def _place(self, placed):
        """Instances: matrices only when the same meshes are placed in the same order, else all again."""
        old = self.placed
        if old is not None and len(old) == len(placed) and all(a[0] == b[0] for a, b in zip(old, placed)):
            for i, ((_, before), (_, now)) in enumerate(zip(old, placed)):
                if before != now.tobytes():
                    self.scene.set_instance_transform(i, now)
                    self.counters["transforms_set"] += 1
        else:
            self.scene.clear_instances()
            for mid, matrix in placed:
                self.scene.add_instance(mid, matrix)
            self.counters["instance_resets"] += 1
        self.placed = [(mid, matrix.tobytes()) for mid, matrix in placed]


# ---------------------------------------------------------------------------------------------
# Final renders: one cache per Blender scene, so the frames of an animation rendered in one
# Blender process reuse what did not change (Blender makes a new engine object for every F12;
# an animation's frames share one engine and depsgraph on 3.4, but not their mesh datablocks).

_render_caches = {}


def for_render(depsgraph, toyrt):
    scene = depsgraph.scene
    key = (getattr(scene, "original", scene) or scene).as_pointer()
    cache = _render_caches.get(key)
    if cache is None:
        _render_caches.clear()  # one scene at a time: another scene's meshes are not kept alive
        cache = _render_caches[key] = SceneCache(toyrt)
    return cache


def discard_render_cache(depsgraph):
    """Drops the scene's cache after a cancelled export (it may be half updated)."""
    scene = depsgraph.scene
    _render_caches.pop((getattr(scene, "original", scene) or scene).as_pointer(), None)


def free_render_caches():
    """On file load and unregister: the Blender data the keys point to is gone."""
    _render_caches.clear()
