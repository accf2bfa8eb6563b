"""The material and texture half of SceneSync (sync.py): Blender materials and images -> the native
scene's material and texture ids, converted on first use, sent again in place when they change.

A mixin, not a class of its own, because it shares SceneSync's state (the scene, the notes, the
id tables): it is here only to keep each file one concern. Nothing else uses it."""
from __future__ import annotations

from . import materials
from .material_mix import MixImages
from .material_normal import tangent_uv_map
from .materials import PLACEHOLDER, PLACEHOLDER_PIXELS, ImageKey


class MaterialSync:
    """Needs from SceneSync: scene, materials, tangent_maps, textures, texture_notes, _converted_now, _note()."""

    def _material_id(self, mat) -> int:
        """The material id of a Blender material (None: an empty slot), converted on first use."""
        name = mat.name_full if mat is not None else ""
        sent = self.materials.get(name)
        if sent is not None:
            return sent[0]
        converted = materials.material_spec(mat)
        mid = self.scene.add_material(**self._material_arguments(converted, name))
        self.materials[name] = (mid, converted.spec)
        self.tangent_maps[name] = tangent_uv_map(mat) if mat is not None else None
        self._converted_now.add(name)
        return mid

    def _tangents_changed(self, mat) -> bool:
        """Whether the UV map whose tangents `mat`'s normal map reads (None: none) changed since
        it was last sent, so the meshes using it need sending again (a viewport update of the
        material alone does not say their geometry changed). False for a material not sent yet."""
        name = mat.name_full
        if name not in self.tangent_maps:
            return False
        now = tangent_uv_map(mat)
        if now == self.tangent_maps[name]:
            return False
        self.tangent_maps[name] = now
        return True

    def _tangent_uv_map(self, slot_materials: tuple) -> str | None:
        """The UV map whose tangents a mesh with these slot materials needs ('': the render-active
        one), read from their node trees as they are now (a final render converts its materials
        again after the meshes); None when none has a tangent-space normal map. One tangent set
        per mesh: slots reading different UV maps get the first one's, noted."""
        wanted = []
        for mat in slot_materials:
            uv_map = tangent_uv_map(mat)
            if uv_map is not None and uv_map not in wanted:
                wanted.append(uv_map)
        if len(wanted) > 1:
            self._note((f"normal maps of one mesh read UV maps {', '.join(repr(w) for w in wanted)} "
                        f"(tangents of {wanted[0]!r} for all)",))
        return wanted[0] if wanted else None

    def _reconvert(self, mat) -> int:
        """Convert `mat` again; send it into the id it has if it changed. Returns 1, or 0 if it
        has no id yet (no mesh uses it)."""
        sent = self.materials.get(mat.name_full)
        if sent is None:
            return 0
        converted = materials.material_spec(mat)
        if converted.spec != sent[1]:
            self.scene.set_material(sent[0], **self._material_arguments(converted, mat.name_full))
            self.materials[mat.name_full] = (sent[0], converted.spec)
        else:
            # Unchanged: nothing to send, but a final render reports what it approximates every
            # frame (the farm test counts one note per frame), its textures' notes included.
            self._note(converted.notes)
            for key in _texture_keys(converted.spec):
                self._note(self.texture_notes.get(key, ()))
        return 1

    def _material_arguments(self, converted: materials.ConvertedMaterial, name: str) -> dict:
        self._note(converted.notes)
        spec = converted.spec
        texture, opacity = spec.texture, spec.opacity_texture
        bent = spec.normal_map.texture if spec.normal_map is not None else None
        glow = spec.emission_texture
        args = spec.arguments(self._texture_id(texture, converted.image) if texture is not None else -1,
                              self._texture_id(opacity, converted.opacity_image) if opacity is not None else -1,
                              self._texture_id(bent, converted.normal_image) if bent is not None else -1,
                              self._texture_id(glow, converted.emission_image) if glow is not None else -1)
        if spec.kind == "mix":
            images = dict(converted.image.images) if isinstance(converted.image, MixImages) else {}
            parts = iter(self.mix_parts.get(name, ()))
            sent = []
            args.update(self._mix_inputs(spec, images, parts, sent))
            self.mix_parts[name] = sent
        return args

    def _mix_inputs(self, spec, images: dict, reuse, sent: list) -> dict:
        """first, second (and fac_texture) of a 'mix' spec: its inputs sent as materials of their own
        (nested mixes first), into the ids `reuse` yields while it has some (the material's inputs
        sent before), else new ones; each id sent is appended to `sent`."""
        ids = []
        for part in spec.mix_inputs:
            if part is None:
                ids.append(-1)
                continue
            args = part.arguments(*(self._texture_id(k, images.get(k)) if k is not None else -1
                                    for k in (part.texture, part.opacity_texture, None)))
            if part.kind == "mix":
                args.update(self._mix_inputs(part, images, reuse, sent))
            mid = next(reuse, None)
            if mid is None:
                mid = self.scene.add_material(**args)
            else:
                self.scene.set_material(mid, **args)
            sent.append(mid)
            ids.append(mid)
        out = dict(first=ids[0], second=ids[1])
        if spec.mix_fac_texture is not None:
            out["fac_texture"] = self._texture_id(spec.mix_fac_texture, images.get(spec.mix_fac_texture))
        return out

    def _texture_id(self, key: ImageKey, image) -> int:
        tid = self.textures.get(key)
        if tid is None:
            pixels, notes = (None, ()) if key.placeholder else materials.image_data(image, key.alpha)
            self.texture_notes[key] = notes
            tid = self._placeholder_id() if pixels is None else self.scene.add_texture(pixels, srgb=key.srgb)
            self.textures[key] = tid
        # Again for every material that reads it: a final render collects the notes afresh.
        self._note(self.texture_notes[key])
        return tid

    def _environment_texture_id(self, env, sent_world) -> int:
        """The texture id of a world's environment (world.EnvironmentSpec): its image's, or for a
        map the add-on computed (a Sky Texture) one texture per world, whose pixels are sent again
        when the settings they come from differ from the world sent before (`sent_world`)."""
        if env.pixels is None:
            return self._texture_id(env.texture, env.image) if not env.texture.placeholder else self._placeholder_id()
        tid = self.textures.get(env.texture)
        if tid is None:
            tid = self.textures[env.texture] = self.scene.add_texture(env.pixels, srgb=False)
            self.texture_notes[env.texture] = ()
        else:
            before = sent_world.environment if sent_world is not None else None
            if before is None or before.texture != env.texture or before.computed_from != env.computed_from:
                self.scene.set_texture(tid, env.pixels, srgb=False)
        return tid

    def _placeholder_id(self) -> int:
        tid = self.textures.get(PLACEHOLDER)
        if tid is None:
            tid = self.textures[PLACEHOLDER] = self.scene.add_texture(PLACEHOLDER_PIXELS, srgb=False)
            self.texture_notes[PLACEHOLDER] = ()
        return tid

    def _refresh_image(self, image) -> int:
        """Send an edited image's pixels again into its texture ids; an image that was missing
        (the placeholder's id) gets its own texture, and its materials are sent again."""
        count = 0
        placeholder = self.textures.get(PLACEHOLDER)
        for key, tid in list(self.textures.items()):
            if key.placeholder or key.name != image.name_full:
                continue
            pixels, notes = materials.image_data(image, key.alpha)
            if pixels is None:
                continue
            if tid == placeholder:
                tid = self.textures[key] = self.scene.add_texture(pixels, srgb=key.srgb)
                for name, (mid, spec) in list(self.materials.items()):
                    bent = spec.normal_map.texture if spec.normal_map is not None else None
                    if spec.kind == "mix":
                        # Its inputs are materials of their own: convert it again, all sent anew.
                        import bpy
                        mat = (bpy.data.materials.get(name)
                               if key in _mix_keys(spec) or key in (bent, spec.emission_texture) else None)
                        if mat is not None:
                            self.scene.set_material(mid, **self._material_arguments(materials.material_spec(mat),
                                                                                    name))
                        continue
                    if key in (spec.texture, spec.opacity_texture, bent, spec.emission_texture):
                        ids = [self.textures.get(k, -1) if k is not None else -1
                               for k in (spec.texture, spec.opacity_texture, bent, spec.emission_texture)]
                        self.scene.set_material(mid, **spec.arguments(*ids))
            else:
                self.scene.set_texture(tid, pixels, srgb=key.srgb)
            self.texture_notes[key] = notes
            count += 1
        return count


def _mix_keys(spec) -> set:
    """Every texture key a 'mix' spec and its inputs read (the normal map's aside)."""
    keys = {spec.texture, spec.opacity_texture, spec.mix_fac_texture}
    for part in spec.mix_inputs:
        if part is not None:
            keys |= _mix_keys(part)
    return keys - {None}


def _texture_keys(spec):
    """Every image key a spec reads: its own textures and, for a mix, its inputs' and factor's."""
    own = (spec.texture, spec.opacity_texture, spec.normal_map.texture if spec.normal_map is not None else None,
           spec.emission_texture)
    yield from (k for k in own if k is not None)
    if spec.mix_fac_texture is not None:
        yield spec.mix_fac_texture
    for part in spec.mix_inputs:
        if part is not None:
            yield from _texture_keys(part)
